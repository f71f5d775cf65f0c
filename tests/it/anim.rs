//! Keyframed channels (`.anim`) against hand-computed values, the CSE169 skin, and the wasp
//! walking, checked against a small independent evaluation written here.

use std::io::Cursor;
use std::path::Path;

use glam::{Mat4, Vec3};
use marionette::formats::cse169_skin::{parse_anim, parse_morph, parse_skin};
use marionette::formats::load_character;
use marionette::rig::anim::Channel;

use crate::common::data_dir;

/// Three channels, one per extrapolation pair and tangent rule (our own numbers).
const CLIP: &str = "animation {
  range 0 2
  numchannels 3
  channel {
    extrapolate constant linear
    keys 4 {
      0 0 smooth smooth
      1 2 flat flat
      1.5 1 linear linear
      2 3 0.5 -1
    }
  }
  channel {
    extrapolate cycle cycle_offset
    keys 3 {
      0 0 smooth smooth
      1 1 smooth smooth
      2 3 smooth smooth
    }
  }
  channel 2{
    extrapolate bounce linear
    keys 2 {
      0 0 flat flat
      2 4 flat linear
    }
  }
}
";

fn clip() -> Vec<Channel> {
    parse_anim(Cursor::new(CLIP), Path::new("test.anim")).unwrap().channels
}

fn close(got: f32, want: f32, what: &str) {
    assert!((got - want).abs() < 1e-5, "{what}: got {got}, want {want}");
}

/// Worked by hand: Hermite with h00 = 2u³−3u²+1, h10 = u³−2u²+u, h01 = −2u³+3u², h11 = u³−u²
/// (at u = ½: ½, ⅛, ½, −⅛; at u = ¼: 27/32, 9/64, 5/32, −3/64), tangents times the span.
#[test]
fn every_tangent_rule_inside_the_keys_matches_hand_values() {
    let c = &clip()[0];
    // Slopes: key 0 smooth at the start = linear to key 1 = 2; key 1 flat; key 2 linear:
    // in (1−2)/0.5 = −2, out (3−1)/0.5 = 4; key 3 given: in 0.5, out −1.
    assert_eq!(c.slopes(0), (2.0, 2.0));
    assert_eq!(c.slopes(1), (0.0, 0.0));
    assert_eq!(c.slopes(2), (-2.0, 4.0));
    assert_eq!(c.slopes(3), (0.5, -1.0));
    close(c.value_at(0.5), 0.125 * 2.0 + 0.5 * 2.0, "span 0 at u = 1/2"); // 1.25
    close(c.value_at(1.25), 0.5 * 2.0 + 0.5 * 1.0 - 0.125 * (-2.0 * 0.5), "span 1"); // 1.625
    close(c.value_at(1.75), 0.5 + 0.125 * 2.0 + 1.5 - 0.125 * 0.25, "span 2"); // 2.21875
    for (t, v) in [(0.0, 0.0), (1.0, 2.0), (1.5, 1.0), (2.0, 3.0)] {
        close(c.value_at(t), v, &format!("on the key at {t}"));
    }
    let smooth = &clip()[1];
    // Key 0: (1−0)/1 = 1 (linear at the start); key 1: (3−0)/2 = 1.5; key 2: (3−1)/1 = 2.
    assert_eq!((smooth.slopes(0).1, smooth.slopes(1).0, smooth.slopes(2).0), (1.0, 1.5, 2.0));
    close(smooth.value_at(0.5), 0.125 + 0.5 - 0.125 * 1.5, "smooth span 0"); // 0.4375
}

#[test]
fn every_extrapolation_before_and_after_matches_hand_values() {
    let [a, b, c] = <[Channel; 3]>::try_from(clip()).unwrap();
    close(a.value_at(-3.0), 0.0, "constant before");
    close(a.value_at(3.0), 3.0 - 1.0, "linear after: the last key's out slope, −1");
    // Cycle before: −0.5 is 1.5 in the keys (span 1 at u = ½: ½·1 + ⅛·1.5 + ½·3 − ⅛·2).
    close(b.value_at(-0.5), 1.9375, "cycle before");
    close(b.value_at(-4.5), 1.9375, "cycle, three periods back");
    // Cycle with offset after: each period adds 3 − 0.
    close(b.value_at(2.5), 0.4375 + 3.0, "cycle_offset, one period on");
    close(b.value_at(6.5), 0.4375 + 9.0, "cycle_offset, three periods on");
    // Bounce before: −0.5 mirrors to 0.5 (u = ¼: h01 = 5/32 of 4); −3 to 1.
    close(c.value_at(-0.5), 0.625, "bounce before");
    close(c.value_at(-3.0), 2.0, "bounce, mirrored once more");
    close(c.value_at(-4.0), 0.0, "bounce, a whole period back");
    close(c.value_at(3.0), 4.0 + 2.0, "linear after along the linear out slope (4 − 0)/2");
}

#[test]
fn value_and_slope_are_continuous_where_the_rules_promise_it() {
    let channels = clip();
    let h = 1e-3;
    for (c, keys) in [(&channels[0], &[1.0f32, 1.5][..]), (&channels[1], &[1.0][..])] {
        for &t in keys {
            let (before, after) = (c.value_at(t - 1e-6), c.value_at(t + 1e-6));
            assert!((before - after).abs() < 1e-4, "value across the key at {t}: {before} {after}");
        }
    }
    // Smooth keys have one slope both sides: 1.5 at t = 1.
    let smooth = &channels[1];
    let left = (smooth.value_at(1.0) - smooth.value_at(1.0 - h)) / h;
    let right = (smooth.value_at(1.0 + h) - smooth.value_at(1.0)) / h;
    assert!((left - 1.5).abs() < 5e-3 && (right - 1.5).abs() < 5e-3, "{left} {right}");
    // Cycle with offset joins its periods without a jump.
    let (before, after) = (smooth.value_at(2.0 - 1e-6), smooth.value_at(2.0 + 1e-6));
    assert!((before - after).abs() < 1e-4, "cycle_offset at the seam: {before} {after}");
}

/// The pieces a clip goes out to glTF in: between two seams (keys, and the keys of every
/// repetition the extrapolation makes) a channel is one cubic, so the Hermite spline made of
/// the one-sided values and slopes at the seams is the channel itself; and the one-sided
/// values are the limits `value_at` approaches from each side.
#[test]
fn between_its_seams_a_channel_is_the_cubic_its_sided_values_and_slopes_make() {
    use marionette::rig::anim::{Extrapolation, Key, Side, Tangent, hermite};
    let key = |time, value, tangent_in, tangent_out| Key { time, value, tangent_in, tangent_out };
    let stepped = Channel::new(
        vec![
            key(0.0, 1.0, Tangent::Smooth, Tangent::Step),
            key(0.7, -2.0, Tangent::Flat, Tangent::Smooth),
            key(1.6, 0.5, Tangent::Fixed(3.0), Tangent::Linear),
        ],
        Extrapolation::Bounce,
        Extrapolation::Cycle,
    );
    let mut channels = clip();
    channels.push(stepped);
    let range = (-3.3, 7.1);
    for (c, channel) in channels.iter().enumerate() {
        let seams = channel.seams(range, 1000).unwrap();
        assert_eq!((seams[0], seams[seams.len() - 1]), range);
        for pair in seams.windows(2) {
            let (t0, t1) = (pair[0], pair[1]);
            let (p0, m0) = channel.sided(t0, Side::After);
            let (p1, m1) = channel.sided(t1, Side::Before);
            let span = t1 - t0;
            for u in [0.1, 0.37, 0.5, 0.83] {
                let t = t0 + u * span;
                let want = channel.value_at(t);
                let got = hermite(p0, m0 * span, p1, m1 * span, u);
                assert!((got - want).abs() < 2e-4, "channel {c} in [{t0}, {t1}] at {t}: {got} against {want}");
            }
            // One-sided limits: the value just inside each end, and the slope by differences.
            let h = 1e-3;
            let (inside0, inside1) = (channel.value_at(t0 + h), channel.value_at(t1 - h));
            assert!((inside0 - (p0 + m0 * h)).abs() < 1e-3, "channel {c} after {t0}: {inside0} against {p0}, {m0}");
            assert!((inside1 - (p1 - m1 * h)).abs() < 1e-3, "channel {c} before {t1}: {inside1} against {p1}, {m1}");
        }
    }
    // The step jumps at 0.7 (and at its bounced and cycled copies); a smooth key does not.
    let stepped = &channels[3];
    assert_eq!(stepped.sided(0.7, Side::Before), (1.0, 0.0));
    assert_eq!(stepped.sided(0.7, Side::After).0, -2.0);
    assert_eq!(stepped.sided(1.6 + 0.7, Side::Before).0, 1.0, "one cycle on");
    let smooth = &channels[1];
    assert_eq!(smooth.sided(1.0, Side::Before), smooth.sided(1.0, Side::After));
    // On a step's next key the curve has that key's value, the last key too.
    let steps = Channel::new(
        vec![key(0.0, 1.0, Tangent::Step, Tangent::Step), key(1.0, 2.0, Tangent::Step, Tangent::Step)],
        Extrapolation::Constant,
        Extrapolation::Constant,
    );
    assert_eq!((steps.value_at(0.999), steps.value_at(1.0)), (1.0, 2.0));
    // Too many repetitions are refused rather than listed.
    assert!(smooth.seams((0.0, 1e9), 1000).unwrap_err().contains("more than the 1000"));
}

#[test]
fn bad_clips_name_the_file_and_line() {
    let cases = [
        ("animation {\n range 0 1\n numchannels 1\n channel {\n extrapolate constant sideways\n", "test.anim:5"),
        (
            "animation {\n range 0 1\n numchannels 1\n channel {\n extrapolate constant constant\n keys 1 {\n 0 1 curly flat\n }\n }\n}\n",
            "test.anim:7",
        ),
        ("animation {\r range 0 x\r", "test.anim:2"),
        (
            "animation {\n range 0 1\n numchannels 2\n channel {\n extrapolate constant constant\n keys 0 {\n }\n }\n}\n",
            "test.anim:9",
        ),
    ];
    for (text, place) in cases {
        let e = parse_anim(Cursor::new(text), Path::new("test.anim")).unwrap_err().to_string();
        assert!(e.contains(place), "{e}");
    }
}

#[test]
fn a_skin_reads_its_sections_and_rejects_bad_indices() {
    let skin = "positions 3 {0 0 0\r1 0 0\r0 1 0}\nnormals 3 {0 0 1 0 0 1 0 0 1}\nskinweights 3 {\n1 0 1\n2 0 0.5 1 0.5\n1 1 1\n}\ntriangles 1 {0 1 2}\nbindings 2 {\nmatrix {\n1 0 0\n0 1 0\n0 0 1\n0 2 0\n}\nmatrix {1 0 0 0 1 0 0 0 1 0 0 0}\n}\n";
    let file = parse_skin(Cursor::new(skin), Path::new("t.skin")).unwrap();
    assert_eq!(file.positions.len(), 3);
    assert_eq!(file.weights[1], vec![(0, 0.5), (1, 0.5)]);
    assert_eq!(file.triangles, vec![[0, 1, 2]]);
    assert_eq!(
        file.bindings[0],
        Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0)),
        "rows a b c are axes, d the position"
    );
    let bad = skin.replace("triangles 1 {0 1 2}", "triangles 1 {0 1 3}");
    let e = parse_skin(Cursor::new(bad), Path::new("t.skin")).unwrap_err().to_string();
    assert!(e.contains("t.skin:10") && e.contains("below 3"), "{e}");
    let morph =
        parse_morph(Cursor::new("positions 1 {\n 2 0.5 0.5 0\n}\nnormals 1 { 2 0 0 1 }"), Path::new("m"), 3).unwrap();
    assert_eq!(morph.positions, vec![(2, Vec3::new(0.5, 0.5, 0.0))]);
    assert!(parse_morph(Cursor::new("positions 1 {\n 3 0 0 0\n}"), Path::new("m"), 3).is_err());
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn every_cse169_skin_morph_and_clip_loads() {
    let data = data_dir().join("cse169");
    for skel in ["project2/tube.skel", "project2/wasp.skel", "project3/wasp.skel", "extras/head.skel"] {
        let path = data.join(skel);
        let skin =
            parse_skin(std::io::BufReader::new(std::fs::File::open(path.with_extension("skin")).unwrap()), &path)
                .unwrap();
        let asset = load_character(&path).unwrap();
        assert_eq!(asset.vertex_count(), skin.positions.len(), "{skel}: one vertex per .skin position");
    }
    let head = parse_skin(
        std::io::BufReader::new(std::fs::File::open(data.join("extras/head.skin")).unwrap()),
        Path::new("head.skin"),
    )
    .unwrap();
    assert_eq!(head.texcoords.len(), head.positions.len());
    assert!(head.texture.as_ref().is_some_and(|t| t.ends_with("head.bmp")));
    for morph in ["extras/head1.morph", "extras/head2.morph"] {
        let m = parse_morph(
            std::io::BufReader::new(std::fs::File::open(data.join(morph)).unwrap()),
            Path::new(morph),
            head.positions.len(),
        )
        .unwrap();
        assert!(!m.positions.is_empty() && m.positions.len() == m.normals.len(), "{morph}");
    }
    // The older skin (four influences, other normals) and the old, unnumbered clip.
    for skin in ["legacy/wasp.skin", "legacy/triangle.skin"] {
        parse_skin(std::io::BufReader::new(std::fs::File::open(data.join(skin)).unwrap()), Path::new(skin)).unwrap();
    }
    for anim in ["project3/wasp_walk.anim", "project3/sample.anim", "legacy/wasp_walk.anim"] {
        let clip = parse_anim(std::io::BufReader::new(std::fs::File::open(data.join(anim)).unwrap()), Path::new(anim))
            .unwrap();
        assert!(!clip.channels.is_empty(), "{anim}");
    }
}

/// An independent reading of a `.anim` for the wasp test: words, Hermite, the rules.
mod independent {
    pub struct Chan {
        pub ext: (String, String),
        pub keys: Vec<(f64, f64, String, String)>,
    }

    pub fn read(text: &str) -> Vec<Chan> {
        let spaced = text.replace('{', " { ").replace('}', " } ");
        let words: Vec<&str> = spaced.split_whitespace().collect();
        let mut out = Vec::new();
        let mut i = 0;
        while i < words.len() {
            if words[i] == "extrapolate" {
                let ext = (words[i + 1].to_string(), words[i + 2].to_string());
                let n: usize = words[i + 4].parse().unwrap();
                let mut k = i + 6;
                let mut keys = Vec::new();
                for _ in 0..n {
                    keys.push((
                        words[k].parse().unwrap(),
                        words[k + 1].parse().unwrap(),
                        words[k + 2].to_string(),
                        words[k + 3].to_string(),
                    ));
                    k += 4;
                }
                out.push(Chan { ext, keys });
                i = k;
            } else {
                i += 1;
            }
        }
        out
    }

    fn tangent(keys: &[(f64, f64, String, String)], k: usize, rule: &str, incoming: bool) -> f64 {
        let sec = |a: usize, b: usize| (keys[b].1 - keys[a].1) / (keys[b].0 - keys[a].0);
        let n = keys.len();
        if n == 1 || rule == "flat" {
            return 0.0;
        }
        if let Ok(v) = rule.parse::<f64>() {
            return v;
        }
        match (rule, k == 0, k == n - 1) {
            (_, true, _) => sec(0, 1),
            (_, _, true) => sec(n - 2, n - 1),
            ("smooth", ..) => sec(k - 1, k + 1),
            _ if incoming => sec(k - 1, k),
            _ => sec(k, k + 1),
        }
    }

    /// The value at t; outside the keys only what the wasp's clip uses (constant, cycle,
    /// cycle_offset).
    pub fn value(c: &Chan, t: f64) -> f64 {
        let keys = &c.keys;
        let (t0, t1) = (keys[0].0, keys[keys.len() - 1].0);
        if keys.len() == 1 {
            return keys[0].1;
        }
        let mut t = t;
        let mut shift = 0.0;
        if t < t0 || t > t1 {
            let mode = if t < t0 { &c.ext.0 } else { &c.ext.1 };
            let periods = ((t - t0) / (t1 - t0)).floor();
            match mode.as_str() {
                "constant" => return if t < t0 { keys[0].1 } else { keys[keys.len() - 1].1 },
                "cycle" => t -= periods * (t1 - t0),
                "cycle_offset" => {
                    t -= periods * (t1 - t0);
                    shift = periods * (keys[keys.len() - 1].1 - keys[0].1);
                }
                other => panic!("the wasp's clip has no `{other}`"),
            }
        }
        let k = (0..keys.len() - 1).rev().find(|&k| keys[k].0 <= t).unwrap_or(0);
        let (a, b) = (&keys[k], &keys[k + 1]);
        let span = b.0 - a.0;
        let u = (t - a.0) / span;
        let m0 = tangent(keys, k, &a.3, false) * span;
        let m1 = tangent(keys, k + 1, &b.2, true) * span;
        shift
            + (2.0 * u.powi(3) - 3.0 * u * u + 1.0) * a.1
            + (u.powi(3) - 2.0 * u * u + u) * m0
            + (-2.0 * u.powi(3) + 3.0 * u * u) * b.1
            + (u.powi(3) - u * u) * m1
    }
}

/// The wasp walks: its joints' positions at t = 0, 1, 2.5 and 5 from our clip evaluation
/// and FK equal those from the independent reading above and a plain FK (translate by the
/// offset, rotate z·y·x), within 1e-4.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn the_wasp_walks_as_an_independent_evaluation_says() {
    let data = data_dir().join("cse169/project3");
    let asset = load_character(&data.join("wasp.skel")).unwrap();
    let skeleton = &asset.skeleton;
    let text = std::fs::read_to_string(data.join("wasp_walk.anim")).unwrap();
    let clip = parse_anim(Cursor::new(&text), Path::new("wasp_walk.anim")).unwrap();
    let theirs = independent::read(&text);
    assert_eq!(theirs.len(), 3 + 3 * skeleton.len());
    let mut moved = 0.0f32;
    let mut first: Option<Vec<Vec3>> = None;
    for t in [0.0f32, 1.0, 2.5, 5.0] {
        let (root, pose) = clip.pose_at(skeleton, t, &skeleton.initial_pose());
        let origin = Mat4::from_translation(root - skeleton.joint(0).rest_offset);
        let mut ours = vec![Mat4::IDENTITY; skeleton.len()];
        marionette::rig::forward_kinematics(skeleton, &pose, origin, &mut ours);
        // Plain FK from the independent values (the wasp's joints have no limits).
        let v: Vec<f64> = theirs.iter().map(|c| independent::value(c, f64::from(t))).collect();
        let mut world = vec![Mat4::IDENTITY; skeleton.len()];
        for j in 0..skeleton.len() {
            let offset =
                if j == 0 { Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32) } else { skeleton.joint(j).rest_offset };
            let (x, y, z) = (v[3 + 3 * j] as f32, v[4 + 3 * j] as f32, v[5 + 3 * j] as f32);
            let local = Mat4::from_translation(offset)
                * Mat4::from_rotation_z(z)
                * Mat4::from_rotation_y(y)
                * Mat4::from_rotation_x(x);
            world[j] = skeleton.parent(j).map_or(Mat4::IDENTITY, |p| world[p]) * local;
        }
        let positions: Vec<Vec3> = world.iter().map(|m| m.w_axis.truncate()).collect();
        for (j, (a, b)) in ours.iter().zip(&world).enumerate() {
            let d = (a.w_axis.truncate() - b.w_axis.truncate()).length();
            assert!(d < 1e-4, "t = {t}, joint {} is {d} away", skeleton.joint(j).name);
        }
        if let Some(f) = &first {
            moved = moved.max(f.iter().zip(&positions).map(|(a, b)| a.distance(*b)).fold(0.0, f32::max));
        } else {
            first = Some(positions);
        }
    }
    assert!(moved > 0.1, "the legs move: {moved}");
}

/// A scene with the wasp and its clip, paused at 2.5 s: the ECS poses the joints as the
/// clip and FK say (oracle), and the clip's state survives a save and reload exactly.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn a_scene_plays_a_clip_on_the_wasp_and_keeps_it_in_the_file() {
    use bevy::prelude::*;
    use marionette::document::scenes::{read_scene, write_scene};
    use marionette::editor::ScenePlugin;
    use marionette::editor::scene_doc::document::{PendingScene, SceneReader};
    use marionette::formats::scene::{AnimDoc, CharacterDoc, SceneDoc, SourceDoc};
    use marionette::scene::{Character, CurrentJointToWorld};

    let data = data_dir().join("cse169/project3");
    let anim = AnimDoc { time: 2.5, playing: false, ..AnimDoc::of(data.join("wasp_walk.anim")) };
    let wasp =
        CharacterDoc { anim: Some(anim.clone()), ..CharacterDoc::new(SourceDoc::File(data.join("wasp.skel")), "wasp") };
    let mut app = crate::ecs::app();
    app.add_plugins(ScenePlugin);
    let doc = SceneDoc { characters: vec![wasp], ..SceneDoc::default() };
    *app.world_mut().resource_mut::<PendingScene>() = PendingScene { doc: Some(doc), frame: false };
    app.update();
    app.update();

    let character = app.world_mut().query::<&Character>().single(app.world()).unwrap().clone();
    let skeleton = &character.asset.skeleton;
    let clip = parse_anim(Cursor::new(std::fs::read_to_string(&anim.file).unwrap()), &anim.file).unwrap();
    let (root, pose) = clip.pose_at(skeleton, 2.5, &skeleton.initial_pose());
    let mut want = vec![Mat4::IDENTITY; skeleton.len()];
    marionette::rig::forward_kinematics(
        skeleton,
        &pose,
        Mat4::from_translation(root - skeleton.joint(0).rest_offset),
        &mut want,
    );
    for (j, &e) in character.joints.iter().enumerate() {
        let got = app.world().get::<CurrentJointToWorld>(e).unwrap().0;
        assert!(got.abs_diff_eq(want[j], 1e-5), "joint {j}");
    }

    let mut reader = bevy::ecs::system::SystemState::<SceneReader>::new(app.world_mut());
    let saved = reader.get(app.world()).unwrap().capture();
    let path = crate::common::scratch("anim-scene").join("wasp.ron");
    write_scene(&path, &saved).unwrap();
    let back = read_scene(&path).unwrap();
    let mut reloaded = back.characters[0].anim.clone().expect("the clip is kept");
    assert_eq!(
        std::fs::canonicalize(&reloaded.file).unwrap(),
        std::fs::canonicalize(&anim.file).unwrap(),
        "the same file, written relative to the scene"
    );
    reloaded.file = anim.file.clone();
    assert_eq!(reloaded, anim, "its time and playback, exactly");
}

/// Keys set on a pose play back exactly at their times, channels without keys leave the
/// rest of the pose alone, and the keys survive `.anim` export and a scene file exactly.
#[test]
fn keyed_poses_play_back_and_survive_anim_export_and_scene_files() {
    use marionette::formats::cse169_skin::write_anim;
    use marionette::formats::scene::{AnimDoc, CharacterDoc, SceneDoc, SourceDoc, parse_scene, save_scene};
    use marionette::rig::JointRotation;
    use marionette::rig::anim::Clip;

    let puppet = marionette::formats::puppet::embedded_puppet();
    let skeleton = &puppet.skeleton;
    let elbow = skeleton.find("l_elbow").unwrap();
    let rest = skeleton.initial_pose();
    let mut bent = rest.clone();
    bent[elbow] = JointRotation::euler_xyz(0.1, -0.7, 0.3);
    bent[0] = JointRotation::euler_xyz(0.0, 0.5, 0.0);
    let clip = Clip::empty(skeleton.len()).with_pose_keyed(&[elbow], &rest, 0.0).with_pose_keyed(&[elbow], &bent, 1.5);
    assert_eq!(clip.range, (0.0, 1.5));
    let (_, at_end) = clip.pose_at(skeleton, 1.5, &rest);
    assert_eq!(at_end[elbow].to_euler(marionette::rig::EulerOrder::Xyz), glam::Vec3::new(0.1, -0.7, 0.3));
    assert_eq!(at_end[0], rest[0], "the root has no keys: it keeps its pose");
    let (_, halfway) = clip.pose_at(skeleton, 0.75, &rest);
    let y = halfway[elbow].to_euler(marionette::rig::EulerOrder::Xyz).y;
    assert!(y < -0.1 && y > -0.6, "between the keys: {y}");

    let mut text = Vec::new();
    write_anim(&mut text, &clip).unwrap();
    let back = parse_anim(Cursor::new(&text), Path::new("keys.anim")).unwrap();
    assert_eq!(back, clip, "the .anim reads back exactly");

    let anim = AnimDoc { keys: Some(clip), time: 0.25, playing: false, ..AnimDoc::default() };
    let doc = SceneDoc {
        characters: vec![CharacterDoc {
            anim: Some(anim.clone()),
            ..CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "p")
        }],
        ..SceneDoc::default()
    };
    let path = crate::common::scratch("keys-scene").join("keys.ron");
    save_scene(&path, &doc).unwrap();
    let reread = parse_scene(std::io::BufReader::new(std::fs::File::open(&path).unwrap()), &path).unwrap();
    assert_eq!(reread.characters[0].anim, Some(anim), "keys survive a save and reload exactly");
}

/// The head's morphs: at full weight the moved vertices are where `head1.morph` puts them
/// (read here on our own), at zero the skin is as loaded, and halfway is halfway.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn the_head_blends_its_morph_targets() {
    let data = data_dir().join("cse169/extras");
    let head = load_character(&data.join("head.skel")).unwrap();
    let names: Vec<&str> = head.morphs.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["head1", "head2"]);
    let text = std::fs::read_to_string(data.join("head1.morph")).unwrap();
    let words: Vec<&str> = text.split(['{', '}', ' ', '\t', '\r', '\n']).filter(|w| !w.is_empty()).collect();
    let count: usize = words[1].parse().unwrap();
    let targets: Vec<(usize, Vec3)> = (0..count)
        .map(|i| {
            let w = &words[2 + 4 * i..6 + 4 * i];
            (w[0].parse().unwrap(), Vec3::new(w[1].parse().unwrap(), w[2].parse().unwrap(), w[3].parse().unwrap()))
        })
        .collect();
    let full = head.morphed_positions(&[1.0, 0.0]);
    let half = head.morphed_positions(&[0.5, 0.0]);
    let base = &head.skin.bind_positions;
    for &(v, target) in &targets {
        assert!((full[v] - target).length() < 1e-5, "vertex {v}");
        assert!((half[v] - (base[v] + target) / 2.0).length() < 1e-5, "vertex {v} halfway");
    }
    assert_eq!(&head.morphed_positions(&[0.0, 0.0]), base);
    let moved: std::collections::HashSet<usize> = targets.iter().map(|t| t.0).collect();
    assert!((0..base.len()).filter(|v| !moved.contains(v)).all(|v| full[v] == base[v]), "the others stay");
}

/// Constant (step) and linear interpolation between keys.
#[test]
fn step_holds_and_linear_tangents_draw_straight_lines() {
    let text = "animation { range 0 2 numchannels 1 channel { extrapolate constant constant keys 3 {
        0 0 linear step
        1 2 linear linear
        2 0 linear linear } } }";
    let clip = parse_anim(Cursor::new(text), Path::new("t.anim")).unwrap();
    let c = &clip.channels[0];
    for t in [0.0, 0.3, 0.99] {
        close(c.value_at(t), 0.0, "held until the next key");
    }
    close(c.value_at(1.0), 2.0, "the next key");
    for t in [1.25f32, 1.5, 1.75] {
        close(c.value_at(t), 2.0 - 2.0 * (t - 1.0), "a straight line between linear keys");
    }
    let mut written = Vec::new();
    marionette::formats::cse169_skin::write_anim(&mut written, &clip).unwrap();
    assert_eq!(parse_anim(Cursor::new(written), Path::new("t.anim")).unwrap(), clip, "step is written and read back");
}

/// A 2 × 2 bitmap written here: rows bottom-up, BGR, each row padded to 4 bytes; decoded
/// top row first as RGBA. Other kinds are refused with what they are.
#[test]
fn bitmaps_decode_top_row_first_and_others_are_refused() {
    use marionette::formats::bmp::decode_bmp;
    let mut bmp = Vec::new();
    bmp.extend_from_slice(b"BM");
    bmp.extend_from_slice(&(54u32 + 16).to_le_bytes());
    bmp.extend_from_slice(&[0; 4]);
    bmp.extend_from_slice(&54u32.to_le_bytes());
    bmp.extend_from_slice(&40u32.to_le_bytes());
    bmp.extend_from_slice(&2i32.to_le_bytes());
    bmp.extend_from_slice(&2i32.to_le_bytes());
    bmp.extend_from_slice(&1u16.to_le_bytes());
    bmp.extend_from_slice(&24u16.to_le_bytes());
    bmp.extend_from_slice(&[0; 24]);
    // Bottom row: blue, green; top row: red, white (BGR, 2 bytes of padding each).
    bmp.extend_from_slice(&[255, 0, 0, 0, 255, 0, 0, 0]);
    bmp.extend_from_slice(&[0, 0, 255, 255, 255, 255, 0, 0]);
    let image = decode_bmp(&bmp, Path::new("t.bmp")).unwrap();
    assert_eq!((image.width, image.height), (2, 2));
    assert_eq!(image.pixels, [255, 0, 0, 255, 255, 255, 255, 255, 0, 0, 255, 255, 0, 255, 0, 255]);
    let mut rle = bmp.clone();
    rle[30] = 1;
    let e = decode_bmp(&rle, Path::new("t.bmp")).unwrap_err().to_string();
    assert!(e.contains("t.bmp") && e.contains("compression 1"), "{e}");
    assert!(decode_bmp(&bmp[..60], Path::new("t.bmp")).is_err(), "cut short");
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn the_head_is_textured_with_its_bitmap() {
    let data = data_dir().join("cse169/extras");
    let head = load_character(&data.join("head.skel")).unwrap();
    assert!(
        matches!(head.base_color_texture(), Some(marionette::rig::SkinTexture::File(t)) if t.ends_with("head.bmp"))
    );
    assert_eq!(head.skin.texcoords.len(), head.vertex_count());
    let bytes = std::fs::read(data.join("head.bmp")).unwrap();
    let image = marionette::formats::bmp::decode_bmp(&bytes, Path::new("head.bmp")).unwrap();
    assert_eq!((image.width, image.height), (512, 512));
}

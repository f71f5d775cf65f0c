//! The editor's document layer: scene files, screenshots and the headless render.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::PathBuf;
use std::process::Command;

use marionette::document::scenes::{pose_from_doc, read_scene, write_scene};
use marionette::editor::present::screenshot::timestamp;
use marionette::formats::scene::{
    CharacterDoc, PlacementDoc, SceneDoc, SourceDoc, ViewDoc, parse_scene, scene_to_string,
};
use marionette::rig::JointRotation;

use crate::common::{data_dir, scratch};

pub fn doc_with(source: SourceDoc, pose: &[(&str, JointRotation)]) -> SceneDoc {
    SceneDoc {
        characters: vec![CharacterDoc {
            placement: PlacementDoc::new(glam::Vec3::new(0.5, 0.0, -1.0), 0.3, 1.2),
            pose: pose.iter().map(|(k, r)| (k.to_string(), *r)).collect::<BTreeMap<_, _>>(),
            view: ViewDoc { weight_colors: true, ..ViewDoc::default() },
            ..CharacterDoc::new(source, "c")
        }],
        camera: None,
        stage: Default::default(),
        ..SceneDoc::default()
    }
}

#[test]
fn scenes_round_trip_with_paths_relative_to_the_scene() {
    let dir = scratch("scene-round-trip");
    std::fs::create_dir_all(dir.join("models")).unwrap();
    let character = dir.join("models/m.skel");
    std::fs::write(&character, "0 0 0 -1\n0 1 0 0\n").unwrap();
    let doc = doc_with(SourceDoc::File(character.clone()), &[("joint1", JointRotation::euler_xyz(0.1, 0.2, 0.3))]);
    let path = dir.join("scene.ron");
    write_scene(&path, &doc).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("File(\"models/m.skel\")"), "stored relative to the scene: {text}");
    let back = read_scene(&path).unwrap();
    assert_eq!(back.characters[0].source, SourceDoc::File(dir.join("models/m.skel")));
    assert_eq!(back.characters[0].pose, doc.characters[0].pose);
    assert_eq!(back.characters[0].placement, doc.characters[0].placement);
    assert_eq!(back.characters[0].view, doc.characters[0].view);
}

#[test]
fn a_failed_save_leaves_the_previous_file_whole() {
    let dir = scratch("atomic-save");
    let path = dir.join("scene.ron");
    std::fs::write(&path, "previous").unwrap();
    let result = marionette::formats::write_atomically(&path, |w| {
        std::io::Write::write_all(w, b"half a scen")?;
        Err(std::io::Error::other("disk full"))
    });
    assert!(result.is_err());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "previous");
    let leftovers: Vec<PathBuf> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    assert_eq!(leftovers, vec![path], "no temporary file is left behind");
}

/// Save writes back to the scene the editor was opened on (not to `scene.ron` in the
/// working folder, where the edits would be lost to the opened file).
#[test]
fn save_goes_back_to_the_opened_scene() {
    use marionette::document::scenes::initial_save_path;
    use std::path::{Path, PathBuf};
    let cwd = Path::new("/work/here");
    assert_eq!(initial_save_path(&[PathBuf::from("/tmp/crowd.ron")], cwd), Path::new("/tmp/crowd.ron"));
    assert_eq!(initial_save_path(&[PathBuf::from("scenes/a.ron")], cwd), Path::new("/work/here/scenes/a.ron"));
    assert_eq!(initial_save_path(&[PathBuf::from("Model1.skel")], cwd), Path::new("/work/here/scene.ron"));
    assert_eq!(initial_save_path(&[], cwd), Path::new("/work/here/scene.ron"));
}

#[test]
fn a_malformed_scene_reports_its_line() {
    let e = parse_scene(
        Cursor::new("(\n  characters: [\n    (source: Nowhere(\"x\"))\n  ],\n)\n"),
        std::path::Path::new("s.ron"),
    )
    .unwrap_err();
    let text = e.to_string();
    let column = text.strip_prefix("s.ron:3:").and_then(|rest| rest.split_once(": ")).map(|(c, _)| c);
    assert!(column.is_some_and(|c| c.parse::<usize>().is_ok()), "line and column: {e}");
}

#[test]
fn unknown_joints_in_a_scene_pose_are_reported_not_fatal() {
    let asset = marionette::formats::puppet::embedded_puppet();
    let doc = doc_with(
        SourceDoc::Embedded("puppet".into()),
        &[("l_elbow", JointRotation::euler_xyz(0.0, 1.0, 0.0)), ("tail", JointRotation::euler_xyz(1.0, 0.0, 0.0))],
    );
    let (pose, messages) = pose_from_doc(&asset, &doc.characters[0]);
    assert_eq!(pose[asset.skeleton.find("l_elbow").unwrap()], JointRotation::euler_xyz(0.0, 1.0, 0.0));
    assert_eq!(messages.len(), 1);
    assert!(messages[0].contains("no joint `tail`"), "{}", messages[0]);
}

#[test]
fn screenshot_names_carry_the_utc_date_and_time() {
    assert_eq!(timestamp(0), "1970-01-01_00-00-00");
    assert_eq!(timestamp(1_795_315_505), "2026-11-22_02-45-05");
    assert_eq!(timestamp(951_782_400), "2000-02-29_00-00-00");
}

#[test]
fn the_shipped_assets_are_what_the_generator_makes() {
    let scene = marionette::document::scenes::default_scene_doc();
    assert_eq!(scene, marionette::document::default_scene::generate());
    assert!(scene.characters.len() >= 2);
    let dir = scratch("gen-assets");
    marionette::formats::puppet::write_6837(&marionette::formats::puppet::puppet(), &dir, "puppet").unwrap();
    for ext in ["skel", "obj", "attach"] {
        let made = std::fs::read_to_string(dir.join(format!("puppet.{ext}"))).unwrap();
        let shipped = std::fs::read_to_string(format!("{}/assets/puppet.{ext}", env!("CARGO_MANIFEST_DIR"))).unwrap();
        assert!(made == shipped, "assets/puppet.{ext} is stale: run `marionette gen-assets assets`");
    }
    let _ = scene_to_string(&scene).expect("serialises");
    let crowd = read_scene(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/crowd_scene.ron")).unwrap();
    assert_eq!(crowd, marionette::document::crowd::shipped_crowd(), "assets/crowd_scene.ron is stale");
}

/// Renders a small scene headlessly (Vulkan; llvmpipe without a GPU) and checks the picture.
#[test]
fn render_draws_characters_distinct_from_floor_and_sky_with_weight_hues() {
    let dir = scratch("render");
    let mut doc =
        doc_with(SourceDoc::Embedded("puppet".into()), &[("l_shoulder", JointRotation::euler_xyz(0.0, 0.0, -1.0))]);
    doc.characters[0].placement = PlacementDoc::default();
    doc.camera = Some(marionette::formats::scene::CameraDoc {
        focus: glam::Vec3::new(0.0, 0.5, 0.0),
        yaw: 0.0,
        pitch: -0.2,
        distance: 1.6,
        ..Default::default()
    });
    let scene = dir.join("scene.ron");
    write_scene(&scene, &doc).unwrap();
    let out = dir.join("shot.png");
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["render", "--width", "200", "--height", "150", "--out"])
        .arg(&out)
        .arg(&scene)
        .output()
        .unwrap();
    assert!(output.status.success(), "render failed: {}", String::from_utf8_lossy(&output.stderr));
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (200, 150));
    let sky = *img.get_pixel(100, 2);
    let floor = *img.get_pixel(100, 147);
    assert_ne!(sky, floor);
    let far = |p: &image::Rgb<u8>, q: &image::Rgb<u8>| {
        p.0.iter().zip(q.0).map(|(a, b)| (*a as i32 - b as i32).abs()).sum::<i32>() > 60
    };
    let character: Vec<&image::Rgb<u8>> = img.pixels().filter(|p| far(p, &sky) && far(p, &floor)).collect();
    assert!(character.len() > 1000, "only {} character pixels", character.len());
    // Weight colours: several distinct hues among saturated pixels.
    let mut hues = std::collections::BTreeSet::new();
    for p in &character {
        let [r, g, b] = p.0.map(|c| c as f32 / 255.0);
        let (max, min) = (r.max(g).max(b), r.min(g).min(b));
        if max - min < 0.15 {
            continue;
        }
        let h = if max == r {
            ((g - b) / (max - min)).rem_euclid(6.0)
        } else if max == g {
            (b - r) / (max - min) + 2.0
        } else {
            (r - g) / (max - min) + 4.0
        };
        hues.insert((h * 2.0) as i32); // 12 bins of 30°
    }
    assert!(hues.len() >= 4, "hues seen: {hues:?}");
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn model1_and_model2_render_side_by_side() {
    let data = data_dir();
    let out = scratch("render-models").join("models.png");
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["render", "--width", "160", "--height", "120", "--out"])
        .arg(&out)
        .arg(data.join("mit6837/Model1.skel"))
        .arg(data.join("mit6837/Model2.skel"))
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    assert_eq!(image::open(&out).unwrap().to_rgb8().dimensions(), (160, 120));
}

/// `marionette bench --json` with `args` on puppets (no data folder): its report.
fn puppet_bench_report(args: &[&str]) -> serde_json::Value {
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["bench", "--json"])
        .args(args)
        .env_remove("MARIONETTE_DATA")
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    serde_json::from_str(String::from_utf8_lossy(&output.stdout).trim()).expect("one JSON object")
}

/// The packed vertices of `n` puppets, as the upload hands them on.
fn puppet_vertex_bytes(n: usize) -> usize {
    n * marionette::formats::puppet::embedded_puppet().vertex_count() * marionette::scene::upload::SKIN_VERTEX_BYTES
}

/// `marionette bench --json` runs a small crowd through the app and the render world
/// (puppets: no data folder) and reports every figure the issue asks for.
#[test]
fn bench_reports_a_crowds_frame_times_as_json() {
    let report = puppet_bench_report(&["--characters", "3", "--frames", "5"]);
    assert_eq!(report["characters"], 3);
    assert_eq!(report["kind"], "puppet");
    for key in ["frame_ms_p50", "frame_ms_p95", "kernel_mvps", "skin_over_ideal"] {
        let value = report[key].as_f64().unwrap_or_else(|| panic!("{key} is a number: {report}"));
        assert!(value > 0.0, "{key} = {value}");
    }
    assert!(report["frame_ms_p95"].as_f64() >= report["frame_ms_p50"].as_f64());
    // Three swaying puppets re-skin every frame: their packed vertices go to the GPU.
    assert_eq!(report["upload_bytes_per_frame"], puppet_vertex_bytes(3));
    assert_eq!(report["gpu_skinning"], false);
    assert_eq!(report["measured"]["drawn"], true);
}

/// `bench --no-draw` turns the camera off once the renderer is ready: the report says the
/// picture was not drawn, and the crowd is still skinned and handed on every frame.
#[test]
fn bench_without_drawing_still_skins_and_hands_on_the_crowd() {
    let report = puppet_bench_report(&["--characters", "2", "--frames", "4", "--no-draw"]);
    assert_eq!(report["measured"]["drawn"], false);
    assert_eq!(report["upload_bytes_per_frame"], puppet_vertex_bytes(2));
}

/// `bench --data` takes the data folder or the SMPL folder itself, refuses a folder with no
/// SMPL body (it used to bench puppets without a word), and `--puppets` asks for puppets;
/// the JSON says how it was measured and every phase's percentiles.
#[test]
fn bench_finds_the_smpl_bodies_it_is_given_or_says_why_not() {
    use marionette::editor::bench::{CrowdOf, crowd_of};
    let dir = crate::common::scratch("bench-no-smpl");
    let e = crowd_of(Some(dir.clone()), false).unwrap_err();
    assert!(e.starts_with(&format!("{}: expected the data folder", dir.display())) && e.contains("--puppets"), "{e}");
    assert_eq!(crowd_of(Some(dir), true), Ok(CrowdOf::Puppets));
    if let Some(data) = crate::common::optional_data_dir() {
        let smpl = data.join("smpl");
        assert_eq!(crowd_of(Some(data), false), Ok(CrowdOf::Smpl(smpl.clone())));
        assert_eq!(crowd_of(Some(smpl.clone()), false), Ok(CrowdOf::Smpl(smpl)));
    }
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["bench", "--characters", "1", "--frames", "2", "--json", "--data", "/"])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1));
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["bench", "--characters", "1", "--frames", "2", "--json", "--puppets"])
        .output()
        .unwrap();
    let report: serde_json::Value = serde_json::from_str(String::from_utf8_lossy(&output.stdout).trim()).unwrap();
    assert_eq!(report["kind"], "puppet");
    assert!(report["measured"]["cores"].as_u64() >= Some(1));
    assert_eq!(report["measured"]["pipelined_rendering"], false);
    let level = format!("{:?}", marionette::rig::simd::Simd::best());
    assert_eq!(report["measured"]["kernel_level"], level.as_str());
    for phase in ["sampling", "fk", "skin", "extract", "upload", "render_world", "frame"] {
        let p = &report["phases_ms"][phase];
        assert!(p["p95"].as_f64() >= p["p50"].as_f64(), "{phase}: {p}");
    }
}

/// `marionette bench --gpu` skins the crowd by the compute shader: only the palettes go to
/// the GPU each frame (one matrix per joint per puppet).
#[test]
fn bench_with_gpu_skinning_hands_on_only_palettes() {
    let report = puppet_bench_report(&["--characters", "3", "--frames", "5", "--gpu"]);
    assert_eq!(report["gpu_skinning"], true);
    let puppet = marionette::formats::puppet::embedded_puppet();
    assert_eq!(report["upload_bytes_per_frame"], 3 * puppet.skeleton.len() * 64);
}

/// Crowds: every member in its own place on the grid; SMPL members each with their own
/// shape and a clip, every third blending a second.
#[test]
fn crowd_members_stand_apart_with_their_own_shape_and_clip() {
    let doc = marionette::document::crowd::puppet_crowd(10);
    let places: Vec<_> = doc.characters.iter().map(|c| c.placement.translation).collect();
    for (i, a) in places.iter().enumerate() {
        for b in &places[i + 1..] {
            assert!(a.distance(*b) >= 0.79, "{a} and {b} overlap");
        }
    }
    if let Some(data) = crate::common::optional_data_dir() {
        let crowd = marionette::document::crowd::smpl_crowd(&data.join("smpl"), 6).unwrap();
        let smpl: Vec<_> = crowd.characters.iter().map(|c| c.smpl.clone().unwrap()).collect();
        assert!(smpl.iter().all(|s| s.playing && s.clip.is_some()));
        assert_ne!(smpl[0].betas, smpl[1].betas);
        assert_eq!(smpl.iter().filter(|s| s.blend_clip.is_some()).count(), 2);
    }
}

/// The extent of the warm (skin-tinted) pixels of a render, as fractions of the picture's
/// width and height: sky and floor are blue-grey, the default tint is warm.
fn silhouette_extent(png: &std::path::Path) -> (f32, f32) {
    let img = image::open(png).unwrap().to_rgb8();
    let (w, h) = img.dimensions();
    let (mut lo, mut hi) = ((w, h), (0, 0));
    for (x, y, p) in img.enumerate_pixels() {
        let [r, _, b] = p.0;
        if r as i32 - b as i32 > 30 {
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
    }
    if hi.0 < lo.0 {
        return (0.0, 0.0);
    }
    ((hi.0 - lo.0 + 1) as f32 / w as f32, (hi.1 - lo.1 + 1) as f32 / h as f32)
}

/// `render` without a saved camera frames what it loaded: the silhouette's larger side
/// covers at least 60 % of the picture (the dragon used to fill a quarter of its width).
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn render_frames_the_characters_to_fill_the_picture() {
    let data = data_dir();
    for file in ["cse169/project1/dragon.skel", "mit6837/Model1.skel"] {
        let out = scratch("render-framing").join("framed.png");
        let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
            .args(["render", "--width", "320", "--height", "200", "--out"])
            .arg(&out)
            .arg(data.join(file))
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        let (w, h) = silhouette_extent(&out);
        eprintln!("{file}: silhouette {:.0} % × {:.0} % of the picture", w * 100.0, h * 100.0);
        assert!(w.max(h) >= 0.6, "{file}: the silhouette covers {w:.2} × {h:.2}");
        assert!(w < 1.0 && h < 1.0, "{file}: the silhouette is cut off ({w:.2} × {h:.2})");
    }
}

/// Floor and grid reach twice as far as the farthest character (at least 10 m), on a round
/// spacing with at most 20 lines a side.
#[test]
fn the_stage_grows_with_the_scene() {
    use marionette::editor::present::stage::StageExtent;
    assert_eq!(StageExtent::reaching(0.0), StageExtent { half: 10.0, step: 0.5 });
    assert_eq!(StageExtent::reaching(3.0), StageExtent { half: 10.0, step: 0.5 });
    for reach in [6.0, 31.0, 250.0, 4000.0] {
        let e = StageExtent::reaching(reach);
        assert_eq!(e.half, 2.0 * reach);
        assert!(e.half / e.step <= 20.0 && e.half / e.step >= 4.0, "{e:?}");
        let mantissa = e.step / 10f32.powf(e.step.log10().floor());
        assert!([1.0, 2.0, 5.0].iter().any(|m| (mantissa - m).abs() < 1e-3), "{e:?}");
    }
}

/// The sun's shadows reach across the whole stage from wherever framing puts the camera,
/// at any scale: Bevy's own cascades for a camera framing people, scaled with a farther one.
/// (With Bevy's defaults at every distance, a model 155 units long, as the Khronos fox is,
/// cast a shadow only within 150 units of the camera.)
#[test]
fn the_suns_shadows_reach_across_the_stage() {
    use bevy::light::CascadeShadowConfigBuilder;
    use bevy::math::Vec3;
    use marionette::editor::present::stage::{StageExtent, sun_shadow_cascades};
    use marionette::editor::state::camera::OrbitCamera;
    let people = CascadeShadowConfigBuilder::default().build();
    for reach in [0.9, 5.0, 80.0, 4000.0] {
        // A model `reach` long either side of the origin and as tall, framed 16:9.
        let (lo, hi) = (Vec3::new(-reach, 0.0, -reach / 4.0), Vec3::new(reach, reach, reach / 4.0));
        let camera = OrbitCamera::framing(lo, hi, 16.0 / 9.0);
        let farthest_floor = camera.distance + StageExtent::reaching(reach).half * std::f32::consts::SQRT_2;
        let cascades = sun_shadow_cascades(camera.distance);
        let reached = *cascades.bounds.last().unwrap();
        assert!(reached >= farthest_floor, "reach {reach}: shadows to {reached}, the floor to {farthest_floor}");
        assert!(cascades.bounds.windows(2).all(|b| b[0] < b[1]), "{:?}", cascades.bounds);
        if reach < 2.0 {
            // A person: Bevy's own cascades, however large the floor is made.
            assert_eq!(cascades.bounds, people.bounds, "camera {}", camera.distance);
        }
    }
}

/// Recent files: the newest first, once each, at most eight, kept whole in a file (its
/// folder made) and read back; a missing file is an empty list.
#[test]
fn recent_files_are_kept_newest_first_and_read_back() {
    use marionette::editor::ui::recent::{KEPT, read_recent, remember, write_recent};
    let file = crate::common::scratch("recent").join("config/marionette/recent.txt");
    assert!(read_recent(&file).is_empty());
    let mut recent = Vec::new();
    for i in 0..10 {
        remember(&mut recent, &format!("/data/model{i}.skel"));
    }
    remember(&mut recent, "/data/model5.skel");
    assert_eq!(recent.len(), KEPT);
    assert_eq!(recent[0], "/data/model5.skel");
    assert_eq!(recent.iter().filter(|r| *r == "/data/model5.skel").count(), 1);
    assert_eq!(recent[1], "/data/model9.skel");
    write_recent(&file, &recent).unwrap();
    assert_eq!(read_recent(&file), recent);
}

/// Materials reach the picture: the Blender pair's walker drawn with its checker also as
/// its normal map (the file changed here) differs from the plain walker where the walker
/// is, and nowhere else (the normal map bends the flat normals; the waver, the floor and the
/// sky stay as they were); the same map at scale −1 bends it the other way.
#[test]
fn a_normal_map_bends_the_light_on_its_surface_only() {
    let dir = scratch("render-normal-map");
    let pair = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender_pair.glb");
    let glb = std::fs::read(&pair).unwrap();
    let with_normal_map = |scale: f32, name: &str| {
        let bumpy = crate::common::glb_with_json(&glb, |json| {
            json["materials"][0]["normalTexture"] = serde_json::json!({ "index": 0, "scale": scale });
        });
        std::fs::write(dir.join(name), bumpy).unwrap();
    };
    with_normal_map(1.0, "bumpy.glb");
    with_normal_map(-1.0, "turned.glb");
    let render = |input: &std::path::Path, name: &str| {
        let out = dir.join(name);
        let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
            .args(["render", "--width", "160", "--height", "120", "--out"])
            .arg(&out)
            .arg(input)
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        image::open(&out).unwrap().to_rgb8()
    };
    let (plain, bumpy) = (render(&pair, "plain.png"), render(&dir.join("bumpy.glb"), "bumpy.png"));
    let changed: Vec<(u32, u32)> = plain
        .enumerate_pixels()
        .filter(|(x, y, p)| p.0.iter().zip(bumpy.get_pixel(*x, *y).0).any(|(a, b)| a.abs_diff(b) > 8))
        .map(|(x, y, _)| (x, y))
        .collect();
    assert!(changed.len() > 100, "the normal map changed {} pixels", changed.len());
    // The walker stands on the left half of the picture; the waver on the right.
    assert!(changed.iter().all(|&(x, _)| x < 80), "changed beyond the walker: {:?}", changed.iter().max());
    // The map's scale multiplies its x and y: at -1 they turn the other way.
    let turned = render(&dir.join("turned.glb"), "turned.png");
    let differ =
        bumpy.pixels().zip(turned.pixels()).filter(|(a, b)| a.0.iter().zip(b.0).any(|(a, b)| a.abs_diff(b) > 8));
    assert!(differ.count() > 50, "the map's scale is not applied");
}

/// `render --from 0 --to 1 --fps 10` writes 11 numbered pictures, each of its time: the
/// puppet raising an arm under a fixed camera, every picture differing from the one before,
/// and frame 7 as `render --time 0.7` draws it.
#[test]
fn a_frame_sequence_writes_one_picture_per_frame_at_its_time() {
    use marionette::formats::scene::{AnimDoc, CameraDoc, CharacterDoc, SceneDoc, SourceDoc};
    use marionette::rig::anim::{Channel, Clip, Extrapolation, Key, Tangent};
    let dir = scratch("render-frames");
    let puppet = marionette::formats::puppet::embedded_puppet();
    let shoulder = puppet.skeleton.find("r_shoulder").unwrap();
    let key = |time, value| Key { time, value, tangent_in: Tangent::Linear, tangent_out: Tangent::Linear };
    let mut clip = Clip::empty(puppet.skeleton.len());
    clip.channels[Clip::joint_channel(shoulder, 2)] =
        Channel::new(vec![key(0.0, 0.0), key(1.0, -2.0)], Extrapolation::Constant, Extrapolation::Constant);
    let anim = AnimDoc { keys: Some(clip), ..AnimDoc::default() };
    let character = CharacterDoc { anim: Some(anim), ..CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "p") };
    let camera = CameraDoc {
        focus: glam::Vec3::new(0.0, 0.7, 0.0),
        yaw: 0.0,
        pitch: -0.1,
        distance: 2.2,
        ..CameraDoc::default()
    };
    let doc = SceneDoc { characters: vec![character], camera: Some(camera), ..SceneDoc::default() };
    let scene = dir.join("arm.ron");
    marionette::document::scenes::write_scene(&scene, &doc).unwrap();
    let render = |extra: &[&str], out: &std::path::Path| {
        let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
            .args(["render", "--width", "64", "--height", "48"])
            .args(extra)
            .arg("--out")
            .arg(out)
            .arg(&scene)
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        String::from_utf8_lossy(&output.stderr).into_owned()
    };
    let said = render(&["--from", "0", "--to", "1", "--fps", "10"], &dir.join("frame_%04d.png"));
    // After the first picture, each is captured in the frame its pose is drawn in (a frame
    // more where the encoding of earlier pictures holds it back), not after three ready
    // frames and a readback as before.
    let per_picture: f64 = said
        .lines()
        .find_map(|l| l.strip_suffix(" frames a picture")?.rsplit(", ").next()?.parse().ok())
        .unwrap_or_else(|| panic!("render reports its frames a picture: {said}"));
    assert!(per_picture < 2.0, "{per_picture} frames a picture");
    let mut names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.retain(|n| n.starts_with("frame_"));
    names.sort();
    let expected: Vec<String> = (0..=10).map(|k| format!("frame_{k:04}.png")).collect();
    assert_eq!(names, expected);
    let picture = |name: &str| image::open(dir.join(name)).unwrap().to_rgb8();
    let differing = |a: &image::RgbImage, b: &image::RgbImage| {
        a.pixels().zip(b.pixels()).filter(|(p, q)| p.0.iter().zip(q.0).any(|(x, y)| x.abs_diff(y) > 8)).count()
    };
    for pair in expected.windows(2) {
        assert!(differing(&picture(&pair[0]), &picture(&pair[1])) > 0, "{} and {} are alike", pair[0], pair[1]);
    }
    render(&["--time", "0.7"], &dir.join("single.png"));
    let at = differing(&picture("frame_0007.png"), &picture("single.png"));
    assert!(at < 10, "frame 7 differs from the picture at 0.7 s in {at} pixels");
}

/// The compute workers' start callback pins the k-th thread to the k-th core the process
/// may run on, wrapping round, and leaves the thread that made it unpinned.
#[cfg(target_os = "linux")]
#[test]
fn compute_workers_are_pinned_one_to_a_core_in_turn() {
    use marionette::editor::cores::{allowed_cores, pin_each_worker_to_a_core};
    let cores = allowed_cores();
    assert!(!cores.is_empty() && cores.is_sorted(), "{cores:?}");
    let Some(pin) = pin_each_worker_to_a_core() else {
        assert_eq!(cores.len(), 1, "only a single core goes unpinned");
        return;
    };
    for k in 0..cores.len() + 1 {
        let pin = pin.clone();
        let own = std::thread::spawn(move || {
            pin();
            allowed_cores()
        });
        assert_eq!(own.join().unwrap(), vec![cores[k % cores.len()]], "thread {k}");
    }
    assert_eq!(allowed_cores(), cores, "the caller keeps every core");
}

/// The skin phase's ideal: the crowd's vertices at the kernel's speed on every core, on as
/// many cores as the phase has tasks (one a character, one a chunk of a larger one).
#[test]
fn the_skin_phases_ideal_uses_only_the_cores_it_has_tasks_for() {
    use marionette::editor::bench::ideal_skin_ms;
    let chunk = marionette::scene::systems::SKIN_CHUNK_VERTICES;
    // 64 SMPL bodies at 500 M vertices/s on two cores: 440,960 ÷ 1e9 s.
    assert!((ideal_skin_ms(64, 6890, 500.0, 2) - 0.44096).abs() < 1e-9);
    // One body is one task: one core, however many there are.
    assert!((ideal_skin_ms(1, 6890, 500.0, 2) - 0.01378).abs() < 1e-9);
    // One body of two chunks is two tasks (in ms: vertices ÷ 1e9 per second × 1e3).
    assert!((ideal_skin_ms(1, 2 * chunk, 500.0, 8) - (2 * chunk) as f64 / 1e6).abs() < 1e-9);
}

/// The frames an app asked for (`RequestRedraw`), counted at the start of each update.
#[derive(bevy::prelude::Resource, Default)]
struct Asked(usize);

fn count(
    mut asked: bevy::prelude::ResMut<Asked>,
    mut redraws: bevy::prelude::MessageReader<bevy::window::RequestRedraw>,
) {
    asked.0 += redraws.read().count();
}

/// The editor draws on change: with nothing playing it asks for no frame; a playing clip
/// asks for one every frame while it plays, and none once paused (the window's own events,
/// input among them, wake Bevy's reactive loop without asking).
#[test]
fn the_editor_asks_for_frames_only_while_something_moves() {
    use bevy::prelude::*;
    use bevy::window::RequestRedraw;
    use marionette::editor::present::redraw::{DrawMode, RedrawPlugin};
    use marionette::scene::keyframes::ClipPlayer;

    let mut app = App::new();
    app.add_plugins(MinimalPlugins)
        .add_message::<RequestRedraw>()
        .add_plugins((marionette::scene::RigCorePlugin, marionette::scene::PlaybackPlugin, RedrawPlugin))
        .init_resource::<Asked>()
        .add_systems(First, count);
    let state = marionette::formats::scene::AnimDoc { playing: false, ..Default::default() };
    let clip = std::sync::Arc::new(marionette::rig::anim::Clip::empty(1));
    let player = app.world_mut().spawn(ClipPlayer { clip, state }).id();
    // Asked between the first update and the last one of `n` more (each frame's asking is
    // counted at the start of the next).
    let asked_over = |app: &mut App, n: usize| {
        app.update();
        let before = app.world().resource::<Asked>().0;
        (0..n).for_each(|_| app.update());
        app.world().resource::<Asked>().0 - before
    };
    assert_eq!(asked_over(&mut app, 10), 0, "idle: no frame asked for");
    assert_eq!(app.world().resource::<DrawMode>().0, None);
    app.world_mut().get_mut::<ClipPlayer>(player).unwrap().state.playing = true;
    assert_eq!(asked_over(&mut app, 10), 10, "a playing clip asks for every frame");
    assert_eq!(app.world().resource::<DrawMode>().0, Some("playing"));
    app.world_mut().get_mut::<ClipPlayer>(player).unwrap().state.playing = false;
    app.update();
    assert_eq!(asked_over(&mut app, 10), 0, "paused: idle again");
}

/// The fast viewport draws fast only while the view is worked (and for a moment after),
/// at the scale's share of each side of the viewport, at least a pixel.
#[test]
fn the_fast_viewport_is_fast_only_while_the_view_is_worked() {
    use marionette::editor::present::fast_viewport::{SETTLE, fast_size, fast_wanted};
    use std::time::Duration;
    assert!(fast_wanted(true, Some(Duration::from_millis(10))));
    assert!(!fast_wanted(true, Some(SETTLE)), "still for the settling time: full quality");
    assert!(!fast_wanted(true, None), "never worked");
    assert!(!fast_wanted(false, Some(Duration::ZERO)), "switched off");
    assert_eq!(fast_size(bevy::math::UVec2::new(1000, 800), 0.4), bevy::math::UVec2::new(400, 320));
    assert_eq!(fast_size(bevy::math::UVec2::new(1, 1), 0.25), bevy::math::UVec2::ONE);
}

/// "Render frames…" renders in the editor's own process, on a thread, through the same
/// render as `marionette render --from --to --fps`: every frame written, the progress
/// counted, the scene set aside removed.
#[test]
fn the_editor_renders_frames_in_its_own_process() {
    use marionette::document::annotate::canny::Canny;
    use marionette::editor::present::data::ControlNetChoice;
    use marionette::editor::present::frames_job::{FramesJob, FramesRequest};
    use marionette::formats::scene::{CharacterDoc, SceneDoc, ShotDoc, SourceDoc};
    let dir = scratch("frames-in-process");
    let puppet = CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "p");
    let doc = SceneDoc {
        characters: vec![puppet],
        shot: ShotDoc { width: 64, height: 48, samples: 1, ..ShotDoc::default() },
        ..SceneDoc::default()
    };
    let pattern = dir.join("f_%02d.png").display().to_string();
    let request = FramesRequest {
        from: 0.0,
        to: 0.25,
        fps: 4.0,
        turntable: None,
        pattern,
        with_data: false,
        controlnet: ControlNetChoice { on: true, canny: true, thresholds: Canny { low: 50.0, high: 150.0 } },
    };
    let mut job = FramesJob::default();
    job.request = request;
    job.start(&doc).unwrap();
    assert!(job.running());
    let started = std::time::Instant::now();
    let ended = loop {
        if let Some(ended) = job.finished() {
            break ended;
        }
        assert!(started.elapsed().as_secs() < 240, "the frames took over 240 s");
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    ended.unwrap();
    assert_eq!(job.progress(), (2, 2));
    for n in 0..2 {
        let picture = image::open(dir.join(format!("f_{n:02}.png"))).unwrap();
        assert_eq!((picture.width(), picture.height()), (64, 48));
        let openpose = image::open(dir.join(format!("f_{n:02}.cn-openpose.png"))).unwrap();
        assert_eq!((openpose.width(), openpose.height()), (64, 48), "the ControlNet maps asked for");
        let canny = image::open(dir.join(format!("f_{n:02}.cn-canny.png"))).unwrap();
        assert_eq!((canny.width(), canny.height()), (64, 48), "the canny edges asked for");
    }
    assert!(!job.running());
}

/// The ControlNet map over the view is worked out only when what it shows changes: once
/// when switched on, not again while nothing moves (no frame asked for either), again for
/// a pose edit, another map, the camera moved; switched off, never.
#[test]
fn the_controlnet_overlay_is_worked_out_only_on_change() {
    use bevy::prelude::*;
    use bevy::window::{PrimaryWindow, RequestRedraw};
    use marionette::editor::edits::commands::Edit;
    use marionette::editor::edits::kinds;
    use marionette::editor::interact::pointer::ViewportArea;
    use marionette::editor::state::camera::OrbitCamera;
    use marionette::editor::ui::conditioning::{ConditioningMap, ConditioningOverlay, work_out_the_overlay_on_change};
    use marionette::formats::scene::CharacterId;

    let mut app = crate::edits::scene_app();
    app.add_message::<RequestRedraw>()
        .init_resource::<Asked>()
        .init_resource::<ConditioningOverlay>()
        .insert_resource(ViewportArea(Some(Rect::new(0.0, 0.0, 320.0, 240.0))))
        .add_systems(First, count)
        .add_systems(PostUpdate, work_out_the_overlay_on_change.after(marionette::scene::MarionetteSystems::Draw));
    app.world_mut().spawn((Window::default(), PrimaryWindow));
    let orbit = app.world_mut().spawn(OrbitCamera::default()).id();
    crate::edits::open_puppets(&mut app, &[Some(1), Some(2)]);
    let drawn = |app: &App| app.world().resource::<ConditioningOverlay>().drawn;
    // Times worked out and frames asked for over `n` updates.
    let over = |app: &mut App, n: usize| {
        let before = (drawn(app), app.world().resource::<Asked>().0);
        (0..n).for_each(|_| app.update());
        app.update(); // the last update's ask is counted at the start of the next
        (drawn(app) - before.0, app.world().resource::<Asked>().0 - before.1)
    };
    assert_eq!(over(&mut app, 5), (0, 0), "off: never worked out");

    app.world_mut().resource_mut::<ConditioningOverlay>().map = Some(ConditioningMap::OpenPose);
    assert_eq!(over(&mut app, 1), (1, 1), "switched on: once, and a frame to show it");
    assert_eq!(over(&mut app, 10), (0, 0), "nothing moves: not again, no frame asked for");

    let elbow = crate::edits::joint(&app, 1, "l_elbow");
    let turn = marionette::rig::JointRotation::euler_xyz(0.0, 0.0, 70f32.to_radians());
    let pose = Edit::from(kinds::Pose { character: CharacterId(1), joints: vec![(elbow, turn)] });
    app.world_mut().resource_mut::<marionette::editor::edits::commands::EditQueue>().push(pose);
    assert_eq!(over(&mut app, 1), (1, 1), "a pose edit: once more");
    assert_eq!(over(&mut app, 5), (0, 0));

    app.world_mut().resource_mut::<ConditioningOverlay>().map = Some(ConditioningMap::Depth);
    assert_eq!(over(&mut app, 3).0, 1, "another map: once");
    app.world_mut().get_mut::<OrbitCamera>(orbit).unwrap().0.yaw += 10.0;
    assert_eq!(over(&mut app, 3).0, 1, "the camera moved: once");

    app.world_mut().resource_mut::<ConditioningOverlay>().map = None;
    assert_eq!(over(&mut app, 5), (0, 0), "switched off: never");
    assert_eq!(app.world().resource::<ConditioningOverlay>().texture(), None);
}

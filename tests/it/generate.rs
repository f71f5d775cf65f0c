//! `marionette generate`: a data set rendered whole (one, three and four scenes a frame) and as
//! four shards (two by `--shard`, one as a Slurm array task, one as a Kubernetes Indexed
//! Job's) gives the same files; a
//! run killed halfway and started again finishes them, rendering only what was missing;
//! `--merge` joins the pictures' COCO files; spec errors stop it before anything renders.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use crate::common::scratch;

/// The example spec made small: `count` pictures of 96×72 with their data.
fn small_spec(dir: &Path, count: usize) -> std::path::PathBuf {
    let example = marionette::document::generate::EXAMPLE
        .replacen("count: 16", &format!("count: {count}"), 1)
        .replacen("width: 320", "width: 96", 1)
        .replacen("height: 240", "height: 72", 1);
    let spec = dir.join("spec.ron");
    std::fs::write(&spec, example).unwrap();
    spec
}

fn generate(spec: &Path, out: &Path, extra: &[&str], env: &[(&str, &str)]) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .arg("generate")
        .arg(spec)
        .arg("--out")
        .arg(out)
        .args(extra)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("JOB_COMPLETION_INDEX")
        .envs(env.iter().copied())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(output.status.success(), "{stderr}");
    stderr
}

/// Every picture's files (not the manifests) by name, with their digests.
fn files(dir: &Path) -> BTreeMap<String, String> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('0') && !n.contains(".tmp"))
        .map(|n| (n.clone(), marionette::document::generate::sha256_of(&dir.join(&n)).unwrap()))
        .collect()
}

#[test]
fn a_data_set_is_the_same_whole_as_in_shards_and_resumed() {
    let dir = scratch("generate");
    let spec = small_spec(&dir, 8);
    let whole = dir.join("whole");
    generate(&spec, &whole, &[], &[]);
    let expected = files(&whole);
    assert_eq!(expected.keys().filter(|n| n.ends_with(".png") && n.len() == 10).count(), 8, "{expected:?}");
    for stem in ["000000", "000007"] {
        for tail in [".png", ".json", ".scene.ron", ".depth.exr", ".mask.png", ".openpose.json"] {
            assert!(expected.contains_key(&format!("{stem}{tail}")), "{stem}{tail}");
        }
    }

    // Three and four scenes a frame (of 8 pictures: the last frame of three draws two) draw
    // the files of the whole run, which drew one a frame (the default on the CPU).
    for n in ["3", "4"] {
        let shared = dir.join(format!("scenes-a-frame-{n}"));
        let said = generate(&spec, &shared, &["--scenes-a-frame", n], &[]);
        assert_eq!(files(&shared), expected, "{n} scenes a frame give the files of one:\n{said}");
    }

    let shards = dir.join("shards");
    generate(&spec, &shards, &["--shard", "0/4"], &[]);
    generate(&spec, &shards, &["--shard", "1/4"], &[]);
    let slurm = generate(&spec, &shards, &[], &[("SLURM_ARRAY_TASK_ID", "2"), ("SLURM_ARRAY_TASK_COUNT", "4")]);
    assert!(slurm.contains("shard 2/4: 2 pictures"), "{slurm}");
    let kube = generate(&spec, &shards, &["--shards", "4"], &[("JOB_COMPLETION_INDEX", "3")]);
    assert!(kube.contains("shard 3/4: 2 pictures"), "{kube}");
    assert_eq!(files(&shards), expected, "four shards give the files of the whole");

    // Killed once some pictures are in its manifest, then started again.
    let resumed = dir.join("resumed");
    let mut child = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .arg("generate")
        .arg(&spec)
        .arg("--out")
        .arg(&resumed)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let manifest = resumed.join("manifest-0000-of-0001.jsonl");
    let lines = || std::fs::read_to_string(&manifest).map_or(0, |t| t.lines().count());
    let started = std::time::Instant::now();
    while lines() < 3 && started.elapsed().as_secs() < 240 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let done = lines();
    assert!((3..8).contains(&done), "killed with {done} of 8 pictures in the manifest");
    let again = generate(&spec, &resumed, &[], &[]);
    let rest = 8 - done;
    assert!(again.contains(&format!("{done} already there, {rest} to render")), "{again}");
    assert_eq!(files(&resumed), expected, "the resumed run's files are the whole run's");
    let text = std::fs::read_to_string(&manifest).unwrap();
    let mut pictures: Vec<u64> = text
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap()["picture"].as_u64().unwrap())
        .collect();
    pictures.sort();
    assert_eq!(pictures, (0..8).collect::<Vec<_>>(), "each picture recorded once");

    // The shards' COCO files joined: one image per picture, the annotations of each.
    let output =
        Command::new(env!("CARGO_BIN_EXE_marionette")).args(["generate", "--merge"]).arg(&shards).output().unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let coco: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(shards.join("coco.json")).unwrap()).unwrap();
    let ids: Vec<u64> = coco["images"].as_array().unwrap().iter().map(|i| i["id"].as_u64().unwrap()).collect();
    assert_eq!(ids, (1..=8).collect::<Vec<_>>());
    let mut annotation_ids: Vec<u64> =
        coco["annotations"].as_array().unwrap().iter().map(|a| a["id"].as_u64().unwrap()).collect();
    let count = annotation_ids.len();
    annotation_ids.dedup();
    assert!(count >= 8 && annotation_ids.len() == count, "one annotation or more a picture, ids unique");
}

/// A spec that cannot be rendered is refused before any picture: the field named, nothing written.
#[test]
fn spec_errors_stop_generate_before_rendering() {
    let dir = scratch("generate-errors");
    let spec = small_spec(&dir, 4);
    let text = std::fs::read_to_string(&spec).unwrap();
    let cases = [
        (text.replacen("what: Puppet", "what: File(path: \"missing.glb\")", 1), "characters[0].path"),
        (
            text.replacen("presets: [\"default\", \"studio\", \"overcast\", \"dusk\"]", "presets: []", 1),
            "empty distribution",
        ),
        (text.replacen("per_picture: (1, 3)", "per_picture: (1, 30)", 1), "do not fit"),
        (text.replacen("width: 96", "width: 90000", 1), "width"),
        (
            text.replacen("canny: None", "canny: Some((low: 100, high: 200))", 1),
            "canny: the canny edges are a ControlNet map",
        ),
        (
            text.replacen("canny: None,", "canny: None,\n    poses: Some((body: [\"fly\"])),", 1),
            "poses.body[0]: expected one of",
        ),
        (text.replacen("canny: None,", "canny: None,\n    poses: Some((hands: [\"claw\"])),", 1), "poses.hands[0]"),
        (
            text.replacen(
                "canny: None,",
                "canny: None,\n    tint: Some((Uniform(1.0, 0.0), Fixed(1.0), Fixed(1.0))),",
                1,
            ),
            "tint.0: an empty distribution",
        ),
        (text.replacen("count: 4", "count: 4,\n    colour: 3", 1), "spec.ron:"),
    ];
    for (bad, words) in cases {
        std::fs::write(&spec, bad).unwrap();
        let out = dir.join("out");
        let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
            .arg("generate")
            .arg(&spec)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success() && stderr.contains(words), "{words}: {stderr}");
        assert!(!out.exists(), "{words}: nothing written");
    }
    std::fs::write(&spec, &text).unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .arg("generate")
        .arg(&spec)
        .args(["--count", "20000000", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && stderr.contains("--count: expected 1 to 10000000 pictures, found 20000000"),
        "{stderr}"
    );
}

/// Digests of the tars in `dir`, by name.
fn tars(dir: &Path) -> BTreeMap<String, String> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tar"))
        .map(|n| (n.clone(), marionette::document::generate::sha256_of(&dir.join(&n)).unwrap()))
        .collect()
}

/// Streams the tars of `set` with the Python `webdataset` package against `folder`
/// (scripts/check_webdataset.py); what it printed.
fn stream(set: &Path, folder: &Path) -> String {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/check_webdataset.py");
    let output = Command::new("python3")
        .arg(script)
        .arg(set)
        .arg(folder)
        .output()
        .expect("python3 with webdataset (scripts/ensure-tools.sh installs it)");
    let said = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(output.status.success(), "{said}{}", String::from_utf8_lossy(&output.stderr));
    said
}

/// `--format webdataset`: tars of `--shard-size` pictures that the `webdataset` package
/// streams as the folder form's files, byte for byte; a tar lost and the run started again
/// comes back the same; split over two shards, the same samples; `--merge` reads the tars.
#[test]
fn a_webdataset_set_streams_as_the_folder_form_and_comes_back_the_same() {
    let dir = scratch("webdataset");
    let spec = small_spec(&dir, 8);
    let folder = dir.join("folder");
    generate(&spec, &folder, &[], &[]);
    let set = dir.join("set");
    let webdataset = ["--format", "webdataset", "--shard-size", "3"];
    generate(&spec, &set, &webdataset, &[]);
    let written = tars(&set);
    let names: Vec<&str> = written.keys().map(String::as_str).collect();
    assert_eq!(names, ["set-000000-000000.tar", "set-000000-000001.tar", "set-000000-000002.tar"]);
    assert!(files(&set).is_empty(), "no loose picture files left: {:?}", files(&set));
    assert_eq!(stream(&set, &folder).trim(), "8 samples");

    // The last tar lost (a run killed before it was written whole), then the run again.
    std::fs::remove_file(set.join("set-000000-000002.tar")).unwrap();
    let again = generate(&spec, &set, &webdataset, &[]);
    assert!(again.contains("6 already there, 2 to render"), "{again}");
    assert_eq!(tars(&set), written, "the same tars, byte for byte");

    let split = dir.join("split");
    generate(&spec, &split, &[&webdataset[..], &["--shard", "0/2"]].concat(), &[]);
    generate(&spec, &split, &[&webdataset[..], &["--shard", "1/2"]].concat(), &[]);
    assert_eq!(tars(&split).len(), 4, "two tars a shard: {:?}", tars(&split));
    assert_eq!(stream(&split, &folder).trim(), "8 samples");

    let output =
        Command::new(env!("CARGO_BIN_EXE_marionette")).args(["generate", "--merge"]).arg(&set).output().unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let coco: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(set.join("coco.json")).unwrap()).unwrap();
    assert_eq!(coco["images"].as_array().unwrap().len(), 8);
}

/// `--seed S` draws every picture from S in place of the spec's seed: the same as a spec
/// that says S, another picture than the spec's own seed gives.
#[test]
fn seed_overrides_the_specs_seed() {
    let dir = scratch("seed");
    let spec = small_spec(&dir, 1);
    let text = std::fs::read_to_string(&spec).unwrap();
    assert!(text.contains("seed: 1,"), "the example's seed");
    let reseeded = dir.join("reseeded.ron");
    std::fs::write(&reseeded, text.replacen("seed: 1,", "seed: 7,", 1)).unwrap();
    let scenes = |spec: &Path, extra: &[&str]| {
        let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
            .arg("generate")
            .arg(spec)
            .args(["--out", dir.join("unused").to_str().unwrap(), "--dry-run"])
            .args(extra)
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        String::from_utf8_lossy(&output.stdout).into_owned()
    };
    let by_flag = scenes(&spec, &["--seed", "7"]);
    assert_eq!(by_flag, scenes(&reseeded, &[]), "--seed 7 is the spec's seed: 7");
    assert_ne!(by_flag, scenes(&spec, &[]), "another seed, another picture");
}

/// `controlnet: true` in a spec writes the maps ControlNet reads beside each picture, as
/// `render --controlnet` does.
#[test]
fn a_spec_asks_for_the_controlnet_maps() {
    let dir = scratch("generate-controlnet");
    let spec = small_spec(&dir, 2);
    let text = std::fs::read_to_string(&spec).unwrap().replacen("controlnet: false", "controlnet: true", 1).replacen(
        "canny: None",
        "canny: Some((low: 100, high: 200))",
        1,
    );
    std::fs::write(&spec, text).unwrap();
    let out = dir.join("set");
    generate(&spec, &out, &[], &[]);
    for stem in ["000000", "000001"] {
        for tail in ["cn-openpose.png", "cn-openpose.json", "cn-depth.png", "cn-normal.png", "cn-canny.png", "json"] {
            assert!(out.join(format!("{stem}.{tail}")).is_file(), "{stem}.{tail}");
        }
    }
}

/// A set's pictures are drawn without waiting frames of their own once the renderer is
/// settled (each checked drawn whole, else drawn again), four scenes a frame: every one
/// equals, byte for byte, `render` of the scene file written beside it, which draws it alone
/// and waits for the renderer to settle.
#[test]
fn a_generated_picture_is_its_scene_rendered_alone() {
    let dir = scratch("generate-alone");
    let spec = small_spec(&dir, 5);
    each_picture_is_its_scene_rendered_alone(&dir, &spec, 5, &["--scenes-a-frame", "4"]);
}

/// Khronos characters, one scene a frame: the second picture drawn brings CesiumMan, the
/// first it shows (its materials take frames of their own); every picture still equals its
/// scene rendered alone.
#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn pictures_of_files_nobody_here_wrote_are_their_scenes_rendered_alone() {
    let dir = scratch("generate-khronos");
    let khronos = crate::common::data_dir().join("khronos").canonicalize().unwrap();
    let who = ["CesiumMan", "RiggedFigure"]
        .map(|m| format!("(what: File(path: {:?}), weight: 1.0),", khronos.join(format!("{m}.glb"))))
        .join(" ");
    let example = marionette::document::generate::EXAMPLE.replacen("count: 16", "count: 8", 1).replacen(
        "(what: Puppet, weight: 1.0),",
        &who,
        1,
    );
    let spec = dir.join("spec.ron");
    std::fs::write(&spec, example).unwrap();
    each_picture_is_its_scene_rendered_alone(&dir, &spec, 8, &["--scenes-a-frame", "1"]);
}

/// Generates `spec` (its `count` pictures) with `extra` and renders each picture's scene
/// file alone: every picture equals its scene's, byte for byte.
fn each_picture_is_its_scene_rendered_alone(dir: &Path, spec: &Path, count: usize, extra: &[&str]) {
    let out = dir.join("set");
    let said = generate(spec, &out, extra, &[]);
    eprintln!("{said}");
    for k in 0..count {
        let stem = format!("{k:06}");
        let alone = dir.join(format!("{stem}.alone.png"));
        let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
            .arg("render")
            .arg(out.join(format!("{stem}.scene.ron")))
            .arg("--out")
            .arg(&alone)
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        let generated = std::fs::read(out.join(format!("{stem}.png"))).unwrap();
        assert!(generated == std::fs::read(&alone).unwrap(), "picture {stem} differs from its scene rendered alone");
    }
}

/// The first picture's scene of the small spec in `dir` with `asked` added to it and three
/// characters a picture, as `--dry-run` prints it (`name` tells the files apart).
fn first_scene_with(dir: &Path, name: &str, asked: &str) -> marionette::formats::scene::SceneDoc {
    let doc = first_scene_of(dir, name, "Puppet", asked);
    assert_eq!(doc.characters.len(), 3);
    doc
}

/// As [`first_scene_with`], the characters of kind `who` (a spec's `Who`).
fn first_scene_of(dir: &Path, name: &str, who: &str, asked: &str) -> marionette::formats::scene::SceneDoc {
    let spec = dir.join(format!("{name}.ron"));
    let text = std::fs::read_to_string(small_spec(dir, 1)).unwrap();
    let text = text.replacen("(what: Puppet, weight: 1.0),", &format!("(what: {who}, weight: 1.0),"), 1);
    let text = text.replacen("canny: None,", &format!("canny: None,\n    {asked}"), 1);
    std::fs::write(&spec, text.replacen("per_picture: (1, 3)", "per_picture: (3, 3)", 1)).unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .arg("generate")
        .arg(&spec)
        .args(["--out", dir.join("unused").to_str().unwrap(), "--dry-run"])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let scene = dir.join(format!("{name}.scene.ron"));
    std::fs::write(&scene, String::from_utf8_lossy(&output.stdout).replacen("// picture 0", "", 1)).unwrap();
    marionette::document::scenes::read_scene(&scene).unwrap()
}

/// `poses:` puts a drawn built-in body pose on every humanoid: the puppets of a spec asking
/// for `sit-chair` have their thighs turned a quarter turn (level) and their knees a
/// quarter turn back (shins down); `t-pose` leaves the legs straight.
#[test]
fn a_spec_poses_its_characters_with_the_body_poses_it_draws() {
    let dir = scratch("generate-poses");
    let legs = |body: &str| {
        let doc = first_scene_with(&dir, body, &format!("poses: Some((body: [\"{body}\"], hands: [\"fist\"])),"));
        let turn = |c: &marionette::formats::scene::CharacterDoc, joint: &str| {
            c.pose.get(joint).map_or(0.0, |r| r.to_quat().angle_between(bevy::math::Quat::IDENTITY).to_degrees())
        };
        let legs = ["l_hip", "r_hip", "l_knee", "r_knee"];
        doc.characters.iter().map(|c| legs.map(|j| (j, turn(c, j)))).collect::<Vec<_>>()
    };
    for (joint, angle) in legs("sit-chair").into_iter().flatten() {
        assert!((angle - 90.0).abs() < 5.0, "sit-chair: {joint} turned {angle:.1}°");
    }
    for (joint, angle) in legs("t-pose").into_iter().flatten() {
        assert!(angle < 10.0, "t-pose: {joint} turned {angle:.1}°");
    }
}

/// `tint:` draws each character's colour: fixed channels give every character that tint.
#[test]
fn a_spec_draws_each_characters_tint() {
    let dir = scratch("generate-tint");
    let doc = first_scene_with(&dir, "tint", "tint: Some((Fixed(0.25), Fixed(0.5), Uniform(0.75, 0.75))),");
    assert!(doc.characters.iter().all(|c| c.view.tint == [0.25, 0.5, 0.75]), "{:?}", doc.characters[0].view.tint);
}

fn rigs() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs")
}

/// `File(path: …, motions: FOLDER)`: each character plays a clip of the folder retargeted
/// onto it, at the drawn time, posed as `--retarget CLIP --time T` poses it; the Mixamo
/// figure and the VRoid avatar, with CMU's and Bandai's walks.
#[test]
fn a_spec_retargets_a_folder_of_clips_onto_character_files() {
    use marionette::document::AssetLibrary;
    let dir = scratch("generate-motions");
    let motions = dir.join("motions");
    std::fs::create_dir_all(&motions).unwrap();
    for clip in ["cmu_walk.bvh", "bandai_walk.bvh"] {
        std::fs::copy(rigs().join(clip), motions.join(clip)).unwrap();
    }
    let mut library = AssetLibrary::default();
    let mut clips_seen = std::collections::BTreeSet::new();
    for rig in ["mixamo.glb", "vroid.glb"] {
        let who = format!("File(path: {:?}, motions: Some(\"motions\"))", rigs().join(rig));
        let doc = first_scene_of(&dir, rig, &who, "");
        for c in &doc.characters {
            let anim = c.anim.as_ref().expect("a clip");
            let Some(marionette::formats::scene::RetargetDoc {
                from: marionette::formats::scene::MotionSourceDoc::File { path, .. },
                ..
            }) = &anim.retarget
            else {
                panic!("{}: not retargeted: {anim:?}", c.name)
            };
            assert!(path.starts_with(&motions), "{}", path.display());
            clips_seen.insert(path.file_name().unwrap().to_owned());
            // Its pose is the walk's at that time, not the rest pose.
            let asset = library.shaped(c).unwrap();
            let (pose, _) = marionette::document::export::still_pose(&mut library, &doc, c, &asset).unwrap();
            let turned = pose.iter().filter(|r| r.to_quat().angle_between(bevy::math::Quat::IDENTITY) > 0.1).count();
            assert!(turned >= 4, "{rig} {}: {turned} joints turned", c.name);
        }
    }
    assert!(!clips_seen.is_empty());
}

/// `poses.blend`: 0 leaves each character in its clip's pose, 1 puts the body pose on whole,
/// and a half turns each joint halfway between (within 1°).
#[test]
fn a_spec_blends_body_poses_with_the_clip() {
    use marionette::document::AssetLibrary;
    let dir = scratch("generate-blend");
    let motions = dir.join("motions");
    std::fs::create_dir_all(&motions).unwrap();
    std::fs::copy(rigs().join("cmu_walk.bvh"), motions.join("cmu_walk.bvh")).unwrap();
    let who = format!("File(path: {:?}, motions: Some(\"motions\"))", rigs().join("mixamo.glb"));
    let mut library = AssetLibrary::default();
    let mut poses = |blend: &str| {
        let asked = format!("poses: Some((body: [\"t-pose\"], blend: Some(Fixed({blend})))),");
        let doc = first_scene_of(&dir, &format!("blend{blend}"), &who, &asked);
        let c = doc.characters[0].clone();
        let asset = library.shaped(&c).unwrap();
        marionette::document::export::still_pose(&mut library, &doc, &c, &asset).unwrap().0
    };
    let (clip, half, whole) = (poses("0.0"), poses("0.5"), poses("1.0"));
    let mut compared = 0;
    for ((a, h), w) in clip.iter().zip(&half).zip(&whole) {
        let (a, h, w) = (a.to_quat(), h.to_quat(), w.to_quat());
        if a.angle_between(w) > 0.2 {
            let off = h.angle_between(a.slerp(w, 0.5)).to_degrees();
            assert!(off < 1.0, "a joint {off:.2}° from halfway");
            compared += 1;
        }
    }
    assert!(compared >= 4, "{compared} joints differ between the clip and the t-pose");
}

/// `props:` stands a prop (an OBJ box) on the floor between the camera and one of the
/// people, as a prop of its own id.
#[test]
fn a_spec_stands_props_between_the_camera_and_the_people() {
    let dir = scratch("generate-props");
    let props = dir.join("props");
    std::fs::create_dir_all(&props).unwrap();
    let corners: Vec<String> = (0..8)
        .map(|k| {
            format!(
                "v {} {} {}",
                0.4 * (k & 1) as f32 - 0.2,
                0.8 * (k >> 1 & 1) as f32,
                0.4 * (k >> 2 & 1) as f32 - 0.2
            )
        })
        .collect();
    let faces = "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6";
    std::fs::write(props.join("box.obj"), format!("{}\n{faces}\n", corners.join("\n"))).unwrap();
    let doc = first_scene_of(&dir, "props", "Puppet", "props: Some((folder: \"props\", per_picture: (2, 2))),");
    assert_eq!(doc.characters.len(), 5);
    let camera = doc.camera.unwrap();
    let eye = camera.eye() * bevy::math::Vec3::new(1.0, 0.0, 1.0);
    let people: Vec<bevy::math::Vec3> = doc.characters[..3].iter().map(|c| c.placement.translation).collect();
    for prop in &doc.characters[3..] {
        assert!(matches!(&prop.source, marionette::formats::scene::SourceDoc::File(p) if p.ends_with("box.obj")));
        let at = prop.placement.translation;
        assert!(at.y.abs() < 1e-4, "on the floor: {at}");
        // On the floor's line from the camera to some person, 40–70 % of the way.
        let on_a_line = people.iter().any(|p| {
            let to = *p * bevy::math::Vec3::new(1.0, 0.0, 1.0) - eye;
            let along = (at - eye).dot(to) / to.length_squared();
            let off = (at - eye - to * along).length();
            (0.35..=0.75).contains(&along) && off < 0.35
        });
        assert!(on_a_line, "{at} is not between the camera {eye} and a person {people:?}");
    }
    let ids: std::collections::BTreeSet<_> = doc.characters.iter().map(|c| c.id).collect();
    assert_eq!(ids.len(), 5, "each its own id");
}

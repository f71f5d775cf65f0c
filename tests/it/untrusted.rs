//! Untrusted files (issue "Untrusted files"): each class of hostile input is refused with
//! its kind and place — never a panic, an abort, a hang, a read outside the model's folder,
//! or a NaN written. The glTF files of `tests/regressions/` are made by
//! `scripts/make_hostile_gltf.py`; those under `tests/regressions/commands/` read fine and
//! are refused by the command that would sample or write them.

use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

use marionette::document::frames::{PictureRequest, Pictures};
use marionette::formats::limits::{MAX_EXCERPT_CHARS, MAX_FILE_BYTES, MAX_SAMPLED_FRAMES};
use marionette::formats::{FormatError, bvh, gltf_import, load_character, load_clip, scene};

use crate::common::scratch;

fn regressions() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regressions")
}

fn marionette(args: &[&std::ffi::OsStr], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_marionette")).args(args).current_dir(dir).output().unwrap()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Runs `f` on its own thread and fails the test if it gives no answer within 5 s (the
/// fuzzer's bound for a hang; not a timing claim).
fn answers<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || tx.send(f()).unwrap());
    rx.recv_timeout(Duration::from_secs(5)).expect("an answer within 5 s (a hang otherwise)")
}

/// Each hostile glTF, with the place and the kind of the error it must give.
const GLTF_CASES: &[(&str, &str)] = &[
    // The gltf crate panicked (exit 101) or overflowed on these.
    (
        "gltf-indices-float.glb",
        "at $.meshes[0].primitives[0].indices: expected an accessor of SCALAR of UNSIGNED_BYTE, SHORT or INT, found $.accessors[1], Scalar of F32",
    ),
    (
        "gltf-joints-float.glb",
        "at $.meshes[0].primitives[0].attributes.JOINTS_0: expected an accessor of VEC4 of UNSIGNED_BYTE or UNSIGNED_SHORT, found $.accessors[2], Vec4 of F32",
    ),
    (
        "gltf-weights-uint.glb",
        "at $.meshes[0].primitives[0].attributes.WEIGHTS_0: expected an accessor of VEC4 of FLOAT or normalised",
    ),
    (
        "gltf-rotation-keys-uint.glb",
        "at $.animations[0].samplers[0].output: expected an accessor of VEC4 of FLOAT or normalised integers, found $.accessors[6], Vec4 of U32",
    ),
    (
        "gltf-position-stride-4.glb",
        "at $.bufferViews[0].byteStride: expected at least the 12 bytes of an element of $.accessors[0], found 4",
    ),
    (
        "gltf-position-vec2.glb",
        "at $.meshes[0].primitives[0].attributes.POSITION: expected an accessor of VEC3 of FLOAT, found $.accessors[0], Vec2 of F32",
    ),
    (
        "gltf-inverse-binds-mat3.glb",
        "at $.skins[0].inverseBindMatrices: expected an accessor of MAT4 of FLOAT, found $.accessors[4], Mat3 of F32",
    ),
    ("gltf-count-zero.glb", "at $.accessors[0].count: expected 1 to 16777216 elements, found 0"),
    ("gltf-count-2-pow-62.glb", "at $.accessors[0].count: expected 1 to 16777216 elements, found 4611686018427387904"),
    (
        "gltf-offset-near-2-pow-64.glb",
        "at $.accessors[0]: expected 3 elements of 12 bytes from byte 18446744073709551608",
    ),
    ("gltf-sparse-count-zero.glb", "at $.accessors[0].sparse.count: expected 1 to the accessor's 3, found 0"),
    ("gltf-header-length-4.glb", "at byte 8: expected a GLB length from 20 to the file's"),
    // Hangs: the nodes above a skeleton are not a tree.
    ("gltf-node-cycle.glb", "expected a tree, found a cycle through node"),
    ("gltf-node-own-child.glb", "at $.nodes[3].children[0]: expected another node, found the node itself"),
    // Files outside the model's folder.
    (
        "gltf-uri-absolute.gltf",
        "at $.buffers[0].uri: expected a path relative to the model's folder, found `/etc/passwd`",
    ),
    (
        "gltf-uri-dotdot.gltf",
        "at $.buffers[0].uri: expected a file inside the model's folder, found `../../../../etc/passwd`, which leaves it",
    ),
    // Numbers nobody can use.
    (
        "gltf-inverse-bind-nan.glb",
        "at $.skins[0].inverseBindMatrices: expected an invertible matrix for joint 1 (`tip`), found numbers that are not finite",
    ),
    (
        "gltf-inverse-bind-singular.glb",
        "at $.skins[0].inverseBindMatrices: expected an invertible matrix for joint 1 (`tip`), found a singular matrix",
    ),
    (
        "gltf-position-inf.glb",
        "at $.meshes[0].primitives[0].attributes.POSITION: expected finite numbers, found vertex 2",
    ),
    (
        "gltf-key-value-nan.glb",
        "at $.animations[0].samplers[1].output: expected finite key values, found an unusable one at value 1",
    ),
    ("gltf-key-time-inf.glb", "at $.animations[0].samplers[0].input: expected finite key times, found inf at key 1"),
    (
        "gltf-rotation-key-zero.glb",
        "at $.animations[0].samplers[0].output: expected finite key values, found an unusable one at value 1 (a rotation that is not zero)",
    ),
    (
        "gltf-node-scale-zero.glb",
        "at $.nodes[2].scale: expected a scale that is not zero on any axis, found [1.0, 0.0, 1.0]",
    ),
    ("gltf-node-translation-inf.glb", "at $.nodes[2].translation: expected finite numbers, found inf"),
    (
        "gltf-node-matrix-singular.glb",
        "at $.nodes[1].matrix: expected an invertible transform, found a singular matrix",
    ),
    (
        "gltf-weight-negative.glb",
        "at $.meshes[0].primitives[0].attributes.WEIGHTS_0: expected weights that are finite and not negative, found -0.5 at vertex 1",
    ),
    (
        "gltf-weight-nan.glb",
        "at $.meshes[0].primitives[0].attributes.WEIGHTS_0: expected weights that are finite and not negative, found NaN at vertex 1",
    ),
    (
        "gltf-normal-nan.glb",
        "at $.meshes[0].primitives[0].attributes.NORMAL: expected finite numbers, found vertex 2's",
    ),
];

#[test]
fn each_hostile_gltf_is_refused_at_its_place() {
    for (file, expected) in GLTF_CASES {
        let path = regressions().join(file);
        let e = answers(move || gltf_import::load_gltf(&path).map(drop)).expect_err(file);
        let message = e.to_string();
        assert!(message.starts_with(&format!("{}: ", regressions().join(file).display())), "{file}: {message}");
        assert!(message.contains(expected), "{file}:\n  said     {message}\n  expected {expected}");
    }
}

#[test]
fn the_valid_base_of_the_hostile_gltf_files_loads() {
    // The clip-length case is the untouched base with a long clip: it reads.
    let characters = gltf_import::load_gltf(&regressions().join("commands/gltf-clip-3e38-seconds.glb")).unwrap();
    assert_eq!(characters[0].asset.skeleton.len(), 2);
    assert_eq!(characters[0].clips[0].duration(), 3e38);
}

/// Each hostile scene, with the field its error names.
const SCENE_CASES: &[(&str, &str)] = &[
    (
        "scene-part-index-2-pow-64.ron",
        "characters[0].source: expected a character index below 65536, found 18446744073709551615",
    ),
    ("scene-anim-keys-nan.ron", "characters[0].anim.keys.channels[0].keys[1]: expected finite numbers"),
    ("scene-anim-range-inf.ron", "characters[0].anim.keys.range: expected two finite times"),
    ("scene-anim-time-nan.ron", "characters[0].anim.time: expected a finite number, found NaN"),
    ("scene-morphs-nan.ron", "characters[0].morphs: expected a finite number, found NaN"),
    ("scene-playback-blend-nan.ron", "characters[0].playback.blend: expected a blend weight in 0..=1, found NaN"),
    ("scene-pose-library-nan.ron", "poses[\"wave\"].joints[\"l_elbow\"]: expected a finite number, found NaN"),
    ("scene-tilt-zero-quaternion.ron", "characters[0].placement.tilt: expected a rotation, found a zero quaternion"),
    ("scene-attached-singular-offset.ron", "characters[1].attached.offset: expected an invertible matrix"),
    ("scene-four-lamps.ron", "stage.lamps: expected at most 3 lamps, found 4"),
    ("scene-sun-elevation-100.ron", "stage.sun.elevation: expected -90 to 90 degrees, found 100"),
    ("scene-camera-fov-0.ron", "camera.fov: expected a field of view of 1 to 170 degrees, found 0"),
    ("scene-shot-samples-9.ron", "shot.samples: expected 1 to 4, found 9"),
    ("scene-shot-too-wide.ron", "shot.width: expected 1 to 4096 pixels at 2 samples, found 8000"),
    ("scene-bookmark-ortho-negative.ron", "bookmarks[\"side\"].ortho: expected a positive finite number, found -2"),
    ("scene-background-colour-2.ron", "stage.background: expected colour parts in 0..=1, found 2"),
    ("scene-view-opacity-nan.ron", "characters[0].view.opacity: expected an opacity in 0..=1, found NaN"),
    ("scene-background-image-empty.ron", "stage.background.path: expected a picture file, found none"),
];

#[test]
fn each_hostile_scene_is_refused_at_its_field() {
    for (file, expected) in SCENE_CASES {
        let path = regressions().join(file);
        let bytes = std::fs::read(&path).unwrap();
        let e = scene::parse_scene(Cursor::new(bytes), &path).expect_err(file);
        assert!(e.to_string().contains(expected), "{file}:\n  said     {e}\n  expected {expected}");
    }
}

#[test]
fn an_smpl_clip_with_a_zero_quaternion_is_refused_at_its_line() {
    let path = regressions().join("smpl-clip-zero-quaternion.txt");
    let bytes = std::fs::read(&path).unwrap();
    let e = marionette::formats::smpl::parse_clip(Cursor::new(bytes), &path, 24).unwrap_err();
    assert!(e.to_string().contains("smpl-clip-zero-quaternion.txt:2: expected a rotation for joint 5"), "{e}");
}

#[test]
fn anim_keys_whose_slopes_overflow_are_refused_at_their_line() {
    let path = regressions().join("cse169-anim-keys-3e38.anim");
    let e = load_clip(&path).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("{}:7: expected a key whose curve stays finite (its value or slope overflows)", path.display())
    );
}

/// `export --animation` writes clips key for key, so clips keyed across 1e30 seconds (or a
/// glTF clip across 3e38) go out as their few keys; a clip whose cycles would need more
/// keys than the limit is refused with the limit's name, writing nothing.
#[test]
fn long_clips_go_out_key_for_key_and_endless_cycles_are_refused_naming_the_limit() {
    let dir = scratch("long-clips");
    let commands = regressions().join("commands");
    let long_gltf = commands.join("gltf-clip-3e38-seconds.glb");
    let out = dir.join("long-gltf.glb");
    let output = marionette(
        &["export".as_ref(), long_gltf.as_os_str(), "--out".as_ref(), out.as_os_str(), "--animation".as_ref()],
        &dir,
    );
    assert!(output.status.success(), "{}", stderr(&output));
    let clips = |p: &Path| marionette::formats::gltf_import::load_gltf(p).unwrap().swap_remove(0).clips;
    assert!(clips(&long_gltf) == clips(&out), "key for key");
    let export = |file: &str| {
        let out = dir.join(format!("{file}.glb"));
        let mut args: Vec<&std::ffi::OsStr> = vec!["export".as_ref()];
        let input = commands.join(file);
        let puppet = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/puppet.skel");
        match file.rsplit('.').next() {
            // A clip file plays on the project's puppet.
            Some("anim") => args.extend([puppet.as_os_str(), "--anim".as_ref(), input.as_os_str()]),
            Some("bvh") => args.extend([input.as_os_str(), "--anim".as_ref(), input.as_os_str()]),
            _ => args.push(input.as_os_str()),
        }
        args.extend(["--out".as_ref(), out.as_os_str(), "--animation".as_ref()]);
        (marionette(&args, &dir), out)
    };
    for file in ["scene-keys-at-0-and-1e30.ron", "anim-range-1e30.anim", "bvh-frame-time-1e30.bvh"] {
        let (output, out) = export(file);
        assert!(output.status.success(), "{file}: {}", stderr(&output));
        let back = marionette::formats::gltf_import::load_gltf(&out).unwrap().swap_remove(0).clips;
        let keys = back[0].tracks.iter().flat_map(|t| t.rotation.iter().map(|r| r.times.len())).max().unwrap_or(0);
        assert!(back[0].duration() >= 1e29 && keys < 100, "{file}: {} s, {keys} keys", back[0].duration());
    }
    let (output, out) = export("anim-cycles-1e30-times.anim");
    let said = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{said}");
    assert!(said.contains("MAX_SAMPLED_FRAMES") && said.contains(&MAX_SAMPLED_FRAMES.to_string()), "{said}");
    assert!(!out.exists(), "wrote {}", out.display());
}

/// Retargetings that cannot be: from a character not in the scene, two characters each
/// playing the other's motion, a file outside every folder that is no character, a rig
/// with no arms, a source clip 3e38 seconds long. Each is refused naming what is wrong, and
/// nothing is written.
#[test]
fn impossible_retargetings_are_refused_and_write_nothing() {
    let dir = scratch("impossible-retargetings");
    let commands = regressions().join("commands");
    let out = dir.join("out.obj");
    let refused = |args: &[&std::ffi::OsStr], says: &str| {
        let mut all: Vec<&std::ffi::OsStr> = vec!["export".as_ref()];
        all.extend_from_slice(args);
        all.extend(["--out".as_ref(), out.as_os_str()]);
        let output = marionette(&all, &dir);
        let said = stderr(&output);
        assert_eq!(output.status.code(), Some(1), "{said}");
        assert!(said.contains(says), "{said}");
        assert!(!out.exists(), "wrote {}", out.display());
    };
    for (file, says) in [
        ("retarget-from-a-missing-character.ron", "#99: expected a character of the scene to take the motion of"),
        ("retarget-cycle.ron", "expected a clip of its own to retarget, found a retargeted one"),
        ("retarget-from-outside.ron", "etc/passwd: expected a character file"),
        ("retarget-from-no-humanoid.ron", "expected both steps and a to have hips and two legs"),
    ] {
        refused(&[commands.join(file).as_os_str()], says);
    }
    let puppet = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/puppet.skel");
    let long = commands.join("gltf-clip-3e38-seconds.glb");
    refused(&[puppet.as_os_str(), "--retarget".as_ref(), long.as_os_str()], "frames at 30 a second to retarget");
}

fn make_fifo(path: &Path) {
    let c = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
    // SAFETY: a valid NUL-terminated path; mkfifo only creates a file.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0, "mkfifo {}", path.display());
}

#[test]
fn fifos_and_devices_are_refused_at_once_as_path_scene_source_and_buffer() {
    let dir = scratch("fifos");
    let fifo = dir.join("motion.bvh");
    make_fifo(&fifo);
    let special = "expected a regular file, found a special file";
    let f = fifo.clone();
    assert!(answers(move || load_clip(&f).unwrap_err().to_string()).contains(special));
    let f = fifo.clone();
    assert!(answers(move || load_character(&f).unwrap_err().to_string()).contains(special));
    let e = answers(|| load_clip(Path::new("/dev/zero")).unwrap_err().to_string());
    assert!(e.contains(special), "{e}");
    assert!(answers(|| load_clip(Path::new("/tmp")).unwrap_err().to_string()).contains("found a folder"));
    // As a scene's source.
    let scene_path = dir.join("scene.ron");
    std::fs::write(&scene_path, "(characters:[(source:File(\"motion.bvh\"),name:\"m\")])").unwrap();
    let out = dir.join("scene.glb");
    let output = answers(move || {
        marionette(&["export".as_ref(), scene_path.as_os_str(), "--out".as_ref(), out.as_os_str()], &dir)
    });
    assert_eq!(output.status.code(), Some(1));
    assert!(stderr(&output).contains(special), "{}", stderr(&output));
    // As a glTF buffer, inside the model's folder.
    let dir = scratch("fifo-buffer");
    let bytes = std::fs::read(regressions().join("gltf-uri-absolute.gltf")).unwrap();
    let text = String::from_utf8(bytes).unwrap().replace("/etc/passwd", "pipe.bin");
    std::fs::write(dir.join("model.gltf"), text).unwrap();
    make_fifo(&dir.join("pipe.bin"));
    let model = dir.join("model.gltf");
    let e = answers(move || gltf_import::load_gltf(&model).unwrap_err().to_string());
    assert!(e.contains("pipe.bin: expected a regular file, found a special file"), "{e}");
}

#[cfg(unix)]
#[test]
fn a_link_out_of_the_models_folder_is_refused() {
    let dir = scratch("link-out");
    let bytes = std::fs::read(regressions().join("gltf-uri-absolute.gltf")).unwrap();
    let text = String::from_utf8(bytes).unwrap().replace("/etc/passwd", "data.bin");
    std::fs::write(dir.join("model.gltf"), text).unwrap();
    std::os::unix::fs::symlink("/etc/passwd", dir.join("data.bin")).unwrap();
    let e = gltf_import::load_gltf(&dir.join("model.gltf")).unwrap_err().to_string();
    assert!(
        e.contains(
            "at $.buffers[0].uri: expected a file inside the model's folder, found `data.bin`, a link out of it"
        ),
        "{e}"
    );
}

#[test]
fn a_percent_encoded_uri_names_its_file() {
    let dir = scratch("percent");
    let source = regressions().join("gltf-uri-absolute.gltf");
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(source).unwrap()).unwrap();
    // The same model with its buffer in a file whose name has a space.
    let glb = std::fs::read(regressions().join("commands/gltf-clip-3e38-seconds.glb")).unwrap();
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let bin = &glb[20 + json_len + 8..];
    std::fs::write(dir.join("my buffer.bin"), bin).unwrap();
    let mut doc = doc;
    doc["buffers"][0]["uri"] = "my%20buffer.bin".into();
    std::fs::write(dir.join("model.gltf"), doc.to_string()).unwrap();
    assert_eq!(gltf_import::load_gltf(&dir.join("model.gltf")).unwrap().len(), 1);
}

#[test]
fn a_file_over_the_limit_is_refused_before_it_is_read() {
    let dir = scratch("sparse");
    for name in ["huge.bvh", "huge.skel"] {
        let path = dir.join(name);
        let file = std::fs::File::create(&path).unwrap();
        file.set_len(2 << 30).unwrap(); // 2 GiB, sparse: nothing on disk
        let p = path.clone();
        let e = answers(move || {
            crate::alloc::reset_peak();
            let e = if p.extension().unwrap() == "bvh" {
                load_clip(&p).unwrap_err()
            } else {
                load_character(&p).unwrap_err()
            };
            (e.to_string(), crate::alloc::peak())
        });
        assert!(e.0.contains(&format!("larger than the {} MiB", MAX_FILE_BYTES >> 20)), "{name}: {}", e.0);
        assert!(e.1 < 1 << 20, "{name}: {} bytes of heap to refuse it", e.1);
        std::fs::remove_file(&path).unwrap();
    }
}

#[test]
fn an_error_quotes_a_short_excerpt_of_a_huge_token() {
    let token = "x".repeat(1 << 20);
    let text = format!("HIERARCHY\nROOT {token}\n");
    let e = bvh::parse_bvh(Cursor::new(text.clone()), Path::new("long.bvh")).unwrap_err().to_string();
    assert!(e.len() < 200 + MAX_EXCERPT_CHARS * 4, "{} bytes of message", e.len());
    let text = format!("HIERARCHY\n{token}\n");
    let e = bvh::parse_bvh(Cursor::new(text), Path::new("long.bvh")).unwrap_err().to_string();
    assert!(
        e.starts_with("long.bvh:2: expected `JOINT`")
            && e.ends_with("found `xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx…`"),
        "{e:.300}"
    );
}

/// A BVH of `frames` frames for a 20-joint chain with 3 rotation channels each (and the
/// root's 3 positions).
fn big_bvh(frames: usize) -> String {
    let mut text = "HIERARCHY\nROOT j0\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n".to_string();
    for k in 1..20 {
        text += &format!("JOINT j{k}\n{{\n OFFSET 0 1 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n");
    }
    text += "End Site\n{\n OFFSET 0 1 0\n}\n";
    text += &"}\n".repeat(20);
    text += &format!("MOTION\nFrames: {frames}\nFrame Time: 0.008333\n");
    let row: Vec<String> = (0..63).map(|c| format!("{:.4}", (c as f32 * 0.37).sin() * 45.0)).collect();
    let row = row.join(" ") + "\n";
    text += &row.repeat(frames);
    text
}

#[test]
fn a_large_bvh_is_read_in_memory_proportional_to_its_motion() {
    let text = big_bvh(20_000); // ~8 MB
    let len = text.len();
    let (clip, peak) = answers(move || {
        crate::alloc::reset_peak();
        let file = bvh::parse_bvh(Cursor::new(text.into_bytes()), Path::new("big.bvh")).unwrap();
        (file.clip, crate::alloc::peak())
    });
    assert_eq!(clip.channels[3 + 3].keys().len(), 20_000);
    // The motion as text is never held whole: the keys (a 24-byte key per value, with
    // the values themselves) and the input dominate, not tokens of the text.
    assert!(peak < 8 * len, "{peak} bytes of heap for {len} bytes of BVH");
}

#[test]
fn a_100000_joint_bvh_chain_is_rejected_without_a_quadratic_pass() {
    let mut text = "HIERARCHY\nROOT j0\n{\n OFFSET 0 0 0\n CHANNELS 0\n".to_string();
    for k in 1..100_000 {
        text += &format!("JOINT j{k}\n{{\n OFFSET 0 0.01 0\n CHANNELS 0\n");
    }
    let e = answers(move || bvh::parse_bvh(Cursor::new(text), Path::new("chain.bvh")).unwrap_err().to_string());
    // Joint k's `JOINT` is on line 2 + 4k.
    assert_eq!(e, format!("chain.bvh:{}: expected at most 65536 joints, found more", 2 + 4 * 65_536));
}

#[test]
fn a_bvh_chain_within_the_joint_limit_gets_its_bone_boxes_in_one_pass() {
    let mut text = "HIERARCHY\nROOT j0\n{\n OFFSET 0 0 0\n CHANNELS 0\n".to_string();
    for k in 1..60_000 {
        text += &format!("JOINT j{k}\n{{\n OFFSET 0 0.01 0\n CHANNELS 0\n");
    }
    text += &"}\n".repeat(60_000);
    text += "MOTION\nFrames: 1\nFrame Time: 0.1\n\n";
    let file = answers(move || bvh::parse_bvh(Cursor::new(text), Path::new("chain.bvh")).unwrap());
    assert_eq!(file.skeleton.len(), 60_000);
    // Along the bone to its child (0.01 up), 8 % of the longest bone thick.
    let bone = file.skeleton.joint(10).bone_box.unwrap();
    assert!((bone.max.y - 0.0108).abs() < 1e-6 && (bone.min.y + 0.0008).abs() < 1e-6, "{bone:?}");
}

#[test]
fn export_never_writes_over_its_input() {
    let dir = scratch("own-input");
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    for ext in ["skel", "obj", "attach"] {
        std::fs::copy(assets.join(format!("puppet.{ext}")), dir.join(format!("puppet.{ext}"))).unwrap();
    }
    let before = std::fs::read(dir.join("puppet.obj")).unwrap();
    let output =
        marionette(&["export".as_ref(), "puppet.skel".as_ref(), "--out".as_ref(), "puppet.obj".as_ref()], &dir);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        stderr(&output).contains("puppet.obj: expected a new file to write, found a file this command read"),
        "{}",
        stderr(&output)
    );
    assert_eq!(std::fs::read(dir.join("puppet.obj")).unwrap(), before);
    // A glTF exported onto itself.
    let glb = dir.join("x.glb");
    std::fs::copy(regressions().join("commands/gltf-clip-3e38-seconds.glb"), &glb).unwrap();
    let before = std::fs::read(&glb).unwrap();
    let output = marionette(&["export".as_ref(), "x.glb".as_ref(), "--out".as_ref(), "x.glb".as_ref()], &dir);
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    assert_eq!(std::fs::read(&glb).unwrap(), before);
}

#[test]
fn info_of_a_path_without_a_folder_reads_the_morphs_beside_it() {
    let dir = scratch("no-folder");
    std::fs::write(dir.join("c07.skel"), "balljoint root { offset 0 0 0 }\n").unwrap();
    std::fs::write(
        dir.join("c07.skin"),
        "positions 3 {0 0 0 1 0 0 0 1 0}\nnormals 3 {0 0 1 0 0 1 0 0 1}\nskinweights 3 {1 0 1 1 0 1 1 0 1}\ntriangles 1 {0 1 2}\nbindings 1 {matrix {1 0 0 0 1 0 0 0 1 0 0 0}}\n",
    )
    .unwrap();
    std::fs::write(dir.join("c07a.morph"), "positions 1 {\n2 0 2 0\n}\n").unwrap();
    let output = marionette(&["info".as_ref(), "c07.skel".as_ref()], &dir);
    assert!(output.status.success(), "{}", stderr(&output));
    let said = String::from_utf8_lossy(&output.stdout);
    assert!(said.contains("c07a"), "the morph is not listed:\n{said}");
    // A corrupt morph beside it is an error at its line.
    std::fs::write(dir.join("c07b.morph"), "positions 1 {\n9 0 nan 0\n}\n").unwrap();
    let output = marionette(&["info".as_ref(), "c07.skel".as_ref()], &dir);
    assert_eq!(output.status.code(), Some(1));
    assert!(stderr(&output).contains("c07b.morph:2:"), "{}", stderr(&output));
}

#[test]
fn render_of_a_scene_whose_clip_fails_to_load_fails_and_writes_nothing() {
    let dir = scratch("render-bad-clip");
    std::fs::write(dir.join("bad.anim"), "animation { range 0 1 numchannels 1 channel { extrapolate constant nan")
        .unwrap();
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, "(characters:[(source:Embedded(\"puppet\"),name:\"p\",anim:Some((file:\"bad.anim\")))])")
        .unwrap();
    let out = dir.join("shot.png");
    let e = marionette::editor::present::render::render(
        vec![scene],
        Default::default(),
        out.clone(),
        PictureRequest { width: Some(64), height: Some(64), samples: None, antialias: None },
        Pictures::Still,
        false,
    )
    .unwrap_err();
    assert!(e.contains("bad.anim:1:") && e.contains("(character `p` of"), "{e}");
    assert!(!out.exists());
}

/// Rejections of every reader carry the file: no error here is placeless.
#[test]
fn a_missing_companion_or_unreadable_file_names_itself() {
    let e: FormatError = load_character(Path::new("/nonexistent/Model9.skel")).unwrap_err();
    assert!(e.to_string().starts_with("/nonexistent/Model9.skel"), "{e}");
}

//! Inputs that used to crash or fool Marionette: deep and huge skeletons, overflowing
//! counts, non-finite numbers, degenerate rigs, and commands that must fail cleanly.

use std::io::Cursor;
use std::path::Path;
use std::process::Command;
use std::sync::Arc;

use bevy::prelude::*;
use marionette::editor::present::readiness::{CaptureGate, GpuStatus, Readiness, readiness};
use marionette::formats::scene::{SceneDoc, joint_of_pose_key, pose_key, save_scene};
use marionette::formats::{cse169, homer, mit6837, write_atomically};
use marionette::rig::ik::{IkGoal, solve_ik};
use marionette::rig::skinning::flat_shade;
use marionette::rig::smpl::{BlendMode, Clip};
use marionette::rig::{CharacterAsset, MAX_JOINTS, RawJoint, Skeleton, Skin, SkinWeights};
use marionette::scene::{Character, CurrentJointToWorld, Placement};

use crate::common::{path, scratch};

/// Runs `f` on a thread with a small stack: a recursion as deep as the input would
/// overflow it (and abort the test binary).
fn on_small_stack<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    std::thread::Builder::new().stack_size(256 * 1024).spawn(f).unwrap().join().unwrap()
}

fn nested_cse169(depth: usize) -> String {
    let mut text = String::with_capacity(depth * 20);
    for k in 0..depth {
        text += &format!("balljoint j{k} {{ offset 0 0.01 0\n");
    }
    text += &"}".repeat(depth);
    text
}

#[test]
fn a_cse169_skeleton_nested_60000_deep_parses_without_recursion() {
    let skeleton =
        on_small_stack(|| cse169::parse_skel(Cursor::new(nested_cse169(60_000)), path("deep.skel")).unwrap());
    assert_eq!(skeleton.len(), 60_000);
    assert_eq!(skeleton.parent(59_999), Some(59_998));
    assert_eq!(skeleton.joint(59_999).name, "j59999");
}

#[test]
fn a_cse169_skeleton_of_200000_nested_joints_is_rejected_at_the_joint_too_many() {
    let e = on_small_stack(|| cse169::parse_skel(Cursor::new(nested_cse169(200_000)), path("deep.skel")).unwrap_err());
    assert_eq!(
        e.to_string(),
        format!("deep.skel:{}: expected at most {MAX_JOINTS} joints, found `balljoint`", MAX_JOINTS + 1)
    );
}

fn chain_6837(joints: usize) -> String {
    let mut text = "0 0 0 -1\n".to_string();
    for k in 1..joints {
        text += &format!("0 0.01 0 {}\n", k - 1);
    }
    text
}

#[test]
fn a_6837_skeleton_beyond_65536_joints_is_rejected_with_its_line() {
    let e = mit6837::parse_skel(Cursor::new(chain_6837(MAX_JOINTS + 1)), path("big.skel")).unwrap_err();
    assert_eq!(e.to_string(), format!("big.skel:{}: expected at most {MAX_JOINTS} joints, found more", MAX_JOINTS + 1));
}

/// A chain of `n` joints 0.01 apart along y, with one triangle weighted to its last joint.
fn chain_character(n: usize) -> Arc<CharacterAsset> {
    let skeleton = mit6837::parse_skel(Cursor::new(chain_6837(n)), path("chain.skel")).unwrap();
    let tip = 0.01 * (n - 1) as f32;
    let (weights, _) = SkinWeights::from_rows(vec![vec![(n - 1, 1.0)]; 3], n).unwrap();
    let corners = vec![Vec3::new(0.0, tip, 0.0), Vec3::new(0.1, tip, 0.0), Vec3::new(0.0, tip, 0.1)];
    let skin = Skin::untextured(corners, vec![[0, 1, 2]], weights);
    Arc::new(CharacterAsset::new("chain", skeleton, skin, Vec::new()).unwrap())
}

#[test]
fn a_50000_joint_chain_runs_through_the_matrix_stack_and_skinning_in_the_ecs() {
    let n = 50_000;
    let mut app = crate::ecs::app();
    let character = crate::ecs::spawn(&mut app, chain_character(n), Placement::default());
    app.update();
    let last = *app.world().get::<Character>(character).unwrap().joints.last().unwrap();
    let tip = app.world().get::<CurrentJointToWorld>(last).unwrap().0.w_axis.truncate();
    // 50,000 f32 additions of 0.01: within 1e-3 relative.
    assert!((tip.y - 0.01 * (n - 1) as f32).abs() < 0.5 && tip.x == 0.0, "{tip}");
    // Removing it despawns the whole joint chain.
    let joints = app.world().get::<Character>(character).unwrap().clone();
    marionette::scene::despawn_character(&mut app.world_mut().commands(), character, &joints);
    app.update();
    assert!(app.world().get_entity(last).is_err());
}

#[test]
fn ik_on_a_20000_joint_chain_solves_along_the_path() {
    let asset = chain_character(20_000);
    let mut pose = asset.skeleton.initial_pose();
    let end = asset.skeleton.len() - 1;
    let target = Vec3::new(60.0, 150.0, 0.0);
    let reports = solve_ik(&asset.skeleton, &mut pose, Mat4::IDENTITY, &[IkGoal { end, target }], 1e-3, 4);
    assert!(reports[0].distance < 0.1, "ended {} from the target", reports[0].distance);
}

#[test]
fn a_homer_rig_with_one_joint_binds_every_vertex_to_it() {
    let dir = scratch("homer-one-joint");
    std::fs::write(dir.join("one.json"), r#"{"root":{"pos":[0,0,0]}}"#).unwrap();
    std::fs::write(dir.join("one.off"), "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").unwrap();
    let asset = homer::load_homer(&dir.join("one.json")).unwrap();
    assert_eq!(asset.skeleton.len(), 1);
    assert!((0..3).all(|v| asset.skin.weights.weight(v, 0) == 1.0));
}

#[test]
fn attach_rows_of_huge_weights_are_normalised_not_zeroed() {
    let (weights, normalised) = mit6837::parse_attach(Cursor::new("3e38 3e38\n"), path("big.attach"), 3, 1).unwrap();
    assert_eq!(weights.weight(0, 1), 0.5);
    assert_eq!(weights.weight(0, 2), 0.5);
    assert_eq!(normalised.len(), 1);
    assert_eq!(normalised[0].sum, 2.0 * f64::from(3e38f32));
}

#[test]
fn a_clip_without_frames_samples_to_identity_and_has_empty_frames() {
    let clip = Clip { name: "empty".into(), root_positions: Vec::new(), rotations: Vec::new(), joint_count: 3 };
    assert!(clip.frame(0).is_empty());
    let mut out = Vec::new();
    clip.sample(2.5, true, BlendMode::Nlerp, &mut out);
    assert_eq!(out, vec![Quat::IDENTITY; 3]);
}

#[test]
fn pose_keys_find_their_own_joint_even_when_a_name_contains_a_hash() {
    let raw = vec![
        RawJoint::new("a", None, Vec3::ZERO),
        RawJoint::new("a", Some(0), Vec3::Y),
        RawJoint::new("a#1", Some(0), Vec3::X),
        RawJoint::new("b#7", Some(0), Vec3::Z),
    ];
    let skeleton = Skeleton::build(raw).unwrap();
    let keys: Vec<String> = (0..4).map(|j| pose_key(&skeleton, j)).collect();
    assert_eq!(keys, ["a#0", "a#1", "a#1#2", "b#7"]);
    for (j, key) in keys.iter().enumerate() {
        assert_eq!(joint_of_pose_key(&skeleton, key), Some(j), "{key}");
    }
}

#[cfg(unix)]
#[test]
fn saving_a_scene_whose_source_path_is_not_utf8_is_an_error_not_a_panic() {
    use std::os::unix::ffi::OsStrExt;
    let dir = scratch("non-utf8");
    let bad = std::path::PathBuf::from(std::ffi::OsStr::from_bytes(b"/tmp/caf\xe9.skel"));
    let mut doc = SceneDoc::default();
    doc.characters
        .push(marionette::formats::scene::CharacterDoc::new(marionette::formats::scene::SourceDoc::File(bad), "c"));
    let out = dir.join("scene.ron");
    let e = save_scene(&out, &doc).unwrap_err();
    assert!(e.to_string().contains("cannot be written"), "{e}");
    assert!(!out.exists());
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "no temporary file is left");
}

#[test]
fn atomic_writes_replace_the_target_and_leave_no_temporary_file() {
    let dir = scratch("atomic");
    let target = dir.join("out.txt");
    for text in ["first", "second"] {
        write_atomically(&target, |w| std::io::Write::write_all(w, text.as_bytes())).unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), text);
    }
    let failed = write_atomically(&target, |_| Err(std::io::Error::other("disk full")));
    assert!(failed.is_err());
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "second");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "only the target remains");
}

#[test]
fn degenerate_triangles_get_a_defined_unit_normal() {
    let p = [Vec3::ZERO, Vec3::ZERO, Vec3::X];
    let (mut pos, mut nrm) = (vec![[0.0; 3]; 3], vec![[0.0; 3]; 3]);
    flat_shade(&p, &[[0, 1, 2]], &mut pos, &mut nrm);
    assert!(nrm.iter().all(|n| (Vec3::from(*n).length() - 1.0).abs() < 1e-6), "{nrm:?}");
}

#[test]
fn the_capture_waits_while_a_pipeline_is_pending_and_counts_distinct_ready_frames() {
    let ready = GpuStatus { frame: 1, ..Default::default() };
    let compiling = GpuStatus { pipelines_waiting: 2, ..ready.clone() };
    assert_eq!(readiness(&compiling, 0, false), Readiness::Waiting("2 pipeline(s) compiling".into()));
    assert_eq!(readiness(&GpuStatus::default(), 0, false), Readiness::Waiting("no frame rendered yet".into()));
    assert!(matches!(readiness(&ready, 1, false), Readiness::Waiting(w) if w.contains("not skinned")));
    assert!(matches!(readiness(&ready, 0, true), Readiness::Waiting(w) if w.contains("scene")));
    let missing = GpuStatus { meshes_missing: 1, images_missing: 1, ..ready.clone() };
    assert!(
        matches!(readiness(&missing, 0, false), Readiness::Waiting(w) if w.contains("mesh") && w.contains("image"))
    );
    let failed = GpuStatus { pipelines_failed: vec!["bad shader".into()], ..ready.clone() };
    assert!(matches!(readiness(&failed, 0, false), Readiness::Failed(_)));
    assert_eq!(readiness(&ready, 0, false), Readiness::Ready);

    let mut gate = CaptureGate::default();
    for frame in 1..=5 {
        gate.observe(frame, readiness(&GpuStatus { frame, ..compiling.clone() }, 0, false));
        assert!(!gate.is_ready(), "a pending pipeline holds the capture");
    }
    gate.observe(6, Readiness::Ready);
    gate.observe(6, Readiness::Ready);
    gate.observe(7, Readiness::Ready);
    assert!(!gate.is_ready(), "a render frame reported twice counts once");
    gate.observe(8, Readiness::Ready);
    assert!(gate.is_ready());
    gate.observe(9, Readiness::Waiting("1 pipeline(s) compiling".into()));
    assert!(!gate.is_ready(), "a new pipeline starts the count again");
    assert_eq!(gate.last_reason.as_deref(), Some("1 pipeline(s) compiling"));
    for frame in 10..=12 {
        gate.observe(frame, Readiness::Ready);
    }
    assert!(gate.is_ready() && !gate.is_speculative());
    // A picture set up once all was drawn, waiting for a pipeline of its own: captured in
    // its first ready frame after, a capture to be checked against what was drawn.
    gate.next_picture();
    gate.observe(13, Readiness::Waiting("1 pipeline(s) compiling".into()));
    assert!(!gate.is_ready());
    gate.observe(14, Readiness::Ready);
    assert!(gate.is_ready() && gate.is_speculative());
    gate.restart();
    gate.observe(15, Readiness::Ready);
    assert!(!gate.is_ready() && !gate.is_speculative(), "a restart counts three ready frames again");
}

fn marionette(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_marionette")).args(args).output().unwrap()
}

fn regression(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regressions").join(name).display().to_string()
}

#[test]
fn render_fails_without_a_picture_for_missing_or_bad_input() {
    let dir = scratch("render-fails");
    let out = dir.join("shot.png");
    let out_s = out.display().to_string();
    let missing_scene = dir.join("missing.ron");
    std::fs::write(&missing_scene, r#"(characters:[(source:File("nope.skel"),name:"n")])"#).unwrap();
    let cases: Vec<(Vec<String>, String)> = vec![
        (vec![dir.join("nope.skel").display().to_string()], "nope.skel".into()),
        (vec![missing_scene.display().to_string()], "nope.skel".into()),
        (vec![regression("scene-truncated.ron")], "scene-truncated.ron:1:39: Expected comma".into()),
        (vec![regression("nan-offset.skel")], "nan-offset.skel:2: expected a finite number, found `nan`".into()),
    ];
    for (paths, expected) in cases {
        let mut args = vec!["render"];
        args.extend(paths.iter().map(String::as_str));
        args.extend(["--out", &out_s]);
        let output = marionette(&args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{paths:?} succeeded");
        assert!(stderr.contains(&expected), "{paths:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(!out.exists(), "{paths:?} wrote a picture");
    }
    let zero = marionette(&["render", "--out", &out_s, "--width", "0"]);
    assert!(!zero.status.success() && !out.exists());
    assert!(String::from_utf8_lossy(&zero.stderr).contains("--width"));
}

#[test]
fn info_and_export_reject_non_finite_numbers_with_their_line_and_write_nothing() {
    let dir = scratch("non-finite");
    let info = marionette(&["info", &regression("nan-offset.skel")]);
    assert!(!info.status.success());
    assert!(String::from_utf8_lossy(&info.stderr).contains("nan-offset.skel:2: expected a finite number, found `nan`"));
    std::fs::copy(regression("nan-vertex.obj"), dir.join("m.obj")).unwrap();
    std::fs::write(dir.join("m.skel"), "0 0 0 -1\n0 1 0 0\n").unwrap();
    std::fs::write(dir.join("m.attach"), "1\n1\n1\n").unwrap();
    let out = dir.join("out.obj");
    let export =
        marionette(&["export", &dir.join("m.skel").display().to_string(), "--out", &out.display().to_string()]);
    assert!(!export.status.success());
    assert!(String::from_utf8_lossy(&export.stderr).contains("m.obj:2: expected a finite number, found `nan`"));
    assert!(!out.exists());
}

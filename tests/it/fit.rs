//! Pose from a photo: characters nobody here made, posed in every built-in body pose, seen
//! from three cameras; the keypoint files `render --data` writes for those pictures (COCO's
//! and OpenPose's, made here by the document layer's own annotation of the posed skin,
//! which is what `render --data` runs on the drawn frame) fed back to the fit. Checked
//! against the truth: the reprojection, the 3D joints after a similarity (Procrustes)
//! alignment, and the knees' bends.

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};
use marionette::document::AssetLibrary;
use marionette::document::annotate::{self, Figure, Pinhole, Surface, raster::FLOOR};
use marionette::document::fit::{FitSpec, Fitted, fit, is_smpl};
use marionette::document::options::{PoseOptions, PoseSpecs, apply_options};
use marionette::document::retarget::humanoid_map;
use marionette::formats::keypoints::parse_keypoints;
use marionette::formats::scene::{CharacterDoc, SceneDoc, SourceDoc};
use marionette::formats::stage::CameraDoc;
use marionette::rig::body_poses::POSES;
use marionette::rig::fk::forward_kinematics;
use marionette::rig::humanoid::{HumanBone, HumanoidMap};
use marionette::rig::{CharacterAsset, JointRotation};

use HumanBone::*;

const SIZE: (u32, u32) = (640, 480);

fn rig(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs").join(file)
}

fn doc_of(library: &mut AssetLibrary, path: &Path) -> CharacterDoc {
    let source = SourceDoc::File(path.to_path_buf());
    let asset = library.load(&source).unwrap();
    library.new_character_doc(source, &asset)
}

/// A character in a built-in pose, as `--preset` poses it (feet on the floor).
struct Posed {
    asset: std::sync::Arc<CharacterAsset>,
    map: HumanoidMap,
    pose: Vec<JointRotation>,
    placement: Mat4,
    smpl: bool,
}

fn posed(library: &mut AssetLibrary, doc: &CharacterDoc, preset: &str) -> Posed {
    let mut scene = SceneDoc { characters: vec![doc.clone()], ..SceneDoc::default() };
    let specs = PoseSpecs { preset: Some(preset.parse().unwrap()), ..PoseSpecs::default() };
    apply_options(&mut scene, &PoseOptions { specs, ..PoseOptions::default() }, library).unwrap();
    let c = &scene.characters[0];
    let asset = library.shaped(c).unwrap();
    let (pose, _) = marionette::document::scenes::pose_from_doc(&asset, c);
    let map = humanoid_map(&asset, &c.humanoid);
    Posed { asset, map, pose, placement: c.placement.to_mat4(), smpl: is_smpl(&c.source) }
}

fn joints_world(asset: &CharacterAsset, pose: &[JointRotation], placement: Mat4) -> Vec<Vec3> {
    let mut world = vec![Mat4::IDENTITY; asset.skeleton.len()];
    forward_kinematics(&asset.skeleton, pose, placement, &mut world);
    world.iter().map(|m| m.w_axis.truncate()).collect()
}

/// The three cameras: ahead and a little to the side, from the character's right, and from
/// behind its left shoulder; each aimed at the hips' height.
fn cameras(height: f32) -> [CameraDoc; 3] {
    let at = |yaw: f32, pitch: f32, distance: f32| CameraDoc {
        focus: Vec3::new(0.0, height * 0.5, 0.0),
        yaw,
        pitch,
        distance: distance * height,
        ..CameraDoc::default()
    };
    [at(0.35, -0.12, 2.2), at(-1.35, -0.3, 2.4), at(2.5, -0.2, 2.3)]
}

/// The keypoint files of the picture: `(coco, openpose)` as `render --data` and
/// `render --controlnet` write them.
fn keypoint_files(p: &Posed, camera: &CameraDoc) -> (String, String) {
    let pinhole = Pinhole::of(camera, SIZE.0, SIZE.1).unwrap();
    let positions = marionette::document::posing::posed_positions(&p.asset, &p.pose, p.placement);
    let joints = joints_world(&p.asset, &p.pose, p.placement);
    let figure = Figure::new("figure", 1, &p.asset, Some(&p.map), positions, &joints, p.smpl);
    let floor = [
        Vec3::new(-20.0, 0.0, -20.0),
        Vec3::new(20.0, 0.0, -20.0),
        Vec3::new(20.0, 0.0, 20.0),
        Vec3::new(-20.0, 0.0, 20.0),
    ];
    let surfaces = [
        figure.surface(),
        Surface { instance: FLOOR, positions: &floor, triangles: &[[0, 2, 1], [0, 3, 2]], parts: &[] },
    ];
    let passes = annotate::rasterize(&pinhole, &surfaces);
    let figures = [figure];
    let image = annotate::coco::image_json(1, "picture.png", &pinhole);
    let annotations = annotate::coco::annotations(&pinhole, &passes, &figures, 1, 1);
    let coco = annotate::coco::file(vec![image], annotations);
    let openpose = annotate::openpose::json(&pinhole, &passes, &figures);
    (coco.to_string(), openpose.to_string())
}

/// The body joints the error is measured on: the humanoid map's, fingers and toes aside.
fn measured(map: &HumanoidMap) -> Vec<usize> {
    HumanBone::ALL
        .iter()
        .filter(|b| !b.is_finger() && !matches!(b, LeftToes | RightToes | LeftShoulder | RightShoulder))
        .filter_map(|b| map.get(b).copied())
        .collect()
}

/// Mean distance between matching points after the best similarity (rotation, scale,
/// translation) takes `a` onto `b` (Umeyama's).
fn procrustes_error(a: &[Vec3], b: &[Vec3]) -> f32 {
    let n = a.len() as f64;
    let mean = |p: &[Vec3]| p.iter().fold(glam::DVec3::ZERO, |s, v| s + v.as_dvec3()) / n;
    let (ma, mb) = (mean(a), mean(b));
    let cov = faer::Mat::<f64>::from_fn(3, 3, |i, j| {
        a.iter().zip(b).map(|(x, y)| (y.as_dvec3() - mb)[i] * (x.as_dvec3() - ma)[j]).sum::<f64>() / n
    });
    let svd = cov.svd().unwrap();
    let (u, s, v) = (svd.U(), svd.S(), svd.V());
    let um = glam::DMat3::from_cols_array(&std::array::from_fn(|k| u[(k % 3, k / 3)]));
    let vm = glam::DMat3::from_cols_array(&std::array::from_fn(|k| v[(k % 3, k / 3)]));
    let sign = if (um * vm.transpose()).determinant() < 0.0 { -1.0 } else { 1.0 };
    let d = glam::DMat3::from_diagonal(glam::DVec3::new(1.0, 1.0, sign));
    let rotation = um * d * vm.transpose();
    let var_a = a.iter().map(|x| (x.as_dvec3() - ma).length_squared()).sum::<f64>() / n;
    let scale = (s[0] + s[1] + s[2] * sign) / var_a;
    let sum: f64 =
        a.iter().zip(b).map(|(x, y)| ((rotation * (x.as_dvec3() - ma)) * scale + mb - y.as_dvec3()).length()).sum();
    (sum / n) as f32
}

/// How far a knee bends backwards: a knee bends about the body's left (from the right hip
/// to the left), the shin turning behind the thigh; the most either turns the other way.
fn knees_backwards(map: &HumanoidMap, at: &[Vec3]) -> f32 {
    let left = (at[map[&LeftUpperLeg]] - at[map[&RightUpperLeg]]).normalize();
    let mut worst: f32 = 0.0;
    for (hip, knee, ankle) in [(LeftUpperLeg, LeftLowerLeg, LeftFoot), (RightUpperLeg, RightLowerLeg, RightFoot)] {
        let (h, k, a) = (at[map[&hip]], at[map[&knee]], at[map[&ankle]]);
        let bend = (k - h).normalize().cross((a - k).normalize()).dot(left);
        worst = worst.max(-bend);
    }
    worst
}

/// Whether the pose stands or sits (the poses the 50 mm bound is for).
fn stands_or_sits(name: &str) -> bool {
    let pose = marionette::rig::body_poses::body_pose(name).unwrap();
    let dirs = pose.directions(false);
    let of = |b: HumanBone| dirs.iter().find(|(x, _)| *x == b).unwrap().1;
    let down = |b| of(b).angle_between(Vec3::NEG_Y) < 25f32.to_radians();
    name.starts_with("sit-") || (down(LeftUpperLeg) && down(RightUpperLeg) && of(Hips).angle_between(Vec3::Y) < 0.45)
}

/// One character's round trip: every pose from every camera, COCO and OpenPose files.
struct Figures {
    reprojection: Vec<f32>,
    standing: Vec<f32>,
    all: Vec<f32>,
    failures: Vec<String>,
}

fn round_trip(library: &mut AssetLibrary, doc: &CharacterDoc, formats: &[usize]) -> Figures {
    let mut out = Figures { reprojection: Vec::new(), standing: Vec::new(), all: Vec::new(), failures: Vec::new() };
    let rest = posed(library, doc, "stand");
    let height = {
        let at = joints_world(&rest.asset, &rest.pose, rest.placement);
        at.iter().map(|p| p.y).fold(0.0, f32::max)
    };
    for body in &POSES {
        let truth = posed(library, doc, body.name);
        let true_joints = joints_world(&truth.asset, &truth.pose, truth.placement);
        for (k, camera) in cameras(height).iter().enumerate() {
            let files = keypoint_files(&truth, camera);
            for &format in formats {
                let text = if format == 0 { &files.0 } else { &files.1 };
                let keypoints = parse_keypoints(text, Path::new("keypoints.json")).unwrap();
                let spec = FitSpec { file: "keypoints.json".into(), ..FitSpec::default() };
                let fitted: Fitted =
                    fit(&truth.asset, &truth.map, rest.placement, truth.smpl, &keypoints, &spec).unwrap();
                let at = joints_world(&truth.asset, &fitted.pose, fitted.placement);
                let joints = measured(&truth.map);
                let fit_points: Vec<Vec3> = joints.iter().map(|&j| at[j]).collect();
                let true_points: Vec<Vec3> = joints.iter().map(|&j| true_joints[j]).collect();
                let mm = 1000.0 * procrustes_error(&fit_points, &true_points) * 1.75 / height;
                let what = format!("{} {} camera {k} {}", doc.name, body.name, ["coco", "openpose"][format]);
                out.reprojection.push(fitted.error);
                out.all.push(mm);
                if stands_or_sits(body.name) {
                    out.standing.push(mm);
                }
                if fitted.error > 3.0 || mm > 120.0 {
                    out.failures.push(format!("{what}: {:.2} px, {mm:.0} mm (from {})", fitted.error, fitted.mode));
                }
                let backwards = knees_backwards(&truth.map, &at);
                if backwards > 0.1 + knees_backwards(&truth.map, &true_joints) {
                    out.failures.push(format!("{what}: a knee bent backwards ({backwards:.2})"));
                }
            }
        }
    }
    out
}

fn mean(v: &[f32]) -> f32 {
    v.iter().sum::<f32>() / v.len().max(1) as f32
}

fn check(name: &str, figures: &Figures) {
    let worst = figures.reprojection.iter().copied().fold(0.0, f32::max);
    println!(
        "{name}: reprojection mean {:.2} px (worst {worst:.2}); PA-MPJPE standing/sitting {:.1} mm, all {:.1} mm over {} fits",
        mean(&figures.reprojection),
        mean(&figures.standing),
        mean(&figures.all),
        figures.all.len()
    );
    for f in &figures.failures {
        println!("  {f}");
    }
    assert!(mean(&figures.reprojection) <= 3.0, "{name}: reprojection");
    assert!(mean(&figures.standing) <= 50.0, "{name}: standing and sitting");
    assert!(mean(&figures.all) <= 80.0, "{name}: all poses");
    assert!(!figures.failures.iter().any(|f| f.contains("backwards")), "{name}: knees");
}

fn own_round_trip(library: &mut AssetLibrary, path: &Path) {
    let doc = doc_of(library, path);
    let figures = round_trip(library, &doc, &[0, 1]);
    check(&doc.name, &figures);
}

#[test]
fn a_mixamo_figure_fitted_to_its_own_keypoints_takes_its_pose() {
    own_round_trip(&mut AssetLibrary::default(), &rig("mixamo.glb"));
}

#[test]
fn a_rigify_figure_fitted_to_its_own_keypoints_takes_its_pose() {
    own_round_trip(&mut AssetLibrary::default(), &rig("rigify.glb"));
}

#[test]
fn a_vroid_figure_fitted_to_its_own_keypoints_takes_its_pose() {
    own_round_trip(&mut AssetLibrary::default(), &rig("vroid.glb"));
}

#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn cesium_man_fitted_to_its_own_keypoints_takes_its_pose() {
    own_round_trip(&mut AssetLibrary::default(), &crate::common::data_dir().join("khronos/CesiumMan.glb"));
}

#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn an_smpl_body_fitted_to_its_own_keypoints_takes_its_pose() {
    own_round_trip(&mut AssetLibrary::default(), &crate::common::data_dir().join("smpl"));
}

/// The Mixamo figure's keypoints (its COCO file, every pose from every camera) fitted to
/// CesiumMan and to an SMPL body: they cannot match its proportions exactly, but come
/// within 5 px mean.
#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn keypoints_of_one_figure_fit_another_character() {
    let data = crate::common::data_dir();
    let mut library = AssetLibrary::default();
    let mixamo = doc_of(&mut library, &rig("mixamo.glb"));
    let height = {
        let rest = posed(&mut library, &mixamo, "stand");
        joints_world(&rest.asset, &rest.pose, rest.placement).iter().map(|p| p.y).fold(0.0, f32::max)
    };
    for target in ["khronos/CesiumMan.glb", "smpl"] {
        let doc = doc_of(&mut library, &data.join(target));
        let other = posed(&mut library, &doc, "stand");
        let mut errors = Vec::new();
        for body in &POSES {
            let truth = posed(&mut library, &mixamo, body.name);
            for camera in &cameras(height) {
                let (coco, _) = keypoint_files(&truth, camera);
                let keypoints = parse_keypoints(&coco, Path::new("keypoints.json")).unwrap();
                let spec = FitSpec { file: "keypoints.json".into(), ..FitSpec::default() };
                let fitted = fit(&other.asset, &other.map, other.placement, other.smpl, &keypoints, &spec).unwrap();
                errors.push(fitted.error);
            }
        }
        let worst = errors.iter().copied().fold(0.0, f32::max);
        println!(
            "mixamo onto {target}: reprojection mean {:.2} px (worst {worst:.2}) over {} fits",
            mean(&errors),
            errors.len()
        );
        assert!(mean(&errors) <= 5.0, "{target}");
    }
}

/// A 2-second walk (CMU's, retargeted onto the Mixamo figure) drawn at 30 fps from one
/// camera, its OpenPose files fitted as a sequence: each frame of the fitted clip within
/// 80 mm PA-MPJPE of the walk, and no frame-to-frame jump of the joints over 3× the walk's
/// own (or 5 mm, where the walk barely moves).
#[test]
fn a_walks_keypoints_fitted_as_a_sequence_give_the_walk() {
    use marionette::formats::scene::{AnimDoc, MotionSourceDoc, RetargetDoc};
    let mut library = AssetLibrary::default();
    let mut doc = doc_of(&mut library, &rig("mixamo.glb"));
    let walk = rig("cmu_walk.bvh");
    doc.anim = Some(AnimDoc {
        retarget: Some(RetargetDoc::of(MotionSourceDoc::File { path: walk, clip: None })),
        ..AnimDoc::default()
    });
    let asset = library.shaped(&doc).unwrap();
    let map = humanoid_map(&asset, &doc.humanoid);
    let scene = SceneDoc { characters: vec![doc.clone()], ..SceneDoc::default() };
    let truth: Vec<Posed> = (0..60)
        .map(|k| {
            let mut at = scene.clone();
            marionette::document::options::pause_clips_at(&mut at, k as f32 / 30.0);
            let c = &at.characters[0];
            let (pose, shift) = marionette::document::export::still_pose(&mut library, &at, c, &asset).unwrap();
            let placement = c.placement.to_mat4() * Mat4::from_translation(shift);
            Posed { asset: asset.clone(), map: map.clone(), pose, placement, smpl: false }
        })
        .collect();
    let hips: Vec<Vec3> = truth.iter().map(|p| joints_world(&asset, &p.pose, p.placement)[map[&Hips]]).collect();
    let middle = (hips[0] + hips[59]) / 2.0;
    let camera = CameraDoc { focus: middle, yaw: 0.9, pitch: -0.15, distance: 6.0, ..CameraDoc::default() };
    let folder = crate::common::scratch("fit_sequence");
    for (k, p) in truth.iter().enumerate() {
        let (_, openpose) = keypoint_files(p, &camera);
        std::fs::write(folder.join(format!("walk_{k:012}_keypoints.json")), openpose).unwrap();
    }
    let spec = marionette::document::fit::SequenceSpec { frames: folder, fps: 30.0, person: None, fov: None };
    let fitted = marionette::document::fit::fit_sequence(&asset, &map, doc.placement.to_mat4(), false, &spec).unwrap();
    let joints = measured(&map);
    let rest_root = asset.skeleton.joint(0).rest_offset;
    let mut errors = Vec::new();
    let (mut fit_before, mut true_before): (Option<Vec<Vec3>>, Option<Vec<Vec3>>) = (None, None);
    let mut failures = Vec::new();
    for (k, p) in truth.iter().enumerate() {
        let (root, pose) = fitted.clip.pose_at(&asset.skeleton, k as f32 / 30.0, &asset.skeleton.initial_pose());
        let placement = doc.placement.to_mat4() * Mat4::from_translation(root - rest_root);
        let fit_at = joints_world(&asset, &pose, placement);
        let true_at = joints_world(&asset, &p.pose, p.placement);
        let fit_points: Vec<Vec3> = joints.iter().map(|&j| fit_at[j]).collect();
        let true_points: Vec<Vec3> = joints.iter().map(|&j| true_at[j]).collect();
        let mm = 1000.0 * procrustes_error(&fit_points, &true_points);
        errors.push(mm);
        if mm > 80.0 {
            failures.push(format!("frame {k}: {mm:.0} mm"));
        }
        if let (Some(a), Some(b)) = (&fit_before, &true_before) {
            // Each joint's move against the hips' (the body's own motion, not its travel).
            let jump = |now: &[Vec3], before: &[Vec3]| {
                let moved = |k: usize| (now[k] - now[0]) - (before[k] - before[0]);
                1000.0 * (0..now.len()).map(|k| moved(k).length()).sum::<f32>() / now.len() as f32
            };
            let (fitted_jump, true_jump) = (jump(&fit_points, a), jump(&true_points, b));
            if fitted_jump > 3.0 * true_jump.max(5.0) {
                failures.push(format!("frame {k}: a jump of {fitted_jump:.0} mm against the walk's {true_jump:.0} mm"));
            }
        }
        (fit_before, true_before) = (Some(fit_points), Some(true_points));
    }
    println!(
        "{}; PA-MPJPE mean {:.1} mm, worst {:.1} mm",
        fitted.describe(),
        mean(&errors),
        errors.iter().copied().fold(0.0, f32::max)
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn marionette(args: &[&std::ffi::OsStr]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_marionette")).args(args).output().unwrap()
}

fn obj_positions(path: &Path) -> Vec<Vec3> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f32> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            Vec3::new(v[0], v[1], v[2])
        })
        .collect()
}

/// `export --fit` on the Mixamo figure's own COCO file of `wave` writes the mesh `export
/// --preset wave` writes (within 0.1 mm a vertex).
#[test]
fn export_fit_writes_the_pose_the_keypoints_were_drawn_in() {
    let mut library = AssetLibrary::default();
    let file = rig("mixamo.glb");
    let doc = doc_of(&mut library, &file);
    let truth = posed(&mut library, &doc, "wave");
    let camera =
        CameraDoc { focus: Vec3::new(0.2, 0.9, 0.0), yaw: 0.5, pitch: -0.2, distance: 3.5, ..CameraDoc::default() };
    let folder = crate::common::scratch("export_fit");
    let keypoints = folder.join("photo.json");
    std::fs::write(&keypoints, keypoint_files(&truth, &camera).0).unwrap();
    let (fitted, preset) = (folder.join("fitted.obj"), folder.join("preset.obj"));
    let out = marionette(&[
        "export".as_ref(),
        file.as_ref(),
        "--fit".as_ref(),
        keypoints.as_ref(),
        "--out".as_ref(),
        fitted.as_ref(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("fitted to 12 points"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = marionette(&[
        "export".as_ref(),
        file.as_ref(),
        "--preset".as_ref(),
        "wave".as_ref(),
        "--out".as_ref(),
        preset.as_ref(),
    ]);
    assert!(out.status.success());
    let (a, b) = (obj_positions(&fitted), obj_positions(&preset));
    assert_eq!(a.len(), b.len());
    let worst = a.iter().zip(&b).map(|(x, y)| x.distance(*y)).fold(0.0, f32::max);
    assert!(worst < 1e-4, "{worst} m");
}

/// Malformed keypoint files are refused with the field's path, never a crash.
#[test]
fn malformed_keypoint_files_are_refused_by_field() {
    let folder = crate::common::scratch("fit_malformed");
    let body = |n: usize| (0..n).map(|k| format!("{}", 100 + k)).collect::<Vec<_>>().join(",");
    let cases = [
        (
            "short.json",
            format!(r#"{{"people":[{{"pose_keypoints_2d":[{}]}}]}}"#, body(52)),
            "people[0].pose_keypoints_2d: 52 numbers, expected 54 or 75",
        ),
        (
            "nan.json",
            r#"{"people":[{"pose_keypoints_2d":["nan"]}]}"#.to_string(),
            "people[0].pose_keypoints_2d[0]: expected a finite number",
        ),
        (
            "negative.json",
            format!(r#"{{"canvas_width":-640,"canvas_height":480,"people":[{{"pose_keypoints_2d":[{}]}}]}}"#, body(54)),
            "canvas_width: expected a positive size",
        ),
        ("empty.json", r#"{"people":[]}"#.to_string(), "people: expected at least one person"),
        (
            "absent.json",
            format!(r#"{{"people":[{{"pose_keypoints_2d":[{}]}}]}}"#, vec!["0"; 54].join(",")),
            "people[0]: every point absent",
        ),
        (
            "coco.json",
            r#"{"annotations":[{"keypoints":[1,2]}]}"#.to_string(),
            "annotations[0].keypoints: 2 numbers, expected 51",
        ),
        ("text.json", "not json".to_string(), "expected JSON"),
    ];
    let out_obj = folder.join("out.obj");
    for (name, text, expected) in cases {
        let path = folder.join(name);
        std::fs::write(&path, text).unwrap();
        let out = marionette(&[
            "export".as_ref(),
            rig("mixamo.glb").as_ref(),
            "--fit".as_ref(),
            path.as_ref(),
            "--out".as_ref(),
            out_obj.as_ref(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{name}: {stderr}");
        assert!(stderr.contains(expected) && stderr.contains(name), "{name}: {stderr}");
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
    }
    assert!(!out_obj.exists(), "nothing written");
}

/// `export --fit-sequence DIR --fps 30 --animation --out walk.glb`: a glTF animation of
/// the frames' span; the same from one file listing the frames (ComfyUI's).
#[test]
fn a_fitted_sequence_exports_as_an_animation() {
    let mut library = AssetLibrary::default();
    let file = rig("mixamo.glb");
    let doc = doc_of(&mut library, &file);
    let folder = crate::common::scratch("fit_sequence_export");
    let frames = folder.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    let camera =
        CameraDoc { focus: Vec3::new(0.0, 0.9, 0.0), yaw: 0.4, pitch: -0.15, distance: 4.0, ..CameraDoc::default() };
    let mut video = Vec::new();
    for (k, pose) in ["stand", "walk", "run", "walk:mirrored", "stand"].iter().enumerate() {
        let truth = posed(&mut library, &doc, pose);
        let openpose = keypoint_files(&truth, &camera).1;
        std::fs::write(frames.join(format!("clip_{k:012}_keypoints.json")), &openpose).unwrap();
        video.push(openpose);
    }
    // The same frames as one list (ComfyUI's POSE_KEYPOINT of a video).
    let list = folder.join("video.json");
    std::fs::write(&list, format!("[{}]", video.join(","))).unwrap();
    for (from, glb) in [(frames, folder.join("walk.glb")), (list, folder.join("video.glb"))] {
        let out = marionette(&[
            "export".as_ref(),
            file.as_ref(),
            "--fit-sequence".as_ref(),
            from.as_ref(),
            "--fps".as_ref(),
            "10".as_ref(),
            "--animation".as_ref(),
            "--out".as_ref(),
            glb.as_ref(),
        ]);
        let said = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success() && said.contains("fitted 5 frames"), "{}: {said}", from.display());
        let gltf = gltf::Gltf::from_slice(&std::fs::read(&glb).unwrap()).unwrap();
        let animation = gltf.animations().next().expect("an animation");
        let end = animation
            .channels()
            .filter_map(|c| c.sampler().input().max())
            .filter_map(|m| m.as_array()?.first()?.as_f64())
            .fold(0.0, f64::max) as f32;
        assert!((end - 0.4).abs() < 1e-4, "{}: {end}", from.display());
    }
}

/// Fingers from the hand points: the Mixamo figure waving with a fist and a pointing hand,
/// its OpenPose file (hands of 21) fitted: the fitted hand points land within 3 px mean of
/// the file's, against more than 3 times that with the fingers left at rest.
#[test]
fn fingers_follow_the_hand_points() {
    let mut library = AssetLibrary::default();
    let doc = doc_of(&mut library, &rig("mixamo.glb"));
    let mut scene = SceneDoc { characters: vec![doc], ..SceneDoc::default() };
    let specs = PoseSpecs {
        preset: Some("wave".parse().unwrap()),
        hands: vec!["left=fist".parse().unwrap(), "right=point".parse().unwrap()],
        ..PoseSpecs::default()
    };
    apply_options(&mut scene, &PoseOptions { specs, ..PoseOptions::default() }, &mut library).unwrap();
    let c = &scene.characters[0];
    let asset = library.shaped(c).unwrap();
    let map = humanoid_map(&asset, &c.humanoid);
    let (pose, _) = marionette::document::scenes::pose_from_doc(&asset, c);
    let truth = Posed { asset: asset.clone(), map: map.clone(), pose, placement: c.placement.to_mat4(), smpl: false };
    let camera =
        CameraDoc { focus: Vec3::new(0.3, 1.2, 0.0), yaw: 0.2, pitch: -0.1, distance: 1.6, ..CameraDoc::default() };
    let (_, openpose) = keypoint_files(&truth, &camera);
    let keypoints = parse_keypoints(&openpose, Path::new("hands.json")).unwrap();
    let spec = FitSpec { file: "hands.json".into(), ..FitSpec::default() };
    let fitted = fit(&asset, &map, truth.placement, false, &keypoints, &spec).unwrap();
    assert!(fitted.finger_points >= 20, "{}", fitted.describe());
    let person = &keypoints.people[0];
    let pinhole = fitted.pinhole();
    let hand_error = |pose: &[JointRotation]| {
        let joints = joints_world(&asset, pose, fitted.placement);
        let positions = marionette::document::posing::posed_positions(&asset, pose, fitted.placement);
        let figure = Figure::new("fitted", 1, &asset, Some(&map), positions, &joints, false);
        let mut errors = Vec::new();
        for (side, hand) in [("left", &person.left_hand), ("right", &person.right_hand)] {
            for (k, p) in hand.iter().enumerate().skip(1) {
                let (Some(p), Some(point)) = (p, figure.points.get(&format!("{side}_hand_{k}"))) else { continue };
                let (x, y, _) = pinhole.project(point.at).unwrap();
                errors.push(glam::Vec2::new(x - p.x, y - p.y).length());
            }
        }
        mean(&errors)
    };
    let with_fingers = hand_error(&fitted.pose);
    let mut rest_fingers = fitted.pose.clone();
    let rest = asset.skeleton.initial_pose();
    for (_, &j) in map.iter().filter(|(b, _)| b.is_finger()) {
        rest_fingers[j] = rest[j];
    }
    let without = hand_error(&rest_fingers);
    println!("hand points: {with_fingers:.2} px mean with the fingers fitted, {without:.2} px at rest");
    assert!(with_fingers <= 3.0 && without > 3.0 * with_fingers, "{with_fingers} vs {without}");
}

/// The editor's "Fit to keypoints…": its edits, pushed together, are one undo step that
/// poses the character as the file shows it (its keypoints within 0.05 px of the file's
/// under the fitted camera) and stands it on the floor; undoing it returns the scene.
#[test]
fn fitting_in_the_editor_is_one_undo_step() {
    use bevy::prelude::App;
    use marionette::editor::edits::commands::EditQueue;
    use marionette::editor::edits::history::{History, HistoryRequest};
    use marionette::editor::ui::fit::{FitTarget, fit_outcome};
    let mut library = AssetLibrary::default();
    let doc = doc_of(&mut library, &rig("mixamo.glb"));
    let truth = posed(&mut library, &doc, "wave");
    let camera =
        CameraDoc { focus: Vec3::new(0.1, 0.9, 0.0), yaw: -0.4, pitch: -0.2, distance: 3.2, ..CameraDoc::default() };
    let folder = crate::common::scratch("fit_in_the_editor");
    let path = folder.join("photo.json");
    std::fs::write(&path, keypoint_files(&truth, &camera).0).unwrap();

    let mut app = crate::edits::scene_app();
    let id = marionette::formats::scene::CharacterId(1);
    let opened = SceneDoc { characters: vec![CharacterDoc { id: Some(id), ..doc.clone() }], ..SceneDoc::default() };
    *app.world_mut().resource_mut::<marionette::editor::scene_doc::document::PendingScene>() =
        marionette::editor::scene_doc::document::PendingScene { doc: Some(opened), frame: false };
    app.update();
    app.update();
    let before = crate::edits::state(&mut app).0;
    let scene_now = |app: &App| app.world().resource::<crate::edits::Captured>().0.clone();
    let c = &before.characters[0];
    let asset = library.shaped(c).unwrap();
    let map = humanoid_map(&asset, &c.humanoid);
    let (pose, _) = marionette::document::scenes::pose_from_doc(&asset, c);
    let target = FitTarget {
        id,
        name: &c.name,
        source: &c.source,
        asset: &asset,
        map: &map,
        pose: &pose,
        placement: c.placement.to_mat4(),
    };
    let outcome = fit_outcome(&path, &target, &before.stage, before.shot).unwrap();
    assert!(outcome.message.contains("fitted to 12 points"), "{}", outcome.message);
    for edit in outcome.edits {
        app.world_mut().resource_mut::<EditQueue>().push(edit);
    }
    app.update();
    app.update();
    assert_eq!(app.world().resource::<History>().undo_steps(), 1, "one undo step");
    let after = scene_now(&app);
    let c = &after.characters[0];
    let (fitted, _) = marionette::document::scenes::pose_from_doc(&asset, c);
    let at = joints_world(&asset, &fitted, c.placement.to_mat4());
    let pinhole = Pinhole::of(&outcome.camera, SIZE.0, SIZE.1).unwrap();
    let true_at = joints_world(&asset, &truth.pose, truth.placement);
    let true_pinhole = Pinhole::of(&camera, SIZE.0, SIZE.1).unwrap();
    for bone in [LeftHand, RightHand, LeftFoot, RightFoot, LeftLowerArm, RightLowerLeg] {
        let (x, y, _) = pinhole.project(at[map[&bone]]).unwrap();
        let (tx, ty, _) = true_pinhole.project(true_at[map[&bone]]).unwrap();
        assert!(glam::Vec2::new(x - tx, y - ty).length() < 0.05, "{bone:?}: ({x}, {y}) vs ({tx}, {ty})");
    }
    assert_eq!((after.shot.width, after.shot.height), SIZE, "the shot at the picture's size");
    app.world_mut().resource_mut::<History>().request = Some(HistoryRequest::Undo);
    app.update();
    app.update();
    let undone = scene_now(&app);
    assert_eq!(undone.characters[0].pose, before.characters[0].pose);
    assert_eq!(undone.characters[0].placement, before.characters[0].placement);
    assert_eq!(undone.shot, before.shot);
}

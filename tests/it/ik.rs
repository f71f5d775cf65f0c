//! FABRIK, rotation-space IK, binding meshes without weights, Homer's rig.

use std::path::PathBuf;
use std::process::Command;

use glam::{Mat4, Vec3};
use marionette::document::posing::posed_positions;
use marionette::formats::load_character;
use marionette::rig::fk::forward_kinematics;
use marionette::rig::ik::{IkGoal, chain_to_sub_base, fabrik, solve_ik};
use marionette::rig::{JointRotation, RawJoint, Skeleton};

use crate::common::{data_dir, scratch};

fn lengths(p: &[Vec3]) -> Vec<f32> {
    p.windows(2).map(|w| w[0].distance(w[1])).collect()
}

fn assert_lengths_kept(before: &[Vec3], after: &[Vec3]) {
    for (a, b) in lengths(before).iter().zip(lengths(after)) {
        assert!((a - b).abs() <= 1e-5 * a.max(1e-3), "bone length {a} became {b}");
    }
}

#[test]
fn fabrik_reaches_reachable_targets_keeping_lengths() {
    let chain = [Vec3::ZERO, Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.0, 2.5, 0.0)];
    for target in [Vec3::new(1.0, 1.0, 0.5), Vec3::new(-0.5, 0.2, 1.2), Vec3::new(0.3, 2.0, 0.0)] {
        let r = fabrik(&chain, target, 1e-4, 100);
        assert!(r.reached, "{target}: distance {}", r.distance);
        assert!(r.iterations <= 100);
        assert!(r.positions[3].distance(target) <= 1e-4);
        assert_eq!(r.positions[0], chain[0], "the base stays");
        assert_lengths_kept(&chain, &r.positions);
    }
}

#[test]
fn fabrik_straightens_the_chain_towards_unreachable_targets() {
    let chain = [Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0)];
    let target = Vec3::new(0.0, 10.0, 0.0);
    let r = fabrik(&chain, target, 1e-4, 50);
    assert!(!r.reached);
    assert!((r.distance - 8.0).abs() < 1e-4);
    for p in &r.positions {
        assert!(p.x.abs() < 1e-5, "on the line to the target: {p}");
    }
    assert_lengths_kept(&chain, &r.positions);
}

fn arm() -> Skeleton {
    Skeleton::build(vec![
        RawJoint::new("root", None, Vec3::ZERO),
        RawJoint::new("shoulder", Some(0), Vec3::new(0.0, 1.0, 0.0)),
        RawJoint::new("elbow", Some(1), Vec3::new(1.0, 0.0, 0.0)),
        RawJoint::new("wrist", Some(2), Vec3::new(1.0, 0.0, 0.0)),
        RawJoint::new("hand", Some(3), Vec3::new(0.3, 0.0, 0.0)),
        RawJoint::new("leg", Some(0), Vec3::new(0.0, -1.0, 0.0)),
    ])
    .unwrap()
}

#[test]
fn chains_run_up_to_the_sub_base() {
    let s = arm();
    assert_eq!(chain_to_sub_base(&s, 4), vec![0, 1, 2, 3, 4]);
    assert_eq!(chain_to_sub_base(&s, 5), vec![0, 5]);
}

#[test]
fn solving_to_a_posed_end_position_lands_there() {
    let s = arm();
    let mut posed = s.rest_pose();
    posed[1] = JointRotation::euler_xyz(0.3, 0.2, 0.5);
    posed[2] = JointRotation::euler_xyz(0.0, 0.4, 0.9);
    posed[3] = JointRotation::euler_xyz(-0.2, 0.1, 0.3);
    let mut world = vec![Mat4::IDENTITY; s.len()];
    forward_kinematics(&s, &posed, Mat4::IDENTITY, &mut world);
    let target = world[4].w_axis.truncate();
    let mut pose = s.rest_pose();
    let reports = solve_ik(&s, &mut pose, Mat4::IDENTITY, &[IkGoal { end: 4, target }], 1e-4, 24);
    assert!(reports[0].reached, "{:?}", reports[0]);
    forward_kinematics(&s, &pose, Mat4::IDENTITY, &mut world);
    assert!(world[4].w_axis.truncate().distance(target) <= 1e-4);
    // The leg (another branch of the sub-base) did not move.
    assert_eq!(pose[5], JointRotation::IDENTITY);
    assert_eq!(pose[0], JointRotation::IDENTITY, "the sub-base does not rotate");
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn joint_limits_stop_the_knee_of_test_skel() {
    let data = data_dir();
    let asset = load_character(&data.join("cse169/project1/test.skel")).unwrap();
    let s = &asset.skeleton;
    let knee = s.find("knee_r").unwrap();
    // Drag the knee forward and up: the solve rotates what its chain allows and the knee's
    // own rotation stays within x in [-2, 0], y = z = 0.
    let mut pose = s.initial_pose();
    let mut world = vec![Mat4::IDENTITY; s.len()];
    forward_kinematics(s, &pose, Mat4::IDENTITY, &mut world);
    let target = world[knee].w_axis.truncate() + Vec3::new(0.0, 0.1, 0.25);
    let reports = solve_ik(s, &mut pose, Mat4::IDENTITY, &[IkGoal { end: knee, target }], 1e-4, 24);
    let a = pose[knee].to_euler(marionette::rig::EulerOrder::Xyz);
    assert!((-2.0 - 1e-5..=1e-5).contains(&a.x) && a.y.abs() < 1e-5 && a.z.abs() < 1e-5, "knee {a}");
    assert!(reports[0].distance.is_finite());
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn homer_exercise_examples_give_length_preserving_poses() {
    let data = data_dir();
    let asset = load_character(&data.join("homer/homerskel.json")).unwrap();
    let s = &asset.skeleton;
    let mut world = vec![Mat4::IDENTITY; s.len()];
    forward_kinematics(s, &s.rest_pose(), Mat4::IDENTITY, &mut world);
    let rest: Vec<Vec3> = world.iter().map(|m| m.w_axis.truncate()).collect();
    for (joint, delta) in [("Right_Forearm", Vec3::new(0.0, 0.2, 0.0)), ("Left_Shin", Vec3::new(-0.2, 0.1, 0.0))] {
        let end = s.find(joint).unwrap();
        let target = rest[end] + delta;
        let mut pose = s.rest_pose();
        let reports = solve_ik(s, &mut pose, Mat4::IDENTITY, &[IkGoal { end, target }], 1e-4, 24);
        let mut after = vec![Mat4::IDENTITY; s.len()];
        forward_kinematics(s, &pose, Mat4::IDENTITY, &mut after);
        let chain = chain_to_sub_base(s, end);
        let before_p: Vec<Vec3> = chain.iter().map(|&j| rest[j]).collect();
        let after_p: Vec<Vec3> = chain.iter().map(|&j| after[j].w_axis.truncate()).collect();
        assert_lengths_kept(&before_p, &after_p);
        let reachable = lengths(&before_p[1..]).iter().sum::<f32>() >= before_p[1].distance(target);
        if reachable {
            assert!(reports[0].reached, "{joint}: {:?}", reports[0]);
        } else {
            // Straightened towards the target: closer than at rest.
            assert!(after_p.last().unwrap().distance(target) < rest[end].distance(target));
        }
        // Joints outside the chain did not move.
        for j in 0..s.len() {
            if !chain.contains(&j) && !is_below(s, j, end) {
                assert!(after[j].w_axis.truncate().distance(rest[j]) < 1e-5, "{} moved", s.joint(j).name);
            }
        }
    }
}

fn is_below(s: &Skeleton, mut j: usize, root: usize) -> bool {
    while let Some(p) = s.parent(j) {
        if p == root {
            return true;
        }
        j = p;
    }
    false
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn bind_output_loads_back_and_poses_without_tearing() {
    let data = data_dir();
    let dir = scratch("bind");
    for f in ["Model1.skel", "Model1.obj"] {
        std::fs::copy(data.join("mit6837").join(f), dir.join(f)).unwrap();
    }
    for method in ["nearest", "smooth", "heat"] {
        let out = dir.join("Model1.attach");
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_marionette"));
        cmd.arg("bind").arg(dir.join("Model1.obj")).arg(dir.join("Model1.skel")).arg("--out").arg(&out);
        match method {
            // The old flag, kept for scripts; heat is the default.
            "smooth" => cmd.arg("--smooth"),
            "nearest" => cmd.args(["--method", "nearest"]),
            _ => &mut cmd,
        };
        assert!(cmd.status().unwrap().success());
        let asset = load_character(&dir.join("Model1.skel")).unwrap();
        assert_eq!(asset.vertex_count(), 13336);
        if method == "nearest" {
            assert_eq!(asset.skin.weights.max_influences(), 1);
        } else {
            assert!(asset.skin.weights.max_influences() > 1);
        }
        // Bend an elbow (joint 6 in the 6.837 layout) and measure the worst edge stretch.
        let mut pose = asset.skeleton.rest_pose();
        pose[6] = JointRotation::euler_xyz(0.0, 0.0, 1.2);
        let posed = posed_positions(&asset, &pose, Mat4::IDENTITY);
        let rest = &asset.skin.bind_positions;
        let worst = asset
            .skin
            .triangles
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .map(|(a, b)| {
                let (a, b) = (a as usize, b as usize);
                posed[a].distance(posed[b]) / rest[a].distance(rest[b]).max(1e-6)
            })
            .fold(0.0f32, f32::max);
        if method != "nearest" {
            assert!(worst < 4.0, "{method} binding stretches an edge {worst}×");
        }
        eprintln!("bind --method {method}: worst edge stretch {worst:.2}×");
    }
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn homer_rig_with_weights_loads_normalised() {
    let data = data_dir();
    let asset = load_character(&data.join("homer/homer.json")).unwrap();
    assert_eq!(asset.skeleton.len(), 18);
    assert_eq!(asset.skeleton.joint(0).name, "Root");
    assert_eq!(asset.vertex_count(), 10002);
    assert!(asset.warnings.iter().any(|w| w.contains("normalised")), "{:?}", asset.warnings);
    for v in 0..asset.vertex_count() {
        let sum: f32 = asset.skin.weights.of_vertex(v).iter().map(|i| i.weight).sum();
        assert!((sum - 1.0).abs() < 1e-5);
    }
    let skel = load_character(&data.join("homer/homerskel.json")).unwrap();
    assert_eq!(skel.skeleton.len(), 17);
    assert_eq!(skel.vertex_count(), 24421, "homerskel.json takes homer3x.off");
    // Parents come before children although the file's keys are not in that order.
    for j in 1..skel.skeleton.len() {
        assert!(skel.skeleton.parent(j).unwrap() < j);
    }
}

#[test]
fn rebinding_in_the_editor_replaces_the_weights_only() {
    use marionette::document::rebind;
    use marionette::formats::scene::BindingDoc;
    let puppet = marionette::formats::puppet::embedded_puppet();
    let rigid = rebind(&puppet, BindingDoc::Nearest);
    assert_eq!(rigid.skin.weights.max_influences(), 1);
    assert_eq!(rigid.skin.bind_positions, puppet.skin.bind_positions);
    assert_eq!(rigid.skeleton, puppet.skeleton);
    let smooth = rebind(&puppet, BindingDoc::Smooth);
    assert!(smooth.skin.weights.max_influences() > 1);
}

#[test]
fn a_limited_knee_stays_in_its_range_and_the_solve_says_so() {
    use marionette::rig::DofLimits;
    let mut knee = RawJoint::new("knee", Some(1), Vec3::new(0.0, -1.0, 0.0));
    // As test.skel's knee_r: x in [-2, 0], y and z locked.
    knee.limits = DofLimits { min: Vec3::new(-2.0, 0.0, 0.0), max: Vec3::new(0.0, 0.0, 0.0) };
    let s = Skeleton::build(vec![
        RawJoint::new("root", None, Vec3::ZERO),
        RawJoint::new("hip", Some(0), Vec3::new(0.1, 0.0, 0.0)),
        knee,
        RawJoint::new("ankle", Some(2), Vec3::new(0.0, -1.0, 0.0)),
        RawJoint::new("other_hip", Some(0), Vec3::new(-0.1, 0.0, 0.0)),
    ])
    .unwrap();
    // Reachable only by bending the knee forwards (positive x), which its limits forbid.
    for target in [Vec3::new(0.1, -1.2, 1.0), Vec3::new(0.1, -0.8, -0.9)] {
        let mut pose = s.rest_pose();
        let reports = solve_ik(&s, &mut pose, Mat4::IDENTITY, &[IkGoal { end: 3, target }], 1e-4, 24);
        let a = pose[2].to_euler(marionette::rig::EulerOrder::Xyz);
        assert!((-2.0 - 1e-5..=1e-5).contains(&a.x), "knee x {a}");
        assert!(a.y.abs() < 1e-5 && a.z.abs() < 1e-5, "locked axes moved: {a}");
        let mut world = vec![Mat4::IDENTITY; s.len()];
        forward_kinematics(&s, &pose, Mat4::IDENTITY, &mut world);
        let reached = world[3].w_axis.truncate().distance(target) <= 1e-4;
        assert_eq!(reached, reports[0].reached);
        if !reached {
            assert!(reports[0].limited, "a miss is explained by the limits: {:?}", reports[0]);
        }
    }
}

#[test]
fn bone_frames_follow_the_exercise() {
    use marionette::rig::bind::bone_frame;
    let (a, b) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 2.0));
    let m = bone_frame(a, b, Some(Vec3::new(0.0, 1.0, 1.0)));
    let (u, v, w, c) = (m.x_axis.truncate(), m.y_axis.truncate(), m.z_axis.truncate(), m.w_axis.truncate());
    assert!(w.abs_diff_eq(Vec3::Z, 1e-6), "w along the bone");
    assert!(v.abs_diff_eq(Vec3::Y, 1e-6), "v: the parent direction without its part along w");
    assert!(u.abs_diff_eq(v.cross(w), 1e-6) && u.abs_diff_eq(Vec3::X, 1e-6));
    assert!(c.abs_diff_eq(Vec3::new(1.0, 0.0, 1.0), 1e-6), "c the middle");
    assert_eq!(m.w_axis.w, 1.0);
    // At the root v comes from (0, 1, 0).
    let root = bone_frame(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), None);
    let v = root.y_axis.truncate();
    assert!(v.dot(root.z_axis.truncate()).abs() < 1e-6 && v.y > 0.0 && (v.length() - 1.0).abs() < 1e-6);
}

/// Two-bone IK on the Blender-made Mixamo and Unreal rigs' legs and arms: 10,000 random
/// reachable targets with random poles each, from their rest pose: the end on the target
/// (1e-4 of the limb), the middle joint within 0.5° of the plane of root, target and pole,
/// the bones' lengths kept (1e-6 of the limb).
#[test]
fn two_bone_ik_reaches_on_real_rigs_with_the_knee_toward_the_pole() {
    use marionette::rig::two_bone::{TwoBoneGoal, solve_two_bone};
    let rigs = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs");
    let limbs = [
        ("mixamo.glb", "mixamorig:LeftFoot"),
        ("mixamo.glb", "mixamorig:RightHand"),
        ("unreal.glb", "foot_r"),
        ("unreal.glb", "hand_l"),
    ];
    for (file, end_name) in limbs {
        let asset = load_character(&rigs.join(file)).unwrap();
        let skeleton = &asset.skeleton;
        let end = skeleton.find(end_name).unwrap();
        let mid = skeleton.parent(end).unwrap();
        let root = skeleton.parent(mid).unwrap();
        let placement = Mat4::from_translation(Vec3::new(0.5, 0.0, -0.2));
        let at = |pose: &[JointRotation]| {
            let mut world = vec![Mat4::IDENTITY; skeleton.len()];
            forward_kinematics(skeleton, pose, placement, &mut world);
            [root, mid, end].map(|j| world[j].w_axis.truncate())
        };
        let rest = at(&skeleton.initial_pose());
        let (upper, lower) = (rest[0].distance(rest[1]), rest[1].distance(rest[2]));
        let reach = upper + lower;
        let mut state = 11u64;
        let mut random = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        };
        let (mut worst_end, mut worst_plane, mut worst_length, mut solved) = (0.0f32, 0.0f32, 0.0f32, 0);
        while solved < 10_000 {
            let offset = Vec3::new(random(), random(), random());
            let target = rest[0] + offset * reach;
            let d = target.distance(rest[0]);
            if offset.length() > 1.0 || d < (upper - lower).abs() + 0.01 * reach || d > 0.999 * reach {
                continue;
            }
            let pole = rest[0] + Vec3::new(random(), random(), random()) * 2.0 * reach;
            let mut pose = skeleton.initial_pose();
            let goal = TwoBoneGoal { end, target, pole: Some(pole), soft: 0.0 };
            solve_two_bone(skeleton, &mut pose, placement, goal, 1e-4 * reach).unwrap();
            let [r, m, e] = at(&pose);
            worst_end = worst_end.max(e.distance(target) / reach);
            let normal = (target - r).cross(pole - r).normalize();
            worst_plane = worst_plane.max((m - r).normalize().dot(normal).abs().asin().to_degrees());
            worst_length =
                worst_length.max((r.distance(m) - upper).abs() / reach).max((m.distance(e) - lower).abs() / reach);
            solved += 1;
        }
        eprintln!("{file} {end_name}: end {worst_end:e}, plane {worst_plane:e}°, lengths {worst_length:e}");
        assert!(worst_end < 1e-4 && worst_plane < 0.5 && worst_length < 1e-6, "{file} {end_name}");
    }
}

/// `--two-bone JOINT=x,y,z@x,y,z` on `export`: the limb reaches (the note says so); a
/// joint no character has is refused by name, as `--ik` is.
#[test]
fn export_takes_two_bone_targets_and_refuses_unknown_joints() {
    let rig = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs/mixamo.glb");
    let out = scratch("two-bone").join("posed.obj");
    let run = |spec: &str| {
        Command::new(env!("CARGO_BIN_EXE_marionette"))
            .arg("export")
            .arg(&rig)
            .args(["--two-bone", spec, "--out"])
            .arg(&out)
            .output()
            .unwrap()
    };
    let asset = load_character(&rig).unwrap();
    let mut world = vec![Mat4::IDENTITY; asset.skeleton.len()];
    forward_kinematics(&asset.skeleton, &asset.skeleton.initial_pose(), Mat4::IDENTITY, &mut world);
    let foot = world[asset.skeleton.find("mixamorig:LeftFoot").unwrap()].w_axis.truncate();
    let target = foot + Vec3::new(0.0, 0.25, 0.2);
    let spec = format!(
        "mixamorig:LeftFoot={},{},{}@{},{},{}",
        target.x,
        target.y,
        target.z,
        foot.x,
        foot.y + 0.5,
        foot.z + 2.0
    );
    let output = run(&spec);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(stderr.contains("two-bone") && stderr.contains("reached"), "{stderr}");
    let output = run("nosuch=0,1,0");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success() && stderr.contains("--two-bone: no character has a joint"), "{stderr}");
    let output = run("mixamorig:LeftFoot=0,1,0@1,2");
    assert!(!output.status.success());
}

/// Look-at on the Mixamo, Unreal and VRoid rigs' heads: for targets all round, the face —
/// where the character faces at rest, carried by the head's frame (FK here) — points at the
/// target within 0.1°, the turn spread over chest and neck (which turn too).
#[test]
fn look_at_turns_a_humanoids_face_to_the_target() {
    use marionette::document::posing::{LookAtSpec, apply_look_at_specs};
    use marionette::rig::humanoid::{HumanBone, detect};
    let rigs = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs");
    for file in ["mixamo.glb", "unreal.glb", "vroid.glb"] {
        let asset = load_character(&rigs.join(file)).unwrap();
        let skeleton = &asset.skeleton;
        let map = detect(skeleton).unwrap();
        let (head, chest) = (map[&HumanBone::Head], map[&HumanBone::Chest]);
        let world_of = |pose: &[JointRotation]| {
            let mut world = vec![Mat4::IDENTITY; skeleton.len()];
            forward_kinematics(skeleton, pose, Mat4::IDENTITY, &mut world);
            world
        };
        let rest = world_of(&skeleton.initial_pose());
        let across = rest[map[&HumanBone::LeftUpperLeg]].w_axis - rest[map[&HumanBone::RightUpperLeg]].w_axis;
        let facing = across.truncate().cross(Vec3::Y).normalize();
        let rotation = marionette::rig::ik::rotation_of;
        let face = rotation(rest[head]).inverse() * facing;
        let eye = rest[head].w_axis.truncate();
        let mut worst = 0.0f32;
        for k in 0..100 {
            let a = k as f32 * 0.37;
            let target = eye + Vec3::new(2.0 * a.sin(), (a * 1.7).sin(), 2.0 * a.cos());
            let mut pose = skeleton.initial_pose();
            let spec = LookAtSpec { joint: skeleton.joint(head).name.clone(), target };
            apply_look_at_specs(skeleton, &map, &mut pose, Mat4::IDENTITY, &[spec]).unwrap();
            let world = world_of(&pose);
            let now = rotation(world[head]) * face;
            worst = worst.max(now.angle_between(target - world[head].w_axis.truncate()).to_degrees());
            if (target - eye).dot(facing) < 0.0 {
                assert_ne!(pose[chest], skeleton.initial_pose()[chest], "{file}: the chest takes a share");
            }
        }
        eprintln!("{file}: look-at worst {worst:e}°");
        assert!(worst < 0.1, "{file}: the face {worst}° off");
    }
}

/// `--hand SIDE=NAME` on `export`: the hand posed (the note says so); a side or preset that
/// does not exist is refused; `info` lists the presets of a rig with fingers.
#[test]
fn export_takes_hand_presets_and_info_lists_them() {
    let rig = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs/mixamo.glb");
    let out = scratch("hands").join("fist.obj");
    let run = |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_marionette")).args(args).output().unwrap();
    let (rig_path, out_path) = (rig.to_str().unwrap(), out.to_str().unwrap());
    let output = run(&["export", rig_path, "--hand", "left=fist", "--hand", "right=point", "--out", out_path]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(stderr.contains("hand left: fist") && stderr.contains("hand right: point"), "{stderr}");
    for bad in ["middle=fist", "left=disco", "fist"] {
        let output = run(&["export", rig_path, "--hand", bad, "--out", out_path]);
        assert!(!output.status.success() && String::from_utf8_lossy(&output.stderr).contains("left=NAME"), "{bad}");
    }
    let info = run(&["info", rig_path]);
    assert!(
        String::from_utf8_lossy(&info.stdout).contains("hand presets (--hand left=NAME, right=NAME): relaxed, fist")
    );
}

/// The viewport's limb handles on the Mixamo-named fixture, placed and turned: made where
/// the character stands (each limb's target at its end, the head's point ahead of it), a
/// moved target brings the wrist or ankle there (1e-4 of the limb) with the elbow or knee
/// in the plane of the limb's root, the target and the pole (0.5°); a moved look-at point
/// turns the face to it (0.1°).
#[test]
fn limb_handles_pose_the_limb_and_the_head_they_hold() {
    use marionette::editor::interact::limb_handles::handles_of;
    use marionette::editor::state::LimbHandle;
    use marionette::formats::scene::CharacterId;
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs/mixamo.glb");
    let asset = load_character(&path).unwrap();
    let skeleton = &asset.skeleton;
    let map = marionette::rig::humanoid::detect(skeleton).unwrap();
    let placement = Mat4::from_scale_rotation_translation(
        Vec3::splat(1.3),
        glam::Quat::from_rotation_y(0.7),
        Vec3::new(0.5, 0.0, -1.0),
    );
    let pose = skeleton.initial_pose();
    let world = |pose: &[JointRotation]| {
        let mut w = vec![Mat4::IDENTITY; skeleton.len()];
        forward_kinematics(skeleton, pose, placement, &mut w);
        w.iter().map(|m| m.w_axis.truncate()).collect::<Vec<_>>()
    };
    let rest = world(&pose);
    let ahead = placement.transform_vector3(Vec3::Z).normalize();
    let handles = handles_of(CharacterId(1), skeleton, &map, ahead, |j| rest[j]);
    assert_eq!(handles.len(), 5, "four limbs and the head");
    for handle in handles {
        let mut pose = pose.clone();
        match handle {
            LimbHandle::TwoBone { character, end, target, pole } => {
                assert!(target.distance(rest[end]) < 1e-6, "made at the limb's end");
                let mid = skeleton.parent(end).unwrap();
                let root = skeleton.parent(mid).unwrap();
                let length = rest[root].distance(rest[mid]) + rest[mid].distance(rest[end]);
                let moved = rest[root] + (target - rest[root]) * 0.8 + ahead * 0.1 * length;
                let moved_handle = LimbHandle::TwoBone { character, end, target: moved, pole };
                moved_handle.solve(skeleton, &map, &mut pose, placement).unwrap();
                let now = world(&pose);
                assert!(
                    now[end].distance(moved) < 1e-4 * length,
                    "{}: {}",
                    skeleton.joint(end).name,
                    now[end].distance(moved)
                );
                let normal = (moved - now[root]).cross(pole - now[root]).normalize();
                let off = (now[mid] - now[root]).normalize().dot(normal).asin().to_degrees().abs();
                assert!(off < 0.5, "{}: the middle joint {off}° off the plane", skeleton.joint(end).name);
            }
            LimbHandle::LookAt { character, head, target } => {
                let moved = target + Vec3::new(0.6, 0.4, 0.0);
                let moved_handle = LimbHandle::LookAt { character, head, target: moved };
                let note = moved_handle.solve(skeleton, &map, &mut pose, placement).unwrap();
                let off: f32 = note
                    .split("face ")
                    .nth(1)
                    .and_then(|s| s.split('°').next())
                    .and_then(|s| s.trim().parse().ok())
                    .unwrap_or(f32::NAN);
                assert!(off < 0.1, "the face {off}° off the point ({note})");
            }
        }
    }
}

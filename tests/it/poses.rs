//! Poses by name: mirroring (twice is nothing; a mirrored pose is the mirror image), and a
//! kept pose reapplied gives the same matrices.

use glam::{Mat4, Quat, Vec3};
use marionette::editor::edits::kinds;
use marionette::editor::edits::pose_library::{apply_named_pose, library_pose, pose_by_name};
use marionette::formats::scene::CharacterId;
use marionette::rig::mirror::{mirrored_name, mirrored_pose, mirrored_rotation};
use marionette::rig::{EulerOrder, JointRotation, forward_kinematics};

#[test]
fn names_pair_by_every_convention_and_mirroring_twice_is_nothing() {
    for (a, b) in [
        ("l_elbow", "r_elbow"),
        ("L_Knee", "R_Knee"),
        ("hand.L", "hand.R"),
        ("hip_01_l", "hip_01_r"),
        ("LeftUpLeg", "RightUpLeg"),
        ("upper_arm_L", "upper_arm_R"),
    ] {
        assert_eq!(mirrored_name(a).as_deref(), Some(b));
        assert_eq!(mirrored_name(b).as_deref(), Some(a));
    }
    assert_eq!(mirrored_name("spine"), None, "a joint on the middle has no other side");
    let pose = vec![
        ("l_elbow".to_string(), JointRotation::Euler(Vec3::new(0.1, -0.4, 0.9), EulerOrder::Zyx)),
        ("chest".to_string(), JointRotation::Quat(Quat::from_euler(glam::EulerRot::XYZ, 0.2, 0.3, -0.1))),
    ];
    assert_eq!(mirrored_pose(&mirrored_pose(&pose)), pose, "twice is the identity, exactly");
}

/// Reflecting a rotation is conjugating it by diag(−1, 1, 1).
#[test]
fn a_mirrored_rotation_is_the_reflected_matrix() {
    let m = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
    for r in [
        JointRotation::Euler(Vec3::new(0.3, -0.5, 1.2), EulerOrder::Xyz),
        JointRotation::Euler(Vec3::new(-0.2, 0.7, 0.4), EulerOrder::Yzx),
        JointRotation::Quat(Quat::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), 0.8)),
    ] {
        let want = m * Mat4::from_mat3(r.to_mat3()) * m;
        let got = Mat4::from_mat3(mirrored_rotation(&r).to_mat3());
        assert!(got.abs_diff_eq(want, 1e-6), "{r:?}");
    }
}

/// The puppet is symmetric: its left arm posed, copied and pasted mirrored on a puppet at
/// rest puts the right hand where the left one was, reflected across x = 0.
#[test]
fn paste_mirrored_puts_the_other_arm_in_the_mirror_image() {
    let puppet = marionette::formats::puppet::embedded_puppet();
    let skeleton = &puppet.skeleton;
    let rest = skeleton.initial_pose();
    let mut posed = rest.clone();
    for (name, r) in [("l_shoulder", (0.3, -0.6, 1.1)), ("l_elbow", (0.0, -1.2, 0.2)), ("l_wrist", (0.4, 0.1, -0.3))] {
        posed[skeleton.find(name).unwrap()] = JointRotation::euler_xyz(r.0, r.1, r.2);
    }
    let left =
        [skeleton.find("l_shoulder").unwrap(), skeleton.find("l_elbow").unwrap(), skeleton.find("l_wrist").unwrap()];
    let copied = pose_by_name(skeleton, &posed, &left);
    let Some(kinds::Pose { joints, .. }) = apply_named_pose(
        CharacterId(1),
        (skeleton, &Default::default(), &skeleton.initial_pose()),
        &copied,
        None,
        true,
    )
    .and_then(|e| e.get::<kinds::Pose>().cloned()) else {
        panic!()
    };
    let mut mirrored = rest.clone();
    joints.iter().for_each(|&(j, r)| mirrored[j] = r);
    let fk = |pose: &[JointRotation]| {
        let mut m = vec![Mat4::IDENTITY; skeleton.len()];
        forward_kinematics(skeleton, pose, Mat4::IDENTITY, &mut m);
        m
    };
    let (a, b) = (fk(&posed), fk(&mirrored));
    for (l, r) in [("l_elbow", "r_elbow"), ("l_wrist", "r_wrist"), ("l_hand", "r_hand")] {
        let p = a[skeleton.find(l).unwrap()].w_axis.truncate();
        let q = b[skeleton.find(r).unwrap()].w_axis.truncate();
        assert!((q - Vec3::new(-p.x, p.y, p.z)).length() < 1e-5, "{r} at {q}, {l} at {p}");
    }
}

/// A pose kept in the library and applied again gives the very same joint matrices.
#[test]
fn a_kept_pose_reapplied_gives_the_same_matrices() {
    let puppet = marionette::formats::puppet::embedded_puppet();
    let skeleton = &puppet.skeleton;
    let mut posed = skeleton.initial_pose();
    posed[skeleton.find("r_knee").unwrap()] = JointRotation::euler_xyz(0.9, 0.0, 0.0);
    posed[0] = JointRotation::Quat(Quat::from_rotation_y(0.4));
    let mut before = vec![Mat4::IDENTITY; skeleton.len()];
    forward_kinematics(skeleton, &posed, Mat4::IDENTITY, &mut before);
    let positions: Vec<Vec3> = before.iter().map(|m| m.w_axis.truncate()).collect();
    let kept = library_pose(skeleton, &positions, pose_by_name(skeleton, &posed, &[]));
    assert_eq!(kept.thumbnail.len(), skeleton.len() - 1, "a segment per bone");
    assert!(kept.thumbnail.iter().flatten().all(|v| (-1e-6..=1.0 + 1e-6).contains(v)));
    let named: Vec<_> = kept.joints.into_iter().collect();
    let Some(kinds::Pose { joints, .. }) = apply_named_pose(
        CharacterId(1),
        (skeleton, &Default::default(), &skeleton.initial_pose()),
        &named,
        None,
        false,
    )
    .and_then(|e| e.get::<kinds::Pose>().cloned()) else {
        panic!()
    };
    let mut again = skeleton.initial_pose();
    joints.iter().for_each(|&(j, r)| again[j] = r);
    let mut after = vec![Mat4::IDENTITY; skeleton.len()];
    forward_kinematics(skeleton, &again, Mat4::IDENTITY, &mut after);
    assert_eq!(before, after);
}

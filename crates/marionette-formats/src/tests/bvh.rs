//! BVH motion capture (our own fixture, `tests/data/steps.bvh`): the skeleton, rotation
//! channels composed outermost first, playing on another character by joint names.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use crate::bvh::parse_bvh;
use glam::{Mat3, Vec3};

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/steps.bvh")
}

fn steps() -> crate::bvh::BvhFile {
    let path = fixture();
    parse_bvh(std::io::BufReader::new(std::fs::File::open(&path).unwrap()), &path).unwrap()
}

#[test]
fn the_skeleton_and_frames_read_with_end_sites_as_tips() {
    let bvh = steps();
    let names: Vec<&str> = bvh.skeleton.joints().iter().map(|j| j.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "Hips",
            "Spine",
            "Head",
            "Head_end",
            "LeftUpLeg",
            "LeftLeg",
            "LeftLeg_end",
            "RightUpLeg",
            "RightLeg",
            "RightLeg_end"
        ]
    );
    assert_eq!(bvh.skeleton.joint(5).rest_offset, Vec3::new(0.0, -18.0, 0.0));
    assert_eq!(bvh.frame_time, 0.5);
    assert_eq!(bvh.clip.range, (0.0, 1.5));
    // The root's position channels: x 0, 2, 4, 6 at 0, 0.5, 1, 1.5 s.
    let x: Vec<f32> = bvh.clip.channels[0].keys().iter().map(|k| k.value).collect();
    assert_eq!(x, [0.0, 2.0, 4.0, 6.0]);
    let (root, _) = bvh.clip.pose_at(&bvh.skeleton, 0.25, &bvh.skeleton.initial_pose());
    assert!((root - Vec3::new(1.0, 35.25, 0.0)).length() < 1e-5, "linear between frames: {root}");
}

/// `Zrotation Xrotation Yrotation` with values z, x, y (degrees) is Rz(z) · Rx(x) · Ry(y).
#[test]
fn rotation_channels_compose_outermost_first() {
    let bvh = steps();
    let (_, pose) = bvh.clip.pose_at(&bvh.skeleton, 0.5, &bvh.skeleton.initial_pose());
    for (joint, (z, x, y)) in [(4, (5.0f32, -10.0f32, 15.0f32)), (5, (10.0, 40.0, -20.0)), (0, (3.0, 0.0, 10.0))] {
        let want = Mat3::from_rotation_z(z.to_radians())
            * Mat3::from_rotation_x(x.to_radians())
            * Mat3::from_rotation_y(y.to_radians());
        let got = pose[joint].to_mat3();
        assert!(got.abs_diff_eq(want, 1e-5), "joint {joint}: {got:?} vs {want:?}");
    }
}

/// A puppet plays the clip by a name map (its `l_knee` is the BVH's `LeftLeg`): that joint
/// turns as the BVH's does; joints without a partner keep their pose.
#[test]
fn another_character_plays_it_by_a_name_map() {
    let bvh = steps();
    let puppet = crate::puppet::embedded_puppet();
    let skeleton = &puppet.skeleton;
    let names = BTreeMap::from([("l_knee".to_string(), "LeftLeg".to_string())]);
    let clip = bvh.clip.retargeted(skeleton, &names);
    assert_eq!(clip.channels.len(), 3 + 3 * skeleton.len());
    let rest = skeleton.initial_pose();
    let (root, pose) = clip.pose_at(skeleton, 0.5, &rest);
    let knee = skeleton.find("l_knee").unwrap();
    let (_, theirs) = bvh.clip.pose_at(&bvh.skeleton, 0.5, &bvh.skeleton.initial_pose());
    assert!(pose[knee].to_mat3().abs_diff_eq(theirs[5].to_mat3(), 1e-5));
    for (j, r) in pose.iter().enumerate().filter(|&(j, _)| j != knee) {
        assert_eq!(*r, rest[j], "joint {j} has no partner and keeps its pose");
    }
    assert_eq!(root, skeleton.joint(0).rest_offset, "the root is not the clip's: it stays");
}

#[test]
fn bad_bvh_names_the_line() {
    let text = std::fs::read_to_string(fixture()).unwrap();
    for (broken, line) in [
        (
            text.replace("Zrotation Xrotation Yrotation\n\t\tJOINT Head", "Zrotation Xturn Yrotation\n\t\tJOINT Head"),
            "steps.bvh:9",
        ),
        (text.replace("Frames: 4", "Frames: 5"), "steps.bvh:55"),
        (text.replace("Frame Time: 0.5", "Frame Time: 0"), "steps.bvh:"),
    ] {
        let e = parse_bvh(Cursor::new(broken), Path::new("steps.bvh")).unwrap_err().to_string();
        assert!(e.contains(line), "{e}");
    }
}

//! Poses kept by name: the scene's pose library (saved in the scene file, with a stick
//! figure thumbnail), and copying a pose (or the selected joints') to paste on any
//! character with the same joint names, as it was or mirrored left to right.

use std::collections::BTreeMap;

use bevy::prelude::*;

use crate::formats::scene::{CharacterId, LibraryPoseDoc, pose_key};
use crate::rig::mirror::mirrored_pose;
use crate::rig::{JointRotation, Skeleton};

use crate::editor::edits::edit::Edit;

/// The scene's poses by name (the scene file's `poses`).
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct PoseLibrary(pub BTreeMap<String, LibraryPoseDoc>);

/// The rotations of `joints` (every joint when none is given) by joint name.
pub fn pose_by_name(skeleton: &Skeleton, pose: &[JointRotation], joints: &[usize]) -> Vec<(String, JointRotation)> {
    let all: Vec<usize> = (0..skeleton.len()).collect();
    let joints = if joints.is_empty() { &all[..] } else { joints };
    joints.iter().filter_map(|&j| Some((pose_key(skeleton, j), *pose.get(j)?))).collect()
}

/// A library entry for these rotations, with a thumbnail of the posed bones (model-space
/// joint positions) seen from the front, fitted into a unit square.
pub fn library_pose(skeleton: &Skeleton, positions: &[Vec3], joints: Vec<(String, JointRotation)>) -> LibraryPoseDoc {
    let (lo, hi) = positions
        .iter()
        .fold((Vec2::INFINITY, Vec2::NEG_INFINITY), |(a, b), p| (a.min(p.truncate()), b.max(p.truncate())));
    let size = (hi - lo).max_element().max(1e-6);
    let centre = (lo + hi) / 2.0;
    let fit = |p: Vec3| (p.truncate() - centre) / size + Vec2::splat(0.5);
    let thumbnail = (0..skeleton.len())
        .filter_map(|j| {
            let parent = skeleton.parent(j)?;
            let (a, b) = (fit(*positions.get(parent)?), fit(*positions.get(j)?));
            Some([a.x, a.y, b.x, b.y])
        })
        .collect();
    LibraryPoseDoc { joints: joints.into_iter().collect(), thumbnail }
}

/// The pose edit that gives character `id` (of `skeleton`) the rotations named in `pose`,
/// mirrored left to right when asked; joints it does not have are skipped.
pub fn apply_named_pose(
    id: CharacterId,
    skeleton: &Skeleton,
    pose: &[(String, JointRotation)],
    mirrored: bool,
) -> Option<Edit> {
    let pose = if mirrored { mirrored_pose(pose) } else { pose.to_vec() };
    let joints: Vec<(usize, JointRotation)> = pose
        .iter()
        .filter_map(|(name, r)| Some((crate::formats::scene::joint_of_pose_key(skeleton, name)?, *r)))
        .collect();
    (!joints.is_empty()).then_some(Edit::Pose { character: id, joints })
}

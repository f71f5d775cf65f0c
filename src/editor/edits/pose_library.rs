//! Poses kept by name: the scene's pose library (saved in the scene file, with a stick
//! figure thumbnail), and copying a pose (or the selected joints') to paste on any
//! character with the same joint names, or through the humanoid maps onto any other, as
//! it was or mirrored left to right.

use crate::editor::edits::edit;
use bevy::prelude::*;

use crate::formats::scene::{CharacterId, LibraryPoseDoc, pose_key};
use crate::rig::humanoid::HumanoidMap;
use crate::rig::{JointRotation, Skeleton};

use crate::editor::edits::edit::Edit;

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
    LibraryPoseDoc { joints: joints.into_iter().collect(), thumbnail, rig: None }
}

/// The pose edit that gives character `id` (of `target`: its skeleton, humanoid map and
/// current pose)
/// the rotations named in `pose`, mirrored left to right when asked: by name, or through
/// the humanoid maps from `source` (the rig the names are of) where the target lacks the
/// names; none when nothing applies.
pub fn apply_named_pose(
    id: CharacterId,
    target: (&Skeleton, &HumanoidMap, &[JointRotation]),
    pose: &[(String, JointRotation)],
    source: Option<(&Skeleton, &HumanoidMap)>,
    mirrored: bool,
) -> Option<Edit> {
    let (skeleton, map, current) = target;
    let joints = crate::document::retarget::pose_onto((skeleton, map), current, pose, source, mirrored);
    (!joints.is_empty()).then_some(Edit::Pose(edit::Pose { character: id, joints }))
}

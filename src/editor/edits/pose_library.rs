//! Poses kept by name: the scene's pose library (saved in the scene file, with a stick
//! figure thumbnail), and copying a pose (or the selected joints') to paste on any
//! character with the same joint names, or through the humanoid maps onto any other, as
//! it was or mirrored left to right.

use crate::editor::edits::kinds;
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
    (!joints.is_empty()).then_some(Edit::from(kinds::Pose { character: id, joints }))
}

/// The edits that put the built-in body pose `spec` on character `id` (of `asset`, its
/// humanoid map `map`, its pose now and its placement), blended from the pose now by
/// `blend`: its joints, and its placement stood on the floor. One gesture, so one undo
/// step. None when the map lacks hips or legs.
pub fn body_pose_edits(
    id: CharacterId,
    target: (&crate::rig::CharacterAsset, &HumanoidMap, &[JointRotation]),
    placement: crate::formats::scene::PlacementDoc,
    spec: &crate::document::posing::BodyPoseSpec,
    blend: f32,
) -> Option<Vec<Edit>> {
    let (asset, map, current) = target;
    let (posed, _) = crate::document::posing::body_posed(&asset.skeleton, map, current, spec, blend)?;
    let stood = crate::document::posing::stood_on_floor(asset, &posed, placement.to_mat4());
    let place = kinds::Place { character: id, placement: crate::formats::scene::PlacementDoc::from_mat4(stood) };
    Some(kinds::Pose::change(id, current, &posed).map(Edit::from).into_iter().chain([place.into()]).collect())
}

/// The edit that flips character `id`'s pose left to right through its humanoid map (see
/// `rig::mirror::flipped_pose`); none without hips and legs in the map, or when the flip
/// changes nothing.
pub fn flip_edit(id: CharacterId, skeleton: &Skeleton, map: &HumanoidMap, current: &[JointRotation]) -> Option<Edit> {
    let left = crate::rig::body_poses::facing_frame(skeleton, map)? * Vec3::X;
    let twin = crate::rig::mirror::counterparts(skeleton, map);
    let flipped = crate::rig::mirror::flipped_pose(skeleton, &twin, current, left);
    kinds::Pose::change(id, current, &flipped).map(Edit::from)
}

/// A stick-figure thumbnail of each built-in body pose on this character.
pub fn body_pose_thumbnails(skeleton: &Skeleton, map: &HumanoidMap) -> Vec<LibraryPoseDoc> {
    crate::rig::body_poses::POSES
        .iter()
        .filter_map(|body| {
            let mut pose = skeleton.initial_pose();
            crate::rig::body_poses::apply_body_pose(skeleton, map, &mut pose, body, false)?;
            let mut world = vec![Mat4::IDENTITY; skeleton.len()];
            crate::rig::fk::forward_kinematics(skeleton, &pose, Mat4::IDENTITY, &mut world);
            let positions: Vec<Vec3> = world.iter().map(|m| m.w_axis.truncate()).collect();
            Some(library_pose(skeleton, &positions, Vec::new()))
        })
        .collect()
}

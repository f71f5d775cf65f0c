//! Forward kinematics over a flat skeleton with the matrix stack.

use glam::{Mat4, Vec3};

use super::matrix_stack::MatrixStack;
use super::pose::JointRotation;
use super::skeleton::Skeleton;

/// Fills `joint_to_world[j]` for every joint: a depth-first walk from the root that
/// pushes each joint's local transform (`T(offset) · R(pose) · S(rest scale)`), writes the top, recurses
/// into the children and pops. `placement` (model → world) starts the stack.
///
/// # Panics
/// When `pose` or `joint_to_world` is not one entry per joint.
pub fn forward_kinematics(skeleton: &Skeleton, pose: &[JointRotation], placement: Mat4, joint_to_world: &mut [Mat4]) {
    forward_kinematics_with_rest(skeleton, pose, RestOverride::default(), placement, joint_to_world)
}

/// Per-joint rest offsets and scales that replace the skeleton's (a reshaped skeleton, or
/// a clip that keys them); none keeps the skeleton's.
#[derive(Debug, Clone, Copy, Default)]
pub struct RestOverride<'a> {
    pub offsets: Option<&'a [Vec3]>,
    pub scales: Option<&'a [Vec3]>,
}

impl<'a> RestOverride<'a> {
    /// Only the offsets replaced.
    pub fn offsets(offsets: &'a [Vec3]) -> Self {
        Self { offsets: Some(offsets), scales: None }
    }
}

/// As [`forward_kinematics`], with the rest offsets and scales `rest` replaces.
///
/// # Panics
/// When `pose`, `joint_to_world` or a replacement is not one entry per joint.
pub fn forward_kinematics_with_rest(
    skeleton: &Skeleton,
    pose: &[JointRotation],
    rest: RestOverride,
    placement: Mat4,
    joint_to_world: &mut [Mat4],
) {
    let n = skeleton.len();
    assert_eq!(pose.len(), n, "one pose entry per joint");
    assert_eq!(joint_to_world.len(), n, "one output matrix per joint");
    for replaced in [rest.offsets, rest.scales].into_iter().flatten() {
        assert_eq!(replaced.len(), n, "one offset or scale per joint");
    }
    let mut stack = MatrixStack::with_capacity(n + 1);
    stack.push(placement);
    let local = |j: usize| {
        let joint = skeleton.joint(j);
        let offset = rest.offsets.map_or(joint.rest_offset, |o| o[j]);
        match rest.scales {
            Some(s) => pose[j].local_transform(offset) * Mat4::from_scale(s[j]),
            None => joint.local_transform(&pose[j], offset),
        }
    };
    // Explicit DFS: (joint, entering?) so each push is matched by one pop.
    let mut todo = vec![(0usize, true)];
    while let Some((j, entering)) = todo.pop() {
        if entering {
            joint_to_world[j] = stack.push(local(j));
            todo.push((j, false));
            todo.extend(skeleton.children(j).iter().rev().map(|&c| (c, true)));
        } else {
            stack.pop();
        }
    }
}

/// Forward kinematics along `path`, a parent-to-child run of joints: each joint's matrix
/// is its parent's (already in `joint_to_world`, or `placement` for the root) times its
/// local transform. What IK uses after turning one joint of a chain: O(path), not O(joints).
///
/// # Panics
/// When a joint of `path` is out of range of `pose` or `joint_to_world`.
pub fn forward_kinematics_along(
    skeleton: &Skeleton,
    pose: &[JointRotation],
    placement: Mat4,
    path: &[usize],
    joint_to_world: &mut [Mat4],
) {
    for &j in path {
        let parent = skeleton.parent(j).map_or(placement, |p| joint_to_world[p]);
        let joint = skeleton.joint(j);
        joint_to_world[j] = parent * joint.local_transform(&pose[j], joint.rest_offset);
    }
}

/// The bind pass: world-to-joint matrices at the rest pose (the inverse of the rest
/// joint-to-world), in model space (identity placement).
pub fn bind_world_to_joint(skeleton: &Skeleton, offsets: Option<&[Vec3]>) -> Vec<Mat4> {
    let mut rest = vec![Mat4::IDENTITY; skeleton.len()];
    let replaced = RestOverride { offsets, scales: None };
    forward_kinematics_with_rest(skeleton, &skeleton.rest_pose(), replaced, Mat4::IDENTITY, &mut rest);
    rest.iter().map(Mat4::inverse).collect()
}

/// World positions of the joints (the translation of each joint-to-world matrix).
pub fn joint_positions(joint_to_world: &[Mat4]) -> Vec<Vec3> {
    joint_to_world.iter().map(|m| m.w_axis.truncate()).collect()
}

/// The skinning palette of `skeleton` at `pose`, placed by `placement`: forward
/// kinematics, then each joint's current transform times its inverse bind.
pub fn posed_palette(
    skeleton: &Skeleton,
    bind_world_to_joint: &[Mat4],
    pose: &[JointRotation],
    placement: Mat4,
) -> Vec<Mat4> {
    posed_palette_with_rest(skeleton, bind_world_to_joint, pose, RestOverride::default(), placement)
}

/// As [`posed_palette`], with the rest offsets and scales `rest` replaces (a clip keys
/// them).
pub fn posed_palette_with_rest(
    skeleton: &Skeleton,
    bind_world_to_joint: &[Mat4],
    pose: &[JointRotation],
    rest: RestOverride,
    placement: Mat4,
) -> Vec<Mat4> {
    let n = skeleton.len();
    let mut current = vec![Mat4::IDENTITY; n];
    forward_kinematics_with_rest(skeleton, pose, rest, placement, &mut current);
    let mut palette = vec![Mat4::IDENTITY; n];
    skinning_palette(&current, bind_world_to_joint, &mut palette);
    palette
}

/// Skinning palette: `current_joint_to_world[j] · bind_world_to_joint[j]`.
pub fn skinning_palette(current_joint_to_world: &[Mat4], bind_world_to_joint: &[Mat4], palette: &mut [Mat4]) {
    assert_eq!(current_joint_to_world.len(), bind_world_to_joint.len());
    assert_eq!(palette.len(), bind_world_to_joint.len());
    for ((p, c), b) in palette.iter_mut().zip(current_joint_to_world).zip(bind_world_to_joint) {
        *p = *c * *b;
    }
}

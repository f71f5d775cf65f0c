//! Forward kinematics over a flat skeleton with the matrix stack.

use glam::{Mat4, Vec3};

use super::matrix_stack::MatrixStack;
use super::pose::JointRotation;
use super::skeleton::Skeleton;

/// Fills `joint_to_world[j]` for every joint: a depth-first walk from the root that
/// pushes each joint's local transform (`T(offset) · R(pose)`), writes the top, recurses
/// into the children and pops. `placement` (model → world) starts the stack.
///
/// # Panics
/// When `pose` or `joint_to_world` is not one entry per joint.
pub fn forward_kinematics(skeleton: &Skeleton, pose: &[JointRotation], placement: Mat4, joint_to_world: &mut [Mat4]) {
    forward_kinematics_with_offsets(skeleton, pose, None, placement, joint_to_world)
}

/// As [`forward_kinematics`], with optional per-joint rest offsets replacing the
/// skeleton's (a reshaped or translated skeleton).
pub fn forward_kinematics_with_offsets(
    skeleton: &Skeleton,
    pose: &[JointRotation],
    offsets: Option<&[Vec3]>,
    placement: Mat4,
    joint_to_world: &mut [Mat4],
) {
    let n = skeleton.len();
    assert_eq!(pose.len(), n, "one pose entry per joint");
    assert_eq!(joint_to_world.len(), n, "one output matrix per joint");
    if let Some(o) = offsets {
        assert_eq!(o.len(), n, "one offset per joint");
    }
    let mut stack = MatrixStack::with_capacity(n + 1);
    stack.push(placement);
    let offset = |j: usize| offsets.map_or(skeleton.joint(j).rest_offset, |o| o[j]);
    // Explicit DFS: (joint, entering?) so each push is matched by one pop.
    let mut todo = vec![(0usize, true)];
    while let Some((j, entering)) = todo.pop() {
        if entering {
            joint_to_world[j] = stack.push(pose[j].local_transform(offset(j)));
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
        joint_to_world[j] = parent * pose[j].local_transform(skeleton.joint(j).rest_offset);
    }
}

/// The bind pass: world-to-joint matrices at the rest pose (the inverse of the rest
/// joint-to-world), in model space (identity placement).
pub fn bind_world_to_joint(skeleton: &Skeleton, offsets: Option<&[Vec3]>) -> Vec<Mat4> {
    let mut rest = vec![Mat4::IDENTITY; skeleton.len()];
    forward_kinematics_with_offsets(skeleton, &skeleton.rest_pose(), offsets, Mat4::IDENTITY, &mut rest);
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
    let n = skeleton.len();
    let mut current = vec![Mat4::IDENTITY; n];
    forward_kinematics(skeleton, pose, placement, &mut current);
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

//! Look-at: a head turned so that its face points at a target, the turn optionally spread
//! over the joints above it (neck, chest), each taking a share of what is left.

use glam::{Mat4, Quat, Vec3};

use crate::fk::forward_kinematics;
use crate::{JointRotation, Skeleton};

/// The share of the turn the chest and then the neck take when a humanoid's look-at
/// spreads over them.
pub const LOOK_AT_SHARES: [f32; 2] = [0.2, 0.35];

/// What a look-at did.
#[derive(Debug, Clone, PartialEq)]
pub struct LookAtReport {
    /// The joints turned, the head last.
    pub joints: Vec<usize>,
    /// The angle between the face and the target after the turn (degrees).
    pub off_degrees: f32,
    /// Some rotation was clamped by its joint's limits.
    pub limited: bool,
}

/// The direction the character faces in its model space at rest: square to the line from
/// its right hip to its left hip and to up (+y).
pub fn facing(right_hip: Vec3, left_hip: Vec3) -> Vec3 {
    (left_hip - right_hip).cross(Vec3::Y).normalize_or(Vec3::Z)
}

/// Turns `joints` (from the highest, e.g. chest, neck, head, down to the head; each below
/// the one before) so that the last one's `face` (a direction in its own frame: where its
/// face points) points at `target` (world space). Each joint but the head takes its share
/// of the turn still left (`shares`, one per joint but the head; the head takes the rest),
/// the smallest rotation that turns the face toward the target, in the joint's own
/// rotation type, clamped to its limits.
pub fn solve_look_at(
    skeleton: &Skeleton,
    pose: &mut [JointRotation],
    placement: Mat4,
    joints: &[usize],
    face: Vec3,
    shares: &[f32],
    target: Vec3,
) -> LookAtReport {
    let mut world = vec![Mat4::IDENTITY; skeleton.len()];
    let Some(&head) = joints.last() else {
        return LookAtReport { joints: Vec::new(), off_degrees: 0.0, limited: false };
    };
    let mut limited = false;
    for (k, &joint) in joints.iter().enumerate() {
        forward_kinematics(skeleton, pose, placement, &mut world);
        let eye = world[head].w_axis.truncate();
        let now = crate::ik::rotation_of(world[head]) * face;
        let wanted = target - eye;
        if now.length_squared() < 1e-12 || wanted.length_squared() < 1e-12 {
            break;
        }
        let share = shares.get(k).copied().unwrap_or(1.0).clamp(0.0, 1.0);
        let share = if joint == head { 1.0 } else { share };
        let turn = Quat::IDENTITY.slerp(Quat::from_rotation_arc(now.normalize(), wanted.normalize()), share);
        let parent_world = skeleton.parent(joint).map_or(placement, |q| world[q]);
        limited |= crate::ik::turn_joint(skeleton, pose, joint, parent_world, turn);
    }
    forward_kinematics(skeleton, pose, placement, &mut world);
    let eye = world[head].w_axis.truncate();
    let now = crate::ik::rotation_of(world[head]) * face;
    let off_degrees = now.angle_between(target - eye).to_degrees();
    LookAtReport { joints: joints.to_vec(), off_degrees, limited }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::RawJoint;

    /// Chest, neck and head over hips, turned at rest; the face is +z of the model at rest.
    fn upper_body() -> Skeleton {
        let mut joints = vec![
            RawJoint::new("hips", None, Vec3::new(0.0, 1.0, 0.0)),
            RawJoint::new("chest", Some(0), Vec3::new(0.0, 0.3, 0.0)),
            RawJoint::new("neck", Some(1), Vec3::new(0.0, 0.25, 0.02)),
            RawJoint::new("head", Some(2), Vec3::new(0.0, 0.1, 0.0)),
        ];
        joints[2].initial_rotation = JointRotation::euler_xyz(0.2, -0.3, 0.1);
        joints[3].initial_rotation = JointRotation::Quat(Quat::from_euler(glam::EulerRot::XYZ, -0.1, 0.4, 0.0));
        Skeleton::build(joints).unwrap()
    }

    /// The head's face at rest, in its own frame, for a character facing +z.
    fn face(skeleton: &Skeleton) -> Vec3 {
        let mut world = vec![Mat4::IDENTITY; skeleton.len()];
        forward_kinematics(skeleton, &skeleton.initial_pose(), Mat4::IDENTITY, &mut world);
        crate::ik::rotation_of(world[3]).inverse() * Vec3::Z
    }

    /// Targets all round: the face points at each within 0.1°, the head alone or spread
    /// over neck and chest (which then turn too).
    #[test]
    fn the_face_turns_to_the_target() {
        let skeleton = upper_body();
        let face = face(&skeleton);
        let mut worst = 0.0f32;
        for k in 0..200 {
            let a = k as f32 * 0.7;
            let target = Vec3::new(3.0 * a.sin(), 1.6 + (a * 1.3).sin(), 3.0 * a.cos());
            for (joints, shares) in [(vec![3], vec![]), (vec![1, 2, 3], vec![0.3, 0.5])] {
                let mut pose = skeleton.initial_pose();
                let report = solve_look_at(&skeleton, &mut pose, Mat4::IDENTITY, &joints, face, &shares, target);
                worst = worst.max(report.off_degrees);
                if joints.len() == 3 && target.z < 0.0 {
                    assert_ne!(pose[1], skeleton.initial_pose()[1], "the chest takes a share");
                }
            }
        }
        assert!(worst < 0.1, "face {worst}° off the target");
    }

    #[test]
    fn a_character_facing_z_has_its_left_hip_at_plus_x() {
        assert!(facing(Vec3::new(-0.1, 1.0, 0.0), Vec3::new(0.1, 1.0, 0.0)).distance(Vec3::Z) < 1e-6);
    }
}

//! Inverse kinematics: FABRIK on joint positions, and its conversion to joint rotations.

use glam::{Mat3, Mat4, Quat, Vec3};

use super::fk::{forward_kinematics, forward_kinematics_along};
use super::pose::JointRotation;
use super::skeleton::Skeleton;

/// Default IK tolerance (model units) and FK↔FABRIK rounds.
pub const IK_TOLERANCE: f32 = 1e-4;
pub const IK_ROUNDS: usize = 24;

/// What a FABRIK solve did.
#[derive(Debug, Clone, PartialEq)]
pub struct FabrikResult {
    /// Solved joint positions, base first; the base never moves.
    pub positions: Vec<Vec3>,
    /// Whether the end is within the tolerance of the target.
    pub reached: bool,
    /// Forward-and-backward iterations used (0 when the chain started within tolerance,
    /// 1 for an unreachable target, which is solved in one straightening pass).
    pub iterations: usize,
    /// Distance from the end to the target after solving.
    pub distance: f32,
}

/// FABRIK (Aristidou & Lasenby): alternating backward passes (end placed on the target)
/// and forward passes (base put back), each keeping every bone length, until the end is
/// within `tolerance` of `target` or `max_iterations` passes were made. An unreachable
/// target (farther than the chain's length) straightens the chain towards it.
pub fn fabrik(chain: &[Vec3], target: Vec3, tolerance: f32, max_iterations: usize) -> FabrikResult {
    let mut p = chain.to_vec();
    let n = p.len();
    if n < 2 {
        let distance = p.first().map_or(f32::INFINITY, |b| b.distance(target));
        return FabrikResult { positions: p, reached: distance <= tolerance, iterations: 0, distance };
    }
    let lengths: Vec<f32> = p.windows(2).map(|w| w[0].distance(w[1])).collect();
    let base = p[0];
    let total: f32 = lengths.iter().sum();
    if base.distance(target) >= total {
        for i in 0..n - 1 {
            let dir = (target - p[i]).normalize_or(Vec3::Y);
            p[i + 1] = p[i] + lengths[i] * dir;
        }
        let distance = p[n - 1].distance(target);
        return FabrikResult { positions: p, reached: distance <= tolerance, iterations: 1, distance };
    }
    let mut iterations = 0;
    let mut distance = p[n - 1].distance(target);
    while distance > tolerance && iterations < max_iterations {
        iterations += 1;
        p[n - 1] = target;
        for i in (0..n - 1).rev() {
            let dir = (p[i] - p[i + 1]).normalize_or(Vec3::Y);
            p[i] = p[i + 1] + lengths[i] * dir;
        }
        p[0] = base;
        for i in 0..n - 1 {
            let dir = (p[i + 1] - p[i]).normalize_or(Vec3::Y);
            p[i + 1] = p[i] + lengths[i] * dir;
        }
        distance = p[n - 1].distance(target);
    }
    FabrikResult { positions: p, reached: distance <= tolerance, iterations, distance }
}

/// The joints from `end` up to its sub-base (the first ancestor with more than one child,
/// or the root), base first.
pub fn chain_to_sub_base(skeleton: &Skeleton, end: usize) -> Vec<usize> {
    let mut chain = vec![end];
    let mut j = end;
    while let Some(p) = skeleton.parent(j) {
        chain.push(p);
        if skeleton.children(p).len() > 1 {
            break;
        }
        j = p;
    }
    chain.reverse();
    chain
}

/// An IK goal: move joint `end` to `target` (world space).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkGoal {
    pub end: usize,
    pub target: Vec3,
}

/// What a rotation-space IK solve did for one goal.
#[derive(Debug, Clone, PartialEq)]
pub struct IkReport {
    pub end: usize,
    /// The joints whose rotations were changed (below the sub-base, down to the end's parent).
    pub chain: Vec<usize>,
    pub reached: bool,
    /// FK ↔ FABRIK rounds used.
    pub rounds: usize,
    /// Total FABRIK iterations over all rounds.
    pub iterations: usize,
    /// Distance from the end joint to the target after the solve (world units).
    pub distance: f32,
    /// Whether some rotation was clamped by the joint's limits.
    pub limited: bool,
}

/// Solves each goal in turn by FABRIK on joint positions, then turns each bone of the
/// chain towards its solved direction with the smallest rotation, expressed in the
/// joint's own rotation type and clamped to its limits; FK and FABRIK alternate for up to
/// `rounds` rounds so a limited chain gets as close as its limits allow. The sub-base does
/// not rotate (its other branches stay put), so the chain that moves starts at the
/// sub-base's child.
pub fn solve_ik(
    skeleton: &Skeleton,
    pose: &mut [JointRotation],
    placement: Mat4,
    goals: &[IkGoal],
    tolerance: f32,
    rounds: usize,
) -> Vec<IkReport> {
    let n = skeleton.len();
    let mut world = vec![Mat4::IDENTITY; n];
    goals
        .iter()
        .map(|goal| {
            let full = chain_to_sub_base(skeleton, goal.end);
            // Positions chain: from the sub-base's child (fixed) down to the end.
            let chain: Vec<usize> = if full.len() > 2 { full[1..].to_vec() } else { full.clone() };
            let mut report = IkReport {
                end: goal.end,
                chain: chain[..chain.len() - 1].to_vec(),
                reached: false,
                rounds: 0,
                iterations: 0,
                distance: f32::INFINITY,
                limited: false,
            };
            for _ in 0..rounds.max(1) {
                forward_kinematics(skeleton, pose, placement, &mut world);
                let positions: Vec<Vec3> = chain.iter().map(|&j| world[j].w_axis.truncate()).collect();
                report.distance = positions[positions.len() - 1].distance(goal.target);
                if report.distance <= tolerance {
                    report.reached = true;
                    break;
                }
                report.rounds += 1;
                let solved = fabrik(&positions, goal.target, tolerance * 0.5, 64);
                report.iterations += solved.iterations;
                // The chain is a parent-to-child path: turning chain[k] moves only the
                // joints after it, so before each bone only its two ends are brought up to
                // date from its (already updated) parent: O(1) per bone, not a whole FK.
                for k in 0..chain.len() - 1 {
                    let (j, child) = (chain[k], chain[k + 1]);
                    forward_kinematics_along(skeleton, pose, placement, &[j, child], &mut world);
                    let from = world[child].w_axis.truncate() - world[j].w_axis.truncate();
                    let to = solved.positions[k + 1] - solved.positions[k];
                    if from.length_squared() < 1e-12 || to.length_squared() < 1e-12 {
                        continue;
                    }
                    let delta = Quat::from_rotation_arc(from.normalize(), to.normalize());
                    let parent_world = skeleton.parent(j).map_or(placement, |p| world[p]);
                    report.limited |= turn_joint(skeleton, pose, j, parent_world, delta);
                    forward_kinematics_along(skeleton, pose, placement, &[j], &mut world);
                }
            }
            forward_kinematics(skeleton, pose, placement, &mut world);
            report.distance = world[goal.end].w_axis.truncate().distance(goal.target);
            report.reached = report.distance <= tolerance;
            report
        })
        .collect()
}

/// Turns joint `joint` by `turn`, a rotation in the world, its parent's world transform
/// being `parent_world`: its local rotation becomes `P⁻¹ · turn · P · local` (P the
/// parent's world rotation), in the joint's own rotation type, clamped to its limits.
/// Returns whether the limits clamped it.
pub fn turn_joint(
    skeleton: &Skeleton,
    pose: &mut [JointRotation],
    joint: usize,
    parent_world: Mat4,
    turn: Quat,
) -> bool {
    let parent = rotation_of(parent_world);
    let local = (parent.inverse() * turn * parent * pose[joint].to_quat()).normalize();
    let wanted = pose[joint].with_rotation_of(local);
    let clamped = wanted.clamped(&skeleton.joint(joint).limits);
    let limited = clamped != wanted;
    pose[joint] = clamped;
    limited
}

/// The rotation part of a transform (scale removed).
pub fn rotation_of(m: Mat4) -> Quat {
    let m3 = Mat3::from_mat4(m);
    Quat::from_mat3(&Mat3::from_cols(m3.x_axis.normalize(), m3.y_axis.normalize(), m3.z_axis.normalize())).normalize()
}

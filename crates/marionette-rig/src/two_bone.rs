//! Two-bone IK with a pole: a thigh and shin (or upper arm and forearm) turned so that the
//! end (ankle, wrist) reaches a target, the middle joint (knee, elbow) bending toward a
//! pole point, solved in closed form by the law of cosines. A soft limit eases a limb
//! into its full stretch so that it does not snap straight.

use glam::{Mat4, Quat, Vec3};

use crate::fk::forward_kinematics;
use crate::{JointRotation, Skeleton};

/// Where the middle and end joints go for a limb from `root` through `mid` to `end`
/// reaching for `target`: the limb keeps its bone lengths, lies in the plane of the root,
/// the target and `pole` (bent toward the pole; without one, or with the pole on the line
/// to the target, toward where the middle joint is now), and stretches straight toward a
/// target it cannot reach. With `soft` above 0 the last `soft` of the limb's reach is eased
/// (the end stops short of a target in that band, smoothly, never snapping straight).
pub fn two_bone_positions(
    root: Vec3,
    mid: Vec3,
    end: Vec3,
    target: Vec3,
    pole: Option<Vec3>,
    soft: f32,
) -> (Vec3, Vec3) {
    let (upper, lower) = (root.distance(mid), mid.distance(end));
    let reach = upper + lower;
    let to_target = target - root;
    let along = to_target.normalize_or((end - root).normalize_or(Vec3::Y));
    let mut d = to_target.length().clamp((upper - lower).abs(), reach);
    let soft = soft.clamp(0.0, reach);
    if soft > 0.0 {
        let start = reach - soft;
        let wanted = to_target.length();
        if wanted > start {
            d = start + soft * (1.0 - (-(wanted - start) / soft).exp());
        }
    }
    let bend = bend_direction(root, along, pole, mid);
    // The angle at the root between the limb's line and its upper bone.
    let cos_root = if upper * d > 0.0 {
        ((upper * upper + d * d - lower * lower) / (2.0 * upper * d)).clamp(-1.0, 1.0)
    } else {
        1.0
    };
    let sin_root = (1.0 - cos_root * cos_root).max(0.0).sqrt();
    let new_mid = root + upper * (cos_root * along + sin_root * bend);
    let new_end = root + d * along;
    (new_mid, new_end)
}

/// The unit direction, square to `along`, the middle joint bends toward: toward the pole,
/// else toward the middle joint now, else any.
fn bend_direction(root: Vec3, along: Vec3, pole: Option<Vec3>, mid: Vec3) -> Vec3 {
    let square = |p: Vec3| {
        let v = p - root;
        (v - along * v.dot(along)).normalize_or_zero()
    };
    let from_pole = pole.map_or(Vec3::ZERO, square);
    if from_pole != Vec3::ZERO {
        return from_pole;
    }
    let from_mid = square(mid);
    if from_mid != Vec3::ZERO { from_mid } else { along.any_orthonormal_vector() }
}

/// A two-bone goal: the limb ending at joint `end` reaching `target` (world space), its
/// middle joint bending toward `pole`, the last `soft` of its reach eased.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoBoneGoal {
    pub end: usize,
    pub target: Vec3,
    pub pole: Option<Vec3>,
    pub soft: f32,
}

/// What a two-bone solve did.
#[derive(Debug, Clone, PartialEq)]
pub struct TwoBoneReport {
    /// The limb's joints: root, middle, end.
    pub chain: [usize; 3],
    /// The end is within `tolerance` of the target.
    pub reached: bool,
    /// From the end to the target after the solve (world units).
    pub distance: f32,
    /// Some rotation was clamped by its joint's limits.
    pub limited: bool,
}

/// Turns the limb ending at the goal's `end` (its parent the middle joint, the middle's
/// parent the root) so that `end` reaches the target with the middle joint bending toward
/// the pole ([`two_bone_positions`]): the root's rotation and then the middle's, each the
/// smallest that aims its bone, in the joint's own rotation type, clamped to its limits.
/// `None` when `end` has no grandparent.
pub fn solve_two_bone(
    skeleton: &Skeleton,
    pose: &mut [JointRotation],
    placement: Mat4,
    goal: TwoBoneGoal,
    tolerance: f32,
) -> Option<TwoBoneReport> {
    let TwoBoneGoal { end, target, pole, soft } = goal;
    let mid = skeleton.parent(end)?;
    let root = skeleton.parent(mid)?;
    let mut world = vec![Mat4::IDENTITY; skeleton.len()];
    forward_kinematics(skeleton, pose, placement, &mut world);
    let at = |world: &[Mat4], j: usize| world[j].w_axis.truncate();
    let (new_mid, new_end) = two_bone_positions(at(&world, root), at(&world, mid), at(&world, end), target, pole, soft);
    let mut limited = false;
    for (joint, child, goal) in [(root, mid, new_mid), (mid, end, new_end)] {
        forward_kinematics(skeleton, pose, placement, &mut world);
        let from = at(&world, child) - at(&world, joint);
        let to = goal - at(&world, joint);
        if from.length_squared() < 1e-12 || to.length_squared() < 1e-12 {
            continue;
        }
        let turn = Quat::from_rotation_arc(from.normalize(), to.normalize());
        let parent_world = skeleton.parent(joint).map_or(placement, |q| world[q]);
        limited |= crate::ik::turn_joint(skeleton, pose, joint, parent_world, turn);
    }
    forward_kinematics(skeleton, pose, placement, &mut world);
    let distance = at(&world, end).distance(target);
    Some(TwoBoneReport { chain: [root, mid, end], reached: distance <= tolerance, distance, limited })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::RawJoint;

    /// A hip above a thigh, a shin and an ankle, the bones turned at rest so that no axis
    /// lines up with the limb.
    fn leg() -> Skeleton {
        let mut joints = vec![
            RawJoint::new("hips", None, Vec3::new(0.0, 1.0, 0.0)),
            RawJoint::new("thigh", Some(0), Vec3::new(0.1, -0.05, 0.0)),
            RawJoint::new("shin", Some(1), Vec3::new(0.0, -0.45, 0.02)),
            RawJoint::new("ankle", Some(2), Vec3::new(0.01, -0.42, -0.03)),
        ];
        joints[1].initial_rotation = JointRotation::Quat(Quat::from_euler(glam::EulerRot::XYZ, 0.3, -0.2, 0.1));
        joints[2].initial_rotation = JointRotation::euler_xyz(0.4, 0.1, -0.2);
        Skeleton::build(joints).unwrap()
    }

    fn goal(end: usize, target: Vec3, pole: Option<Vec3>) -> TwoBoneGoal {
        TwoBoneGoal { end, target, pole, soft: 0.0 }
    }

    fn positions(skeleton: &Skeleton, pose: &[JointRotation], placement: Mat4) -> Vec<Vec3> {
        let mut world = vec![Mat4::IDENTITY; skeleton.len()];
        forward_kinematics(skeleton, pose, placement, &mut world);
        world.iter().map(|m| m.w_axis.truncate()).collect()
    }

    /// A random point in the unit ball (SplitMix64).
    fn random_point(state: &mut u64) -> Vec3 {
        let mut unit = || {
            *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = *state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        loop {
            let p = Vec3::new(unit(), unit(), unit());
            if p.length() <= 1.0 {
                return p;
            }
        }
    }

    /// 10,000 reachable targets with poles: the end on the target (1e-4 of the limb), the
    /// knee in the plane of hip, target and pole (0.5°) on the pole's side, the bones'
    /// lengths kept (1e-6 of the limb).
    #[test]
    fn the_end_reaches_and_the_knee_bends_toward_the_pole() {
        let skeleton = leg();
        let placement = Mat4::from_rotation_translation(Quat::from_rotation_y(0.7), Vec3::new(0.3, 0.0, -1.0));
        let rest = positions(&skeleton, &skeleton.initial_pose(), placement);
        let (upper, lower) = (rest[1].distance(rest[2]), rest[2].distance(rest[3]));
        let reach = upper + lower;
        let mut state = 7u64;
        let (mut worst_end, mut worst_plane, mut worst_length) = (0.0f32, 0.0f32, 0.0f32);
        let mut solved = 0;
        while solved < 10_000 {
            let target = rest[1] + random_point(&mut state) * reach;
            let d = target.distance(rest[1]);
            if d < (upper - lower).abs() + 0.01 * reach || d > 0.999 * reach {
                continue;
            }
            let pole = rest[1] + random_point(&mut state) * 2.0;
            let mut pose = skeleton.initial_pose();
            let report =
                solve_two_bone(&skeleton, &mut pose, placement, goal(3, target, Some(pole)), 1e-4 * reach).unwrap();
            assert!(!report.limited);
            let at = positions(&skeleton, &pose, placement);
            worst_end = worst_end.max(at[3].distance(target) / reach);
            let normal = (target - at[1]).cross(pole - at[1]).normalize();
            let knee = at[2] - at[1];
            worst_plane = worst_plane.max(knee.normalize().dot(normal).abs().asin().to_degrees());
            let square =
                (pole - at[1]) - (target - at[1]).normalize() * (pole - at[1]).dot((target - at[1]).normalize());
            assert!(knee.dot(square) > 0.0, "the knee bends toward the pole");
            worst_length = worst_length
                .max((at[1].distance(at[2]) - upper).abs() / reach)
                .max((at[2].distance(at[3]) - lower).abs() / reach);
            solved += 1;
        }
        eprintln!(
            "two-bone, 10,000 targets: end {worst_end:e}, knee off the plane {worst_plane:e}°, lengths {worst_length:e}"
        );
        assert!(worst_end < 1e-4, "end off by {worst_end} of the limb");
        assert!(worst_plane < 0.5, "knee {worst_plane}° out of the plane");
        assert!(worst_length < 1e-6, "bone lengths changed by {worst_length} of the limb");
    }

    /// A target beyond reach: the limb straight, pointing at it. With a soft limit the end
    /// eases into the stretch: continuous, short of full reach, never past the target.
    #[test]
    fn an_unreachable_target_straightens_the_limb_toward_it_and_soft_eases_in() {
        let skeleton = leg();
        let rest = positions(&skeleton, &skeleton.initial_pose(), Mat4::IDENTITY);
        let reach = rest[1].distance(rest[2]) + rest[2].distance(rest[3]);
        let target = rest[1] + Vec3::new(0.3, -1.0, 0.4).normalize() * 2.0 * reach;
        let mut pose = skeleton.initial_pose();
        let report = solve_two_bone(&skeleton, &mut pose, Mat4::IDENTITY, goal(3, target, None), 1e-4).unwrap();
        assert!(!report.reached);
        let at = positions(&skeleton, &pose, Mat4::IDENTITY);
        assert!((at[3].distance(at[1]) - reach).abs() < 1e-5 * reach, "straight");
        assert!((at[3] - at[1]).angle_between(target - at[1]).to_degrees() < 0.01, "pointing at the target");
        // Soft: the end's distance from the hip as the target moves out, step by step.
        let direction = Vec3::new(0.2, -1.0, 0.1).normalize();
        let reached = |t: f32| {
            let (_, end) =
                two_bone_positions(rest[1], rest[2], rest[3], rest[1] + direction * t * reach, None, 0.05 * reach);
            end.distance(rest[1]) / reach
        };
        let mut last = reached(0.9);
        for k in 1..=300 {
            let t = 0.9 + k as f32 * 0.001;
            let now = reached(t);
            assert!(now >= last - 1e-6 && now - last < 0.0011, "continuous and rising at {t}: {last} → {now}");
            assert!(now <= t + 1e-6 && now < 1.0, "short of full reach and of the target at {t}");
            last = now;
        }
    }
}

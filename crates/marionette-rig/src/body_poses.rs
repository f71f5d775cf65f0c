//! The built-in body poses, defined once on the humanoid map: each bone's direction in the
//! character's facing frame (x its left, y up, z where it faces at rest), put on any mapped
//! character by aiming its bones from the hips out. Bones a pose does not name stand as in
//! `stand`; the shoulders, hands and fingers keep their rest turn against the bone before
//! them; a foot whose shin is within 45° of straight down stands flat (its rest turn in
//! the model), else keeps its rest turn against the shin.
//!
//! A bone's direction is from its joint to the next bone's joint: the torso from the hips
//! to the chest (turned at the hips), the chest to the neck, the neck to the head, each
//! upper limb to its lower, each lower limb to the hand or foot.

use glam::{Mat4, Quat, Vec3};

use crate::fk::forward_kinematics;
use crate::humanoid::{HumanBone, HumanoidMap};
use crate::ik::{rotation_of, turn_joint};
use crate::{JointRotation, Skeleton};

use HumanBone::*;

/// One built-in pose: directions for the bones it names (not normalised), and where the
/// face looks (none: straight along the neck's turn).
pub struct BodyPose {
    pub name: &'static str,
    pub bones: &'static [(HumanBone, [f32; 3])],
    pub look: Option<[f32; 3]>,
}

const fn pose(name: &'static str, bones: &'static [(HumanBone, [f32; 3])]) -> BodyPose {
    BodyPose { name, bones, look: None }
}

/// The bones every pose aims, in the order they are aimed, and their direction in `stand`.
pub const AIMED: [(HumanBone, [f32; 3]); 11] = [
    (Hips, [0.0, 1.0, 0.0]),
    (Chest, [0.0, 1.0, 0.0]),
    (Neck, [0.0, 1.0, 0.0]),
    (LeftUpperArm, [0.15, -1.0, 0.0]),
    (LeftLowerArm, [0.08, -1.0, 0.12]),
    (RightUpperArm, [-0.15, -1.0, 0.0]),
    (RightLowerArm, [-0.08, -1.0, 0.12]),
    (LeftUpperLeg, [0.03, -1.0, 0.0]),
    (LeftLowerLeg, [0.0, -1.0, 0.0]),
    (RightUpperLeg, [-0.03, -1.0, 0.0]),
    (RightLowerLeg, [0.0, -1.0, 0.0]),
];

const H: f32 = std::f32::consts::FRAC_1_SQRT_2;

/// The library.
pub const POSES: [BodyPose; 32] = [
    pose(
        "t-pose",
        &[
            (LeftUpperArm, [1.0, 0.0, 0.0]),
            (LeftLowerArm, [1.0, 0.0, 0.0]),
            (RightUpperArm, [-1.0, 0.0, 0.0]),
            (RightLowerArm, [-1.0, 0.0, 0.0]),
            (LeftUpperLeg, [0.0, -1.0, 0.0]),
            (RightUpperLeg, [0.0, -1.0, 0.0]),
        ],
    ),
    pose(
        "a-pose",
        &[
            (LeftUpperArm, [H, -H, 0.0]),
            (LeftLowerArm, [H, -H, 0.0]),
            (RightUpperArm, [-H, -H, 0.0]),
            (RightLowerArm, [-H, -H, 0.0]),
            (LeftUpperLeg, [0.0, -1.0, 0.0]),
            (RightUpperLeg, [0.0, -1.0, 0.0]),
        ],
    ),
    pose("stand", &[]),
    pose(
        "walk",
        &[
            (LeftUpperLeg, [0.03, -1.0, 0.35]),
            (LeftLowerLeg, [0.0, -1.0, 0.1]),
            (RightUpperLeg, [-0.03, -1.0, -0.3]),
            (RightLowerLeg, [0.0, -1.0, -0.45]),
            (LeftUpperArm, [0.12, -1.0, -0.3]),
            (LeftLowerArm, [0.05, -1.0, 0.1]),
            (RightUpperArm, [-0.12, -1.0, 0.3]),
            (RightLowerArm, [-0.05, -1.0, 0.6]),
        ],
    ),
    pose(
        "run",
        &[
            (Hips, [0.0, 1.0, 0.2]),
            (Chest, [0.0, 1.0, 0.25]),
            (LeftUpperLeg, [0.03, -0.6, 0.8]),
            (LeftLowerLeg, [0.0, -1.0, -0.1]),
            (RightUpperLeg, [-0.03, -1.0, -0.5]),
            (RightLowerLeg, [0.0, -0.5, -1.0]),
            (LeftUpperArm, [0.15, -1.0, -0.6]),
            (LeftLowerArm, [0.0, 0.3, 1.0]),
            (RightUpperArm, [-0.15, -1.0, 0.5]),
            (RightLowerArm, [0.0, 0.6, 1.0]),
        ],
    ),
    pose(
        "jump",
        &[
            (LeftUpperArm, [0.4, 1.0, 0.15]),
            (LeftLowerArm, [0.3, 1.0, 0.1]),
            (RightUpperArm, [-0.4, 1.0, 0.15]),
            (RightLowerArm, [-0.3, 1.0, 0.1]),
            (LeftUpperLeg, [0.1, -0.6, 0.8]),
            (LeftLowerLeg, [0.0, -1.0, -0.5]),
            (RightUpperLeg, [-0.1, -0.6, 0.8]),
            (RightLowerLeg, [0.0, -1.0, -0.5]),
        ],
    ),
    pose(
        "sit-chair",
        &[
            (LeftUpperLeg, [0.0, 0.0, 1.0]),
            (LeftLowerLeg, [0.0, -1.0, 0.0]),
            (RightUpperLeg, [0.0, 0.0, 1.0]),
            (RightLowerLeg, [0.0, -1.0, 0.0]),
            (LeftUpperArm, [0.1, -1.0, 0.35]),
            (LeftLowerArm, [0.0, -0.3, 1.0]),
            (RightUpperArm, [-0.1, -1.0, 0.35]),
            (RightLowerArm, [0.0, -0.3, 1.0]),
        ],
    ),
    pose(
        "sit-floor",
        &[
            (LeftUpperLeg, [0.1, 0.0, 1.0]),
            (LeftLowerLeg, [0.05, 0.0, 1.0]),
            (RightUpperLeg, [-0.1, 0.0, 1.0]),
            (RightLowerLeg, [-0.05, 0.0, 1.0]),
            (LeftUpperArm, [0.25, -1.0, -0.35]),
            (LeftLowerArm, [0.1, -1.0, -0.3]),
            (RightUpperArm, [-0.25, -1.0, -0.35]),
            (RightLowerArm, [-0.1, -1.0, -0.3]),
        ],
    ),
    pose(
        "sit-cross-legged",
        &[
            (LeftUpperLeg, [0.8, -0.15, 0.6]),
            (LeftLowerLeg, [-0.85, 0.0, 0.5]),
            (RightUpperLeg, [-0.8, -0.15, 0.6]),
            (RightLowerLeg, [0.85, -0.1, 0.5]),
            (LeftUpperArm, [0.15, -1.0, 0.3]),
            (LeftLowerArm, [0.1, -0.5, 1.0]),
            (RightUpperArm, [-0.15, -1.0, 0.3]),
            (RightLowerArm, [-0.1, -0.5, 1.0]),
        ],
    ),
    pose(
        "kneel",
        &[
            (LeftUpperLeg, [0.05, -1.0, 0.0]),
            (LeftLowerLeg, [0.0, 0.0, -1.0]),
            (RightUpperLeg, [-0.05, -1.0, 0.0]),
            (RightLowerLeg, [0.0, 0.0, -1.0]),
        ],
    ),
    pose(
        "crouch",
        &[
            (Hips, [0.0, 1.0, 0.5]),
            (Chest, [0.0, 1.0, 0.4]),
            (LeftUpperLeg, [0.25, -0.3, 1.0]),
            (LeftLowerLeg, [0.0, -1.0, -0.4]),
            (RightUpperLeg, [-0.25, -0.3, 1.0]),
            (RightLowerLeg, [0.0, -1.0, -0.4]),
            (LeftUpperArm, [0.15, -0.6, 1.0]),
            (LeftLowerArm, [0.0, -0.2, 1.0]),
            (RightUpperArm, [-0.15, -0.6, 1.0]),
            (RightLowerArm, [0.0, -0.2, 1.0]),
        ],
    ),
    pose(
        "lunge",
        &[
            (LeftUpperLeg, [0.05, -0.25, 1.0]),
            (LeftLowerLeg, [0.0, -1.0, 0.0]),
            (RightUpperLeg, [-0.05, -1.0, -0.7]),
            (RightLowerLeg, [0.0, -0.25, -1.0]),
            (LeftUpperArm, [0.25, -1.0, 0.0]),
            (RightUpperArm, [-0.25, -1.0, 0.0]),
        ],
    ),
    pose(
        "lie-back",
        &[
            (Hips, [0.0, 0.0, -1.0]),
            (Chest, [0.0, 0.0, -1.0]),
            (Neck, [0.0, 0.15, -1.0]),
            (LeftUpperLeg, [0.05, 0.0, 1.0]),
            (LeftLowerLeg, [0.0, 0.0, 1.0]),
            (RightUpperLeg, [-0.05, 0.0, 1.0]),
            (RightLowerLeg, [0.0, 0.0, 1.0]),
            (LeftUpperArm, [0.2, 0.0, 1.0]),
            (LeftLowerArm, [0.1, 0.0, 1.0]),
            (RightUpperArm, [-0.2, 0.0, 1.0]),
            (RightLowerArm, [-0.1, 0.0, 1.0]),
        ],
    ),
    pose(
        "lie-front",
        &[
            (Hips, [0.0, 0.0, 1.0]),
            (Chest, [0.0, 0.0, 1.0]),
            (Neck, [0.0, 0.3, 1.0]),
            (LeftUpperLeg, [0.05, 0.0, -1.0]),
            (LeftLowerLeg, [0.0, 0.0, -1.0]),
            (RightUpperLeg, [-0.05, 0.0, -1.0]),
            (RightLowerLeg, [0.0, 0.0, -1.0]),
            (LeftUpperArm, [0.2, 0.0, -1.0]),
            (LeftLowerArm, [0.1, 0.0, -1.0]),
            (RightUpperArm, [-0.2, 0.0, -1.0]),
            (RightLowerArm, [-0.1, 0.0, -1.0]),
        ],
    ),
    pose(
        "reach-up",
        &[
            (LeftUpperArm, [0.12, 1.0, 0.05]),
            (LeftLowerArm, [0.08, 1.0, 0.05]),
            (RightUpperArm, [-0.12, 1.0, 0.05]),
            (RightLowerArm, [-0.08, 1.0, 0.05]),
        ],
    ),
    pose("point", &[(RightUpperArm, [-0.15, 0.1, 1.0]), (RightLowerArm, [-0.1, 0.12, 1.0])]),
    pose("wave", &[(RightUpperArm, [-1.0, 0.25, 0.1]), (RightLowerArm, [-0.15, 1.0, 0.1])]),
    pose(
        "arms-crossed",
        &[
            (LeftUpperArm, [0.25, -1.0, 0.3]),
            (LeftLowerArm, [-1.0, 0.15, 0.3]),
            (RightUpperArm, [-0.25, -1.0, 0.35]),
            (RightLowerArm, [1.0, 0.2, 0.3]),
        ],
    ),
    pose(
        "hands-on-hips",
        &[
            (LeftUpperArm, [0.7, -1.0, -0.3]),
            (LeftLowerArm, [-0.6, -0.7, 0.2]),
            (RightUpperArm, [-0.7, -1.0, -0.3]),
            (RightLowerArm, [0.6, -0.7, 0.2]),
        ],
    ),
    pose(
        "fight",
        &[
            (Chest, [0.0, 1.0, 0.15]),
            (LeftUpperArm, [0.35, -1.0, 0.6]),
            (LeftLowerArm, [-0.25, 0.9, 0.8]),
            (RightUpperArm, [-0.35, -1.0, 0.3]),
            (RightLowerArm, [0.2, 1.0, 0.6]),
            (LeftUpperLeg, [0.15, -1.0, 0.25]),
            (LeftLowerLeg, [0.0, -1.0, 0.05]),
            (RightUpperLeg, [-0.15, -1.0, -0.25]),
            (RightLowerLeg, [0.0, -1.0, -0.1]),
        ],
    ),
    pose(
        "lean",
        &[
            (Hips, [0.15, 1.0, 0.0]),
            (Chest, [0.3, 1.0, 0.0]),
            (Neck, [0.2, 1.0, 0.0]),
            (LeftUpperArm, [0.2, -1.0, 0.0]),
            (RightUpperArm, [-0.05, -1.0, 0.0]),
        ],
    ),
    BodyPose { name: "look-back", bones: &[(Chest, [0.0, 1.0, -0.05])], look: Some([-0.9, 0.0, -0.45]) },
    BodyPose {
        name: "think",
        bones: &[
            (RightUpperArm, [-0.25, -1.0, 0.35]),
            (RightLowerArm, [0.3, 1.0, 0.45]),
            (LeftUpperArm, [0.15, -1.0, 0.25]),
            (LeftLowerArm, [-0.9, 0.0, 0.45]),
        ],
        look: Some([0.0, -0.3, 1.0]),
    },
    pose(
        "bow",
        &[
            (Hips, [0.0, 1.0, 0.7]),
            (Chest, [0.0, 1.0, 0.8]),
            (LeftUpperArm, [0.05, -1.0, 0.0]),
            (RightUpperArm, [-0.05, -1.0, 0.0]),
            (LeftLowerArm, [0.0, -1.0, 0.0]),
            (RightLowerArm, [0.0, -1.0, 0.0]),
        ],
    ),
    pose("salute", &[(RightUpperArm, [-1.0, 0.1, 0.35]), (RightLowerArm, [0.75, 0.65, 0.1])]),
    pose(
        "cheer",
        &[
            (LeftUpperArm, [0.7, 0.8, 0.05]),
            (LeftLowerArm, [0.6, 0.9, 0.0]),
            (RightUpperArm, [-0.7, 0.8, 0.05]),
            (RightLowerArm, [-0.6, 0.9, 0.0]),
        ],
    ),
    pose(
        "shrug",
        &[
            (LeftUpperArm, [0.45, -1.0, 0.0]),
            (LeftLowerArm, [0.7, -0.05, 0.8]),
            (RightUpperArm, [-0.45, -1.0, 0.0]),
            (RightLowerArm, [-0.7, -0.05, 0.8]),
        ],
    ),
    pose(
        "kick",
        &[
            (Hips, [0.0, 1.0, -0.2]),
            (RightUpperLeg, [-0.03, -0.15, 1.0]),
            (RightLowerLeg, [0.0, 0.0, 1.0]),
            (LeftUpperArm, [1.0, -0.3, 0.0]),
            (RightUpperArm, [-1.0, -0.3, 0.0]),
            (LeftLowerArm, [1.0, -0.2, 0.1]),
            (RightLowerArm, [-1.0, -0.2, 0.1]),
        ],
    ),
    pose("phone", &[(RightUpperArm, [-0.2, -1.0, 0.15]), (RightLowerArm, [0.25, 1.0, 0.1])]),
    pose(
        "stretch",
        &[
            (Hips, [-0.1, 1.0, 0.0]),
            (Chest, [-0.35, 1.0, 0.0]),
            (LeftUpperArm, [-0.3, 1.0, 0.0]),
            (LeftLowerArm, [-0.6, 1.0, 0.0]),
            (RightUpperArm, [-0.6, 1.0, 0.0]),
            (RightLowerArm, [-0.9, 0.7, 0.0]),
        ],
    ),
    pose(
        "carry",
        &[
            (LeftUpperArm, [0.25, -1.0, 0.45]),
            (LeftLowerArm, [0.1, 0.0, 1.0]),
            (RightUpperArm, [-0.25, -1.0, 0.45]),
            (RightLowerArm, [-0.1, 0.0, 1.0]),
        ],
    ),
    pose(
        "pray",
        &[
            (LeftUpperArm, [0.25, -1.0, 0.3]),
            (LeftLowerArm, [-0.55, 0.6, 0.6]),
            (RightUpperArm, [-0.25, -1.0, 0.3]),
            (RightLowerArm, [0.55, 0.6, 0.6]),
        ],
    ),
];

/// The pose of that name.
pub fn body_pose(name: &str) -> Option<&'static BodyPose> {
    POSES.iter().find(|p| p.name == name)
}

impl BodyPose {
    /// Each aimed bone's direction (unit, facing frame), mirrored left to right on request:
    /// the pose's own, else `stand`'s.
    pub fn directions(&self, mirrored: bool) -> Vec<(HumanBone, Vec3)> {
        AIMED
            .iter()
            .map(|&(bone, _)| {
                let source = if mirrored { other_side(bone) } else { bone };
                let named = |list: &[(HumanBone, [f32; 3])]| list.iter().find(|(b, _)| *b == source).map(|&(_, d)| d);
                let d = named(self.bones).or_else(|| named(&AIMED)).expect("every aimed bone stands");
                let d = Vec3::from(d);
                (bone, if mirrored { Vec3::new(-d.x, d.y, d.z) } else { d }.normalize())
            })
            .collect()
    }

    /// Where the face looks (unit, facing frame), mirrored on request.
    pub fn look(&self, mirrored: bool) -> Option<Vec3> {
        self.look.map(|d| if mirrored { Vec3::new(-d[0], d[1], d[2]) } else { Vec3::from(d) }.normalize())
    }
}

/// The bone on the other side (bones on the middle are their own).
pub fn other_side(bone: HumanBone) -> HumanBone {
    match bone {
        LeftShoulder => RightShoulder,
        RightShoulder => LeftShoulder,
        LeftUpperArm => RightUpperArm,
        RightUpperArm => LeftUpperArm,
        LeftLowerArm => RightLowerArm,
        RightLowerArm => LeftLowerArm,
        LeftHand => RightHand,
        RightHand => LeftHand,
        LeftUpperLeg => RightUpperLeg,
        RightUpperLeg => LeftUpperLeg,
        LeftLowerLeg => RightLowerLeg,
        RightLowerLeg => LeftLowerLeg,
        LeftFoot => RightFoot,
        RightFoot => LeftFoot,
        LeftToes => RightToes,
        RightToes => LeftToes,
        _ if bone.is_finger() => {
            let k = HumanBone::ALL.iter().position(|&b| b == bone).expect("every bone is listed");
            HumanBone::ALL[HumanBone::BODY_COUNT + (k - HumanBone::BODY_COUNT + 15) % 30]
        }
        _ => bone,
    }
}

/// The character's facing frame at rest, in its model space: columns its left, up, and the
/// way it faces (from its hips: square to the line from the right hip to the left).
pub fn facing_frame(skeleton: &Skeleton, map: &HumanoidMap) -> Option<Quat> {
    let mut rest = vec![Mat4::IDENTITY; skeleton.len()];
    forward_kinematics(skeleton, &skeleton.initial_pose(), Mat4::IDENTITY, &mut rest);
    let at = |b: HumanBone| map.get(&b).map(|&j| rest[j].w_axis.truncate());
    let (left, right) = (at(LeftUpperLeg)?, at(RightUpperLeg)?);
    let forward = crate::look_at::facing(right, left);
    let left = Vec3::Y.cross(forward).normalize();
    Some(Quat::from_mat3(&glam::Mat3::from_cols(left, Vec3::Y, forward)))
}

/// The joint a bone's direction ends at: the next mapped bone along the body.
pub fn aim_end(map: &HumanoidMap, bone: HumanBone) -> Option<usize> {
    let first = |bones: &[HumanBone]| bones.iter().find_map(|b| map.get(b).copied());
    match bone {
        Hips => first(&[Chest, Spine, Neck]),
        Chest => first(&[Neck, Head]),
        Neck => first(&[Head]),
        LeftUpperArm => first(&[LeftLowerArm]),
        LeftLowerArm => first(&[LeftHand]),
        RightUpperArm => first(&[RightLowerArm]),
        RightLowerArm => first(&[RightHand]),
        LeftUpperLeg => first(&[LeftLowerLeg]),
        LeftLowerLeg => first(&[LeftFoot]),
        RightUpperLeg => first(&[RightLowerLeg]),
        RightLowerLeg => first(&[RightFoot]),
        _ => None,
    }
}

/// The joint a bone's direction starts at: its own, or for the chest the spine where the
/// rig has no chest.
pub fn aim_start(map: &HumanoidMap, bone: HumanBone) -> Option<usize> {
    match bone {
        Chest => map.get(&Chest).or_else(|| map.get(&Spine)).copied(),
        _ => map.get(&bone).copied(),
    }
}

/// The joint turned to aim from `start` to `end`: the lowest joint above both (`start`
/// itself on a chain; the root where a rig hangs its hips and its spine side by side).
pub fn turned_joint(skeleton: &Skeleton, start: usize, end: usize) -> usize {
    let above = |j: usize| std::iter::successors(Some(j), |&k| skeleton.parent(k)).collect::<Vec<_>>();
    let over_end = above(end);
    above(start).into_iter().find(|j| over_end.contains(j)).unwrap_or(0)
}

/// What putting a body pose on a character did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BodyPoseReport {
    /// Joints the limits held short of the pose's direction.
    pub limited: Vec<usize>,
}

/// Puts `body` on `pose` (the character's, whose humanoid map is `map`): the body's joints
/// back to rest, then each aimed bone turned, from the hips out, the smallest turn from
/// where it points to the pose's direction, in the joint's own rotation type and clamped to
/// its limits; feet flat where the shin is near upright; the face turned to the pose's look.
/// Fingers keep their rotations. `None` when the map lacks hips or legs.
pub fn apply_body_pose(
    skeleton: &Skeleton,
    map: &HumanoidMap,
    pose: &mut [JointRotation],
    body: &BodyPose,
    mirrored: bool,
) -> Option<BodyPoseReport> {
    aim_body(skeleton, map, pose, &body.directions(mirrored), body.look(mirrored))
}

/// Puts a body pose given by its bones' directions (unit, in the facing frame, the bones of
/// [`AIMED`] in their order) and its look on `pose`, as [`apply_body_pose`] does.
pub fn aim_body(
    skeleton: &Skeleton,
    map: &HumanoidMap,
    pose: &mut [JointRotation],
    directions: &[(HumanBone, Vec3)],
    look_along: Option<Vec3>,
) -> Option<BodyPoseReport> {
    let frame = facing_frame(skeleton, map)?;
    let rest = skeleton.initial_pose();
    let fingers: Vec<usize> = map.iter().filter(|(b, _)| b.is_finger()).map(|(_, &j)| j).collect();
    for j in 0..skeleton.len() {
        if !fingers.contains(&j) {
            pose[j] = rest[j];
        }
    }
    let mut world = vec![Mat4::IDENTITY; skeleton.len()];
    let mut rest_world = vec![Mat4::IDENTITY; skeleton.len()];
    forward_kinematics(skeleton, &rest, Mat4::IDENTITY, &mut rest_world);
    let mut report = BodyPoseReport::default();
    let mut aim = |pose: &mut [JointRotation], start: usize, end: usize, wanted: Vec3, report: &mut BodyPoseReport| {
        let joint = turned_joint(skeleton, start, end);
        refresh(skeleton, pose, &mut world, &[start, end]);
        let now = world[end].w_axis.truncate() - world[start].w_axis.truncate();
        if now.length_squared() < 1e-12 {
            return;
        }
        let turn = Quat::from_rotation_arc(now.normalize(), wanted);
        let parent = skeleton.parent(joint).map_or(Mat4::IDENTITY, |p| world[p]);
        if turn_joint(skeleton, pose, joint, parent, turn) && !report.limited.contains(&joint) {
            report.limited.push(joint);
        }
    };
    for &(bone, direction) in directions {
        if bone == LeftUpperArm {
            // The look turns the chest and neck, before the limbs hung from them are aimed.
            look(skeleton, map, pose, look_along, frame, &rest_world, &mut report);
        }
        let (Some(start), Some(end)) = (aim_start(map, bone), aim_end(map, bone)) else { continue };
        aim(pose, start, end, frame * direction, &mut report);
    }
    for (shin, foot) in [(LeftLowerLeg, LeftFoot), (RightLowerLeg, RightFoot)] {
        let (Some(&shin), Some(&foot)) = (map.get(&shin), map.get(&foot)) else { continue };
        refresh(skeleton, pose, &mut world, &[shin, foot]);
        let down = (world[foot].w_axis.truncate() - world[shin].w_axis.truncate()).normalize_or(Vec3::NEG_Y);
        if down.dot(Vec3::NEG_Y) > std::f32::consts::FRAC_1_SQRT_2 {
            let turn = rotation_of(rest_world[foot]) * rotation_of(world[foot]).inverse();
            let parent = skeleton.parent(foot).map_or(Mat4::IDENTITY, |p| world[p]);
            if turn_joint(skeleton, pose, foot, parent, turn) && !report.limited.contains(&foot) {
                report.limited.push(foot);
            }
        }
    }
    Some(report)
}

/// `world` brought up to date for `joints` and every joint above them (the rest may be
/// stale): forward kinematics along their chains only.
fn refresh(skeleton: &Skeleton, pose: &[JointRotation], world: &mut [Mat4], joints: &[usize]) {
    for &j in joints {
        let mut path: Vec<usize> = std::iter::successors(Some(j), |&k| skeleton.parent(k)).collect();
        path.reverse();
        crate::fk::forward_kinematics_along(skeleton, pose, Mat4::IDENTITY, &path, world);
    }
}

/// Turns the head (with shares of the chest and neck) to face along the pose's look.
fn look(
    skeleton: &Skeleton,
    map: &HumanoidMap,
    pose: &mut [JointRotation],
    look: Option<Vec3>,
    frame: Quat,
    rest_world: &[Mat4],
    report: &mut BodyPoseReport,
) {
    let (Some(look), Some(&head)) = (look, map.get(&Head)) else { return };
    let mut world = vec![Mat4::IDENTITY; skeleton.len()];
    forward_kinematics(skeleton, pose, Mat4::IDENTITY, &mut world);
    let face = rotation_of(rest_world[head]).inverse() * (frame * Vec3::Z);
    // Not a joint the hips hang from (a rig whose chest is its root).
    let hips = map.get(&Hips).map(|&h| std::iter::successors(Some(h), |&k| skeleton.parent(k)).collect::<Vec<_>>());
    let joints: Vec<usize> = [Chest, Neck, Head]
        .iter()
        .filter_map(|b| map.get(b).copied())
        .filter(|j| !hips.as_ref().is_some_and(|above| above.contains(j)))
        .collect();
    let target = world[head].w_axis.truncate() + frame * look * 10.0;
    let done = crate::look_at::solve_look_at(
        skeleton,
        pose,
        Mat4::IDENTITY,
        &joints,
        face,
        &crate::look_at::LOOK_AT_SHARES,
        target,
    );
    if done.limited {
        report.limited.push(head);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_library_has_the_poses_the_issue_names_and_thirty() {
        for name in [
            "t-pose",
            "a-pose",
            "stand",
            "walk",
            "run",
            "jump",
            "sit-chair",
            "sit-floor",
            "kneel",
            "crouch",
            "lie-back",
            "reach-up",
            "point",
            "wave",
            "arms-crossed",
            "hands-on-hips",
            "fight",
            "lean",
            "look-back",
            "think",
        ] {
            assert!(body_pose(name).is_some(), "{name}");
        }
        assert!(POSES.len() >= 30);
        let mut names: Vec<&str> = POSES.iter().map(|p| p.name).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), POSES.len(), "names are unique");
        // Every named bone is aimed.
        for p in &POSES {
            for (b, _) in p.bones {
                assert!(AIMED.iter().any(|(a, _)| a == b), "{}: {b:?}", p.name);
            }
        }
    }

    /// A mirrored pose gives each bone its twin's direction reflected across x = 0.
    #[test]
    fn a_mirrored_pose_is_the_twins_reflected() {
        for p in &POSES {
            let plain = p.directions(false);
            for (bone, mirrored) in p.directions(true) {
                let twin = plain.iter().find(|(b, _)| *b == other_side(bone)).unwrap().1;
                assert!((Vec3::new(-twin.x, twin.y, twin.z) - mirrored).length() < 1e-6, "{} {bone:?}", p.name);
            }
        }
        for &b in &HumanBone::ALL {
            assert_eq!(other_side(other_side(b)), b);
        }
    }
}

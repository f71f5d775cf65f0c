//! Retargeting: the motion of one humanoid carried onto another through their humanoid
//! maps, frame by frame.
//!
//! - **Rotations.** Each mapped target bone turns in the world as its source bone turned
//!   from the source's initial pose, starting from the target's initial pose aligned to the
//!   source's: with [`RestAlignment::Directions`] each bone's rest is first swung to point
//!   where the source's rest bone points (so a T-pose clip lifts an A-pose character's arms
//!   where the clip lifts them), and each frame the bone is swung onto the source bone's
//!   direction (to its next mapped bone), its twist the source's. With
//!   [`RestAlignment::OwnRest`] the rotations are carried from rest to rest (the source's
//!   rest frame gives the target its own rest pose). Rigs facing another way in their
//!   model space (a multiple of 90° about +y) are turned to face the source's way.
//! - **Translation.** The hips move across as the source's, scaled by the ratio of leg
//!   lengths (thigh + shin); in height the target's lowest foot joint stands as far over its
//!   floor as it does standing, raised as the source's rises over its own standing
//!   clearance times that ratio (so a target of other proportions stands on its floor
//!   where the source stands on its own).
//! - **Feet.** Where the source plants a foot (low and still), the target's foot keeps the
//!   place it had when the contact began, moving only as the source's foot moves (scaled);
//!   no ankle sinks below its standing height (less a two-hundredth of the leg, which a
//!   straight knee would bend degrees to give) where the source's stands on the floor, and
//!   no toe below the floor. The legs
//!   reach by the IK solver, the feet keeping their turn in the world; after a contact
//!   the correction fades over a few frames.
//! - **Limits.** Every rotation is clamped to the target joint's limits; the joints and
//!   frames clamped are reported.

use glam::{Mat4, Quat, Vec3};

use super::humanoid::{HumanBone, HumanoidMap};
use super::ik::{IkGoal, solve_ik};
use super::{JointRotation, Skeleton};

/// How the rest poses of source and target are matched.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum RestAlignment {
    /// Each target bone points where the source's points.
    #[default]
    Directions,
    /// Rotations carried from rest to rest: the source's rest gives the target its own.
    OwnRest,
}

/// A humanoid to retarget from or onto: its skeleton, map, the height of the floor its
/// motion stands on in model space, and of its lowest point standing in its initial pose
/// (for a target, the same); its soles: points of its skin under its feet, by which it
/// stands (empty: its foot joints); and the pose it stands in where its initial pose does
/// not (a motion capture whose rest lies along +x: its motion's first frame), which then
/// takes the initial pose's place.
#[derive(Clone, Copy)]
pub struct Humanoid<'a> {
    pub skeleton: &'a Skeleton,
    pub map: &'a HumanoidMap,
    pub floor: f32,
    pub rest_floor: f32,
    pub soles: &'a [Sole],
    pub stands: Option<&'a Frame>,
}

/// A skin point as its joints move it: each joint, its weight, and the point in that
/// joint's frame.
pub type Sole = Vec<(usize, f32, Vec3)>;

impl Humanoid<'_> {
    /// The height of its lowest sole point (or foot joint) with its joints turned and
    /// placed as `rotations` and `at` say; infinite without feet.
    fn lowest_foot(&self, rotations: &[Quat], at: &[Vec3]) -> f32 {
        if self.soles.is_empty() {
            return FEET.iter().filter_map(|b| self.map.get(b)).map(|&j| at[j].y).fold(f32::INFINITY, f32::min);
        }
        let height = |sole: &Sole| sole.iter().map(|&(j, w, p)| w * (at[j] + rotations[j] * p).y).sum::<f32>();
        self.soles.iter().map(height).fold(f32::INFINITY, f32::min)
    }
}

/// One frame of motion: the root joint's position in model space, every joint's rotation,
/// and every joint's offset where the motion moves joints below the root.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    pub root: Vec3,
    pub pose: Vec<JointRotation>,
    /// Every joint's offset in its parent's frame; none: the rest offsets.
    pub offsets: Option<Vec<Vec3>>,
}

impl Frame {
    /// A frame that moves no joint below the root.
    pub fn posed(root: Vec3, pose: Vec<JointRotation>) -> Self {
        Self { root, pose, offsets: None }
    }

    /// Each joint's world rotation and position in this frame.
    pub fn world(&self, skeleton: &Skeleton) -> WorldFrames {
        world_frames_with(skeleton, self.root, &self.pose, self.offsets.as_deref())
    }

    /// The model-space move the matrix stack starts from: the root from its rest offset (or
    /// the frame's) to the frame's root.
    pub fn origin(&self, skeleton: &Skeleton) -> Mat4 {
        origin(skeleton, self.root, self.offsets.as_deref())
    }
}

/// The move from the root's rest offset (`offsets`' where given) to `root`.
fn origin(skeleton: &Skeleton, root: Vec3, offsets: Option<&[Vec3]>) -> Mat4 {
    Mat4::from_translation(root - offsets.map_or(skeleton.joint(0).rest_offset, |o| o[0]))
}

/// A retargeted motion: its frames, which of them hold each foot (left, right) planted,
/// in which the legs were turned off the source's directions to plant a foot or keep it
/// above the floor, and the (frame, joint) pairs whose rotation the target's limits
/// clamped.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Retargeted {
    pub frames: Vec<Frame>,
    pub planted: [Vec<bool>; 2],
    pub legs_moved: [Vec<bool>; 2],
    pub clamped: Vec<(usize, usize)>,
}

/// A mapped target joint and the source joint that drives it.
struct Bone {
    source: usize,
    /// The target's rest world rotation turned to line up with the source's rest.
    aligned_rest: Quat,
    /// The next mapped joint on each side, where the bone has one.
    aim: Option<(usize, usize)>,
}

/// Carries frames of one humanoid's motion onto another. Made once per pair.
pub struct Retargeter<'a> {
    source: Humanoid<'a>,
    target: Humanoid<'a>,
    rest: RestAlignment,
    source_rest: Vec<Quat>,
    source_rest_at: Vec<Vec3>,
    target_rest_at: Vec<Vec3>,
    bones: Vec<Option<Bone>>,
    /// For each unmapped target joint, the source joint of the same name (a rig of the
    /// same family: fingers, spine joints between mapped ones), whose local turn it takes.
    namesakes: Vec<Option<usize>>,
    /// Where the target's hips hang below its chest (6.837's models): the first joint from
    /// the chest down to the hips, aimed so the hips lie from the chest as the source's do.
    waist: Option<usize>,
    /// Target leg length over the source's.
    ratio: f32,
    source_leg: f32,
    target_leg: f32,
    /// How far each one's lowest foot point stands over its floor in its initial pose
    /// (source, target).
    clearances: (f32, f32),
}

/// The bones a humanoid stands on.
const FEET: [HumanBone; 4] = [HumanBone::LeftFoot, HumanBone::RightFoot, HumanBone::LeftToes, HumanBone::RightToes];

/// The bones each standard bone points at, the first mapped on both sides taken.
fn aims(bone: HumanBone) -> &'static [HumanBone] {
    static BONES: [HumanBone; HumanBone::ALL.len()] = HumanBone::ALL;
    use HumanBone::*;
    if let Some(k) = BONES.iter().position(|&b| b == bone).filter(|_| bone.is_finger()) {
        // A phalanx points at the next one out.
        return if (k - HumanBone::BODY_COUNT) % 3 < 2 { std::slice::from_ref(&BONES[k + 1]) } else { &[] };
    }
    match bone {
        Hips => &[Spine, Chest],
        Spine => &[Chest],
        Chest => &[Neck, Head],
        Neck => &[Head],
        LeftShoulder => &[LeftUpperArm],
        LeftUpperArm => &[LeftLowerArm],
        LeftLowerArm => &[LeftHand],
        RightShoulder => &[RightUpperArm],
        RightUpperArm => &[RightLowerArm],
        RightLowerArm => &[RightHand],
        LeftUpperLeg => &[LeftLowerLeg],
        LeftLowerLeg => &[LeftFoot],
        LeftFoot => &[LeftToes],
        RightUpperLeg => &[RightLowerLeg],
        RightLowerLeg => &[RightFoot],
        RightFoot => &[RightToes],
        _ => &[],
    }
}

/// Every joint's world rotation and position.
pub type WorldFrames = (Vec<Quat>, Vec<Vec3>);

/// Each joint's world rotation and position for `pose` with the root at `root`.
pub fn world_frames(skeleton: &Skeleton, root: Vec3, pose: &[JointRotation]) -> WorldFrames {
    world_frames_with(skeleton, root, pose, None)
}

/// As [`world_frames`], the joints at `offsets` (one per joint) in place of their rest
/// offsets where given.
fn world_frames_with(skeleton: &Skeleton, root: Vec3, pose: &[JointRotation], offsets: Option<&[Vec3]>) -> WorldFrames {
    let mut rotations = vec![Quat::IDENTITY; skeleton.len()];
    for j in 0..skeleton.len() {
        let parent = skeleton.parent(j).map_or(Quat::IDENTITY, |p| rotations[p]);
        rotations[j] = (parent * pose[j].to_quat()).normalize();
    }
    let mut world = vec![Mat4::IDENTITY; skeleton.len()];
    let rest = super::fk::RestOverride { offsets, scales: None };
    super::fk::forward_kinematics_with_rest(skeleton, pose, rest, origin(skeleton, root, offsets), &mut world);
    (rotations, world.iter().map(|m| m.w_axis.truncate()).collect())
}

/// The leg length (thigh + shin, the mean of both legs) in the initial pose.
pub fn leg_length(map: &HumanoidMap, at: &[Vec3]) -> Option<f32> {
    use HumanBone::*;
    let leg = |[upper, lower, foot]: [HumanBone; 3]| {
        let (u, l, f) = (at[*map.get(&upper)?], at[*map.get(&lower)?], at[*map.get(&foot)?]);
        Some(u.distance(l) + l.distance(f))
    };
    Some((leg([LeftUpperLeg, LeftLowerLeg, LeftFoot])? + leg([RightUpperLeg, RightLowerLeg, RightFoot])?) / 2.0)
}

/// The turn about +y, a multiple of 90°, that faces the target's hips (right to left leg)
/// the source's way.
fn facing(source: &HumanoidMap, s_at: &[Vec3], target: &HumanoidMap, t_at: &[Vec3]) -> Quat {
    use HumanBone::*;
    let side = |map: &HumanoidMap, at: &[Vec3]| {
        let v = at[map[&LeftUpperLeg]] - at[map[&RightUpperLeg]];
        v.z.atan2(v.x)
    };
    let turn = side(target, t_at) - side(source, s_at);
    let quarter = (turn / std::f32::consts::FRAC_PI_2).round() * std::f32::consts::FRAC_PI_2;
    Quat::from_rotation_y(quarter)
}

impl<'a> Retargeter<'a> {
    /// A retargeter from `source` to `target`; none when either lacks the legs (thigh,
    /// shin, foot) or the hips.
    pub fn new(source: Humanoid<'a>, target: Humanoid<'a>, rest: RestAlignment) -> Option<Self> {
        let (s, t) = (source.skeleton, target.skeleton);
        let (source_rest, source_rest_at) = match source.stands {
            Some(frame) => frame.world(s),
            None => world_frames(s, s.joint(0).rest_offset, &s.initial_pose()),
        };
        let (target_rest, target_rest_at) = world_frames(t, t.joint(0).rest_offset, &t.initial_pose());
        source.map.get(&HumanBone::Hips)?;
        target.map.get(&HumanBone::Hips)?;
        let (source_leg, target_leg) =
            (leg_length(source.map, &source_rest_at)?, leg_length(target.map, &target_rest_at)?);
        let turn = facing(source.map, &source_rest_at, target.map, &target_rest_at);
        let mut bones: Vec<Option<Bone>> = (0..t.len()).map(|_| None).collect();
        for (&bone, &tj) in target.map {
            let Some(&sj) = source.map.get(&bone) else { continue };
            // Only a bone below it is one the joint's turn can aim.
            let below = |map: &HumanoidMap, skeleton: &Skeleton, b: &HumanBone, j: usize| {
                map.get(b).copied().filter(|&c| skeleton.is_below(c, j))
            };
            let next =
                aims(bone).iter().find_map(|b| Some((below(target.map, t, b, tj)?, below(source.map, s, b, sj)?)));
            let turned_rest = turn * target_rest[tj];
            let (aligned_rest, aim) = match next {
                Some((tc, sc)) => {
                    let t_dir = (target_rest_at[tc] - target_rest_at[tj]).normalize_or_zero();
                    let s_dir = (source_rest_at[sc] - source_rest_at[sj]).normalize_or_zero();
                    let swing = match rest {
                        RestAlignment::Directions => Quat::from_rotation_arc(turn * t_dir, s_dir),
                        RestAlignment::OwnRest => Quat::IDENTITY,
                    };
                    ((swing * turned_rest).normalize(), Some((tc, sc)))
                }
                None => (turned_rest, None),
            };
            bones[tj] = Some(Bone { source: sj, aligned_rest, aim });
        }
        // A bone without a direction of its own (a hand, the head) keeps its rest as it
        // lies on its parent bone's aligned rest.
        for j in 0..t.len() {
            let Some(bone) = &bones[j] else { continue };
            if bone.aim.is_some() || rest == RestAlignment::OwnRest {
                continue;
            }
            let mut p = t.parent(j);
            while let Some(up) = p {
                if let Some(parent) = &bones[up] {
                    let carried = parent.aligned_rest * target_rest[up].inverse() * target_rest[j];
                    bones[j].as_mut().expect("checked above").aligned_rest = carried.normalize();
                    break;
                }
                p = t.parent(up);
            }
        }
        let namesakes =
            (0..t.len()).map(|j| if bones[j].is_some() { None } else { s.find(&t.joint(j).name) }).collect();
        let waist = waist(t, target.map).filter(|_| source.map.contains_key(&HumanBone::Chest));
        let clearances = (
            source.lowest_foot(&source_rest, &source_rest_at) - source.rest_floor,
            target.lowest_foot(&target_rest, &target_rest_at) - target.rest_floor,
        );
        Some(Self {
            source,
            target,
            rest,
            namesakes,
            waist,
            source_rest,
            source_rest_at,
            target_rest_at,
            bones,
            ratio: target_leg / source_leg.max(1e-9),
            source_leg,
            target_leg,
            clearances,
        })
    }

    /// The target's joints the source drives: the mapped ones and the namesakes.
    pub fn driven(&self) -> Vec<usize> {
        (0..self.bones.len()).filter(|&j| self.bones[j].is_some() || self.namesakes[j].is_some()).collect()
    }

    /// Target leg length over the source's.
    pub fn leg_ratio(&self) -> f32 {
        self.ratio
    }

    /// The source's frame carried onto the target (no feet planted), and the joints whose
    /// rotations the target's limits clamped.
    pub fn frame(&self, source: &Frame) -> (Frame, Vec<usize>) {
        let (pose, clamped, (s_rot, s_at)) = self.carried(source, self.target.skeleton.initial_pose(), |_| true);
        let root = self.placed_root((&s_rot, &s_at), &pose);
        (Frame::posed(root, pose), clamped)
    }

    /// The source's pose carried onto `base` (a pose of the target): the mapped joints
    /// whose source joints `drives` says, and (driving every joint) the unmapped joints
    /// with namesakes; the rest keep `base`. With the joints it clamped and the source's
    /// joints' world rotations and positions.
    fn carried(
        &self,
        source: &Frame,
        mut pose: Vec<JointRotation>,
        drives: impl Fn(usize) -> bool,
    ) -> (Vec<JointRotation>, Vec<usize>, WorldFrames) {
        let (s, t) = (self.source.skeleton, self.target.skeleton);
        let (s_rot, s_at) = source.world(s);
        let mut world = vec![Quat::IDENTITY; t.len()];
        let mut clamped = Vec::new();
        // Unmapped joints first (they hang on no mapped turn): their namesakes' turns.
        for (j, rotation) in pose.iter_mut().enumerate() {
            if let (None, Some(sj)) = (&self.bones[j], self.namesakes[j])
                && drives(sj)
            {
                *rotation = rotation.with_rotation_of(source.pose[sj].to_quat()).clamped(&t.joint(j).limits);
            }
        }
        for j in 0..t.len() {
            let parent = t.parent(j).map_or(Quat::IDENTITY, |p| world[p]);
            if let Some(bone) = self.bones[j].as_ref().filter(|b| drives(b.source)) {
                let turned = (s_rot[bone.source] * self.source_rest[bone.source].inverse()).normalize();
                let mut wanted = (turned * bone.aligned_rest).normalize();
                if let (RestAlignment::Directions, Some((tc, sc))) = (self.rest, bone.aim) {
                    let local = reach_in_frame(t, &pose, j, tc).normalize_or_zero();
                    let now = (s_at[sc] - s_at[bone.source]).normalize_or_zero();
                    if now != Vec3::ZERO && local != Vec3::ZERO {
                        wanted = (Quat::from_rotation_arc((wanted * local).normalize(), now) * wanted).normalize();
                    }
                }
                let free = pose[j].with_rotation_of((parent.inverse() * wanted).normalize());
                let held = free.clamped(&t.joint(j).limits);
                let (a, b) = (held.to_quat(), free.to_quat());
                if (a - b).length().min((a + b).length()) > 1e-4 {
                    clamped.push(j);
                }
                pose[j] = held;
            }
            if Some(j) == self.waist
                && let (Some(&sh), Some(&sc)) =
                    (self.source.map.get(&HumanBone::Hips), self.source.map.get(&HumanBone::Chest))
                && drives(sh)
            {
                let local = reach_in_frame(t, &pose, j, self.target.map[&HumanBone::Hips]);
                let now = (s_at[sh] - s_at[sc]).normalize_or_zero();
                let turned = (parent * pose[j].to_quat()).normalize();
                // The hips on the line from the chest along the source's direction, where
                // the waist (a child of the chest) can reach it: from the waist at `from`
                // (the chest at 0), the farther point of that line at the hips' distance.
                let from = parent * t.joint(j).rest_offset;
                let along = now.dot(from);
                let reach = (along * along - from.length_squared() + local.length_squared()).max(0.0).sqrt();
                let goal = (now * (along + reach) - from).normalize_or_zero();
                if goal != Vec3::ZERO && local != Vec3::ZERO {
                    let wanted = (Quat::from_rotation_arc((turned * local).normalize(), goal) * turned).normalize();
                    let free = pose[j].with_rotation_of((parent.inverse() * wanted).normalize());
                    pose[j] = free.clamped(&t.joint(j).limits);
                    if pose[j] != free {
                        clamped.push(j);
                    }
                }
            }
            world[j] = (parent * pose[j].to_quat()).normalize();
        }
        (pose, clamped, (s_rot, s_at))
    }

    /// The target's joints driven by the source joints `driving`, carried from
    /// `source_pose` onto the target posed as `base`: each such bone turned in the world
    /// as the source's (pointing as it does), under its parents as `base` has them.
    pub fn pose_over(
        &self,
        source_pose: &[JointRotation],
        base: &[JointRotation],
        driving: &[usize],
    ) -> Vec<(usize, JointRotation)> {
        let frame = Frame::posed(self.source.skeleton.joint(0).rest_offset, source_pose.to_vec());
        let (pose, _, _) = self.carried(&frame, base.to_vec(), |sj| driving.contains(&sj));
        (0..pose.len()).filter(|&j| pose[j] != base[j]).map(|j| (j, pose[j])).collect()
    }

    /// The target root that puts its hips where the source's are, scaled by the leg ratio:
    /// across from their rests; in height, its lowest foot joint as far over its floor as
    /// it stands, raised as the source's is over its own standing clearance times the
    /// ratio (the hips' height over the floor, from their standing heights, for a rig
    /// without feet on either side).
    fn placed_root(&self, (s_rot, s_at): (&[Quat], &[Vec3]), pose: &[JointRotation]) -> Vec3 {
        let t = self.target.skeleton;
        let (sh, th) = (self.source.map[&HumanBone::Hips], self.target.map[&HumanBone::Hips]);
        let root_offset = t.joint(0).rest_offset;
        let (rotations, at) = world_frames(t, root_offset, pose);
        let moved = (s_at[sh] - self.source_rest_at[sh]) * self.ratio;
        let mut shift = self.target_rest_at[th] + moved - at[th];
        let (s_low, t_low) = (self.source.lowest_foot(s_rot, s_at), self.target.lowest_foot(&rotations, &at));
        let (s_clear, t_clear) = self.clearances;
        shift.y = if s_low.is_finite() && t_low.is_finite() {
            self.target.floor + t_clear + (s_low - self.source.floor - s_clear) * self.ratio - t_low
        } else {
            let (s_standing, t_standing) = (
                self.source_rest_at[sh].y - self.source.rest_floor,
                self.target_rest_at[th].y - self.target.rest_floor,
            );
            self.target.floor + t_standing + (s_at[sh].y - self.source.floor - s_standing) * self.ratio - at[th].y
        };
        root_offset + shift
    }

    /// Every frame carried onto the target (`fps` frames a second), with the source's
    /// planted feet kept planted when `plant`.
    pub fn motion(&self, frames: &[Frame], fps: f32, plant: bool) -> Retargeted {
        let mut out = Retargeted::default();
        for (f, frame) in frames.iter().enumerate() {
            let (carried, clamped) = self.frame(frame);
            out.clamped.extend(clamped.into_iter().map(|j| (f, j)));
            out.frames.push(carried);
        }
        use HumanBone::*;
        for (k, (bone, toes)) in [(LeftFoot, LeftToes), (RightFoot, RightToes)].into_iter().enumerate() {
            if let (Some(&sf), Some(&tf)) = (self.source.map.get(&bone), self.target.map.get(&bone)) {
                let toes = self.target.map.get(&toes).copied();
                (out.planted[k], out.legs_moved[k]) =
                    self.plant_foot(frames, &mut out.frames, fps, (sf, tf, toes), plant);
            }
        }
        out
    }

    /// Keeps the source's planted foot `sf` planted on the target's `tf` (with `plant`),
    /// and the target's foot and its toes above the floor: which frames hold it, and in
    /// which the leg was moved.
    fn plant_foot(
        &self,
        source: &[Frame],
        target: &mut [Frame],
        fps: f32,
        (sf, tf, toes): (usize, usize, Option<usize>),
        plant: bool,
    ) -> (Vec<bool>, Vec<bool>) {
        let (s, t) = (self.source.skeleton, self.target.skeleton);
        let s_foot: Vec<Vec3> = source.iter().map(|f| f.world(s).1[sf]).collect();
        // The ankles' standing heights over their floors.
        let (s_ankle, t_ankle) =
            (self.source_rest_at[sf].y - self.source.rest_floor, self.target_rest_at[tf].y - self.target.rest_floor);
        let (floor, leg) = (self.source.floor, self.source_leg);
        let mut planted = planted_frames(&s_foot, fps, floor, floor + s_ankle, leg);
        planted.iter_mut().for_each(|p| *p &= plant);
        // The lowest the target's ankle may go, for the source's ankle at `y`: standing
        // height where the source's stands (or higher), lower in proportion where the
        // source's is lower (a foot rolled onto its toes).
        // Within a two-hundredth of the leg of it (a few millimetres, which a near-straight
        // knee would have to bend degrees to give), an ankle is left where the source's
        // directions put it.
        let slack = 0.005 * self.target_leg;
        let lowest = |y: f32| {
            let standing = ((y - self.source.floor) / s_ankle.max(1e-6)).clamp(0.0, 1.0);
            self.target.floor + t_ankle.max(0.0) * standing - slack
        };
        let fade = (fps * 0.15).round().max(1.0) as usize;
        let mut anchor: Option<(Vec3, Vec3)> = None;
        let mut last_fix = Vec3::ZERO;
        let mut since_contact = usize::MAX;
        let mut moved = vec![false; target.len()];
        for f in 0..target.len() {
            let free = world_frames(t, target[f].root, &target[f].pose).1[tf];
            let floor_fix = Vec3::Y * (lowest(s_foot[f].y) - free.y).max(0.0);
            let goal = if planted[f] {
                let (start_target, start_source) = *anchor.get_or_insert((free + floor_fix, s_foot[f]));
                since_contact = 0;
                at_least_at(start_target + (s_foot[f] - start_source) * self.ratio, lowest(s_foot[f].y))
            } else {
                anchor = None;
                since_contact = since_contact.saturating_add(1);
                let fading = if since_contact <= fade {
                    last_fix * (1.0 - since_contact as f32 / (fade + 1) as f32)
                } else {
                    Vec3::ZERO
                };
                at_least_at(free + fading, lowest(s_foot[f].y))
            };
            last_fix = if planted[f] { goal - free } else { last_fix };
            if goal.distance(free) > 1e-6 * self.target_leg {
                self.reach(&mut target[f], tf, goal);
                moved[f] = true;
            }
            if let Some(toes) = toes {
                self.lift_toes(&mut target[f], tf, toes);
            }
        }
        (planted, moved)
    }

    /// Turns the target's foot `foot` up about its ankle as far as keeps its toes `toes`
    /// on the floor, where they would go below it.
    fn lift_toes(&self, frame: &mut Frame, foot: usize, toes: usize) {
        let t = self.target.skeleton;
        let (rotations, at) = world_frames(t, frame.root, &frame.pose);
        let floor = self.target.floor;
        let (ankle, tip) = (at[foot], at[toes]);
        if tip.y >= floor || ankle.y <= floor {
            return;
        }
        let along = tip - ankle;
        let (length, flat) = (along.length(), Vec3::new(along.x, 0.0, along.z));
        let drop = floor - ankle.y;
        let wanted = (flat.normalize_or_zero() * (length * length - drop * drop).max(0.0).sqrt()) + Vec3::Y * drop;
        let turn = Quat::from_rotation_arc(along.normalize(), wanted.normalize());
        let parent = t.parent(foot).map_or(Quat::IDENTITY, |p| rotations[p]);
        let local = (parent.inverse() * turn * rotations[foot]).normalize();
        frame.pose[foot] = frame.pose[foot].with_rotation_of(local).clamped(&t.joint(foot).limits);
    }

    /// Moves the target's foot `foot` to `goal` by IK on its leg, the foot keeping its turn
    /// in the world.
    fn reach(&self, frame: &mut Frame, foot: usize, goal: Vec3) {
        let t = self.target.skeleton;
        let origin = frame.origin(t);
        let (before, _) = world_frames(t, frame.root, &frame.pose);
        let tolerance = 1e-4 * self.target_leg;
        solve_ik(t, &mut frame.pose, origin, &[IkGoal { end: foot, target: goal }], tolerance, 8);
        let (after, _) = world_frames(t, frame.root, &frame.pose);
        if let Some(p) = t.parent(foot) {
            let local = (after[p].inverse() * before[foot]).normalize();
            frame.pose[foot] = frame.pose[foot].with_rotation_of(local).clamped(&t.joint(foot).limits);
        }
    }
}

/// Where joint `below` lies in joint `j`'s turned frame, through the turns `pose` gives
/// the joints between them.
fn reach_in_frame(skeleton: &Skeleton, pose: &[JointRotation], j: usize, below: usize) -> Vec3 {
    let mut at = skeleton.joint(below).rest_offset;
    let mut k = below;
    while let Some(p) = skeleton.parent(k).filter(|&p| p != j) {
        at = skeleton.joint(p).rest_offset + pose[p].to_quat() * at;
        k = p;
    }
    at
}

/// The joint that hangs `map`'s hips below its chest: the first on the way from the chest
/// down to the hips, where the hips lie below the chest.
fn waist(skeleton: &Skeleton, map: &HumanoidMap) -> Option<usize> {
    let (hips, chest) = (*map.get(&HumanBone::Hips)?, *map.get(&HumanBone::Chest)?);
    let mut j = hips;
    while let Some(p) = skeleton.parent(j) {
        if p == chest {
            // Hips hung from the chest itself turn with it: no joint between to aim.
            return (j != hips).then_some(j);
        }
        j = p;
    }
    None
}

/// `v` raised to height `y` where it lies lower.
fn at_least_at(v: Vec3, y: f32) -> Vec3 {
    Vec3::new(v.x, v.y.max(y), v.z)
}

/// The frames in which a foot at `at` (a position per frame) is planted: still (slower
/// than a tenth of its leg length a second) and low (its ankle within a quarter leg of its
/// standing height over the floor).
pub fn planted_frames(at: &[Vec3], fps: f32, floor: f32, standing: f32, leg: f32) -> Vec<bool> {
    let n = at.len();
    (0..n)
        .map(|f| {
            let (a, b) = (f.saturating_sub(1), (f + 1).min(n.saturating_sub(1)));
            let span = (b - a).max(1) as f32 / fps;
            let speed = at[b].distance(at[a]) / span;
            let height = at[f].y - floor;
            speed < 0.1 * leg && height < (standing - floor) + 0.25 * leg
        })
        .collect()
}

/// `source_pose` of the source carried onto the target, rotations only (the pose library,
/// copy and paste): each mapped bone turned as the source's from rest to rest.
pub fn retarget_pose(
    source: (&Skeleton, &HumanoidMap),
    source_pose: &[JointRotation],
    target: (&Skeleton, &HumanoidMap),
    rest: RestAlignment,
) -> Option<Vec<JointRotation>> {
    let retargeter = Retargeter::new(
        Humanoid { skeleton: source.0, map: source.1, floor: 0.0, rest_floor: 0.0, soles: &[], stands: None },
        Humanoid { skeleton: target.0, map: target.1, floor: 0.0, rest_floor: 0.0, soles: &[], stands: None },
        rest,
    )?;
    let frame = Frame::posed(source.0.joint(0).rest_offset, source_pose.to_vec());
    Some(retargeter.frame(&frame).0.pose)
}

//! Posing and exporting without the ECS: `JOINT=rx,ry,rz` specs, posed skins, and the
//! `info` summary. Used by the CLI and by tests; no Bevy.

use glam::{Mat4, Vec3};

use marionette_rig::dqs::SkinningMethod;
use marionette_rig::fk::{RestOverride, posed_palette_with_rest};
use marionette_rig::node_clip::NodeClip;
use marionette_rig::{CharacterAsset, JointRotation, Skeleton};

/// What is wrong with a `JOINT=rx,ry,rz` spec.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PoseSpecError {
    #[error("`{spec}`: expected JOINT=rx,ry,rz (radians)")]
    Syntax { spec: String },
    #[error("`{spec}`: no joint named or numbered `{joint}` (joints: {known})")]
    UnknownJoint { spec: String, joint: String, known: String },
    /// A spec of another shape, and what it expects.
    #[error("`{spec}`: {expected}")]
    Expected { spec: String, expected: String },
}

/// A parsed `JOINT=rx,ry,rz` (angles in radians, x applied first).
#[derive(Debug, Clone, PartialEq)]
pub struct PoseSpec {
    pub joint: String,
    pub angles: Vec3,
}

impl std::str::FromStr for PoseSpec {
    type Err = PoseSpecError;

    fn from_str(spec: &str) -> Result<Self, Self::Err> {
        let err = || PoseSpecError::Syntax { spec: spec.to_string() };
        let (joint, angles) = spec.split_once('=').ok_or_else(err)?;
        let a: Vec<f32> =
            angles.split(',').map(|t| t.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|_| err())?;
        if joint.is_empty() || a.len() != 3 || a.iter().any(|v| !v.is_finite()) {
            return Err(err());
        }
        Ok(Self { joint: joint.to_string(), angles: Vec3::new(a[0], a[1], a[2]) })
    }
}

/// Applies specs on top of `pose`, each clamped to its joint's limits.
pub fn apply_pose_specs(
    skeleton: &Skeleton,
    pose: &mut [JointRotation],
    specs: &[PoseSpec],
) -> Result<(), PoseSpecError> {
    for spec in specs {
        let j = skeleton.resolve(&spec.joint).ok_or_else(|| PoseSpecError::UnknownJoint {
            spec: format!("{}={},{},{}", spec.joint, spec.angles.x, spec.angles.y, spec.angles.z),
            joint: spec.joint.clone(),
            known: joint_list(skeleton),
        })?;
        let order = match pose[j] {
            JointRotation::Euler(_, order) => order,
            JointRotation::Quat(_) => Default::default(),
        };
        pose[j] = JointRotation::Euler(spec.angles, order).clamped(&skeleton.joint(j).limits);
    }
    Ok(())
}

fn joint_list(skeleton: &Skeleton) -> String {
    let names: Vec<&str> = skeleton.joints().iter().map(|j| j.name.as_str()).collect();
    name_list(&names)
}

/// Names for a message: all of them, or the first 12 and how many there are.
pub fn name_list(names: &[impl AsRef<str>]) -> String {
    let names: Vec<&str> = names.iter().map(AsRef::as_ref).collect();
    if names.len() > 12 {
        format!("{}, ... ({} in all)", names[..12].join(", "), names.len())
    } else {
        names.join(", ")
    }
}

/// The skin's vertices at `pose`, in source order, with the character placed by `placement`.
pub fn posed_positions(asset: &CharacterAsset, pose: &[JointRotation], placement: Mat4) -> Vec<Vec3> {
    posed_positions_by(asset, pose, placement, SkinningMethod::Linear)
}

/// As [`posed_positions`], by linear blend or dual quaternion skinning.
pub fn posed_positions_by(
    asset: &CharacterAsset,
    pose: &[JointRotation],
    placement: Mat4,
    method: SkinningMethod,
) -> Vec<Vec3> {
    posed_positions_with_rest(asset, pose, RestOverride::default(), placement, method)
}

/// As [`posed_positions_by`], with the rest offsets and scales a clip keys.
pub fn posed_positions_with_rest(
    asset: &CharacterAsset,
    pose: &[JointRotation],
    rest: RestOverride,
    placement: Mat4,
    method: SkinningMethod,
) -> Vec<Vec3> {
    let mut out = vec![Vec3::ZERO; asset.vertex_count()];
    let (skeleton, binds, weights) = (&asset.skeleton, &asset.bind_world_to_joint, &asset.skin.weights);
    // Skinned in model space, then placed, as the editor does (its placement is the
    // character's transform; a dual quaternion holds no scale).
    let palette = posed_palette_with_rest(skeleton, binds, pose, rest, Mat4::IDENTITY);
    marionette_rig::dqs::skin_by(method, &asset.skin.bind_positions, weights, &palette, &mut out);
    out.iter_mut().for_each(|p| *p = placement.transform_point3(*p));
    out
}

/// The animation `spec` names among a character's clips: by name, or by its index among
/// the file's animations.
pub fn find_clip<'a>(clips: &'a [NodeClip], spec: &str) -> Option<&'a NodeClip> {
    clips.iter().find(|c| c.name == spec).or_else(|| {
        let index: usize = spec.parse().ok()?;
        clips.iter().find(|c| c.index == index)
    })
}

/// A human-readable summary of what was loaded.
pub fn describe(asset: &CharacterAsset) -> String {
    let s = &asset.skeleton;
    let w = &asset.skin.weights;
    let (lo, hi) = asset.bounds();
    let mut out = String::new();
    out += &format!("character: {}\n", asset.name);
    out += &format!("joints: {}\n", s.len());
    for (i, j) in s.joints().iter().enumerate() {
        let parent = j.parent.map_or("-".to_string(), |p| p.to_string());
        let limits = if j.limits.is_unlimited() {
            String::new()
        } else {
            format!(
                "  limits x[{:.3},{:.3}] y[{:.3},{:.3}] z[{:.3},{:.3}]",
                j.limits.min.x, j.limits.max.x, j.limits.min.y, j.limits.max.y, j.limits.min.z, j.limits.max.z
            )
        };
        out += &format!(
            "  {i:3} {:<24} parent {parent:>3}  offset ({:.4}, {:.4}, {:.4}){limits}\n",
            j.name, j.rest_offset.x, j.rest_offset.y, j.rest_offset.z
        );
    }
    let kind = match asset.skin_kind {
        marionette_rig::character::SkinKind::Mesh => "mesh",
        marionette_rig::character::SkinKind::BoneBoxes => "bone boxes (no mesh in the source)",
        marionette_rig::character::SkinKind::Rigid => "meshes carried by their nodes (a prop: nothing skinned)",
    };
    out += &format!("skin: {kind}\n");
    out += &describe_humanoid(asset);
    out += &format!("vertices: {}\n", asset.vertex_count());
    out += &format!("triangles: {}\n", asset.triangle_count());
    if !asset.morphs.is_empty() {
        let names: Vec<&str> = asset.morphs.iter().map(|m| m.name.as_str()).collect();
        out += &format!("morphs: {}\n", names.join(", "));
    }
    if !asset.expressions.is_empty() {
        let names: Vec<&str> = asset.expressions.iter().map(|e| e.name.as_str()).collect();
        out += &format!("expressions: {}\n", names.join(", "));
    }
    let avg = if w.vertex_count() > 0 { w.total_influences() as f32 / w.vertex_count() as f32 } else { 0.0 };
    out += &format!("influences per vertex: max {}, mean {avg:.2}\n", w.max_influences());
    out += &format!("bounds: ({:.3}, {:.3}, {:.3}) .. ({:.3}, {:.3}, {:.3})\n", lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
    if asset.warnings.is_empty() {
        out += "weight warnings: none\n";
    } else {
        for warning in &asset.warnings {
            out += &format!("warning: {warning}\n");
        }
    }
    out
}

/// The humanoid map: how many bones and how they were found, then a line a bone
/// (`Bone = joint (how)`) and a line for each doubt; or why there is none.
pub fn describe_humanoid(asset: &CharacterAsset) -> String {
    let skeleton = &asset.skeleton;
    if skeleton.len() < 5 {
        return String::new();
    }
    let Some(found) = marionette_rig::humanoid::of_asset(asset) else {
        return "humanoid: not found (no two legs and two arms)\n".to_string();
    };
    use marionette_rig::humanoid::Found;
    let count = |how: Found| found.found.values().filter(|&&f| f == how).count();
    let mut out = format!(
        "humanoid: {} of {} bones ({} by name, {} by structure, {} named by the file)\n",
        found.map.len(),
        marionette_rig::humanoid::HumanBone::ALL.len(),
        count(Found::Name),
        count(Found::Structure),
        count(Found::File),
    );
    for (bone, &j) in &found.map {
        let how = match found.found.get(bone) {
            Some(Found::Name) => "name",
            Some(Found::Structure) => "structure",
            Some(Found::File) => "file",
            None => "assigned",
        };
        out += &format!("  {bone:?} = {} ({how})\n", skeleton.joint(j).name);
    }
    for doubt in &found.doubts {
        out += &format!("humanoid doubt: {doubt}\n");
    }
    if found.map.contains_key(&marionette_rig::humanoid::HumanBone::Hips) {
        let names: Vec<&str> = marionette_rig::body_poses::POSES.iter().map(|p| p.name).collect();
        out += &format!("body poses (--preset NAME[:mirrored]): {}\n", names.join(", "));
    }
    if found.map.keys().any(|b| b.is_finger()) {
        let names: Vec<&str> = marionette_rig::hands::PRESETS.iter().map(|p| p.0).collect();
        out += &format!("hand presets (--hand left=NAME, right=NAME): {}\n", names.join(", "));
    }
    out
}

/// A parsed `JOINT=x,y,z`: move the joint to a world-space target by IK.
#[derive(Debug, Clone, PartialEq)]
pub struct IkSpec {
    pub joint: String,
    pub target: Vec3,
}

impl std::str::FromStr for IkSpec {
    type Err = PoseSpecError;

    fn from_str(spec: &str) -> Result<Self, Self::Err> {
        let pose: PoseSpec = spec
            .parse()
            .map_err(|_| PoseSpecError::Syntax { spec: format!("{spec} (expected JOINT=x,y,z, world space)") })?;
        Ok(Self { joint: pose.joint, target: pose.angles })
    }
}

/// A parsed `JOINT=x,y,z[@x,y,z]`: the limb ending at JOINT (an ankle or a wrist) turned
/// by two-bone IK so that JOINT reaches the target, its middle joint bending toward the
/// pole (world space).
#[derive(Debug, Clone, PartialEq)]
pub struct TwoBoneSpec {
    pub joint: String,
    pub target: Vec3,
    pub pole: Option<Vec3>,
}

impl std::str::FromStr for TwoBoneSpec {
    type Err = PoseSpecError;

    fn from_str(spec: &str) -> Result<Self, Self::Err> {
        let syntax = || PoseSpecError::Syntax { spec: format!("{spec} (expected JOINT=x,y,z or JOINT=x,y,z@x,y,z)") };
        let (goal, pole) = match spec.split_once('@') {
            Some((goal, pole)) => (goal, Some(pole)),
            None => (spec, None),
        };
        let goal: IkSpec = goal.parse().map_err(|_| syntax())?;
        let pole = pole
            .map(|p| {
                let numbers: Vec<f32> =
                    p.split(',').map(|n| n.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|_| syntax())?;
                match numbers[..] {
                    [x, y, z] if [x, y, z].iter().all(|v| v.is_finite()) => Ok(Vec3::new(x, y, z)),
                    _ => Err(syntax()),
                }
            })
            .transpose()?;
        Ok(Self { joint: goal.joint, target: goal.target, pole })
    }
}

/// Solves the two-bone specs in turn on top of `pose`, for a character placed by
/// `placement`; a joint without a grandparent is refused.
pub fn apply_two_bone_specs(
    skeleton: &Skeleton,
    pose: &mut [JointRotation],
    placement: Mat4,
    specs: &[TwoBoneSpec],
) -> Result<Vec<marionette_rig::two_bone::TwoBoneReport>, PoseSpecError> {
    specs
        .iter()
        .map(|s| {
            let unknown = || PoseSpecError::UnknownJoint {
                spec: s.joint.clone(),
                joint: s.joint.clone(),
                known: joint_list(skeleton),
            };
            let end = skeleton.resolve(&s.joint).ok_or_else(unknown)?;
            let goal = marionette_rig::two_bone::TwoBoneGoal { end, target: s.target, pole: s.pole, soft: 0.0 };
            marionette_rig::two_bone::solve_two_bone(skeleton, pose, placement, goal, IK_TOLERANCE).ok_or_else(|| {
                PoseSpecError::Expected {
                    spec: s.joint.clone(),
                    expected: "expected the end of a limb: a joint with a parent and a grandparent".into(),
                }
            })
        })
        .collect()
}

/// One line about a two-bone solve.
pub fn describe_two_bone(skeleton: &Skeleton, r: &marionette_rig::two_bone::TwoBoneReport) -> String {
    let [root, mid, end] = r.chain.map(|j| skeleton.joint(j).name.as_str());
    format!(
        "two-bone {root} → {mid} → {end}: {}, distance {:.5}{}",
        if r.reached { "reached" } else { "not reached (the limb straight toward it)" },
        r.distance,
        if r.limited { ", stopped by joint limits" } else { "" }
    )
}

/// A parsed `JOINT=x,y,z`: JOINT (a head) turned so that its face points at the target
/// (world space).
#[derive(Debug, Clone, PartialEq)]
pub struct LookAtSpec {
    pub joint: String,
    pub target: Vec3,
}

impl std::str::FromStr for LookAtSpec {
    type Err = PoseSpecError;

    fn from_str(spec: &str) -> Result<Self, Self::Err> {
        let goal: IkSpec = spec.parse()?;
        Ok(Self { joint: goal.joint, target: goal.target })
    }
}

/// A parsed `NAME`, `NAME:mirrored` and either with `@BLEND`: a built-in body pose
/// (`sit-chair`, `wave`, …), blended from the pose it is put over by `blend` (1, all the
/// way, unless given; `walk@0.5` halfway from a clip's pose at `--time`).
#[derive(Debug, Clone, PartialEq)]
pub struct BodyPoseSpec {
    pub name: String,
    pub mirrored: bool,
    pub blend: f32,
}

impl BodyPoseSpec {
    /// The body pose `name`, as it is or mirrored, all the way.
    pub fn new(name: impl Into<String>, mirrored: bool) -> Self {
        Self { name: name.into(), mirrored, blend: 1.0 }
    }
}

impl std::str::FromStr for BodyPoseSpec {
    type Err = PoseSpecError;

    fn from_str(spec: &str) -> Result<Self, Self::Err> {
        let expected = |what: String| PoseSpecError::Expected { spec: spec.to_string(), expected: what };
        let (pose, blend) = match spec.trim().split_once('@') {
            Some((pose, blend)) => match blend.trim().parse::<f32>() {
                Ok(b) if (0.0..=1.0).contains(&b) => (pose, b),
                _ => return Err(expected(format!("expected a blend from 0 to 1 after `@`, found `{blend}`"))),
            },
            None => (spec.trim(), 1.0),
        };
        let (name, mirrored) = match pose.trim().split_once(':') {
            Some((name, "mirrored" | "mirror")) => (name, true),
            Some(_) => ("", false),
            None => (pose.trim(), false),
        };
        if marionette_rig::body_poses::body_pose(name).is_none() {
            let names: Vec<&str> = marionette_rig::body_poses::POSES.iter().map(|p| p.name).collect();
            return Err(expected(format!(
                "expected NAME or NAME:mirrored (then @BLEND), NAME one of {}",
                names.join(", ")
            )));
        }
        Ok(Self { name: name.to_string(), mirrored, blend })
    }
}

/// `pose` with the built-in body pose `spec` put on it through the humanoid map `map`,
/// blended from the pose as it was by `blend` (0: as it was, 1: the body pose; each joint
/// turned the shortest way). Returns the new pose and the joints the limits held short, or
/// `None` when the map lacks hips or legs.
pub fn body_posed(
    skeleton: &Skeleton,
    map: &marionette_rig::humanoid::HumanoidMap,
    pose: &[JointRotation],
    spec: &BodyPoseSpec,
    blend: f32,
) -> Option<(Vec<JointRotation>, Vec<usize>)> {
    let body = marionette_rig::body_poses::body_pose(&spec.name)?;
    let mut posed = pose.to_vec();
    let report = marionette_rig::body_poses::apply_body_pose(skeleton, map, &mut posed, body, spec.mirrored)?;
    if blend < 1.0 {
        for (to, from) in posed.iter_mut().zip(pose) {
            let (a, b) = (from.to_quat(), to.to_quat());
            *to = from.with_rotation_of(a.slerp(b, blend.clamp(0.0, 1.0)));
        }
    }
    Some((posed, report.limited))
}

/// What a body pose did, for the notes.
pub fn describe_body_pose(skeleton: &Skeleton, spec: &BodyPoseSpec, limited: &[usize]) -> String {
    let mut name = if spec.mirrored { format!("{} (mirrored)", spec.name) } else { spec.name.clone() };
    if spec.blend < 1.0 {
        name += &format!(" blended {:.2} of the way", spec.blend);
    }
    match limited {
        [] => format!("pose {name}"),
        _ => {
            let joints: Vec<&str> = limited.iter().map(|&j| skeleton.joint(j).name.as_str()).collect();
            format!("pose {name}, held short by the limits of {}", joints.join(", "))
        }
    }
}

/// `placement` moved up or down so that the skin at `pose` (its joints, for a skeleton
/// without skin) rests on the floor, y = 0.
pub fn stood_on_floor(asset: &CharacterAsset, pose: &[JointRotation], placement: Mat4) -> Mat4 {
    let skin = posed_positions(asset, pose, placement);
    let lowest = if skin.is_empty() {
        let mut world = vec![Mat4::IDENTITY; asset.skeleton.len()];
        marionette_rig::fk::forward_kinematics(&asset.skeleton, pose, placement, &mut world);
        world.iter().map(|m| m.w_axis.y).fold(f32::INFINITY, f32::min)
    } else {
        skin.iter().map(|p| p.y).fold(f32::INFINITY, f32::min)
    };
    if lowest.is_finite() { Mat4::from_translation(Vec3::new(0.0, -lowest, 0.0)) * placement } else { placement }
}

/// A parsed `SIDE=NAME`: a hand preset (`fist`, `open`, …) on the left or right hand.
#[derive(Debug, Clone, PartialEq)]
pub struct HandSpec {
    pub left: bool,
    pub preset: String,
}

impl std::str::FromStr for HandSpec {
    type Err = PoseSpecError;

    fn from_str(spec: &str) -> Result<Self, Self::Err> {
        let names: Vec<&str> = marionette_rig::hands::PRESETS.iter().map(|p| p.0).collect();
        let syntax = || PoseSpecError::Expected {
            spec: spec.to_string(),
            expected: format!("expected left=NAME or right=NAME, NAME one of {}", names.join(", ")),
        };
        let (side, preset) = spec.split_once('=').ok_or_else(syntax)?;
        let left = match side.trim() {
            "left" | "l" => true,
            "right" | "r" => false,
            _ => return Err(syntax()),
        };
        if marionette_rig::hands::preset(preset.trim()).is_none() {
            return Err(syntax());
        }
        Ok(Self { left, preset: preset.trim().to_string() })
    }
}

/// Puts the hand presets on `pose` through the skeleton's humanoid map `map`. Returns a note per
/// hand, or why a hand could not be posed (no humanoid, no fingers mapped).
pub fn apply_hand_specs(
    skeleton: &Skeleton,
    map: &marionette_rig::humanoid::HumanoidMap,
    pose: &mut [JointRotation],
    specs: &[HandSpec],
) -> Vec<String> {
    specs
        .iter()
        .map(|s| {
            let side = if s.left { "left" } else { "right" };
            let (curl, spread) = marionette_rig::hands::preset(&s.preset).unwrap_or(([0.0; 5], 0.0));
            match marionette_rig::hands::apply_hand(skeleton, map, pose, s.left, curl, spread) {
                Some(false) => format!("hand {side}: {}", s.preset),
                Some(true) => format!("hand {side}: {}, stopped by joint limits", s.preset),
                None => format!("hand {side}: no fingers mapped; {} skipped", s.preset),
            }
        })
        .collect()
}

pub use marionette_rig::look_at::LOOK_AT_SHARES;

/// Turns each spec's joint so that its face points at the target, on top of `pose`, for a
/// character placed by `placement`. The face is where the character faces at rest (square
/// to its hips' line, from the humanoid map `map`; else +z); a joint the map calls the head
/// spreads the turn over the chest and neck.
pub fn apply_look_at_specs(
    skeleton: &Skeleton,
    map: &marionette_rig::humanoid::HumanoidMap,
    pose: &mut [JointRotation],
    placement: Mat4,
    specs: &[LookAtSpec],
) -> Result<Vec<marionette_rig::look_at::LookAtReport>, PoseSpecError> {
    let goals = look_at_goals(skeleton, map, specs)?;
    Ok(goals.iter().map(|g| g.solve(skeleton, pose, placement)).collect())
}

/// A look-at worked out for a skeleton: the joints it turns (the head last), the head's
/// face in its own frame, the target.
#[derive(Debug, Clone)]
struct LookAtGoal {
    joints: Vec<usize>,
    face: Vec3,
    target: Vec3,
}

impl LookAtGoal {
    fn solve(&self, skeleton: &Skeleton, pose: &mut [JointRotation], placement: Mat4) -> LookAtReport {
        let (joints, face) = (&self.joints, self.face);
        marionette_rig::look_at::solve_look_at(skeleton, pose, placement, joints, face, &LOOK_AT_SHARES, self.target)
    }

    /// The angle between the face and the target in `world` (degrees).
    fn off_degrees(&self, world: &[Mat4]) -> f32 {
        let head = world[*self.joints.last().expect("a look-at turns its joint")];
        let now = marionette_rig::ik::rotation_of(head) * self.face;
        now.angle_between(self.target - head.w_axis.truncate()).to_degrees()
    }
}

use marionette_rig::look_at::LookAtReport;

/// The look-at goals of `specs`: the face is where the character faces at rest (square to
/// its hips' line, from the humanoid map `map`; else +z); a joint the map calls the head
/// spreads the turn over the chest and neck.
fn look_at_goals(
    skeleton: &Skeleton,
    map: &marionette_rig::humanoid::HumanoidMap,
    specs: &[LookAtSpec],
) -> Result<Vec<LookAtGoal>, PoseSpecError> {
    use marionette_rig::humanoid::HumanBone;
    let mut rest = vec![Mat4::IDENTITY; skeleton.len()];
    marionette_rig::fk::forward_kinematics(skeleton, &skeleton.initial_pose(), Mat4::IDENTITY, &mut rest);
    let at = |j: usize| rest[j].w_axis.truncate();
    let facing = match (map.get(&HumanBone::RightUpperLeg), map.get(&HumanBone::LeftUpperLeg)) {
        (Some(&r), Some(&l)) => marionette_rig::look_at::facing(at(r), at(l)),
        _ => Vec3::Z,
    };
    specs
        .iter()
        .map(|s| {
            let joint = skeleton.resolve(&s.joint).ok_or_else(|| PoseSpecError::UnknownJoint {
                spec: s.joint.clone(),
                joint: s.joint.clone(),
                known: joint_list(skeleton),
            })?;
            let face = marionette_rig::ik::rotation_of(rest[joint]).inverse() * facing;
            let spread = [HumanBone::Chest, HumanBone::Neck].map(|b| map.get(&b).copied());
            let joints = match spread {
                [Some(chest), Some(neck)] if map.get(&HumanBone::Head) == Some(&joint) => vec![chest, neck, joint],
                _ => vec![joint],
            };
            Ok(LookAtGoal { joints, face, target: s.target })
        })
        .collect()
}

/// What the solving still edits reported, each measured on the pose they leave.
#[derive(Debug, Clone, Default)]
pub struct SolveReports {
    pub ik: Vec<marionette_rig::ik::IkReport>,
    pub two_bone: Vec<marionette_rig::two_bone::TwoBoneReport>,
    pub look_at: Vec<LookAtReport>,
}

impl SolveReports {
    /// Every report as the command line prints it, named by `who`.
    pub fn lines(&self, skeleton: &Skeleton, who: &str) -> Vec<String> {
        let ik = self.ik.iter().map(|r| describe_ik(skeleton, r));
        let two_bone = self.two_bone.iter().map(|r| describe_two_bone(skeleton, r));
        let look_at = self.look_at.iter().map(|r| describe_look_at(skeleton, r));
        ik.chain(two_bone).chain(look_at).map(|l| format!("{who}: {l}")).collect()
    }
}

/// Rounds of solving at most before the constraints are taken as they stand.
pub const CONSTRAINT_ROUNDS: usize = 4;

/// The solving still edits — IK, two-bone, look-at — on top of `pose`, for a character
/// placed by `placement`, composed so that each holds on the pose they leave together:
/// IK first, then the two-bone and look-at goals parents before children (by the depth of
/// the highest joint each turns: a look-at that turns the chest before the arm's
/// two-bone), all again while one that held no longer does (at most
/// [`CONSTRAINT_ROUNDS`]). Every report is measured on the final pose.
pub fn solve_constraints(
    skeleton: &Skeleton,
    map: &marionette_rig::humanoid::HumanoidMap,
    pose: &mut [JointRotation],
    placement: Mat4,
    (ik, two_bone, look_at): (&[IkSpec], &[TwoBoneSpec], &[LookAtSpec]),
) -> Result<SolveReports, PoseSpecError> {
    let looks = look_at_goals(skeleton, map, look_at)?;
    let depth = |mut j: usize| {
        let mut d = 0;
        while let Some(p) = skeleton.parent(j) {
            (j, d) = (p, d + 1);
        }
        d
    };
    // Two-bone goals as `Ok(k)`, look-ats as `Err(k)`, by the depth of their highest joint.
    let mut order: Vec<(usize, Result<usize, usize>)> = Vec::new();
    for (k, s) in two_bone.iter().enumerate() {
        let top = skeleton.resolve(&s.joint).and_then(|e| skeleton.parent(e)).and_then(|m| skeleton.parent(m));
        order.push((top.map_or(0, depth), Ok(k)));
    }
    order.extend(looks.iter().enumerate().map(|(k, g)| (depth(g.joints[0]), Err(k))));
    order.sort_by_key(|(d, _)| *d);
    let mut reports = SolveReports::default();
    for _ in 0..CONSTRAINT_ROUNDS {
        reports.ik = apply_ik_specs(skeleton, pose, placement, ik)?;
        reports.two_bone.clear();
        let mut twos = vec![None; two_bone.len()];
        let mut lookings = vec![None; looks.len()];
        for (_, goal) in &order {
            match *goal {
                Ok(k) => twos[k] = apply_two_bone_specs(skeleton, pose, placement, &two_bone[k..=k])?.pop(),
                Err(k) => lookings[k] = Some(looks[k].solve(skeleton, pose, placement)),
            }
        }
        reports.two_bone = twos.into_iter().flatten().collect();
        reports.look_at = lookings.into_iter().flatten().collect();
        let solved = (reports.ik.clone(), reports.two_bone.clone(), reports.look_at.clone());
        let targets = (ik.iter().map(|s| s.target).collect(), two_bone.iter().map(|s| s.target).collect());
        measure(skeleton, pose, placement, targets, &looks, &mut reports);
        let held = |was: bool, is: bool| !was || is;
        let still_hold = solved.0.iter().zip(&reports.ik).all(|(a, b)| held(a.reached, b.reached))
            && solved.1.iter().zip(&reports.two_bone).all(|(a, b)| held(a.reached, b.reached))
            && solved.2.iter().zip(&reports.look_at).all(|(a, b)| b.off_degrees <= a.off_degrees.max(LOOK_AT_HOLDS));
        if still_hold {
            break;
        }
    }
    Ok(reports)
}

/// A look-at holds within this angle (degrees).
pub const LOOK_AT_HOLDS: f32 = 0.1;

/// The reports' distances and angles (and whether each is reached) measured on `pose`.
fn measure(
    skeleton: &Skeleton,
    pose: &[JointRotation],
    placement: Mat4,
    (ik, two_bone): (Vec<Vec3>, Vec<Vec3>),
    looks: &[LookAtGoal],
    r: &mut SolveReports,
) {
    let mut world = vec![Mat4::IDENTITY; skeleton.len()];
    marionette_rig::fk::forward_kinematics(skeleton, pose, placement, &mut world);
    let at = |j: usize| world[j].w_axis.truncate();
    for (report, target) in r.ik.iter_mut().zip(ik) {
        report.distance = at(report.end).distance(target);
        report.reached = report.distance <= IK_TOLERANCE;
    }
    for (report, target) in r.two_bone.iter_mut().zip(two_bone) {
        report.distance = at(report.chain[2]).distance(target);
        report.reached = report.distance <= IK_TOLERANCE;
    }
    for (report, goal) in r.look_at.iter_mut().zip(looks) {
        report.off_degrees = goal.off_degrees(&world);
    }
}

/// One line about a look-at.
pub fn describe_look_at(skeleton: &Skeleton, r: &marionette_rig::look_at::LookAtReport) -> String {
    let names: Vec<&str> = r.joints.iter().map(|&j| skeleton.joint(j).name.as_str()).collect();
    format!(
        "look-at {}: the face {:.3}° off the target{}",
        names.join(" → "),
        r.off_degrees,
        if r.limited { ", stopped by joint limits" } else { "" }
    )
}

pub use marionette_rig::ik::{IK_ROUNDS, IK_TOLERANCE};

/// Solves the IK specs in turn on top of `pose` (after `--pose`), for a character placed
/// by `placement`.
pub fn apply_ik_specs(
    skeleton: &Skeleton,
    pose: &mut [JointRotation],
    placement: Mat4,
    specs: &[IkSpec],
) -> Result<Vec<marionette_rig::ik::IkReport>, PoseSpecError> {
    let goals = specs
        .iter()
        .map(|s| {
            let end = skeleton.resolve(&s.joint).ok_or_else(|| PoseSpecError::UnknownJoint {
                spec: s.joint.clone(),
                joint: s.joint.clone(),
                known: joint_list(skeleton),
            })?;
            Ok(marionette_rig::ik::IkGoal { end, target: s.target })
        })
        .collect::<Result<Vec<_>, PoseSpecError>>()?;
    Ok(marionette_rig::ik::solve_ik(skeleton, pose, placement, &goals, IK_TOLERANCE, IK_ROUNDS))
}

/// One line about an IK solve.
pub fn describe_ik(skeleton: &Skeleton, r: &marionette_rig::ik::IkReport) -> String {
    format!(
        "ik {}: {} after {} rounds ({} FABRIK iterations), distance {:.5}{}",
        skeleton.joint(r.end).name,
        if r.reached { "reached" } else { "not reached" },
        r.rounds,
        r.iterations,
        r.distance,
        if r.limited { ", stopped by joint limits" } else { "" }
    )
}

/// One line on a glTF clip: its index and name, length, channels, keys and interpolations.
pub fn describe_clip(clip: &NodeClip) -> String {
    use marionette_rig::node_clip::Interpolation;
    let mut channels = 0;
    let mut keys = 0;
    let mut kinds = Vec::new();
    let mut count = |times: usize, interpolation: Interpolation| {
        channels += 1;
        keys += times;
        if !kinds.contains(&interpolation) {
            kinds.push(interpolation);
        }
    };
    for t in &clip.tracks {
        t.translation.iter().for_each(|k| count(k.times.len(), k.interpolation));
        t.rotation.iter().for_each(|k| count(k.times.len(), k.interpolation));
        t.scale.iter().for_each(|k| count(k.times.len(), k.interpolation));
    }
    let weights = clip.weights.iter().flatten().count();
    clip.weights.iter().flatten().for_each(|k| count(k.times.len(), k.interpolation));
    let kinds: Vec<&str> = kinds
        .iter()
        .map(|k| match k {
            Interpolation::Step => "STEP",
            Interpolation::Linear => "LINEAR",
            Interpolation::CubicSpline => "CUBICSPLINE",
        })
        .collect();
    let morphs = if weights > 0 { format!(" ({weights} morph weights)") } else { String::new() };
    format!(
        "animation {} `{}`: {:.3} s, {channels} channels{morphs}, {keys} keys, {}",
        clip.index,
        clip.name,
        clip.duration(),
        kinds.join(" + ")
    )
}

/// One line on a material: its name, factors, textures, alpha and sidedness.
pub fn describe_material(m: &marionette_rig::material::Material) -> String {
    let [r, g, b, a] = m.base_color;
    let textures: Vec<&str> = m.textures().map(|(what, _)| what).collect();
    let textures = if textures.is_empty() { String::new() } else { format!(", textures: {}", textures.join(", ")) };
    let alpha = match m.alpha {
        marionette_rig::material::AlphaMode::Opaque => "opaque".to_string(),
        marionette_rig::material::AlphaMode::Mask(cutoff) => format!("alpha mask at {cutoff}"),
        marionette_rig::material::AlphaMode::Blend => "alpha blended".to_string(),
    };
    let sides = if m.double_sided { ", double-sided" } else { "" };
    format!(
        "material `{}`: base colour ({r:.3}, {g:.3}, {b:.3}, {a:.3}), metallic {:.2}, roughness {:.2}{textures}, {alpha}{sides}",
        m.name, m.metallic, m.roughness
    )
}

//! The humanoid map: which of a skeleton's joints is the hips, the spine, each arm's and
//! leg's bones. Found from the skeleton's structure as it stands (so rigs with numbered
//! joints, like the 6.837 models, are mapped too): the feet are its two lowest leaves on
//! either side, the hips where their chains meet; the hands the two leaves off the legs
//! farthest out on either side, the chest where theirs meet; the head the highest leaf
//! beyond the chest. Along each limb the upper and lower bone are its two longest
//! consecutive segments. Sides are told across the hips (from one hip joint to the other,
//! so a character turned or walking is read the same); left is the side the names say
//! (`L_`, `Left`, `.L`, `l_`), or else the one towards +x (a character facing +z).

use std::collections::BTreeMap;

use glam::{Mat4, Vec3};

use super::Skeleton;

pub mod names;

use names::{NameSays, Role, Side};

/// The standard bones of a humanoid: the body's, then each hand's fingers (thumb, index,
/// middle, ring, little), three phalanges each from the palm out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize)]
pub enum HumanBone {
    Hips,
    Spine,
    Chest,
    Neck,
    Head,
    LeftShoulder,
    LeftUpperArm,
    LeftLowerArm,
    LeftHand,
    RightShoulder,
    RightUpperArm,
    RightLowerArm,
    RightHand,
    LeftUpperLeg,
    LeftLowerLeg,
    LeftFoot,
    LeftToes,
    RightUpperLeg,
    RightLowerLeg,
    RightFoot,
    RightToes,
    LeftThumbProximal,
    LeftThumbIntermediate,
    LeftThumbDistal,
    LeftIndexProximal,
    LeftIndexIntermediate,
    LeftIndexDistal,
    LeftMiddleProximal,
    LeftMiddleIntermediate,
    LeftMiddleDistal,
    LeftRingProximal,
    LeftRingIntermediate,
    LeftRingDistal,
    LeftLittleProximal,
    LeftLittleIntermediate,
    LeftLittleDistal,
    RightThumbProximal,
    RightThumbIntermediate,
    RightThumbDistal,
    RightIndexProximal,
    RightIndexIntermediate,
    RightIndexDistal,
    RightMiddleProximal,
    RightMiddleIntermediate,
    RightMiddleDistal,
    RightRingProximal,
    RightRingIntermediate,
    RightRingDistal,
    RightLittleProximal,
    RightLittleIntermediate,
    RightLittleDistal,
}

impl HumanBone {
    pub const ALL: [HumanBone; 51] = [
        HumanBone::Hips,
        HumanBone::Spine,
        HumanBone::Chest,
        HumanBone::Neck,
        HumanBone::Head,
        HumanBone::LeftShoulder,
        HumanBone::LeftUpperArm,
        HumanBone::LeftLowerArm,
        HumanBone::LeftHand,
        HumanBone::RightShoulder,
        HumanBone::RightUpperArm,
        HumanBone::RightLowerArm,
        HumanBone::RightHand,
        HumanBone::LeftUpperLeg,
        HumanBone::LeftLowerLeg,
        HumanBone::LeftFoot,
        HumanBone::LeftToes,
        HumanBone::RightUpperLeg,
        HumanBone::RightLowerLeg,
        HumanBone::RightFoot,
        HumanBone::RightToes,
        HumanBone::LeftThumbProximal,
        HumanBone::LeftThumbIntermediate,
        HumanBone::LeftThumbDistal,
        HumanBone::LeftIndexProximal,
        HumanBone::LeftIndexIntermediate,
        HumanBone::LeftIndexDistal,
        HumanBone::LeftMiddleProximal,
        HumanBone::LeftMiddleIntermediate,
        HumanBone::LeftMiddleDistal,
        HumanBone::LeftRingProximal,
        HumanBone::LeftRingIntermediate,
        HumanBone::LeftRingDistal,
        HumanBone::LeftLittleProximal,
        HumanBone::LeftLittleIntermediate,
        HumanBone::LeftLittleDistal,
        HumanBone::RightThumbProximal,
        HumanBone::RightThumbIntermediate,
        HumanBone::RightThumbDistal,
        HumanBone::RightIndexProximal,
        HumanBone::RightIndexIntermediate,
        HumanBone::RightIndexDistal,
        HumanBone::RightMiddleProximal,
        HumanBone::RightMiddleIntermediate,
        HumanBone::RightMiddleDistal,
        HumanBone::RightRingProximal,
        HumanBone::RightRingIntermediate,
        HumanBone::RightRingDistal,
        HumanBone::RightLittleProximal,
        HumanBone::RightLittleIntermediate,
        HumanBone::RightLittleDistal,
    ];

    /// How many of [`HumanBone::ALL`] are the body's (the fingers' follow).
    pub const BODY_COUNT: usize = 21;

    /// A finger's phalanx: `left`'s hand, `finger` 0 (thumb) to 4 (little), `phalanx` 0
    /// (proximal) to 2 (distal).
    pub fn finger(left: bool, finger: usize, phalanx: usize) -> HumanBone {
        HumanBone::ALL[Self::BODY_COUNT + usize::from(!left) * 15 + finger * 3 + phalanx]
    }

    /// Whether the bone is a finger's.
    pub fn is_finger(self) -> bool {
        HumanBone::ALL.iter().position(|&b| b == self).is_some_and(|k| k >= Self::BODY_COUNT)
    }
}

/// Each standard bone's joint (bones a rig lacks are absent).
pub type HumanoidMap = BTreeMap<HumanBone, usize>;

/// How a bone of the map was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Found {
    /// By the joint's name (see [`names`]).
    Name,
    /// By the skeleton's shape.
    Structure,
    /// Named by the file itself (a VRM avatar's humanoid bones).
    File,
}

/// A humanoid map with how each bone was found and what is doubtful about it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Detected {
    pub map: HumanoidMap,
    pub found: BTreeMap<HumanBone, Found>,
    pub doubts: Vec<String>,
}

/// The humanoid map of `skeleton` in its initial pose; none when it has no two legs and two
/// arms to find.
pub fn detect(skeleton: &Skeleton) -> Option<HumanoidMap> {
    detect_reported(skeleton).map(|d| d.map)
}

/// The humanoid map of `skeleton`, with how each bone was found. Names first: the hands
/// and feet named for a side, and along each limb the bones its names say; what names do
/// not give, the skeleton's shape gives (see the module's doc). Joints named as controls,
/// IK goals, twist or roll joints, ends, capes, hair, tails or weapons are never mapped,
/// nor are zero-length leaves whose names say nothing.
pub fn detect_reported(skeleton: &Skeleton) -> Option<Detected> {
    let mut world = vec![Mat4::IDENTITY; skeleton.len()];
    super::fk::forward_kinematics(skeleton, &skeleton.initial_pose(), Mat4::IDENTITY, &mut world);
    let at: Vec<Vec3> = world.iter().map(|m| m.w_axis.truncate()).collect();
    let (lo, hi) = at.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| (l.min(*p), h.max(*p)));
    let size = (hi - lo).max_element().max(1e-6);
    let joint_names: Vec<&str> = skeleton.joints().iter().map(|j| j.name.as_str()).collect();
    let says: Vec<NameSays> = names::without_common_prefix(&joint_names).iter().map(|n| names::read(n)).collect();
    let body: Vec<bool> = (0..skeleton.len()).map(|j| !says[j].excluded).collect();
    // A zero-length leaf whose name says nothing marks where a chain ends (no hand or foot
    // of its own), or is a bone drawn as a point (a 6.837 model's head).
    let stubs: Vec<bool> = (0..skeleton.len())
        .map(|j| {
            skeleton.children(j).is_empty()
                && says[j].role.is_none()
                && skeleton.parent(j).is_some_and(|p| at[p].distance(at[j]) < 1e-4 * size)
        })
        .collect();
    let tree = Tree::new(skeleton, &at, &body, &stubs);
    let mut out = Detected::default();

    let ends = named_ends(&tree, &says).or_else(|| structural_ends(&tree, size, &mut out.doubts))?;
    let Ends { hands: [left_hand, right_hand], feet: [left_foot, right_foot], by_name } = ends;
    let how = if by_name { Found::Name } else { Found::Structure };
    // Where limbs meet on mechanism joints (Rigify's `ORG-`), their deforming twins (`DEF-`).
    let chest = tree.twin(tree.meeting(left_hand, right_hand));
    let mut hips = tree.twin(tree.meeting(left_foot, right_foot));
    // Legs hung from a pelvis beside the spine (Daz): the hips are where legs and spine meet.
    let joint = tree.meeting(hips, chest);
    if joint != chest {
        hips = joint;
    }
    use HumanBone::*;
    out.put(Hips, hips, how);
    out.put(Chest, chest, how);
    let spine = tree.path(hips, chest);
    let named_spine = spine.iter().copied().find(|&j| j != chest && says[j].role == Some(Role::Spine));
    match (named_spine, spine.first().filter(|&&j| j != chest)) {
        (Some(j), _) => out.put(Spine, j, Found::Name),
        (None, Some(&j)) => out.put(Spine, j, Found::Structure),
        _ => {}
    }
    head_and_neck(&tree, &says, chest, [[left_hand, right_hand], [left_foot, right_foot]], &mut out);
    for (end, side, [shoulder, upper, lower, hand]) in [
        (left_hand, Side::Left, [LeftShoulder, LeftUpperArm, LeftLowerArm, LeftHand]),
        (right_hand, Side::Right, [RightShoulder, RightUpperArm, RightLowerArm, RightHand]),
    ] {
        let limb = tree.limb(chest, end, true);
        let (before, upper_j, lower_j, found) = match (named_arm(&tree, &says, chest, end, side), &limb) {
            (Some((c, u, l)), _) => (c, u, l, Found::Name),
            (None, Some(limb)) => (limb.before, limb.upper, limb.lower, Found::Structure),
            (None, None) => return None,
        };
        // Found by shape, the hand is the limb's end (the leaf may be a finger's tip); an
        // arm of a clavicle, upper and lower arm has none.
        let hand_j = match (&limb, by_name) {
            (Some(limb), false) => limb.end,
            _ => Some(end),
        };
        if let Some(hand_j) = hand_j {
            out.put(hand, hand_j, how);
        }
        out.put(upper, upper_j, found);
        out.put(lower, lower_j, found);
        if let Some(c) = before {
            out.put(shoulder, c, found);
        }
    }
    for (end, side, [upper, lower, foot, toes]) in [
        (left_foot, Side::Left, [LeftUpperLeg, LeftLowerLeg, LeftFoot, LeftToes]),
        (right_foot, Side::Right, [RightUpperLeg, RightLowerLeg, RightFoot, RightToes]),
    ] {
        let limb = tree.limb(hips, end, false);
        let (u, l, found) = match (named_leg(&tree, &says, hips, end, side), &limb) {
            (Some((u, l)), _) => (u, l, Found::Name),
            (None, Some(limb)) => (limb.upper, limb.lower, Found::Structure),
            (None, None) => return None,
        };
        out.put(upper, u, found);
        out.put(lower, l, found);
        // Found by shape, the foot is the limb's end (the leaf is its toes' tip).
        let foot_j = match (&limb, by_name) {
            (Some(Limb { end: Some(foot), .. }), false) => *foot,
            _ => end,
        };
        out.put(foot, foot_j, how);
        let after = limb.as_ref().and_then(|l| l.after).filter(|&a| a != foot_j && tree.below(a, foot_j));
        match (named_toes(&tree, &says, foot_j), after) {
            (Some(t), _) => out.put(toes, t, Found::Name),
            (None, Some(after)) => out.put(toes, after, Found::Structure),
            (None, None) => {}
        }
    }
    for (left, hand) in [(true, out.map.get(&LeftHand).copied()), (false, out.map.get(&RightHand).copied())] {
        let Some(hand) = hand else { continue };
        fingers(&tree, &says, left, hand, &mut out);
        let named = (0..5).any(|f| out.map.contains_key(&HumanBone::finger(left, f, 0)));
        if !named {
            fingers_by_shape(&tree, left, hand, &mut out);
        }
    }
    Some(out)
}

/// A character's humanoid map: the bones its file names (a VRM avatar's), the rest found
/// from its skeleton where they do not contradict them.
pub fn of_asset(asset: &super::CharacterAsset) -> Option<Detected> {
    let detected = detect_reported(&asset.skeleton);
    if asset.humanoid.is_empty() {
        return detected;
    }
    let mut out = Detected::default();
    for (&bone, &j) in &asset.humanoid {
        out.put(bone, j, Found::File);
    }
    if let Some(Detected { map, found, doubts }) = detected {
        for (bone, j) in map {
            if !out.map.contains_key(&bone) && !out.map.values().any(|&k| k == j) {
                out.put(bone, j, found[&bone]);
            }
        }
        out.doubts = doubts;
    }
    Some(out)
}

impl Detected {
    fn put(&mut self, bone: HumanBone, joint: usize, found: Found) {
        self.map.insert(bone, joint);
        self.found.insert(bone, found);
    }
}

/// The hands and feet, and whether names gave them.
struct Ends {
    hands: [usize; 2],
    feet: [usize; 2],
    by_name: bool,
}

/// The hands and feet as names give them: on each side the shallowest joint named a hand
/// (or wrist) and a foot (or ankle), the four on four separate chains.
fn named_ends(tree: &Tree, says: &[NameSays]) -> Option<Ends> {
    let shallowest = |side: Side, roles: &[Role]| {
        (0..says.len())
            .filter(|&j| tree.body[j] && says[j].side == Some(side) && says[j].role.is_some_and(|r| roles.contains(&r)))
            .min_by_key(|&j| tree.depth(j))
    };
    let hands = [shallowest(Side::Left, &[Role::Hand])?, shallowest(Side::Right, &[Role::Hand])?];
    let feet =
        [shallowest(Side::Left, &[Role::Foot, Role::Ankle])?, shallowest(Side::Right, &[Role::Foot, Role::Ankle])?];
    let all = [hands[0], hands[1], feet[0], feet[1]];
    let separate = all.iter().enumerate().all(|(i, &a)| all[i + 1..].iter().all(|&b| tree.apart(a, b)));
    separate.then_some(Ends { hands, feet, by_name: true })
}

/// The hands and feet from the skeleton's shape: the feet its two lowest ends on either
/// side, the hips where their chains meet; the hands the two ends off the legs farthest
/// out on either side.
fn structural_ends(tree: &Tree, size: f32, doubts: &mut Vec<String>) -> Option<Ends> {
    let (skeleton, at) = (tree.skeleton, tree.at);
    let leaves: Vec<usize> = (0..skeleton.len()).filter(|&j| tree.is_end(j)).collect();
    let by_height = |a: &usize, b: &usize| at[*a].y.total_cmp(&at[*b].y);
    let first_foot = leaves.iter().copied().min_by(by_height)?;
    let second_foot = leaves
        .iter()
        .copied()
        .filter(|&l| tree.apart(first_foot, l) && flat(at[l] - at[first_foot]).length() > 0.05 * size)
        .min_by(by_height)?;
    let hips = tree.meeting(first_foot, second_foot);
    let (first_leg, second_leg) = (tree.path(hips, first_foot), tree.path(hips, second_foot));
    let legs = [first_leg[0], second_leg[0]];
    // Across the body: from one hip joint to the other (the first joints down the legs
    // that part), level, towards +x: whatever the pose, the hips keep their width.
    let parted =
        first_leg.iter().zip(&second_leg).map(|(&a, &b)| flat(at[b] - at[a])).find(|v| v.length() > 1e-3 * size);
    let across = parted.and_then(Vec3::try_normalize).unwrap_or(Vec3::X);
    let across = if across.x < 0.0 || (across.x == 0.0 && across.z < 0.0) { -across } else { across };
    let out_by = |j: usize| (at[j] - at[hips]).dot(across);
    let upper: Vec<usize> = leaves.iter().copied().filter(|&l| !legs.iter().any(|&leg| tree.below(l, leg))).collect();
    let out = |side: f32| {
        upper
            .iter()
            .copied()
            .filter(|&l| out_by(l) * side > 0.05 * size)
            .max_by(|a, b| (out_by(*a) * side).total_cmp(&(out_by(*b) * side)))
    };
    let (plus_hand, minus_hand) = (out(1.0)?, out(-1.0)?);
    let named_left = left_side(skeleton, at, hips, across);
    if named_left.is_none() {
        doubts.push("no joint's name says left or right: the left is taken as the side towards +x".into());
    }
    let left_is_plus = named_left.unwrap_or(true);
    let foot_plus = if across.dot(at[second_foot] - at[first_foot]) < 0.0 { first_foot } else { second_foot };
    let foot_minus = if foot_plus == first_foot { second_foot } else { first_foot };
    let (hands, feet) = if left_is_plus {
        ([plus_hand, minus_hand], [foot_plus, foot_minus])
    } else {
        ([minus_hand, plus_hand], [foot_minus, foot_plus])
    };
    Some(Ends { hands, feet, by_name: false })
}

/// The head (the shallowest joint named so below the chest, off the arms; else the highest
/// end there off the legs too, or the joint on the way to it where a face branches) and the
/// neck (named on the way, else the first joint of it).
fn head_and_neck(tree: &Tree, says: &[NameSays], chest: usize, [hands, feet]: [[usize; 2]; 2], out: &mut Detected) {
    let off_arms = |j: usize| tree.below(j, chest) && j != chest && hands.iter().all(|&h| tree.apart(j, h));
    let named = (0..says.len())
        .filter(|&j| tree.body[j] && off_arms(j) && says[j].role == Some(Role::Head))
        .min_by_key(|&j| tree.depth(j));
    if let Some(head) = named {
        out.put(HumanBone::Head, head, Found::Name);
        let path = tree.path(chest, head);
        let neck = path.iter().copied().find(|&j| j != head && says[j].role == Some(Role::Neck));
        match (neck, path.first().filter(|&&j| j != head)) {
            (Some(n), _) => out.put(HumanBone::Neck, n, Found::Name),
            (None, Some(&n)) => out.put(HumanBone::Neck, n, Found::Structure),
            _ => {}
        }
        return;
    }
    let at = tree.at;
    // The highest end off the arms and legs (a point bone, where there is no other).
    let off_limbs = |j: usize| off_arms(j) && feet.iter().all(|&f| tree.apart(j, f));
    let highest = |pick: &dyn Fn(usize) -> bool| {
        (0..says.len()).filter(|&j| pick(j) && off_limbs(j)).max_by(|a, b| at[*a].y.total_cmp(&at[*b].y))
    };
    let Some(top) = highest(&|j| tree.is_end(j)).or_else(|| highest(&|j| tree.stubs[j] && tree.body[j])) else {
        return;
    };
    let path = tree.path(chest, top);
    // A head carries its face (eyes, jaw, brows): the deepest joint on the way that branches.
    let branching = path[..path.len().saturating_sub(1)]
        .iter()
        .rposition(|&j| tree.skeleton.children(j).iter().filter(|&&c| tree.body[c]).count() >= 2);
    if let Some(k) = branching {
        out.put(HumanBone::Head, path[k], Found::Structure);
        if k > 0 {
            out.put(HumanBone::Neck, path[0], Found::Structure);
        }
        return;
    }
    // Else the top itself, the neck the first joint on the way.
    match path.as_slice() {
        [] => {}
        [only] => out.put(HumanBone::Head, *only, Found::Structure),
        [neck, .., head] => {
            out.put(HumanBone::Neck, *neck, Found::Structure);
            out.put(HumanBone::Head, *head, Found::Structure);
        }
    }
}

/// Whether `j`'s name puts it on `side`, or on no side.
fn on_side(says: &NameSays, side: Side) -> bool {
    says.side.is_none_or(|s| s == side)
}

/// An arm's bones as its names give them, from the chest to the hand `hand`: the clavicle
/// (where there is one), the upper and the lower arm. None unless both arm bones are named.
fn named_arm(
    tree: &Tree,
    says: &[NameSays],
    chest: usize,
    hand: usize,
    side: Side,
) -> Option<(Option<usize>, usize, usize)> {
    let path: Vec<usize> = tree
        .path(chest, hand)
        .into_iter()
        .map(|j| if tree.body[j] { j } else { tree.twin(j) })
        .filter(|&j| j != hand && tree.body[j] && on_side(&says[j], side))
        .collect();
    let role = |j: usize| says[j].role;
    let lower_at = path.iter().position(|&j| role(j) == Some(Role::LowerArm))?;
    let above = &path[..lower_at];
    let clavicle_at = above.iter().position(|&j| role(j) == Some(Role::Clavicle));
    let upper_at = above
        .iter()
        .position(|&j| role(j) == Some(Role::UpperArm))
        .or_else(|| {
            above
                .iter()
                .enumerate()
                .position(|(k, &j)| role(j) == Some(Role::Shoulder) && clavicle_at.is_some_and(|c| c < k))
        })
        .or_else(|| above.iter().rposition(|&j| role(j) == Some(Role::Shoulder)))?;
    let clavicle =
        above[..upper_at].iter().copied().find(|&j| matches!(role(j), Some(Role::Clavicle | Role::Shoulder)));
    Some((clavicle, above[upper_at], path[lower_at]))
}

/// A leg's upper and lower bones as its names give them, from the hips to the foot.
fn named_leg(tree: &Tree, says: &[NameSays], hips: usize, foot: usize, side: Side) -> Option<(usize, usize)> {
    let path: Vec<usize> =
        tree.path(hips, foot).into_iter().filter(|&j| j != foot && tree.body[j] && on_side(&says[j], side)).collect();
    let role = |j: usize| says[j].role;
    let lower_at = path.iter().position(|&j| role(j) == Some(Role::LowerLeg))?;
    let above = &path[..lower_at];
    let upper_at = above
        .iter()
        .position(|&j| role(j) == Some(Role::UpperLeg))
        // The sided hip nearest the knee (one above it runs to the hip socket).
        .or_else(|| above.iter().rposition(|&j| role(j) == Some(Role::SidedHip)))?;
    Some((above[upper_at], path[lower_at]))
}

/// The toes below the foot `foot` as their names give them: the shallowest joint named
/// toes (or a foot below an ankle).
fn named_toes(tree: &Tree, says: &[NameSays], foot: usize) -> Option<usize> {
    let toes_roles: &[Role] =
        if says[foot].role == Some(Role::Ankle) { &[Role::Toes, Role::Foot] } else { &[Role::Toes] };
    (0..says.len())
        .filter(|&j| j != foot && tree.body[j] && tree.below(j, foot))
        .filter(|&j| says[j].role.is_some_and(|r| toes_roles.contains(&r)))
        .min_by_key(|&j| tree.depth(j))
}

/// Each finger of the hand `hand` as names give it: the first three joints named for the
/// finger down one chain (coinciding joints counted once).
fn fingers(tree: &Tree, says: &[NameSays], left: bool, hand: usize, out: &mut Detected) {
    let side = if left { Side::Left } else { Side::Right };
    for finger in 0..5 {
        let mut joints: Vec<usize> = (0..says.len())
            .filter(|&j| j != hand && tree.body[j] && tree.below(j, hand) && on_side(&says[j], side))
            .filter(|&j| says[j].role == Some(Role::Finger(finger)))
            .collect();
        joints.sort_by_key(|&j| tree.depth(j));
        let mut chain: Vec<usize> = Vec::new();
        for j in joints {
            let follows = chain.last().is_none_or(|&last| tree.skeleton.is_below(j, last));
            let apart = chain.last().is_none_or(|&last| tree.at[last].distance(tree.at[j]) > 0.0);
            if follows && apart && chain.len() < 3 {
                chain.push(j);
            }
        }
        for (phalanx, &j) in chain.iter().enumerate() {
            out.put(HumanBone::finger(left, finger, phalanx), j, Found::Name);
        }
    }
}

/// The fingers of a hand whose names say none, from its shape: the hand's chains (from
/// the first body joints below it, a palm of mechanism joints (`ORG-`, `MCH-`) passed through; each down
/// its first body joint at each step, coinciding joints counted once), two to five of
/// them, each of two joints or more. The thumb is the chain that leaves the hand's
/// direction the most; the others follow from the thumb's side outwards (index, middle,
/// ring, little). A chain of four or five joints whose last is its tip starts with a
/// metacarpal (left out) or ends with the tip (left out); the phalanges are the three
/// before the tip.
fn fingers_by_shape(tree: &Tree, left: bool, hand: usize, out: &mut Detected) {
    let solid = |j: usize| tree.body[j] && !tree.stubs[j];
    let mut starts = Vec::new();
    let mut open: Vec<usize> = tree.skeleton.children(hand).to_vec();
    while let Some(j) = open.pop() {
        let name = &tree.skeleton.joint(j).name;
        if solid(j) {
            starts.push(j);
        } else if name.starts_with("ORG-") || name.starts_with("MCH-") {
            // A mechanism joint the deforming fingers hang from (Rigify's palm).
            open.extend_from_slice(tree.skeleton.children(j));
        }
    }
    starts.sort_unstable();
    let chains: Vec<Vec<usize>> = starts
        .into_iter()
        .map(|start| {
            let mut chain = vec![start];
            let mut at = start;
            while let Some(&next) = tree.skeleton.children(at).iter().find(|&&c| solid(c)) {
                if tree.at[next].distance(tree.at[at]) > 0.0 {
                    chain.push(next);
                } else if let Some(last) = chain.last_mut() {
                    *last = next;
                }
                at = next;
            }
            chain
        })
        .filter(|c| c.len() >= 2)
        .collect();
    if !(2..=5).contains(&chains.len()) {
        return;
    }
    let base = tree.at[hand];
    let direction = |c: &[usize]| (tree.at[c[c.len() - 1]] - tree.at[c[0]]).normalize_or_zero();
    let along = chains.iter().map(|c| direction(c)).sum::<Vec3>().normalize_or_zero();
    if along == Vec3::ZERO {
        return;
    }
    let thumb = (0..chains.len())
        .min_by(|&a, &b| direction(&chains[a]).dot(along).total_cmp(&direction(&chains[b]).dot(along)))
        .unwrap_or(0);
    // Across the hand: from the thumb's root, square to the hand's direction.
    let off = |c: &[usize]| {
        let v = tree.at[c[0]] - base;
        v - along * v.dot(along)
    };
    let thumb_side = off(&chains[thumb]).normalize_or_zero();
    let mut others: Vec<usize> = (0..chains.len()).filter(|&k| k != thumb).collect();
    others.sort_by(|&a, &b| off(&chains[b]).dot(thumb_side).total_cmp(&off(&chains[a]).dot(thumb_side)));
    let fingers = std::iter::once((0, thumb)).chain(others.into_iter().enumerate().map(|(k, c)| (k + 1, c)));
    for (finger, k) in fingers {
        let chain = &chains[k];
        let ends_in_tip = tree.is_end(chain[chain.len() - 1]);
        let phalanges: &[usize] = match chain.len() {
            5 if ends_in_tip => &chain[1..4],
            4 if ends_in_tip => &chain[..3],
            n => &chain[n.saturating_sub(3)..],
        };
        for (phalanx, &j) in phalanges.iter().enumerate() {
            out.put(HumanBone::finger(left, finger, phalanx), j, Found::Structure);
        }
    }
    out.doubts.push(format!(
        "the {} hand's fingers are found by their shape (the thumb the chain most apart)",
        if left { "left" } else { "right" }
    ));
}

/// A vector made level (its height dropped).
fn flat(v: Vec3) -> Vec3 {
    Vec3::new(v.x, 0.0, v.z)
}

/// Whether the names put the character's left on the side `across` points to: the side of
/// the hips that joints named left lie on (none when no joint is named for a side).
fn left_side(skeleton: &Skeleton, at: &[Vec3], hips: usize, across: Vec3) -> Option<bool> {
    let mut votes = 0i32;
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let side = match name_side(&joint.name) {
            Some(true) => 1,
            Some(false) => -1,
            None => continue,
        };
        let dx = (at[j] - at[hips]).dot(across);
        if dx.abs() > 1e-4 {
            votes += side * if dx > 0.0 { 1 } else { -1 };
        }
    }
    (votes != 0).then_some(votes > 0)
}

/// Whether a joint's name says left (`Some(true)`) or right: `L_Hip`, `LeftUpLeg`,
/// `mixamorig:LeftArm`, `thigh.L`, `l_knee`, `upperarm_l`, `leg_joint_L_1`.
fn name_side(name: &str) -> Option<bool> {
    let base = name.rsplit(':').next().unwrap_or(name);
    let lower = base.to_ascii_lowercase();
    if lower.starts_with("left") || lower.contains("_left") {
        return Some(true);
    }
    if lower.starts_with("right") || lower.contains("_right") {
        return Some(false);
    }
    let marked = |c: char| {
        lower.contains(&format!("_{c}_"))
            || lower.starts_with(&format!("{c}_"))
            || lower.ends_with(&format!("_{c}"))
            || lower.ends_with(&format!(".{c}"))
            || lower.starts_with(&format!("{c}."))
    };
    match (marked('l'), marked('r')) {
        (true, false) => Some(true),
        (false, true) => Some(false),
        _ => None,
    }
}

/// A limb from where it leaves the body to its last joint: the upper and lower bones (the
/// two longest consecutive segments), the joint before the upper one (a shoulder), the
/// limb's end (a hand, a foot; none where the lower bone is the last joint) and the one
/// after it (toes).
struct Limb {
    before: Option<usize>,
    upper: usize,
    lower: usize,
    end: Option<usize>,
    after: Option<usize>,
}

struct Tree<'a> {
    skeleton: &'a Skeleton,
    at: &'a [Vec3],
    /// Whether each joint may be a bone of the body (see [`detect_reported`]).
    body: &'a [bool],
    /// Whether each joint is a body joint with none below it (stubs apart).
    ends: Vec<bool>,
    /// Whether each joint is a zero-length leaf whose name says nothing.
    stubs: Vec<bool>,
    /// For a mechanism joint (`ORG-x`), its deforming twin (`DEF-x`).
    twins: Vec<Option<usize>>,
}

impl<'a> Tree<'a> {
    fn new(skeleton: &'a Skeleton, at: &'a [Vec3], body: &'a [bool], stubs: &[bool]) -> Self {
        let solid = |j: usize| body[j] && !stubs[j];
        let mut below = vec![false; skeleton.len()];
        for j in (0..skeleton.len()).rev() {
            below[j] = skeleton.children(j).iter().any(|&c| solid(c) || below[c]);
        }
        let ends = (0..skeleton.len()).map(|j| solid(j) && !below[j]).collect();
        let stubs = stubs.to_vec();
        let twins = skeleton
            .joints()
            .iter()
            .map(|joint| {
                let rest = joint.name.strip_prefix("ORG-")?;
                skeleton.find(&format!("DEF-{rest}"))
            })
            .collect();
        Self { skeleton, at, body, ends, stubs, twins }
    }

    /// `j`, or its deforming twin where it is a mechanism joint that has one.
    fn twin(&self, j: usize) -> usize {
        self.twins[j].unwrap_or(j)
    }

    fn is_end(&self, j: usize) -> bool {
        self.ends[j]
    }

    /// How many joints lie above `j`.
    fn depth(&self, j: usize) -> usize {
        self.ancestors(j).len()
    }

    /// The joints from `j` up to the root, `j` first.
    fn ancestors(&self, mut j: usize) -> Vec<usize> {
        let mut out = vec![j];
        while let Some(p) = self.skeleton.parent(j) {
            out.push(p);
            j = p;
        }
        out
    }

    /// The deepest joint both chains pass through.
    fn meeting(&self, a: usize, b: usize) -> usize {
        let up = self.ancestors(b);
        self.ancestors(a).into_iter().find(|j| up.contains(j)).unwrap_or(0)
    }

    /// Whether `j` is `ancestor` or below it.
    fn below(&self, j: usize, ancestor: usize) -> bool {
        j == ancestor || self.skeleton.is_below(j, ancestor)
    }

    /// Whether neither lies on the other's chain.
    fn apart(&self, a: usize, b: usize) -> bool {
        let m = self.meeting(a, b);
        m != a && m != b
    }

    /// The joints from just below `from` down to `to`.
    fn path(&self, from: usize, to: usize) -> Vec<usize> {
        let mut up = self.ancestors(to);
        if let Some(k) = up.iter().position(|&j| j == from) {
            up.truncate(k);
        }
        up.reverse();
        up
    }

    /// The limb from `from` (the body joint it leaves) to the leaf `leaf`; an arm (`arm`)
    /// may end in its lower bone.
    fn limb(&self, from: usize, leaf: usize, arm: bool) -> Option<Limb> {
        // The chain's distinct places: where several joints coincide, the last of them.
        let mut chain: Vec<usize> = vec![from];
        for j in self.path(from, leaf).into_iter().filter(|&j| self.body[j] || j == leaf) {
            if self.at[j].distance(self.at[*chain.last()?]) < 1e-6 {
                chain.pop();
            }
            chain.push(j);
        }
        if chain.len() < 3 {
            return None;
        }
        // An arm of two bones from the body's own place (6.837's: a joint on the chest runs
        // to the shoulder, the next to the elbow, the last is the elbow): the first leaves
        // the body's middle, so it is a clavicle, and the lower arm ends in no joint.
        if arm && chain.len() == 3 {
            return Some(Limb {
                before: (chain[0] != from).then_some(chain[0]),
                upper: chain[1],
                lower: chain[2],
                end: None,
                after: None,
            });
        }
        let length = |k: usize| self.at[chain[k + 1]].distance(self.at[chain[k]]);
        // The body joint itself is no limb bone, where the limb has joints enough.
        let first = usize::from(chain.len() >= 4);
        let k = (first..chain.len() - 2)
            .max_by(|&a, &b| (length(a) + length(a + 1)).total_cmp(&(length(b) + length(b + 1))))?;
        Some(Limb {
            before: (k >= 1 && chain[k - 1] != from).then(|| chain[k - 1]),
            upper: chain[k],
            lower: chain[k + 1],
            end: Some(chain[k + 2]),
            after: chain.get(k + 3).copied(),
        })
    }
}

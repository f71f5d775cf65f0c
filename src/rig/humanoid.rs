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

/// The standard bones of a humanoid.
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
}

impl HumanBone {
    pub const ALL: [HumanBone; 21] = [
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
    ];
}

/// Each standard bone's joint (bones a rig lacks are absent).
pub type HumanoidMap = BTreeMap<HumanBone, usize>;

/// The humanoid map of `skeleton` in its initial pose; none when it has no two legs and two
/// arms to find.
pub fn detect(skeleton: &Skeleton) -> Option<HumanoidMap> {
    let mut world = vec![Mat4::IDENTITY; skeleton.len()];
    super::fk::forward_kinematics(skeleton, &skeleton.initial_pose(), Mat4::IDENTITY, &mut world);
    let at: Vec<Vec3> = world.iter().map(|m| m.w_axis.truncate()).collect();
    let tree = Tree { skeleton, at: &at };
    let leaves: Vec<usize> = (0..skeleton.len()).filter(|&j| skeleton.children(j).is_empty()).collect();
    let (lo, hi) = at.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| (l.min(*p), h.max(*p)));
    let size = (hi - lo).max_element().max(1e-6);

    // The feet: the lowest leaf, and the lowest leaf whose chain parts from its on the other side.
    let by_height = |a: &usize, b: &usize| at[*a].y.total_cmp(&at[*b].y);
    let first_foot = leaves.iter().copied().min_by(by_height)?;
    let second_foot = leaves
        .iter()
        .copied()
        .filter(|&l| tree.apart(first_foot, l) && flat(at[l] - at[first_foot]).length() > 0.05 * size)
        .min_by(by_height)?;
    let hips = tree.meeting(first_foot, second_foot);

    // The hands: off the legs, the leaves farthest out on either side. (A rig may hang its
    // hips from the chest, and its arms below the hips: neither is assumed.)
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
    let chest = tree.meeting(plus_hand, minus_hand);
    let head = upper
        .iter()
        .copied()
        .filter(|&l| tree.below(l, chest) && tree.apart(l, plus_hand) && tree.apart(l, minus_hand))
        .max_by(by_height);

    let left_is_plus = left_side(skeleton, &at, hips, across).unwrap_or(true);
    let (left_hand, right_hand) = if left_is_plus { (plus_hand, minus_hand) } else { (minus_hand, plus_hand) };
    let foot_plus = if across.dot(at[second_foot] - at[first_foot]) < 0.0 { first_foot } else { second_foot };
    let foot_minus = if foot_plus == first_foot { second_foot } else { first_foot };
    let (left_foot, right_foot) = if left_is_plus { (foot_plus, foot_minus) } else { (foot_minus, foot_plus) };

    let mut map = HumanoidMap::new();
    map.insert(HumanBone::Hips, hips);
    let spine = tree.path(hips, chest);
    if let Some(&first) = spine.first().filter(|&&j| j != chest) {
        map.insert(HumanBone::Spine, first);
    }
    map.insert(HumanBone::Chest, chest);
    if let Some(head) = head {
        let neck = tree.path(chest, head);
        match neck.as_slice() {
            [] => {}
            [only] => {
                map.insert(HumanBone::Head, *only);
            }
            [neck, head, ..] => {
                map.insert(HumanBone::Neck, *neck);
                map.insert(HumanBone::Head, *head);
            }
        }
    }
    use HumanBone::*;
    for (end, from, [shoulder, upper, lower, hand]) in [
        (left_hand, chest, [LeftShoulder, LeftUpperArm, LeftLowerArm, LeftHand]),
        (right_hand, chest, [RightShoulder, RightUpperArm, RightLowerArm, RightHand]),
    ] {
        let limb = tree.limb(from, end)?;
        if let Some(before) = limb.before {
            map.insert(shoulder, before);
        }
        map.extend([(upper, limb.upper), (lower, limb.lower), (hand, limb.end)]);
    }
    for (end, [upper, lower, foot, toes]) in [
        (left_foot, [LeftUpperLeg, LeftLowerLeg, LeftFoot, LeftToes]),
        (right_foot, [RightUpperLeg, RightLowerLeg, RightFoot, RightToes]),
    ] {
        let limb = tree.limb(hips, end)?;
        map.extend([(upper, limb.upper), (lower, limb.lower), (foot, limb.end)]);
        if let Some(after) = limb.after {
            map.insert(toes, after);
        }
    }
    Some(map)
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
/// two longest consecutive segments), the joint before the upper one (a shoulder) and the
/// one after the end (toes).
struct Limb {
    before: Option<usize>,
    upper: usize,
    lower: usize,
    end: usize,
    after: Option<usize>,
}

struct Tree<'a> {
    skeleton: &'a Skeleton,
    at: &'a [Vec3],
}

impl Tree<'_> {
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

    /// The limb from `from` (the body joint it leaves) to the leaf `leaf`.
    fn limb(&self, from: usize, leaf: usize) -> Option<Limb> {
        // The chain's distinct places: where several joints coincide, the last of them.
        let mut chain: Vec<usize> = vec![from];
        for j in self.path(from, leaf) {
            if self.at[j].distance(self.at[*chain.last()?]) < 1e-6 {
                chain.pop();
            }
            chain.push(j);
        }
        if chain.len() < 3 {
            return None;
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
            end: chain[k + 2],
            after: chain.get(k + 3).copied(),
        })
    }
}

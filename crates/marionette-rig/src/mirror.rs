//! Mirroring poses left to right: joint names paired by the usual conventions, rotations
//! reflected across the character's symmetry plane x = 0 (model space; the course rigs,
//! SMPL and the puppet put their left side at +x).
//!
//! Reflecting by `M = diag(−1, 1, 1)`, a joint's rotation `R` becomes `M R M`: a rotation
//! about x keeps its angle, those about y and z change sign, so Euler angles (x, y, z)
//! become (x, −y, −z) in any order and a quaternion (x, y, z, w) becomes (x, −y, −z, w).

use super::pose::JointRotation;

/// Prefixes, suffixes and words that name a side, each with its counterpart.
const PREFIXES: [(&str, &str); 2] = [("l_", "r_"), ("L_", "R_")];
const SUFFIXES: [(&str, &str); 4] = [(".L", ".R"), (".l", ".r"), ("_l", "_r"), ("_L", "_R")];
const WORDS: [(&str, &str); 3] = [("left", "right"), ("Left", "Right"), ("LEFT", "RIGHT")];
/// Side marks inside a name (`upper_arm.L.001`, `arm_l_twist`).
const INFIXES: [(&str, &str); 4] = [(".L.", ".R."), (".l.", ".r."), ("_L_", "_R_"), ("_l_", "_r_")];

/// The name of the joint on the other side (`l_elbow` ↔ `r_elbow`, `hand.L` ↔ `hand.R`,
/// `hip_01_l` ↔ `hip_01_r`, `LeftArm` ↔ `RightArm`, `upper_arm.L.001` ↔ `upper_arm.R.001`,
/// Daz's `lShldrBend` ↔ `rShldrBend`), or none for a joint on the middle.
pub fn mirrored_name(name: &str) -> Option<String> {
    for (a, b) in INFIXES {
        for (from, to) in [(a, b), (b, a)] {
            if name.contains(from) {
                return Some(name.replacen(from, to, 1));
            }
        }
    }
    let mut chars = name.chars();
    if let (Some(side @ ('l' | 'r')), Some(next)) = (chars.next(), chars.next())
        && next.is_ascii_uppercase()
    {
        return Some(format!("{}{}", if side == 'l' { 'r' } else { 'l' }, &name[1..]));
    }
    for (a, b) in PREFIXES {
        for (from, to) in [(a, b), (b, a)] {
            if let Some(rest) = name.strip_prefix(from) {
                return Some(format!("{to}{rest}"));
            }
        }
    }
    for (a, b) in SUFFIXES {
        for (from, to) in [(a, b), (b, a)] {
            if let Some(rest) = name.strip_suffix(from) {
                return Some(format!("{rest}{to}"));
            }
        }
    }
    for (a, b) in WORDS {
        for (from, to) in [(a, b), (b, a)] {
            if name.contains(from) {
                return Some(name.replacen(from, to, 1));
            }
        }
    }
    None
}

/// The rotation reflected across the plane x = 0.
pub fn mirrored_rotation(rotation: &JointRotation) -> JointRotation {
    match *rotation {
        JointRotation::Euler(a, order) => JointRotation::Euler(glam::Vec3::new(a.x, -a.y, -a.z), order),
        JointRotation::Quat(q) => JointRotation::Quat(glam::Quat::from_xyzw(q.x, -q.y, -q.z, q.w)),
    }
}

/// A pose by joint name, mirrored: each rotation reflected and moved to the joint on the
/// other side (joints on the middle keep their names).
pub fn mirrored_pose(pose: &[(String, JointRotation)]) -> Vec<(String, JointRotation)> {
    pose.iter().map(|(name, r)| (mirrored_name(name).unwrap_or_else(|| name.clone()), mirrored_rotation(r))).collect()
}

/// Each joint's counterpart on the other side of the body: the humanoid map's twin bones,
/// else the joint named for the other side, else itself.
pub fn counterparts(skeleton: &crate::Skeleton, map: &crate::humanoid::HumanoidMap) -> Vec<usize> {
    let mut twin: Vec<usize> = (0..skeleton.len())
        .map(|j| mirrored_name(&skeleton.joint(j).name).and_then(|n| skeleton.find(&n)).unwrap_or(j))
        .collect();
    for (&bone, &j) in map {
        if let Some(&k) = map.get(&crate::body_poses::other_side(bone)) {
            twin[j] = k;
        }
    }
    twin
}

/// A rotation reflected across the plane whose normal is `normal` (unit): about the
/// reflected axis, by the opposite angle.
pub fn reflected(q: glam::Quat, normal: glam::Vec3) -> glam::Quat {
    let v = q.xyz();
    let v = 2.0 * v.dot(normal) * normal - v;
    glam::Quat::from_xyzw(v.x, v.y, v.z, q.w)
}

/// The model-space turn of every joint from rest (`W · W₀⁻¹`).
fn turns_from_rest(skeleton: &crate::Skeleton, pose: &[JointRotation]) -> (Vec<glam::Quat>, Vec<glam::Quat>) {
    use glam::Mat4;
    let world_rotations = |pose: &[JointRotation]| {
        let mut world = vec![Mat4::IDENTITY; skeleton.len()];
        crate::fk::forward_kinematics(skeleton, pose, Mat4::IDENTITY, &mut world);
        world.iter().map(|&m| crate::ik::rotation_of(m)).collect::<Vec<_>>()
    };
    let (now, rest) = (world_rotations(pose), world_rotations(&skeleton.initial_pose()));
    (now.iter().zip(&rest).map(|(w, r)| (*w * r.inverse()).normalize()).collect(), rest)
}

/// The pose flipped left to right through `twin` (see [`counterparts`]): each joint turned
/// from rest as its twin is, reflected across the body's middle plane (normal `left`, the
/// character's left in its model space). For a rig symmetric at rest, flipping twice gives
/// the pose back; each rotation keeps its joint's type and limits.
pub fn flipped_pose(
    skeleton: &crate::Skeleton,
    twin: &[usize],
    pose: &[JointRotation],
    left: glam::Vec3,
) -> Vec<JointRotation> {
    let (turns, rest) = turns_from_rest(skeleton, pose);
    let wanted: Vec<glam::Quat> = (0..skeleton.len()).map(|k| reflected(turns[twin[k]], left) * rest[k]).collect();
    (0..skeleton.len())
        .map(|k| {
            let parent = skeleton.parent(k).map_or(glam::Quat::IDENTITY, |p| wanted[p]);
            pose[k].with_rotation_of((parent.inverse() * wanted[k]).normalize()).clamped(&skeleton.joint(k).limits)
        })
        .collect()
}

/// What joint `j`'s twin turns to when `j` is posed with symmetry on: the twin turned from
/// rest as `j` is, reflected (see [`flipped_pose`]), under its parent as it stands. None
/// for a joint on the middle.
pub fn mirrored_joint(
    skeleton: &crate::Skeleton,
    twin: &[usize],
    pose: &[JointRotation],
    j: usize,
    left: glam::Vec3,
) -> Option<(usize, JointRotation)> {
    let k = twin[j];
    if k == j {
        return None;
    }
    let (turns, rest) = turns_from_rest(skeleton, pose);
    let parent_turn = skeleton.parent(k).map_or(glam::Quat::IDENTITY, |p| turns[p] * rest[p]);
    let wanted = reflected(turns[j], left) * rest[k];
    Some((k, pose[k].with_rotation_of((parent_turn.inverse() * wanted).normalize()).clamped(&skeleton.joint(k).limits)))
}

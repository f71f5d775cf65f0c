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

/// The name of the joint on the other side (`l_elbow` ↔ `r_elbow`, `hand.L` ↔ `hand.R`,
/// `hip_01_l` ↔ `hip_01_r`, `LeftArm` ↔ `RightArm`), or none for a joint on the middle.
pub fn mirrored_name(name: &str) -> Option<String> {
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

//! Bones: the segments from joints to their children, and the distance to one.

use glam::Vec3;

use super::skeleton::Skeleton;

/// A bone: the segment from a joint to one of its children, moved by that joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bone {
    /// The joint whose frame carries the bone (the segment's start).
    pub joint: usize,
    pub start: Vec3,
    pub end: Vec3,
}

/// Every bone of a skeleton given world (or model) joint positions; zero-length bones
/// are skipped. A leaf adds nothing (it has no child to reach).
pub fn bones(skeleton: &Skeleton, joint_positions: &[Vec3]) -> Vec<Bone> {
    (1..skeleton.len())
        .filter_map(|c| {
            let p = skeleton.parent(c)?;
            let (start, end) = (joint_positions[p], joint_positions[c]);
            (start.distance_squared(end) > 1e-12).then_some(Bone { joint: p, start, end })
        })
        .collect()
}

/// Distance from `p` to the segment `a`–`b` (clamped at its ends).
pub fn segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-20)).clamp(0.0, 1.0);
    p.distance(a + t * ab)
}

//! Clips of joint transforms (glTF animations): per joint, keyed translation, rotation and
//! scale, each with its own key times and interpolation (step, linear, cubic Hermite
//! spline), sampled at any time in seconds.

use glam::{Mat4, Quat, Vec3};

use super::pose::JointRotation;
use super::skeleton::Skeleton;

/// How values between two keys are found (glTF's `sampler.interpolation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// The earlier key's value until the next key.
    Step,
    /// Straight-line (vectors) or spherical-linear (rotations) between the keys.
    Linear,
    /// A cubic Hermite spline through the keys with each key's in- and out-tangents.
    CubicSpline,
}

/// A value that keys can hold.
pub trait Keyed: Copy {
    fn lerp_to(self, other: Self, u: f32) -> Self;
    fn scaled(self, s: f32) -> Self;
    fn plus(self, other: Self) -> Self;
    /// Brings a value back to what it stands for (a unit quaternion).
    fn tidy(self) -> Self;
}

/// Values that blend linearly (vectors, morph weights).
macro_rules! linear_keyed {
    ($($t:ty),*) => {$(
        impl Keyed for $t {
            fn lerp_to(self, other: Self, u: f32) -> Self {
                self + (other - self) * u
            }
            fn scaled(self, s: f32) -> Self {
                self * s
            }
            fn plus(self, other: Self) -> Self {
                self + other
            }
            fn tidy(self) -> Self {
                self
            }
        }
    )*};
}

linear_keyed!(f32, Vec3);

impl Keyed for Quat {
    fn lerp_to(self, other: Self, u: f32) -> Self {
        self.slerp(other, u)
    }
    fn scaled(self, s: f32) -> Self {
        self * s
    }
    fn plus(self, other: Self) -> Self {
        self + other
    }
    fn tidy(self) -> Self {
        self.normalize()
    }
}

/// One keyed property: key times (seconds, increasing) and values; a cubic spline holds
/// three values per key (in-tangent, value, out-tangent), as glTF stores them.
#[derive(Debug, Clone, PartialEq)]
pub struct Track<T> {
    pub times: Vec<f32>,
    pub values: Vec<T>,
    pub interpolation: Interpolation,
}

impl<T: Keyed> Track<T> {
    /// The value of key `k`.
    fn key(&self, k: usize) -> T {
        match self.interpolation {
            Interpolation::CubicSpline => self.values[3 * k + 1],
            _ => self.values[k],
        }
    }

    /// The value at time `t` (seconds); before the first key the first value, after the
    /// last the last (glTF's clamping).
    pub fn sample(&self, t: f32) -> T {
        let n = self.times.len();
        // Not after the first key (or not a number): the first value.
        if n == 1 || t.partial_cmp(&self.times[0]).is_none_or(|o| o.is_le()) {
            return self.key(0);
        }
        if t >= self.times[n - 1] {
            return self.key(n - 1);
        }
        // The last key at or before t.
        let k = self.times.partition_point(|&k| k <= t) - 1;
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        let dt = t1 - t0;
        let u = if dt > 0.0 { (t - t0) / dt } else { 0.0 };
        match self.interpolation {
            Interpolation::Step => self.key(k),
            Interpolation::Linear => self.key(k).lerp_to(self.key(k + 1), u),
            Interpolation::CubicSpline => {
                // glTF 2.0 Appendix C: p(u) = h00 v_k + h10 dt b_k + h01 v_k+1 + h11 dt a_k+1.
                let (u2, u3) = (u * u, u * u * u);
                let out_tangent = self.values[3 * k + 2];
                let in_tangent = self.values[3 * (k + 1)];
                self.key(k)
                    .scaled(2.0 * u3 - 3.0 * u2 + 1.0)
                    .plus(out_tangent.scaled(dt * (u3 - 2.0 * u2 + u)))
                    .plus(self.key(k + 1).scaled(-2.0 * u3 + 3.0 * u2))
                    .plus(in_tangent.scaled(dt * (u3 - u2)))
                    .tidy()
            }
        }
    }

    /// Whether the track has keys and as many values as its interpolation needs.
    pub fn is_complete(&self) -> bool {
        let per_key = if self.interpolation == Interpolation::CubicSpline { 3 } else { 1 };
        !self.times.is_empty() && self.values.len() == per_key * self.times.len()
    }

    fn end(&self) -> f32 {
        self.times.last().copied().unwrap_or(0.0)
    }
}

/// The keyed properties of one joint: its node's translation, rotation and scale.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointTracks {
    pub translation: Option<Track<Vec3>>,
    pub rotation: Option<Track<Quat>>,
    pub scale: Option<Track<Vec3>>,
}

/// A clip: tracks by joint index and by morph target. `root_parent` is the transform of
/// the nodes above the root joint (folded into the root's rest), applied to the root's keyed
/// transform too.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeClip {
    pub name: String,
    /// Its index among the file's animations.
    pub index: usize,
    /// `tracks[j]` moves joint j (one entry per joint of the skeleton).
    pub tracks: Vec<JointTracks>,
    /// `weights[m]` keys the weight of morph target m (one entry per target, or none).
    pub weights: Vec<Option<Track<f32>>>,
    pub root_parent: Mat4,
}

/// A sampled pose: every joint's rotation, rest offset and scale.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NodePose {
    pub rotations: Vec<Quat>,
    pub offsets: Vec<Vec3>,
    pub scales: Vec<Vec3>,
}

impl NodePose {
    /// The skeleton's own pose (its file's rotations), offsets and scales.
    pub fn of(skeleton: &Skeleton) -> Self {
        let joints = skeleton.joints();
        Self {
            rotations: joints.iter().map(|j| j.initial_rotation.to_quat()).collect(),
            offsets: joints.iter().map(|j| j.rest_offset).collect(),
            scales: joints.iter().map(|j| j.rest_scale).collect(),
        }
    }

    /// Every joint's rotation as a pose.
    pub fn pose(&self) -> Vec<JointRotation> {
        self.rotations.iter().map(|&q| JointRotation::Quat(q)).collect()
    }

    /// Every joint's model-space transform in this pose, from `placement` (the matrix
    /// stack with the pose's offsets and scales).
    pub fn joint_to_world(&self, skeleton: &Skeleton, placement: Mat4) -> Vec<Mat4> {
        let mut out = vec![Mat4::IDENTITY; skeleton.len()];
        let rest = super::fk::RestOverride { offsets: Some(&self.offsets), scales: Some(&self.scales) };
        super::fk::forward_kinematics_with_rest(skeleton, &self.pose(), rest, placement, &mut out);
        out
    }

    /// `self` blended towards `other` by `alpha`: rotations along the shorter arc
    /// (normalised linear interpolation), offsets and scales linearly.
    pub fn blended(&self, other: &NodePose, alpha: f32) -> NodePose {
        NodePose {
            rotations: self
                .rotations
                .iter()
                .zip(&other.rotations)
                .map(|(&a, &b)| super::smpl::blend_rotation(a, b, alpha, super::smpl::BlendMode::Nlerp))
                .collect(),
            offsets: self.offsets.iter().zip(&other.offsets).map(|(a, b)| a.lerp(*b, alpha)).collect(),
            scales: self.scales.iter().zip(&other.scales).map(|(a, b)| a.lerp(*b, alpha)).collect(),
        }
    }
}

impl NodeClip {
    /// The clip's length: its last key time, in seconds.
    pub fn duration(&self) -> f32 {
        let ends = self.tracks.iter().flat_map(|t| {
            [
                t.translation.as_ref().map(Track::end),
                t.rotation.as_ref().map(Track::end),
                t.scale.as_ref().map(Track::end),
            ]
        });
        let weight_ends = self.weights.iter().flatten().map(Track::end);
        ends.flatten().chain(weight_ends).fold(0.0, f32::max)
    }

    /// Whether it keys any morph target's weight.
    pub fn keys_weights(&self) -> bool {
        self.weights.iter().any(Option::is_some)
    }

    /// The morph weights at `t` seconds: keyed ones sampled, the others from `base`.
    pub fn sample_weights(&self, base: &[f32], t: f32) -> Vec<f32> {
        let mut weights = base.to_vec();
        weights.resize(self.weights.len().max(base.len()), 0.0);
        for (w, track) in weights.iter_mut().zip(&self.weights) {
            if let Some(track) = track {
                *w = track.sample(t);
            }
        }
        weights
    }

    /// The root joint's own rest transform in its node's parent frame (its rest with the
    /// nodes above taken off).
    fn root_local_rest(&self, root: &super::skeleton::JointDef) -> Mat4 {
        self.root_parent.inverse() * root.local_transform(&root.initial_rotation, root.rest_offset)
    }

    /// The pose at `t` seconds: keyed properties sampled, the others as the skeleton has
    /// them.
    pub fn sample(&self, skeleton: &Skeleton, t: f32) -> NodePose {
        let mut pose = NodePose::of(skeleton);
        for (j, tracks) in self.tracks.iter().enumerate().take(skeleton.len()) {
            let joint = skeleton.joint(j);
            if j == 0 && tracks != &JointTracks::default() {
                // The root's keys are in its node's parent frame; the nodes above come first.
                let (s0, r0, t0) = self.root_local_rest(joint).to_scale_rotation_translation();
                let local = Mat4::from_scale_rotation_translation(
                    tracks.scale.as_ref().map_or(s0, |s| s.sample(t)),
                    tracks.rotation.as_ref().map_or(r0, |r| r.sample(t)),
                    tracks.translation.as_ref().map_or(t0, |s| s.sample(t)),
                );
                let (s, r, tr) = (self.root_parent * local).to_scale_rotation_translation();
                (pose.scales[0], pose.rotations[0], pose.offsets[0]) = (s, r.normalize(), tr);
                continue;
            }
            if let Some(track) = &tracks.translation {
                pose.offsets[j] = track.sample(t);
            }
            if let Some(track) = &tracks.rotation {
                pose.rotations[j] = track.sample(t).normalize();
            }
            if let Some(track) = &tracks.scale {
                pose.scales[j] = track.sample(t);
            }
        }
        pose
    }
}

/// [`sample_mix`] at `t`, its rotations put on the joints either clip turns in `pose`
/// (the others keep theirs); the sample itself returned for its offsets and scales.
pub fn pose_mix(
    skeleton: &Skeleton,
    clip: &NodeClip,
    blend: Option<(&NodeClip, f32)>,
    t: f32,
    pose: &mut [JointRotation],
) -> NodePose {
    let now = sample_mix(skeleton, clip, blend, t);
    for (j, q) in now.rotations.iter().enumerate() {
        if clip.turns(j) || blend.is_some_and(|(k, _)| k.turns(j)) {
            pose[j] = JointRotation::Quat(*q);
        }
    }
    now
}

/// The pose of `clip` at `t` seconds, blended with `blend`'s clip by its weight (which runs
/// on the same clock, wrapped to its own length).
pub fn sample_mix(skeleton: &Skeleton, clip: &NodeClip, blend: Option<(&NodeClip, f32)>, t: f32) -> NodePose {
    let pose = clip.sample(skeleton, t);
    match blend {
        Some((other, weight)) if weight > 0.0 => {
            let length = other.duration();
            let wrapped = if length > 0.0 { t.rem_euclid(length) } else { t };
            pose.blended(&other.sample(skeleton, wrapped), weight)
        }
        _ => pose,
    }
}

impl NodeClip {
    /// Whether it keys joint `j`'s rotation.
    pub fn turns(&self, j: usize) -> bool {
        self.tracks.get(j).is_some_and(|t| t.rotation.is_some())
    }

    /// Whether it keys any joint's translation or scale.
    pub fn moves_rest(&self) -> bool {
        self.tracks.iter().any(|t| t.translation.is_some() || t.scale.is_some())
    }
}

/// The morph weights `clip` keys at `t` seconds over `weights` (kept where it keys none),
/// with `blend`'s clip mixed in by its weight (on the same clock, wrapped to its own
/// length): what the editor's player and export give a character's morphs.
pub fn weights_mix(weights: &[f32], clip: &NodeClip, blend: Option<(&NodeClip, f32)>, t: f32) -> Vec<f32> {
    if !clip.keys_weights() {
        return weights.to_vec();
    }
    let mut mixed = clip.sample_weights(weights, t);
    if let Some((other, weight)) = blend.filter(|(k, w)| k.keys_weights() && *w > 0.0) {
        let length = other.duration();
        let wrapped = if length > 0.0 { t.rem_euclid(length) } else { t };
        let theirs = other.sample_weights(&mixed, wrapped);
        mixed.iter_mut().zip(theirs).for_each(|(w, o)| *w += (o - *w) * weight);
    }
    mixed.truncate(weights.len());
    mixed
}

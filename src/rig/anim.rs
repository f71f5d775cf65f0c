//! Keyframed channels, as CSE169's `.anim` clips hold them: each channel is one number
//! over time, cubic Hermite between keys, its tangents from a rule (`flat`, `linear`,
//! `smooth`) or given, and extrapolated before the first key and after the last.
//!
//! Between keys k and k+1 (times t₀ < t₁, span Δ = t₁ − t₀, u = (t − t₀)/Δ):
//! `p(u) = h₀₀ p₀ + h₁₀ Δ v₀ + h₀₁ p₁ + h₁₁ Δ v₁`, v₀ the out-tangent of key k and v₁ the
//! in-tangent of key k+1 (slopes per second, so scaled by the span).

use glam::Vec3;

use super::pose::{EulerOrder, JointRotation};
use super::skeleton::Skeleton;

/// How a key's tangent (its slope, value per second) is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tangent {
    /// Zero slope.
    Flat,
    /// The slope to the neighbouring key on that side (the other side's at an end).
    Linear,
    /// The slope between the two neighbours (as `Linear` at the ends).
    Smooth,
    /// This slope.
    Fixed(f32),
}

/// What a channel does before its first key or after its last.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Extrapolation {
    /// Holds the end key's value.
    Constant,
    /// Goes on along the end key's tangent.
    Linear,
    /// Repeats the keys.
    Cycle,
    /// Repeats the keys, each repetition shifted by the change from first to last key.
    CycleOffset,
    /// Repeats the keys forwards, then backwards.
    Bounce,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Key {
    pub time: f32,
    pub value: f32,
    pub tangent_in: Tangent,
    pub tangent_out: Tangent,
}

/// One animated number: keys in time order and the extrapolation on each side. Tangent
/// slopes are worked out once, when the channel is made.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    keys: Vec<Key>,
    /// Each key's in and out slopes.
    slopes: Vec<(f32, f32)>,
    pub before: Extrapolation,
    pub after: Extrapolation,
}

impl Channel {
    /// A channel of `keys` (sorted by time here; keys at the same time keep their order).
    pub fn new(mut keys: Vec<Key>, before: Extrapolation, after: Extrapolation) -> Self {
        keys.sort_by(|a, b| a.time.total_cmp(&b.time));
        let slopes = (0..keys.len())
            .map(|k| (slope(&keys, k, keys[k].tangent_in, true), slope(&keys, k, keys[k].tangent_out, false)))
            .collect();
        Self { keys, slopes, before, after }
    }

    pub fn keys(&self) -> &[Key] {
        &self.keys
    }

    /// The key's (in, out) slopes.
    pub fn slopes(&self, key: usize) -> (f32, f32) {
        self.slopes[key]
    }

    /// The channel's value at time `t` (seconds); 0 without keys.
    pub fn value_at(&self, t: f32) -> f32 {
        let (Some(first), Some(last)) = (self.keys.first(), self.keys.last()) else { return 0.0 };
        let (start, end) = (first.time, last.time);
        let length = end - start;
        if t < start {
            self.extrapolate(self.before, t, start, length, true)
        } else if t > end {
            self.extrapolate(self.after, t, end, length, false)
        } else {
            self.inside(t)
        }
    }

    fn extrapolate(&self, mode: Extrapolation, t: f32, edge: f32, length: f32, before: bool) -> f32 {
        let (first, last) = (self.keys[0], self.keys[self.keys.len() - 1]);
        if length <= 0.0 && !matches!(mode, Extrapolation::Linear) {
            return if before { first.value } else { last.value };
        }
        match mode {
            Extrapolation::Constant => {
                if before {
                    first.value
                } else {
                    last.value
                }
            }
            Extrapolation::Linear => {
                let slope = if before { self.slopes[0].0 } else { self.slopes[self.keys.len() - 1].1 };
                let value = if before { first.value } else { last.value };
                value + slope * (t - edge)
            }
            Extrapolation::Cycle | Extrapolation::CycleOffset => {
                let cycles = ((t - first.time) / length).floor();
                let inside = self.inside(t - cycles * length);
                if mode == Extrapolation::CycleOffset { inside + cycles * (last.value - first.value) } else { inside }
            }
            Extrapolation::Bounce => {
                let phase = (t - first.time).rem_euclid(2.0 * length);
                let local = if phase <= length { phase } else { 2.0 * length - phase };
                self.inside(first.time + local)
            }
        }
    }

    /// The value at `t` within the keys' range.
    fn inside(&self, t: f32) -> f32 {
        let keys = &self.keys;
        // The span [k, k+1] holding t (the last span at the last key).
        let k = keys.partition_point(|key| key.time <= t).saturating_sub(1).min(keys.len().saturating_sub(2));
        if keys.len() == 1 {
            return keys[0].value;
        }
        let (a, b) = (keys[k], keys[k + 1]);
        let span = b.time - a.time;
        if span <= 0.0 {
            return b.value;
        }
        let u = ((t - a.time) / span).clamp(0.0, 1.0);
        hermite(a.value, self.slopes[k].1 * span, b.value, self.slopes[k + 1].0 * span, u)
    }
}

/// Cubic Hermite on [0, 1]: values p0, p1 and (already span-scaled) tangents m0, m1.
pub fn hermite(p0: f32, m0: f32, p1: f32, m1: f32, u: f32) -> f32 {
    let (u2, u3) = (u * u, u * u * u);
    (2.0 * u3 - 3.0 * u2 + 1.0) * p0 + (u3 - 2.0 * u2 + u) * m0 + (-2.0 * u3 + 3.0 * u2) * p1 + (u3 - u2) * m1
}

/// The slope of key `k` by `rule`, on its incoming side (`incoming`) or outgoing side.
fn slope(keys: &[Key], k: usize, rule: Tangent, incoming: bool) -> f32 {
    let secant = |a: usize, b: usize| {
        let dt = keys[b].time - keys[a].time;
        if dt > 0.0 { (keys[b].value - keys[a].value) / dt } else { 0.0 }
    };
    let (prev, next) = (k.checked_sub(1), Some(k + 1).filter(|&n| n < keys.len()));
    match (rule, prev, next) {
        (Tangent::Flat, ..) | (_, None, None) => 0.0,
        (Tangent::Fixed(s), ..) => s,
        (Tangent::Smooth, Some(p), Some(n)) => secant(p, n),
        (Tangent::Linear, Some(p), Some(n)) => {
            if incoming {
                secant(p, k)
            } else {
                secant(k, n)
            }
        }
        (_, Some(p), None) => secant(p, k),
        (_, None, Some(n)) => secant(k, n),
    }
}

/// A clip: channels over a time range. Channels 0–2 move the root (x, y, z translation);
/// then three per joint (x, y, z rotation, radians) in the skeleton's depth-first order.
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    pub range: (f32, f32),
    pub channels: Vec<Channel>,
}

impl Clip {
    /// Every channel's value at `t`.
    pub fn values_at(&self, t: f32) -> Vec<f32> {
        self.channels.iter().map(|c| c.value_at(t)).collect()
    }

    /// The root's translation and the joints' rotations at `t` for `skeleton`, each
    /// rotation clamped to its joint's limits. Joints the clip has no channels for keep
    /// `fallback`'s rotation; without translation channels the root stays at its offset.
    pub fn pose_at(&self, skeleton: &Skeleton, t: f32, fallback: &[JointRotation]) -> (Vec3, Vec<JointRotation>) {
        let values = self.values_at(t);
        let root_offset = skeleton.joints().first().map_or(Vec3::ZERO, |j| j.rest_offset);
        let root = match values.get(0..3) {
            Some(v) => Vec3::new(v[0], v[1], v[2]),
            None => root_offset,
        };
        let pose = (0..skeleton.len())
            .map(|j| match values.get(3 + 3 * j..6 + 3 * j) {
                Some(v) => JointRotation::Euler(Vec3::new(v[0], v[1], v[2]), EulerOrder::Xyz)
                    .clamped(&skeleton.joint(j).limits),
                None => fallback.get(j).copied().unwrap_or_default(),
            })
            .collect();
        (root, pose)
    }
}

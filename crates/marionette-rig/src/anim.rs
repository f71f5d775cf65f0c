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
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Tangent {
    /// Zero slope.
    Flat,
    /// The slope to the neighbouring key on that side (the other side's at an end).
    Linear,
    /// The slope between the two neighbours (as `Linear` at the ends).
    Smooth,
    /// This slope.
    Fixed(f32),
    /// As an out-tangent: hold the key's value until the next key (constant
    /// interpolation); as an in-tangent, flat.
    Step,
}

/// What a channel does before its first key or after its last.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
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

#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Key {
    pub time: f32,
    pub value: f32,
    pub tangent_in: Tangent,
    pub tangent_out: Tangent,
}

/// One animated number: keys in time order and the extrapolation on each side. Tangent
/// slopes are worked out once, when the channel is made (scene files keep the keys).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(from = "ChannelKeys", into = "ChannelKeys")]
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

    /// A channel with no keys, extrapolated as `constant` (it animates nothing).
    pub fn empty() -> Self {
        Self::new(Vec::new(), Extrapolation::Constant, Extrapolation::Constant)
    }

    /// This channel with its keys edited by `change` (slopes worked out again).
    pub fn with_keys(&self, change: impl FnOnce(&mut Vec<Key>)) -> Self {
        let mut keys = self.keys.clone();
        change(&mut keys);
        Self::new(keys, self.before, self.after)
    }

    /// This channel with a key of `value` at `time` (replacing one within
    /// [`SAME_TIME`] of it), its tangents smooth unless it replaces a key.
    pub fn with_key_at(&self, time: f32, value: f32) -> Self {
        self.with_keys(|keys| match keys.iter_mut().find(|k| (k.time - time).abs() <= SAME_TIME) {
            Some(k) => k.value = value,
            None => keys.push(Key { time, value, tangent_in: Tangent::Smooth, tangent_out: Tangent::Smooth }),
        })
    }

    /// The first key (in time order) whose numbers the curve cannot use: a time, value or
    /// slope that is not finite, or a span whose Hermite terms overflow (values near ±3e38,
    /// keys a hair apart); none when every value the channel gives is finite.
    pub fn first_unusable_key(&self) -> Option<usize> {
        let keys = &self.keys;
        if let Some(k) = keys.iter().position(|key| !(key.time.is_finite() && key.value.is_finite())) {
            return Some(k);
        }
        for (k, key) in keys.iter().enumerate() {
            let (slope_in, slope_out) = self.slopes[k];
            if !(slope_in.is_finite() && slope_out.is_finite()) {
                return Some(k);
            }
            if let Some(next) = keys.get(k + 1) {
                let span = next.time - key.time;
                // The Hermite basis is within [-1, 1] on [0, 1]: this sum bounds every value.
                let bound =
                    key.value.abs() + (slope_out * span).abs() + next.value.abs() + (self.slopes[k + 1].0 * span).abs();
                if !bound.is_finite() || !(next.value - keys[0].value).is_finite() {
                    return Some(k + 1);
                }
            }
        }
        None
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

    /// The channel's value and slope (per second) as `t` is approached from `side`. They
    /// differ between the sides where the curve jumps (a step, the seam of a cycle) or
    /// turns (a bounce, a key whose tangents differ); elsewhere the value is `value_at`'s.
    pub fn sided(&self, t: f32, side: Side) -> (f32, f32) {
        let (Some(first), Some(last)) = (self.keys.first(), self.keys.last()) else { return (0.0, 0.0) };
        if t < first.time || (t == first.time && side == Side::Before) {
            self.extrapolate_sided(self.before, t, side, true)
        } else if t > last.time || (t == last.time && side == Side::After) {
            self.extrapolate_sided(self.after, t, side, false)
        } else {
            self.inside_sided(t, side)
        }
    }

    fn extrapolate_sided(&self, mode: Extrapolation, t: f32, side: Side, before: bool) -> (f32, f32) {
        let (first, last) = (self.keys[0], self.keys[self.keys.len() - 1]);
        let length = last.time - first.time;
        let edge = if before { first } else { last };
        if length <= 0.0 && !matches!(mode, Extrapolation::Linear) {
            return (edge.value, 0.0);
        }
        match mode {
            Extrapolation::Constant => (edge.value, 0.0),
            Extrapolation::Linear => {
                let slope = if before { self.slopes[0].0 } else { self.slopes[self.keys.len() - 1].1 };
                (edge.value + slope * (t - edge.time), slope)
            }
            Extrapolation::Cycle | Extrapolation::CycleOffset => {
                let mut cycles = ((t - first.time) / length).floor();
                let mut local = t - cycles * length;
                // At a seam, the side before is the end of the previous cycle.
                if side == Side::Before && local <= first.time {
                    (cycles, local) = (cycles - 1.0, local + length);
                } else if side == Side::After && local >= last.time {
                    (cycles, local) = (cycles + 1.0, local - length);
                }
                let (value, slope) = self.inside_sided(self.snapped(local), side);
                let offset = if mode == Extrapolation::CycleOffset { cycles * (last.value - first.value) } else { 0.0 };
                (value + offset, slope)
            }
            Extrapolation::Bounce => {
                let phase = (t - first.time).rem_euclid(2.0 * length);
                // At a turn, the side decides the direction: forwards after the first key's
                // turn and before the last key's.
                let forwards = if phase == 0.0 {
                    side == Side::After
                } else if phase == length {
                    side == Side::Before
                } else {
                    phase < length
                };
                if forwards {
                    self.inside_sided(self.snapped(first.time + phase), side)
                } else {
                    let local = if phase == 0.0 { 0.0 } else { 2.0 * length - phase };
                    let (value, slope) = self.inside_sided(self.snapped(first.time + local), side.other());
                    (value, -slope)
                }
            }
        }
    }

    /// A time within the keys' range that a repetition brought there (`t − n·length`, with
    /// its rounding), put on the key it is a few floats from: a repetition's seams are its
    /// keys, and their sides must be the keys' sides.
    fn snapped(&self, t: f32) -> f32 {
        let (first, last) = (self.keys[0].time, self.keys[self.keys.len() - 1].time);
        let near = 16.0 * f32::EPSILON * (first.abs().max(last.abs()) + (last - first));
        let k = self.keys.partition_point(|key| key.time < t);
        let nearest = [k.checked_sub(1), Some(k)]
            .into_iter()
            .flatten()
            .filter_map(|k| self.keys.get(k))
            .map(|key| key.time)
            .find(|&time| (time - t).abs() <= near);
        nearest.unwrap_or(t).clamp(first, last)
    }

    /// As [`sided`](Self::sided) within the keys' range: the span on `side` of `t`.
    fn inside_sided(&self, t: f32, side: Side) -> (f32, f32) {
        let keys = &self.keys;
        if keys.len() == 1 {
            return (keys[0].value, 0.0);
        }
        let starts_at_or_before = |key: &Key| match side {
            Side::After => key.time <= t,
            Side::Before => key.time < t,
        };
        let k = keys.partition_point(starts_at_or_before).saturating_sub(1).min(keys.len() - 2);
        let (a, b) = (keys[k], keys[k + 1]);
        let span = b.time - a.time;
        if span <= 0.0 {
            return (b.value, 0.0);
        }
        if a.tangent_out == Tangent::Step {
            return (a.value, 0.0);
        }
        let u = ((t - a.time) / span).clamp(0.0, 1.0);
        let (m0, m1) = (self.slopes[k].1 * span, self.slopes[k + 1].0 * span);
        (hermite(a.value, m0, b.value, m1, u), hermite_slope(a.value, m0, b.value, m1, u) / span)
    }

    /// The times within `range` (its ends included, in order) between which the channel is
    /// one cubic: its keys, and the keys of every repetition its extrapolation makes. Refused
    /// when there would be more than `most`.
    pub fn seams(&self, range: (f32, f32), most: usize) -> Result<Vec<f32>, String> {
        let mut seams = vec![range.0, range.1];
        let (Some(first), Some(last)) = (self.keys.first(), self.keys.last()) else { return Ok(seams) };
        let length = last.time - first.time;
        let repeats = |mode: Extrapolation| {
            length > 0.0 && matches!(mode, Extrapolation::Cycle | Extrapolation::CycleOffset | Extrapolation::Bounce)
        };
        let repetition = |t: f32| ((f64::from(t) - f64::from(first.time)) / f64::from(length)).floor();
        let from = if repeats(self.before) { repetition(range.0).min(0.0) } else { 0.0 };
        let to = if repeats(self.after) { repetition(range.1).max(0.0) } else { 0.0 };
        let count = (to - from + 1.0) * self.keys.len() as f64;
        if count.is_nan() || count > most as f64 {
            return Err(format!(
                "a channel repeats its {} keys {} times within {:?}: more than the {most} keys a clip is written with",
                self.keys.len(),
                to - from + 1.0,
                range
            ));
        }
        for n in from as i64..=to as i64 {
            let start = first.time + n as f32 * length;
            let bounced = self.before == Extrapolation::Bounce && n < 0 || self.after == Extrapolation::Bounce && n > 0;
            let backwards = bounced && n.rem_euclid(2) == 1;
            for key in &self.keys {
                let t = if backwards { start + (last.time - key.time) } else { start + (key.time - first.time) };
                if range.0 <= t && t <= range.1 {
                    seams.push(t);
                }
            }
        }
        seams.sort_by(f32::total_cmp);
        seams.dedup();
        Ok(seams)
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
        // On the last key (or past a span of none): its value, even after a step.
        if span <= 0.0 || t >= b.time {
            return b.value;
        }
        if a.tangent_out == Tangent::Step {
            return a.value;
        }
        let u = ((t - a.time) / span).clamp(0.0, 1.0);
        hermite(a.value, self.slopes[k].1 * span, b.value, self.slopes[k + 1].0 * span, u)
    }
}

/// Keys closer in time than this (seconds) are one key.
pub const SAME_TIME: f32 = 1e-4;

/// What scene files keep of a channel.
#[derive(serde::Serialize, serde::Deserialize)]
struct ChannelKeys {
    before: Extrapolation,
    after: Extrapolation,
    keys: Vec<Key>,
}

impl From<ChannelKeys> for Channel {
    fn from(c: ChannelKeys) -> Self {
        Channel::new(c.keys, c.before, c.after)
    }
}

impl From<Channel> for ChannelKeys {
    fn from(c: Channel) -> Self {
        ChannelKeys { before: c.before, after: c.after, keys: c.keys }
    }
}

/// Cubic Hermite on [0, 1]: values p0, p1 and (already span-scaled) tangents m0, m1.
pub fn hermite(p0: f32, m0: f32, p1: f32, m1: f32, u: f32) -> f32 {
    let (u2, u3) = (u * u, u * u * u);
    (2.0 * u3 - 3.0 * u2 + 1.0) * p0 + (u3 - 2.0 * u2 + u) * m0 + (-2.0 * u3 + 3.0 * u2) * p1 + (u3 - u2) * m1
}

/// The derivative in `u` of [`hermite`].
pub fn hermite_slope(p0: f32, m0: f32, p1: f32, m1: f32, u: f32) -> f32 {
    let u2 = u * u;
    (6.0 * u2 - 6.0 * u) * (p0 - p1) + (3.0 * u2 - 4.0 * u + 1.0) * m0 + (3.0 * u2 - 2.0 * u) * m1
}

/// Which side of a time a one-sided limit comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    Before,
    After,
}

impl Side {
    pub fn other(self) -> Self {
        match self {
            Side::Before => Side::After,
            Side::After => Side::Before,
        }
    }
}

/// The slope of key `k` by `rule`, on its incoming side (`incoming`) or outgoing side.
fn slope(keys: &[Key], k: usize, rule: Tangent, incoming: bool) -> f32 {
    let secant = |a: usize, b: usize| {
        let dt = keys[b].time - keys[a].time;
        if dt > 0.0 { (keys[b].value - keys[a].value) / dt } else { 0.0 }
    };
    let (prev, next) = (k.checked_sub(1), Some(k + 1).filter(|&n| n < keys.len()));
    match (rule, prev, next) {
        (Tangent::Flat | Tangent::Step, ..) | (_, None, None) => 0.0,
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
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Clip {
    pub range: (f32, f32),
    pub channels: Vec<Channel>,
    /// The joints the channels are for, by name (motion capture); empty when they follow
    /// the skeleton's own order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joint_names: Vec<String>,
    /// Joints below the root moved by keys of their own (a BVH joint's position channels).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub offsets: Vec<OffsetChannels>,
}

/// A joint's place in its parent's frame over time, in place of its rest offset: x, y, z.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OffsetChannels {
    /// The joint (an index into the clip's joints: its names, or the skeleton's order).
    pub joint: usize,
    pub channels: [Channel; 3],
}

impl Clip {
    /// Why the clip cannot be played, if it cannot: a range that is not finite (or whose
    /// length is not), or a channel with an unusable key (see
    /// [`Channel::first_unusable_key`]). The message starts with the field's path.
    pub fn check(&self) -> Result<(), String> {
        let (start, end) = self.range;
        if !(start.is_finite() && end.is_finite() && (end - start).is_finite()) {
            return Err(format!("range: expected two finite times a finite length apart, found {start} and {end}"));
        }
        let offsets = self.offsets.iter().enumerate().flat_map(|(o, offset)| {
            offset.channels.iter().enumerate().map(move |(axis, c)| (format!("offsets[{o}].channels[{axis}]"), c))
        });
        let channels = self.channels.iter().enumerate().map(|(c, channel)| (format!("channels[{c}]"), channel));
        for (path, channel) in channels.chain(offsets) {
            if let Some(k) = channel.first_unusable_key() {
                let key = channel.keys[k];
                return Err(format!(
                    "{path}.keys[{k}]: expected finite numbers whose curve stays finite, found time {} and value {}",
                    key.time, key.value
                ));
            }
        }
        Ok(())
    }

    /// Every channel's value at `t`.
    pub fn values_at(&self, t: f32) -> Vec<f32> {
        self.channels.iter().map(|c| c.value_at(t)).collect()
    }

    /// An empty clip for `joints` joints: a channel without keys per root axis and DOF.
    pub fn empty(joints: usize) -> Self {
        Self {
            range: (0.0, 1.0),
            channels: vec![Channel::empty(); 3 + 3 * joints],
            joint_names: Vec::new(),
            offsets: Vec::new(),
        }
    }

    /// This clip for `skeleton`: a clip named by joints (motion capture) has its channels
    /// moved to the skeleton's joints of the same names, or of the names `names` maps them
    /// to (target name → clip name); joints without one get no keys (they keep their
    /// pose), and the root and the joints the clip moves move only when the skeleton's
    /// root is the clip's (the same rig: its units).
    pub fn retargeted(&self, skeleton: &Skeleton, names: &std::collections::BTreeMap<String, String>) -> Clip {
        if self.joint_names.is_empty() {
            return self.clone();
        }
        // The clip's joints by name (the first of a repeated name), for one look-up per joint.
        let mut by_name = std::collections::HashMap::with_capacity(self.joint_names.len());
        for (i, name) in self.joint_names.iter().enumerate() {
            by_name.entry(name.as_str()).or_insert(i);
        }
        let source = |target: &str| by_name.get(names.get(target).map_or(target, String::as_str)).copied();
        let mut clip = Clip::empty(skeleton.len());
        clip.range = self.range;
        let same_root = source(&skeleton.joint(0).name) == Some(0);
        for (j, def) in skeleton.joints().iter().enumerate() {
            let Some(s) = source(&def.name) else { continue };
            if j == 0 && s == 0 {
                clip.channels[..3].clone_from_slice(&self.channels[..3]);
            }
            if let Some(moved) = self.offsets.iter().find(|o| o.joint == s).filter(|_| same_root && j > 0) {
                clip.offsets.push(OffsetChannels { joint: j, channels: moved.channels.clone() });
            }
            for axis in 0..3 {
                if let Some(c) = self.channels.get(Self::joint_channel(s, axis)) {
                    clip.channels[Self::joint_channel(j, axis)] = c.clone();
                }
            }
        }
        clip
    }

    /// The channel of `axis` (0–2) of joint `joint`.
    pub fn joint_channel(joint: usize, axis: usize) -> usize {
        3 + 3 * joint + axis
    }

    /// The root's translation and the joints' rotations at `t` for `skeleton`, each
    /// rotation clamped to its joint's limits. A channel that is missing or has no keys
    /// leaves its number as `fallback` (and the root's offset) has it.
    pub fn pose_at(&self, skeleton: &Skeleton, t: f32, fallback: &[JointRotation]) -> (Vec3, Vec<JointRotation>) {
        self.sampled_pose(skeleton, t, fallback, true)
    }

    /// Every joint's offset in its parent's frame at `t` where the clip moves joints below
    /// the root (the rest offsets elsewhere); none where it moves none.
    pub fn offsets_at(&self, skeleton: &Skeleton, t: f32) -> Option<Vec<Vec3>> {
        if self.offsets.is_empty() {
            return None;
        }
        let mut offsets: Vec<Vec3> = skeleton.joints().iter().map(|j| j.rest_offset).collect();
        let joints = offsets.len();
        for moved in self.offsets.iter().filter(|o| o.joint < joints) {
            let rest = offsets[moved.joint];
            let value = |axis: usize| {
                let c = &moved.channels[axis];
                if c.keys.is_empty() { rest[axis] } else { c.value_at(t) }
            };
            offsets[moved.joint] = Vec3::new(value(0), value(1), value(2));
        }
        Some(offsets)
    }

    /// As [`pose_at`](Self::pose_at), the keyed rotations not clamped: for the ECS, whose
    /// `Solve` step clamps every changed pose (once).
    pub fn pose_at_unclamped(
        &self,
        skeleton: &Skeleton,
        t: f32,
        fallback: &[JointRotation],
    ) -> (Vec3, Vec<JointRotation>) {
        self.sampled_pose(skeleton, t, fallback, false)
    }

    fn sampled_pose(
        &self,
        skeleton: &Skeleton,
        t: f32,
        fallback: &[JointRotation],
        clamp: bool,
    ) -> (Vec3, Vec<JointRotation>) {
        let value = |c: usize, otherwise: f32| match self.channels.get(c) {
            Some(channel) if !channel.keys.is_empty() => channel.value_at(t),
            _ => otherwise,
        };
        let root_offset = skeleton.joints().first().map_or(Vec3::ZERO, |j| j.rest_offset);
        let root = Vec3::new(value(0, root_offset.x), value(1, root_offset.y), value(2, root_offset.z));
        let pose = (0..skeleton.len())
            .map(|j| {
                let before = fallback.get(j).copied().unwrap_or_default();
                let channels = Self::joint_channel(j, 0)..Self::joint_channel(j, 3);
                if channels.clone().all(|c| self.channels.get(c).is_none_or(|ch| ch.keys.is_empty())) {
                    return before;
                }
                let old = before.to_euler(EulerOrder::Xyz);
                let angles = Vec3::new(
                    value(channels.start, old.x),
                    value(channels.start + 1, old.y),
                    value(channels.start + 2, old.z),
                );
                let rotation = JointRotation::Euler(angles, EulerOrder::Xyz);
                if clamp { rotation.clamped(&skeleton.joint(j).limits) } else { rotation }
            })
            .collect();
        (root, pose)
    }

    /// A clip keyed at every frame (`fps` a second from 0): the root's position and the
    /// x, y, z angles of the joints `joints`, linear between frames. Each joint's angles
    /// are taken, of the two Euler triples of its rotation and their turns by 2π, nearest
    /// the frame before, so the curves do not jump.
    pub fn from_frames(skeleton: &Skeleton, frames: &[super::retarget::Frame], fps: f32, joints: &[usize]) -> Self {
        let key =
            |time: f32, value: f32| Key { time, value, tangent_in: Tangent::Linear, tangent_out: Tangent::Linear };
        let channel = |keys: Vec<Key>| Channel::new(keys, Extrapolation::Constant, Extrapolation::Constant);
        let times: Vec<f32> = (0..frames.len()).map(|f| f as f32 / fps).collect();
        let mut clip = Clip::empty(skeleton.len());
        clip.range = (0.0, times.last().copied().unwrap_or(0.0).max(1.0 / fps));
        for axis in 0..3 {
            clip.channels[axis] = channel(frames.iter().zip(&times).map(|(f, &t)| key(t, f.root[axis])).collect());
        }
        for &j in joints {
            let mut previous: Option<Vec3> = None;
            let angles: Vec<Vec3> = frames
                .iter()
                .map(|f| {
                    let a = nearest_euler(f.pose[j].to_euler(EulerOrder::Xyz), previous);
                    previous = Some(a);
                    a
                })
                .collect();
            for axis in 0..3 {
                let keys = angles.iter().zip(&times).map(|(a, &t)| key(t, a[axis])).collect();
                clip.channels[Self::joint_channel(j, axis)] = channel(keys);
            }
        }
        clip
    }

    /// This clip with keys at `time` for the joints `joints` of `pose` (their x, y, z
    /// angles), the range grown to hold `time`.
    pub fn with_pose_keyed(&self, joints: &[usize], pose: &[JointRotation], time: f32) -> Self {
        let mut clip = self.clone();
        for &j in joints {
            let Some(rotation) = pose.get(j) else { continue };
            let angles = rotation.to_euler(EulerOrder::Xyz);
            for axis in 0..3 {
                let c = Self::joint_channel(j, axis);
                if c >= clip.channels.len() {
                    clip.channels.resize(c + 1, Channel::empty());
                }
                clip.channels[c] = clip.channels[c].with_key_at(time, angles[axis]);
            }
        }
        clip.range = (clip.range.0.min(time), clip.range.1.max(time));
        clip
    }
}

/// Of the XYZ Euler triples for the same rotation as `angles` (it, and (x+π, π−y, z+π),
/// each angle give or take 2π), the one nearest `previous`.
fn nearest_euler(angles: Vec3, previous: Option<Vec3>) -> Vec3 {
    use std::f32::consts::{PI, TAU};
    let Some(previous) = previous else { return angles };
    let near = |a: f32, to: f32| a + ((to - a) / TAU).round() * TAU;
    let wrapped = |v: Vec3| Vec3::new(near(v.x, previous.x), near(v.y, previous.y), near(v.z, previous.z));
    let first = wrapped(angles);
    let second = wrapped(Vec3::new(angles.x + PI, PI - angles.y, angles.z + PI));
    if first.distance_squared(previous) <= second.distance_squared(previous) { first } else { second }
}

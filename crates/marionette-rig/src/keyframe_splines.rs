//! A keyframed clip as cubic Hermite splines (glTF's CUBICSPLINE): a [`NodeClip`] keyed
//! where the clip is keyed, with each key's own slopes on either side.
//!
//! The root's translation (and the offsets a clip keys for joints below it) comes out
//! exactly: between the seams of its three channels (their
//! keys, and the keys of the repetitions their extrapolation makes) each channel is one
//! cubic, and a cubic Hermite spline with the curve's values and slopes at both ends of a
//! span is that cubic. A joint's rotation cannot: a cubic in Euler angles is not a cubic in
//! quaternion components. It is keyed at the seams of its three channels with the
//! quaternion's exact value and slopes there, and between them at as many more times as
//! keep the spline within [`ROTATION_TOLERANCE`] of the clip's rotation (a few where the
//! joint turns fast, none where it turns slowly). Where a curve jumps (a step key, a
//! cycle's seam) it is keyed twice, one float apart: the value before the jump, then after.

use glam::{DVec3, DVec4, Mat4, Quat, Vec3};

use super::anim::{Channel, Clip, Side};
use super::node_clip::{Interpolation, JointTracks, NodeClip, Track};
use super::pose::{DofLimits, EulerOrder, JointRotation};
use super::skeleton::Skeleton;

/// How far (radians) a joint's spline may turn away from the clip's rotation between keys.
pub const ROTATION_TOLERANCE: f64 = 1e-5;

/// The shortest span a rotation's keys are refined to (seconds): where a joint reaches its
/// limit its rotation has a kink, which no refinement makes smooth.
const SHORTEST_SPAN: f32 = 1e-5;

/// A curve's value and its slope per second, as 4 numbers (a translation's w is 0; a
/// rotation is a quaternion, x, y, z, w).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Sample {
    value: DVec4,
    slope: DVec4,
}

/// `clip` (over its range, times from its start) for `skeleton` as splines: the root's
/// translation where a root channel is keyed, each joint's the clip moves by its offsets, the rotation of every joint with a keyed
/// channel (clamped to its limits; its unkeyed axes at `fallback`'s angles), as
/// [`Clip::pose_at`] poses it. Refused where it would take more than `most` keys per track.
pub fn spline_clip(
    clip: &Clip,
    skeleton: &Skeleton,
    fallback: &[JointRotation],
    name: &str,
    most: usize,
) -> Result<NodeClip, String> {
    let mut tracks = vec![JointTracks::default(); skeleton.len()];
    if let Some(first) = tracks.first_mut() {
        let root = [0, 1, 2].map(|c| clip.channels.get(c));
        first.translation = translation_track(root, clip.range, skeleton.joint(0).rest_offset, most)?;
    }
    for moved in clip.offsets.iter().filter(|o| o.joint < skeleton.len()) {
        let channels = [0, 1, 2].map(|c| Some(&moved.channels[c]));
        let rest = skeleton.joint(moved.joint).rest_offset;
        tracks[moved.joint].translation = translation_track(channels, clip.range, rest, most)?;
    }
    for (j, tracks) in tracks.iter_mut().enumerate() {
        let held = fallback.get(j).copied().unwrap_or_default().to_euler(EulerOrder::Xyz);
        tracks.rotation = rotation_track(clip, j, held, &skeleton.joint(j).limits, most)?;
    }
    Ok(NodeClip { name: name.to_owned(), index: 0, tracks, weights: Vec::new(), root_parent: Mat4::IDENTITY })
}

/// `clip` with its root's keys in the frame of `frame`, the nodes above the root that a glTF
/// import folded into it ([`NodeClip::root_parent`]): the export writes that frame as a node
/// above the root, so the root's keys go out as `frame⁻¹ ·` the keyed transform. For a frame
/// of uniform scale, the translation's values move by the inverse frame (its slopes by its
/// linear part) and the rotation's values and slopes turn by its inverse rotation: both
/// linear, so each spline stays the same curve.
pub fn reframed(mut clip: NodeClip, frame: Mat4) -> NodeClip {
    let inverse = frame.inverse();
    let (_, turn, _) = inverse.to_scale_rotation_translation();
    if let Some(root) = clip.tracks.first_mut() {
        if let Some(track) = &mut root.translation {
            for (i, v) in track.values.iter_mut().enumerate() {
                // In-slope, value, out-slope: a value is a point, a slope a direction.
                *v = if i % 3 == 1 { inverse.transform_point3(*v) } else { inverse.transform_vector3(*v) };
            }
        }
        if let Some(track) = &mut root.rotation {
            track.values.iter_mut().for_each(|q| *q = turn * *q);
        }
    }
    clip.root_parent = frame;
    clip
}

/// The seams of `channels` that have keys (none keyed: None).
fn seams_of<'c>(
    channels: impl IntoIterator<Item = Option<&'c Channel>>,
    range: (f32, f32),
    most: usize,
) -> Result<Option<Vec<f32>>, String> {
    let mut seams = Vec::new();
    for channel in channels.into_iter().flatten().filter(|c| !c.keys().is_empty()) {
        seams.extend(channel.seams(range, most)?);
    }
    if seams.is_empty() {
        return Ok(None);
    }
    seams.sort_by(f32::total_cmp);
    seams.dedup();
    Ok(Some(seams))
}

/// The value and slope of `channel` at `t` from `side`, or `held` (still) without keys.
fn channel_at(channel: Option<&Channel>, t: f32, side: Side, held: f32) -> (f64, f64) {
    match channel.filter(|c| !c.keys().is_empty()) {
        Some(channel) => {
            let (value, slope) = channel.sided(t, side);
            (f64::from(value), f64::from(slope))
        }
        None => (f64::from(held), 0.0),
    }
}

/// A translation keyed by `channels` (x, y, z; `rest`'s value where one has no keys).
fn translation_track(
    channels: [Option<&Channel>; 3],
    range: (f32, f32),
    rest: Vec3,
    most: usize,
) -> Result<Option<Track<Vec3>>, String> {
    let Some(seams) = seams_of(channels, range, most)? else { return Ok(None) };
    let sided = |t: f32, side: Side| {
        let [x, y, z] = [0, 1, 2].map(|c| channel_at(channels[c], t, side, rest[c]));
        Sample { value: DVec4::new(x.0, y.0, z.0, 0.0), slope: DVec4::new(x.1, y.1, z.1, 0.0) }
    };
    let keys = spline_keys(&seams, range.0, &sided, None, most)?;
    let vector = |v: DVec4| v.truncate().as_vec3();
    Ok(Some(Track { times: keys.times, values: keys.values.into_iter().map(vector).collect(), interpolation: CUBIC }))
}

fn rotation_track(
    clip: &Clip,
    joint: usize,
    held: Vec3,
    limits: &DofLimits,
    most: usize,
) -> Result<Option<Track<Quat>>, String> {
    let channels = Clip::joint_channel(joint, 0)..Clip::joint_channel(joint, 3);
    let Some(seams) = seams_of(channels.clone().map(|c| clip.channels.get(c)), clip.range, most)? else {
        return Ok(None);
    };
    let sided = |t: f32, side: Side| {
        let mut angles = DVec3::ZERO;
        let mut rates = DVec3::ZERO;
        for axis in 0..3 {
            let (angle, rate) = channel_at(clip.channels.get(channels.start + axis), t, side, held[axis]);
            let (lo, hi) = (f64::from(limits.min[axis]), f64::from(limits.max[axis]));
            // Clamped as `DofLimits::clamp` clamps; held still at a limit.
            let clamped = angle.max(lo).min(hi);
            angles[axis] = clamped;
            rates[axis] = if clamped == angle { rate } else { 0.0 };
        }
        euler_xyz_quat(angles, rates)
    };
    let keys = spline_keys(&seams, clip.range.0, &sided, Some(ROTATION_TOLERANCE), most)?;
    let quat = |v: DVec4| Quat::from_vec4(v.as_vec4());
    Ok(Some(Track { times: keys.times, values: keys.values.into_iter().map(quat).collect(), interpolation: CUBIC }))
}

const CUBIC: Interpolation = Interpolation::CubicSpline;

/// The rotation `Rz(z)·Ry(y)·Rx(x)` (`JointRotation::Euler(_, Xyz)`) as a quaternion
/// (continuous in the angles), and its slope for the angles' `rates`: the product rule over
/// the three axis quaternions, each `d/dθ (sin θ/2 a, cos θ/2) = ½ (cos θ/2 a, −sin θ/2)`.
fn euler_xyz_quat(angles: DVec3, rates: DVec3) -> Sample {
    let axis = |a: usize, theta: f64| {
        let (s, c) = (theta / 2.0).sin_cos();
        let mut q = DVec4::new(0.0, 0.0, 0.0, c);
        let mut dq = DVec4::new(0.0, 0.0, 0.0, -s / 2.0);
        q[a] = s;
        dq[a] = c / 2.0;
        (q, dq)
    };
    let (x, dx) = axis(0, angles.x);
    let (y, dy) = axis(1, angles.y);
    let (z, dz) = axis(2, angles.z);
    let value = product(product(z, y), x);
    let slope = product(product(z, y), dx) * rates.x
        + product(product(z, dy), x) * rates.y
        + product(product(dz, y), x) * rates.z;
    Sample { value, slope }
}

/// The angle (radians) between the rotations of two unit quaternions, accurate when small:
/// `2 atan2(|a − b|, |a + b|)` with b on a's side.
fn angle_between(a: DVec4, b: DVec4) -> f64 {
    let b = if a.dot(b) < 0.0 { -b } else { b };
    2.0 * (a - b).length().atan2((a + b).length())
}

/// The Hamilton product of two quaternions stored x, y, z, w (not necessarily unit).
fn product(a: DVec4, b: DVec4) -> DVec4 {
    let (av, bv) = (a.truncate(), b.truncate());
    let v = bv * a.w + av * b.w + av.cross(bv);
    v.extend(a.w * b.w - av.dot(bv))
}

/// A spline's keys: times from the clip's start and three values per key (in-slope, value,
/// out-slope), as glTF stores a CUBICSPLINE sampler.
#[derive(Default)]
struct Keys {
    times: Vec<f32>,
    values: Vec<DVec4>,
}

impl Keys {
    /// Appends a key; one at or before the last key's time (seams a float apart that
    /// round together once measured from the clip's start) is left out.
    fn push(&mut self, time: f32, slope_in: DVec4, value: DVec4, slope_out: DVec4) {
        if self.times.last().is_some_and(|&last| last >= time) {
            return;
        }
        self.times.push(time);
        self.values.extend([slope_in, value, slope_out]);
    }
}

/// The keys of a curve given by its one-sided samples: one at each of `seams` (absolute
/// times; two, a float apart, where the curve jumps), and with a `tolerance` (radians,
/// for rotations) more between them until the spline stays within it.
fn spline_keys(
    seams: &[f32],
    start: f32,
    sided: &dyn Fn(f32, Side) -> Sample,
    tolerance: Option<f64>,
    most: usize,
) -> Result<Keys, String> {
    let mut keys = Keys::default();
    for (i, &seam) in seams.iter().enumerate() {
        let time = seam - start;
        // The value at a seam is the one after it (as `Channel::value_at` gives it); where
        // the curve jumps there, the value before goes one float earlier.
        let after = sided(seam, Side::After);
        match (i > 0).then(|| sided(seam, Side::Before)) {
            Some(before) if before.value != after.value => {
                keys.push(f32::from_bits(time.to_bits() - 1), before.slope, before.value, DVec4::ZERO);
                keys.push(time, DVec4::ZERO, after.value, after.slope);
            }
            Some(before) => keys.push(time, before.slope, after.value, after.slope),
            None => keys.push(time, DVec4::ZERO, after.value, after.slope),
        }
        if let (Some(tolerance), Some(&next)) = (tolerance, seams.get(i + 1)) {
            let span = Span { start: (seam, after), end: (next, sided(next, Side::Before)) };
            refine(&mut keys, start, span, sided, tolerance, most)?;
        }
        if keys.times.len() > most {
            return Err(too_many(most));
        }
    }
    Ok(keys)
}

/// A span of a curve between two keys: each end's time and its sample on the span's side.
#[derive(Clone, Copy)]
struct Span {
    start: (f32, Sample),
    end: (f32, Sample),
}

/// Keys inside `span` (halving it) until the spline over each piece turns less than
/// `tolerance` from the curve at its quarter points, or the pieces are
/// [`SHORTEST_SPAN`] long.
fn refine(
    keys: &mut Keys,
    start: f32,
    span: Span,
    sided: &dyn Fn(f32, Side) -> Sample,
    tolerance: f64,
    most: usize,
) -> Result<(), String> {
    let ((t0, a), (t1, b)) = (span.start, span.end);
    let dt = f64::from(t1 - t0);
    let spline = |u: f64| {
        let (u2, u3) = (u * u, u * u * u);
        (a.value * (2.0 * u3 - 3.0 * u2 + 1.0)
            + a.slope * (dt * (u3 - 2.0 * u2 + u))
            + b.value * (-2.0 * u3 + 3.0 * u2)
            + b.slope * (dt * (u3 - u2)))
            .normalize()
    };
    let off = |u: f64| {
        let exact = sided(t0 + (u * dt) as f32, Side::After).value.normalize();
        angle_between(spline(u), exact)
    };
    let worst = [0.25, 0.5, 0.75].map(off).into_iter().fold(0.0, f64::max);
    let middle = t0 + (t1 - t0) / 2.0;
    // Within tolerance, short enough, or a span of two neighbouring floats.
    if worst.is_nan() || worst <= tolerance || t1 - t0 <= SHORTEST_SPAN || !(t0 < middle && middle < t1) {
        return Ok(());
    }
    if keys.times.len() >= most {
        return Err(too_many(most));
    }
    let (before, after) = (sided(middle, Side::Before), sided(middle, Side::After));
    refine(keys, start, Span { start: span.start, end: (middle, before) }, sided, tolerance, most)?;
    keys.push(middle - start, before.slope, after.value, after.slope);
    refine(keys, start, Span { start: (middle, after), end: span.end }, sided, tolerance, most)
}

fn too_many(most: usize) -> String {
    format!("the clip needs more than the {most} keys a track is written with")
}

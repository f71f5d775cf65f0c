//! BVH motion capture: `HIERARCHY` (`ROOT`/`JOINT name { OFFSET x y z  CHANNELS n …
//! }`, `End Site { OFFSET … }`) then `MOTION` (`Frames: N`, `Frame Time: dt`, one line of
//! channel values per frame). Rotations are in degrees; a joint's channels list its
//! rotation axes outermost first (`Zrotation Xrotation Yrotation` is `Rz · Rx · Ry`).
//!
//! Read as a skeleton (end sites become leaf joints named `<parent>_end`, so the last bones
//! show) and a clip with a key per frame on each root-translation and x/y/z-rotation channel
//! (linear between frames), named by the BVH's joints so other characters can play it.

use std::io::BufRead;
use std::path::Path;

use glam::{Quat, Vec3};

use super::cse169::{Tokens, tokenize};
use super::error::{FormatError, Lines, excerpt};
use marionette_rig::anim::{Channel, Clip, Extrapolation, Key, OffsetChannels, Tangent};
use marionette_rig::{EulerOrder, JointRotation, MAX_JOINTS, RawJoint, Skeleton};

/// A BVH file: its skeleton and its motion as a clip.
#[derive(Debug, Clone)]
pub struct BvhFile {
    pub skeleton: Skeleton,
    pub clip: Clip,
    pub frame_time: f32,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Dof {
    Position(usize),
    Rotation(usize),
}

/// A joint as read: its channels (into the frame lines) in file order.
struct Read {
    raw: RawJoint,
    dofs: Vec<(Dof, usize)>,
}

/// Parses a BVH file.
pub fn parse_bvh(reader: impl BufRead, path: &Path) -> Result<BvhFile, FormatError> {
    let mut lines = Lines::new(reader, path);
    let hierarchy = hierarchy_text(&mut lines)?;
    let mut tokens = Tokens::new(tokenize(hierarchy.as_bytes(), path)?, path);
    tokens.expect("HIERARCHY")?;
    let mut joints: Vec<Read> = Vec::new();
    let mut open: Vec<usize> = Vec::new();
    let mut columns = 0usize;
    let mut first = true;
    loop {
        let word = tokens.next_token("`ROOT`, `JOINT`, `End`, `}` or `MOTION`")?;
        match word.text.as_str() {
            "ROOT" | "JOINT" => {
                if (word.text == "ROOT") != first || (word.text == "ROOT" && !open.is_empty()) {
                    return Err(FormatError::syntax(
                        path,
                        word.line,
                        format!("expected one ROOT first, found `{}`", excerpt(&word.text)),
                    ));
                }
                first = false;
                if joints.len() >= MAX_JOINTS {
                    return Err(FormatError::syntax(
                        path,
                        word.line,
                        format!("expected at most {MAX_JOINTS} joints, found more"),
                    ));
                }
                let name = tokens.next_token("a joint name")?.text;
                tokens.expect("{")?;
                tokens.expect("OFFSET")?;
                let offset = tokens.vec3("the offset")?;
                tokens.expect("CHANNELS")?;
                let line = tokens.line();
                let n = tokens.number("the number of channels")?;
                if !(0.0..=6.0).contains(&n) || n.fract() != 0.0 {
                    return Err(FormatError::syntax(path, line, format!("expected 0 to 6 channels, found {n}")));
                }
                let mut dofs = Vec::new();
                for _ in 0..n as usize {
                    let t = tokens.next_token("a channel name")?;
                    let dof = match t.text.as_str() {
                        "Xposition" => Dof::Position(0),
                        "Yposition" => Dof::Position(1),
                        "Zposition" => Dof::Position(2),
                        "Xrotation" => Dof::Rotation(0),
                        "Yrotation" => Dof::Rotation(1),
                        "Zrotation" => Dof::Rotation(2),
                        other => {
                            return Err(FormatError::syntax(
                                path,
                                t.line,
                                format!("expected a channel (Xposition … Zrotation), found `{}`", excerpt(other)),
                            ));
                        }
                    };
                    dofs.push((dof, columns));
                    columns += 1;
                }
                let parent = open.last().copied();
                joints.push(Read { raw: RawJoint::new(name, parent, offset), dofs });
                open.push(joints.len() - 1);
            }
            "End" => {
                tokens.expect("Site")?;
                tokens.expect("{")?;
                tokens.expect("OFFSET")?;
                let offset = tokens.vec3("the end site's offset")?;
                tokens.expect("}")?;
                let parent = *open
                    .last()
                    .ok_or_else(|| FormatError::syntax(path, word.line, "expected a joint around the end site"))?;
                let name = format!("{}_end", joints[parent].raw.name);
                joints.push(Read { raw: RawJoint::new(name, Some(parent), offset), dofs: Vec::new() });
            }
            "}" => {
                open.pop()
                    .ok_or_else(|| FormatError::syntax(path, word.line, "expected a joint to close, found `}`"))?;
            }
            "MOTION" if open.is_empty() && !first => break,
            other => {
                return Err(FormatError::syntax(
                    path,
                    word.line,
                    format!("expected `JOINT`, `End` or `}}`, found `{}`", excerpt(other)),
                ));
            }
        }
    }
    if !tokens.at_end() {
        return Err(tokens.error("the line end after `MOTION`"));
    }
    let mut motion = Numbers { lines, words: Vec::new(), next: 0, path };
    let frames = frame_header(&mut motion)?;
    motion.expect("Frame")?;
    motion.expect("Time:")?;
    let frame_time = motion.number("the frame time")?;
    if frame_time <= 0.0 {
        return Err(motion.error("a positive frame time"));
    }
    if (frames as u64) * (columns as u64) > MAX_CHANNEL_VALUES as u64 {
        return Err(
            motion.error(&format!("at most {MAX_CHANNEL_VALUES} channel values ({frames} frames of {columns})"))
        );
    }
    if frames as f64 * f64::from(frame_time) > f64::from(f32::MAX) {
        return Err(motion.error("a frame time that keeps the clip's length finite"));
    }
    let mut values = Vec::with_capacity(frames * columns);
    for _ in 0..frames * columns {
        values.push(motion.number("a channel value")?);
    }
    if !motion.at_end()? {
        return Err(motion.error(&format!("the end of the file after {frames} frames of {columns} values")));
    }
    let names: Vec<String> = joints.iter().map(|j| j.raw.name.clone()).collect();
    give_bone_boxes(&mut joints);
    let dofs: Vec<Vec<(Dof, usize)>> = joints.iter().map(|j| j.dofs.clone()).collect();
    let skeleton =
        Skeleton::build(joints.into_iter().map(|j| j.raw).collect()).map_err(|e| FormatError::rig(path, e))?;
    let clip = motion_clip(&skeleton, &dofs, (&values, columns), frame_time, names);
    Ok(BvhFile { skeleton, clip, frame_time })
}

/// Each joint a box along the bone to its first child (a small cube at a tip), so the
/// skeleton shows as boxes whatever the file's units. One pass over the joints.
fn give_bone_boxes(joints: &mut [Read]) {
    let typical = joints.iter().map(|j| j.raw.rest_offset.length()).fold(0.0, f32::max).max(1e-3) * 0.08;
    let mut first_child: Vec<Option<usize>> = vec![None; joints.len()];
    for (c, joint) in joints.iter().enumerate().rev() {
        if let Some(p) = joint.raw.parent {
            first_child[p] = Some(c);
        }
    }
    for j in 0..joints.len() {
        let bone = first_child[j].map(|c| joints[c].raw.rest_offset);
        let thick = bone.map_or(typical, |b| (b.length() * 0.15).min(typical)).max(1e-4);
        let end = bone.unwrap_or(Vec3::ZERO);
        joints[j].raw.bone_box = Some(marionette_rig::BoneBox {
            min: end.min(Vec3::ZERO) - Vec3::splat(thick),
            max: end.max(Vec3::ZERO) + Vec3::splat(thick),
        });
    }
}

/// `Frames:` and a whole count.
fn frame_header<R: BufRead>(motion: &mut Numbers<R>) -> Result<usize, FormatError> {
    motion.expect("Frames:")?;
    let n = motion.number("the number of frames")?;
    if n < 0.0 || n.fract() != 0.0 || n > 1e7 {
        return Err(motion.error("a whole number of frames"));
    }
    Ok(n as usize)
}

/// The most channel values (frames × channels) a BVH file may hold.
const MAX_CHANNEL_VALUES: usize = 50_000_000;

/// The text up to the line of `MOTION` (that line included), read line by line: the rest,
/// the frames, is read as a stream of numbers.
fn hierarchy_text<R: BufRead>(lines: &mut Lines<'_, R>) -> Result<String, FormatError> {
    let mut text = String::new();
    while let Some((_, line)) = lines.next_line()? {
        text.push_str(line);
        text.push('\n');
        if line.split_whitespace().next() == Some("MOTION") {
            break;
        }
    }
    Ok(text)
}

/// The words of the motion section, read a line at a time (one frame's values are never
/// all held as text).
struct Numbers<'p, R> {
    lines: Lines<'p, R>,
    words: Vec<String>,
    next: usize,
    path: &'p Path,
}

impl<R: BufRead> Numbers<'_, R> {
    /// The next word, or none at the end of the file.
    fn peek(&mut self) -> Result<Option<&str>, FormatError> {
        while self.next >= self.words.len() {
            let Some((_, line)) = self.lines.next_line()? else { return Ok(None) };
            self.words = line.split_whitespace().map(str::to_string).collect();
            self.next = 0;
        }
        Ok(Some(&self.words[self.next]))
    }

    fn error(&self, expected: &str) -> FormatError {
        let found = self.words.get(self.next).map_or("the end of the file".into(), |w| format!("`{}`", excerpt(w)));
        FormatError::syntax(self.path, self.lines.line().max(1), format!("expected {expected}, found {found}"))
    }

    fn expect(&mut self, word: &str) -> Result<(), FormatError> {
        if self.peek()? == Some(word) {
            self.next += 1;
            Ok(())
        } else {
            Err(self.error(&format!("`{word}`")))
        }
    }

    fn number(&mut self, what: &str) -> Result<f32, FormatError> {
        match self.peek()?.map(str::parse::<f32>) {
            Some(Ok(v)) if v.is_finite() => {
                self.next += 1;
                Ok(v)
            }
            Some(Ok(_)) => Err(self.error(&format!("a finite number ({what})"))),
            _ => Err(self.error(&format!("a number ({what})"))),
        }
    }

    fn at_end(&mut self) -> Result<bool, FormatError> {
        Ok(self.peek()?.is_none())
    }
}

/// The motion as a clip: per frame, the root's position, each lower joint's position where
/// it has position channels, and each joint's rotation as x, y, z angles (unwrapped from
/// frame to frame so the linear keys between them turn the short way).
fn motion_clip(
    skeleton: &Skeleton,
    dofs: &[Vec<(Dof, usize)>],
    (values, columns): (&[f32], usize),
    frame_time: f32,
    names: Vec<String>,
) -> Clip {
    let frames = values.len().checked_div(columns).unwrap_or(0);
    let mut channels: Vec<Vec<Key>> = vec![Vec::new(); 3 + 3 * skeleton.len()];
    let has_positions = |joint: &[(Dof, usize)]| joint.iter().any(|(dof, _)| matches!(dof, Dof::Position(_)));
    let moved: Vec<usize> = (1..dofs.len()).filter(|&j| has_positions(&dofs[j])).collect();
    let mut offsets: Vec<[Vec<Key>; 3]> = vec![Default::default(); moved.len()];
    let key = |time, value| Key { time, value, tangent_in: Tangent::Linear, tangent_out: Tangent::Linear };
    for f in 0..frames {
        let row = &values[f * columns..(f + 1) * columns];
        let time = f as f32 * frame_time;
        if has_positions(&dofs[0]) {
            let root = positioned(skeleton.joint(0).rest_offset, &dofs[0], row);
            for (axis, channel) in channels.iter_mut().take(3).enumerate() {
                channel.push(key(time, root[axis]));
            }
        }
        for (keys, &j) in offsets.iter_mut().zip(&moved) {
            let at = positioned(skeleton.joint(j).rest_offset, &dofs[j], row);
            for (axis, channel) in keys.iter_mut().enumerate() {
                channel.push(key(time, at[axis]));
            }
        }
        for (j, joint) in dofs.iter().enumerate() {
            if !joint.iter().any(|(dof, _)| matches!(dof, Dof::Rotation(_))) {
                continue;
            }
            let angles = JointRotation::Quat(rotation_in(joint, row)).to_euler(EulerOrder::Xyz);
            for axis in 0..3 {
                let c = Clip::joint_channel(j, axis);
                let previous = channels[c].last().map(|k| k.value);
                let value = previous.map_or(angles[axis], |p| p + marionette_rig::turn::wrap_angle(angles[axis] - p));
                channels[c].push(key(time, value));
            }
        }
    }
    let channel = |keys| Channel::new(keys, Extrapolation::Constant, Extrapolation::Constant);
    let offsets = moved
        .into_iter()
        .zip(offsets)
        .map(|(joint, keys)| OffsetChannels { joint, channels: keys.map(channel) })
        .collect();
    let end = frames.saturating_sub(1) as f32 * frame_time;
    Clip {
        range: (0.0, end.max(frame_time)),
        channels: channels.into_iter().map(channel).collect(),
        joint_names: names,
        offsets,
    }
}

/// `offset` with the axes its position channels give replaced by this frame's values.
fn positioned(offset: Vec3, dofs: &[(Dof, usize)], row: &[f32]) -> Vec3 {
    let mut at = offset;
    for &(dof, column) in dofs {
        if let Dof::Position(axis) = dof {
            at[axis] = row[column];
        }
    }
    at
}

/// A joint's rotation in one frame: its rotation channels listed outermost first,
/// `R = R(a₀) · R(a₁) · …`.
fn rotation_in(dofs: &[(Dof, usize)], row: &[f32]) -> Quat {
    dofs.iter().fold(Quat::IDENTITY, |q, &(dof, column)| match dof {
        Dof::Rotation(axis) => q * Quat::from_axis_angle(Vec3::AXES[axis], row[column].to_radians()),
        Dof::Position(_) => q,
    })
}

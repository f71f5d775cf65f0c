//! The SMPL body model of the exercise: linear blendshapes for the mesh and the joints,
//! a shaped skeleton whose bind rotations are identity, quaternion clips and blending.

use glam::{Quat, Vec3};

/// Frames per second of the SMPL clips.
pub const CLIP_FPS: f32 = 30.0;

use super::RigError;
use super::character::{CharacterAsset, Skin};
use super::skeleton::Skeleton;
use super::skinning::SkinWeights;

/// The model: a base mesh and skeleton, per-shape deltas, faces and weights.
#[derive(Debug, Clone, PartialEq)]
pub struct SmplModel {
    /// Hierarchy (names, parents); rest offsets are set from the shaped joints.
    pub skeleton: Skeleton,
    /// x_0: base mesh vertices (model space, T-pose).
    pub base_positions: Vec<Vec3>,
    /// x_b − x_0 for each shape b = 1..
    pub vertex_deltas: Vec<Vec<Vec3>>,
    /// p_0: base absolute joint positions.
    pub base_joints: Vec<Vec3>,
    /// p_b − p_0 for each shape b.
    pub joint_deltas: Vec<Vec<Vec3>>,
    pub triangles: Vec<[u32; 3]>,
    pub weights: SkinWeights,
}

impl SmplModel {
    pub fn shape_count(&self) -> usize {
        self.vertex_deltas.len()
    }

    /// x_β = x_0 + Σ β_b (x_b − x_0). Missing βs count as 0.
    pub fn shaped_positions(&self, betas: &[f32], out: &mut Vec<Vec3>) {
        out.clear();
        out.extend_from_slice(&self.base_positions);
        for (beta, deltas) in betas.iter().zip(&self.vertex_deltas) {
            if *beta != 0.0 {
                for (o, d) in out.iter_mut().zip(deltas) {
                    *o += *beta * *d;
                }
            }
        }
    }

    /// p_β = p_0 + Σ β_b (p_b − p_0).
    pub fn shaped_joints(&self, betas: &[f32]) -> Vec<Vec3> {
        let mut out = self.base_joints.clone();
        for (beta, deltas) in betas.iter().zip(&self.joint_deltas) {
            for (o, d) in out.iter_mut().zip(deltas) {
                *o += *beta * *d;
            }
        }
        out
    }

    /// Rest offsets from absolute joint positions: the root's is its position, every
    /// other joint's is its position minus its parent's.
    pub fn rest_offsets(&self, joints: &[Vec3]) -> Vec<Vec3> {
        (0..joints.len()).map(|j| self.skeleton.parent(j).map_or(joints[j], |p| joints[j] - joints[p])).collect()
    }

    /// A character of shape β: shaped mesh, shaped skeleton, bind at the shaped rest pose.
    pub fn asset(&self, name: &str, betas: &[f32]) -> Result<CharacterAsset, RigError> {
        let mut skeleton = self.skeleton.clone();
        skeleton.set_rest_offsets(&self.rest_offsets(&self.shaped_joints(betas)));
        let mut positions = Vec::new();
        self.shaped_positions(betas, &mut positions);
        let skin = Skin::untextured(positions, self.triangles.clone(), self.weights.clone());
        CharacterAsset::new(name, skeleton, skin, Vec::new())
    }
}

/// A quaternion motion clip: per frame a root position and one local rotation per joint.
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    pub name: String,
    pub root_positions: Vec<Vec3>,
    /// `frame_count × joint_count` rotations, frame-major.
    pub rotations: Vec<Quat>,
    pub joint_count: usize,
}

impl Clip {
    pub fn frame_count(&self) -> usize {
        self.root_positions.len()
    }

    /// The rotations of one frame (clamped to the last); empty for a clip without frames
    /// (the readers never make one).
    pub fn frame(&self, f: usize) -> &[Quat] {
        let f = f.min(self.frame_count().saturating_sub(1));
        self.rotations.get(f * self.joint_count..(f + 1) * self.joint_count).unwrap_or(&[])
    }

    /// Rotations at a fractional frame time, interpolated between neighbouring frames;
    /// `looping` wraps the time, otherwise it is clamped.
    pub fn sample(&self, time_frames: f32, looping: bool, mode: BlendMode, out: &mut Vec<Quat>) {
        let n = self.frame_count();
        out.clear();
        if n == 0 {
            out.resize(self.joint_count, Quat::IDENTITY);
            return;
        }
        let t = if looping { time_frames.rem_euclid(n as f32) } else { time_frames.clamp(0.0, (n - 1) as f32) };
        let f0 = t.floor() as usize % n;
        let f1 = if looping { (f0 + 1) % n } else { (f0 + 1).min(n - 1) };
        blend_rotations(self.frame(f0), self.frame(f1), t.fract(), mode, out);
    }
}

/// The turn that stands a clip up (`upright`): its first frame's root brought to +y (the
/// mocap clips carry a global rotation from a z-up capture); none otherwise.
pub fn upright_turn(clip: &Clip, upright: bool) -> Quat {
    if !upright {
        return Quat::IDENTITY;
    }
    let first_up = clip.frame(0).first().copied().unwrap_or(Quat::IDENTITY) * Vec3::Y;
    Quat::from_rotation_arc(first_up.normalize(), Vec3::Y)
}

/// Scratch for sampling a clip with a second one blended in (the editor's playback and
/// the frames a retargeting samples), reused from call to call.
#[derive(Debug, Default)]
pub struct BlendSampler {
    first: Vec<Quat>,
    second: Vec<Quat>,
    mixed: Vec<Quat>,
}

impl BlendSampler {
    /// `clip` at `time_frames` (looping, or clamped to its frames), with `blend`'s clip
    /// mixed in by its weight when that is positive (on the same clock, wrapped to its own
    /// length).
    pub fn sample(&mut self, clip: &Clip, blend: Option<(&Clip, f32)>, time_frames: f32, looping: bool) -> &[Quat] {
        clip.sample(time_frames, looping, BlendMode::Nlerp, &mut self.first);
        match blend {
            Some((other, weight)) if weight > 0.0 => {
                other.sample(time_frames, true, BlendMode::Nlerp, &mut self.second);
                blend_rotations(&self.first, &self.second, weight, BlendMode::Nlerp, &mut self.mixed);
                &self.mixed
            }
            _ => &self.first,
        }
    }

    /// The pose SMPL playback gives a body — `clip` at `time_frames` with `blend` mixed in
    /// ([`Self::sample`]), turned upright at the root when `upright` ([`upright_turn`]): the
    /// one rule the editor's player, export and retargeting share.
    pub fn playback_pose(
        &mut self,
        clip: &Clip,
        blend: Option<(&Clip, f32)>,
        time_frames: f32,
        looping: bool,
        upright: bool,
    ) -> Vec<crate::JointRotation> {
        let turn = upright_turn(clip, upright);
        self.sample(clip, blend, time_frames, looping)
            .iter()
            .enumerate()
            .map(|(j, &q)| crate::JointRotation::Quat(if j == 0 { turn * q } else { q }))
            .collect()
    }
}

/// How two rotations are interpolated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum BlendMode {
    /// Normalised linear interpolation along the shorter arc (the exercise's choice).
    #[default]
    Nlerp,
    /// Spherical linear interpolation.
    Slerp,
}

/// `out[j]` = the blend of `a[j]` and `b[j]` at `alpha` (0 gives a, 1 gives b).
pub fn blend_rotations(a: &[Quat], b: &[Quat], alpha: f32, mode: BlendMode, out: &mut Vec<Quat>) {
    out.clear();
    out.extend(a.iter().zip(b).map(|(&qa, &qb)| blend_rotation(qa, qb, alpha, mode)));
}

/// One rotation blend (shorter arc).
pub fn blend_rotation(a: Quat, b: Quat, alpha: f32, mode: BlendMode) -> Quat {
    let b = if a.dot(b) < 0.0 { -b } else { b };
    match mode {
        BlendMode::Nlerp => (a * (1.0 - alpha) + b * alpha).normalize(),
        BlendMode::Slerp => a.slerp(b, alpha),
    }
}

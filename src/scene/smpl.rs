//! SMPL characters in the ECS: live shape (β) and clip playback with a second clip blended
//! in; used by the editor and the headless renderer alike. Scene files keep β, clips, time.

use std::path::PathBuf;
use std::sync::Arc;

use bevy::prelude::*;

use crate::formats::scene::SmplDoc;
use crate::rig::JointRotation;
use crate::rig::smpl::{BlendMode, Clip, SmplModel, blend_rotations};
use crate::scene::{Character, JointPose, MarionetteSystems, PoseDirty};

/// Frames per second of the SMPL clips.
pub const CLIP_FPS: f32 = 30.0;

/// The SMPL state of a character.
#[derive(Component, Clone)]
pub struct SmplCharacter {
    pub model: Arc<SmplModel>,
    pub dir: PathBuf,
    pub clips: Vec<(String, Arc<Clip>)>,
    pub betas: [f32; 10],
    pub clip: Option<usize>,
    /// Playback time in frames.
    pub time: f32,
    pub playing: bool,
    pub speed: f32,
    pub looping: bool,
    pub blend_clip: Option<usize>,
    /// 0: the first clip only; 1: the second only.
    pub blend: f32,
    /// Turn the root so the clip's first frame stands upright.
    pub upright: bool,
    /// The shape the character's asset was built for.
    built_betas: [f32; 10],
}

impl SmplCharacter {
    pub fn new(model: Arc<SmplModel>, dir: PathBuf, clips: Vec<(String, Arc<Clip>)>, doc: Option<&SmplDoc>) -> Self {
        let index = |name: &Option<String>| name.as_ref().and_then(|n| clips.iter().position(|c| &c.0 == n));
        let mut betas = [0.0; 10];
        if let Some(d) = doc {
            for (b, v) in betas.iter_mut().zip(&d.betas) {
                *b = *v;
            }
        }
        let d = doc.cloned().unwrap_or_default();
        Self {
            clip: index(&d.clip),
            blend_clip: index(&d.blend_clip),
            time: d.time,
            playing: d.playing,
            speed: if d.speed == 0.0 { 1.0 } else { d.speed },
            looping: d.looping,
            blend: d.blend,
            upright: d.upright,
            model,
            dir,
            clips,
            betas,
            built_betas: [0.0; 10],
        }
    }

    /// Takes the state of a document (β, clips, time, playback), keeping the model, its
    /// clips and the shape the asset was built for (so a β change reshapes it).
    pub fn apply_doc(&mut self, doc: &SmplDoc) {
        let built_betas = self.built_betas;
        *self = Self::new(self.model.clone(), self.dir.clone(), self.clips.clone(), Some(doc));
        self.built_betas = built_betas;
    }

    pub fn doc(&self) -> SmplDoc {
        SmplDoc {
            betas: self.betas.to_vec(),
            clip: self.clip.map(|c| self.clips[c].0.clone()),
            time: self.time,
            playing: self.playing,
            speed: self.speed,
            looping: self.looping,
            blend_clip: self.blend_clip.map(|c| self.clips[c].0.clone()),
            blend: self.blend,
            upright: self.upright,
        }
    }

    /// Length of the current clip in frames (0 without one).
    pub fn clip_frames(&self) -> usize {
        self.clip.map_or(0, |c| self.clips[c].1.frame_count())
    }
}

/// SMPL playback within `Animate`: advance clips, reshape by β, pose from the clips.
/// Whatever builds scenes runs before it.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SmplPlayback;

/// SMPL bodies: β reshaping and clip playback.
pub struct SmplPlugin;

impl Plugin for SmplPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PostUpdate,
            (advance_playback, reshape_bodies, pose_from_clips)
                .chain()
                .in_set(MarionetteSystems::Animate)
                .in_set(SmplPlayback),
        );
    }
}

/// Advances playing clips by the frame time (reads `Time`; writes `SmplCharacter`).
fn advance_playback(time: Res<Time>, mut bodies: Query<&mut SmplCharacter>) {
    for mut body in &mut bodies {
        if !body.playing || body.clip.is_none() {
            continue;
        }
        let n = body.clip_frames() as f32;
        let mut t = body.time + time.delta_secs() * CLIP_FPS * body.speed;
        if body.looping {
            t = t.rem_euclid(n.max(1.0));
        } else if t >= n - 1.0 {
            t = n - 1.0;
            body.playing = false;
        }
        body.time = t;
    }
}

/// Rebuilds the shaped mesh, skeleton and inverse binds when β changed (writes
/// `Character`'s asset and `PoseDirty`; the bind pass, matrix stack and skinning follow).
fn reshape_bodies(mut bodies: Query<(&mut SmplCharacter, &mut Character, &mut PoseDirty), Changed<SmplCharacter>>) {
    for (mut body, mut character, mut dirty) in &mut bodies {
        if body.built_betas == body.betas
            && character.asset.skin.bind_positions.len() == body.model.base_positions.len()
        {
            continue;
        }
        let Ok(asset) = body.model.asset(&character.asset.name, &body.betas) else {
            continue;
        };
        character.asset = Arc::new(asset);
        body.built_betas = body.betas;
        dirty.bind = true;
        dirty.matrices = true;
    }
}

/// Writes the clip pose (blended with the second clip) into the joints when the clip,
/// time or blend changed (writes `JointPose`). A paused body keeps slider edits.
fn pose_from_clips(
    bodies: Query<(&SmplCharacter, &Character), Changed<SmplCharacter>>,
    mut poses: Query<&mut JointPose>,
) {
    let mut a = Vec::new();
    let mut b = Vec::new();
    let mut mixed = Vec::new();
    for (body, character) in &bodies {
        let Some(c) = body.clip else { continue };
        body.clips[c].1.sample(body.time, body.looping, BlendMode::Nlerp, &mut a);
        let rotations = match body.blend_clip {
            Some(k) if body.blend > 0.0 => {
                let other = &body.clips[k].1;
                // The second clip runs on the same clock, wrapped to its own length.
                other.sample(body.time, true, BlendMode::Nlerp, &mut b);
                blend_rotations(&a, &b, body.blend, BlendMode::Nlerp, &mut mixed);
                &mixed
            }
            _ => &a,
        };
        let upright = if body.upright {
            let first_up = body.clips[c].1.frame(0).first().copied().unwrap_or(Quat::IDENTITY) * Vec3::Y;
            Quat::from_rotation_arc(first_up.normalize(), Vec3::Y)
        } else {
            Quat::IDENTITY
        };
        for (j, (&e, q)) in character.joints.iter().zip(rotations).enumerate() {
            let q = if j == 0 { upright * *q } else { *q };
            if let Ok(mut pose) = poses.get_mut(e) {
                pose.set_if_neq(JointPose(JointRotation::Quat(q)));
            }
        }
    }
}

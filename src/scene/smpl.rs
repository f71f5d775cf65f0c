//! SMPL characters in the ECS: live shape (β) and clip playback with a second clip blended
//! in; used by the editor and the headless renderer alike. Scene files keep β, clips, time.

use std::path::PathBuf;
use std::sync::Arc;

use bevy::prelude::*;

use crate::formats::scene::SmplDoc;
use crate::rig::playback::{Clock, Span};
use crate::rig::smpl::{Clip, SmplModel};
use crate::scene::playhead::{Playhead, advance_playheads};
use crate::scene::{Character, JointPose, PoseDirty};

pub use crate::rig::smpl::CLIP_FPS;

/// An SMPL body: the model and the clips of its folder, and its live state, the scene
/// file's own `SmplDoc` (β, clips by file name, time, playback, blend).
#[derive(Component, Clone)]
pub struct SmplCharacter {
    pub model: Arc<SmplModel>,
    pub dir: PathBuf,
    pub clips: Vec<(String, Arc<Clip>)>,
    pub state: SmplDoc,
    /// The shape the character's asset was built for (none: the mean shape).
    built_betas: Vec<f32>,
}

impl SmplCharacter {
    pub fn new(model: Arc<SmplModel>, dir: PathBuf, clips: Vec<(String, Arc<Clip>)>, state: SmplDoc) -> Self {
        Self { model, dir, clips, state, built_betas: Vec::new() }
    }

    /// The index of the clip file `name` in the folder.
    pub fn clip_index(&self, name: Option<&str>) -> Option<usize> {
        let name = name?;
        self.clips.iter().position(|c| c.0 == name)
    }

    /// The clip that plays, if its file is in the folder.
    pub fn clip(&self) -> Option<&Clip> {
        self.clip_index(self.state.clip.as_deref()).map(|c| &*self.clips[c].1)
    }

    /// The clip blended in, if its file is in the folder.
    pub fn blend_clip(&self) -> Option<&Clip> {
        self.clip_index(self.state.blend_clip.as_deref()).map(|c| &*self.clips[c].1)
    }

    /// Length of the current clip in frames (0 without one).
    pub fn clip_frames(&self) -> usize {
        self.clip().map_or(0, Clip::frame_count)
    }
}

/// Its clock runs in frames, at [`CLIP_FPS`] times its speed; it loops through the step
/// from the last frame back to the first.
impl Playhead for SmplCharacter {
    fn clock(&self) -> Clock {
        let s = &self.state;
        Clock { time: s.time, playing: s.playing, speed: s.speed * CLIP_FPS, looping: s.looping }
    }

    fn set_clock(&mut self, clock: Clock) {
        (self.state.time, self.state.playing) = (clock.time, clock.playing);
    }

    fn span(&self) -> Option<Span> {
        Some(self.clip_frames()).filter(|&n| n > 0).map(Span::frames)
    }
}

/// SMPL bodies: β reshaping and clip playback.
pub struct SmplPlugin;

impl Plugin for SmplPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PostUpdate,
            (advance_playheads::<SmplCharacter>, reshape_bodies, pose_from_clips)
                .chain()
                .in_set(super::AnimateSteps::Smpl),
        );
    }
}

/// Rebuilds the shaped mesh, skeleton and inverse binds when β changed (writes
/// `Character`'s asset and `PoseDirty`; the bind pass, matrix stack and skinning follow).
fn reshape_bodies(mut bodies: Query<(&mut SmplCharacter, &mut Character, &mut PoseDirty), Changed<SmplCharacter>>) {
    for (mut body, mut character, mut dirty) in &mut bodies {
        if same_shape(&body.built_betas, &body.state.betas)
            && character.asset.skin.bind_positions.len() == body.model.base_positions.len()
        {
            continue;
        }
        let Ok(asset) = body.model.asset(&character.asset.name, &body.state.betas) else {
            continue;
        };
        character.asset = Arc::new(asset);
        let body = &mut *body;
        body.built_betas.clone_from(&body.state.betas);
        dirty.bind = true;
        dirty.matrices = true;
    }
}

/// Whether two β lists give the same shape (missing coefficients are zero).
fn same_shape(a: &[f32], b: &[f32]) -> bool {
    (0..a.len().max(b.len())).all(|i| a.get(i).unwrap_or(&0.0) == b.get(i).unwrap_or(&0.0))
}

/// Writes the clip pose (blended with the second clip) into the joints when the clip,
/// time or blend changed (writes `JointPose`). A paused body keeps slider edits.
fn pose_from_clips(
    bodies: Query<(&SmplCharacter, &Character), Changed<SmplCharacter>>,
    mut poses: Query<&mut JointPose>,
) {
    let mut sampler = crate::rig::smpl::BlendSampler::default();
    for (body, character) in &bodies {
        let Some(clip) = body.clip() else { continue };
        let state = &body.state;
        let blend = body.blend_clip().map(|other| (other, state.blend));
        let rotations = sampler.playback_pose(clip, blend, state.time, state.looping, state.upright);
        for (&e, rotation) in character.joints.iter().zip(rotations) {
            if let Ok(mut pose) = poses.get_mut(e) {
                pose.set_if_neq(JointPose(rotation));
            }
        }
    }
}

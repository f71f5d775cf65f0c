//! SMPL characters in the ECS: live shape (β) and clip playback with a second clip blended
//! in (posed by [`crate::scene::motion`]); used by the editor and the headless renderer
//! alike. Scene files keep β, clips, time.

use std::path::PathBuf;
use std::sync::Arc;

use bevy::prelude::*;

use crate::document::motion::{Clock, Clocked, SmplMotion};
use crate::formats::scene::SmplDoc;
use crate::rig::smpl::{Clip, SmplModel};
use crate::scene::{Character, PoseDirty};

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

    /// What it plays, for the motion service: its clip, the clip blended in, upright or
    /// not, on its clock; none without a clip.
    pub fn motion(&self) -> Option<(SmplMotion<'_>, Clock)> {
        let blend = self.blend_clip().map(|k| (k, self.state.blend));
        let motion = SmplMotion { clip: self.clip()?, blend, upright: self.state.upright };
        Some((motion, self.state.clock()))
    }
}

/// Rebuilds the shaped mesh, skeleton and inverse binds when β changed (writes
/// `Character`'s asset and `PoseDirty`; the bind pass, matrix stack and skinning follow).
pub(super) fn reshape_bodies(
    mut bodies: Query<(&mut SmplCharacter, &mut Character, &mut PoseDirty), Changed<SmplCharacter>>,
) {
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

//! Keyframed clips (CSE169 `.anim`) playing on any character: the clip's channels give the
//! root's translation and every joint's x, y, z rotation at the playback time. Scene files
//! keep the clip's file, time and playback (`AnimDoc`).

use std::sync::Arc;

use bevy::prelude::*;

use crate::formats::scene::AnimDoc;
use crate::rig::JointRotation;
use crate::rig::anim::Clip;

/// A keyframed clip on a character and its playback state (the scene file's `AnimDoc`).
#[derive(Component, Clone)]
pub struct ClipPlayer {
    pub clip: Arc<Clip>,
    pub state: AnimDoc,
}

/// The root joint's translation (model space) where a clip moves it, in place of the
/// root's offset; none keeps the offset.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct RootTranslation(pub Option<Vec3>);

impl RootTranslation {
    /// What the matrix stack starts from: the move from the root's offset to here.
    pub fn origin(&self, root_offset: Vec3) -> Mat4 {
        self.0.map_or(Mat4::IDENTITY, |t| Mat4::from_translation(t - root_offset))
    }
}

/// The clip state after keying `joints` (all of them when none is given) at `pose` at the
/// clip's current time. A character without a clip gets keys of its own at 0 s, paused.
pub fn keyed(player: Option<&ClipPlayer>, joint_count: usize, joints: &[usize], pose: &[JointRotation]) -> AnimDoc {
    let (clip, mut state) = match player {
        Some(p) => ((*p.clip).clone(), p.state.clone()),
        None => (Clip::empty(joint_count), AnimDoc { playing: false, ..AnimDoc::default() }),
    };
    let all: Vec<usize> = (0..joint_count).collect();
    let joints = if joints.is_empty() { &all[..] } else { joints };
    state.keys = Some(clip.with_pose_keyed(joints, pose, state.time));
    state
}

//! Keyframed clips (CSE169 `.anim`) playing on any character: the clip's channels give the
//! root's translation and every joint's x, y, z rotation at the playback time. Scene files
//! keep the clip's file, time and playback (`AnimDoc`).

use std::sync::Arc;

use bevy::prelude::*;

use crate::formats::scene::AnimDoc;
use crate::rig::JointRotation;
use crate::rig::anim::Clip;
use crate::rig::playback::{Clock, Span};
use crate::scene::playhead::{Playhead, advance_playheads};
use crate::scene::{Character, JointPose};

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

/// Its clock runs in seconds over the clip's keyed range.
impl Playhead for ClipPlayer {
    fn clock(&self) -> Clock {
        let s = &self.state;
        Clock { time: s.time, playing: s.playing, speed: s.speed, looping: s.looping }
    }

    fn set_clock(&mut self, clock: Clock) {
        (self.state.time, self.state.playing) = (clock.time, clock.playing);
    }

    fn span(&self) -> Option<Span> {
        Some(Span::keyed(self.clip.range.0, self.clip.range.1))
    }
}

pub struct KeyframePlugin;

impl Plugin for KeyframePlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PostUpdate,
            (advance_playheads::<ClipPlayer>, pose_from_keyframes).chain().in_set(super::AnimateSteps::Keyframes),
        );
    }
}

/// Poses the joints and moves the root from the clip at its time, when the clip or time
/// changed (writes `JointPose`, `RootTranslation`). A paused clip keeps slider edits.
pub fn pose_from_keyframes(
    mut players: Query<(&ClipPlayer, &Character, &mut RootTranslation), Changed<ClipPlayer>>,
    mut poses: Query<&mut JointPose>,
) {
    for (player, character, mut root) in &mut players {
        let skeleton = &character.asset.skeleton;
        let now: Vec<_> = character.joints.iter().map(|&e| poses.get(e).map_or(Default::default(), |p| p.0)).collect();
        // Not clamped here: `Solve` clamps every changed pose.
        let (translation, pose) = player.clip.pose_at_unclamped(skeleton, player.state.time, &now);
        root.set_if_neq(RootTranslation(Some(translation)));
        for (&entity, rotation) in character.joints.iter().zip(pose) {
            if let Ok(mut p) = poses.get_mut(entity) {
                p.set_if_neq(JointPose(rotation));
            }
        }
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

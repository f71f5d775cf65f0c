//! A character playing its source's own clips (a glTF file's animations): clip, time in
//! seconds, speed, loop, and a second clip blended in on the same clock, like SMPL bodies.
//! Keyed rotations go to the joints' poses; keyed translations and scales to
//! [`RestOverrides`], which the matrix stack uses in place of the skeleton's rest.

use std::sync::Arc;

use bevy::prelude::*;

use crate::formats::scene::PlaybackDoc;
use crate::rig::JointRotation;
use crate::rig::node_clip::{NodeClip, NodePose, sample_mix};
use crate::rig::playback::{Clock, Span};
use crate::scene::morphs::Morphs;
use crate::scene::playhead::{Playhead, advance_playheads};
use crate::scene::{Character, JointPose, RestOverrides};

/// The source's clips and their playback (the scene file's own `PlaybackDoc`).
#[derive(Component, Clone)]
pub struct NodeClipPlayer {
    pub clips: Arc<[NodeClip]>,
    pub state: PlaybackDoc,
}

impl NodeClipPlayer {
    fn named(&self, name: Option<&str>) -> Option<&NodeClip> {
        let name = name?;
        self.clips.iter().find(|c| c.name == name)
    }

    /// The clip that plays.
    pub fn clip(&self) -> Option<&NodeClip> {
        self.named(self.state.clip.as_deref())
    }

    /// The clip blended in.
    pub fn blend_clip(&self) -> Option<&NodeClip> {
        self.named(self.state.blend_clip.as_deref())
    }

    /// The pose at the state's time, blended with the second clip where one is set; none
    /// without a clip.
    pub fn sample(&self, skeleton: &crate::rig::Skeleton) -> Option<NodePose> {
        let blend = self.blend_clip().map(|c| (c, self.state.blend));
        Some(sample_mix(skeleton, self.clip()?, blend, self.state.time))
    }

    /// The clip and the clip blended in.
    pub fn playing_clips(&self) -> impl Iterator<Item = &NodeClip> {
        [self.clip(), self.blend_clip()].into_iter().flatten()
    }
}

/// Its clock runs in seconds over the clip, from 0 to its duration.
impl Playhead for NodeClipPlayer {
    fn clock(&self) -> Clock {
        let s = &self.state;
        Clock { time: s.time, playing: s.playing, speed: s.speed, looping: s.looping }
    }

    fn set_clock(&mut self, clock: Clock) {
        (self.state.time, self.state.playing) = (clock.time, clock.playing);
    }

    fn span(&self) -> Option<Span> {
        self.clip().map(|c| Span::keyed(0.0, c.duration()))
    }
}

/// Playback of the sources' own clips, within `Animate`.
pub struct NodeClipPlugin;

impl Plugin for NodeClipPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PostUpdate,
            (advance_playheads::<NodeClipPlayer>, pose_from_node_clips, weights_from_node_clips)
                .chain()
                .in_set(super::AnimateSteps::NodeClips),
        );
    }
}

/// Poses the joints the clips key from the clips at their time, when the player changed
/// (writes `JointPose`, `RestOverrides`). A paused clip keeps slider edits; joints no clip
/// keys keep theirs.
fn pose_from_node_clips(
    mut players: Query<(&NodeClipPlayer, &Character, &mut RestOverrides), Changed<NodeClipPlayer>>,
    mut poses: Query<&mut JointPose>,
) {
    for (player, character, mut rest) in &mut players {
        let skeleton = &character.asset.skeleton;
        let Some(pose) = player.sample(skeleton) else {
            rest.set_if_neq(RestOverrides::default());
            continue;
        };
        for (j, (&entity, &q)) in character.joints.iter().zip(&pose.rotations).enumerate() {
            if player.playing_clips().any(|c| c.turns(j))
                && let Ok(mut p) = poses.get_mut(entity)
            {
                p.set_if_neq(JointPose(JointRotation::Quat(q)));
            }
        }
        let wanted = if player.playing_clips().any(NodeClip::moves_rest) {
            RestOverrides { offsets: pose.offsets, scales: pose.scales }
        } else {
            RestOverrides::default()
        };
        rest.set_if_neq(wanted);
    }
}

/// Sets the morph weights the clips key, when the player changed (writes `Morphs`; the
/// clip blended in mixes its weights in by its weight).
fn weights_from_node_clips(mut players: Query<(&NodeClipPlayer, &mut Morphs), Changed<NodeClipPlayer>>) {
    for (player, mut morphs) in &mut players {
        let Some(clip) = player.clip() else { continue };
        let state = &player.state;
        let blend = player.blend_clip().map(|other| (other, state.blend));
        let weights = crate::rig::node_clip::weights_mix(&morphs.weights, clip, blend, state.time);
        if morphs.weights != weights {
            morphs.weights = weights;
        }
    }
}

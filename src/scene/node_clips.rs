//! A character playing its source's own clips (a glTF file's animations): clip, time in
//! seconds, speed, loop, and a second clip blended in on the same clock, like SMPL bodies.
//! The motion service ([`crate::scene::motion`]) turns keyed rotations into the joints'
//! poses, keyed translations and scales into [`RestOverrides`](crate::scene::RestOverrides).

use std::sync::Arc;

use bevy::prelude::*;

use crate::document::motion::{Clock, Clocked, NodeMotion};
use crate::formats::scene::PlaybackDoc;
use crate::rig::node_clip::NodeClip;

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

    /// What it plays, for the motion service: the clip and the clip blended in, on its
    /// clock; none without a clip.
    pub fn motion(&self) -> Option<(NodeMotion<'_>, Clock)> {
        let blend = self.blend_clip().map(|c| (c, self.state.blend));
        Some((NodeMotion { clip: self.clip()?, blend }, self.state.clock()))
    }

    /// The clip and the clip blended in.
    pub fn playing_clips(&self) -> impl Iterator<Item = &NodeClip> {
        [self.clip(), self.blend_clip()].into_iter().flatten()
    }
}

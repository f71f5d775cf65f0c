//! What a glTF or FBX file holds: parts, each a character or a prop with its own clips.

use marionette_rig::CharacterAsset;
use marionette_rig::node_clip::NodeClip;

/// One part of a glTF or FBX file: its asset (with its materials), the file's animations of
/// its nodes, and its morph weights as the file sets them.
#[derive(Debug, Clone)]
pub struct Part {
    pub asset: CharacterAsset,
    pub clips: Vec<NodeClip>,
    /// The morph targets' weights as the file sets them (0 where unset).
    pub morph_weights: Vec<f32>,
}

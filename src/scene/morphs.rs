//! Morph targets blended into the bind mesh before skinning (CSE169 `.morph`): a
//! character's weights, and the shaped asset rebuilt when they change.

use std::sync::Arc;

use bevy::prelude::*;

use crate::rig::CharacterAsset;
use crate::scene::{Character, PoseDirty};

/// A character's morph weights (one per target of its asset, the scene file's `morphs`)
/// and the asset as loaded, which they blend from.
#[derive(Component, Clone)]
pub struct Morphs {
    pub base: Arc<CharacterAsset>,
    pub weights: Vec<f32>,
}

pub struct MorphPlugin;

impl Plugin for MorphPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(PostUpdate, blend_morphs.in_set(super::AnimateSteps::Morphs));
    }
}

/// Rebuilds the bind mesh of characters whose weights changed (writes `Character`'s asset
/// and `PoseDirty`; the skinning follows). The character's asset is copied from the base
/// the first time only (and again while the GPU skinning holds it); after that, a clip that
/// keys weights every frame rewrites the positions in place.
pub fn blend_morphs(mut characters: Query<(&Morphs, &mut Character, &mut PoseDirty), Changed<Morphs>>) {
    for (morphs, mut character, mut dirty) in &mut characters {
        let asset = Arc::make_mut(&mut character.asset);
        morphs.base.morph_into(&morphs.weights, &mut asset.skin.bind_positions);
        dirty.matrices = true;
    }
}

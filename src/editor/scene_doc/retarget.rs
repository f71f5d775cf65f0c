//! Retargeted clips in the editor: a clip that plays another humanoid's motion
//! (`AnimDoc::retarget`, without keys of its own) is worked out by the document layer from
//! the scene as it stands, once per setting, and plays as any keyframed clip.

use std::sync::Arc;

use bevy::prelude::*;

use crate::editor::scene_doc::document::{Library, SceneReader};
use crate::editor::state::Messages;
use crate::formats::scene::RetargetDoc;
use crate::scene::keyframes::ClipPlayer;

/// The retargeting a character's clip was last worked out for.
#[derive(Component, Clone, PartialEq, Debug)]
pub struct RetargetedFrom(pub RetargetDoc);

/// Works out the clip of every character whose player asks for a retargeting it has not
/// had yet (reads the scene; writes `ClipPlayer`, `RetargetedFrom` by commands). A failure
/// is said in the messages, and not tried again until the setting changes.
pub fn resolve_retargets(
    mut commands: Commands,
    players: Query<(Entity, &ClipPlayer, Option<&RetargetedFrom>)>,
    scene: SceneReader,
    mut library: ResMut<Library>,
    mut messages: ResMut<Messages>,
) {
    let mut doc = None;
    for (entity, player, done) in &players {
        let (None, Some(wanted)) = (&player.state.keys, &player.state.retarget) else { continue };
        if done.is_some_and(|d| &d.0 == wanted) {
            continue;
        }
        let Some(target) = scene.character_doc(entity) else { continue };
        let doc = doc.get_or_insert_with(|| scene.capture());
        let clip = crate::document::retarget::shaped_asset(&mut library, &target)
            .and_then(|asset| crate::document::retarget::anim_clip(&mut library, doc, &target, &asset, &player.state));
        match clip {
            Ok(clip) => {
                commands.entity(entity).insert(ClipPlayer { clip: Arc::new(clip), state: player.state.clone() });
            }
            Err(e) => messages.push(format!("{}: the motion was not retargeted: {e}", target.name)),
        }
        commands.entity(entity).insert(RetargetedFrom(wanted.clone()));
    }
}

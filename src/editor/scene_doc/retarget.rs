//! Retargeted clips in the editor: a clip that plays another humanoid's motion
//! (`AnimDoc::retarget`, without keys of its own) is worked out by the document layer from
//! the scene as it stands, again when the setting, the humanoid map or the source
//! character's motion changes, and plays as any keyframed clip.

use std::sync::Arc;

use bevy::prelude::*;

use crate::document::retarget::{describe, motion_source_doc, retarget};
pub use crate::editor::scene_doc::document::RetargetedFrom;
use crate::editor::scene_doc::document::{Library, SceneReader};
use crate::editor::state::Messages;
use crate::formats::scene::MotionSourceDoc;
use crate::scene::keyframes::ClipPlayer;

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
        let source_motion = source_motion(&scene, &wanted.from);
        let bones = scene.characters.get(entity).ok().and_then(|c| c.humanoid).map(|h| h.0.clone()).unwrap_or_default();
        if done.is_some_and(|d| &d.settings == wanted && d.bones == bones && d.source_motion == source_motion) {
            continue;
        }
        let Some(target) = scene.character_doc(entity) else { continue };
        let doc = doc.get_or_insert_with(|| scene.capture());
        let worked = library.shaped(&target).and_then(|asset| {
            let source = motion_source_doc(&mut library, doc, &wanted.from)?;
            let done = retarget(&mut library, &source, &target, &asset, wanted)?;
            Ok((describe(&done, &source.name, &target.name, &asset.skeleton), done.clip.clone()))
        });
        let report = match worked {
            Ok((report, clip)) => {
                commands.entity(entity).insert(ClipPlayer { clip: Arc::new(clip), state: player.state.clone() });
                report
            }
            Err(e) => {
                let said = format!("{}: the motion was not retargeted: {e}", target.name);
                messages.push(said.clone());
                said
            }
        };
        commands.entity(entity).insert(RetargetedFrom { settings: wanted.clone(), bones, source_motion, report });
    }
}

/// What a scene character's motion is, as far as retargeting it goes: its keyframed clip
/// (which one), its SMPL clips, blend and shape, its glTF clips and blend; not the time.
/// Empty for a file's motion (it does not change under the editor).
fn source_motion(scene: &SceneReader, from: &MotionSourceDoc) -> String {
    let MotionSourceDoc::Character(id) = from else { return String::new() };
    let Some(c) = scene.characters.iter().find(|c| c.scene.id == *id) else { return String::new() };
    let clip = c.player.map(|p| Arc::as_ptr(&p.clip));
    let smpl = c.smpl.map(|b| (&b.state.clip, &b.state.blend_clip, b.state.blend, &b.state.betas, b.state.upright));
    let playback = c.node_clips.map(|p| (&p.state.clip, &p.state.blend_clip, p.state.blend));
    format!("{clip:?} {smpl:?} {playback:?}")
}

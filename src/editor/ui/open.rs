//! What a path given to the editor does (typed in Add, picked in a dialog, dropped on the
//! window): open a scene, play a clip, or add characters.

use crate::editor::edits::kinds;
use std::path::Path;

use super::{InspectorState, Panels};
use crate::editor::scene_doc::arrange::beside;
use crate::editor::state::Selection;
use crate::formats::scene::{AnimDoc, CharacterDoc, PlacementDoc};

/// Puts the clip at `path` on the selected character, playing.
fn add_clip(path: &str, panels: &mut Panels) {
    match panels.selection.character {
        Some(character) => panels.push(kinds::Clip { character, anim: Some(AnimDoc::of(path)) }),
        None => panels.messages.push(format!("select the character that {path} should play on")),
    }
}

/// What a path given to the editor (typed in Add, or dropped on the window) does: a
/// `.ron` opens as the scene, a `.anim` plays on the selected character, anything else is
/// added as a character.
pub fn open_path(path: &str, state: &mut InspectorState, panels: &mut Panels) {
    if !path.is_empty()
        && let Some(recent) = panels.recent.as_mut()
    {
        recent.remember(path);
    }
    if path.ends_with(".ron") {
        crate::editor::scene_doc::document::open_scene_from(path, &mut panels.pending, &mut panels.messages);
        state.scene_path = path.to_string();
    } else if path.ends_with(".anim") {
        add_clip(path, panels);
    } else {
        add_character(path, state, panels);
    }
}

/// Loads a character file (every character of a glTF file) and adds it right of the
/// others, standing on the floor, and selects it; errors go to the messages.
fn add_character(path: &str, state: &mut InspectorState, panels: &mut Panels) {
    if path.is_empty() {
        return;
    }
    let mut loaded = Vec::new();
    for source in panels.library.sources_of(Path::new(path)) {
        match panels.library.load(&source) {
            Ok(asset) => loaded.push((source, asset)),
            Err(e) => return panels.messages.push(e.to_string()),
        }
    }
    // The characters of one file move together: they keep the layout the file gives them.
    let (lo, hi) = crate::editor::scene_doc::arrange::union(loaded.iter().map(|(_, a)| a.bounds()));
    let translation = beside(&panels.world_boxes(), lo, hi, 1.0);
    for (source, asset) in loaded {
        panels.messages.0.extend(asset.warnings.iter().cloned());
        let id = panels.ids.take();
        let doc = panels.library.new_character_doc(source, &asset);
        panels.push(kinds::Add(Box::new(CharacterDoc {
            id: Some(id),
            placement: PlacementDoc::new(translation, 0.0, 1.0),
            ..doc
        })));
        *panels.selection = Selection { character: Some(id), joints: Vec::new() };
    }
    if let Some(dir) = Path::new(path).parent() {
        state.add_path = format!("{}/", dir.display());
    }
}

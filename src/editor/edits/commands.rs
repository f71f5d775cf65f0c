//! Edits as commands. Every user action — from the panels, the shortcuts, a drag in the
//! viewport — is an [`Edit`] pushed to the [`EditQueue`]; [`apply_edits`] applies them to
//! the live ECS in `Animate` (so an edit is skinned the frame it is made) and records what
//! undoes each: edits too, which each command works out itself ([`edit::Command`]). Undo
//! and redo apply those, so entities and ids stay; only adding and removing spawn or despawn.

use bevy::prelude::*;

pub use crate::editor::edits::edit::{Edit, EditQueue, GestureHold};
use crate::editor::edits::history::History;
use crate::editor::edits::kinds;
use crate::editor::scene_doc::document::{CharacterIndex, NextCharacterId};
use crate::editor::state::Messages;

/// Edits as commands, and their history.
pub struct CommandsPlugin;

impl Plugin for CommandsPlugin {
    fn build(&self, app: &mut App) {
        crate::editor::order::add_editor_order(app);
        app.init_resource::<EditQueue>()
            .init_resource::<History>()
            .init_resource::<crate::editor::state::SavedState>()
            .init_resource::<GestureHold>()
            .init_resource::<CharacterIndex>()
            .init_resource::<NextCharacterId>()
            .init_resource::<crate::editor::state::Symmetry>()
            .add_systems(PostUpdate, apply_edits.in_set(crate::editor::order::EditorSystems::Edits));
    }
}

/// Applies the queued edits and serves undo/redo, recording what undoes each edit into the
/// gesture under way. A gesture ends in the first frame no mouse button or widget is held,
/// and is judged (what changed) in the next, once that frame's chain has run: a clip's
/// pose is only written by playback. Exclusive: edits may spawn and despawn.
pub fn apply_edits(world: &mut World) {
    record_save(world);
    if world.resource::<History>().gesture_ended {
        close_gesture(world);
    }
    let queue = std::mem::take(&mut world.resource_mut::<EditQueue>().0);
    let request = world.resource_mut::<History>().request.take();
    if queue.is_empty() && request.is_none() && !world.resource::<History>().gesture_open() {
        return;
    }
    for edit in queue {
        for inverse in apply_reporting(world, edit) {
            world.resource_mut::<History>().record(inverse);
        }
    }
    let held = world.get_resource::<ButtonInput<MouseButton>>().is_some_and(|b| b.get_pressed().next().is_some())
        || world.resource::<GestureHold>().held();
    world.resource_mut::<History>().gesture_ended = !held;
    if request.is_some() {
        // What is undone must be a step first.
        close_gesture(world);
    }
    if let Some(request) = request
        && let Some((id, step)) = world.resource_mut::<History>().pop(request)
    {
        let back = replay(world, step);
        world.resource_mut::<History>().push_opposite(request, (id, back));
    }
}

/// A save made since the last frame marks the history's state as the file's.
fn record_save(world: &mut World) {
    let state = world.resource::<History>().state();
    if let Some(mut saved) = world.get_resource_mut::<crate::editor::state::SavedState>()
        && saved.saved_now
    {
        *saved = crate::editor::state::SavedState { at: state, changed_at_start: false, saved_now: false };
    }
}

/// Ends the gesture under way: what undoes it becomes one undo step, less what would
/// change nothing now (a drag that came back, a click that only selected).
fn close_gesture(world: &mut World) {
    let mut step = world.resource_mut::<History>().take_gesture();
    step.retain(|inverse| inverse.undo(world).is_ok_and(|undo| !undo.is_empty()));
    if !step.is_empty() {
        world.resource_mut::<History>().commit(step);
    }
}

/// Applies a step's edits last first; returns what undoes the replay.
fn replay(world: &mut World, step: Vec<Edit>) -> Vec<Edit> {
    step.into_iter().rev().flat_map(|edit| apply_reporting(world, edit)).collect()
}

fn apply_reporting(world: &mut World, edit: Edit) -> Vec<Edit> {
    apply(world, edit).unwrap_or_else(|message| {
        world.resource_mut::<Messages>().push(message);
        Vec::new()
    })
}

/// Applies `edit` to the live scene. Returns what undoes it, to be applied last first
/// (empty when it changed nothing), or why it could not be applied.
pub fn apply(world: &mut World, mut edit: Edit) -> Result<Vec<Edit>, String> {
    if let Some(kinds::Add(doc)) = edit.get_mut::<kinds::Add>()
        && doc.id.is_none()
    {
        doc.id = Some(world.resource_mut::<NextCharacterId>().take());
    }
    if world.get_resource::<crate::editor::state::Symmetry>().is_some_and(|s| s.0)
        && let Some(pose) = edit.get::<kinds::Pose>()
    {
        let twins = crate::editor::edits::access::twins_of(world, pose.character, &pose.joints)?;
        edit.get_mut::<kinds::Pose>().expect("a pose edit").joints.extend(twins);
    }
    let undo = edit.undo(world)?;
    if !undo.is_empty() {
        edit.write(world)?;
    }
    Ok(undo)
}

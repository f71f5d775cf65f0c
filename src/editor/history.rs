//! Undo and redo of pose, placement and add/remove edits: snapshots of the scene
//! document, one per edit gesture (a whole slider drag is one step).

use bevy::prelude::*;

use super::document::{PendingScene, SceneReader};
use crate::formats::scene::SceneDoc;

/// Snapshots before each edit, and those undone.
#[derive(Resource, Default)]
pub struct History {
    pub undo: Vec<SceneDoc>,
    pub redo: Vec<SceneDoc>,
    /// An edit gesture is under way (its snapshot is already taken).
    pub editing: bool,
    /// Requests from keys or buttons, served by `apply_history_requests`.
    pub request: Option<HistoryRequest>,
    /// The redo steps a gesture cleared, given back if it turns out to change nothing.
    redo_before_gesture: Vec<SceneDoc>,
    /// Whether this gesture pushed an undo step.
    pushed: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HistoryRequest {
    Undo,
    Redo,
}

/// How many steps are kept.
pub const HISTORY_DEPTH: usize = 200;

impl History {
    /// Records `before` as the state to return to, once per gesture.
    pub fn begin_edit(&mut self, before: &SceneDoc) {
        if self.editing {
            return;
        }
        self.editing = true;
        self.pushed = self.undo.last() != Some(before);
        if self.pushed {
            self.undo.push(before.clone());
            if self.undo.len() > HISTORY_DEPTH {
                self.undo.remove(0);
            }
        }
        self.redo_before_gesture = std::mem::take(&mut self.redo);
    }

    /// Ends the gesture (no button held any more). A gesture that left the scene as it
    /// was (a click that only selected) is no undo step: its entry is dropped and the redo
    /// steps come back.
    pub fn end_gesture(&mut self, now: &SceneDoc) {
        self.editing = false;
        if self.pushed && self.undo.last() == Some(now) {
            self.undo.pop();
            self.redo = std::mem::take(&mut self.redo_before_gesture);
        }
        self.pushed = false;
        self.redo_before_gesture.clear();
    }

    /// The state to restore for undo, given the current one.
    pub fn undo(&mut self, current: SceneDoc) -> Option<SceneDoc> {
        let previous = self.undo.pop()?;
        self.redo.push(current);
        Some(previous)
    }

    pub fn redo(&mut self, current: SceneDoc) -> Option<SceneDoc> {
        let next = self.redo.pop()?;
        self.undo.push(current);
        Some(next)
    }
}

pub struct HistoryPlugin;

impl Plugin for HistoryPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<History>().add_systems(Update, (end_gestures, apply_history_requests));
    }
}

/// Ends an edit gesture when no mouse button is held (reads input and the scene; writes
/// `History`).
fn end_gestures(buttons: Res<ButtonInput<MouseButton>>, reader: SceneReader, mut history: ResMut<History>) {
    if history.editing && !buttons.get_pressed().any(|_| true) {
        history.end_gesture(&reader.capture());
    }
}

/// Serves undo/redo requests by rebuilding the scene from a snapshot, keeping the camera
/// (reads the scene; writes `History`, `PendingScene`).
fn apply_history_requests(mut history: ResMut<History>, reader: SceneReader, mut pending: ResMut<PendingScene>) {
    let Some(request) = history.request.take() else {
        return;
    };
    let current = reader.capture();
    let target = match request {
        HistoryRequest::Undo => history.undo(current),
        HistoryRequest::Redo => history.redo(current),
    };
    if let Some(doc) = target {
        *pending = PendingScene { doc: Some(doc), with_camera: false, frame: false };
    }
}

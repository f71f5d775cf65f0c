//! Undo and redo as commands: each step is the list of edits that undoes one gesture (a
//! whole slider or IK drag, one key press, one button), in the order they were recorded.
//! [`apply_edits`](crate::editor::edits::commands::apply_edits) fills and replays it.

use bevy::prelude::*;

use crate::editor::edits::edit::Edit;
use crate::editor::edits::kinds;

/// The undo and redo steps, and what undoes the gesture under way.
#[derive(Resource, Default, Debug)]
pub struct History {
    undo: Vec<Step>,
    redo: Vec<Step>,
    /// The id the next committed step gets.
    next_id: u64,
    /// What undoes the gesture under way, in the order its edits were applied.
    gesture: Vec<Edit>,
    /// Where the gesture's last add or remove was recorded: edits before it are not merged
    /// with those after (they may name another incarnation of the character).
    barrier: usize,
    /// The gesture ended (nothing held) and becomes a step in the next frame.
    pub gesture_ended: bool,
    /// Requests from keys or buttons, served by `apply_edits`.
    pub request: Option<HistoryRequest>,
}

/// An undo or redo step: the state it returns from (its id), and the edits that undo it.
pub type Step = (u64, Vec<Edit>);

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HistoryRequest {
    Undo,
    Redo,
}

/// How many steps are kept.
pub const HISTORY_DEPTH: usize = 200;

impl History {
    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty() || !self.gesture.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// The number of undo steps.
    pub fn undo_steps(&self) -> usize {
        self.undo.len()
    }

    pub fn redo_steps(&self) -> usize {
        self.redo.len()
    }

    pub fn gesture_open(&self) -> bool {
        !self.gesture.is_empty()
    }

    /// Which state the scene is in: the id of the step undo would reverse (0 where the
    /// history began). Undoing back to a state gives its id again.
    pub fn state(&self) -> u64 {
        self.undo.last().map_or(0, |(id, _)| *id)
    }

    /// Adds what undoes one applied edit to the gesture under way. Within a gesture only
    /// the first value of each thing edited is kept: a slider dragged over a hundred frames
    /// is one value to return to.
    pub fn record(&mut self, inverse: Edit) {
        let recent = &self.gesture[self.barrier..];
        if inverse.get::<kinds::Add>().is_some() || inverse.get::<kinds::Remove>().is_some() {
            self.gesture.push(inverse);
            self.barrier = self.gesture.len();
        } else if let Some(kinds::Pose { character, joints }) = inverse.get::<kinds::Pose>() {
            let earlier = |j: usize| {
                recent
                    .iter()
                    .filter_map(|e| e.get::<kinds::Pose>())
                    .any(|e| e.character == *character && e.joints.iter().any(|&(k, _)| k == j))
            };
            let joints: Vec<_> = joints.iter().copied().filter(|&(j, _)| !earlier(j)).collect();
            if !joints.is_empty() {
                self.gesture.push(kinds::Pose { character: *character, joints }.into());
            }
        } else if !recent.iter().any(|e| e.same_slot(&inverse)) {
            self.gesture.push(inverse);
        }
    }

    /// Takes what undoes the gesture under way, ending it.
    pub fn take_gesture(&mut self) -> Vec<Edit> {
        self.barrier = 0;
        self.gesture_ended = false;
        std::mem::take(&mut self.gesture)
    }

    /// Records a finished gesture as an undo step; a new step clears the redo steps.
    pub fn commit(&mut self, step: Vec<Edit>) {
        self.redo.clear();
        self.next_id += 1;
        push_bounded(&mut self.undo, (self.next_id, step));
    }

    /// The step to replay for `request`.
    pub fn pop(&mut self, request: HistoryRequest) -> Option<Step> {
        match request {
            HistoryRequest::Undo => self.undo.pop(),
            HistoryRequest::Redo => self.redo.pop(),
        }
    }

    /// Records what undoes a replayed step on the other stack.
    pub fn push_opposite(&mut self, request: HistoryRequest, step: Step) {
        match request {
            HistoryRequest::Undo => push_bounded(&mut self.redo, step),
            HistoryRequest::Redo => push_bounded(&mut self.undo, step),
        }
    }
}

fn push_bounded(stack: &mut Vec<Step>, step: Step) {
    stack.push(step);
    if stack.len() > HISTORY_DEPTH {
        stack.remove(0);
    }
}

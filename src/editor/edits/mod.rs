//! Edits as commands: the edit values and their queue, applying them in `Animate` with
//! their inverses, the undo history, and the scene's pose library.

pub mod commands;
pub mod edit;
pub mod history;
pub mod pose_library;

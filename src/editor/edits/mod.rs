//! Edits as commands: the edit values and their queue, applying them in `Animate` with
//! their inverses, the undo history, and the scene's pose library.

mod access;
pub mod character_edits;
pub mod commands;
pub mod edit;
pub mod history;
pub mod pose_library;
pub mod scene_edits;

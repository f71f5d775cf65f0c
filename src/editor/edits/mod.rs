//! Edits as commands: the edit values and their queue, applying them in `Animate` with
//! their inverses, the undo history, and the scene's pose library.

mod access;
pub mod commands;
pub mod edit;
pub mod history;
pub mod kinds;
pub mod pose_library;

//! Each command's body besides the editor's: the SMPL exercise's tasks and sequences
//! ([`smpl_tasks`]). No Bevy; `main.rs` is thin glue over these and the document layer
//! (`document::posing` holds the `JOINT=…` specs and the `info` summary).

pub mod smpl_tasks;

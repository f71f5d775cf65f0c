//! What the command line needs besides the editor: `JOINT=…` pose and IK specs and the
//! `info` summary ([`posing`]), and the SMPL exercise's tasks and sequences
//! ([`smpl_tasks`]). No Bevy; `main.rs` is thin glue over these.

pub mod posing;
pub mod smpl_tasks;

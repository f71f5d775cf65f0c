//! Marionette: scenes of skinned characters.
//!
//! - [`rig`]: skeletons, matrix stack, poses, skinning kernels (no Bevy).
//! - [`formats`]: readers and writers of the course formats (no Bevy).
//! - [`document`]: the asset library, scene documents and files, layout, the default and
//!   crowd scenes, posing specs and export (no Bevy).
//! - [`scene`]: the ECS (joints as entities, matrix-stack and skinning systems).
//! - [`editor`]: the windowed app and the headless renderer.
//! - [`cli`]: the command line's specs, summaries and the SMPL exercise's tasks (no Bevy).

// Bevy queries are spelled as types; naming each one would hide more than it shows (Bevy
// allows this lint across its own workspace for the same reason).
#![allow(clippy::type_complexity)]

pub mod cli;
pub mod editor;
pub mod scene;

// The Bevy-free layers are crates of their own; these names keep one path for each.
pub use marionette_document as document;
pub use marionette_formats as formats;
pub use marionette_rig as rig;

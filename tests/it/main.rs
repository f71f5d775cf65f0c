//! The one integration-test binary (each test binary links bevy, so there is only one).

mod common;
mod data;
mod ecs;
mod editor;
mod formats;
mod ik;
mod rig;
mod smpl;

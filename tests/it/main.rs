//! The one integration-test binary (each test binary links bevy, so there is only one).

mod alloc;
mod anim;
mod arrange;
mod bvh;
mod common;
mod data;
mod dqs;
mod ecs;
mod editor;
mod edits;
mod formats;
mod fuzz;
mod gizmo;
mod gltf;
mod gltf_fuzz;
mod gpu;
mod heat;
mod ik;
mod kernel;
mod layers;
mod poses;
mod rig;
mod robust;
mod smpl;
mod untrusted;
mod writers;

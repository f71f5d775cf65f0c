//! The viewport's interaction: who has the pointer, the orbit camera, picking joints,
//! IK drags, the rotation and move gizmos and the keyboard shortcuts. They push edits; none imports
//! another to know who has the mouse ([`pointer::PointerOwner`]) or to be ordered
//! ([`crate::editor::order`]).

pub mod camera;
pub mod ik_drag;
pub mod limb_handles;
pub mod move_gizmo;
pub mod picking;
pub mod pointer;
pub mod rotate_gizmo;
pub mod shortcuts;

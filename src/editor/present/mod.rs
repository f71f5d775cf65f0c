//! What is shown and captured: the stage (floor, light), skeletons and gizmo drawing, the
//! skin material, the scene's plugins for the window and the renderer (`view`), when a
//! frame may be captured, screenshots and the headless render.

pub mod data;
pub mod draw;
pub mod fast_viewport;
pub mod frames_job;
pub mod readiness;
pub mod redraw;
pub mod render;
pub mod screenshot;
pub mod skin_material;
pub mod stage;
pub mod view;

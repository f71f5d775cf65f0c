//! Who has the pointer: the panels (egui) or the viewport, and within the viewport the
//! rotation gizmo when it holds a press, a turn or a typed rotation. Each owner publishes
//! here; the camera, picking and IK drags read it, so no tool imports another to know.

use bevy::prelude::*;

/// Who besides the panels has the pointer, as the rotation gizmo last published it
/// (reads nothing; written by the gizmo's systems at the end of their chain).
#[derive(Resource, Default, Clone, Copy, Debug, PartialEq, Eq)]
pub struct PointerOwner {
    /// A press landed on the gizmo (it turns the joint: no pick, no IK drag, no orbit).
    pub gizmo_holds_pointer: bool,
    /// A turn is under way (dragged or typed).
    pub gizmo_turning: bool,
    /// A typed turn is under way (its gesture goes on between key presses).
    pub gizmo_typing: bool,
}

pub use crate::editor::state::ViewportHasPointer;

/// The part of the window between the side panels (logical pixels), set by the inspector;
/// `None` leaves the camera on the whole window.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewportArea(pub Option<Rect>);

/// Notes whether the pointer belongs to the 3D view: inside the area between the panels
/// and not used by egui (a popup, a drag that started on a widget), so clicks and drags
/// on the panels neither orbit nor pick (reads `EguiWantsInput`, `ViewportArea`, the
/// cursor; writes `ViewportHasPointer`).
pub fn track_egui_pointer(
    wants: Option<Res<bevy_egui::input::EguiWantsInput>>,
    area: Option<Res<ViewportArea>>,
    windows: Query<&Window, With<bevy::window::PrimaryWindow>>,
    buttons: Res<ButtonInput<MouseButton>>,
    mut pointer: ResMut<ViewportHasPointer>,
) {
    let egui_wants = wants.is_some_and(|w| w.wants_any_pointer_input());
    let cursor = windows.single().ok().and_then(Window::cursor_position);
    let in_view = match (area.and_then(|a| a.0), cursor) {
        (Some(rect), Some(cursor)) => rect.contains(cursor),
        _ => true,
    };
    // Decide when a drag starts and keep it for the whole drag.
    if buttons.get_just_pressed().next().is_some() || !buttons.get_pressed().any(|_| true) {
        pointer.0 = in_view && !egui_wants;
    }
}

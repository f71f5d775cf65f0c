//! The orbit camera: left drag rotates, middle drag pans, right drag or the wheel zooms.

use crate::editor::interact::pointer::{PointerOwner, ViewportArea, ViewportHasPointer};
use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll, MouseScrollUnit};
use bevy::prelude::*;

use crate::editor::state::camera::{CameraRequest, OrbitCamera};
use crate::formats::scene::CameraDoc;

/// Puts the requested camera on (reads and clears `CameraRequest`; writes `OrbitCamera`).
pub fn apply_camera_request(mut request: ResMut<CameraRequest>, mut cameras: Query<&mut OrbitCamera>) {
    if let Some(camera) = request.0.take() {
        cameras.iter_mut().for_each(|mut orbit| orbit.0 = camera);
    }
}

/// Reads mouse drags and the wheel into the orbit (reads input; writes `OrbitCamera`).
#[allow(clippy::too_many_arguments)]
pub fn orbit_camera_input(
    buttons: Res<ButtonInput<MouseButton>>,
    motion: Res<AccumulatedMouseMotion>,
    scroll: Res<AccumulatedMouseScroll>,
    pointer: Option<Res<ViewportHasPointer>>,
    drag: Option<Res<crate::editor::state::JointDrag>>,
    handles: Option<Res<crate::editor::state::LimbHandles>>,
    owner: Option<Res<PointerOwner>>,
    mut cameras: Query<&mut OrbitCamera>,
) {
    if pointer.is_some_and(|p| !p.0)
        || drag.is_some_and(|d| d.active.is_some())
        || handles.is_some_and(|h| h.dragged.is_some())
        || owner.is_some_and(|o| o.gizmo_holds_pointer || o.gizmo_turning)
    {
        return;
    }
    let delta = motion.delta;
    let wheel = match scroll.unit {
        MouseScrollUnit::Line => scroll.delta.y,
        MouseScrollUnit::Pixel => scroll.delta.y / 40.0,
    };
    for mut orbit in &mut cameras {
        if buttons.pressed(MouseButton::Left) && delta != Vec2::ZERO {
            orbit.yaw -= delta.x * 0.008;
            orbit.pitch = (orbit.pitch - delta.y * 0.008).clamp(-1.55, 1.55);
        }
        if buttons.pressed(MouseButton::Middle) && delta != Vec2::ZERO {
            let rotation = Quat::from_euler(EulerRot::YXZ, orbit.yaw, orbit.pitch, 0.0);
            let scale = orbit.distance * 0.0015;
            orbit.focus += rotation * Vec3::new(-delta.x * scale, delta.y * scale, 0.0);
        }
        if buttons.pressed(MouseButton::Right) && delta.y != 0.0 {
            orbit.0 = zoomed(orbit.0, 1.0 + delta.y * 0.005);
        }
        if wheel != 0.0 {
            orbit.0 = zoomed(orbit.0, 0.9f32.powf(wheel));
        }
    }
}

/// The camera `factor` times as far from the focus (an orthographic lens shows `factor`
/// times the height).
fn zoomed(camera: CameraDoc, factor: f32) -> CameraDoc {
    CameraDoc {
        distance: (camera.distance * factor).clamp(0.05, 500.0),
        ortho: camera.ortho.map(|h| (h * factor).clamp(0.01, 1000.0)),
        ..camera
    }
}

/// Gives the window's camera the area between the panels as its viewport, so the view is
/// centred (and F frames) in the visible middle (reads `ViewportArea`, the window; writes
/// `Camera::viewport`).
pub fn fit_camera_viewport(
    area: Res<ViewportArea>,
    windows: Query<&Window, With<bevy::window::PrimaryWindow>>,
    mut cameras: Query<&mut Camera, With<OrbitCamera>>,
) {
    let Ok(window) = windows.single() else { return };
    let viewport = area.0.and_then(|rect| {
        let scale = window.scale_factor();
        let size = window.physical_size().as_vec2();
        let min = (rect.min * scale).round().clamp(Vec2::ZERO, size);
        let max = (rect.max * scale).round().clamp(Vec2::ZERO, size);
        (max.x - min.x >= 1.0 && max.y - min.y >= 1.0).then(|| bevy::camera::Viewport {
            physical_position: min.as_uvec2(),
            physical_size: (max - min).as_uvec2(),
            ..default()
        })
    });
    for mut camera in &mut cameras {
        if camera.viewport.as_ref().map(|v| (v.physical_position, v.physical_size))
            != viewport.as_ref().map(|v| (v.physical_position, v.physical_size))
        {
            camera.viewport = viewport.clone();
        }
    }
}

//! The orbit camera: left drag rotates, middle drag pans, right drag or the wheel zooms.

use crate::editor::interact::pointer::{PointerOwner, ViewportArea, ViewportHasPointer};
use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll, MouseScrollUnit};
use bevy::prelude::*;

use crate::formats::scene::{CameraDoc, ViewName};

/// The share of the picture's half-height (and half-width) that framing fills.
pub const FRAMING_FILL: f32 = 0.85;

/// The width / height of the picture that opening a scene frames for (`render` sets its
/// picture's; the editor uses its viewport's).
#[derive(Resource, Clone, Copy, Debug)]
pub struct FramingAspect(pub f32);

impl Default for FramingAspect {
    fn default() -> Self {
        Self(1.6)
    }
}

/// A camera the panels ask for (a lens, a view, a bookmark), put on at the next update.
#[derive(Resource, Default, Debug)]
pub struct CameraRequest(pub Option<CameraDoc>);

/// Puts the requested camera on (reads and clears `CameraRequest`; writes `OrbitCamera`).
pub fn apply_camera_request(mut request: ResMut<CameraRequest>, mut cameras: Query<&mut OrbitCamera>) {
    if let Some(camera) = request.0.take() {
        cameras.iter_mut().for_each(|mut orbit| orbit.0 = camera);
    }
}

/// Camera views kept by name (the scene file's `bookmarks`).
#[derive(Resource, Clone, Debug, Default, PartialEq, Deref, DerefMut)]
pub struct Bookmarks(pub std::collections::BTreeMap<String, CameraDoc>);

/// The camera's orbit: the scene file's own type (focus, yaw, pitch, distance) on the
/// camera entity.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Deref, DerefMut)]
pub struct OrbitCamera(pub CameraDoc);

impl OrbitCamera {
    /// A three-quarter view of the box `lo..hi` from as close as keeps every corner inside
    /// [`FRAMING_FILL`] of a picture of `aspect` (width / height).
    pub fn framing(lo: Vec3, hi: Vec3, aspect: f32) -> Self {
        let corners = (0..8).map(|i| {
            Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        });
        Self::framing_points(corners, aspect)
    }

    /// A three-quarter view of `points` with Bevy's default lens: see [`Self::framing_from`].
    pub fn framing_points(points: impl Iterator<Item = Vec3> + Clone, aspect: f32) -> Self {
        Self::framing_from(points, aspect, CameraDoc::default().looking_from(ViewName::ThreeQuarter))
    }

    /// `view`'s direction and lens framing `points` (centred on their box) from as close as
    /// keeps every one inside [`FRAMING_FILL`] of a picture of `aspect` (width / height);
    /// an orthographic lens is sized to them instead. Framing the skinned vertices
    /// themselves fills the picture with the silhouette, not with a box around it.
    pub fn framing_from(points: impl Iterator<Item = Vec3> + Clone, aspect: f32, view: CameraDoc) -> Self {
        let (lo, hi) = points
            .clone()
            .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(p), hi.max(p)));
        let mut focus = if lo.x <= hi.x { (lo + hi) / 2.0 } else { Vec3::ZERO };
        let rotation = view.rotation();
        let (right, up, back) = (rotation * Vec3::X, rotation * Vec3::Y, rotation * Vec3::Z);
        let aspect = aspect.max(0.1);
        if view.ortho.is_some() {
            let (min, max) = points
                .clone()
                .map(|p| Vec2::new((p - focus).dot(right), (p - focus).dot(up)))
                .fold((Vec2::INFINITY, Vec2::NEG_INFINITY), |(a, b), s| (a.min(s), b.max(s)));
            let middle = if min.x <= max.x { (min + max) / 2.0 } else { Vec2::ZERO };
            focus += right * middle.x + up * middle.y;
            let half = ((max - min) / 2.0).max(Vec2::splat(0.01));
            let height = 2.0 * (half.y).max(half.x / aspect) / FRAMING_FILL;
            let depth = points.map(|p| (p - focus).dot(back)).fold(0.0f32, f32::max);
            return Self(CameraDoc { focus, ortho: Some(height), distance: view.distance.max(depth + 1.0), ..view });
        }
        let tan_y = (view.fov.to_radians() / 2.0).tan() * FRAMING_FILL;
        let tan_x = tan_y * aspect;
        // A point at depth z (towards the camera) and offsets x, y stays inside when the
        // camera is at least z + |x| / tan_x (and z + |y| / tan_y) away.
        let distance_from = |focus: Vec3| {
            points
                .clone()
                .map(|p| p - focus)
                .map(|c| c.dot(back) + (c.dot(right).abs() / tan_x).max(c.dot(up).abs() / tan_y))
                .fold(0.05f32, f32::max)
        };
        // Seen in perspective, the near side of the points looks larger than the far side:
        // a few rounds of moving the focus to the middle of what the camera sees, then
        // backing off just enough, centre the picture on them.
        for _ in 0..4 {
            let distance = distance_from(focus);
            // Where each point lands, as a share of the half picture, and their middle.
            let seen = |c: Vec3| {
                let depth = (distance - c.dot(back)).max(1e-6);
                Vec2::new(c.dot(right) / (depth * tan_x), c.dot(up) / (depth * tan_y))
            };
            let (min, max) = points
                .clone()
                .map(|p| seen(p - focus))
                .fold((Vec2::INFINITY, Vec2::NEG_INFINITY), |(a, b), s| (a.min(s), b.max(s)));
            let middle = (min + max) / 2.0;
            focus += (right * middle.x * tan_x + up * middle.y * tan_y) * distance;
        }
        Self(CameraDoc { focus, distance: distance_from(focus), ..view })
    }

    /// Where the camera stands and how it is turned (straight up or down too).
    pub fn transform(&self) -> Transform {
        Transform { translation: self.eye(), rotation: self.rotation(), scale: Vec3::ONE }
    }

    /// Bevy's projection for the lens.
    pub fn projection(&self) -> Projection {
        match self.ortho {
            Some(height) => Projection::Orthographic(OrthographicProjection {
                scaling_mode: bevy::camera::ScalingMode::FixedVertical { viewport_height: height },
                // Everything between the camera and well behind the focus.
                near: 0.0,
                far: self.distance + 1000.0,
                ..OrthographicProjection::default_3d()
            }),
            None => Projection::Perspective(PerspectiveProjection { fov: self.fov.to_radians(), ..default() }),
        }
    }
}

/// Reads mouse drags and the wheel into the orbit (reads input; writes `OrbitCamera`).
pub fn orbit_camera_input(
    buttons: Res<ButtonInput<MouseButton>>,
    motion: Res<AccumulatedMouseMotion>,
    scroll: Res<AccumulatedMouseScroll>,
    pointer: Option<Res<ViewportHasPointer>>,
    drag: Option<Res<crate::editor::state::JointDrag>>,
    owner: Option<Res<PointerOwner>>,
    mut cameras: Query<&mut OrbitCamera>,
) {
    if pointer.is_some_and(|p| !p.0)
        || drag.is_some_and(|d| d.active.is_some())
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

/// Places cameras from their orbit and sets their lens (reads `OrbitCamera`; writes
/// `Transform`, `Projection`).
pub fn apply_orbit_camera(mut cameras: Query<(&OrbitCamera, &mut Transform, &mut Projection), Changed<OrbitCamera>>) {
    for (orbit, mut transform, mut projection) in &mut cameras {
        *transform = orbit.transform();
        *projection = orbit.projection();
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

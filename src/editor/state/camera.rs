//! The camera's model, shared by the rooms: the orbit (the scene file's `CameraDoc` on the
//! camera entity), framing, the views kept by name, a camera asked for, and placing the
//! camera from its orbit.

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

/// Camera views kept by name (the scene file's `bookmarks`).
#[derive(Resource, Clone, Debug, Default, PartialEq, Deref, DerefMut)]
pub struct Bookmarks(pub std::collections::BTreeMap<String, CameraDoc>);

/// The camera's orbit: the scene file's own type (focus, yaw, pitch, distance) on the
/// camera entity (of slot 0 unless it says otherwise).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Deref, DerefMut)]
#[require(crate::scene::Slot)]
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

/// Places cameras from their orbit and sets their lens (reads `OrbitCamera`; writes
/// `Transform`, `Projection`).
pub fn apply_orbit_camera(mut cameras: Query<(&OrbitCamera, &mut Transform, &mut Projection), Changed<OrbitCamera>>) {
    for (orbit, mut transform, mut projection) in &mut cameras {
        *transform = orbit.transform();
        *projection = orbit.projection();
    }
}

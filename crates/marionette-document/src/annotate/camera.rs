//! The picture's camera as a pinhole model: intrinsics `K` in pixels and the world-to-camera
//! transform in OpenCV's convention (x right, y down, z forward; pixel (0, 0)'s centre at
//! (0.5, 0.5)), built from the scene's camera exactly as the renderer places it.

use glam::{Mat4, Vec3};
use marionette_formats::scene::CameraDoc;

/// Data pictures are of a perspective camera only.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("--data: the scene's camera is orthographic; data pictures need a perspective camera")]
pub struct Orthographic;

/// The renderer's near plane (Bevy's perspective default), metres.
pub const NEAR: f32 = 0.1;
/// The farthest distance the data passes keep, metres.
pub const FAR: f32 = 1000.0;

/// A pinhole camera over a picture of `width` × `height` pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pinhole {
    pub world_to_camera: Mat4,
    /// Focal length in pixels (square pixels: the same along x and y).
    pub focal: f32,
    pub width: u32,
    pub height: u32,
}

impl Pinhole {
    /// The camera `doc` over a picture of `width` × `height`: its vertical field of view
    /// spans the picture's height. An orthographic camera has no pinhole model.
    pub fn of(doc: &CameraDoc, width: u32, height: u32) -> Result<Self, Orthographic> {
        if doc.ortho.is_some() {
            return Err(Orthographic);
        }
        // The renderer's camera looks along its -z with y up; OpenCV's along +z with y down.
        let camera_to_world = Mat4::from_rotation_translation(doc.rotation(), doc.eye());
        let flip = Mat4::from_scale(Vec3::new(1.0, -1.0, -1.0));
        let focal = height as f32 / 2.0 / (doc.fov.to_radians() / 2.0).tan();
        Ok(Self { world_to_camera: flip * camera_to_world.inverse(), focal, width, height })
    }

    /// `K`, rows first.
    pub fn k(&self) -> [[f32; 3]; 3] {
        let (cx, cy) = (self.width as f32 / 2.0, self.height as f32 / 2.0);
        [[self.focal, 0.0, cx], [0.0, self.focal, cy], [0.0, 0.0, 1.0]]
    }

    /// A world point in the camera's frame (metres; z is the depth along the view axis).
    pub fn to_camera(&self, world: Vec3) -> Vec3 {
        self.world_to_camera.transform_point3(world)
    }

    /// A camera-frame point's pixel position (x, y), for z > 0.
    pub fn pixel_of(&self, c: Vec3) -> (f32, f32) {
        let [[f, _, cx], [_, _, cy], _] = self.k();
        (f * c.x / c.z + cx, f * c.y / c.z + cy)
    }

    /// A world point's pixel position and depth; none in front of the near plane.
    pub fn project(&self, world: Vec3) -> Option<(f32, f32, f32)> {
        let c = self.to_camera(world);
        (c.z >= NEAR).then(|| {
            let (x, y) = self.pixel_of(c);
            (x, y, c.z)
        })
    }

    /// Whether a pixel position lies inside the picture.
    pub fn inside(&self, x: f32, y: f32) -> bool {
        (0.0..self.width as f32).contains(&x) && (0.0..self.height as f32).contains(&y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_focus_lands_on_the_centre_at_the_cameras_distance() {
        let doc = CameraDoc {
            focus: Vec3::new(0.3, 1.0, -0.2),
            yaw: 0.7,
            pitch: -0.4,
            distance: 4.0,
            ..CameraDoc::default()
        };
        let camera = Pinhole::of(&doc, 640, 480).unwrap();
        let (x, y, z) = camera.project(doc.focus).unwrap();
        assert!((x - 320.0).abs() < 1e-3 && (y - 240.0).abs() < 1e-3 && (z - 4.0).abs() < 1e-5, "{x} {y} {z}");
        // A point above the focus is higher in the picture (smaller y).
        let (_, up, _) = camera.project(doc.focus + Vec3::Y * 0.1).unwrap();
        assert!(up < 240.0);
        // The top edge of the field of view is the picture's top edge.
        let top = doc.focus + doc.rotation() * Vec3::new(0.0, 4.0 * (doc.fov.to_radians() / 2.0).tan(), 0.0);
        let (_, y, _) = camera.project(top).unwrap();
        assert!(y.abs() < 1e-2, "{y}");
    }
}

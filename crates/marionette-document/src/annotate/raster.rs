//! The data passes by rasterising the scene's triangles through the picture's pinhole
//! camera: per pixel the nearest surface's depth along the view axis, its normal in the
//! camera's frame, its instance and its body part. The triangles are the ones drawn (the
//! skinned vertices in the world), so the passes agree with the picture to its pixels'
//! edges.

use glam::{Vec2, Vec3};

use super::camera::{NEAR, Pinhole};

/// The instance of a pixel where nothing was hit.
pub const NOTHING: u16 = 0;
/// The instance the floor's pixels carry in the passes (0 in the mask written).
pub const FLOOR: u16 = u16::MAX;

/// Triangles of one instance, in world metres.
pub struct Surface<'a> {
    pub instance: u16,
    pub positions: &'a [Vec3],
    pub triangles: &'a [[u32; 3]],
    /// Each vertex's body part (empty: part 0 everywhere).
    pub parts: &'a [u8],
}

/// What the camera sees at each pixel, rows first from the top.
pub struct Passes {
    pub width: u32,
    pub height: u32,
    /// Metres along the view axis; infinity where nothing was hit.
    pub depth: Vec<f32>,
    /// The surface's unit normal in the camera's frame (OpenCV: x right, y down, z
    /// forward), turned towards the camera; zero where nothing was hit.
    pub normal: Vec<Vec3>,
    pub instance: Vec<u16>,
    pub part: Vec<u8>,
}

impl Passes {
    fn empty(width: u32, height: u32) -> Self {
        let n = (width * height) as usize;
        Self {
            width,
            height,
            depth: vec![f32::INFINITY; n],
            normal: vec![Vec3::ZERO; n],
            instance: vec![NOTHING; n],
            part: vec![0; n],
        }
    }

    /// The index of the pixel at column `x`, row `y`.
    pub fn at(&self, x: u32, y: u32) -> usize {
        (y * self.width + x) as usize
    }
}

/// The passes of `surfaces` seen by `camera`.
pub fn rasterize(camera: &Pinhole, surfaces: &[Surface]) -> Passes {
    let mut passes = Passes::empty(camera.width, camera.height);
    for surface in surfaces {
        for t in surface.triangles {
            let Some(corners) =
                t.map(|v| surface.positions.get(v as usize).copied()).into_iter().collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            let part = triangle_part(surface.parts, t);
            let c = corners.iter().map(|&p| camera.to_camera(p)).collect::<Vec<_>>();
            let mut normal = (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero();
            if normal == Vec3::ZERO {
                continue;
            }
            if normal.dot(c[0]) > 0.0 {
                normal = -normal;
            }
            let polygon = clipped_to_near(&c);
            for k in 1..polygon.len().saturating_sub(1) {
                let tri = [polygon[0], polygon[k], polygon[k + 1]];
                fill(camera, &mut passes, tri, normal, surface.instance, part);
            }
        }
    }
    passes
}

/// The body part most of the triangle's corners have (the first corner's on a tie).
fn triangle_part(parts: &[u8], t: &[u32; 3]) -> u8 {
    let p = t.map(|v| parts.get(v as usize).copied().unwrap_or(0));
    if p[1] == p[2] { p[1] } else { p[0] }
}

/// The part of a triangle (camera frame) at or beyond the near plane, as a convex polygon.
fn clipped_to_near(c: &[Vec3]) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(4);
    for k in 0..c.len() {
        let (a, b) = (c[k], c[(k + 1) % c.len()]);
        let (a_in, b_in) = (a.z >= NEAR, b.z >= NEAR);
        if a_in {
            out.push(a);
        }
        if a_in != b_in {
            let s = (NEAR - a.z) / (b.z - a.z);
            out.push(a + (b - a) * s);
        }
    }
    out
}

/// Fills one triangle (camera frame, all at or beyond the near plane) into the passes: at
/// each pixel centre inside it, the depth by interpolating 1/z across the picture.
fn fill(camera: &Pinhole, passes: &mut Passes, tri: [Vec3; 3], normal: Vec3, instance: u16, part: u8) {
    let screen = tri.map(|c| {
        let (x, y) = camera.pixel_of(c);
        Vec2::new(x, y)
    });
    let inverse_depth = tri.map(|c| 1.0 / c.z);
    let area = edge(screen[0], screen[1], screen[2]);
    if area.abs() < 1e-12 || !area.is_finite() {
        return;
    }
    let lo = screen[0].min(screen[1]).min(screen[2]);
    let hi = screen[0].max(screen[1]).max(screen[2]);
    let (w, h) = (camera.width as f32, camera.height as f32);
    let x0 = (lo.x - 0.5).ceil().clamp(0.0, w) as u32;
    let x1 = (hi.x - 0.5).floor().clamp(-1.0, w - 1.0);
    let y0 = (lo.y - 0.5).ceil().clamp(0.0, h) as u32;
    let y1 = (hi.y - 0.5).floor().clamp(-1.0, h - 1.0);
    if x1 < 0.0 || y1 < 0.0 {
        return;
    }
    for y in y0..=y1 as u32 {
        for x in x0..=x1 as u32 {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let l = [edge(screen[1], screen[2], p), edge(screen[2], screen[0], p), edge(screen[0], screen[1], p)]
                .map(|e| e / area);
            if l.iter().any(|&l| l < 0.0) {
                continue;
            }
            let depth = 1.0 / (l[0] * inverse_depth[0] + l[1] * inverse_depth[1] + l[2] * inverse_depth[2]);
            let i = passes.at(x, y);
            if depth < passes.depth[i] {
                passes.depth[i] = depth;
                passes.normal[i] = normal;
                passes.instance[i] = instance;
                passes.part[i] = part;
            }
        }
    }
}

/// Twice the signed area of the triangle a, b, p.
fn edge(a: Vec2, b: Vec2, p: Vec2) -> f32 {
    (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use marionette_formats::scene::CameraDoc;

    /// The floor's depth at every pixel that sees it is the distance along the view axis
    /// to where the pixel's ray meets the plane; its normal is the world's up.
    #[test]
    fn a_floor_seen_from_above_has_the_ray_plane_depth_and_points_up() {
        let doc = CameraDoc { focus: Vec3::new(0.0, 0.0, 0.0), pitch: -0.5, distance: 3.0, ..CameraDoc::default() };
        let camera = Pinhole::of(&doc, 64, 48).unwrap();
        let floor = [
            Vec3::new(-50.0, 0.0, -50.0),
            Vec3::new(50.0, 0.0, -50.0),
            Vec3::new(50.0, 0.0, 50.0),
            Vec3::new(-50.0, 0.0, 50.0),
        ];
        let triangles = [[0, 2, 1], [0, 3, 2]];
        let passes =
            rasterize(&camera, &[Surface { instance: FLOOR, positions: &floor, triangles: &triangles, parts: &[] }]);
        let to_world = camera.world_to_camera.inverse();
        let eye = to_world.transform_point3(Vec3::ZERO);
        let mut seen = 0;
        for y in 0..48 {
            for x in 0..64 {
                let i = passes.at(x, y);
                let [[f, _, cx], [_, _, cy], _] = camera.k();
                let ray = Vec3::new((x as f32 + 0.5 - cx) / f, (y as f32 + 0.5 - cy) / f, 1.0);
                let world_ray = to_world.transform_vector3(ray);
                if world_ray.y >= 0.0 {
                    assert_eq!(passes.instance[i], NOTHING, "({x}, {y}) looks above the horizon");
                    continue;
                }
                // Where the ray meets y = 0: its depth is the multiple of the unit-z ray.
                let depth = -eye.y / world_ray.y;
                assert!(
                    (passes.depth[i] - depth).abs() < 1e-3 * depth.max(1.0),
                    "({x}, {y}): {} vs {depth}",
                    passes.depth[i]
                );
                let up = to_world.transform_vector3(passes.normal[i]);
                assert!(up.angle_between(Vec3::Y) < 0.5f32.to_radians(), "({x}, {y}): {up}");
                seen += 1;
            }
        }
        assert!(seen > 1000, "{seen}");
    }

    #[test]
    fn the_nearer_of_two_overlapping_triangles_wins() {
        let doc = CameraDoc { focus: Vec3::ZERO, pitch: 0.0, distance: 5.0, ..CameraDoc::default() };
        let camera = Pinhole::of(&doc, 32, 32).unwrap();
        let square = |z: f32| {
            [Vec3::new(-1.0, -1.0, z), Vec3::new(1.0, -1.0, z), Vec3::new(1.0, 1.0, z), Vec3::new(-1.0, 1.0, z)]
        };
        let (near, far) = (square(1.0), square(-1.0));
        let triangles = [[0, 1, 2], [0, 2, 3]];
        let passes = rasterize(
            &camera,
            &[
                Surface { instance: 1, positions: &far, triangles: &triangles, parts: &[3; 4] },
                Surface { instance: 2, positions: &near, triangles: &triangles, parts: &[5; 4] },
            ],
        );
        let centre = passes.at(16, 16);
        assert_eq!((passes.instance[centre], passes.part[centre]), (2, 5));
        assert!((passes.depth[centre] - 4.0).abs() < 1e-5);
        // Facing the camera: its normal points back along -z (OpenCV's frame).
        assert!(passes.normal[centre].abs_diff_eq(Vec3::new(0.0, 0.0, -1.0), 1e-6));
    }
}

//! The maps ControlNet's models read, in their own conventions:
//! - the OpenPose drawing as the annotator draws it (lllyasviel's `draw_bodypose`, which
//!   `controlnet_aux` carries in `open_pose/util.py`): each limb an `cv2.ellipse2Poly`
//!   polygon of half-width 4 filled by `cv2.fillConvexPoly` at 0.6 of its colour, then each
//!   point a filled `cv2.circle` of radius 4, person by person, on black. OpenCV's
//!   integer drawing is reproduced here step for step (its sine table, its rounding, its
//!   scanlines and outline), so the pixels are the annotator's;
//! - its JSON in the 18-point order the OpenPose model was trained on, with the canvas size;
//! - depth as MiDaS-style relative inverse depth over what the picture shows: 1 / depth
//!   normalised to 1–255, the nearest shown point 255, nothing 0;
//! - normals in ControlNet 1.1's Normal convention (its README: "blue is front, red is left,
//!   green is top"): a surface facing the viewer's left is red; nothing faces the viewer.

use image::{GrayImage, Luma, Rgb, RgbImage};
use serde_json::{Value, json};

use super::openpose::{BODY_18, COLOURS, LIMBS};
use super::{Figure, Passes, Pinhole, seen};

/// A person's 18 points in pixels, where the picture shows them.
pub type Body18 = [Option<(f32, f32)>; 18];

/// Each person's 18 points: those in the picture (seen or hidden by something in front).
pub fn bodies(camera: &Pinhole, passes: &Passes, figures: &[Figure]) -> Vec<Body18> {
    let point = |figure: &Figure, name: &str| {
        let (x, y, v) = seen(camera, passes, figure.instance, figure.points.get(name)?);
        (v > 0).then_some((x, y))
    };
    figures.iter().filter(|f| f.is_person()).map(|f| BODY_18.map(|name| point(f, name))).collect()
}

/// The annotator's drawing of `people` on a black canvas of `width` × `height`.
pub fn openpose_drawing(width: u32, height: u32, people: &[Body18]) -> RgbImage {
    let mut canvas = RgbImage::new(width, height);
    for body in people {
        draw_body(&mut canvas, body);
    }
    canvas
}

/// `draw_bodypose` for one person: its limbs, then its points.
fn draw_body(canvas: &mut RgbImage, body: &Body18) {
    const STICK_WIDTH: i32 = 4;
    for (limb, colour) in LIMBS.iter().zip(COLOURS) {
        let (Some((x1, y1)), Some((x2, y2))) = (body[limb[0] - 1], body[limb[1] - 1]) else { continue };
        // The annotator's names: X runs down the picture, Y across it.
        let (xs, ys) = ([f64::from(y1), f64::from(y2)], [f64::from(x1), f64::from(x2)]);
        let (m_x, m_y) = ((xs[0] + xs[1]) / 2.0, (ys[0] + ys[1]) / 2.0);
        let length = ((xs[0] - xs[1]).powi(2) + (ys[0] - ys[1]).powi(2)).sqrt();
        let angle = (xs[0] - xs[1]).atan2(ys[0] - ys[1]).to_degrees();
        let polygon = ellipse_to_poly((m_y as i32, m_x as i32), ((length / 2.0) as i32, STICK_WIDTH), angle as i32);
        fill_convex_poly(canvas, &polygon, colour.map(|c| (f64::from(c) * 0.6) as u8));
    }
    for (point, colour) in body.iter().zip(COLOURS) {
        if let Some((x, y)) = point {
            fill_circle(canvas, (*x as i32, *y as i32), 4, colour);
        }
    }
}

/// OpenCV's `SinTable`: the sine of whole degrees 0..=450, to seven decimals, as floats.
fn sin_table(degrees: i32) -> f32 {
    let exact = f64::from(degrees).to_radians().sin();
    ((exact * 1e7).round() / 1e7) as f32
}

/// `cv::ellipse2Poly(center, axes, angle, 0, 360, 1)`: the ellipse's points a degree apart,
/// rounded to pixels (ties to even), repeats dropped.
fn ellipse_to_poly(center: (i32, i32), axes: (i32, i32), angle: i32) -> Vec<(i32, i32)> {
    let angle = angle.rem_euclid(360);
    let (alpha, beta) = (f64::from(sin_table(450 - angle)), f64::from(sin_table(angle)));
    let mut points: Vec<(i32, i32)> = Vec::new();
    for degree in 0..=360 {
        let x = f64::from(axes.0) * f64::from(sin_table(450 - degree));
        let y = f64::from(axes.1) * f64::from(sin_table(degree));
        let px = f64::from(center.0) + x * alpha - y * beta;
        let py = f64::from(center.1) + x * beta + y * alpha;
        let point = (px.round_ties_even() as i32, py.round_ties_even() as i32);
        if points.last() != Some(&point) {
            points.push(point);
        }
    }
    if points.len() == 1 {
        points = vec![center, center];
    }
    points
}

/// Sets the pixels `x1..=x2` of row `y` (clipped to the canvas).
fn hline(canvas: &mut RgbImage, y: i64, x1: i64, x2: i64, colour: [u8; 3]) {
    let (w, h) = (i64::from(canvas.width()), i64::from(canvas.height()));
    if !(0..h).contains(&y) {
        return;
    }
    for x in x1.max(0)..=x2.min(w - 1) {
        canvas.put_pixel(x as u32, y as u32, Rgb(colour));
    }
}

/// `cv::line` of thickness 1, 8-connected, walked left to right as its `LineIterator`
/// walks it.
fn line8(canvas: &mut RgbImage, mut p1: (i64, i64), mut p2: (i64, i64), colour: [u8; 3]) {
    let (w, h) = (i64::from(canvas.width()), i64::from(canvas.height()));
    let (mut dx, mut dy) = (p2.0 - p1.0, p2.1 - p1.1);
    if dx < 0 {
        (dx, dy) = (-dx, -dy);
        std::mem::swap(&mut p1, &mut p2);
    }
    let (mut delta_x, mut delta_y) = (1, 1);
    if dy < 0 {
        dy = -dy;
        delta_y = -1;
    }
    let vertical = dy > dx;
    if vertical {
        std::mem::swap(&mut dx, &mut dy);
        std::mem::swap(&mut delta_x, &mut delta_y);
    }
    let (mut err, plus_delta, minus_delta) = (dx - (dy + dy), dx + dx, -(dy + dy));
    // Each step moves along the major axis, and along the minor one where `err` went
    // below 0.
    let (mut minus_shift, mut plus_shift, mut minus_step, mut plus_step) = (delta_x, 0, 0, delta_y);
    if vertical {
        std::mem::swap(&mut plus_step, &mut plus_shift);
        std::mem::swap(&mut minus_step, &mut minus_shift);
    }
    let mut p = p1;
    for _ in 0..=dx {
        if (0..w).contains(&p.0) && (0..h).contains(&p.1) {
            canvas.put_pixel(p.0 as u32, p.1 as u32, Rgb(colour));
        }
        let below = err < 0;
        err += minus_delta + if below { plus_delta } else { 0 };
        p.0 += minus_shift + if below { plus_shift } else { 0 };
        p.1 += minus_step + if below { plus_step } else { 0 };
    }
}

/// `cv::fillConvexPoly` with 8-connected edges and no fractional bits: the outline, then
/// each row between the two edges walked down from the topmost point.
fn fill_convex_poly(canvas: &mut RgbImage, v: &[(i32, i32)], colour: [u8; 3]) {
    const SHIFT: u32 = 16;
    const ONE: i64 = 1 << SHIFT;
    let n = v.len();
    if n == 0 {
        return;
    }
    let v: Vec<(i64, i64)> = v.iter().map(|&(x, y)| (i64::from(x), i64::from(y))).collect();
    let (mut xmin, mut xmax, mut ymin, mut ymax, mut imin) = (v[0].0, v[0].0, v[0].1, v[0].1, 0);
    let mut p0 = v[n - 1];
    for (i, &p) in v.iter().enumerate() {
        if p.1 < ymin {
            (ymin, imin) = (p.1, i);
        }
        (ymax, xmax, xmin) = (ymax.max(p.1), xmax.max(p.0), xmin.min(p.0));
        line8(canvas, p0, p, colour);
        p0 = p;
    }
    let (w, h) = (i64::from(canvas.width()), i64::from(canvas.height()));
    if n < 3 || xmax < 0 || ymax < 0 || xmin >= w || ymin >= h {
        return;
    }
    let ymax = ymax.min(h - 1);
    let half = ONE >> 1;
    // Each edge: the index of its lower end, its direction round the polygon, x (16
    // fractional bits), its step a row, the row it ends on.
    let mut edges = [(imin, 1usize, -ONE, 0i64, ymin), (imin, n - 1, -ONE, 0i64, ymin)];
    let mut remaining = n as i64;
    let mut y = ymin;
    loop {
        for edge in &mut edges {
            if y < edge.4 {
                continue;
            }
            let (mut idx0, di) = (edge.0, edge.1);
            let mut idx = (idx0 + di) % n;
            loop {
                remaining -= 1;
                if remaining < 0 {
                    break;
                }
                let ty = v[idx].1;
                if ty > y {
                    let (xs, xe) = (v[idx0].0 << SHIFT, v[idx].0 << SHIFT);
                    *edge = (idx, di, xs, ((xe - xs) * 2 + (ty - y)) / (2 * (ty - y)), ty);
                    break;
                }
                idx0 = idx;
                idx = (idx + di) % n;
            }
        }
        if remaining < 0 {
            break;
        }
        if y >= 0 {
            let (left, right) = if edges[0].2 > edges[1].2 { (1, 0) } else { (0, 1) };
            let (x1, x2) = ((edges[left].2 + half) >> SHIFT, (edges[right].2 + half) >> SHIFT);
            if x2 >= 0 && x1 < w {
                hline(canvas, y, x1, x2, colour);
            }
        }
        edges[0].2 += edges[0].3;
        edges[1].2 += edges[1].3;
        y += 1;
        if y > ymax {
            break;
        }
    }
}

/// `cv::circle(…, thickness = -1)`: OpenCV's midpoint circle, each step's rows filled.
fn fill_circle(canvas: &mut RgbImage, center: (i32, i32), radius: i32, colour: [u8; 3]) {
    let (cx, cy) = (i64::from(center.0), i64::from(center.1));
    let (mut err, mut dx, mut dy, mut plus, mut minus) =
        (0i64, i64::from(radius), 0i64, 1i64, i64::from(radius) * 2 - 1);
    while dx >= dy {
        hline(canvas, cy - dy, cx - dx, cx + dx, colour);
        hline(canvas, cy + dy, cx - dx, cx + dx, colour);
        hline(canvas, cy - dx, cx - dy, cx + dy, colour);
        hline(canvas, cy + dx, cx - dy, cx + dy, colour);
        dy += 1;
        err += plus;
        plus += 2;
        let mask = if err <= 0 { 0 } else { -1 };
        err -= minus & mask;
        dx += mask;
        minus -= mask & 2;
    }
}

/// The OpenPose JSON ControlNet front ends import: each person's 18 points as
/// `pose_keypoints_2d` (x, y, confidence 1; 0, 0, 0 where not in the picture), with the
/// canvas size.
pub fn openpose_json(width: u32, height: u32, people: &[Body18]) -> Value {
    let people: Vec<Value> = people
        .iter()
        .map(|body| {
            let points: Vec<f32> = body.iter().flat_map(|p| p.map_or([0.0, 0.0, 0.0], |(x, y)| [x, y, 1.0])).collect();
            json!({ "pose_keypoints_2d": points })
        })
        .collect();
    json!({ "people": people, "canvas_width": width, "canvas_height": height })
}

/// Relative inverse depth over what the picture shows: 1 / depth normalised to 1–255 (the
/// nearest shown point 255), 0 where nothing is.
pub fn inverse_depth(passes: &Passes) -> GrayImage {
    let inverse: Vec<Option<f32>> = passes.depth.iter().map(|&d| (d.is_finite() && d > 0.0).then(|| 1.0 / d)).collect();
    let shown = inverse.iter().flatten();
    let (lo, hi) = shown.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let span = if hi > lo { hi - lo } else { 1.0 };
    GrayImage::from_fn(passes.width, passes.height, |x, y| {
        let value = inverse[passes.at(x, y)].map_or(0, |v| (1.0 + 254.0 * (v - lo) / span).round() as u8);
        Luma([value])
    })
}

/// Normals in Normal 1.1's convention: red the part toward the viewer's left, green up,
/// blue toward the viewer, as n · 0.5 + 0.5; where nothing is, a surface facing the viewer.
pub fn normal_map(passes: &Passes) -> RgbImage {
    RgbImage::from_fn(passes.width, passes.height, |x, y| {
        let n = passes.normal[passes.at(x, y)];
        // From OpenCV's camera frame (x right, y down, z forward).
        let n = if n == glam::Vec3::ZERO { glam::Vec3::Z } else { glam::Vec3::new(-n.x, -n.y, -n.z) };
        Rgb(n.to_array().map(|c| ((c * 0.5 + 0.5) * 255.0).round() as u8))
    })
}

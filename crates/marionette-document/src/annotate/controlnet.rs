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

use super::canny::Canny;
use super::openpose::{BODY_18, COLOURS, HAND_EDGES, LIMBS};
use super::{Figure, Passes, Pinhole, seen};

/// Which of the maps to write: the OpenPose drawing and JSON, depth and normals always,
/// the picture's canny edges where asked.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ControlNet {
    pub canny: Option<Canny>,
}

/// The maps of one picture, as the files beside it hold them.
pub struct Maps {
    pub openpose: RgbImage,
    pub openpose_json: Value,
    pub depth: GrayImage,
    pub normal: RgbImage,
    /// The edges of the picture `shown`, where asked.
    pub canny: Option<GrayImage>,
}

/// The maps `maps` asks for of a picture whose passes are `passes` (`shown`: the picture,
/// for its edges).
pub fn maps(camera: &Pinhole, passes: &Passes, figures: &[Figure], maps: ControlNet, shown: &RgbImage) -> Maps {
    let people = people(camera, passes, figures);
    let (w, h) = (passes.width, passes.height);
    Maps {
        openpose: openpose_drawing(w, h, &people),
        openpose_json: openpose_json(w, h, &people),
        depth: inverse_depth(passes),
        normal: normal_map(passes),
        canny: maps.canny.map(|canny| super::canny::edges(shown, canny)),
    }
}

/// A person's 18 points in pixels, where the picture shows them.
pub type Body18 = [Option<(f32, f32)>; 18];

/// A hand's 21 points in pixels, (0, 0) where the picture does not show one (as the
/// detector gives them).
pub type Hand21 = [(f32, f32); 21];

/// A person as the annotator draws them: body, left hand, right hand.
#[derive(Debug, Clone, PartialEq)]
pub struct Person {
    pub body: Body18,
    /// Left, then right; none where the rig's fingers are not mapped.
    pub hands: [Option<Hand21>; 2],
}

/// Each person's points: those in the picture (seen or hidden by something in front).
pub fn people(camera: &Pinhole, passes: &Passes, figures: &[Figure]) -> Vec<Person> {
    let point = |figure: &Figure, name: &str| {
        let (x, y, v) = seen(camera, passes, figure.instance, figure.points.get(name)?);
        (v > 0).then_some((x, y))
    };
    let hand = |figure: &Figure, side: &str| {
        let names: [String; 21] = std::array::from_fn(|k| format!("{side}_hand_{k}"));
        let all = names.iter().all(|n| figure.points.contains_key(n));
        all.then(|| names.map(|n| point(figure, &n).unwrap_or((0.0, 0.0))))
    };
    let person =
        |f: &Figure| Person { body: BODY_18.map(|name| point(f, name)), hands: [hand(f, "left"), hand(f, "right")] };
    figures.iter().filter(|f| f.is_person()).map(person).collect()
}

/// The annotator's drawing of `people` (`draw_poses`: each person's body, left hand, right
/// hand) on a black canvas of `width` × `height`.
pub fn openpose_drawing(width: u32, height: u32, people: &[Person]) -> RgbImage {
    let mut canvas = RgbImage::new(width, height);
    for person in people {
        draw_body(&mut canvas, &person.body);
        person.hands.iter().flatten().for_each(|hand| draw_hand(&mut canvas, hand));
    }
    canvas
}

/// `draw_handpose`: each bone a line 2 pixels thick in its colour round the hue circle,
/// then each point a blue filled circle of radius 4; points at the picture's edge (0) are
/// left out.
fn draw_hand(canvas: &mut RgbImage, hand: &Hand21) {
    const EPS: i32 = 0;
    let (w, h) = (canvas.width() as f32, canvas.height() as f32);
    // The annotator works on points divided by the canvas size and multiplies them back.
    let pixel =
        |(x, y): (f32, f32)| ((f64::from(x / w) * f64::from(w)) as i32, (f64::from(y / h) * f64::from(h)) as i32);
    for (k, [a, b]) in HAND_EDGES.iter().enumerate() {
        let ((x1, y1), (x2, y2)) = (pixel(hand[*a]), pixel(hand[*b]));
        if x1 > EPS && y1 > EPS && x2 > EPS && y2 > EPS {
            thick_line2(canvas, (x1, y1), (x2, y2), hue(k as f64 / HAND_EDGES.len() as f64));
        }
    }
    for &point in hand {
        let (x, y) = pixel(point);
        if x > EPS && y > EPS {
            fill_circle(canvas, (x, y), 4, [0, 0, 255]);
        }
    }
}

/// matplotlib's `hsv_to_rgb([h, 1, 1]) * 255` as OpenCV rounds a colour (ties to even).
fn hue(h: f64) -> [u8; 3] {
    let i = (h * 6.0).floor();
    let f = h * 6.0 - i;
    let (q, t) = (1.0 - f, f);
    let rgb = match i as i64 % 6 {
        0 => [1.0, t, 0.0],
        1 => [q, 1.0, 0.0],
        2 => [0.0, 1.0, t],
        3 => [0.0, q, 1.0],
        4 => [t, 0.0, 1.0],
        _ => [1.0, 0.0, q],
    };
    rgb.map(|c: f64| (c * 255.0).round_ties_even().clamp(0.0, 255.0) as u8)
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

/// `cv::fillConvexPoly` of pixel points, 8-connected edges.
fn fill_convex_poly(canvas: &mut RgbImage, v: &[(i32, i32)], colour: [u8; 3]) {
    let v: Vec<(i64, i64)> = v.iter().map(|&(x, y)| (i64::from(x), i64::from(y))).collect();
    fill_convex_poly_fixed(canvas, &v, colour, 0);
}

/// OpenCV's fixed point: 16 fractional bits.
const XY_SHIFT: u32 = 16;
const XY_ONE: i64 = 1 << XY_SHIFT;

/// OpenCV's `FillConvexPoly` (8-connected) of points with `shift` fractional bits: the
/// outline, then each row between the two edges walked down from the topmost point.
fn fill_convex_poly_fixed(canvas: &mut RgbImage, v: &[(i64, i64)], colour: [u8; 3], shift: u32) {
    let n = v.len();
    if n == 0 {
        return;
    }
    let delta = (1i64 << shift) >> 1;
    let up = |p: (i64, i64)| (p.0 << (XY_SHIFT - shift), p.1 << (XY_SHIFT - shift));
    let (mut xmin, mut xmax, mut ymin, mut ymax, mut imin) = (v[0].0, v[0].0, v[0].1, v[0].1, 0);
    let mut p0 = up(v[n - 1]);
    for (i, &p) in v.iter().enumerate() {
        if p.1 < ymin {
            (ymin, imin) = (p.1, i);
        }
        (ymax, xmax, xmin) = (ymax.max(p.1), xmax.max(p.0), xmin.min(p.0));
        let p = up(p);
        if shift == 0 {
            line8(canvas, (p0.0 >> XY_SHIFT, p0.1 >> XY_SHIFT), (p.0 >> XY_SHIFT, p.1 >> XY_SHIFT), colour);
        } else {
            line_fixed(canvas, p0, p, colour);
        }
        p0 = p;
    }
    let (xmin, xmax, ymin, ymax) =
        ((xmin + delta) >> shift, (xmax + delta) >> shift, (ymin + delta) >> shift, (ymax + delta) >> shift);
    let (w, h) = (i64::from(canvas.width()), i64::from(canvas.height()));
    if n < 3 || xmax < 0 || ymax < 0 || xmin >= w || ymin >= h {
        return;
    }
    let ymax = ymax.min(h - 1);
    let half = XY_ONE >> 1;
    // Each edge: the index of its lower end, its direction round the polygon, x (16
    // fractional bits), its step a row, the row it ends on.
    let mut edges = [(imin, 1usize, -XY_ONE, 0i64, ymin), (imin, n - 1, -XY_ONE, 0i64, ymin)];
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
                let ty = (v[idx].1 + delta) >> shift;
                if ty > y {
                    let (xs, xe) = (v[idx0].0 << (XY_SHIFT - shift), v[idx].0 << (XY_SHIFT - shift));
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
            let (x1, x2) = ((edges[left].2 + half) >> XY_SHIFT, (edges[right].2 + half) >> XY_SHIFT);
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

/// OpenCV's `Line2`: a line between fixed-point ends, one pixel a step along its longer
/// axis.
fn line_fixed(canvas: &mut RgbImage, mut p1: (i64, i64), mut p2: (i64, i64), colour: [u8; 3]) {
    let (w, h) = (i64::from(canvas.width()), i64::from(canvas.height()));
    let mut put = |x: i64, y: i64| {
        if (0..w).contains(&x) && (0..h).contains(&y) {
            canvas.put_pixel(x as u32, y as u32, Rgb(colour));
        }
    };
    let (dx, dy) = (p2.0 - p1.0, p2.1 - p1.1);
    let (ax, ay) = (dx.abs(), dy.abs());
    let (x_step, y_step, mut count);
    if ax > ay {
        if dx < 0 {
            std::mem::swap(&mut p1, &mut p2);
        }
        let dy = if dx < 0 { -dy } else { dy };
        (x_step, y_step) = (XY_ONE, (dy << XY_SHIFT) / (ax | 1));
        count = (p2.0 - p1.0) >> XY_SHIFT;
    } else {
        if dy < 0 {
            std::mem::swap(&mut p1, &mut p2);
        }
        let dx = if dy < 0 { -dx } else { dx };
        (x_step, y_step) = ((dx << XY_SHIFT) / (ay | 1), XY_ONE);
        count = (p2.1 - p1.1) >> XY_SHIFT;
    }
    let half = XY_ONE >> 1;
    let (mut x, mut y) = (p1.0 + half, p1.1 + half);
    put((p2.0 + half) >> XY_SHIFT, (p2.1 + half) >> XY_SHIFT);
    if ax > ay {
        x >>= XY_SHIFT;
        while count >= 0 {
            put(x, y >> XY_SHIFT);
            x += 1;
            y += y_step;
            count -= 1;
        }
    } else {
        y >>= XY_SHIFT;
        while count >= 0 {
            put(x >> XY_SHIFT, y);
            x += x_step;
            y += 1;
            count -= 1;
        }
    }
}

/// `cv::line(…, thickness = 2)`: OpenCV's `ThickLine`, a quadrilateral a pixel either side
/// of the line with a round cap of radius 1 at each end.
fn thick_line2(canvas: &mut RgbImage, p0: (i32, i32), p1: (i32, i32), colour: [u8; 3]) {
    let (p0, p1) = (
        (i64::from(p0.0) << XY_SHIFT, i64::from(p0.1) << XY_SHIFT),
        (i64::from(p1.0) << XY_SHIFT, i64::from(p1.1) << XY_SHIFT),
    );
    let inverse = 1.0 / XY_ONE as f64;
    let (dx, dy) = ((p0.0 - p1.0) as f64 * inverse, (p1.1 - p0.1) as f64 * inverse);
    let r = dx * dx + dy * dy;
    let thickness = 2i64 << (XY_SHIFT - 1);
    if r.abs() > f64::EPSILON {
        let r = thickness as f64 / r.sqrt();
        let dp = ((dy * r).round_ties_even() as i64, (dx * r).round_ties_even() as i64);
        let quad = [
            (p0.0 + dp.0, p0.1 + dp.1),
            (p0.0 - dp.0, p0.1 - dp.1),
            (p1.0 - dp.0, p1.1 - dp.1),
            (p1.0 + dp.0, p1.1 + dp.1),
        ];
        fill_convex_poly_fixed(canvas, &quad, colour, XY_SHIFT);
    }
    let radius = ((thickness + (XY_ONE >> 1)) >> XY_SHIFT) as i32;
    for p in [p0, p1] {
        let centre = (((p.0 + (XY_ONE >> 1)) >> XY_SHIFT) as i32, ((p.1 + (XY_ONE >> 1)) >> XY_SHIFT) as i32);
        fill_circle(canvas, centre, radius, colour);
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
/// `pose_keypoints_2d` (x, y, confidence 1; 0, 0, 0 where not in the picture), the hands'
/// 21 as `hand_left_keypoints_2d` and `hand_right_keypoints_2d` (empty without mapped
/// fingers), with the canvas size.
pub fn openpose_json(width: u32, height: u32, people: &[Person]) -> Value {
    let hand = |hand: &Option<Hand21>| -> Vec<f32> {
        let point = |&(x, y): &(f32, f32)| if (x, y) == (0.0, 0.0) { [0.0; 3] } else { [x, y, 1.0] };
        hand.as_ref().map_or_else(Vec::new, |h| h.iter().flat_map(point).collect())
    };
    let people: Vec<Value> = people
        .iter()
        .map(|person| {
            let points: Vec<f32> =
                person.body.iter().flat_map(|p| p.map_or([0.0, 0.0, 0.0], |(x, y)| [x, y, 1.0])).collect();
            json!({
                "pose_keypoints_2d": points,
                "hand_left_keypoints_2d": hand(&person.hands[0]),
                "hand_right_keypoints_2d": hand(&person.hands[1]),
            })
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

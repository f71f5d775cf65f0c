//! OpenPose's outputs: its JSON (BODY_25 and the hands' 21 points) and the skeleton drawing
//! ControlNet's OpenPose models were trained on (18 body points, its colours and limb order,
//! limbs at 60 % of their colour under full-colour points, hands in rainbow lines with blue
//! points), on black.

use image::{Rgb, RgbImage};
use serde_json::{Value, json};

use super::{Figure, Passes, Pinhole, seen};

/// OpenPose's BODY_25 points, in its order (our keypoint names).
pub const BODY_25: [&str; 25] = {
    let mut out = [""; 25];
    let mut k = 0;
    while k < 25 {
        out[k] = marionette_formats::keypoints::BODY_25[k].name();
        k += 1;
    }
    out
};

/// The 18 points ControlNet draws (OpenPose's COCO-18 order).
pub const BODY_18: [&str; 18] = [
    "nose",
    "neck",
    "right_shoulder",
    "right_elbow",
    "right_wrist",
    "left_shoulder",
    "left_elbow",
    "left_wrist",
    "right_hip",
    "right_knee",
    "right_ankle",
    "left_hip",
    "left_knee",
    "left_ankle",
    "right_eye",
    "left_eye",
    "right_ear",
    "left_ear",
];

/// ControlNet's limbs over [`BODY_18`] (numbered from 1), drawn in this order.
pub const LIMBS: [[usize; 2]; 17] = [
    [2, 3],
    [2, 6],
    [3, 4],
    [4, 5],
    [6, 7],
    [7, 8],
    [2, 9],
    [9, 10],
    [10, 11],
    [2, 12],
    [12, 13],
    [13, 14],
    [2, 1],
    [1, 15],
    [15, 17],
    [1, 16],
    [16, 18],
];

/// ControlNet's colours: limb k and point k each take colour k.
pub const COLOURS: [[u8; 3]; 18] = [
    [255, 0, 0],
    [255, 85, 0],
    [255, 170, 0],
    [255, 255, 0],
    [170, 255, 0],
    [85, 255, 0],
    [0, 255, 0],
    [0, 255, 85],
    [0, 255, 170],
    [0, 255, 255],
    [0, 170, 255],
    [0, 85, 255],
    [0, 0, 255],
    [85, 0, 255],
    [170, 0, 255],
    [255, 0, 255],
    [255, 0, 170],
    [255, 0, 85],
];

/// The hand's bones over its 21 points.
pub const HAND_EDGES: [[usize; 2]; 20] = [
    [0, 1],
    [1, 2],
    [2, 3],
    [3, 4],
    [0, 5],
    [5, 6],
    [6, 7],
    [7, 8],
    [0, 9],
    [9, 10],
    [10, 11],
    [11, 12],
    [0, 13],
    [13, 14],
    [14, 15],
    [15, 16],
    [0, 17],
    [17, 18],
    [18, 19],
    [19, 20],
];

/// A point as OpenPose gives it: x, y and a confidence (1 seen, 0.5 hidden, 0 not in the
/// picture: at (0, 0)).
fn openpose_point(camera: &Pinhole, passes: &Passes, figure: &Figure, name: &str) -> [f32; 3] {
    match figure.points.get(name).map(|p| seen(camera, passes, figure.instance, p)) {
        Some((x, y, 2)) => [x, y, 1.0],
        Some((x, y, 1)) => [x, y, 0.5],
        _ => [0.0, 0.0, 0.0],
    }
}

/// The hand's 21 points of `side` (`left`, `right`); none where its fingers are not mapped.
fn hand(camera: &Pinhole, passes: &Passes, figure: &Figure, side: &str) -> Option<Vec<[f32; 3]>> {
    let names: Vec<String> = (0..21).map(|k| format!("{side}_hand_{k}")).collect();
    names
        .iter()
        .all(|n| figure.points.contains_key(n))
        .then(|| names.iter().map(|n| openpose_point(camera, passes, figure, n)).collect())
}

/// OpenPose's JSON: a person for each figure with a humanoid map.
pub fn json(camera: &Pinhole, passes: &Passes, figures: &[Figure]) -> Value {
    let people: Vec<Value> = figures
        .iter()
        .filter(|f| f.is_person())
        .map(|figure| {
            let body: Vec<f32> = BODY_25.iter().flat_map(|n| openpose_point(camera, passes, figure, n)).collect();
            let hand_of = |side| hand(camera, passes, figure, side).map_or_else(Vec::new, |h| h.concat());
            json!({
                "person_id": [figure.instance],
                "character": figure.name,
                "pose_keypoints_2d": body,
                "hand_left_keypoints_2d": hand_of("left"),
                "hand_right_keypoints_2d": hand_of("right"),
                "face_keypoints_2d": [],
            })
        })
        .collect();
    json!({ "version": 1.3, "canvas_width": camera.width, "canvas_height": camera.height, "people": people })
}

/// The OpenPose drawing of the figures' points on black, as ControlNet draws them: each
/// limb whose two points are in the picture an ellipse 4 pixels wide at 60 % of its colour,
/// then each point a disc of radius 4 in its colour; hands after.
pub fn drawing(camera: &Pinhole, passes: &Passes, figures: &[Figure]) -> RgbImage {
    let mut canvas = RgbImage::new(camera.width, camera.height);
    for figure in figures.iter().filter(|f| f.is_person()) {
        let points: Vec<Option<(f32, f32)>> = BODY_18
            .iter()
            .map(|n| {
                let [x, y, c] = openpose_point(camera, passes, figure, n);
                (c > 0.0).then_some((x, y))
            })
            .collect();
        for (limb, colour) in LIMBS.iter().zip(COLOURS) {
            if let (Some(a), Some(b)) = (points[limb[0] - 1], points[limb[1] - 1]) {
                // As ControlNet's `int(float(c) * 0.6)`, in double precision.
                let dim = colour.map(|c| (f64::from(c) * 0.6) as u8);
                fill_ellipse(&mut canvas, a, b, 4.0, Rgb(dim));
            }
        }
        for (point, colour) in points.iter().zip(COLOURS) {
            if let Some(p) = point {
                fill_disc(&mut canvas, *p, 4.0, Rgb(colour));
            }
        }
        for side in ["left", "right"] {
            let Some(hand) = hand(camera, passes, figure, side) else { continue };
            for (k, [a, b]) in HAND_EDGES.iter().enumerate() {
                let (pa, pb) = (hand[*a], hand[*b]);
                if pa[2] > 0.0 && pb[2] > 0.0 {
                    let rgb = marionette_rig::skinning::hsv_to_rgb(k as f32 / HAND_EDGES.len() as f32, 1.0, 1.0);
                    fill_ellipse(&mut canvas, (pa[0], pa[1]), (pb[0], pb[1]), 1.0, Rgb(rgb.map(|c| (c * 255.0) as u8)));
                }
            }
            for p in hand.iter().filter(|p| p[2] > 0.0) {
                fill_disc(&mut canvas, (p[0], p[1]), 2.0, Rgb([0, 0, 255]));
            }
        }
    }
    canvas
}

/// Fills the ellipse whose long axis runs from `a` to `b` and whose half width is `half`.
fn fill_ellipse(canvas: &mut RgbImage, a: (f32, f32), b: (f32, f32), half: f32, colour: Rgb<u8>) {
    let centre = ((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0);
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let long = ((dx * dx + dy * dy).sqrt() / 2.0).max(half);
    let (cos, sin) = if dx == 0.0 && dy == 0.0 { (1.0, 0.0) } else { (dx / (2.0 * long), dy / (2.0 * long)) };
    let reach = long + 1.0;
    fill_where(canvas, centre, reach, colour, |x, y| {
        let (u, v) = (x * cos + y * sin, -x * sin + y * cos);
        (u / long).powi(2) + (v / half).powi(2) <= 1.0
    });
}

fn fill_disc(canvas: &mut RgbImage, centre: (f32, f32), radius: f32, colour: Rgb<u8>) {
    fill_where(canvas, centre, radius + 1.0, colour, |x, y| x * x + y * y <= radius * radius);
}

/// Sets the pixels within `reach` of `centre` whose centre's offset from it passes `inside`.
fn fill_where(
    canvas: &mut RgbImage,
    centre: (f32, f32),
    reach: f32,
    colour: Rgb<u8>,
    inside: impl Fn(f32, f32) -> bool,
) {
    let (w, h) = (canvas.width() as f32, canvas.height() as f32);
    let x0 = (centre.0 - reach).floor().clamp(0.0, w) as u32;
    let x1 = (centre.0 + reach).ceil().clamp(0.0, w) as u32;
    let y0 = (centre.1 - reach).floor().clamp(0.0, h) as u32;
    let y1 = (centre.1 + reach).ceil().clamp(0.0, h) as u32;
    for y in y0..y1 {
        for x in x0..x1 {
            if inside(x as f32 + 0.5 - centre.0, y as f32 + 0.5 - centre.1) {
                canvas.put_pixel(x, y, colour);
            }
        }
    }
}

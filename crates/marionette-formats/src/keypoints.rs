//! A pose detector's 2D keypoints, in the files people have: OpenPose JSON
//! (`people[].pose_keypoints_2d`, 18 points in OpenPose's COCO order or 25 in BODY_25,
//! `hand_left_keypoints_2d`/`hand_right_keypoints_2d` of 21, `canvas_width`/`canvas_height`
//! where given, as ControlNet's annotators and DWPose write it) and COCO keypoints
//! (`annotations[].keypoints`: 17 points, or COCO-WholeBody's 133 as DWPose and RTMPose
//! give them, flat or split into `foot_kpts`, `face_kpts`, `lefthand_kpts` and
//! `righthand_kpts`; the picture's size from `images[]`).
//!
//! Each point is `x, y, c`; a point of confidence (or COCO visibility) 0 is absent, not at
//! (0, 0). OpenPose points all within 0 to 1 with a canvas given are normalised to it (as
//! controlnet_aux writes them) and are scaled by it; a list of OpenPose frames (ComfyUI's
//! `POSE_KEYPOINT`) gives its first, or every frame to a sequence. Every number is checked: an error names the field's path
//! (`people[0].pose_keypoints_2d: 52 numbers, expected 54 or 75`).

use std::path::Path;

use serde_json::Value;

use super::error::FormatError;

/// The body points a detector gives, by name (in alphabetical order; each file's order is
/// its table's).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BodyPoint {
    LeftAnkle,
    LeftBigToe,
    LeftEar,
    LeftElbow,
    LeftEye,
    LeftHeel,
    LeftHip,
    LeftKnee,
    LeftShoulder,
    LeftSmallToe,
    LeftWrist,
    MidHip,
    Neck,
    Nose,
    RightAnkle,
    RightBigToe,
    RightEar,
    RightElbow,
    RightEye,
    RightHeel,
    RightHip,
    RightKnee,
    RightShoulder,
    RightSmallToe,
    RightWrist,
}

use BodyPoint::*;

impl BodyPoint {
    /// Its name as Marionette's data pictures and OpenPose's drawing call it (`left_big_toe`,
    /// `mid_hip`).
    pub const fn name(self) -> &'static str {
        match self {
            LeftAnkle => "left_ankle",
            LeftBigToe => "left_big_toe",
            LeftEar => "left_ear",
            LeftElbow => "left_elbow",
            LeftEye => "left_eye",
            LeftHeel => "left_heel",
            LeftHip => "left_hip",
            LeftKnee => "left_knee",
            LeftShoulder => "left_shoulder",
            LeftSmallToe => "left_small_toe",
            LeftWrist => "left_wrist",
            MidHip => "mid_hip",
            Neck => "neck",
            Nose => "nose",
            RightAnkle => "right_ankle",
            RightBigToe => "right_big_toe",
            RightEar => "right_ear",
            RightElbow => "right_elbow",
            RightEye => "right_eye",
            RightHeel => "right_heel",
            RightHip => "right_hip",
            RightKnee => "right_knee",
            RightShoulder => "right_shoulder",
            RightSmallToe => "right_small_toe",
            RightWrist => "right_wrist",
        }
    }
}

/// OpenPose's BODY_25.
pub const BODY_25: [BodyPoint; 25] = [
    Nose,
    Neck,
    RightShoulder,
    RightElbow,
    RightWrist,
    LeftShoulder,
    LeftElbow,
    LeftWrist,
    MidHip,
    RightHip,
    RightKnee,
    RightAnkle,
    LeftHip,
    LeftKnee,
    LeftAnkle,
    RightEye,
    LeftEye,
    RightEar,
    LeftEar,
    LeftBigToe,
    LeftSmallToe,
    LeftHeel,
    RightBigToe,
    RightSmallToe,
    RightHeel,
];

/// OpenPose's 18 points (its COCO model, ControlNet's drawing): BODY_25's without the
/// middle of the hips and the feet.
pub const OPENPOSE_18: [BodyPoint; 18] = {
    let mut out = [Nose; 18];
    let mut k = 0;
    while k < 18 {
        // BODY_25 puts MidHip at 8; the 18 skip it.
        out[k] = BODY_25[if k < 8 { k } else { k + 1 }];
        k += 1;
    }
    out
};

/// COCO's 17 keypoints (the first 17 of COCO-WholeBody's 133).
pub const COCO_17: [BodyPoint; 17] = [
    Nose,
    LeftEye,
    RightEye,
    LeftEar,
    RightEar,
    LeftShoulder,
    RightShoulder,
    LeftElbow,
    RightElbow,
    LeftWrist,
    RightWrist,
    LeftHip,
    RightHip,
    LeftKnee,
    RightKnee,
    LeftAnkle,
    RightAnkle,
];

/// COCO-WholeBody's 6 foot points (points 17–22 of its 133).
pub const WHOLEBODY_FEET: [BodyPoint; 6] = [LeftBigToe, LeftSmallToe, LeftHeel, RightBigToe, RightSmallToe, RightHeel];

/// Points of a hand (OpenPose's and COCO-WholeBody's order: the wrist, then four a finger
/// from the thumb to the little finger, each from the palm out).
pub const HAND_POINTS: usize = 21;

/// Points of a face in COCO-WholeBody (points 23–90 of its 133).
const WHOLEBODY_FACE: usize = 68;

/// A point seen in the picture: pixels from its top left, and the detector's confidence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point2d {
    pub x: f32,
    pub y: f32,
    pub confidence: f32,
}

/// One person's points: the body's by name, each hand's 21 (empty where the file has none).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Person2d {
    pub body: Vec<(BodyPoint, Point2d)>,
    pub left_hand: Vec<Option<Point2d>>,
    pub right_hand: Vec<Option<Point2d>>,
}

impl Person2d {
    /// The point of that name, where the file gives it.
    pub fn point(&self, name: BodyPoint) -> Option<Point2d> {
        self.body.iter().find(|(n, _)| *n == name).map(|&(_, p)| p)
    }

    /// Every point given: the body's, then the hands'.
    pub fn points(&self) -> impl Iterator<Item = &Point2d> {
        self.body.iter().map(|(_, p)| p).chain(self.left_hand.iter().chain(&self.right_hand).flatten())
    }

    /// Every point's x times `w` and y times `h`.
    fn scale(&mut self, w: f32, h: f32) {
        let hands = self.left_hand.iter_mut().chain(&mut self.right_hand).flatten();
        for p in self.body.iter_mut().map(|(_, p)| p).chain(hands) {
            (p.x, p.y) = (p.x * w, p.y * h);
        }
    }

    /// The area of the box around every point given (pixels²).
    pub fn area(&self) -> f32 {
        let (lo, hi) = self.points().fold(([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]), |(lo, hi), p| {
            ([lo[0].min(p.x), lo[1].min(p.y)], [hi[0].max(p.x), hi[1].max(p.y)])
        });
        ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(0.0)
    }
}

/// A keypoint file: the picture's size where it says, and its people.
#[derive(Debug, Clone, PartialEq)]
pub struct Keypoints {
    pub size: Option<(f32, f32)>,
    pub people: Vec<Person2d>,
}

impl Keypoints {
    /// Person `n` (from 0), or the largest (by the box around its points) without one.
    pub fn person(&self, n: Option<usize>) -> Result<&Person2d, String> {
        match n {
            Some(n) => self.people.get(n).ok_or_else(|| {
                format!(
                    "--person {n}: the file has {} {} (0 to {})",
                    self.people.len(),
                    if self.people.len() == 1 { "person" } else { "people" },
                    self.people.len() - 1
                )
            }),
            None => Ok(self.people.iter().max_by(|a, b| a.area().total_cmp(&b.area())).expect("a file has people")),
        }
    }
}

/// Reads a keypoint file (OpenPose JSON or COCO keypoints; see the module).
pub fn read_keypoints(path: &Path) -> Result<Keypoints, FormatError> {
    let text = super::error::read_text(super::error::open(path)?, path)?;
    parse_keypoints(&text, path)
}

/// Reads a keypoint file's frames: each of a list of OpenPose frames (ComfyUI's
/// `POSE_KEYPOINT` of a video), or the file's one.
pub fn read_keypoint_frames(path: &Path) -> Result<Vec<Keypoints>, FormatError> {
    let text = super::error::read_text(super::error::open(path)?, path)?;
    parse_keypoint_frames(&text, path)
}

/// Parses the text of a keypoint file read from `path` (of a list of frames, the first).
pub fn parse_keypoints(text: &str, path: &Path) -> Result<Keypoints, FormatError> {
    Ok(parse_keypoint_frames(text, path)?.swap_remove(0))
}

/// Parses the frames of a keypoint file read from `path` (see [`read_keypoint_frames`]).
pub fn parse_keypoint_frames(text: &str, path: &Path) -> Result<Vec<Keypoints>, FormatError> {
    let json: Value = serde_json::from_str(text)
        .map_err(|e| FormatError::syntax(path, e.line().max(1), format!("expected JSON: {e}")))?;
    let fail = |message: String| FormatError::other(path, message);
    match json {
        Value::Array(frames) if !frames.is_empty() && frames.iter().all(|f| f.get("people").is_some()) => frames
            .iter()
            .enumerate()
            .map(|(k, frame)| keypoints_of(frame).map_err(|m| fail(format!("[{k}].{m}"))))
            .collect(),
        Value::Array(_) => Err(fail("expected a list of OpenPose frames (each with `people`)".into())),
        json => Ok(vec![keypoints_of(&json).map_err(fail)?]),
    }
}

/// One frame's keypoints: OpenPose's or COCO's, with at least one person.
fn keypoints_of(json: &Value) -> Result<Keypoints, String> {
    let keypoints = if json.get("people").is_some() {
        openpose(json)
    } else if json.get("annotations").is_some() {
        coco(json)
    } else {
        Err("expected OpenPose's `people` or COCO's `annotations`, found neither".to_string())
    }?;
    if keypoints.people.is_empty() {
        return Err("people: expected at least one person, found none".into());
    }
    Ok(keypoints)
}

/// OpenPose's JSON.
fn openpose(json: &Value) -> Result<Keypoints, String> {
    let size = match (json.get("canvas_width"), json.get("canvas_height")) {
        (Some(w), Some(h)) => Some((side(w, "canvas_width")?, side(h, "canvas_height")?)),
        _ => None,
    };
    let people = json["people"].as_array().ok_or("people: expected a list")?;
    let mut out = Vec::new();
    for (k, person) in people.iter().enumerate() {
        let at = |field: &str| format!("people[{k}].{field}");
        let body = numbers(&person["pose_keypoints_2d"], &at("pose_keypoints_2d"))?;
        let names: &[BodyPoint] = match body.len() {
            54 => &OPENPOSE_18,
            75 => &BODY_25,
            n => return Err(format!("{}: {n} numbers, expected 54 or 75", at("pose_keypoints_2d"))),
        };
        let hand = |field: &str| -> Result<Vec<Option<Point2d>>, String> {
            match person.get(field) {
                None | Some(Value::Null) => Ok(Vec::new()),
                Some(v) => match numbers(v, &at(field))? {
                    h if h.is_empty() => Ok(Vec::new()),
                    h if h.len() == 3 * HAND_POINTS => Ok(points(&h)),
                    h => Err(format!("{}: {} numbers, expected {}", at(field), h.len(), 3 * HAND_POINTS)),
                },
            }
        };
        let (left_hand, right_hand) = (hand("hand_left_keypoints_2d")?, hand("hand_right_keypoints_2d")?);
        out.push(person_of(names, &points(&body), left_hand, right_hand, &format!("people[{k}]"))?);
    }
    if let Some((w, h)) = size
        && w > 2.0
        && h > 2.0
        && out.iter().all(|p| p.points().all(|q| (0.0..=1.0).contains(&q.x) && (0.0..=1.0).contains(&q.y)))
    {
        // Normalised to the canvas (as controlnet_aux and some ComfyUI nodes write it).
        for p in &mut out {
            p.scale(w, h);
        }
    }
    Ok(Keypoints { size, people: out })
}

/// COCO keypoints: 17 a person, or COCO-WholeBody's 133 (flat, or its parts apart).
fn coco(json: &Value) -> Result<Keypoints, String> {
    let annotations = json["annotations"].as_array().ok_or("annotations: expected a list")?;
    let images = json.get("images").and_then(Value::as_array);
    let mut size = None;
    let mut out = Vec::new();
    for (k, a) in annotations.iter().enumerate() {
        let at = |field: &str| format!("annotations[{k}].{field}");
        let mut all = numbers(&a["keypoints"], &at("keypoints"))?;
        for (field, count) in
            [("foot_kpts", 6), ("face_kpts", WHOLEBODY_FACE), ("lefthand_kpts", 21), ("righthand_kpts", 21)]
        {
            let Some(part) = a.get(field) else { continue };
            let part = numbers(part, &at(field))?;
            if part.len() != 3 * count {
                return Err(format!("{}: {} numbers, expected {}", at(field), part.len(), 3 * count));
            }
            all.extend(part);
        }
        if all.len() != 51 && all.len() != 399 {
            return Err(format!("{}: {} numbers, expected 51 (17 points) or 399 (133)", at("keypoints"), all.len()));
        }
        let points = points(&all);
        let hands =
            |from: usize| if points.len() == 133 { points[from..from + HAND_POINTS].to_vec() } else { Vec::new() };
        let mut names = COCO_17.to_vec();
        if points.len() == 133 {
            names.extend(WHOLEBODY_FEET);
        }
        let person = person_of(&names, &points, hands(91), hands(112), &format!("annotations[{k}]"))?;
        if size.is_none()
            && let Some(image) = images.and_then(|i| i.iter().find(|i| i.get("id") == a.get("image_id")))
        {
            size = Some((side(&image["width"], "images[].width")?, side(&image["height"], "images[].height")?));
        }
        out.push(person);
    }
    Ok(Keypoints { size, people: out })
}

/// A picture's side: a positive, finite number.
fn side(v: &Value, field: &str) -> Result<f32, String> {
    match v.as_f64() {
        Some(s) if s > 0.0 && s.is_finite() && s < 1e6 => Ok(s as f32),
        _ => Err(format!("{field}: expected a positive size in pixels, found {v}")),
    }
}

/// A list of finite numbers.
fn numbers(v: &Value, field: &str) -> Result<Vec<f32>, String> {
    let list = v.as_array().ok_or_else(|| format!("{field}: expected a list of numbers, found {v}"))?;
    list.iter()
        .enumerate()
        .map(|(i, x)| match x.as_f64() {
            Some(n) if n.is_finite() && n.abs() < 1e9 => Ok(n as f32),
            _ => Err(format!("{field}[{i}]: expected a finite number, found {x}")),
        })
        .collect()
}

/// `x, y, c` triples as points, those of confidence 0 (or less) absent.
fn points(values: &[f32]) -> Vec<Option<Point2d>> {
    values.chunks_exact(3).map(|p| (p[2] > 0.0).then_some(Point2d { x: p[0], y: p[1], confidence: p[2] })).collect()
}

/// A person of the points `names` name (the first of `points`), refused where every point
/// is absent.
fn person_of(
    names: &[BodyPoint],
    points: &[Option<Point2d>],
    left_hand: Vec<Option<Point2d>>,
    right_hand: Vec<Option<Point2d>>,
    at: &str,
) -> Result<Person2d, String> {
    let body: Vec<(BodyPoint, Point2d)> =
        names.iter().zip(points).filter_map(|(&name, p)| p.map(|p| (name, p))).collect();
    if body.is_empty() && left_hand.iter().chain(&right_hand).all(Option::is_none) {
        return Err(format!("{at}: every point absent (confidence 0)"));
    }
    Ok(Person2d { body, left_hand, right_hand })
}

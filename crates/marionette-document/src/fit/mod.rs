//! Pose from a photo: a humanoid fitted to a pose detector's 2D keypoints.
//!
//! The fit finds the body pose (each aimed bone's direction in the character's facing
//! frame and where the face looks: [`marionette_rig::body_poses::aim_body`], so bones keep
//! their lengths and joints their limits) and the camera (yaw, pitch, where it stands, and
//! its field of view unless given) that put the character's keypoints, as the data pictures
//! define them ([`crate::annotate::keypoints`]), on the file's points. Its prior has the
//! built-in body poses, each also mirrored, and the rest pose as modes: every mode is tried
//! as a start (the camera placed for it), the best few are refined by Levenberg–Marquardt on
//! the pixel errors plus a pull toward their mode, and the lowest cost wins; a knee bent
//! forward costs as much as a large miss. Fingers then follow the hand points where the rig
//! has mapped fingers. The character is stood on the floor and the camera moved with it.

mod sequence;
mod solve;

pub use sequence::{FittedClip, SequenceSpec, fit_sequence, frame_files};

use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec2, Vec3};
use marionette_formats::keypoints::{HAND_POINTS, Keypoints, Person2d};
use marionette_formats::stage::CameraDoc;
use marionette_rig::body_poses::{AIMED, POSES, aim_body, aim_end, aim_start, facing_frame};
use marionette_rig::fk::forward_kinematics;
use marionette_rig::humanoid::{HumanBone, HumanoidMap};
use marionette_rig::ik::turn_joint;
use marionette_rig::{CharacterAsset, JointRotation, Skeleton};

use crate::annotate::camera::Pinhole;

/// What `--fit` is given: the keypoint file, the person in it, the field of view.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FitSpec {
    pub file: PathBuf,
    /// `--person N` (from 0); none: the largest.
    pub person: Option<usize>,
    /// `--fov DEG`: the camera's vertical field of view; none: estimated.
    pub fov: Option<f32>,
}

/// A fitted pose and camera.
#[derive(Debug, Clone)]
pub struct Fitted {
    pub pose: Vec<JointRotation>,
    /// The placement the fit was made at (the character's own).
    pub placement: Mat4,
    pub camera: CameraDoc,
    /// The picture's size (pixels) the camera sees.
    pub size: (u32, u32),
    /// Mean distance (pixels) from each body point to where the fitted character puts it.
    pub error: f32,
    /// The body points fitted.
    pub points: usize,
    /// The finger points fitted (none where the file has no hands or the rig no fingers).
    pub finger_points: usize,
    /// The prior's mode the fit came from (`walk`, `sit-chair (mirrored)`, `rest`).
    pub mode: String,
}

impl Fitted {
    /// The camera as a pinhole over the picture.
    pub fn pinhole(&self) -> Pinhole {
        Pinhole::of(&self.camera, self.size.0, self.size.1).expect("a fitted camera has a perspective")
    }

    /// What the fit did, for the notes.
    pub fn describe(&self) -> String {
        let fingers = match self.finger_points {
            0 => String::new(),
            n => format!(", fingers from {n} hand points"),
        };
        format!(
            "fitted to {} points: {:.1} px mean error at {}×{} (from {}, field of view {:.0}°{fingers})",
            self.points, self.error, self.size.0, self.size.1, self.mode, self.camera.fov
        )
    }
}

/// Why a fit cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    #[error(transparent)]
    Format(#[from] marionette_formats::FormatError),
    #[error("{file}: {message}")]
    File { file: String, message: String },
    #[error("--fit: the character has no humanoid map (hips, two legs, two arms)")]
    NoHumanoid,
    #[error("{file}: person {person} has {found} body points the character has, expected at least 6")]
    TooFewPoints { file: String, person: usize, found: usize },
}

/// Where a keypoint sits on the character: a point fixed in a joint's frame, or midway
/// between two other keypoints.
#[derive(Debug, Clone, Copy)]
enum Anchor {
    Fixed { joint: usize, local: Vec3 },
    Between(usize, usize),
}

/// A character as the fit sees it: its skeleton, humanoid map, placement, facing frame and
/// keypoints.
pub struct Body<'a> {
    skeleton: &'a Skeleton,
    map: &'a HumanoidMap,
    placement: Mat4,
    frame: Quat,
    names: Vec<String>,
    anchors: Vec<Anchor>,
}

impl<'a> Body<'a> {
    /// The character `asset` (an SMPL body when `smpl`: its face and feet from the mesh's
    /// landmarks) at `placement`; none without hips and legs in `map`.
    pub fn new(asset: &'a CharacterAsset, map: &'a HumanoidMap, placement: Mat4, smpl: bool) -> Option<Self> {
        let skeleton = &asset.skeleton;
        let frame = facing_frame(skeleton, map)?;
        let rest = skeleton.initial_pose();
        let mut world = vec![Mat4::IDENTITY; skeleton.len()];
        forward_kinematics(skeleton, &rest, Mat4::IDENTITY, &mut world);
        let joint_world: Vec<Vec3> = world.iter().map(|m| m.w_axis.truncate()).collect();
        let positions = if smpl { crate::posing::posed_positions(asset, &rest, Mat4::IDENTITY) } else { Vec::new() };
        let parts = crate::annotate::joint_parts(skeleton, Some(map));
        let points = crate::annotate::keypoints(skeleton, map, &joint_world, &parts, &positions, smpl);
        let mapped: Vec<usize> = map.values().copied().collect();
        let mut names = Vec::new();
        let mut anchors = Vec::new();
        for (name, point) in &points {
            if name == "neck" || name == "mid_hip" {
                continue;
            }
            // The joint at the point (a mapped one first), else the nearest.
            let key = |j: &usize| {
                let d = joint_world[*j].distance(point.at);
                (d > 1e-5, !mapped.contains(j), d)
            };
            let Some(joint) = (0..skeleton.len()).min_by(|a, b| key(a).partial_cmp(&key(b)).expect("finite")) else {
                continue;
            };
            names.push(name.clone());
            anchors.push(Anchor::Fixed { joint, local: world[joint].inverse().transform_point3(point.at) });
        }
        for (name, a, b) in [("neck", "left_shoulder", "right_shoulder"), ("mid_hip", "left_hip", "right_hip")] {
            let at = |n: &str| names.iter().position(|m| m == n);
            if let (Some(a), Some(b)) = (at(a), at(b)) {
                names.push(name.to_string());
                anchors.push(Anchor::Between(a, b));
            }
        }
        Some(Self { skeleton, map, placement, frame, names, anchors })
    }

    /// The keypoints' world positions at `pose`.
    fn points(&self, pose: &[JointRotation], world: &mut [Mat4]) -> Vec<Vec3> {
        forward_kinematics(self.skeleton, pose, self.placement, world);
        let mut out = vec![Vec3::ZERO; self.anchors.len()];
        for (k, anchor) in self.anchors.iter().enumerate() {
            out[k] = match *anchor {
                Anchor::Fixed { joint, local } => world[joint].transform_point3(local),
                Anchor::Between(a, b) => (out[a] + out[b]) / 2.0,
            };
        }
        out
    }

    /// The pose of these bone directions and look.
    fn posed(&self, body: &BodyState) -> Vec<JointRotation> {
        let mut pose = self.skeleton.initial_pose();
        let directions: Vec<(HumanBone, Vec3)> = AIMED.iter().map(|(b, _)| *b).zip(body.directions).collect();
        aim_body(self.skeleton, self.map, &mut pose, &directions, body.look);
        pose
    }

    /// The rest pose's bone directions in the facing frame.
    fn rest_directions(&self) -> [Vec3; 11] {
        let mut world = vec![Mat4::IDENTITY; self.skeleton.len()];
        forward_kinematics(self.skeleton, &self.skeleton.initial_pose(), Mat4::IDENTITY, &mut world);
        std::array::from_fn(|k| {
            let bone = AIMED[k].0;
            match (aim_start(self.map, bone), aim_end(self.map, bone)) {
                (Some(a), Some(b)) => {
                    let d = world[b].w_axis.truncate() - world[a].w_axis.truncate();
                    (self.frame.inverse() * d).normalize_or(Vec3::from(AIMED[k].1).normalize())
                }
                _ => Vec3::from(AIMED[k].1).normalize(),
            }
        })
    }
}

/// A body pose as the fit moves it: the aimed bones' directions (facing frame) and the look.
#[derive(Debug, Clone, Copy, PartialEq)]
struct BodyState {
    directions: [Vec3; 11],
    look: Option<Vec3>,
}

/// A prior's mode: a built-in pose (mirrored or not) or the rest pose.
struct Mode {
    name: String,
    body: BodyState,
}

/// The modes: every built-in pose, its mirror where it differs, and the rest pose.
fn modes(body: &Body) -> Vec<Mode> {
    let mut out: Vec<Mode> = Vec::new();
    for pose in &POSES {
        for mirrored in [false, true] {
            let directions: Vec<Vec3> = pose.directions(mirrored).into_iter().map(|(_, d)| d).collect();
            let state =
                BodyState { directions: directions.try_into().expect("11 aimed bones"), look: pose.look(mirrored) };
            if out.iter().any(|m| m.body == state) {
                continue;
            }
            let name = if mirrored { format!("{} (mirrored)", pose.name) } else { pose.name.to_string() };
            out.push(Mode { name, body: state });
        }
    }
    out.push(Mode { name: "rest".into(), body: BodyState { directions: body.rest_directions(), look: None } });
    out
}

/// One observed point: its keypoint's index on the body, where the file puts it, its weight.
#[derive(Debug, Clone, Copy)]
struct Seen {
    anchor: usize,
    at: Vec2,
    weight: f32,
}

/// The person's body points the character has.
fn seen_points(body: &Body, person: &Person2d) -> Vec<Seen> {
    person
        .body
        .iter()
        .filter_map(|(name, p)| {
            let anchor = body.names.iter().position(|n| n == name.name())?;
            Some(Seen { anchor, at: Vec2::new(p.x, p.y), weight: p.confidence.clamp(0.05, 1.0) })
        })
        .collect()
}

/// The picture's size: the file's, else the points' farthest x and y and a tenth more.
pub fn picture_size(keypoints: &Keypoints, person: &Person2d) -> (u32, u32) {
    if let Some((w, h)) = keypoints.size {
        return (w.round().max(1.0) as u32, h.round().max(1.0) as u32);
    }
    let (mut w, mut h) = (1.0f32, 1.0f32);
    for (_, p) in &person.body {
        (w, h) = (w.max(p.x), h.max(p.y));
    }
    ((w * 1.1).ceil() as u32, (h * 1.1).ceil() as u32)
}

/// The picture size a keypoint file gives for its person `person` (see [`fit`]); none
/// where it cannot be read (the fit says why).
pub fn file_picture_size(file: &Path, person: Option<usize>) -> Option<(u32, u32)> {
    let keypoints = marionette_formats::keypoints::read_keypoints(file).ok()?;
    let person = keypoints.person(person).ok()?;
    Some(picture_size(&keypoints, person))
}

/// Fits `asset` (its humanoid map `map`, at `placement`) to person `spec.person` of the
/// keypoint file `keypoints` (read from `file`).
pub fn fit(
    asset: &CharacterAsset,
    map: &HumanoidMap,
    placement: Mat4,
    smpl: bool,
    keypoints: &Keypoints,
    spec: &FitSpec,
) -> Result<Fitted, FitError> {
    let file = spec.file.display().to_string();
    let person = keypoints.person(spec.person).map_err(|message| FitError::File { file: file.clone(), message })?;
    let body = Body::new(asset, map, placement, smpl).ok_or(FitError::NoHumanoid)?;
    let seen = seen_points(&body, person);
    if seen.len() < 6 {
        let index = spec.person.unwrap_or_else(|| keypoints.people.iter().position(|p| p == person).unwrap_or(0));
        return Err(FitError::TooFewPoints { file, person: index, found: seen.len() });
    }
    let size = picture_size(keypoints, person);
    let problem = solve::Problem::new(&body, &seen, size, spec.fov);
    let best = problem.best(&modes(&body));
    let mut pose = body.posed(&best.state.body);
    let finger_points = fit_fingers(&body, &mut pose, &best.camera(), size, person);
    Ok(Fitted {
        pose,
        placement,
        camera: best.camera(),
        size,
        error: best.error,
        points: seen.len(),
        finger_points,
        mode: best.mode.clone(),
    })
}

/// Whether a character of this source is an SMPL body (its keypoints' face and feet from
/// the mesh).
pub fn is_smpl(source: &marionette_formats::scene::SourceDoc) -> bool {
    matches!(source, marionette_formats::scene::SourceDoc::File(dir) if marionette_formats::smpl::is_smpl_dir(dir))
}

/// Reads the keypoint file and fits (see [`fit`]).
pub fn fit_file(
    asset: &CharacterAsset,
    map: &HumanoidMap,
    placement: Mat4,
    smpl: bool,
    spec: &FitSpec,
) -> Result<Fitted, FitError> {
    let keypoints = marionette_formats::keypoints::read_keypoints(&spec.file)?;
    fit(asset, map, placement, smpl, &keypoints, spec)
}

/// The picture a keypoint file was made from, where it lies beside it: COCO's first
/// `images[].file_name`, else the file's name without `.json` and then without
/// `_keypoints` (OpenPose's naming) or `.openpose` / `.cn-openpose` (the files `render
/// --data` and `--controlnet` write beside a picture), as PNG or JPEG.
pub fn picture_beside(file: &Path) -> Option<PathBuf> {
    let folder = file.parent()?;
    let named = std::fs::read_to_string(file)
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .and_then(|json| json["images"][0]["file_name"].as_str().map(|name| folder.join(name)))
        .filter(|p| p.is_file());
    if named.is_some() {
        return named;
    }
    let stem = file.file_stem()?.to_string_lossy();
    let stem = ["_keypoints", ".cn-openpose", ".openpose"].iter().find_map(|s| stem.strip_suffix(s)).unwrap_or(&stem);
    ["png", "jpg", "jpeg", "PNG", "JPG"].iter().map(|ext| folder.join(format!("{stem}.{ext}"))).find(|p| p.is_file())
}

/// Turns each mapped finger's bones, from the palm out, so that each bone's end lands on its
/// hand point as the camera sees it (its depth making up its length, toward the camera or
/// away as it was); returns the points used.
fn fit_fingers(
    body: &Body,
    pose: &mut [JointRotation],
    camera: &CameraDoc,
    size: (u32, u32),
    person: &Person2d,
) -> usize {
    let pinhole = Pinhole::of(camera, size.0, size.1).expect("a perspective camera");
    let skeleton = body.skeleton;
    let mut world = vec![Mat4::IDENTITY; skeleton.len()];
    let mut used = 0;
    for (left, hand) in [(true, &person.left_hand), (false, &person.right_hand)] {
        if hand.len() != HAND_POINTS {
            continue;
        }
        for finger in 0..5 {
            let joints: Vec<Option<usize>> =
                (0..3).map(|p| body.map.get(&HumanBone::finger(left, finger, p)).copied()).collect();
            let [Some(a), Some(b), Some(c)] = joints[..] else { continue };
            let tip_name = format!("{}_hand_{}", if left { "left" } else { "right" }, 4 * finger + 4);
            for (p, (from, to)) in [(a, Some(b)), (b, Some(c)), (c, None)].into_iter().enumerate() {
                let Some(p1) = hand[2 + 4 * finger + p] else { continue };
                forward_kinematics(skeleton, pose, body.placement, &mut world);
                let start = world[from].w_axis.truncate();
                let end = match to {
                    Some(to) => world[to].w_axis.truncate(),
                    None => match body.names.iter().position(|n| *n == tip_name).map(|k| body.anchors[k]) {
                        Some(Anchor::Fixed { joint, local }) => world[joint].transform_point3(local),
                        _ => continue,
                    },
                };
                // From where the bone starts now (the bones before put it on its point).
                let Some((x0, y0, _)) = pinhole.project(start) else { continue };
                let Some(wanted) = direction_seen_along(&pinhole, start, end, Vec2::new(p1.x - x0, p1.y - y0)) else {
                    continue;
                };
                let wanted = wanted.normalize();
                let now = (end - start).normalize_or_zero();
                if now == Vec3::ZERO {
                    continue;
                }
                let parent = skeleton.parent(from).map_or(body.placement, |q| world[q]);
                turn_joint(skeleton, pose, from, parent, Quat::from_rotation_arc(now, wanted));
                used += 1;
            }
        }
    }
    used
}

/// The direction from `start` of a bone as long as `end - start` that the camera sees as
/// the picture's segment `along` (pixels) from `start`: in the plane of the view ray and the
/// picture's direction, its depth making up the length the picture does not show, toward
/// the camera or away as the bone is now.
fn direction_seen_along(pinhole: &Pinhole, start: Vec3, end: Vec3, along: Vec2) -> Option<Vec3> {
    if along.length() < 1e-3 {
        return None;
    }
    let to_world = pinhole.world_to_camera.inverse();
    let c = pinhole.to_camera(start);
    if c.z <= 0.0 {
        return None;
    }
    // The camera-frame directions: across the picture along `along` (at the point's depth),
    // and along the ray.
    let across = to_world.transform_vector3(Vec3::new(along.x, along.y, 0.0).normalize()).normalize();
    let ray = to_world.transform_vector3(c.normalize()).normalize();
    let across = (across - ray * across.dot(ray)).normalize();
    let length = end.distance(start);
    let seen = along.length() * c.z / pinhole.focal;
    if seen >= length {
        return Some(across * length);
    }
    let away = if (end - start).dot(ray) >= 0.0 { 1.0 } else { -1.0 };
    Some(across * seen + ray * away * (length * length - seen * seen).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The picture beside a keypoint file: COCO's file name, else the file's own name less
    /// what OpenPose and `render` add to it.
    #[test]
    fn the_picture_beside_a_keypoint_file_is_found() {
        let dir = std::env::temp_dir().join(format!("marionette-beside-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for name in ["shot.png", "photo.jpg", "frame_000001.png"] {
            std::fs::write(dir.join(name), b"").unwrap();
        }
        let file = |name: &str, text: &str| {
            std::fs::write(dir.join(name), text).unwrap();
            picture_beside(&dir.join(name)).map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        };
        assert_eq!(file("shot.openpose.json", "{}"), Some("shot.png".into()));
        assert_eq!(file("shot.cn-openpose.json", "{}"), Some("shot.png".into()));
        assert_eq!(file("frame_000001_keypoints.json", "{}"), Some("frame_000001.png".into()));
        assert_eq!(file("coco.json", r#"{"images": [{"file_name": "photo.jpg"}]}"#), Some("photo.jpg".into()));
        assert_eq!(file("alone.json", "{}"), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The chosen bone, from its start, ends where the picture's segment does.
    #[test]
    fn a_direction_seen_along_projects_along_it() {
        let camera =
            CameraDoc { focus: Vec3::new(0.0, 1.0, 0.0), yaw: 0.3, pitch: -0.2, distance: 3.0, ..Default::default() };
        let pinhole = Pinhole::of(&camera, 640, 480).unwrap();
        let start = Vec3::new(0.1, 1.2, 0.2);
        for along in [Vec2::new(10.0, 0.0), Vec2::new(-3.0, 8.0), Vec2::new(0.0, -12.0)] {
            let d = direction_seen_along(&pinhole, start, start + Vec3::new(0.0, 0.1, 0.05), along).unwrap();
            let (x0, y0, _) = pinhole.project(start).unwrap();
            let (x1, y1, _) = pinhole.project(start + d).unwrap();
            let seen = Vec2::new(x1 - x0, y1 - y0);
            assert!((seen - along).length() < 0.5, "{seen} vs {along}");
            assert!((d.length() - Vec3::new(0.0, 0.1, 0.05).length()).abs() < 1e-5);
        }
    }
}

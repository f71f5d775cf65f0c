//! A video's keypoints into a clip: every frame's file fitted, warm-started from the frame
//! before, smoothed over time, and keyed into a clip on the character (the root's travel
//! and turn included) that plays, retargets and exports like any other.
//!
//! The camera stays where the first frame puts it (its field of view too, once estimated):
//! a later frame's camera, fitted around the still character at the first one's pitch,
//! becomes the character's move under the first camera (its travel and turn on the floor).

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};
use marionette_formats::keypoints::{Keypoints, read_keypoint_frames};
use marionette_rig::CharacterAsset;
use marionette_rig::anim::Clip;
use marionette_rig::humanoid::HumanoidMap;
use marionette_rig::ik::rotation_of;
use marionette_rig::retarget::Frame;

use super::solve::{Problem, State};
use super::{Body, FitError, modes, picture_size, seen_points};
use marionette_formats::stage::CameraDoc;

/// What `--fit-sequence` is given.
#[derive(Debug, Clone, PartialEq)]
pub struct SequenceSpec {
    /// A folder of per-frame keypoint files (`*.json`, in name order), or a text file
    /// listing them one a line.
    pub frames: PathBuf,
    /// Frames a second.
    pub fps: f32,
    pub person: Option<usize>,
    pub fov: Option<f32>,
}

/// A fitted clip.
#[derive(Debug, Clone)]
pub struct FittedClip {
    pub clip: Clip,
    pub camera: CameraDoc,
    pub size: (u32, u32),
    /// Each frame's mean pixel error (after smoothing).
    pub errors: Vec<f32>,
}

impl FittedClip {
    pub fn describe(&self) -> String {
        let mean = self.errors.iter().sum::<f32>() / self.errors.len().max(1) as f32;
        let worst = self.errors.iter().copied().fold(0.0, f32::max);
        format!(
            "fitted {} frames into a clip of {:.2} s: {mean:.1} px mean error (worst frame {worst:.1}) at {}×{}",
            self.errors.len(),
            self.clip.range.1 - self.clip.range.0,
            self.size.0,
            self.size.1
        )
    }
}

/// The frames' files: a folder's `.json` files in name order, a `.json` file itself (a
/// list of frames, ComfyUI's), or a list's lines (relative to the list's folder).
pub fn frame_files(path: &Path) -> Result<Vec<PathBuf>, FitError> {
    let fail = |message: String| FitError::File { file: path.display().to_string(), message };
    let is_json = |p: &Path| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let files: Vec<PathBuf> = if path.is_dir() {
        let entries = std::fs::read_dir(path).map_err(|e| fail(format!("cannot read the folder: {e}")))?;
        let mut files: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| is_json(p)).collect();
        files.sort();
        files
    } else if is_json(path) {
        vec![path.to_path_buf()]
    } else {
        let text = std::fs::read_to_string(path).map_err(|e| fail(format!("cannot read the list: {e}")))?;
        let folder = path.parent().unwrap_or(Path::new("."));
        text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')).map(|l| folder.join(l)).collect()
    };
    if files.is_empty() {
        return Err(fail("expected keypoint files (`*.json`), found none".into()));
    }
    Ok(files)
}

/// Every frame of the files, in order, each with the file it came from.
fn frames_of(files: &[PathBuf]) -> Result<Vec<(&PathBuf, Keypoints)>, FitError> {
    let mut frames = Vec::new();
    for file in files {
        frames.extend(read_keypoint_frames(file)?.into_iter().map(|k| (file, k)));
    }
    Ok(frames)
}

/// Frames averaged over this many on either side (weights falling off linearly).
const SMOOTHING: usize = 1;

/// Fits every frame of `spec` onto `asset` at `placement` and keys the clip.
pub fn fit_sequence(
    asset: &CharacterAsset,
    map: &HumanoidMap,
    placement: Mat4,
    smpl: bool,
    spec: &SequenceSpec,
) -> Result<FittedClip, FitError> {
    let files = frame_files(&spec.frames)?;
    let body = Body::new(asset, map, placement, smpl).ok_or(FitError::NoHumanoid)?;
    let all_modes = modes(&body);
    let mut states: Vec<State> = Vec::with_capacity(files.len());
    let mut seens = Vec::with_capacity(files.len());
    let mut fov = spec.fov;
    let mut size = None;
    let frames = frames_of(&files)?;
    for (file, keypoints) in &frames {
        let person = keypoints
            .person(spec.person)
            .map_err(|message| FitError::File { file: file.display().to_string(), message })?;
        let seen = seen_points(&body, person);
        if seen.len() < 6 {
            let index = spec.person.unwrap_or(0);
            return Err(FitError::TooFewPoints { file: file.display().to_string(), person: index, found: seen.len() });
        }
        let frame_size = *size.get_or_insert_with(|| picture_size(keypoints, person));
        let mut problem = Problem::new(&body, &seen, frame_size, fov);
        if let Some(first) = states.first() {
            problem.follow(first);
        }
        let state = match states.last() {
            None => problem.best(&all_modes).state,
            Some(previous) => {
                let warm = problem.from(previous);

                if warm.error > 3.0 {
                    let fresh = problem.best(&all_modes);
                    if fresh.error < warm.error / 2.0 { fresh.state } else { warm.state }
                } else {
                    warm.state
                }
            }
        };
        fov.get_or_insert(state.camera.fov);
        states.push(state);
        seens.push(seen);
    }
    let size = size.expect("at least one frame");
    let states = smoothed(&states);
    let first = states[0].camera.to_world();
    let mut frames = Vec::with_capacity(states.len());
    let mut errors = Vec::with_capacity(states.len());
    for (state, seen) in states.iter().zip(&seens) {
        // The character's move under the first camera that shows it as this frame's camera
        // shows it unmoved.
        let moved = placement.inverse() * first * state.camera.to_world().inverse() * placement;
        let mut pose = body.posed(&state.body);
        let root = asset.skeleton.joint(0).rest_offset;
        pose[0] = pose[0].with_rotation_of(rotation_of(moved) * pose[0].to_quat());
        frames.push(Frame::posed(moved.transform_point3(root), pose));
        errors.push(Problem::new(&body, seen, size, fov).error_of(state));
    }
    let joints: Vec<usize> = (0..asset.skeleton.len()).collect();
    let clip = Clip::from_frames(&asset.skeleton, &frames, spec.fps, &joints);
    let camera = states[0].camera.doc((body_centre(&body, &frames[0]) - states[0].camera.eye).length().max(0.1));
    Ok(FittedClip { clip, camera, size, errors })
}

/// Where the character's joints are, on average, in a frame.
fn body_centre(body: &Body, frame: &Frame) -> Vec3 {
    let world = frame.world(body.skeleton);
    let sum: Vec3 = world.1.iter().copied().sum();
    body.placement.transform_point3(sum / world.1.len().max(1) as f32)
}

/// Each frame's camera and bone directions averaged with its neighbours'.
fn smoothed(states: &[State]) -> Vec<State> {
    (0..states.len())
        .map(|t| {
            let lo = t.saturating_sub(SMOOTHING);
            let hi = (t + SMOOTHING).min(states.len() - 1);
            let weighted: Vec<(f32, &State)> =
                (lo..=hi).map(|k| ((SMOOTHING + 1 - k.abs_diff(t)) as f32, &states[k])).collect();
            State::mean(&states[t], &weighted)
        })
        .collect()
}

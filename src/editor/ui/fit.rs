//! "Fit to keypoints…": a pose detector's keypoint file fitted onto the selected character
//! (the document layer's [`fit`](crate::document::fit)), as one undo step (its pose, its
//! place on the floor, the picture behind it and the picture's size), the view moved to
//! the fitted camera, and the file's points drawn over the view until hidden.

use std::path::Path;

use bevy_egui::egui;

use super::{InspectorState, Panels};
use crate::document::annotate::openpose::HAND_EDGES;
use crate::editor::edits::kinds;
use crate::formats::keypoints::{BodyPoint, HAND_POINTS, Person2d};
use crate::formats::scene::{BackgroundDoc, CharacterId, ShotDoc};

/// The file's points over the view, in its picture's pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct KeypointOverlay {
    pub size: (u32, u32),
    pub points: Vec<egui::Pos2>,
    pub lines: Vec<(egui::Pos2, egui::Pos2)>,
}

/// The body's limbs between detector points.
const LIMBS: [(BodyPoint, BodyPoint); 17] = {
    use BodyPoint::*;
    [
        (Nose, Neck),
        (Neck, RightShoulder),
        (RightShoulder, RightElbow),
        (RightElbow, RightWrist),
        (Neck, LeftShoulder),
        (LeftShoulder, LeftElbow),
        (LeftElbow, LeftWrist),
        (RightShoulder, RightHip),
        (LeftShoulder, LeftHip),
        (RightHip, LeftHip),
        (RightHip, RightKnee),
        (RightKnee, RightAnkle),
        (LeftHip, LeftKnee),
        (LeftKnee, LeftAnkle),
        (Nose, LeftEye),
        (Nose, RightEye),
        (LeftAnkle, LeftBigToe),
    ]
};

impl KeypointOverlay {
    fn of(person: &Person2d, size: (u32, u32)) -> Self {
        let at = |p: crate::formats::keypoints::Point2d| egui::pos2(p.x, p.y);
        let mut points: Vec<egui::Pos2> = person.body.iter().map(|(_, p)| at(*p)).collect();
        let mut lines: Vec<(egui::Pos2, egui::Pos2)> =
            LIMBS.iter().filter_map(|&(a, b)| Some((at(person.point(a)?), at(person.point(b)?)))).collect();
        for hand in [&person.left_hand, &person.right_hand].into_iter().filter(|h| h.len() == HAND_POINTS) {
            points.extend(hand.iter().flatten().map(|p| at(*p)));
            lines.extend(HAND_EDGES.iter().filter_map(|&[a, b]| Some((at(hand[a]?), at(hand[b]?)))));
        }
        Self { size, points, lines }
    }

    /// The points of person `person` (the largest where none) of a keypoint file; none
    /// where it cannot be read.
    pub fn of_file(path: &Path, person: Option<usize>) -> Option<Self> {
        let keypoints = crate::formats::keypoints::read_keypoints(path).ok()?;
        let person = keypoints.person(person).ok()?;
        Some(Self::of(person, crate::document::fit::picture_size(&keypoints, person)))
    }

    /// Draws the points and limbs over the view `viewport`, where the camera (whose field of
    /// view spans the view's height) puts the picture's pixels.
    pub fn draw(&self, painter: &egui::Painter, viewport: egui::Rect) {
        let height = viewport.height();
        let width = height * self.size.0 as f32 / self.size.1.max(1) as f32;
        let frame = egui::Rect::from_center_size(viewport.center(), egui::vec2(width, height));
        let scale = egui::vec2(frame.width() / self.size.0 as f32, frame.height() / self.size.1 as f32);
        let on_screen = |p: egui::Pos2| frame.min + p.to_vec2() * scale;
        let colour = egui::Color32::from_rgb(255, 200, 0);
        for &(a, b) in &self.lines {
            painter.line_segment([on_screen(a), on_screen(b)], egui::Stroke::new(2.0, colour));
        }
        for &p in &self.points {
            painter.circle_filled(on_screen(p), 3.5, colour);
        }
    }
}

/// What fitting a character to a keypoint file asks of the editor: the edits (one undo
/// step), the camera, the points to draw and what to say.
pub struct FitOutcome {
    pub edits: Vec<crate::editor::edits::edit::Edit>,
    pub camera: crate::formats::scene::CameraDoc,
    pub overlay: KeypointOverlay,
    pub message: String,
}

/// A character as it is now, to fit: its id, name, source, asset, humanoid map, pose and
/// placement.
pub struct FitTarget<'a> {
    pub id: CharacterId,
    pub name: &'a str,
    pub source: &'a crate::formats::scene::SourceDoc,
    pub asset: &'a crate::rig::CharacterAsset,
    pub map: &'a crate::rig::humanoid::HumanoidMap,
    pub pose: &'a [crate::rig::JointRotation],
    pub placement: glam::Mat4,
}

/// Fits `target` to the keypoint file at `path` (the scene's stage and shot as they are):
/// its pose, its place on the floor, the picture beside the file behind it and the shot at
/// the picture's size, and the fitted camera moved with it; or why it cannot be fitted.
pub fn fit_outcome(
    path: &Path,
    target: &FitTarget,
    stage: &crate::formats::scene::StageDoc,
    shot: ShotDoc,
) -> Result<FitOutcome, String> {
    let FitTarget { id, name, source, asset, map, pose, placement } = *target;
    let spec = crate::document::fit::FitSpec { file: path.to_path_buf(), ..Default::default() };
    let smpl = crate::document::fit::is_smpl(source);
    let keypoints = crate::formats::keypoints::read_keypoints(path).map_err(|e| e.to_string())?;
    let fitted =
        crate::document::fit::fit(asset, map, placement, smpl, &keypoints, &spec).map_err(|e| e.to_string())?;
    let person = keypoints.person(None).expect("the fit found one");
    let overlay = KeypointOverlay::of(person, crate::document::fit::picture_size(&keypoints, person));
    let stood = crate::document::posing::stood_on_floor(asset, &fitted.pose, placement);
    let mut camera = fitted.camera;
    camera.focus += (stood * placement.inverse()).w_axis.truncate();
    let mut edits: Vec<crate::editor::edits::edit::Edit> =
        kinds::Pose::change(id, pose, &fitted.pose).into_iter().map(Into::into).collect();
    edits.push(kinds::Place { character: id, placement: crate::formats::scene::PlacementDoc::from_mat4(stood) }.into());
    if let Some(picture) = crate::document::fit::picture_beside(path) {
        let stage = crate::formats::scene::StageDoc {
            background: BackgroundDoc::Image { path: picture, fill: false },
            ..stage.clone()
        };
        edits.push(kinds::Stage(stage).into());
    }
    let sized = ShotDoc { width: fitted.size.0, height: fitted.size.1, ..shot };
    if sized != shot {
        edits.push(kinds::Shot(sized).into());
    }
    Ok(FitOutcome { edits, camera, overlay, message: format!("{name}: {}", fitted.describe()) })
}

/// "Fit to keypoints…" on character `id`: [`fit_outcome`]'s edits pushed together (one
/// undo step), the view moved to its camera, its points drawn, its words said.
pub fn fit_to_keypoints(path: &Path, id: CharacterId, state: &mut InspectorState, panels: &mut Panels) {
    let Some(c) = panels.scene.characters.iter().find(|c| c.scene.id == id) else { return };
    let map = c.humanoid_map.map(|m| m.0.clone()).unwrap_or_default();
    let pose: Vec<crate::rig::JointRotation> =
        c.character.joints.iter().map(|&e| panels.scene.poses.get(e).map_or(Default::default(), |p| p.0)).collect();
    let target = FitTarget {
        id,
        name: &c.scene.name,
        source: &c.scene.source,
        asset: &c.character.asset,
        map: &map,
        pose: &pose,
        placement: c.placement.0.to_mat4(),
    };
    match fit_outcome(path, &target, &panels.scene.stage.0, panels.scene.shot.0) {
        Ok(outcome) => {
            outcome.edits.into_iter().for_each(|e| panels.push(e));
            panels.camera_request.0 = Some(outcome.camera);
            panels.messages.push(outcome.message);
            state.keypoints = Some(outcome.overlay);
        }
        Err(e) => panels.messages.push(format!("Fit to keypoints: {e}")),
    }
}

/// `edit --fit FILE`: the file's points drawn over the view from the start.
pub fn show_startup_keypoints(
    edits: Option<bevy::prelude::Res<crate::editor::state::StartupEdits>>,
    mut state: bevy::prelude::ResMut<InspectorState>,
) {
    let Some(spec) = edits.as_ref().and_then(|e| e.pose.fit.as_ref()) else { return };
    state.keypoints = KeypointOverlay::of_file(&spec.file, spec.person);
}

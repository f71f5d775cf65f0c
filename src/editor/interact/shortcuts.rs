//! Keyboard shortcuts in the viewport: S display mode, A axes, Ctrl+Z / Ctrl+Shift+Z undo
//! and redo, F12 screenshot (Ctrl+S / Ctrl+O, which save and open the path in the scene
//! panel, are the panels') (scene edits go out as `Edit`s);
//! F frames the selection; the numpad's views (as in Blender): 1 front, 3 right, 7 top, with
//! Ctrl the opposite side, 9 three-quarter, 5 perspective / orthographic.

use crate::editor::edits::kinds;
use bevy::prelude::*;

use crate::editor::edits::edit::EditQueue;
use crate::editor::edits::history::{History, HistoryRequest};
use crate::editor::present::screenshot::ScreenshotRequest;
use crate::editor::scene_doc::document::SceneReader;
use crate::editor::state::Selection;
use crate::editor::state::camera::OrbitCamera;
use crate::formats::scene::{ViewDoc, ViewName};
use crate::scene::{Character, CurrentJointToWorld, Placement};

/// Whether the keys are the viewport's (egui has no text field focused).
pub fn viewport_has_keys(wants: &Option<Res<bevy_egui::input::EguiWantsInput>>) -> bool {
    !wants.as_ref().is_some_and(|w| w.wants_any_keyboard_input())
}

pub fn ctrl_held(keys: &ButtonInput<KeyCode>) -> bool {
    keys.any_pressed([KeyCode::ControlLeft, KeyCode::ControlRight, KeyCode::SuperLeft, KeyCode::SuperRight])
}

/// The shortcuts that edit or undo the scene, or take a screenshot (reads keys and the
/// scene; writes `EditQueue`, `History`'s request, `ScreenshotRequest`).
pub fn scene_shortcuts(
    keys: Res<ButtonInput<KeyCode>>,
    wants: Option<Res<bevy_egui::input::EguiWantsInput>>,
    selection: Res<Selection>,
    scene: SceneReader,
    mut edits: ResMut<EditQueue>,
    mut history: ResMut<History>,
    mut shot: ResMut<ScreenshotRequest>,
) {
    if !viewport_has_keys(&wants) {
        return;
    }
    if keys.just_pressed(KeyCode::F12) {
        shot.request();
    }
    if ctrl_held(&keys) {
        let shift = keys.any_pressed([KeyCode::ShiftLeft, KeyCode::ShiftRight]);
        if keys.just_pressed(KeyCode::KeyZ) {
            history.request = Some(if shift { HistoryRequest::Redo } else { HistoryRequest::Undo });
        }
        return;
    }
    if keys.just_pressed(KeyCode::KeyK)
        && let Some(id) = selection.character
        && let Some(c) = scene.characters.iter().find(|c| c.scene.id == id)
    {
        let character = c.character;
        let pose: Vec<_> =
            character.joints.iter().map(|&e| scene.poses.get(e).map_or(Default::default(), |p| p.0)).collect();
        let anim = crate::scene::keyframes::keyed(c.player, character.joints.len(), &selection.joints, &pose);
        edits.push(kinds::Clip { character: id, anim: Some(anim) });
    }
    if keys.just_pressed(KeyCode::KeyA) {
        edits.push(kinds::Stage(crate::formats::scene::StageDoc { axes: !scene.stage.axes, ..scene.stage.0.clone() }));
    }
    if keys.just_pressed(KeyCode::KeyS) {
        // The selected character, or every character when none is selected.
        for c in &scene.characters {
            let (sc, view) = (c.scene, c.view);
            if selection.character.is_none_or(|id| id == sc.id) {
                let view = ViewDoc { display: view.display.next(), ..view.0.clone() };
                edits.push(kinds::View { character: sc.id, view });
            }
        }
    }
}

/// F frames the selected joints, the selected character, or everything (reads joints;
/// writes `OrbitCamera`).
pub fn frame_selection(
    keys: Res<ButtonInput<KeyCode>>,
    wants: Option<Res<bevy_egui::input::EguiWantsInput>>,
    selection: Res<Selection>,
    characters: Query<(&crate::editor::scene_doc::document::SceneCharacter, &Character, &Placement)>,
    joints: Query<&CurrentJointToWorld>,
    mut cameras: Query<&mut OrbitCamera>,
) {
    if !keys.just_pressed(KeyCode::KeyF) || ctrl_held(&keys) || !viewport_has_keys(&wants) {
        return;
    }
    let points: Vec<Vec3> = characters
        .iter()
        .filter(|c| selection.character.is_none_or(|id| id == c.0.id))
        .flat_map(|(_, character, placement)| {
            let chosen: Vec<usize> = if selection.joints.is_empty() || selection.character.is_none() {
                (0..character.joints.len()).collect()
            } else {
                selection.joints.clone()
            };
            chosen
                .into_iter()
                .filter_map(|j| Some(joints.get(*character.joints.get(j)?).ok()?.world_position(placement)))
                .collect::<Vec<_>>()
        })
        .collect();
    if points.is_empty() {
        return;
    }
    let lo = points.iter().fold(Vec3::splat(f32::INFINITY), |a, p| a.min(*p));
    let hi = points.iter().fold(Vec3::splat(f32::NEG_INFINITY), |a, p| a.max(*p));
    for mut orbit in &mut cameras {
        let framed = OrbitCamera::framing(lo, hi + Vec3::splat(0.15), 1.6);
        orbit.focus = (lo + hi) / 2.0;
        orbit.distance = framed.distance.max(0.4);
    }
}

/// The view a numpad key asks for (Ctrl: the opposite side).
fn numpad_view(keys: &ButtonInput<KeyCode>) -> Option<ViewName> {
    let opposite = ctrl_held(keys);
    [
        (KeyCode::Numpad1, ViewName::Front, ViewName::Back),
        (KeyCode::Numpad3, ViewName::Right, ViewName::Left),
        (KeyCode::Numpad7, ViewName::Top, ViewName::Bottom),
        (KeyCode::Numpad9, ViewName::ThreeQuarter, ViewName::ThreeQuarter),
    ]
    .into_iter()
    .find(|(key, ..)| keys.just_pressed(*key))
    .map(|(_, view, other)| if opposite { other } else { view })
}

/// The numpad's views and lens switch (reads keys; writes `OrbitCamera`).
pub fn view_shortcuts(
    keys: Res<ButtonInput<KeyCode>>,
    wants: Option<Res<bevy_egui::input::EguiWantsInput>>,
    mut cameras: Query<&mut OrbitCamera>,
) {
    if !viewport_has_keys(&wants) {
        return;
    }
    let view = numpad_view(&keys);
    let toggle = keys.just_pressed(KeyCode::Numpad5);
    for mut orbit in &mut cameras {
        if let Some(view) = view {
            orbit.0 = orbit.0.looking_from(view);
        }
        if toggle {
            orbit.0 = orbit.0.toggled_ortho();
        }
    }
}

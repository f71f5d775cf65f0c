//! The scene panel: scene files and history, adding characters, the character list and
//! the selected character's name, placement, view, weights and SMPL state, the stage's view
//! options, screenshots and messages.

use crate::editor::edits::kinds;
use std::path::{Path, PathBuf};

use bevy::prelude::*;
use bevy_egui::egui;

use super::dialogs::DialogPurpose;
use super::{InspectorState, Panels};
use crate::editor::edits::edit::Edit;
use crate::editor::edits::history::HistoryRequest;
use crate::editor::interact::shortcuts::{ctrl_held, viewport_has_keys};
use crate::editor::present::screenshot::ScreenshotRequest;
use crate::editor::scene_doc::arrange::{beside, rescaled_keeping_feet};
use crate::editor::scene_doc::document::{open_scene_from, save_scene_to};
use crate::editor::state::Selection;
use crate::formats::scene::{BindingDoc, CharacterId, DisplayDoc, PlacementDoc, SkinningDoc, ViewDoc};

pub fn scene_panel(ui: &mut egui::Ui, state: &mut InspectorState, panels: &mut Panels, shot: &mut ScreenshotRequest) {
    ui.heading("Scene");
    scene_file_row(ui, state, panels);
    history_row(ui, panels);
    ui.separator();
    add_row(ui, state, panels);
    ui.separator();
    let mut list: Vec<(Entity, CharacterId)> = panels.scene.characters.iter().map(|c| (c.entity, c.scene.id)).collect();
    list.sort_by_key(|c| c.1);
    for (entity, id) in list {
        character_row(ui, panels, entity, id);
        if panels.selection.character == Some(id) {
            selected_character(ui, panels, entity, id);
        }
    }
    ui.separator();
    ui.heading("View");
    super::stage_panel::stage_panel(ui, state, panels);
    ui.label("S cycles mesh / skeleton / both; F frames the selection; click a joint to select it.");
    ui.separator();
    screenshot_rows(ui, state, shot);
    ui.separator();
    messages(ui, panels);
}

fn scene_file_row(ui: &mut egui::Ui, state: &mut InspectorState, panels: &mut Panels) {
    ui.horizontal(|ui| {
        ui.add(egui::TextEdit::singleline(&mut state.scene_path).desired_width(170.0));
        if ui.button("Save").on_hover_text("Ctrl+S").clicked() {
            save_scene_to(&state.scene_path, &panels.scene.capture(), &mut panels.messages, &mut panels.saved);
        }
        if ui.button("Open").on_hover_text("Ctrl+O").clicked() {
            open_scene_from(&state.scene_path, &mut panels.pending, &mut panels.messages);
        }
    });
    ui.horizontal(|ui| {
        let near = state.scene_path.clone();
        if ui.button("Open…").clicked() {
            state.dialogs.open(DialogPurpose::OpenScene, &near);
        }
        if ui.button("Save as…").clicked() {
            state.dialogs.open(DialogPurpose::SaveScene, &near);
        }
        if ui.button("Export glTF…").clicked() {
            state.dialogs.open(DialogPurpose::ExportGltf, &near);
        }
    });
}

fn history_row(ui: &mut egui::Ui, panels: &mut Panels) {
    ui.horizontal(|ui| {
        let undo = egui::Button::new("Undo");
        if ui.add_enabled(panels.history.can_undo(), undo).on_hover_text("Ctrl+Z").clicked() {
            panels.history.request = Some(HistoryRequest::Undo);
        }
        let redo = egui::Button::new("Redo");
        if ui.add_enabled(panels.history.can_redo(), redo).on_hover_text("Ctrl+Shift+Z").clicked() {
            panels.history.request = Some(HistoryRequest::Redo);
        }
    });
}

fn add_row(ui: &mut egui::Ui, state: &mut InspectorState, panels: &mut Panels) {
    ui.label("Add a character or prop (.skel, .skin, .glb, .gltf, .fbx, SMPL folder, rig .json, .bvh; an .obj alone is a prop), a clip for the selected one (.anim) or open a scene (.ron); or drop files on the window:");
    ui.horizontal(|ui| {
        ui.add(egui::TextEdit::singleline(&mut state.add_path).desired_width(220.0));
        if ui.button("Add").clicked() {
            let path = state.add_path.trim().to_string();
            super::open::open_path(&path, state, panels);
        }
        if ui.button("…").on_hover_text("choose a file").clicked() {
            let near = state.add_path.clone();
            state.dialogs.open(DialogPurpose::AddFile, &near);
        }
    });
    ui.horizontal(|ui| {
        ui.add(egui::DragValue::new(&mut state.crowd_size).range(1..=512).suffix(" characters"));
        let hint = "SMPL bodies (clips and shapes varied, playing) from the selected body's folder or the \
                    SMPL folder above; puppets otherwise. One undo step.";
        if ui.button("Add crowd").on_hover_text(hint).clicked() {
            add_crowd(state, panels);
        }
    });
    let recent = panels.recent.as_ref().map(|r| r.0.clone()).unwrap_or_default();
    if recent.is_empty() {
        return;
    }
    ui.horizontal_wrapped(|ui| {
        ui.label("Recent:");
        for r in recent {
            let label = Path::new(&r).file_name().map_or(r.clone(), |n| n.to_string_lossy().into_owned());
            if ui.small_button(label).on_hover_text(&r).clicked() {
                super::open::open_path(&r, state, panels);
            }
        }
    });
}

/// Adds a crowd right of the characters already there (one undo step: its edits land in
/// one frame).
fn add_crowd(state: &InspectorState, panels: &mut Panels) {
    let selected_body = panels.selection.character.and_then(|id| {
        panels.scene.characters.iter().find(|c| c.scene.id == id).and_then(|c| c.smpl.map(|body| body.dir.clone()))
    });
    let typed = PathBuf::from(state.add_path.trim());
    let folder = selected_body.or_else(|| crate::formats::smpl::is_smpl_dir(&typed).then_some(typed));
    let crowd = match &folder {
        Some(dir) => crate::document::crowd::smpl_crowd(dir, state.crowd_size),
        None => Ok(crate::document::crowd::puppet_crowd(state.crowd_size)),
    };
    let crowd = match crowd {
        Ok(doc) => doc,
        Err(e) => return panels.messages.push(e.to_string()),
    };
    let right = panels.scene.characters.iter().map(|c| c.placement.translation.x).fold(f32::NEG_INFINITY, f32::max);
    let width = crowd.characters.iter().map(|c| c.placement.translation.x).fold(0.0f32, |m, x| m.max(x.abs()));
    let shift = if right.is_finite() { right + 1.0 + width } else { 0.0 };
    for mut c in crowd.characters {
        c.id = Some(panels.ids.take());
        c.placement.translation.x += shift;
        panels.push(kinds::Add(Box::new(c)));
    }
}

/// The character's name (a click selects it) and its visibility.
fn character_row(ui: &mut egui::Ui, panels: &mut Panels, entity: Entity, id: CharacterId) {
    let Ok(c) = panels.scene.characters.get(entity) else { return };
    let (sc, view) = (c.scene, c.view);
    let selected = panels.selection.character == Some(id);
    let mut shown = view.visible;
    let (name, view) = (sc.name.clone(), view.0.clone());
    ui.horizontal(|ui| {
        if ui.selectable_label(selected, &name).clicked() && !selected {
            *panels.selection = Selection { character: Some(id), joints: Vec::new() };
        }
        if ui.checkbox(&mut shown, "").on_hover_text("show").changed() {
            panels.push(kinds::View { character: id, view: ViewDoc { visible: shown, ..view } });
        }
    });
}

/// Name, source, duplicate/remove, placement, display and colours, weights, SMPL state of
/// the selected character.
fn selected_character(ui: &mut egui::Ui, panels: &mut Panels, entity: Entity, id: CharacterId) {
    let Ok(c) = panels.scene.characters.get(entity) else { return };
    let (sc, character, placement, view, smpl) = (c.scene, c.character, c.placement, c.view, c.smpl);
    let (player, morphs, node_clips) = (c.player, c.morphs, c.node_clips);
    let (skinning, on_gpu) = (c.skinning.0, c.on_gpu.0);
    let (mut name, source, binding) = (sc.name.clone(), sc.source.label(), sc.binding);
    let (mut p, mut v) = (placement.0, view.0.clone());
    let height = panels.height(entity).unwrap_or(0.0);
    let counts = format!(
        "{} joints, {} vertices, {height:.2} m tall",
        character.asset.skeleton.len(),
        character.asset.vertex_count()
    );
    let mut match_height = false;
    let mut edits: Vec<Edit> = Vec::new();
    let (mut duplicate, mut remove) = (false, false);
    let mut held = None;
    egui::Frame::group(ui.style()).show(ui, |ui| {
        ui.horizontal(|ui| {
            ui.label("Name");
            if ui.text_edit_singleline(&mut name).changed() {
                edits.push(kinds::Rename { character: id, name: name.clone() }.into());
            }
        });
        ui.label(egui::RichText::new(source).small());
        ui.label(counts);
        ui.horizontal(|ui| {
            duplicate = ui.button("Duplicate").clicked();
            remove = ui.button("Remove").clicked();
            match_height = ui
                .button("Match height")
                .on_hover_text("scale every other character to this one's height (one undo step)")
                .clicked();
        });
        if c.attached.is_none() {
            placement_rows(ui, &mut p);
        }
        held = super::attach_panel::attach_rows(ui, panels, entity, id);
        ui.horizontal(|ui| {
            ui.radio_value(&mut v.display, DisplayDoc::Mesh, "mesh");
            ui.radio_value(&mut v.display, DisplayDoc::Skeleton, "skeleton");
            ui.radio_value(&mut v.display, DisplayDoc::Both, "both");
        });
        ui.checkbox(&mut v.weight_colors, "weight colours");
        ui.checkbox(&mut v.heat_of_selected, "weights of the selected joint");
        ui.add(egui::Slider::new(&mut v.opacity, 0.1..=1.0).text("opacity"))
            .on_hover_text("below 1 the character is a ghost, to draw over a reference picture");
    });
    if p != placement.0 {
        edits.push(kinds::Place { character: id, placement: p }.into());
    }
    if v != view.0 {
        edits.push(kinds::View { character: id, view: v }.into());
    }
    edits.extend(held);
    ui.horizontal_wrapped(|ui| {
        ui.label("Weights:");
        for (label, b) in [
            ("from the file", None),
            ("bone heat", Some(BindingDoc::Heat)),
            ("nearest bone", Some(BindingDoc::Nearest)),
            ("smooth", Some(BindingDoc::Smooth)),
        ] {
            if ui.selectable_label(binding == b, label).clicked() && binding != b {
                edits.push(kinds::Rebind { character: id, binding: b }.into());
            }
        }
    });
    ui.horizontal(|ui| {
        ui.label("Skinning:");
        for (label, m) in [("linear blend", SkinningDoc::Linear), ("dual quaternion", SkinningDoc::DualQuaternion)] {
            if ui.selectable_label(skinning == m, label).clicked() && skinning != m {
                edits.push(kinds::Skinning { character: id, method: m }.into());
            }
        }
    });
    ui.horizontal(|ui| {
        ui.label("Skinned by:");
        for (label, on) in [("the CPU", false), ("a GPU compute shader", true)] {
            if ui.selectable_label(on_gpu == on, label).clicked() && on_gpu != on {
                edits.push(kinds::SkinOnGpu { character: id, on }.into());
            }
        }
    })
    .response
    .on_hover_text(
        "The CPU path is the course assignments'; the GPU path is the 6.837 \"accelerate SSD using shaders\".",
    );
    if let Some(body) = smpl
        && let Some(state) = super::smpl_panel::smpl_panel(ui, body)
    {
        edits.push(kinds::Smpl { character: id, state }.into());
    }
    if let Some(player) = player
        && let Some(anim) = super::clip_panel::clip_panel(ui, player)
    {
        edits.push(kinds::Clip { character: id, anim }.into());
    }
    if let Some(player) = node_clips
        && let Some(state) = super::clip_panel::playback_panel(ui, player)
    {
        edits.push(kinds::Playback { character: id, state }.into());
    }
    edits.extend(super::motion_panel::motion_rows(ui, panels, entity, id));
    edits.extend(super::motion_panel::humanoid_rows(ui, panels, entity, id));
    if let Some(morphs) = morphs
        && let Some(weights) = morph_sliders(ui, morphs)
    {
        edits.push(kinds::Morph { character: id, weights }.into());
    }
    if duplicate && let Some(mut copy) = panels.scene.character_doc(entity) {
        let copy_id = panels.ids.take();
        copy.id = Some(copy_id);
        copy.name = format!("{} copy", copy.name);
        copy.attached = None;
        if let Ok((lo, hi)) = panels.skins.get(entity).map(|s| s.bounds) {
            copy.placement.translation = beside(&panels.world_boxes(), lo, hi, copy.placement.scale);
            copy.placement.yaw = 0.0;
        }
        edits.push(kinds::Add(Box::new(copy)).into());
        *panels.selection = Selection { character: Some(copy_id), joints: Vec::new() };
    }
    if match_height && height > 0.0 {
        edits.extend(match_heights(panels, entity, height));
    }
    if remove {
        edits.push(kinds::Remove(id).into());
        *panels.selection = Selection::default();
    }
    edits.into_iter().for_each(|e| panels.push(e));
}

/// Placement edits that scale every character other than `entity` to `height`, feet kept
/// where they stood.
fn match_heights(panels: &Panels, entity: Entity, height: f32) -> Vec<Edit> {
    panels
        .scene
        .characters
        .iter()
        .filter(|c| c.entity != entity)
        .filter_map(|c| {
            let (other, sc, placement) = (c.entity, c.scene, c.placement);
            let own = panels.height(other).filter(|&h| h > 0.0)?;
            let lowest = panels.skins.get(other).ok()?.bounds.0.y;
            let placement = rescaled_keeping_feet(&placement.0, lowest, placement.scale * height / own);
            Some(Edit::from(kinds::Place { character: sc.id, placement }))
        })
        .collect()
}

/// A button per expression (a VRM avatar's: sets the morph weights it names) and a slider
/// per morph target; the new weights when one changed them.
fn morph_sliders(ui: &mut egui::Ui, morphs: &crate::scene::morphs::Morphs) -> Option<Vec<f32>> {
    let mut weights = morphs.weights.clone();
    egui::CollapsingHeader::new("Morphs").default_open(true).show(ui, |ui| {
        if !morphs.base.expressions.is_empty() {
            ui.horizontal_wrapped(|ui| {
                ui.label("Expression");
                if ui.button("neutral").clicked() {
                    weights.iter_mut().for_each(|w| *w = 0.0);
                }
                for expression in &morphs.base.expressions {
                    if ui.button(&expression.name).clicked() {
                        weights = expression.morph_weights(weights.len());
                    }
                }
            });
        }
        for (target, w) in morphs.base.morphs.iter().zip(weights.iter_mut()) {
            ui.add(egui::Slider::new(w, 0.0..=1.0).text(&target.name).clamping(egui::SliderClamping::Edits));
        }
    });
    (weights != morphs.weights).then_some(weights)
}

/// Position, turn (degrees) and scale.
fn placement_rows(ui: &mut egui::Ui, p: &mut PlacementDoc) {
    ui.horizontal(|ui| {
        ui.label("Position");
        for k in 0..3 {
            ui.add(egui::DragValue::new(&mut p.translation[k]).speed(0.01).max_decimals(3));
        }
    });
    let mut yaw_deg = p.yaw.to_degrees();
    ui.horizontal(|ui| {
        ui.label("Turn");
        if ui.add(egui::DragValue::new(&mut yaw_deg).speed(1.0).suffix("°")).changed() {
            p.yaw = yaw_deg.to_radians();
        }
        ui.label("Scale");
        ui.add(egui::DragValue::new(&mut p.scale).speed(0.01).range(0.01..=100.0));
    });
}

fn screenshot_rows(ui: &mut egui::Ui, state: &mut InspectorState, shot: &mut ScreenshotRequest) {
    ui.heading("Screenshot");
    ui.horizontal(|ui| {
        ui.label("Folder");
        ui.add(egui::TextEdit::singleline(&mut shot.dir_text).desired_width(150.0));
        if ui.button("…").on_hover_text("choose the folder").clicked() {
            let near = format!("{}/", shot.dir_text);
            state.dialogs.open(DialogPurpose::ScreenshotFolder, &near);
        }
    });
    ui.checkbox(&mut shot.with_panels, "include the panels");
    ui.checkbox(&mut shot.with_data, "with data").on_hover_text(
        "beside the picture: depth, normals, instance and body-part masks, OpenPose drawing and JSON, COCO keypoints with the camera",
    );
    super::stage_panel::controlnet_choice(
        ui,
        &mut shot.controlnet,
        "beside the picture: the OpenPose drawing as ControlNet's annotator draws it and its 18-point JSON, relative inverse depth, Normal 1.1 normals",
    );
    if ui.button("Save screenshot (F12)").clicked() {
        shot.request();
    }
}

fn messages(ui: &mut egui::Ui, panels: &Panels) {
    ui.heading("Messages");
    for m in panels.messages.0.iter().rev().take(8) {
        let color = if m.contains("saved") || m.contains("wrote") {
            egui::Color32::DARK_GREEN
        } else {
            egui::Color32::from_rgb(190, 40, 40)
        };
        ui.colored_label(color, m);
    }
}

/// Ctrl+S saves the scene to the scene path, Ctrl+O opens the scene there, while the
/// viewport has the keys (reads keys and the scene; writes the file, `PendingScene`,
/// `Messages`, `SavedState`).
pub fn file_shortcuts(
    keys: Res<ButtonInput<KeyCode>>,
    wants: Option<Res<bevy_egui::input::EguiWantsInput>>,
    state: Res<InspectorState>,
    scene: crate::editor::scene_doc::document::SceneReader,
    mut pending: ResMut<crate::editor::scene_doc::document::PendingScene>,
    mut messages: ResMut<crate::editor::state::Messages>,
    mut saved: ResMut<crate::editor::state::SavedState>,
) {
    if !viewport_has_keys(&wants) || !ctrl_held(&keys) {
        return;
    }
    if keys.just_pressed(KeyCode::KeyS) {
        save_scene_to(&state.scene_path, &scene.capture(), &mut messages, &mut saved);
    }
    if keys.just_pressed(KeyCode::KeyO) {
        open_scene_from(&state.scene_path, &mut pending, &mut messages);
    }
}

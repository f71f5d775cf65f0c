//! The egui inspector: the scene panel (characters, add/duplicate/remove/rename/show,
//! placement, view options, scene files, screenshots, messages) and the joint panel
//! (joint tree, one slider per DOF within its limits, resets); keyboard shortcuts.

use std::path::{Path, PathBuf};

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy_egui::{EguiContexts, EguiPrimaryContextPass, egui};

use super::camera::{OrbitCamera, ViewportArea, fit_camera_viewport};
use super::document::{
    AssetLibrary, NextCharacterId, PendingScene, SceneCharacter, SceneReader, read_scene, spawn_from_doc, write_scene,
};
use super::history::{History, HistoryRequest};
use super::screenshot::ScreenshotRequest;
use super::stage::StageSettings;
use super::state::{Messages, Selection};
use crate::formats::scene::{BindingDoc, CharacterDoc, DisplayDoc, PlacementDoc, SceneDoc, SourceDoc, ViewDoc};
use crate::rig::{EulerOrder, JointRotation, Skeleton};
use crate::scene::smpl::SmplCharacter;
use crate::scene::{Character, CurrentJointToWorld, DisplayMode, JointLimits, JointPose, Placement, SkinView};

/// Text fields and transient state of the inspector.
#[derive(Resource)]
pub struct InspectorState {
    pub add_path: String,
    pub recent: Vec<String>,
    pub scene_path: String,
    /// The DOF being dragged and its value, shown in the viewport.
    pub active_dof: Option<String>,
}

impl Default for InspectorState {
    fn default() -> Self {
        let cwd = std::env::current_dir().map(|d| d.display().to_string()).unwrap_or_default();
        Self {
            add_path: format!("{cwd}/"),
            recent: Vec::new(),
            scene_path: format!("{cwd}/scene.ron"),
            active_dof: None,
        }
    }
}

/// The scene captured at the start of the frame (before this frame's edits): what undo
/// returns to, what Ctrl+S writes.
#[derive(Resource, Default)]
pub struct SceneSnapshot(pub SceneDoc);

pub struct InspectorPlugin;

impl Plugin for InspectorPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<InspectorState>()
            .init_resource::<ViewportArea>()
            .add_systems(PostUpdate, fit_camera_viewport)
            .init_resource::<SceneSnapshot>()
            .add_systems(Update, capture_snapshot.run_if(scene_changed).before(shortcuts))
            .add_systems(EguiPrimaryContextPass, inspector_ui);
    }
}

/// Captures the scene document (reads the scene; writes `SceneSnapshot`).
fn capture_snapshot(reader: SceneReader, mut snapshot: ResMut<SceneSnapshot>) {
    snapshot.0 = reader.capture();
}

/// Whether anything a scene document holds changed since the last frame: only then is the
/// snapshot captured again (an idle editor builds no document).
#[allow(clippy::too_many_arguments)]
fn scene_changed(
    poses: Query<(), Changed<JointPose>>,
    characters: Query<
        (),
        Or<(
            Changed<SceneCharacter>,
            Changed<Placement>,
            Changed<SkinView>,
            Changed<DisplayMode>,
            Changed<SmplCharacter>,
        )>,
    >,
    mut removed: RemovedComponents<SceneCharacter>,
    cameras: Query<(), Changed<OrbitCamera>>,
    stage: Res<StageSettings>,
    unloaded: Res<super::state::UnloadedCharacters>,
) -> bool {
    !poses.is_empty()
        || !characters.is_empty()
        || removed.read().next().is_some()
        || !cameras.is_empty()
        || stage.is_changed()
        || unloaded.is_changed()
}

/// What the inspector edits.
#[derive(SystemParam)]
pub struct Editable<'w, 's> {
    pub characters: Query<
        'w,
        's,
        (
            Entity,
            &'static mut SceneCharacter,
            &'static Character,
            &'static mut Placement,
            &'static mut SkinView,
            &'static mut DisplayMode,
        ),
    >,
    pub poses: Query<'w, 's, (&'static mut JointPose, &'static JointLimits)>,
    pub stage: ResMut<'w, StageSettings>,
    pub selection: ResMut<'w, Selection>,
    pub history: ResMut<'w, History>,
    pub messages: ResMut<'w, Messages>,
    pub smpl: Query<'w, 's, &'static mut SmplCharacter>,
}

/// Adding, removing and loading characters and scenes.
#[derive(SystemParam)]
pub struct SceneOps<'w, 's> {
    pub commands: Commands<'w, 's>,
    pub meshes: ResMut<'w, Assets<Mesh>>,
    pub library: ResMut<'w, AssetLibrary>,
    pub ids: ResMut<'w, NextCharacterId>,
    pub pending: ResMut<'w, PendingScene>,
    pub snapshot: Res<'w, SceneSnapshot>,
}

/// Draws the panels and applies their edits; one undo step per gesture.
fn inspector_ui(
    mut contexts: EguiContexts,
    mut state: ResMut<InspectorState>,
    mut edit: Editable,
    mut ops: SceneOps,
    mut shot: ResMut<ScreenshotRequest>,
    mut viewport_area: ResMut<ViewportArea>,
) -> Result {
    if shot.hide_ui() {
        // A screenshot without panels shows the whole window.
        viewport_area.set_if_neq(ViewportArea(None));
        return Ok(());
    }
    let ctx = contexts.ctx_mut()?.clone();
    let mut ui = egui::Ui::new(
        ctx.clone(),
        "viewport".into(),
        egui::UiBuilder::new().layer_id(egui::LayerId::background()).max_rect(ctx.viewport_rect()),
    );
    let mut edited = false;
    state.active_dof = None;
    egui::Panel::left("scene_panel").resizable(true).default_size(250.0).show(&mut ui, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| {
            edited |= scene_panel(ui, &mut state, &mut edit, &mut ops, &mut shot);
        });
    });
    egui::Panel::right("joint_panel").resizable(true).default_size(250.0).show(&mut ui, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| {
            edited |= joint_panel(ui, &mut state, &mut edit);
        });
    });
    let central = ui.available_rect_before_wrap();
    let area = ViewportArea(Some(Rect::new(central.min.x, central.min.y, central.max.x, central.max.y)));
    viewport_area.set_if_neq(area);
    if let Some(text) = &state.active_dof {
        egui::Area::new("active_dof".into()).anchor(egui::Align2::CENTER_TOP, [0.0, 12.0]).show(&ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| ui.label(egui::RichText::new(text).size(20.0).strong()));
        });
    }
    if edited {
        edit.history.begin_edit(&ops.snapshot.0);
    }
    Ok(())
}

fn scene_panel(
    ui: &mut egui::Ui,
    state: &mut InspectorState,
    edit: &mut Editable,
    ops: &mut SceneOps,
    shot: &mut ScreenshotRequest,
) -> bool {
    let mut edited = false;
    ui.heading("Scene");
    ui.horizontal(|ui| {
        ui.add(egui::TextEdit::singleline(&mut state.scene_path).desired_width(170.0));
        if ui.button("Save").on_hover_text("Ctrl+S").clicked() {
            save_scene(&state.scene_path, &ops.snapshot.0, &mut edit.messages);
        }
        if ui.button("Open").on_hover_text("Ctrl+O").clicked() {
            open_scene(&state.scene_path, &mut ops.pending, &mut edit.messages);
        }
    });
    ui.horizontal(|ui| {
        if ui.add_enabled(!edit.history.undo.is_empty(), egui::Button::new("Undo")).on_hover_text("Ctrl+Z").clicked() {
            edit.history.request = Some(HistoryRequest::Undo);
        }
        if ui
            .add_enabled(!edit.history.redo.is_empty(), egui::Button::new("Redo"))
            .on_hover_text("Ctrl+Shift+Z")
            .clicked()
        {
            edit.history.request = Some(HistoryRequest::Redo);
        }
    });
    ui.separator();
    ui.label("Add a character (.skel, SMPL folder, rig .json):");
    ui.horizontal(|ui| {
        ui.add(egui::TextEdit::singleline(&mut state.add_path).desired_width(220.0));
        if ui.button("Add").clicked() {
            let path = state.add_path.trim().to_string();
            edited |= add_character(&path, state, edit, ops);
        }
    });
    if !state.recent.is_empty() {
        ui.horizontal_wrapped(|ui| {
            ui.label("Recent:");
            for r in state.recent.clone() {
                let label = Path::new(&r).file_name().map_or(r.clone(), |n| n.to_string_lossy().into_owned());
                if ui.small_button(label).on_hover_text(&r).clicked() {
                    edited |= add_character(&r, state, edit, ops);
                }
            }
        });
    }
    ui.separator();
    let mut remove = None;
    let mut rebind_request: Option<(u64, Option<BindingDoc>)> = None;
    let mut duplicate = None;
    let mut list: Vec<(Entity, u64, String)> =
        edit.characters.iter().map(|c| (c.0, c.1.id, c.1.name.clone())).collect();
    list.sort_by_key(|c| c.1);
    for (entity, id, name) in list {
        let selected = edit.selection.character == Some(id);
        ui.horizontal(|ui| {
            if ui.selectable_label(selected, &name).clicked() && !selected {
                *edit.selection = Selection { character: Some(id), joints: Vec::new() };
            }
            if let Ok(mut c) = edit.characters.get_mut(entity) {
                let mut visible = c.1.visible;
                if ui.checkbox(&mut visible, "").on_hover_text("show").changed() {
                    c.1.visible = visible;
                    edited = true;
                }
            }
        });
        if !selected {
            continue;
        }
        let Ok((_, mut sc, character, mut placement, mut view, mut display)) = edit.characters.get_mut(entity) else {
            continue;
        };
        egui::Frame::group(ui.style()).show(ui, |ui| {
            ui.horizontal(|ui| {
                ui.label("Name");
                edited |= ui.text_edit_singleline(&mut sc.name).changed();
            });
            ui.label(egui::RichText::new(sc.source.label()).small());
            ui.label(format!("{} joints, {} vertices", character.asset.skeleton.len(), character.asset.vertex_count()));
            ui.horizontal(|ui| {
                if ui.button("Duplicate").clicked() {
                    duplicate = Some(id);
                }
                if ui.button("Remove").clicked() {
                    remove = Some(entity);
                }
            });
            let mut p = *placement;
            ui.horizontal(|ui| {
                ui.label("Position");
                for k in 0..3 {
                    ui.add(egui::DragValue::new(&mut p.translation[k]).speed(0.01).max_decimals(3));
                }
            });
            let mut yaw_deg = p.yaw.to_degrees();
            ui.horizontal(|ui| {
                ui.label("Turn");
                ui.add(egui::DragValue::new(&mut yaw_deg).speed(1.0).suffix("°"));
                ui.label("Scale");
                ui.add(egui::DragValue::new(&mut p.scale).speed(0.01).range(0.01..=100.0));
            });
            p.yaw = yaw_deg.to_radians();
            if p != *placement {
                *placement = p;
                edited = true;
            }
            ui.horizontal(|ui| {
                let mut d = **display;
                ui.radio_value(&mut d, DisplayDoc::Mesh, "mesh");
                ui.radio_value(&mut d, DisplayDoc::Skeleton, "skeleton");
                ui.radio_value(&mut d, DisplayDoc::Both, "both");
                if d != **display {
                    **display = d;
                    edited = true;
                }
            });
            let mut colors = view.weight_colors;
            if ui.checkbox(&mut colors, "weight colours").changed() {
                view.weight_colors = colors;
                edited = true;
            }
            edited |= ui.checkbox(&mut sc.heat_of_selected, "weights of the selected joint").changed();
        });
        let binding = sc.binding;
        ui.horizontal(|ui| {
            ui.label("Weights:");
            for (label, b) in [
                ("from the file", None),
                ("nearest bone", Some(BindingDoc::Nearest)),
                ("smooth", Some(BindingDoc::Smooth)),
            ] {
                if ui.selectable_label(binding == b, label).clicked() && binding != b {
                    rebind_request = Some((id, b));
                }
            }
        });
        if let Ok(mut body) = edit.smpl.get_mut(entity) {
            edited |= smpl_panel(ui, &mut body);
        }
    }
    if let Some((id, binding)) = rebind_request {
        // Rebuild the scene from this frame's document with the new binding (undoable).
        if let Some(k) = ops.snapshot.0.characters.iter().position(|c| c.id == Some(id)) {
            let mut doc = ops.snapshot.0.clone();
            doc.characters[k].binding = binding;
            *ops.pending = PendingScene { doc: Some(doc), with_camera: false, frame: false };
            edited = true;
        }
    }
    if let Some((entity, character)) = remove.and_then(|e| Some((e, edit.characters.get(e).ok()?.2.clone()))) {
        crate::scene::despawn_character(&mut ops.commands, entity, &character);
        edit.selection.character = None;
        edit.selection.joints.clear();
        edited = true;
    }
    if let Some(id) = duplicate
        && let Some(doc) = character_doc(&ops.snapshot.0, id)
    {
        let mut copy = doc;
        copy.name = format!("{} copy", copy.name);
        copy.placement.translation[0] += 0.5;
        edited |= spawn_doc(&copy, edit, ops);
    }
    ui.separator();
    ui.heading("View");
    let mut s = *edit.stage;
    ui.horizontal(|ui| {
        ui.checkbox(&mut s.floor, "floor");
        ui.checkbox(&mut s.shadows, "shadows");
        ui.checkbox(&mut s.axes, "axes (A)");
    });
    if s != *edit.stage {
        *edit.stage = s;
    }
    ui.label("S cycles mesh / skeleton / both; F frames the selection; click a joint to select it.");
    ui.separator();
    ui.heading("Screenshot");
    ui.horizontal(|ui| {
        ui.label("Folder");
        ui.text_edit_singleline(&mut shot.dir_text);
    });
    ui.checkbox(&mut shot.with_panels, "include the panels");
    if ui.button("Save screenshot (F12)").clicked() {
        shot.request();
    }
    ui.separator();
    ui.heading("Messages");
    for m in edit.messages.0.iter().rev().take(8) {
        let color = if m.contains("saved") || m.contains("wrote") {
            egui::Color32::DARK_GREEN
        } else {
            egui::Color32::from_rgb(190, 40, 40)
        };
        ui.colored_label(color, m);
    }
    edited
}

/// The document of one character from the frame's snapshot.
fn character_doc(snapshot: &SceneDoc, id: u64) -> Option<CharacterDoc> {
    snapshot.characters.iter().find(|c| c.id == Some(id)).cloned()
}

/// Loads and adds a character beside the others; errors go to the messages.
fn add_character(path: &str, state: &mut InspectorState, edit: &mut Editable, ops: &mut SceneOps) -> bool {
    if path.is_empty() {
        return false;
    }
    let source = SourceDoc::File(PathBuf::from(path));
    let asset = match ops.library.load(&source) {
        Ok(a) => a,
        Err(e) => {
            edit.messages.push(e.to_string());
            return false;
        }
    };
    edit.messages.0.extend(asset.warnings.iter().cloned());
    let right = edit.characters.iter().map(|c| c.3.translation.x).fold(f32::NEG_INFINITY, f32::max);
    let (lo, hi) = asset.bounds();
    let x = if right.is_finite() { right + 0.3 + (hi.x - lo.x) } else { 0.0 };
    let center = (lo + hi) / 2.0;
    let doc = CharacterDoc {
        id: None,
        source,
        name: asset.name.clone(),
        placement: PlacementDoc { translation: Vec3::new(x - center.x, -lo.y, -center.z), yaw: 0.0, scale: 1.0 },
        pose: Default::default(),
        view: ViewDoc::default(),
        smpl: None,
        binding: None,
    };
    state.recent.retain(|r| r != path);
    state.recent.insert(0, path.to_string());
    state.recent.truncate(8);
    if let Some(dir) = Path::new(path).parent() {
        state.add_path = format!("{}/", dir.display());
    }
    spawn_doc(&doc, edit, ops)
}

fn spawn_doc(doc: &CharacterDoc, edit: &mut Editable, ops: &mut SceneOps) -> bool {
    let id = ops.ids.take();
    match spawn_from_doc(&mut ops.commands, &mut ops.meshes, &mut ops.library, doc, id) {
        Ok((_, notes)) => {
            notes.into_iter().for_each(|m| edit.messages.push(m));
            *edit.selection = Selection { character: Some(id), joints: Vec::new() };
            true
        }
        Err(e) => {
            edit.messages.push(e.to_string());
            false
        }
    }
}

fn save_scene(path: &str, doc: &SceneDoc, messages: &mut Messages) {
    match write_scene(Path::new(path), doc) {
        Ok(()) => messages.push(format!("saved the scene to {path}")),
        Err(e) => messages.push(format!("the scene was not saved: {e}")),
    }
}

fn open_scene(path: &str, pending: &mut PendingScene, messages: &mut Messages) {
    match read_scene(Path::new(path)) {
        Ok(doc) => *pending = PendingScene { frame: doc.camera.is_none(), doc: Some(doc), with_camera: true },
        Err(e) => messages.push(e.to_string()),
    }
}

const AXES: [&str; 3] = ["X", "Y", "Z"];

fn joint_panel(ui: &mut egui::Ui, state: &mut InspectorState, edit: &mut Editable) -> bool {
    let mut edited = false;
    ui.heading("Joints");
    let Some(id) = edit.selection.character else {
        ui.label("Select a character (left panel) or click a joint in the viewport.");
        return false;
    };
    let Some((_, _, character, ..)) = edit.characters.iter().find(|c| c.1.id == id) else {
        return false;
    };
    let character = character.clone();
    let skeleton = &character.asset.skeleton;
    if ui.button("Reset the whole pose").clicked() {
        for (j, &e) in character.joints.iter().enumerate() {
            if let Ok((mut pose, _)) = edit.poses.get_mut(e) {
                pose.set_if_neq(JointPose(skeleton.joint(j).initial_rotation));
            }
        }
        edited = true;
    }
    ui.separator();
    let selected = edit.selection.joints.clone();
    for &j in &selected {
        let Some(Ok((mut pose, limits))) = character.joints.get(j).map(|&e| edit.poses.get_mut(e)) else {
            continue;
        };
        let name = &skeleton.joint(j).name;
        ui.label(egui::RichText::new(name).strong());
        let (mut angles, order) = match pose.0 {
            JointRotation::Euler(a, order) => (a, order),
            JointRotation::Quat(_) => (pose.0.to_euler(EulerOrder::Xyz), EulerOrder::Xyz),
        };
        let mut changed = false;
        for axis in 0..3 {
            let (lo, hi) = limits.0.display_range(axis);
            let locked = limits.0.is_locked(axis);
            let slider = egui::Slider::new(&mut angles[axis], lo..=hi.max(lo))
                .text(format!("{name} {}", AXES[axis]))
                .max_decimals(3);
            let response = ui.add_enabled(!locked, slider);
            changed |= response.changed();
            if response.dragged() || response.has_focus() {
                state.active_dof = Some(format!("{name} {} = {:.3}", AXES[axis], angles[axis]));
            }
        }
        if changed {
            let rotation = match pose.0 {
                JointRotation::Euler(..) => JointRotation::Euler(angles, order),
                JointRotation::Quat(_) => JointRotation::Quat(JointRotation::Euler(angles, EulerOrder::Xyz).to_quat()),
            };
            pose.0 = rotation.clamped(&limits.0);
            edited = true;
        }
        if ui.small_button("Reset joint").clicked() {
            pose.0 = skeleton.joint(j).initial_rotation;
            edited = true;
        }
        ui.separator();
    }
    let additive = ui.input(|i| i.modifiers.shift || i.modifiers.command || i.modifiers.ctrl);
    joint_tree(ui, skeleton, 0, id, &mut edit.selection, additive);
    edited
}

/// Indentation of one tree level, and the deepest level indented further.
const TREE_INDENT: f32 = 12.0;
const TREE_MAX_INDENT_LEVELS: usize = 24;
/// Width of the collapse toggle (and of the space leaves keep in its place).
const TREE_TOGGLE_WIDTH: f32 = 14.0;

/// The joint tree as indented rows, collapsible per joint (+/-); a click selects,
/// Shift/Ctrl-click adds. Walked with an explicit stack, so any depth shows.
fn joint_tree(ui: &mut egui::Ui, skeleton: &Skeleton, root: usize, id: u64, selection: &mut Selection, additive: bool) {
    let mut todo = vec![(root, 0usize)];
    while let Some((j, depth)) = todo.pop() {
        let children = skeleton.children(j);
        let key = ui.make_persistent_id(("joint-collapsed", id, j));
        let mut collapsed = ui.data(|d| d.get_temp::<bool>(key)).unwrap_or(false);
        ui.horizontal(|ui| {
            ui.add_space(TREE_INDENT * depth.min(TREE_MAX_INDENT_LEVELS) as f32);
            if children.is_empty() {
                ui.add_space(TREE_TOGGLE_WIDTH);
            } else if ui
                .add_sized([TREE_TOGGLE_WIDTH, 16.0], egui::Button::new(if collapsed { "+" } else { "-" }).small())
                .on_hover_text(if collapsed { "show the joints below" } else { "hide the joints below" })
                .clicked()
            {
                collapsed = !collapsed;
                ui.data_mut(|d| d.insert_temp(key, collapsed));
            }
            let is_selected = selection.character == Some(id) && selection.joints.contains(&j);
            let label = format!("{} ({j})", skeleton.joint(j).name);
            if ui.selectable_label(is_selected, label).clicked() {
                super::picking::select_joint(selection, id, j, additive);
            }
        });
        if !collapsed {
            todo.extend(children.iter().rev().map(|&c| (c, depth + 1)));
        }
    }
}

/// Keyboard shortcuts in the viewport: S display mode, A axes, F frame selection,
/// Ctrl+Z / Ctrl+Shift+Z undo/redo, Ctrl+S / Ctrl+O save/open, F12 screenshot.
#[allow(clippy::too_many_arguments)]
pub fn shortcuts(
    keys: Res<ButtonInput<KeyCode>>,
    wants: Option<Res<bevy_egui::input::EguiWantsInput>>,
    selection: Res<Selection>,
    mut characters: Query<(&SceneCharacter, &Character, &mut DisplayMode, &Placement)>,
    joints: Query<&CurrentJointToWorld>,
    mut stage: ResMut<StageSettings>,
    mut history: ResMut<History>,
    mut cameras: Query<&mut OrbitCamera>,
    mut shot: ResMut<ScreenshotRequest>,
    state: Option<Res<InspectorState>>,
    snapshot: Option<Res<SceneSnapshot>>,
    mut pending: ResMut<PendingScene>,
    mut messages: ResMut<Messages>,
) {
    if wants.is_some_and(|w| w.wants_any_keyboard_input()) {
        return;
    }
    let ctrl = keys.any_pressed([KeyCode::ControlLeft, KeyCode::ControlRight, KeyCode::SuperLeft, KeyCode::SuperRight]);
    let shift = keys.any_pressed([KeyCode::ShiftLeft, KeyCode::ShiftRight]);
    if keys.just_pressed(KeyCode::F12) {
        shot.request();
    }
    if ctrl {
        if keys.just_pressed(KeyCode::KeyZ) {
            history.request = Some(if shift { HistoryRequest::Redo } else { HistoryRequest::Undo });
        }
        if let (Some(state), Some(snapshot)) = (&state, &snapshot) {
            if keys.just_pressed(KeyCode::KeyS) {
                save_scene(&state.scene_path, &snapshot.0, &mut messages);
            }
            if keys.just_pressed(KeyCode::KeyO) {
                open_scene(&state.scene_path, &mut pending, &mut messages);
            }
        }
        return;
    }
    if keys.just_pressed(KeyCode::KeyA) {
        stage.axes = !stage.axes;
    }
    let selected = characters.iter_mut().find(|c| Some(c.0.id) == selection.character);
    if keys.just_pressed(KeyCode::KeyS) {
        if let Some((_, _, mut display, _)) = selected {
            **display = display.next();
        } else {
            for (_, _, mut display, _) in &mut characters {
                **display = display.next();
            }
        }
    } else if keys.just_pressed(KeyCode::KeyF) {
        let points: Vec<Vec3> = characters
            .iter()
            .filter(|c| selection.character.is_none() || Some(c.0.id) == selection.character)
            .flat_map(|(_, character, _, placement)| {
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
        if !points.is_empty() {
            let lo = points.iter().fold(Vec3::splat(f32::INFINITY), |a, p| a.min(*p));
            let hi = points.iter().fold(Vec3::splat(f32::NEG_INFINITY), |a, p| a.max(*p));
            for mut orbit in &mut cameras {
                let framed = OrbitCamera::framing(lo, hi + Vec3::splat(0.15));
                orbit.focus = (lo + hi) / 2.0;
                orbit.distance = framed.distance.max(0.4);
            }
        }
    }
}

/// β sliders, clip list, timeline and blending of an SMPL body. Returns whether it edited.
fn smpl_panel(ui: &mut egui::Ui, body: &mut Mut<SmplCharacter>) -> bool {
    let mut edited = false;
    egui::CollapsingHeader::new("SMPL shape and motion").default_open(true).show(ui, |ui| {
        let mut betas = body.betas;
        for (b, beta) in betas.iter_mut().enumerate() {
            edited |= ui.add(egui::Slider::new(beta, -3.0..=3.0).text(format!("β{}", b + 1)).max_decimals(3)).changed();
        }
        if ui.small_button("Zero the shape").clicked() {
            betas = [0.0; 10];
            edited = true;
        }
        if betas != body.betas {
            body.betas = betas;
        }
        let names: Vec<String> = body
            .clips
            .iter()
            .map(|c| c.0.trim_start_matches("smpl_quaternions_").trim_end_matches(".txt").to_string())
            .collect();
        let mut clip = body.clip;
        clip_choice(ui, "clip", &names, &mut clip);
        if clip != body.clip {
            body.clip = clip;
            body.time = 0.0;
            edited = true;
        }
        if body.clip.is_some() {
            ui.horizontal(|ui| {
                let text = if body.playing { "Pause" } else { "Play" };
                if ui.button(text).clicked() {
                    body.playing = !body.playing;
                }
                let mut looping = body.looping;
                if ui.checkbox(&mut looping, "loop").changed() {
                    body.looping = looping;
                }
                let mut upright = body.upright;
                if ui.checkbox(&mut upright, "upright").changed() {
                    body.upright = upright;
                    edited = true;
                }
            });
            let last = body.clip_frames().saturating_sub(1) as f32;
            let mut t = body.time;
            if ui.add(egui::Slider::new(&mut t, 0.0..=last).text("frame").max_decimals(1)).changed() {
                body.time = t;
                edited = true;
            }
            let mut speed = body.speed;
            if ui.add(egui::Slider::new(&mut speed, 0.1..=3.0).text("speed")).changed() {
                body.speed = speed;
            }
            let mut second = body.blend_clip;
            clip_choice(ui, "blend with", &names, &mut second);
            if second != body.blend_clip {
                body.blend_clip = second;
                edited = true;
            }
            if body.blend_clip.is_some() {
                let mut blend = body.blend;
                if ui.add(egui::Slider::new(&mut blend, 0.0..=1.0).text("blend")).changed() {
                    body.blend = blend;
                    edited = true;
                }
            }
        }
    });
    edited
}

/// A drop-down of clip names (or none).
fn clip_choice(ui: &mut egui::Ui, label: &str, names: &[String], choice: &mut Option<usize>) {
    let shown = choice.map_or("(none)".to_string(), |i| names[i].clone());
    egui::ComboBox::from_label(label).selected_text(shown).show_ui(ui, |ui| {
        ui.selectable_value(choice, None, "(none)");
        for (i, n) in names.iter().enumerate() {
            ui.selectable_value(choice, Some(i), n);
        }
    });
}

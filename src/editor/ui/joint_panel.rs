//! The joint panel: one slider per DOF of the selected joints within their limits, resets,
//! and the joint tree.

use crate::editor::edits::kinds;
use bevy_egui::egui;

use super::{InspectorState, Panels};
use crate::editor::state::Selection;
use crate::formats::scene::CharacterId;
use crate::rig::{EulerOrder, JointRotation, Skeleton};
use crate::scene::Character;

const AXES: [&str; 3] = ["X", "Y", "Z"];

pub fn joint_panel(ui: &mut egui::Ui, state: &mut InspectorState, panels: &mut Panels) {
    ui.heading("Joints");
    let Some(id) = panels.selection.character else {
        ui.label("Select a character (left panel) or click a joint in the viewport.");
        return;
    };
    let Some(character) = panels.scene.characters.iter().find(|c| c.scene.id == id).map(|c| c.character) else {
        return;
    };
    let character = character.clone();
    let skeleton = &character.asset.skeleton;
    let mut edits = Vec::new();
    ui.horizontal(|ui| {
        if ui.button("Reset the whole pose").on_hover_text("to the pose the file gives").clicked() {
            let joints = skeleton.joints().iter().enumerate().map(|(j, def)| (j, def.initial_rotation)).collect();
            edits.push(kinds::Pose { character: id, joints });
        }
        if ui.button("Rest").on_hover_text("every joint unturned (within its limits)").clicked() {
            let joints = (0..skeleton.len()).map(|j| (j, JointRotation::IDENTITY)).collect();
            edits.push(kinds::Pose { character: id, joints });
        }
    });
    ui.separator();
    for &j in &panels.selection.joints {
        if let Some(rotation) = joint_sliders(ui, state, panels, &character, j) {
            edits.push(kinds::Pose { character: id, joints: vec![(j, rotation)] });
        }
        ui.separator();
    }
    edits.into_iter().for_each(|e| panels.push(e));
    super::keyframe_panel::keyframe_panel(ui, state, panels, id);
    super::pose_panel::pose_panel(ui, state, panels, id);
    ui.separator();
    let additive = ui.input(|i| i.modifiers.shift || i.modifiers.command || i.modifiers.ctrl);
    joint_tree(ui, skeleton, 0, id, &mut panels.selection, additive);
}

/// The sliders of joint `j` (a locked axis greyed out) and its reset; returns the joint's
/// new rotation when one was moved.
fn joint_sliders(
    ui: &mut egui::Ui,
    state: &mut InspectorState,
    panels: &Panels,
    character: &Character,
    j: usize,
) -> Option<JointRotation> {
    let def = character.asset.skeleton.joints().get(j)?;
    let pose = panels.scene.poses.get(*character.joints.get(j)?).ok()?.0;
    let name = &def.name;
    ui.label(egui::RichText::new(name).strong());
    let (mut angles, order) = match pose {
        JointRotation::Euler(a, order) => (a, order),
        JointRotation::Quat(_) => (pose.to_euler(EulerOrder::Xyz), EulerOrder::Xyz),
    };
    let mut changed = false;
    for axis in 0..3 {
        let (lo, hi) = def.limits.display_range(axis);
        let slider = egui::Slider::new(&mut angles[axis], lo..=hi.max(lo))
            .text(format!("{name} {}", AXES[axis]))
            .max_decimals(3)
            .clamping(egui::SliderClamping::Edits);
        let response = ui.add_enabled(!def.limits.is_locked(axis), slider);
        changed |= response.changed();
        if response.dragged() || response.has_focus() {
            state.active_dof = Some(format!("{name} {} = {:.3}", AXES[axis], angles[axis]));
        }
    }
    if ui.small_button("Reset joint").clicked() {
        return Some(def.initial_rotation);
    }
    changed.then(|| match pose {
        JointRotation::Euler(..) => JointRotation::Euler(angles, order),
        JointRotation::Quat(_) => JointRotation::Quat(JointRotation::Euler(angles, EulerOrder::Xyz).to_quat()),
    })
}

/// Indentation of one tree level, and the deepest level indented further.
const TREE_INDENT: f32 = 12.0;
const TREE_MAX_INDENT_LEVELS: usize = 24;
/// Width of the collapse toggle (and of the space leaves keep in its place).
const TREE_TOGGLE_WIDTH: f32 = 14.0;

/// The joint tree as indented rows, collapsible per joint (+/-); a click selects,
/// Shift/Ctrl-click adds. Walked with an explicit stack, so any depth shows.
fn joint_tree(
    ui: &mut egui::Ui,
    skeleton: &Skeleton,
    root: usize,
    id: CharacterId,
    selection: &mut Selection,
    additive: bool,
) {
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
                crate::editor::interact::picking::select_joint(selection, id, j, additive);
            }
        });
        if !collapsed {
            todo.extend(children.iter().rev().map(|&c| (c, depth + 1)));
        }
    }
}

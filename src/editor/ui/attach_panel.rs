//! Holding a prop in a joint: attach the selected character to a joint of another one, or
//! let it go where it stands.

use crate::editor::edits::kinds;
use bevy::prelude::*;
use bevy_egui::egui;

use super::Panels;
use crate::editor::edits::edit::Edit;
use crate::editor::scene_doc::attach::holding_joint_world;
use crate::formats::scene::{AttachDoc, CharacterId, pose_key};

/// The holder and joint chosen in the panel before "Attach" is pressed.
#[derive(Clone, Default)]
struct Choice {
    holder: Option<CharacterId>,
    joint: usize,
}

/// "Held by …" with Detach, or a holder, one of its joints and Attach (the edits to push).
pub fn attach_rows(ui: &mut egui::Ui, panels: &Panels, entity: Entity, id: CharacterId) -> Option<Edit> {
    let c = panels.scene.characters.get(entity).ok()?;
    if let Some(attached) = c.attached {
        let holder = panels.scene.characters.iter().find(|h| h.scene.id == attached.to);
        let name = holder.map_or_else(|| format!("character {}", attached.to), |h| h.scene.name.clone());
        let mut edit = None;
        ui.horizontal(|ui| {
            ui.label(format!("Held by {name}, joint {}", attached.joint));
            if ui.button("Detach").on_hover_text("let go: it stays where it is").clicked() {
                edit = Some(Edit::from(kinds::Attach { character: id, attached: None, placement: c.placement.0 }));
            }
        });
        return edit;
    }
    let memory = egui::Id::new(("attach choice", id.0));
    let mut choice: Choice = ui.data(|d| d.get_temp(memory)).unwrap_or_default();
    let others: Vec<_> = panels.scene.characters.iter().filter(|h| h.scene.id != id).collect();
    if others.is_empty() {
        return None;
    }
    let holder = others.iter().find(|h| Some(h.scene.id) == choice.holder).unwrap_or(&others[0]);
    choice.holder = Some(holder.scene.id);
    let skeleton = &holder.character.asset.skeleton;
    choice.joint = choice.joint.min(skeleton.len() - 1);
    let mut attach = false;
    ui.horizontal(|ui| {
        ui.label("Attach to");
        egui::ComboBox::from_id_salt(("attach holder", id.0)).selected_text(&holder.scene.name).show_ui(ui, |ui| {
            for h in &others {
                ui.selectable_value(&mut choice.holder, Some(h.scene.id), &h.scene.name);
            }
        });
        egui::ComboBox::from_id_salt(("attach joint", id.0))
            .selected_text(&skeleton.joint(choice.joint).name)
            .height(300.0)
            .show_ui(ui, |ui| {
                for (j, joint) in skeleton.joints().iter().enumerate() {
                    ui.selectable_value(&mut choice.joint, j, &joint.name);
                }
            });
        attach = ui.button("Attach").on_hover_text("it follows the joint from where it stands now").clicked();
    });
    ui.data_mut(|d| d.insert_temp(memory, choice.clone()));
    if !attach {
        return None;
    }
    let key = pose_key(skeleton, choice.joint);
    let joint_world = holding_joint_world((holder.character, holder.placement), &key, &panels.joint_matrices)?;
    let attached = AttachDoc::holding(holder.scene.id, key, joint_world, &c.placement.0);
    Some(Edit::from(kinds::Attach { character: id, attached: Some(attached), placement: c.placement.0 }))
}

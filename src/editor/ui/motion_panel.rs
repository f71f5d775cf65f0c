//! Another humanoid's motion on the selected character ("Play the motion of …", baking it
//! into keys), and its humanoid map, a row per standard bone.

use crate::editor::edits::kinds;
use bevy::prelude::*;
use bevy_egui::egui;

use super::Panels;
use crate::editor::edits::edit::Edit;
use crate::formats::scene::{AnimDoc, CharacterId, MotionSourceDoc, RetargetDoc, pose_key};
use crate::rig::humanoid::HumanBone;
use crate::rig::retarget::RestAlignment;

/// The source and settings chosen before "Play" is pressed.
#[derive(Clone)]
struct Choice {
    source: Option<CharacterId>,
    file: String,
    clip: String,
    rest: RestAlignment,
    plant_feet: bool,
}

impl Default for Choice {
    fn default() -> Self {
        Self {
            source: None,
            file: String::new(),
            clip: String::new(),
            rest: RestAlignment::Directions,
            plant_feet: true,
        }
    }
}

/// The retargeting the character plays (its report, "Bake into keys", "Stop"), and the
/// rows that start one: the edits to push.
pub fn motion_rows(ui: &mut egui::Ui, panels: &Panels, entity: Entity, id: CharacterId) -> Option<Edit> {
    let c = panels.scene.characters.get(entity).ok()?;
    let mut edit = None;
    egui::CollapsingHeader::new("Motion of another character").default_open(false).show(ui, |ui| {
        if let Some(player) = c.player
            && let (None, Some(settings)) = (&player.state.keys, &player.state.retarget)
        {
            ui.label(format!("Plays the motion of {}", source_label(panels, &settings.from)));
            if let Some(done) = c.retargeted {
                ui.label(egui::RichText::new(&done.report).small());
            }
            ui.horizontal(|ui| {
                if ui.button("Bake into keys").on_hover_text("the clip becomes this character's own keys").clicked() {
                    let keys = Some((*player.clip).clone());
                    edit = Some(Edit::from(kinds::Clip {
                        character: id,
                        anim: Some(AnimDoc { keys, retarget: None, ..player.state.clone() }),
                    }));
                }
                if ui.button("Stop").clicked() {
                    edit = Some(Edit::from(kinds::Clip { character: id, anim: None }));
                }
            });
        }
        edit = edit.take().or_else(|| start_rows(ui, panels, id));
    });
    edit
}

/// "Play the motion of" a character or a file, rests, feet, and Play.
fn start_rows(ui: &mut egui::Ui, panels: &Panels, id: CharacterId) -> Option<Edit> {
    let memory = egui::Id::new(("motion choice", id.0));
    let others: Vec<_> = panels.scene.characters.iter().filter(|h| h.scene.id != id).collect();
    let mut choice: Choice = ui
        .data(|d| d.get_temp(memory))
        .unwrap_or_else(|| Choice { source: others.first().map(|h| h.scene.id), ..Choice::default() });
    let name_of = |c: Option<CharacterId>| {
        others.iter().find(|h| Some(h.scene.id) == c).map_or("a file:".to_string(), |h| h.scene.name.clone())
    };
    let mut play = false;
    ui.horizontal(|ui| {
        ui.label("Play the motion of");
        egui::ComboBox::from_id_salt(("motion source", id.0)).selected_text(name_of(choice.source)).show_ui(ui, |ui| {
            for h in &others {
                ui.selectable_value(&mut choice.source, Some(h.scene.id), &h.scene.name);
            }
            ui.selectable_value(&mut choice.source, None, "a file:");
        });
    });
    if choice.source.is_none() {
        ui.horizontal(|ui| {
            ui.add(
                egui::TextEdit::singleline(&mut choice.file)
                    .hint_text("a .glb, .bvh or SMPL folder")
                    .desired_width(180.0),
            );
            ui.add(egui::TextEdit::singleline(&mut choice.clip).hint_text("clip").desired_width(60.0));
        });
    }
    ui.horizontal(|ui| {
        ui.radio_value(&mut choice.rest, RestAlignment::Directions, "bones point as the source's")
            .on_hover_text("a T-pose clip lifts an A-pose character's arms where it lifts them");
        ui.radio_value(&mut choice.rest, RestAlignment::OwnRest, "from rest to rest")
            .on_hover_text("the source's rest pose gives this character its own rest pose");
    });
    ui.horizontal(|ui| {
        ui.checkbox(&mut choice.plant_feet, "keep planted feet planted");
        play = ui.button("Play").clicked();
    });
    ui.data_mut(|d| d.insert_temp(memory, choice.clone()));
    if !play {
        return None;
    }
    let from = match choice.source {
        Some(source) => MotionSourceDoc::Character(source),
        None if !choice.file.trim().is_empty() => MotionSourceDoc::File {
            path: choice.file.trim().into(),
            clip: Some(choice.clip.trim().to_string()).filter(|c| !c.is_empty()),
        },
        None => return None,
    };
    let retarget = Some(RetargetDoc { from, rest: choice.rest, plant_feet: choice.plant_feet });
    Some(Edit::from(kinds::Clip { character: id, anim: Some(AnimDoc { retarget, ..AnimDoc::default() }) }))
}

/// A motion source as the panel names it.
fn source_label(panels: &Panels, from: &MotionSourceDoc) -> String {
    match from {
        MotionSourceDoc::Character(id) => panels
            .scene
            .characters
            .iter()
            .find(|c| c.scene.id == *id)
            .map_or_else(|| format!("character {id} (not in the scene)"), |c| c.scene.name.clone()),
        MotionSourceDoc::File { path, clip } => {
            format!("{}{}", path.display(), clip.as_ref().map(|c| format!(", clip {c}")).unwrap_or_default())
        }
    }
}

/// A row per standard bone: the joint it is (found from the skeleton, or assigned), a
/// choice of any joint or none. Returns the edit that assigns a changed one.
pub fn humanoid_rows(ui: &mut egui::Ui, panels: &Panels, entity: Entity, id: CharacterId) -> Option<Edit> {
    let c = panels.scene.characters.get(entity).ok()?;
    let assigned = c.humanoid.map(|h| h.0.clone()).unwrap_or_default();
    let skeleton = &c.character.asset.skeleton;
    let map = c.humanoid_map.map(|m| m.0.clone()).unwrap_or_default();
    let mut edit = None;
    egui::CollapsingHeader::new(format!("Humanoid map ({} of {} bones)", map.len(), HumanBone::ALL.len()))
        .default_open(false)
        .show(ui, |ui| {
            egui::Grid::new(("humanoid", id.0)).num_columns(2).show(ui, |ui| {
                for bone in HumanBone::ALL {
                    let now = map.get(&bone).copied();
                    let mut chosen = now;
                    ui.label(format!("{bone:?}"));
                    let shown = now.map_or("—".to_string(), |j| skeleton.joint(j).name.clone());
                    egui::ComboBox::from_id_salt(("bone", id.0, bone as usize))
                        .selected_text(shown)
                        .height(300.0)
                        .show_ui(ui, |ui| {
                            ui.selectable_value(&mut chosen, None, "—");
                            for (j, joint) in skeleton.joints().iter().enumerate() {
                                ui.selectable_value(&mut chosen, Some(j), &joint.name);
                            }
                        });
                    ui.end_row();
                    if chosen != now {
                        let mut bones = assigned.clone();
                        bones.insert(bone, chosen.map_or_else(String::new, |j| pose_key(skeleton, j)));
                        edit = Some(Edit::from(kinds::Humanoid { character: id, bones }));
                    }
                }
            });
        });
    edit
}

//! The pose section of the joint panel: copy the selected character's pose (or its
//! selected joints'), paste it on any character (by joint names, or through the humanoid
//! maps), as it was or mirrored; keep poses in the scene's library with a thumbnail, apply
//! or remove them.

use crate::editor::edits::kinds;
use bevy_egui::egui;

use super::{InspectorState, Panels};
use crate::editor::edits::pose_library::{
    apply_named_pose, body_pose_edits, body_pose_thumbnails, flip_edit, library_pose, pose_by_name,
};
use crate::formats::scene::{CharacterId, LibraryPoseDoc};
use crate::rig::JointRotation;

const THUMBNAIL: f32 = 56.0;

pub fn pose_panel(ui: &mut egui::Ui, state: &mut InspectorState, panels: &mut Panels, id: CharacterId) {
    let Some(c) = panels.scene.characters.iter().find(|c| c.scene.id == id) else {
        return;
    };
    let (character, source) = (c.character.clone(), c.scene.source.clone());
    let map = c.humanoid_map.map(|m| m.0.clone()).unwrap_or_default();
    let skeleton = &character.asset.skeleton;
    let pose: Vec<JointRotation> =
        character.joints.iter().map(|&e| panels.scene.poses.get(e).map_or(Default::default(), |p| p.0)).collect();
    let positions: Vec<glam::Vec3> = character
        .joints
        .iter()
        .map(|&e| panels.joint_matrices.get(e).map_or(glam::Vec3::ZERO, |m| m.position()))
        .collect();
    let selected = panels.selection.joints.clone();
    let target = (skeleton, &map, &pose[..]);
    let mut edits = Vec::new();
    egui::CollapsingHeader::new("Body poses").default_open(true).show(ui, |ui| {
        if map.contains_key(&crate::rig::humanoid::HumanBone::Hips) {
            let placement = c.placement.0;
            fit_row(ui, state, id);
            body_poses(ui, state, &mut panels.posing, &mut edits, id, (&character.asset, &map, &pose), placement);
        } else {
            ui.label("No humanoid map (hips, two legs): assign bones under Retarget.");
        }
    });
    if map.keys().any(|b| b.is_finger()) {
        egui::CollapsingHeader::new("Hands").default_open(false).show(ui, |ui| {
            for left in [true, false] {
                hand(ui, &mut state.hand_shapes[usize::from(!left)], &mut edits, id, (skeleton, &map, &pose), left);
            }
        });
    }
    egui::CollapsingHeader::new("Poses").default_open(false).show(ui, |ui| {
        ui.horizontal(|ui| {
            if ui.button("Copy").on_hover_text("the selected joints' rotations (all when none)").clicked() {
                state.copied_pose = pose_by_name(skeleton, &pose, &selected);
                state.copied_rig = Some((character.asset.clone(), map.clone()));
            }
            let any = !state.copied_pose.is_empty();
            let from = state.copied_rig.as_ref().map(|(asset, map)| (&asset.skeleton, map));
            if ui.add_enabled(any, egui::Button::new("Paste")).clicked() {
                edits.extend(apply_named_pose(id, target, &state.copied_pose, from, false));
            }
            if ui.add_enabled(any, egui::Button::new("Paste mirrored")).clicked() {
                edits.extend(apply_named_pose(id, target, &state.copied_pose, from, true));
            }
        });
        ui.horizontal(|ui| {
            ui.add(egui::TextEdit::singleline(&mut state.pose_name).desired_width(120.0));
            if ui.button("Keep pose").on_hover_text("in the scene's library under this name").clicked()
                && !state.pose_name.trim().is_empty()
            {
                let mut kept = library_pose(skeleton, &positions, pose_by_name(skeleton, &pose, &selected));
                kept.rig = Some(source.clone());
                edits.push(kinds::Library { name: state.pose_name.trim().to_string(), pose: Some(kept) }.into());
            }
        });
        let kept_rigs: Vec<_> = panels
            .scene
            .pose_library
            .0
            .values()
            .map(|kept| kept.rig.as_ref().and_then(|rig| panels.library.rig(rig).ok()))
            .collect();
        for ((name, kept), rig) in panels.scene.pose_library.0.iter().zip(&kept_rigs) {
            let from = rig.as_ref().map(|(a, m)| (&a.skeleton, &**m));
            ui.horizontal(|ui| {
                thumbnail(ui, kept);
                ui.vertical(|ui| {
                    ui.label(format!("{name} ({} joints)", kept.joints.len()));
                    ui.horizontal(|ui| {
                        let named: Vec<(String, JointRotation)> = kept.joints.clone().into_iter().collect();
                        if ui.small_button("Apply").clicked() {
                            edits.extend(apply_named_pose(id, target, &named, from, false));
                        }
                        if ui.small_button("Mirrored").clicked() {
                            edits.extend(apply_named_pose(id, target, &named, from, true));
                        }
                        if ui.small_button("Remove").clicked() {
                            edits.push(kinds::Library { name: name.clone(), pose: None }.into());
                        }
                    });
                });
            });
        }
    });
    edits.into_iter().for_each(|e| panels.push(e));
}

/// The "Fit to keypoints…" button (the file dialog, then [`super::fit::fit_to_keypoints`])
/// and, while the file's points are shown, the one that hides them.
fn fit_row(ui: &mut egui::Ui, state: &mut InspectorState, id: CharacterId) {
    ui.horizontal(|ui| {
        let hint = "a pose detector's keypoints (OpenPose JSON, COCO, DWPose): this character posed and the \
                    camera placed to match them; the picture beside the file shown behind. One undo step.";
        if ui.button("Fit to keypoints…").on_hover_text(hint).clicked() {
            let near = state.add_path.clone();
            state.dialogs.open(super::dialogs::DialogPurpose::FitKeypoints(id), &near);
        }
        if state.keypoints.is_some() && ui.button("Hide keypoints").clicked() {
            state.keypoints = None;
        }
    });
}

/// The built-in body poses as a grid of thumbnails to click, with the blend, mirrored,
/// flip and symmetry.
fn body_poses(
    ui: &mut egui::Ui,
    state: &mut InspectorState,
    posing: &mut super::PosingTools,
    edits: &mut Vec<crate::editor::edits::edit::Edit>,
    id: CharacterId,
    target: (&crate::rig::CharacterAsset, &crate::rig::humanoid::HumanoidMap, &[JointRotation]),
    placement: crate::formats::scene::PlacementDoc,
) {
    let (asset, map, pose) = target;
    ui.horizontal(|ui| {
        ui.add(egui::Slider::new(&mut state.body_blend, 0.0..=1.0).text("blend"))
            .on_hover_text("how far from the pose now to the one clicked");
        ui.checkbox(&mut state.body_mirrored, "mirrored");
    });
    ui.horizontal(|ui| {
        if ui.button("Flip pose").on_hover_text("left and right swapped, through the humanoid map").clicked() {
            edits.extend(flip_edit(id, &asset.skeleton, map, pose));
        }
        if let Some(symmetry) = posing.symmetry.as_deref_mut() {
            ui.checkbox(&mut symmetry.0, "Symmetry").on_hover_text("a joint turned on one side turns its twin");
        }
        if let Some(handles) = posing.handles.as_deref_mut() {
            let mut shown = handles.handles.iter().any(|h| h.character() == id);
            let hint = "targets and poles for the arms and legs, a point the head looks at: drag them";
            if ui.checkbox(&mut shown, "Limb handles").on_hover_text(hint).changed() {
                handles.handles.retain(|h| h.character() != id);
                handles.dragged = None;
                if shown {
                    handles.handles.extend(limb_handles(id, target, placement));
                }
            }
        }
    });
    if state.body_thumbnails.as_ref().is_none_or(|(of, drawn_with, _)| *of != id || drawn_with != map) {
        state.body_thumbnails = Some((id, map.clone(), body_pose_thumbnails(&asset.skeleton, map)));
    }
    let Some((.., thumbnails)) = &state.body_thumbnails else { return };
    let mut clicked = None;
    egui::Grid::new("body poses").spacing(egui::vec2(4.0, 4.0)).show(ui, |ui| {
        for (k, (body, kept)) in crate::rig::body_poses::POSES.iter().zip(thumbnails).enumerate() {
            if thumbnail(ui, kept).on_hover_text(body.name).clicked() {
                clicked = Some(body.name);
            }
            if k % 5 == 4 {
                ui.end_row();
            }
        }
    });
    if let Some(name) = clicked {
        let spec = crate::document::posing::BodyPoseSpec::new(name, state.body_mirrored);
        edits.extend(body_pose_edits(id, target, placement, &spec, state.body_blend).into_iter().flatten());
    }
}

/// One hand's presets, its curl and spread, and each finger's: a change poses the hand's
/// fingers (one pose edit; a slider's drag is one undo step).
fn hand(
    ui: &mut egui::Ui,
    shape: &mut crate::rig::hands::HandShape,
    edits: &mut Vec<crate::editor::edits::edit::Edit>,
    id: CharacterId,
    target: (&crate::rig::Skeleton, &crate::rig::humanoid::HumanoidMap, &[JointRotation]),
    left: bool,
) {
    use crate::rig::hands::{HandShape, PRESETS};
    let (skeleton, map, pose) = target;
    let before = *shape;
    ui.label(if left { "Left hand" } else { "Right hand" });
    ui.horizontal_wrapped(|ui| {
        for (name, ..) in PRESETS {
            if ui.small_button(name).clicked() {
                *shape = HandShape::preset(name).unwrap_or_default();
            }
        }
    });
    let mut curl = shape.curl.iter().sum::<f32>() / 5.0;
    let mut spread = (shape.fan[1] - shape.fan[3]) / 2.0;
    ui.horizontal(|ui| {
        if ui.add(egui::Slider::new(&mut curl, 0.0..=1.6).text("curl")).changed() {
            shape.curl = [curl; 5];
        }
        if ui.add(egui::Slider::new(&mut spread, -0.3..=0.4).text("spread")).changed() {
            shape.fan = HandShape::of_preset(shape.curl, spread).fan;
        }
    });
    egui::Grid::new(("fingers", left)).show(ui, |ui| {
        for (f, name) in ["thumb", "index", "middle", "ring", "little"].iter().enumerate() {
            ui.label(*name);
            ui.add(egui::Slider::new(&mut shape.curl[f], 0.0..=1.6).text("curl"));
            ui.add(egui::Slider::new(&mut shape.fan[f], -0.6..=0.6).text("spread"));
            ui.end_row();
        }
    });
    if *shape != before {
        let mut posed = pose.to_vec();
        crate::rig::hands::apply_hand_shape(skeleton, map, &mut posed, left, *shape);
        edits.extend(crate::editor::edits::kinds::Pose::change(id, pose, &posed).map(Into::into));
    }
}

/// The limb handles of a character where it stands.
fn limb_handles(
    id: CharacterId,
    target: (&crate::rig::CharacterAsset, &crate::rig::humanoid::HumanoidMap, &[JointRotation]),
    placement: crate::formats::scene::PlacementDoc,
) -> Vec<crate::editor::state::LimbHandle> {
    let (asset, map, pose) = target;
    let skeleton = &asset.skeleton;
    let placed = placement.to_mat4();
    let mut world = vec![glam::Mat4::IDENTITY; skeleton.len()];
    crate::rig::fk::forward_kinematics(skeleton, pose, placed, &mut world);
    let frame = crate::rig::body_poses::facing_frame(skeleton, map).unwrap_or_default();
    let ahead = placed.transform_vector3(frame * glam::Vec3::Z).normalize_or(glam::Vec3::Z);
    crate::editor::interact::limb_handles::handles_of(id, skeleton, map, ahead, |j| world[j].w_axis.truncate())
}

/// The pose's stick figure (clickable).
fn thumbnail(ui: &mut egui::Ui, pose: &LibraryPoseDoc) -> egui::Response {
    let (response, painter) = ui.allocate_painter(egui::vec2(THUMBNAIL, THUMBNAIL), egui::Sense::click());
    let rect = response.rect;
    painter.rect_filled(rect, 3.0, egui::Color32::from_gray(28));
    let at = |x: f32, y: f32| egui::pos2(rect.left() + x * rect.width(), rect.bottom() - y * rect.height());
    for s in &pose.thumbnail {
        painter.line_segment(
            [at(s[0], s[1]), at(s[2], s[3])],
            egui::Stroke::new(1.5, egui::Color32::from_rgb(235, 225, 200)),
        );
    }
    response
}

//! File dialogs drawn by egui (`egui-file-dialog`: no desktop portal needed, so they work
//! under Xvfb too): open and save the scene, add a character or clip, export glTF, pick
//! the screenshot folder.

use std::path::Path;

use bevy_egui::egui;
use egui_file_dialog::FileDialog;

use super::{InspectorState, Panels};
use crate::editor::present::screenshot::ScreenshotRequest;

/// What the open dialog is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DialogPurpose {
    OpenScene,
    SaveScene,
    /// A character file, a clip for the selected character or a scene.
    AddFile,
    ExportGltf,
    ScreenshotFolder,
    /// A keypoint file to fit this character to.
    FitKeypoints(crate::formats::scene::CharacterId),
}

/// The file dialog and what it was opened for.
pub struct FileDialogs {
    dialog: FileDialog,
    purpose: Option<DialogPurpose>,
}

impl Default for FileDialogs {
    fn default() -> Self {
        Self { dialog: FileDialog::new(), purpose: None }
    }
}

impl FileDialogs {
    /// Opens the dialog for `purpose`, starting in `near` when it is a folder, else in
    /// its folder.
    pub fn open(&mut self, purpose: DialogPurpose, near: &str) {
        let near = Path::new(near);
        let folder =
            if near.is_dir() { Some(near) } else { near.parent().filter(|d| d.is_dir()) }.map(Path::to_path_buf);
        let (title, name) = match purpose {
            DialogPurpose::OpenScene => ("Open a scene", None),
            DialogPurpose::SaveScene => ("Save the scene", Some("scene.ron")),
            DialogPurpose::AddFile => ("Add a character, a clip or a scene", None),
            DialogPurpose::ExportGltf => ("Export the scene as glTF", Some("scene.glb")),
            DialogPurpose::ScreenshotFolder => ("Screenshot folder", None),
            DialogPurpose::FitKeypoints(_) => ("Fit to a keypoint file", None),
        };
        let mut dialog = FileDialog::new().title(title);
        if let Some(folder) = folder {
            dialog = dialog.initial_directory(folder);
        }
        if let Some(name) = name {
            dialog = dialog.default_file_name(name);
        }
        match purpose {
            DialogPurpose::SaveScene | DialogPurpose::ExportGltf => dialog.save_file(),
            DialogPurpose::ScreenshotFolder => dialog.pick_directory(),
            DialogPurpose::OpenScene | DialogPurpose::AddFile | DialogPurpose::FitKeypoints(_) => dialog.pick_file(),
        }
        self.dialog = dialog;
        self.purpose = Some(purpose);
    }
}

/// Draws the dialog while one is open and does what it was opened for once a path is
/// picked.
pub fn show(ctx: &egui::Context, state: &mut InspectorState, panels: &mut Panels, shot: &mut ScreenshotRequest) {
    let Some(purpose) = state.dialogs.purpose else { return };
    state.dialogs.dialog.update(ctx);
    let Some(path) = state.dialogs.dialog.take_picked() else { return };
    state.dialogs.purpose = None;
    let text = path.to_string_lossy().into_owned();
    match purpose {
        DialogPurpose::OpenScene => {
            state.scene_path = text.clone();
            if let Some(recent) = panels.recent.as_mut() {
                recent.remember(&text);
            }
            crate::editor::scene_doc::document::open_scene_from(&text, &mut panels.pending, &mut panels.messages);
        }
        DialogPurpose::SaveScene => {
            state.scene_path = text.clone();
            crate::editor::scene_doc::document::save_scene_to(
                &text,
                &panels.scene.capture(),
                &mut panels.messages,
                &mut panels.saved,
            );
        }
        DialogPurpose::AddFile => super::open::open_path(&text, state, panels),
        DialogPurpose::ExportGltf => export_gltf(&path, panels),
        DialogPurpose::ScreenshotFolder => shot.dir_text = text,
        DialogPurpose::FitKeypoints(id) => super::fit::fit_to_keypoints(&path, id, state, panels),
    }
}

/// Writes the scene as it is to `path` as glTF, saying so in the messages.
fn export_gltf(path: &Path, panels: &mut Panels) {
    let doc = panels.scene.capture();
    let written = crate::document::export::scene_glb(&doc, crate::formats::gltf::GltfMesh::Skinned, true)
        .map_err(|e| e.to_string())
        .and_then(|glb| {
            crate::formats::write_atomically(path, |w| std::io::Write::write_all(w, &glb)).map_err(|e| e.to_string())
        });
    panels.messages.push(match written {
        Ok(()) => format!("exported the scene to {}", path.display()),
        Err(e) => format!("{}: the scene was not exported: {e}", path.display()),
    });
}

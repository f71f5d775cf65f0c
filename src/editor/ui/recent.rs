//! Recently opened files, kept between sessions: one path per line in `recent.txt` of the
//! user's config folder (`$MARIONETTE_CONFIG_DIR`, else `$XDG_CONFIG_HOME/marionette`, else
//! `~/.config/marionette`). Only the editor's window app keeps them; apps without a
//! [`RecentFilesStore`] (the tests, the renderer) remember nothing on disk.

use std::path::{Path, PathBuf};

use bevy::prelude::*;

use crate::editor::state::Messages;

/// How many recent files are kept.
pub const KEPT: usize = 8;

/// Where the recent files are kept (none: nowhere).
#[derive(Resource, Clone, Debug)]
pub struct RecentFilesStore(pub PathBuf);

impl RecentFilesStore {
    /// The user's file, where the environment names a config folder.
    pub fn for_user() -> Option<Self> {
        let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty()).map(PathBuf::from);
        let dir = var("MARIONETTE_CONFIG_DIR")
            .or_else(|| var("XDG_CONFIG_HOME").map(|d| d.join("marionette")))
            .or_else(|| var("HOME").map(|d| d.join(".config/marionette")))?;
        Some(Self(dir.join("recent.txt")))
    }
}

/// The recently opened files, most recent first (the panel's "Recent" row).
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct RecentFiles(pub Vec<String>);

impl RecentFiles {
    /// `path` first, once, at most [`KEPT`] kept.
    pub fn remember(&mut self, path: &str) {
        remember(&mut self.0, path);
    }
}

/// `path` first among `recent`, once, at most [`KEPT`] kept.
pub fn remember(recent: &mut Vec<String>, path: &str) {
    recent.retain(|r| r != path);
    recent.insert(0, path.to_string());
    recent.truncate(KEPT);
}

/// The list in `file` (empty when there is none).
pub fn read_recent(file: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(file).unwrap_or_default();
    text.lines().filter(|l| !l.trim().is_empty()).take(KEPT).map(str::to_string).collect()
}

/// Writes the list to `file` whole (its folder made when missing).
pub fn write_recent(file: &Path, recent: &[String]) -> std::io::Result<()> {
    if let Some(dir) = file.parent() {
        std::fs::create_dir_all(dir)?;
    }
    crate::formats::write_atomically(file, |w| {
        use std::io::Write;
        recent.iter().try_for_each(|r| writeln!(w, "{r}"))
    })
}

/// Keeps the recent files of the window app.
pub struct RecentFilesPlugin;

impl Plugin for RecentFilesPlugin {
    fn build(&self, app: &mut App) {
        if let Some(store) = RecentFilesStore::for_user() {
            app.insert_resource(store);
        }
        app.init_resource::<RecentFiles>().add_systems(Startup, load_recent_files).add_systems(Last, save_recent_files);
    }
}

/// Fills the list from the store (reads `RecentFilesStore`; writes `RecentFiles`).
fn load_recent_files(store: Option<Res<RecentFilesStore>>, mut recent: ResMut<RecentFiles>) {
    if let Some(store) = store {
        recent.0 = read_recent(&store.0);
    }
}

/// Writes the list when it changed (reads `RecentFiles`; a failure is a message).
fn save_recent_files(
    store: Option<Res<RecentFilesStore>>,
    recent: Res<RecentFiles>,
    mut saved: Local<Option<Vec<String>>>,
    mut messages: ResMut<Messages>,
) {
    let Some(store) = store else { return };
    if saved.as_ref() == Some(&recent.0) {
        return;
    }
    if saved.is_some()
        && let Err(e) = write_recent(&store.0, &recent.0)
    {
        messages.push(format!("{}: the recent files were not kept: {e}", store.0.display()));
    }
    *saved = Some(recent.0.clone());
}

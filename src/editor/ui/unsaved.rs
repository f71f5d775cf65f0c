//! Never losing a user's work: the window title says whether the scene differs from its
//! file (`name *`); closing the window, or opening or dropping another scene, with unsaved
//! changes asks Save / Don't save / Cancel; while changes are unsaved the scene is written every so often (two minutes,
//! `MARIONETTE_AUTOSAVE_SECONDS`; 0 turns it off) to the user's recovery folder, whole or
//! not at all, on another thread; a clean close removes it, and a panic writes the newest
//! state there before the process ends. On start, what sessions that did not close
//! cleanly left there is offered (Recover / Discard / Later); `marionette edit --recover`
//! opens the newest.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use bevy::prelude::*;
use bevy::window::{PrimaryWindow, WindowCloseRequested};
use bevy_egui::{EguiContexts, EguiPrimaryContextPass, egui};

use crate::editor::edits::history::History;
use crate::editor::present::redraw::WakeWithin;
use crate::editor::scene_doc::document::{PendingScene, SceneReader, save_scene_to};
use crate::editor::state::{Messages, SavedState};
use crate::editor::ui::InspectorState;

/// How often the scene is autosaved while it has unsaved changes, unless
/// `MARIONETTE_AUTOSAVE_SECONDS` says otherwise.
pub const AUTOSAVE_EVERY: Duration = Duration::from_secs(120);

pub struct UnsavedWorkPlugin;

impl Plugin for UnsavedWorkPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<UnsavedQuestion>()
            .init_resource::<crate::editor::state::SavedState>()
            .insert_resource(Autosave::from_env())
            .add_systems(Update, (ask_before_closing, show_unsaved_in_title, autosave_unsaved_scene))
            .add_systems(
                Update,
                panic_when_asked.after(autosave_unsaved_scene).run_if(|| std::env::var_os(PANIC_AFTER).is_some()),
            )
            // After the panels' pass (where Open is clicked), before the scene is replaced.
            .add_systems(
                PostUpdate,
                ask_before_opening
                    .after(bevy_egui::EguiPostUpdateSet::EndPass)
                    .before(crate::editor::order::EditorSystems::OpenScene),
            )
            .init_resource::<LeftRecovery>()
            .add_systems(Startup, find_left_recovery)
            .add_systems(EguiPrimaryContextPass, (close_question_ui, recovery_offer_ui));
    }
}

/// The "save the changes first?" question: what waits on the answer (none: no question),
/// and an open let through once answered.
#[derive(Resource, Default)]
pub struct UnsavedQuestion {
    pub about: Option<Leaving>,
    let_open: bool,
}

/// What would lose the unsaved changes.
pub enum Leaving {
    /// The window closing.
    Close,
    /// Another scene opening (held back from `PendingScene`).
    Open(Box<PendingScene>),
}

/// The autosave: how often (none: off), where, when it last wrote and which state.
#[derive(Resource, Debug)]
pub struct Autosave {
    pub every: Option<Duration>,
    pub file: PathBuf,
    last: Instant,
    written: Option<u64>,
}

impl Autosave {
    /// Every `every` (none: off) into `file`.
    pub fn new(every: Option<Duration>, file: PathBuf) -> Self {
        Self { every, file, last: Instant::now(), written: None }
    }

    /// From `MARIONETTE_AUTOSAVE_SECONDS` (a number of seconds; 0 off), the recovery
    /// folder and this process.
    pub fn from_env() -> Self {
        let seconds = std::env::var("MARIONETTE_AUTOSAVE_SECONDS").ok().and_then(|s| s.trim().parse::<f64>().ok());
        let every = match seconds {
            Some(s) if s.is_finite() && s > 0.0 => Some(Duration::from_secs_f64(s)),
            Some(_) => None,
            None => Some(AUTOSAVE_EVERY),
        };
        Self::new(every, recovery_dir().join(format!("scene-{}.ron", std::process::id())))
    }
}

/// For tests of the panic hook: the editor panics this many seconds after it starts.
pub const PANIC_AFTER: &str = "MARIONETTE_TEST_PANIC_AFTER_SECONDS";

/// Panics [`PANIC_AFTER`] seconds after the app started, once autosave has captured the
/// scene (a test's crash).
fn panic_when_asked(time: Res<Time<Real>>, wake: Option<ResMut<WakeWithin>>) {
    // Awake for it, however idle the editor is.
    if let Some(mut wake) = wake {
        wake.ask(Duration::from_millis(500));
    }
    let after = std::env::var(PANIC_AFTER).ok().and_then(|s| s.parse::<f32>().ok()).unwrap_or(f32::INFINITY);
    let captured = LAST_STATE.lock().is_ok_and(|s| s.is_some());
    if time.elapsed_secs() > after && captured {
        panic!("{PANIC_AFTER} asked for a crash after {after} s");
    }
}

/// The user's recovery folder: `$XDG_STATE_HOME/marionette/recovery`, else
/// `~/.local/state/marionette/recovery`.
pub fn recovery_dir() -> PathBuf {
    let state = std::env::var_os("XDG_STATE_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".local/state")))
        .unwrap_or_else(std::env::temp_dir);
    state.join("marionette").join("recovery")
}

/// Recovery files sessions that did not close cleanly left (their process gone), newest
/// first, offered on start.
#[derive(Resource, Default, Debug)]
pub struct LeftRecovery(pub Vec<PathBuf>);

/// The recovery files in `dir` whose sessions are gone (not this process's, nor a running
/// one's), newest first.
pub fn left_recovery_files(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut files: Vec<(std::time::SystemTime, PathBuf)> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .filter(|p| {
            let pid = p.file_stem().and_then(|s| s.to_str()).and_then(|s| s.strip_prefix("scene-"));
            match pid.and_then(|p| p.parse::<u32>().ok()) {
                Some(pid) => pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists(),
                None => true,
            }
        })
        .filter_map(|p| Some((std::fs::metadata(&p).ok()?.modified().ok()?, p)))
        .collect();
    files.sort_by_key(|f| std::cmp::Reverse(f.0));
    files.into_iter().map(|(_, p)| p).collect()
}

fn find_left_recovery(mut left: ResMut<LeftRecovery>) {
    left.0 = left_recovery_files(&recovery_dir());
}

/// The offer: Recover (the newest opens; the files stay until it is saved or closed),
/// Discard (the files are removed), Later (asked again next start).
fn recovery_offer_ui(
    mut contexts: EguiContexts,
    mut left: ResMut<LeftRecovery>,
    mut pending: ResMut<PendingScene>,
    mut messages: ResMut<Messages>,
    mut changed: ResMut<crate::editor::scene_doc::document::ChangedAtStartup>,
) -> Result {
    let Some(newest) = left.0.first().cloned() else { return Ok(()) };
    let ctx = contexts.ctx_mut()?;
    let mut answer = None;
    egui::Modal::new(egui::Id::new("recovery offer")).show(ctx, |ui| {
        ui.heading("Recover unsaved work?");
        ui.label(format!(
            "A session that did not close cleanly left {} recovery file(s); the newest is {}.",
            left.0.len(),
            newest.display()
        ));
        ui.horizontal(|ui| {
            for label in ["Recover", "Discard", "Later"] {
                if ui.button(label).clicked() {
                    answer = Some(label);
                }
            }
        });
    });
    match answer {
        Some("Recover") => match crate::document::scenes::read_scene(&newest) {
            Ok(doc) => {
                // Recovered work is saved nowhere yet.
                *pending = PendingScene { frame: doc.camera.is_none(), doc: Some(doc) };
                changed.0 = true;
            }
            Err(e) => messages.push(format!("could not recover: {e}")),
        },
        Some("Discard") => left.0.iter().for_each(|f| {
            let _ = std::fs::remove_file(f);
        }),
        _ => {}
    }
    if answer.is_some() {
        left.0.clear();
    }
    Ok(())
}

/// The newest recovery file, if any.
pub fn newest_recovery() -> Option<PathBuf> {
    let entries = std::fs::read_dir(recovery_dir()).ok()?;
    entries
        .filter_map(Result::ok)
        .filter(|e| e.path().extension().is_some_and(|x| x == "ron"))
        .filter_map(|e| Some((e.metadata().ok()?.modified().ok()?, e.path())))
        .max()
        .map(|(_, p)| p)
}

/// The newest state written for the panic hook (the recovery file and its text).
static LAST_STATE: Mutex<Option<String>> = Mutex::new(None);

/// On a panic, the newest state autosave captured is written to the recovery file before
/// the process ends, and the message says where. For the editor's process only (a hook is
/// the process's).
pub fn install_panic_hook(file: PathBuf) {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if let Some(text) = LAST_STATE.lock().ok().and_then(|s| s.clone())
            && write_recovery(&file, &text).is_ok()
        {
            eprintln!("marionette: the scene was saved to {} before the crash", file.display());
        }
        previous(info);
    }));
}

fn write_recovery(file: &Path, text: &str) -> std::io::Result<()> {
    if let Some(dir) = file.parent() {
        std::fs::create_dir_all(dir)?;
    }
    crate::formats::write_atomically(file, |w| std::io::Write::write_all(w, text.as_bytes()))
}

/// The recovery text of the scene in memory: where it came from, then the scene.
fn recovery_text(scene: &SceneReader, from: &str) -> Option<String> {
    let text = crate::formats::scene::scene_to_string(&scene.capture()).ok()?;
    Some(format!("// Marionette's recovery of {from}\n{text}"))
}

/// Writes the scene to the recovery file every [`Autosave::every`] while it has unsaved
/// changes (captured here, written on another thread); keeps the panic hook's copy.
fn autosave_unsaved_scene(
    mut autosave: ResMut<Autosave>,
    saved: Res<SavedState>,
    history: Res<History>,
    scene: SceneReader,
    state: Option<Res<InspectorState>>,
    wake: Option<ResMut<WakeWithin>>,
) {
    let Some(every) = autosave.every else { return };
    let now = history.state();
    if !saved.unsaved(now, history.gesture_open()) || autosave.written == Some(now) {
        return;
    }
    if autosave.last.elapsed() < every {
        // The editor sleeps when idle: awake when this autosave is due.
        if let Some(mut wake) = wake {
            wake.ask(every - autosave.last.elapsed());
        }
        return;
    }
    autosave.last = Instant::now();
    autosave.written = Some(now);
    let from = state.map_or_else(|| "an unsaved scene".to_string(), |s| s.scene_path.clone());
    let Some(text) = recovery_text(&scene, &from) else { return };
    if let Ok(mut last) = LAST_STATE.lock() {
        *last = Some(text.clone());
    }
    let file = autosave.file.clone();
    std::thread::spawn(move || {
        if let Err(e) = write_recovery(&file, &text) {
            warn!("autosave to {} failed: {e}", file.display());
        }
    });
}

/// The window's title: the scene's file name, with ` *` while it has unsaved changes.
fn show_unsaved_in_title(
    saved: Res<SavedState>,
    history: Res<History>,
    state: Option<Res<InspectorState>>,
    mut windows: Query<&mut Window, With<PrimaryWindow>>,
) {
    let path = state.map(|s| PathBuf::from(&s.scene_path)).unwrap_or_default();
    let name = path.file_name().map_or("untitled".into(), |n| n.to_string_lossy());
    let star = if saved.unsaved(history.state(), history.gesture_open()) { " *" } else { "" };
    let title = format!("{name}{star} — Marionette");
    for mut window in &mut windows {
        if window.title != title {
            window.title = title.clone();
        }
    }
}

/// A close request: with unsaved changes it opens the question; otherwise the app ends.
fn ask_before_closing(
    mut requests: MessageReader<WindowCloseRequested>,
    saved: Res<SavedState>,
    history: Res<History>,
    mut question: ResMut<UnsavedQuestion>,
    autosave: Res<Autosave>,
    mut exit: MessageWriter<AppExit>,
) {
    if requests.read().count() == 0 {
        return;
    }
    if saved.unsaved(history.state(), history.gesture_open()) {
        question.about = Some(Leaving::Close);
    } else {
        close_cleanly(&autosave, &mut exit);
    }
}

/// Another scene about to replace one with unsaved changes is held back, and the question
/// asked (unless it was answered for it).
fn ask_before_opening(
    mut pending: ResMut<PendingScene>,
    saved: Res<SavedState>,
    history: Res<History>,
    mut question: ResMut<UnsavedQuestion>,
) {
    if pending.doc.is_none() || std::mem::take(&mut question.let_open) {
        return;
    }
    if saved.unsaved(history.state(), history.gesture_open()) && question.about.is_none() {
        question.about = Some(Leaving::Open(Box::new(std::mem::take(&mut *pending))));
    }
}

/// Ends the app, its recovery file removed (nothing is lost).
fn close_cleanly(autosave: &Autosave, exit: &mut MessageWriter<AppExit>) {
    let _ = std::fs::remove_file(&autosave.file);
    exit.write(AppExit::Success);
}

/// What the close question's buttons do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CloseAnswer {
    Save,
    DontSave,
    Cancel,
}

/// The question: Save (then go on, unless the save failed: its reason in the messages, the
/// changes kept), Don't save (go on), Cancel.
#[allow(clippy::too_many_arguments)]
fn close_question_ui(
    mut contexts: EguiContexts,
    mut question: ResMut<UnsavedQuestion>,
    mut saved: ResMut<SavedState>,
    mut messages: ResMut<Messages>,
    mut pending: ResMut<PendingScene>,
    scene: SceneReader,
    state: Res<InspectorState>,
    autosave: Res<Autosave>,
    mut exit: MessageWriter<AppExit>,
) -> Result {
    let Some(about) = &question.about else { return Ok(()) };
    let what = match about {
        Leaving::Close => "closing",
        Leaving::Open(_) => "opening another scene",
    };
    let ctx = contexts.ctx_mut()?;
    let mut answer = None;
    egui::Modal::new(egui::Id::new("unsaved question")).show(ctx, |ui| {
        ui.heading(format!("Save the changes before {what}?"));
        ui.label(format!("{} has changes that are not saved.", state.scene_path));
        ui.horizontal(|ui| {
            for (label, a) in
                [("Save", CloseAnswer::Save), ("Don't save", CloseAnswer::DontSave), ("Cancel", CloseAnswer::Cancel)]
            {
                if ui.button(label).clicked() {
                    answer = Some(a);
                }
            }
        });
    });
    let Some(answer) = answer else { return Ok(()) };
    let about = question.about.take();
    let save = || save_scene_to(&state.scene_path, &scene.capture(), &mut messages, &mut saved);
    if closes_after(answer, save) {
        match about {
            Some(Leaving::Close) => close_cleanly(&autosave, &mut exit),
            Some(Leaving::Open(scene)) => {
                *pending = *scene;
                question.let_open = true;
            }
            None => {}
        }
    }
    Ok(())
}

/// Whether the app closes after `answer`: Save closes when `save` succeeds (a failed save
/// keeps the app and the changes), Don't save closes, Cancel does not.
pub fn closes_after(answer: CloseAnswer, save: impl FnOnce() -> bool) -> bool {
    match answer {
        CloseAnswer::Save => save(),
        CloseAnswer::DontSave => true,
        CloseAnswer::Cancel => false,
    }
}

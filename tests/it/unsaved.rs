//! Never losing a user's work, on the live ECS (no window): an edit leaves the scene
//! unsaved, undoing back to the saved state clears it, a save clears it and a failed one
//! keeps it; a close request with unsaved changes asks and does not exit, without them it
//! exits; opening another scene asks likewise, the scene in memory kept; the question's
//! answers; autosave writes a recovery file that reads back as
//! the scene in memory.

use marionette::editor::edits::kinds;
use std::time::Duration;

use bevy::prelude::*;
use bevy::window::WindowCloseRequested;
use marionette::editor::edits::commands::Edit;
use marionette::editor::edits::history::{History, HistoryRequest};
use marionette::editor::scene_doc::document::{PendingScene, SceneReader, save_scene_to};
use marionette::editor::state::SavedState;
use marionette::editor::ui::unsaved::{
    Autosave, CloseAnswer, Leaving, UnsavedQuestion, UnsavedWorkPlugin, closes_after,
};
use marionette::formats::scene::{CharacterDoc, CharacterId, SceneDoc, SourceDoc};
use marionette::rig::JointRotation;

use crate::common::scratch;
use crate::edits::{Captured, edit, entity, joint, request, scene_app};

/// The scene app with the unsaved-work plugin (its autosave off unless a test sets it) and
/// a puppet (id 1) opened.
fn app() -> App {
    let mut app = scene_app();
    app.add_message::<WindowCloseRequested>().add_plugins(UnsavedWorkPlugin);
    app.insert_resource(Autosave::new(None, scratch("unsaved-off").join("never.ron")));
    let puppet =
        CharacterDoc { id: Some(CharacterId(1)), ..CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "p") };
    *app.world_mut().resource_mut::<PendingScene>() =
        PendingScene { doc: Some(SceneDoc { characters: vec![puppet], ..SceneDoc::default() }), frame: false };
    app.update();
    app.update();
    app
}

fn unsaved(app: &App) -> bool {
    let history = app.world().resource::<History>();
    app.world().resource::<SavedState>().unsaved(history.state(), history.gesture_open())
}

fn bend_elbow(app: &mut App, angle: f32) {
    let elbow = joint(app, 1, "l_elbow");
    let rotation = JointRotation::Euler(glam::Vec3::new(0.0, angle, 0.0), marionette::rig::EulerOrder::Xyz);
    edit(app, Edit::from(kinds::Pose { character: CharacterId(1), joints: vec![(elbow, rotation)] }));
    app.update();
}

/// Saves the scene in memory to `path` as the editor's Save does; whether it was saved.
fn save(app: &mut App, path: &std::path::Path) -> bool {
    let path = path.display().to_string();
    let ok = app
        .world_mut()
        .run_system_once(
            move |scene: SceneReader,
                  mut messages: ResMut<marionette::editor::Messages>,
                  mut saved: ResMut<SavedState>| {
                save_scene_to(&path, &scene.capture(), &mut messages, &mut saved)
            },
        )
        .unwrap();
    app.update();
    ok
}

use bevy::ecs::system::RunSystemOnce;

#[test]
fn an_edit_leaves_the_scene_unsaved_until_undone_or_saved() {
    let mut app = app();
    assert!(!unsaved(&app), "a scene just opened is its file");
    bend_elbow(&mut app, 0.5);
    assert!(unsaved(&app), "an edit");
    request(&mut app, HistoryRequest::Undo);
    app.update();
    assert!(!unsaved(&app), "undone back to the saved state");
    request(&mut app, HistoryRequest::Redo);
    app.update();
    assert!(unsaved(&app), "redone");
    let dir = scratch("unsaved-save");
    assert!(save(&mut app, &dir.join("scene.ron")));
    assert!(!unsaved(&app), "saved");
    bend_elbow(&mut app, 0.9);
    assert!(unsaved(&app));
    // A save that fails (a folder where the file should be) keeps the changes and says why.
    std::fs::create_dir_all(dir.join("taken.ron")).unwrap();
    assert!(!save(&mut app, &dir.join("taken.ron")));
    assert!(unsaved(&app), "a failed save keeps the changes");
    let messages = &app.world().resource::<marionette::editor::Messages>().0;
    assert!(messages.last().unwrap().contains("not saved"), "{messages:?}");
    // Undo to the state saved last: saved again.
    request(&mut app, HistoryRequest::Undo);
    app.update();
    assert!(!unsaved(&app));
}

fn exits(app: &App) -> usize {
    app.world().resource::<bevy::ecs::message::Messages<AppExit>>().len()
}

#[test]
fn closing_with_unsaved_changes_asks_and_does_not_exit() {
    let mut app = app();
    let window = entity(&app, 1);
    bend_elbow(&mut app, 0.5);
    app.world_mut().write_message(WindowCloseRequested { window });
    app.update();
    assert!(matches!(app.world().resource::<UnsavedQuestion>().about, Some(Leaving::Close)), "the question opens");
    assert_eq!(exits(&app), 0, "the app stays");
    // Without changes a close request ends the app.
    request(&mut app, HistoryRequest::Undo);
    app.update();
    app.world_mut().resource_mut::<UnsavedQuestion>().about = None;
    app.world_mut().write_message(WindowCloseRequested { window });
    app.update();
    assert!(app.world().resource::<UnsavedQuestion>().about.is_none());
    assert!(exits(&app) > 0, "closed");
    // The answers: Don't save closes, Cancel stays, Save closes only when the save worked.
    assert!(closes_after(CloseAnswer::DontSave, || unreachable!("no save")));
    assert!(!closes_after(CloseAnswer::Cancel, || unreachable!("no save")));
    assert!(closes_after(CloseAnswer::Save, || true));
    assert!(!closes_after(CloseAnswer::Save, || false));
}

#[test]
fn autosave_writes_a_recovery_file_that_reads_back_as_the_scene_in_memory() {
    let mut app = app();
    let file = scratch("unsaved-autosave").join("recovery").join("scene.ron");
    app.insert_resource(Autosave::new(Some(Duration::from_millis(200)), file.clone()));
    bend_elbow(&mut app, 0.7);
    std::thread::sleep(Duration::from_millis(250));
    app.update();
    // Written on another thread: wait for it.
    let mut waited = 0;
    while !file.is_file() && waited < 100 {
        std::thread::sleep(Duration::from_millis(50));
        waited += 1;
    }
    let back = marionette::document::scenes::read_scene(&file).expect("a recovery file");
    let memory = app.world().resource::<Captured>().0.clone();
    assert_eq!(back, memory, "the recovery file is the scene in memory");
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.starts_with("// Marionette's recovery of "), "{}", &text[..60.min(text.len())]);
}

#[test]
fn opening_another_scene_with_unsaved_changes_holds_it_back_and_asks() {
    let mut app = app();
    bend_elbow(&mut app, 0.5);
    let before = app.world().resource::<Captured>().0.clone();
    let other =
        CharacterDoc { id: Some(CharacterId(7)), ..CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "q") };
    *app.world_mut().resource_mut::<PendingScene>() =
        PendingScene { doc: Some(SceneDoc { characters: vec![other], ..SceneDoc::default() }), frame: false };
    app.update();
    app.update();
    assert!(matches!(app.world().resource::<UnsavedQuestion>().about, Some(Leaving::Open(_))), "the question opens");
    assert_eq!(app.world().resource::<Captured>().0, before, "the scene in memory stays");
    assert!(unsaved(&app));
}

/// End to end, under a private Xvfb: `edit scene.ron --pose …` with autosave every 3 s,
/// killed with SIGKILL once it has autosaved, leaves a recovery file that holds the pose and
/// renders; `edit --recover` finds it (its newest).
#[test]
fn a_killed_editor_leaves_a_recovery_file_that_holds_its_pose_and_renders() {
    use std::process::{Command, Stdio};
    let dir = scratch("unsaved-killed");
    let state = dir.join("state");
    let scene = puppet_scene(&dir);
    let display = Display::start(90 + std::process::id() % 500);
    let args = ["edit", scene.to_str().unwrap(), "--pose", "l_elbow=0,1.2,0"];
    let mut editor = display.editor(&args, "3", &state).stderr(Stdio::null()).spawn().unwrap();
    let recovery = state.join("marionette/recovery");
    let mut found = None;
    for _ in 0..180 {
        std::thread::sleep(Duration::from_millis(500));
        // The recovery file, not the temporary file it is written through.
        let whole = |p: &std::path::PathBuf| !p.to_string_lossy().ends_with(".tmp");
        found = std::fs::read_dir(&recovery).ok().and_then(|d| d.flatten().map(|e| e.path()).find(whole));
        if found.is_some() || editor.try_wait().unwrap().is_some() {
            break;
        }
    }
    editor.kill().ok();
    editor.wait().ok();
    drop(display);
    let file = found.expect("the editor autosaved within 90 s");
    // Written whole: give a rename under way its moment, then read.
    std::thread::sleep(Duration::from_millis(200));
    let doc = marionette::document::scenes::read_scene(&file).unwrap();
    let pose = &doc.characters[0].pose;
    let elbow = pose.get("l_elbow").expect("the pose --pose set");
    let q = elbow.to_quat();
    let want = JointRotation::Euler(glam::Vec3::new(0.0, 1.2, 0.0), marionette::rig::EulerOrder::Xyz).to_quat();
    assert!((q - want).length().min((q + want).length()) < 1e-5, "{elbow:?}");
    // The file renders.
    let out = dir.join("recovered.png");
    let render = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["render", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--width", "64", "--height", "48"])
        .output()
        .unwrap();
    assert!(render.status.success(), "{}", String::from_utf8_lossy(&render.stderr));
    // `edit --recover` would open the newest: this one.
    let left = marionette::editor::ui::unsaved::left_recovery_files(&recovery);
    assert_eq!(left.first(), Some(&file), "the killed session's file is offered");
}

/// A private Xvfb display for the life of the value.
struct Display {
    name: String,
    server: std::process::Child,
}

impl Display {
    fn start(number: u32) -> Self {
        let name = format!(":{number}");
        let server = std::process::Command::new("Xvfb")
            .args([name.as_str(), "-screen", "0", "1280x800x24", "-nolisten", "tcp"])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("Xvfb (scripts/install-deps.sh installs it)");
        std::thread::sleep(Duration::from_secs(1));
        Self { name, server }
    }
}

impl Display {
    /// The editor with `args` on this display, autosaving every `autosave` seconds into
    /// `state`'s recovery folder, its settings (recent files) there too, never the user's;
    /// its errors piped.
    fn editor(&self, args: &[&str], autosave: &str, state: &std::path::Path) -> std::process::Command {
        let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_marionette"));
        command
            .args(args)
            .env("DISPLAY", &self.name)
            .env("MARIONETTE_AUTOSAVE_SECONDS", autosave)
            .env("XDG_STATE_HOME", state)
            .env("MARIONETTE_CONFIG_DIR", state.join("config"))
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped());
        command
    }
}

/// A scene of one puppet written to `dir/scene.ron`.
fn puppet_scene(dir: &std::path::Path) -> std::path::PathBuf {
    let scene = dir.join("scene.ron");
    let puppet = CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "p");
    marionette::document::scenes::write_scene(&scene, &SceneDoc { characters: vec![puppet], ..SceneDoc::default() })
        .unwrap();
    scene
}

impl Drop for Display {
    fn drop(&mut self) {
        self.server.kill().ok();
        self.server.wait().ok();
    }
}

/// The editor under random input (a fixed seed): clicks, drags, wheel turns and shortcut
/// keys over the whole window for `MARIONETTE_MONKEY_SECONDS` (60 by default), with
/// autosave every 2 s. It must still be running at the end (no panic, no exit), answer
/// to more input, and what it autosaved must read back as a valid scene (no NaN).
#[test]
fn the_editor_survives_random_input() {
    use std::process::{Command, Stdio};
    let seconds: u64 = std::env::var("MARIONETTE_MONKEY_SECONDS").ok().and_then(|s| s.parse().ok()).unwrap_or(60);
    let dir = scratch("monkey");
    let display = Display::start(600 + std::process::id() % 300);
    let mut editor = display.editor(&[], "2", &dir.join("state")).current_dir(&dir).spawn().unwrap();
    let xdotool = |args: &[String]| {
        Command::new("xdotool").args(args).env("DISPLAY", &display.name).stderr(Stdio::null()).status().ok();
    };
    // The window first (llvmpipe takes a while).
    std::thread::sleep(Duration::from_secs(8));
    let mut seed: u64 = 0x5EED_1234;
    let mut next = |n: u64| {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 33) % n
    };
    let keys = ["s", "f", "k", "Escape", "ctrl+z", "ctrl+shift+z", "Delete", "space", "Tab", "r", "g", "1", "Left"];
    let started = std::time::Instant::now();
    let mut actions = 0;
    while started.elapsed() < Duration::from_secs(seconds) && editor.try_wait().unwrap().is_none() {
        let (x, y) = (next(1280).to_string(), next(800).to_string());
        let action: Vec<String> = match next(6) {
            0 | 1 => vec!["mousemove".into(), x, y, "click".into(), "1".into()],
            2 => {
                let (x2, y2) = (next(1280).to_string(), next(800).to_string());
                let drag = ["mousemove", &x, &y, "mousedown", "1", "mousemove", &x2, &y2, "mouseup", "1"];
                drag.iter().map(|s| s.to_string()).collect()
            }
            3 => vec!["mousemove".into(), x, y, "click".into(), if next(2) == 0 { "4" } else { "5" }.into()],
            _ => vec!["key".into(), keys[next(keys.len() as u64) as usize].into()],
        };
        xdotool(&action);
        actions += 1;
        std::thread::sleep(Duration::from_millis(100 + next(300)));
    }
    let alive = editor.try_wait().unwrap().is_none();
    editor.kill().ok();
    let output = editor.wait_with_output().unwrap();
    let log = String::from_utf8_lossy(&output.stderr);
    assert!(
        alive,
        "the editor ended under random input after {actions} actions:\n{}",
        &log[log.len().saturating_sub(3000)..]
    );
    assert!(!log.contains("panicked"), "{}", &log[log.len().saturating_sub(3000)..]);
    // Whatever it autosaved is a valid scene.
    let recovery = dir.join("state/marionette/recovery");
    for file in std::fs::read_dir(&recovery).into_iter().flatten().filter_map(Result::ok) {
        marionette::document::scenes::read_scene(&file.path()).expect("the autosaved scene reads back");
    }
    eprintln!("monkey: {actions} actions over {seconds} s");
}

/// A panic in the editor writes the newest state to the recovery file before the process
/// ends, and says where: `edit --pose` under Xvfb, autosave every 2 s, made to panic after
/// 12 s (`MARIONETTE_TEST_PANIC_AFTER_SECONDS`).
#[test]
fn a_panic_leaves_the_recovery_file_and_says_where() {
    let dir = scratch("unsaved-panic");
    let scene = puppet_scene(&dir);
    let display = Display::start(60 + std::process::id() % 25);
    let mut editor = display
        .editor(&["edit", scene.to_str().unwrap(), "--pose", "l_knee=0.8,0,0"], "2", &dir.join("state"))
        .env(marionette::editor::ui::unsaved::PANIC_AFTER, "12")
        .spawn()
        .unwrap();
    let mut ended = None;
    for _ in 0..240 {
        std::thread::sleep(Duration::from_millis(500));
        if let Some(status) = editor.try_wait().unwrap() {
            ended = Some(status);
            break;
        }
    }
    editor.kill().ok();
    let output = editor.wait_with_output().unwrap();
    drop(display);
    let log = String::from_utf8_lossy(&output.stderr);
    assert!(ended.is_some_and(|s| !s.success()), "the editor crashed:\n{}", &log[log.len().saturating_sub(2000)..]);
    let said = log.lines().find(|l| l.contains("the scene was saved to")).expect("the crash says where the scene went");
    let file = dir.join("state/marionette/recovery").read_dir().unwrap().next().unwrap().unwrap().path();
    assert!(said.contains(&file.display().to_string()), "{said}");
    let doc = marionette::document::scenes::read_scene(&file).unwrap();
    assert!(doc.characters[0].pose.contains_key("l_knee"), "the pose --pose set");
}

/// The window's title names the scene's file and carries a star while it is unsaved.
#[test]
fn the_title_carries_a_star_while_unsaved() {
    let mut app = app();
    let window = app.world_mut().spawn((Window::default(), bevy::window::PrimaryWindow)).id();
    app.update();
    let title = |app: &App| app.world().get::<Window>(window).unwrap().title.clone();
    assert!(!title(&app).contains('*'), "{}", title(&app));
    bend_elbow(&mut app, 0.4);
    assert!(title(&app).contains(" *"), "{}", title(&app));
    request(&mut app, HistoryRequest::Undo);
    app.update();
    assert!(!title(&app).contains('*'), "{}", title(&app));
}

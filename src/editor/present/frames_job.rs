//! "Render frames…" in the editor: the scene as it stands is saved aside and rendered by
//! `marionette render --from A --to B --fps N` in a process of its own, so the editor stays
//! responsive; its progress lines feed a progress bar, Cancel stops it.

use std::io::BufRead;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};

use bevy::prelude::*;

use crate::editor::state::Messages;
use crate::formats::scene::SceneDoc;

/// What the panel asks for.
#[derive(Debug, Clone, PartialEq)]
pub struct FramesRequest {
    pub from: f32,
    pub to: f32,
    pub fps: f32,
    /// Seconds for one turn of the camera (none: it stays).
    pub turntable: Option<f32>,
    /// Where the frames go: a path with one `%04d`.
    pub pattern: String,
    /// Write each frame's data pictures and one COCO file (`render --data`).
    pub with_data: bool,
}

impl Default for FramesRequest {
    fn default() -> Self {
        let cwd = std::env::current_dir().map(|d| d.display().to_string()).unwrap_or_default();
        Self {
            from: 0.0,
            to: 2.0,
            fps: 24.0,
            turntable: None,
            pattern: format!("{cwd}/frames/frame_%04d.png"),
            with_data: false,
        }
    }
}

/// The render under way (if any): its process, frames done of all, and the last lines it
/// wrote (its error, if it fails).
#[derive(Resource, Default)]
pub struct FramesJob {
    pub request: FramesRequest,
    child: Option<Child>,
    scene: Option<PathBuf>,
    progress: Arc<Mutex<(usize, usize, Vec<String>)>>,
}

impl FramesJob {
    pub fn running(&self) -> bool {
        self.child.is_some()
    }

    /// Frames done and all of them (0 of 0 before the first is known).
    pub fn progress(&self) -> (usize, usize) {
        self.progress.lock().map(|p| (p.0, p.1)).unwrap_or((0, 0))
    }

    /// Saves `doc` aside and starts rendering it; says why not when it cannot.
    pub fn start(&mut self, doc: &SceneDoc) -> Result<(), String> {
        if self.running() {
            return Err("frames are being rendered already".into());
        }
        let r = self.request.clone();
        if let Some(dir) = std::path::Path::new(&r.pattern).parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        let scene = std::env::temp_dir().join(format!("marionette-frames-{}.ron", std::process::id()));
        crate::document::scenes::write_scene(&scene, doc).map_err(|e| e.to_string())?;
        let exe = std::env::current_exe().map_err(|e| format!("cannot find the marionette program: {e}"))?;
        let mut command = Command::new(exe);
        command.arg("render").arg(&scene).args(["--from", &r.from.to_string(), "--to", &r.to.to_string()]);
        command.args(["--fps", &r.fps.to_string(), "--out", &r.pattern]);
        if let Some(seconds) = r.turntable {
            command.args(["--turntable", &seconds.to_string()]);
        }
        if r.with_data {
            command.arg("--data");
        }
        let mut child = command
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| format!("cannot start the render: {e}"))?;
        let progress = Arc::new(Mutex::new((0, 0, Vec::new())));
        if let Some(stderr) = child.stderr.take() {
            let shared = progress.clone();
            std::thread::spawn(move || read_progress(stderr, &shared));
        }
        (self.child, self.scene, self.progress) = (Some(child), Some(scene), progress);
        Ok(())
    }

    /// Stops the render under way.
    pub fn cancel(&mut self) {
        if let Some(mut child) = self.child.take() {
            let _ = child.kill();
            let _ = child.wait();
        }
        self.clean_up();
    }

    fn clean_up(&mut self) {
        if let Some(scene) = self.scene.take() {
            let _ = std::fs::remove_file(scene);
        }
    }
}

/// Reads `progress: k/n` lines into `shared`, keeping the last few other lines.
fn read_progress(stderr: impl std::io::Read, shared: &Mutex<(usize, usize, Vec<String>)>) {
    for line in std::io::BufReader::new(stderr).lines().map_while(Result::ok) {
        let Ok(mut p) = shared.lock() else { return };
        match line.strip_prefix("progress: ").and_then(|s| s.split_once('/')) {
            Some((k, n)) => (p.0, p.1) = (k.trim().parse().unwrap_or(p.0), n.trim().parse().unwrap_or(p.1)),
            // Bevy's own log lines are not the render's word.
            None if line.contains(" INFO ") || line.contains(" WARN ") => {}
            None => {
                p.2.push(line);
                let excess = p.2.len().saturating_sub(4);
                p.2.drain(..excess);
            }
        }
    }
}

/// Says when the render under way ends, and how (reads the process; writes `FramesJob`,
/// `Messages`).
pub fn finish_frames_job(mut job: ResMut<FramesJob>, mut messages: ResMut<Messages>) {
    let Some(child) = job.child.as_mut() else { return };
    let Ok(Some(status)) = child.try_wait() else { return };
    job.child = None;
    job.clean_up();
    let (done, _) = job.progress();
    let pattern = job.request.pattern.clone();
    if status.success() {
        messages.push(format!("wrote {done} frames as {pattern}"));
    } else {
        let said = job.progress.lock().map(|p| p.2.join(" ")).unwrap_or_default();
        messages.push(format!("the frames were not rendered: {said}"));
    }
}

impl Drop for FramesJob {
    fn drop(&mut self) {
        self.cancel();
    }
}

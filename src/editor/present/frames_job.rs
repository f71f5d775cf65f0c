//! "Render frames…" in the editor: the scene as it stands is saved aside and rendered on a
//! thread of its own by the same render as `marionette render --from A --to B --fps N`
//! (an offscreen app of its own), so the editor stays responsive; each frame written moves
//! the progress bar, Cancel stops it.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use bevy::prelude::*;

use crate::document::frames::{FrameSequence, PictureRequest, Pictures};
use crate::editor::present::data::ControlNetChoice;
use crate::editor::present::render::{OnWritten, Rendering, render_with};
use crate::editor::state::{Messages, StartupEdits};
use crate::formats::scene::{SceneDoc, ShotDoc};

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
    /// Write each frame's ControlNet maps (`render --controlnet`).
    pub controlnet: ControlNetChoice,
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
            controlnet: ControlNetChoice::default(),
        }
    }
}

/// The render under way (if any): the thread rendering it, frames done of all, whether it
/// was asked to stop, and the scene file it renders.
#[derive(Resource, Default)]
pub struct FramesJob {
    pub request: FramesRequest,
    worker: Option<std::thread::JoinHandle<Result<(Vec<String>, ShotDoc), String>>>,
    scene: Option<PathBuf>,
    progress: Arc<Mutex<(usize, usize)>>,
    cancelled: Arc<AtomicBool>,
}

impl FramesJob {
    pub fn running(&self) -> bool {
        self.worker.is_some()
    }

    /// Frames done and all of them (0 of 0 before the first is known).
    pub fn progress(&self) -> (usize, usize) {
        self.progress.lock().map(|p| *p).unwrap_or((0, 0))
    }

    /// Saves `doc` aside and starts rendering it on a thread of its own, through the same
    /// render as `marionette render --from A --to B --fps N`; says why not when it cannot.
    pub fn start(&mut self, doc: &SceneDoc) -> Result<(), String> {
        if self.running() {
            return Err("frames are being rendered already".into());
        }
        let r = self.request.clone();
        let sequence = FrameSequence { from: r.from, to: r.to, fps: r.fps, turntable: r.turntable };
        let count = sequence.times().map_err(|e| e.to_string())?.len();
        if let Some(dir) = std::path::Path::new(&r.pattern).parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        let scene = std::env::temp_dir().join(format!("marionette-frames-{}.ron", std::process::id()));
        crate::document::scenes::write_scene(&scene, doc).map_err(|e| e.to_string())?;
        let (progress, cancelled) = (Arc::new(Mutex::new((0, count))), Arc::new(AtomicBool::new(false)));
        let (done, stop) = (progress.clone(), cancelled.clone());
        let on_written: OnWritten = Box::new(move |index| {
            if let Ok(mut p) = done.lock() {
                p.0 = p.0.max(index + 1);
            }
            if stop.load(Ordering::Relaxed) { Err("cancelled".into()) } else { Ok(()) }
        });
        let rendering = Rendering {
            paths: vec![scene.clone()],
            edits: StartupEdits::default(),
            out: PathBuf::from(&r.pattern),
            picture: PictureRequest::default(),
            pictures: Pictures::Sequence(sequence),
            data: r.with_data,
            controlnet: r.controlnet.maps(),
        };
        let worker = std::thread::Builder::new()
            .name("frames".into())
            .spawn(move || render_with(rendering, Some(on_written)))
            .map_err(|e| format!("cannot start the render: {e}"))?;
        (self.worker, self.scene, self.progress, self.cancelled) = (Some(worker), Some(scene), progress, cancelled);
        Ok(())
    }

    /// Stops the render under way (after the frame being written) and waits for it.
    pub fn cancel(&mut self) {
        self.cancelled.store(true, Ordering::Relaxed);
        if let Some(worker) = self.worker.take() {
            let _ = worker.join();
        }
        self.clean_up();
    }

    /// How the render ended, once it has: `None` while it runs (or when none was started).
    pub fn finished(&mut self) -> Option<Result<(), String>> {
        if !self.worker.as_ref().is_some_and(std::thread::JoinHandle::is_finished) {
            return None;
        }
        let worker = self.worker.take()?;
        self.clean_up();
        let ended = worker.join().unwrap_or_else(|_| Err("the render stopped unexpectedly".into()));
        Some(ended.map(|_| ()))
    }

    fn clean_up(&mut self) {
        if let Some(scene) = self.scene.take() {
            let _ = std::fs::remove_file(scene);
        }
    }
}

/// Says when the render under way ends, and how (writes `FramesJob`, `Messages`).
pub fn finish_frames_job(mut job: ResMut<FramesJob>, mut messages: ResMut<Messages>) {
    let Some(ended) = job.finished() else { return };
    let (done, _) = job.progress();
    let pattern = job.request.pattern.clone();
    messages.push(match ended {
        Ok(()) => format!("wrote {done} frames as {pattern}"),
        Err(e) => format!("the frames were not rendered: {e}"),
    });
}

impl Drop for FramesJob {
    fn drop(&mut self) {
        self.cancel();
    }
}

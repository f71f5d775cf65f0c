//! When a frame may be captured: every pipeline the frame needs is compiled (nothing
//! waiting, nothing failed in the render world's `PipelineCache`), every drawn mesh and
//! every camera's target image is prepared on the GPU, and every character is skinned for
//! its current pose, for [`READY_FRAMES`] rendered frames in a row. The CLI render, F12
//! and the test pictures capture only then. (Fast GPUs used to pass "two frames agree"
//! while the PBR and shadow pipelines were still compiling in the background.)
//!
//! Once settled, a picture that only changes what is drawn is captured without waiting
//! frames of its own, in the frame that first draws it: a new pose, or a new scene lit by
//! lights of the last one's kinds. The render world says of every frame whether it drew
//! all it was given (each main-world frame's meshes and targets, by [`WantedAssets`]'s
//! generation, every pipeline compiled: [`DrawnFrames`]), and such a capture of a frame
//! that did not is taken again.

use std::sync::{Arc, Mutex};

use bevy::camera::RenderTarget;
use bevy::prelude::*;
use bevy::render::mesh::RenderMesh;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_resource::{CachedPipelineState, PipelineCache};
use bevy::render::texture::GpuImage;
use bevy::render::{Render, RenderApp, RenderSystems};

use crate::editor::scene_doc::document::PendingScene;
use crate::scene::PoseDirty;

/// Rendered frames in a row that must be ready before a capture.
pub const READY_FRAMES: u32 = 3;

/// What the render world reported after its last frame.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct GpuStatus {
    /// Render-world frames seen so far.
    pub frame: u64,
    /// The main world's frame (its [`WantedAssets`] generation) the last one drew.
    pub generation: u64,
    /// Pipelines queued or compiling.
    pub pipelines_waiting: usize,
    /// Pipelines whose shaders failed (they will never draw).
    pub pipelines_failed: Vec<String>,
    /// Meshes drawn in the main world that the GPU does not hold yet.
    pub meshes_missing: usize,
    /// Camera target images the GPU does not hold yet.
    pub images_missing: usize,
}

/// The assets a main-world frame draws, for the render world to look for when it draws
/// that frame (extracted with it); `generation` counts the main world's frames.
#[derive(Resource, Debug, Clone, Default)]
pub struct WantedAssets {
    pub generation: u64,
    meshes: Vec<AssetId<Mesh>>,
    images: Vec<AssetId<Image>>,
}

/// How many frames' outcomes the render world keeps (more than captures wait for).
const DRAWN_KEPT: usize = 64;

/// Shared between the main and the render world: the last frame's status, and whether
/// each recent generation was drawn whole.
#[derive(Resource, Clone, Default)]
pub struct DrawnFrames {
    status: Arc<Mutex<GpuStatus>>,
    drawn: Arc<Mutex<std::collections::VecDeque<(u64, bool)>>>,
}

impl DrawnFrames {
    /// Whether the frame of `generation` was drawn with every mesh and target on the GPU
    /// and no pipeline compiling; none while it is not drawn yet (or forgotten).
    pub fn drawn_whole(&self, generation: u64) -> Option<bool> {
        let drawn = self.drawn.lock().ok()?;
        drawn.iter().find(|(g, _)| *g == generation).map(|&(_, whole)| whole)
    }
}

/// Whether a capture may happen now.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Readiness {
    Ready,
    /// Still waiting; says for what.
    Waiting(String),
    /// Can never become ready; says why.
    Failed(String),
}

/// Decides from the render world's report and the main world's unfinished work
/// (characters not yet skinned for their pose, a scene not yet built).
pub fn readiness(gpu: &GpuStatus, characters_unskinned: usize, scene_pending: bool) -> Readiness {
    if !gpu.pipelines_failed.is_empty() {
        return Readiness::Failed(format!("pipelines failed to compile: {}", gpu.pipelines_failed.join("; ")));
    }
    let mut waiting = Vec::new();
    if gpu.frame == 0 {
        waiting.push("no frame rendered yet".to_string());
    }
    if scene_pending {
        waiting.push("the scene is being built".to_string());
    }
    let mut count = |n: usize, what: &str| {
        if n > 0 {
            waiting.push(format!("{n} {what}"));
        }
    };
    count(gpu.pipelines_waiting, "pipeline(s) compiling");
    count(gpu.meshes_missing, "mesh(es) not on the GPU yet");
    count(gpu.images_missing, "image(s) not on the GPU yet");
    count(characters_unskinned, "character(s) not skinned for their pose yet");
    if waiting.is_empty() { Readiness::Ready } else { Readiness::Waiting(waiting.join(", ")) }
}

/// Counts ready render frames in a row; what was last waited for.
#[derive(Resource, Debug, Default)]
pub struct CaptureGate {
    ready_frames: u32,
    last_frame: u64,
    /// Everything the frames need was on the GPU and drawn before this picture was set up:
    /// it needs one ready frame of its own (else [`READY_FRAMES`]).
    settled: bool,
    /// The last reason not to capture (for a time-out's message).
    pub last_reason: Option<String>,
    /// Set when the frame can never be ready.
    pub failed: Option<String>,
    /// The main world's frame now, and the one the render world last drew.
    generations: (u64, u64),
    /// The first main-world frame that draws what the picture shows (render frames of
    /// earlier ones do not count towards its capture).
    since: u64,
}

impl CaptureGate {
    /// Takes one frame's readiness (`frame` is the render world's frame it is based on:
    /// a frame reported twice counts once).
    pub fn observe(&mut self, frame: u64, readiness: Readiness) {
        match readiness {
            Readiness::Ready => {
                let drew_it = frame != self.last_frame && self.generations.1 >= self.since;
                if drew_it || self.settled {
                    self.ready_frames += 1;
                }
                self.last_reason = None;
            }
            // A settled picture that waits (for a pipeline or a mesh of its own) stays
            // settled: its capture is checked against `DrawnFrames` all the same.
            Readiness::Waiting(reason) => {
                self.ready_frames = 0;
                self.last_reason = Some(reason);
            }
            Readiness::Failed(reason) => {
                self.ready_frames = 0;
                self.failed = Some(reason);
            }
        }
        self.last_frame = frame;
    }

    /// Counts ready frames from none again: what is drawn changed (a new pose, from the
    /// library: its edits land in a later frame), and only frames after the change count.
    pub fn restart(&mut self) {
        self.ready_frames = 0;
        self.settled = false;
        self.since = self.generations.0 + 1;
    }

    /// The main world's frame now and the one the render world last drew.
    pub fn note_generations(&mut self, now: u64, drawn: u64) {
        self.generations = (now, drawn);
    }

    /// The next picture is set up after a capture (clips at a new time, the camera turned,
    /// or a new scene drawn as plain skins): once the gate was ready, its first ready frame
    /// may be captured (its pose is skinned, its entities' meshes, materials, shadows and
    /// the camera's lens taken up in the frame it is drawn in).
    pub fn next_picture(&mut self) {
        self.settled = self.is_ready();
        self.ready_frames = 0;
        self.since = self.generations.0 + 1;
    }

    /// Whether a capture now is of a picture set up after the gate was ready (and so must
    /// be checked against [`DrawnFrames`] once drawn).
    pub fn is_speculative(&self) -> bool {
        self.settled
    }

    /// Whether enough ready frames passed in a row.
    pub fn is_ready(&self) -> bool {
        self.ready_frames >= if self.settled { 1 } else { READY_FRAMES } && self.failed.is_none()
    }
}

/// The step (in `Last`) that updates [`CaptureGate`]; captures run after it.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct UpdateCaptureGate;

/// Keeps a [`CaptureGate`] up to date from the render world (where there is one).
pub struct ReadinessPlugin;

impl Plugin for ReadinessPlugin {
    fn build(&self, app: &mut App) {
        let channel = DrawnFrames::default();
        app.insert_resource(channel.clone())
            .init_resource::<CaptureGate>()
            .init_resource::<WantedAssets>()
            .add_systems(Last, (publish_wanted_assets, update_capture_gate).chain().in_set(UpdateCaptureGate));
        if let Some(render_app) = app.get_sub_app_mut(RenderApp) {
            render_app
                .insert_resource(channel)
                .init_resource::<WantedAssets>()
                .add_systems(bevy::render::ExtractSchedule, extract_wanted_assets)
                .add_systems(Render, report_gpu_status.in_set(RenderSystems::Cleanup));
        }
    }
}

/// Lists the meshes drawn and the cameras' target images, a generation later (reads
/// `Mesh3d`, `RenderTarget`; writes `WantedAssets`).
fn publish_wanted_assets(mut wanted: ResMut<WantedAssets>, meshes: Query<&Mesh3d>, targets: Query<&RenderTarget>) {
    wanted.generation += 1;
    // The same buffers every frame: no allocation once they are large enough.
    wanted.meshes.clear();
    wanted.meshes.extend(meshes.iter().map(|m| m.id()));
    wanted.images.clear();
    wanted.images.extend(targets.iter().filter_map(|t| t.as_image().map(Handle::id)));
}

/// The main world's list, with the frame the render world is about to draw.
fn extract_wanted_assets(mut wanted: ResMut<WantedAssets>, main: bevy::render::Extract<Res<WantedAssets>>) {
    wanted.clone_from(&main);
}

/// Feeds this frame's readiness to the gate (reads the channel, `PoseDirty`,
/// `PendingScene`; writes `CaptureGate`).
fn update_capture_gate(
    channel: Res<DrawnFrames>,
    wanted: Res<WantedAssets>,
    dirty: Query<&PoseDirty>,
    pending: Option<Res<PendingScene>>,
    mut gate: ResMut<CaptureGate>,
) {
    let gpu = channel.status.lock().map(|s| s.clone()).unwrap_or_default();
    let unskinned = dirty.iter().filter(|d| **d != PoseDirty::default()).count();
    let scene_pending = pending.is_some_and(|p| p.doc.is_some());
    gate.note_generations(wanted.generation, gpu.generation);
    gate.observe(gpu.frame, readiness(&gpu, unskinned, scene_pending));
}

/// After the render world's frame: counts pipelines waiting or failed and the wanted
/// assets not prepared (reads `PipelineCache`, render assets; writes the channel).
fn report_gpu_status(
    channel: Res<DrawnFrames>,
    wanted: Res<WantedAssets>,
    cache: Res<PipelineCache>,
    meshes: Res<RenderAssets<RenderMesh>>,
    images: Res<RenderAssets<GpuImage>>,
) {
    // A pipeline whose shader is merely not loaded yet is retried (it stays waiting); one
    // in error and not waiting has failed for good.
    let waiting: std::collections::HashSet<_> = cache.waiting_pipelines().collect();
    let pipelines_failed = cache
        .pipelines()
        .enumerate()
        .filter_map(|(id, p)| match &p.state {
            CachedPipelineState::Err(e) if !waiting.contains(&id) => Some(e.to_string()),
            _ => None,
        })
        .collect::<Vec<_>>();
    let meshes_missing = wanted.meshes.iter().filter(|&&id| meshes.get(id).is_none()).count();
    let images_missing = wanted.images.iter().filter(|&&id| images.get(id).is_none()).count();
    let whole = waiting.is_empty() && pipelines_failed.is_empty() && meshes_missing == 0 && images_missing == 0;
    if let Ok(mut drawn) = channel.drawn.lock() {
        if drawn.len() == DRAWN_KEPT {
            drawn.pop_front();
        }
        drawn.push_back((wanted.generation, whole));
    }
    let Ok(mut status) = channel.status.lock() else { return };
    *status = GpuStatus {
        frame: status.frame + 1,
        generation: wanted.generation,
        pipelines_waiting: waiting.len(),
        pipelines_failed,
        meshes_missing,
        images_missing,
    };
}

//! `marionette render`: the scene rendered offscreen into an image, saved as PNG, without
//! a window (works on Vulkan's llvmpipe on machines without a GPU).

use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use bevy::app::{AppExit, ScheduleRunnerPlugin};
use bevy::camera::RenderTarget;
use bevy::prelude::*;
use bevy::render::render_resource::{TextureFormat, TextureUsages};
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};

use crate::document::AssetLibrary;
use crate::document::frames::{FrameSequence, PictureRequest, frame_path};
use crate::document::picture;
use crate::document::scenes::{read_scene, scene_path};
use crate::editor::interact::camera::OrbitCamera;
use crate::editor::present::readiness::CaptureGate;
use crate::editor::present::stage;
use crate::editor::present::view::ViewPlugin;
use crate::editor::scene_doc::document::Library;
use crate::editor::state::{Messages, StartupEdits, StartupPaths};
use crate::formats::scene::{BackgroundDoc, BindingDoc, ShotDoc, SourceDoc};
use crate::scene::{RigCorePlugin, SkinningPlugin};

/// Seconds after which the render gives up, saying what was still pending.
const GIVE_UP_SECONDS: u64 = 300;

/// The render in progress: for each frame it waits for [`CaptureGate`] (every pipeline
/// compiled, every mesh on the GPU, every character skinned), captures and saves; then
/// puts the clips (and a turntable's camera) at the next frame's time.
#[derive(Resource)]
struct RenderJob {
    /// Each picture's time (none: the scene as it opens) and file.
    frames: Vec<(Option<f32>, PathBuf)>,
    /// Rendered pixels a side of each saved one.
    samples: u32,
    /// The frame being rendered.
    next: usize,
    sequence: Option<FrameSequence>,
    /// The camera's yaw at the first frame (a turntable turns from it).
    first_yaw: Option<f32>,
    target: Handle<Image>,
    started: std::time::Instant,
    /// The capture of `next` was requested.
    requested: bool,
    /// The result of saving `next`, until the next frame is set up.
    saved: Option<Result<(), String>>,
    /// The result of the whole render, once done.
    done: Option<Result<(), String>>,
    /// Where the result and the messages are left for the caller.
    outcome: Arc<Mutex<(Option<Result<(), String>>, Vec<String>)>>,
}

/// Renders `paths` (a scene `.ron`, character files, or the default scene when empty) into
/// `out`, or with `sequence` one picture per frame into the files `out` numbers
/// (`frame_%04d.png`), at the size and samples asked for (else the scene's shot). Returns
/// the notes and the picture's size, or what went wrong.
pub fn render(
    paths: Vec<PathBuf>,
    mut edits: StartupEdits,
    out: PathBuf,
    picture: PictureRequest,
    sequence: Option<FrameSequence>,
) -> Result<(Vec<String>, ShotDoc), String> {
    let frames = match &sequence {
        Some(sequence) => {
            let times = sequence.times()?;
            let paths = (0..times.len()).map(|n| frame_path(&out, n)).collect::<Result<Vec<_>, _>>()?;
            edits.time = times.first().copied();
            times.into_iter().map(Some).zip(paths).collect()
        }
        None => vec![(None, out)],
    };
    let (library, shot) = preload(&paths, &edits)?;
    let picture = picture.resolved(&shot)?;
    let (width, height) = (picture.width, picture.height);
    for (_, out) in &frames {
        crate::formats::error::refuse_overwriting_input(out).map_err(|e| e.to_string())?;
    }
    let mut app = App::new();
    app.add_plugins(crate::editor::windowless_plugins())
        .add_plugins(ScheduleRunnerPlugin::run_loop(Duration::from_millis(2)))
        .insert_resource(ClearColor(stage::SKY))
        .insert_resource(crate::editor::interact::camera::FramingAspect(width as f32 / height as f32))
        .insert_resource(StartupPaths(paths))
        .insert_resource(Library(library))
        .insert_resource(edits)
        .add_plugins((RigCorePlugin, SkinningPlugin, ViewPlugin));
    let target = {
        let mut images = app.world_mut().resource_mut::<Assets<Image>>();
        let (w, h) = (width * picture.samples, height * picture.samples);
        let mut image = Image::new_target_texture(w, h, TextureFormat::Rgba8UnormSrgb, None);
        image.texture_descriptor.usage |= TextureUsages::COPY_SRC;
        images.add(image)
    };
    let outcome = Arc::new(Mutex::new((None, Vec::new())));
    app.insert_resource(RenderJob {
        frames,
        samples: picture.samples,
        next: 0,
        sequence,
        first_yaw: None,
        target: target.clone(),
        started: std::time::Instant::now(),
        requested: false,
        saved: None,
        done: None,
        outcome: outcome.clone(),
    });
    app.add_systems(Startup, move |mut commands: Commands| {
        let orbit = OrbitCamera::default();
        commands.spawn((Camera3d::default(), RenderTarget::Image(target.clone().into()), orbit, orbit.transform()));
    });
    app.add_systems(
        Last,
        (next_frame, capture_when_ready).chain().after(crate::editor::present::readiness::UpdateCaptureGate),
    )
    .add_systems(PostUpdate, clear_behind_gradient.after(stage::apply_stage_settings));
    let exit = app.run();
    // `App::run` hands the world to the runner: the outcome comes back through `outcome`.
    let (done, messages) = outcome.lock().map(|o| o.clone()).unwrap_or_default();

    match (exit, done) {
        (AppExit::Success, Some(Ok(()))) => Ok((messages, picture)),
        (_, Some(Err(e))) => Err(e),
        _ => Err("the render stopped before a picture was captured".to_string()),
    }
}

/// Loads everything the render will show before any window or GPU work, so that a missing
/// file, an unparsable scene, a character or a clip that fails to load is an error (and no
/// picture is written). Returns the loaded assets for the app to reuse.
fn preload(paths: &[PathBuf], edits: &StartupEdits) -> Result<(AssetLibrary, ShotDoc), String> {
    let mut library = AssetLibrary::default();
    let mut shot = ShotDoc::default();
    // Each source and the clip file it plays, with what names it in a scene file (for the message).
    let mut sources: Vec<(SourceDoc, Option<BindingDoc>, Option<PathBuf>, String)> = match scene_path(paths) {
        Some(scene) => read_scene(scene)
            .map_err(|e| e.to_string())
            .inspect(|doc| shot = doc.shot)?
            .characters
            .into_iter()
            .map(|c| {
                let clip = c.anim.filter(|a| a.keys.is_none()).map(|a| a.file);
                (c.source, c.binding, clip, format!(" (character `{}` of {})", c.name, scene.display()))
            })
            .collect(),
        None => paths.iter().flat_map(|p| library.sources_of(p)).map(|s| (s, None, None, String::new())).collect(),
    };
    if let Some(anim) = &edits.anim {
        sources.iter_mut().for_each(|s| s.2 = Some(anim.file.clone()));
    }
    let errors: Vec<String> = sources
        .iter()
        .filter_map(|(source, binding, clip, named_in)| {
            let loaded = library.load_bound(source, *binding).map(drop);
            let clip = clip.as_ref().map_or(Ok(()), |file| library.keyframe_clip(file).map(drop));
            loaded.and(clip).err().map(|e| format!("{e}{named_in}"))
        })
        .collect();
    if errors.is_empty() { Ok((library, shot)) } else { Err(errors.join("\n")) }
}

/// Once the gate opens, captures the target once, saves it and exits; gives up after
/// [`GIVE_UP_SECONDS`] or when a pipeline failed, saying what was pending.
fn capture_when_ready(
    mut commands: Commands,
    mut job: ResMut<RenderJob>,
    gate: Res<CaptureGate>,
    messages: Res<Messages>,
    stage: Res<stage::StageSettings>,
    mut exit: MessageWriter<AppExit>,
) {
    if let Some(done) = job.done.clone() {
        if let Ok(mut o) = job.outcome.lock() {
            *o = (Some(done), messages.0.clone());
        }
        exit.write(AppExit::Success);
        return;
    }
    if let Some(failed) = &gate.failed {
        job.done = Some(Err(format!("cannot render: {failed}")));
        return;
    }
    if job.started.elapsed().as_secs() > GIVE_UP_SECONDS {
        let pending = gate.last_reason.clone().unwrap_or_else(|| "nothing reported".into());
        job.done = Some(Err(format!("the render was not ready within {GIVE_UP_SECONDS} s; still pending: {pending}")));
        return;
    }
    if job.requested || job.saved.is_some() || !gate.is_ready() {
        return;
    }
    job.requested = true;
    let out = job.frames[job.next].1.clone();
    let (samples, background) = (job.samples, stage.background);
    commands.spawn(Screenshot::image(job.target.clone())).observe(
        move |captured: On<ScreenshotCaptured>, mut job: ResMut<RenderJob>| {
            job.saved = Some(save_picture(&captured.image, samples, &background, &out));
        },
    );
}

/// The captured pixels averaged down from their samples, over the background, as PNG.
fn save_picture(image: &Image, samples: u32, background: &BackgroundDoc, out: &std::path::Path) -> Result<(), String> {
    let rendered = image.clone().try_into_dynamic().map_err(|e| format!("unreadable capture: {e}"))?.to_rgba8();
    let picture = picture::over_background(picture::downsampled(&rendered, samples), background);
    let mut bytes = Vec::new();
    picture.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).map_err(|e| e.to_string())?;
    crate::formats::write_atomically(out, |w| std::io::Write::write_all(w, &bytes))
        .map_err(|e| format!("{}: {e}", out.display()))
}

/// A gradient goes behind the picture once captured: the render clears to nothing
/// (reads `StageSettings`; writes `ClearColor`).
fn clear_behind_gradient(settings: Res<stage::StageSettings>, mut clear: ResMut<ClearColor>) {
    if settings.is_changed() && matches!(settings.background, BackgroundDoc::Gradient { .. }) {
        clear.0 = Color::NONE;
    }
}

/// Once a frame is saved: the render is done after the last (or a failed save); else every
/// clip is paused at the next frame's time, a turntable's camera turned to it, and the gate
/// counts its ready frames afresh (writes `ClipPlayer`, `SmplCharacter`, `NodeClipPlayer`,
/// `OrbitCamera`, `CaptureGate`).
fn next_frame(
    mut job: ResMut<RenderJob>,
    mut gate: ResMut<CaptureGate>,
    mut keyframes: Query<&mut crate::scene::keyframes::ClipPlayer>,
    mut smpl: Query<&mut crate::scene::smpl::SmplCharacter>,
    mut node_clips: Query<&mut crate::scene::node_clips::NodeClipPlayer>,
    mut cameras: Query<&mut OrbitCamera>,
) {
    let Some(saved) = job.saved.take() else { return };
    if saved.is_err() || job.next + 1 == job.frames.len() {
        job.done = Some(saved);
        return;
    }
    let first_yaw = *job.first_yaw.get_or_insert_with(|| cameras.iter().next().map_or(0.0, |c| c.0.yaw));
    job.next += 1;
    job.requested = false;
    let Some(t) = job.frames[job.next].0 else { return };
    for mut player in &mut keyframes {
        (player.state.time, player.state.playing) = (t, false);
    }
    for mut body in smpl.iter_mut().filter(|b| b.state.clip.is_some()) {
        (body.state.time, body.state.playing) = (t * crate::rig::smpl::CLIP_FPS, false);
    }
    for mut player in node_clips.iter_mut().filter(|p| p.state.clip.is_some()) {
        (player.state.time, player.state.playing) = (t, false);
    }
    if let Some(sequence) = job.sequence.filter(|s| s.turntable.is_some()) {
        cameras.iter_mut().for_each(|mut c| c.0.yaw = first_yaw + sequence.turn_at(t));
    }
    gate.restart();
}

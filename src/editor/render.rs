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
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;

use super::camera::OrbitCamera;
use super::{Messages, StartupPaths, ViewPlugin, stage};
use crate::scene::{RigCorePlugin, SkinningPlugin};

/// Frames rendered before the first capture.
const WARMUP_FRAMES: u32 = 4;
/// Seconds after which the render gives up.
const GIVE_UP_SECONDS: u64 = 300;

/// The render in progress. Pipelines compile asynchronously over the first frames, so the
/// scene is captured again and again until two captures in a row are identical; that one
/// is saved.
#[derive(Resource)]
struct RenderJob {
    out: PathBuf,
    target: Handle<Image>,
    frames: u32,
    started: std::time::Instant,
    /// A capture is under way.
    waiting: bool,
    previous: Option<Vec<u8>>,
    /// The result of saving, once done.
    done: Option<Result<(), String>>,
    /// Where the result and the messages are left for the caller.
    outcome: Arc<Mutex<(Option<Result<(), String>>, Vec<String>)>>,
}

/// Renders `paths` (a scene `.ron`, character files, or the default scene when empty) at
/// `width`×`height` into `out`. Returns what went wrong, if anything.
pub fn render(
    paths: Vec<PathBuf>,
    edits: super::StartupEdits,
    out: PathBuf,
    width: u32,
    height: u32,
) -> Result<Vec<String>, String> {
    let mut app = App::new();
    app.add_plugins(
        DefaultPlugins
            .set(WindowPlugin {
                primary_window: None,
                exit_condition: ExitCondition::DontExit,
                close_when_requested: false,
                ..default()
            })
            .disable::<WinitPlugin>(),
    )
    .add_plugins(ScheduleRunnerPlugin::run_loop(Duration::from_millis(2)))
    .insert_resource(ClearColor(stage::SKY))
    .insert_resource(StartupPaths(paths))
    .insert_resource(edits)
    .add_plugins((RigCorePlugin, SkinningPlugin, ViewPlugin));
    let target = {
        let mut images = app.world_mut().resource_mut::<Assets<Image>>();
        let mut image = Image::new_target_texture(width, height, TextureFormat::Rgba8UnormSrgb, None);
        image.texture_descriptor.usage |= TextureUsages::COPY_SRC;
        images.add(image)
    };
    let outcome = Arc::new(Mutex::new((None, Vec::new())));
    app.insert_resource(RenderJob {
        out,
        target: target.clone(),
        frames: 0,
        started: std::time::Instant::now(),
        waiting: false,
        previous: None,
        done: None,
        outcome: outcome.clone(),
    });
    app.add_systems(Startup, move |mut commands: Commands| {
        let orbit = OrbitCamera::default();
        commands.spawn((Camera3d::default(), RenderTarget::Image(target.clone().into()), orbit, orbit.transform()));
    });
    app.add_systems(Last, capture_when_ready);
    let exit = app.run();
    // `App::run` hands the world to the runner: the outcome comes back through `outcome`.
    let (done, messages) = outcome.lock().map(|o| o.clone()).unwrap_or_default();

    match (exit, done) {
        (AppExit::Success, Some(Ok(()))) => Ok(messages),
        (_, Some(Err(e))) => Err(e),
        _ => Err(format!("the render did not settle within {GIVE_UP_SECONDS} s")),
    }
}

/// After the warm-up, captures the target until two captures agree, saves that one and
/// exits (or gives up after a while).
fn capture_when_ready(
    mut commands: Commands,
    mut job: ResMut<RenderJob>,
    messages: Res<Messages>,
    mut exit: MessageWriter<AppExit>,
) {
    job.frames += 1;
    if job.done.is_some() {
        if let Ok(mut o) = job.outcome.lock() {
            *o = (job.done.clone(), messages.0.clone());
        }
        exit.write(AppExit::Success);
        return;
    }
    if job.started.elapsed().as_secs() > GIVE_UP_SECONDS {
        exit.write(AppExit::error());
        return;
    }
    if job.frames < WARMUP_FRAMES || job.waiting {
        return;
    }
    job.waiting = true;
    let out = job.out.clone();
    commands.spawn(Screenshot::image(job.target.clone())).observe(
        move |captured: On<ScreenshotCaptured>, mut job: ResMut<RenderJob>| {
            job.waiting = false;
            let data = captured.image.data.clone().unwrap_or_default();
            if job.previous.as_ref() == Some(&data) {
                job.done = Some(super::screenshot::save_png(&captured.image, &out));
            } else {
                job.previous = Some(data);
            }
        },
    );
}

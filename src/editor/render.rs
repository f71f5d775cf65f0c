//! `marionette render`: the scene rendered offscreen into an image, saved as PNG, without
//! a window (works on Vulkan's llvmpipe on machines without a GPU).

use std::path::PathBuf;
use std::time::Duration;

use bevy::app::{AppExit, ScheduleRunnerPlugin};
use bevy::camera::RenderTarget;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;

use super::camera::OrbitCamera;
use super::{Messages, StartupPaths, ViewPlugin, stage};
use crate::scene::{RigCorePlugin, SkinningPlugin};

/// Frames rendered before the capture (pipelines compile over the first frames).
const WARMUP_FRAMES: u32 = 12;
/// Frames after which the render gives up.
const GIVE_UP_FRAMES: u32 = 3000;

#[derive(Resource)]
struct RenderJob {
    out: PathBuf,
    target: Handle<Image>,
    frames: u32,
    requested: bool,
    /// Set by the capture observer: the result of saving.
    done: Option<Result<(), String>>,
}

/// Renders `paths` (a scene `.ron`, character files, or the default scene when empty) at
/// `width`×`height` into `out`. Returns what went wrong, if anything.
pub fn render(paths: Vec<PathBuf>, out: PathBuf, width: u32, height: u32) -> Result<Vec<String>, String> {
    let mut app = App::new();
    app.add_plugins(
        DefaultPlugins
            .set(WindowPlugin { primary_window: None, exit_condition: ExitCondition::DontExit, close_when_requested: false, ..default() })
            .disable::<WinitPlugin>(),
    )
    .add_plugins(ScheduleRunnerPlugin::run_loop(Duration::ZERO))
    .insert_resource(ClearColor(stage::SKY))
    .insert_resource(StartupPaths(paths))
    .add_plugins((RigCorePlugin, SkinningPlugin, ViewPlugin));
    let target = {
        let mut images = app.world_mut().resource_mut::<Assets<Image>>();
        images.add(Image::new_target_texture(width, height, TextureFormat::Rgba8UnormSrgb, None))
    };
    app.insert_resource(RenderJob { out, target: target.clone(), frames: 0, requested: false, done: None });
    app.add_systems(Startup, move |mut commands: Commands| {
        let orbit = OrbitCamera::default();
        commands.spawn((Camera3d::default(), RenderTarget::Image(target.clone().into()), orbit, orbit.transform()));
    });
    app.add_systems(Last, capture_when_ready);
    let exit = app.run();
    let messages = app.world().get_resource::<Messages>().map(|m| m.0.clone()).unwrap_or_default();
    let done = app.world().get_resource::<RenderJob>().and_then(|j| j.done.clone());
    match (exit, done) {
        (AppExit::Success, Some(Ok(()))) => Ok(messages),
        (_, Some(Err(e))) => Err(e),
        _ => Err(format!("the render did not finish within {GIVE_UP_FRAMES} frames")),
    }
}

/// After the warm-up, captures the target image; exits once it is saved (or on time-out).
fn capture_when_ready(mut commands: Commands, mut job: ResMut<RenderJob>, mut exit: MessageWriter<AppExit>) {
    job.frames += 1;
    if job.done.is_some() {
        exit.write(AppExit::Success);
        return;
    }
    if job.frames > GIVE_UP_FRAMES {
        exit.write(AppExit::error());
        return;
    }
    if job.frames >= WARMUP_FRAMES && !job.requested {
        job.requested = true;
        let out = job.out.clone();
        commands.spawn(Screenshot::image(job.target.clone())).observe(move |captured: On<ScreenshotCaptured>, mut job: ResMut<RenderJob>| {
            job.done = Some(super::screenshot::save_png(&captured.image, &out));
        });
    }
}

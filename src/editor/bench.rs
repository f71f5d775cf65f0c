//! `marionette bench`: a crowd of animated characters, headless, through the real app
//! schedule and the render world (extraction and upload; the picture is drawn into a small
//! offscreen target), timed per phase over many frames, with the skinning kernel's speed on
//! one of its characters. The kernels against each other and against ozz are `benches/`'s.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use bevy::app::AppExit;
use bevy::camera::RenderTarget;
use bevy::prelude::*;
use bevy::render::pipelined_rendering::PipelinedRenderingPlugin;
use bevy::render::render_resource::{TextureFormat, TextureUsages};
use bevy::render::{Render, RenderApp, RenderSystems};

use crate::document::crowd::{puppet_crowd, smpl_crowd};
use crate::editor::present::readiness::CaptureGate;
use crate::editor::scene_doc::document::PendingScene;
use crate::editor::state::camera::OrbitCamera;
use crate::rig::{CharacterAsset, JointRotation};
use crate::scene::smpl::SmplCharacter;
use crate::scene::upload::HandedOn;
use crate::scene::{Character, JointPose, MarionetteSystems, RigCorePlugin, SkinningPlugin};

/// What one run measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct BenchReport {
    pub measured: Measured,
    /// Every phase's (and the whole frame's) 50th and 95th percentiles.
    pub phases_ms: std::collections::BTreeMap<String, Percentiles>,
    pub characters: usize,
    pub kind: String,
    /// Skinned by the GPU skinning compute shader (else on the CPU).
    pub gpu_skinning: bool,
    pub vertices_per_character: usize,
    pub frames: usize,
    /// CPU work of a frame: main-world schedule, extraction, and the render world's asset
    /// and mesh preparation (the upload, or the GPU skinning's dispatch).
    pub frame_ms_p50: f64,
    pub frame_ms_p95: f64,
    /// Medians of the phases.
    pub sampling_ms_p50: f64,
    pub fk_ms_p50: f64,
    pub skin_ms_p50: f64,
    /// The skin phase against its ideal: the crowd's vertices at the kernel's speed
    /// (`kernel_mvps`) on every core, `skin_ms_p50 ÷ (vertices ÷ (kernel × cores))`, on as
    /// many cores as the phase has characters (or chunks of one) to share among them (a
    /// figure of CPU skinning: with `gpu_skinning` the phase only bounds and hands over).
    pub skin_over_ideal: f64,
    pub extract_ms_p50: f64,
    pub upload_ms_p50: f64,
    /// The rest of the render world (drawing; on llvmpipe that is CPU work too).
    pub render_world_ms_p50: f64,
    pub upload_bytes_per_frame: usize,
    /// The LBS kernel on one character of the crowd, positions only, on one core, in M
    /// vertices per second.
    pub kernel_mvps: f64,
}

/// The 50th and 95th percentiles of a phase, in milliseconds.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Percentiles {
    pub p50: f64,
    pub p95: f64,
}

impl Percentiles {
    fn of(samples: Vec<f64>) -> Self {
        Self { p50: percentile(samples.clone(), 0.5), p95: percentile(samples, 0.95) }
    }
}

/// How a run was measured, so two runs can be compared.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Measured {
    /// The cores the process may use.
    pub cores: usize,
    /// The build profile (`debug` is the dev profile, marionette at opt-level 3) and whether
    /// debug assertions (and overflow checks) were on.
    pub profile: String,
    pub debug_assertions: bool,
    /// Bevy's pipelined rendering (off: each phase is timed in order).
    pub pipelined_rendering: bool,
    /// The level of the skinning kernels this CPU ran (`Avx512Vl`, `Avx2` or `Portable`).
    pub kernel_level: String,
    /// Whether the picture was drawn between the measured frames (`--no-draw`: not, as on
    /// a machine whose GPU draws it; on llvmpipe the drawing is CPU work that empties the
    /// caches between frames).
    pub drawn: bool,
}

impl Measured {
    fn now(pipelined_rendering: bool, drawn: bool) -> Self {
        Self {
            cores: core_count(),
            profile: env!("MARIONETTE_BUILD_PROFILE").to_string(),
            debug_assertions: cfg!(debug_assertions),
            pipelined_rendering,
            kernel_level: format!("{:?}", crate::rig::simd::Simd::best()),
            drawn,
        }
    }
}

/// The cores the process may use.
fn core_count() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// What `bench` runs.
#[derive(Debug, Clone)]
pub struct Setup {
    pub characters: usize,
    pub frames: usize,
    pub crowd: CrowdOf,
    /// Skinned by the GPU skinning compute shader (else on the CPU).
    pub gpu_skinning: bool,
    /// The picture drawn between the measured frames.
    pub drawn: bool,
}

/// What the crowd is made of.
#[derive(Debug, Clone, PartialEq)]
pub enum CrowdOf {
    /// SMPL bodies from this SMPL folder.
    Smpl(PathBuf),
    Puppets,
}

/// The crowd `bench` runs: puppets when asked (`--puppets`); else SMPL bodies from `data`
/// (the data folder with its `smpl`, or an SMPL folder itself; `MARIONETTE_DATA` when not
/// given); puppets when no folder is named at all. A folder named that holds no SMPL body
/// is refused (it used to fall back to puppets without a word).
pub fn crowd_of(data: Option<PathBuf>, puppets: bool) -> Result<CrowdOf, String> {
    if puppets {
        return Ok(CrowdOf::Puppets);
    }
    let Some(dir) = data.or_else(|| std::env::var_os("MARIONETTE_DATA").map(PathBuf::from)) else {
        return Ok(CrowdOf::Puppets);
    };
    let is_smpl = crate::formats::smpl::is_smpl_dir;
    [dir.join("smpl"), dir.clone()].into_iter().find(|d| is_smpl(d)).map(CrowdOf::Smpl).ok_or_else(|| {
        format!(
            "{}: expected the data folder (with `smpl/`) or an SMPL folder (smpl_00.obj, smpl_skin.txt …), found neither \
             (`--puppets` benchmarks the project's puppets)",
            dir.display()
        )
    })
}

/// Instants at the phase boundaries of the main world's frame.
#[derive(Resource, Default)]
struct MainClock([Option<Instant>; 4]);

/// Instants around the render world's asset preparation.
#[derive(Resource, Default)]
struct RenderClock([Option<Instant>; 2]);

/// Runs the crowd bench as `setup` says: SMPL bodies (clips and β varied, all playing) or
/// puppets swaying; skinned on the CPU or by the GPU skinning compute shader; the picture
/// drawn between frames or not.
pub fn run(setup: &Setup) -> Result<BenchReport, String> {
    let Setup { characters, frames, ref crowd, gpu_skinning, drawn } = *setup;
    let smpl_dir = match crowd {
        CrowdOf::Smpl(dir) => Some(dir.clone()),
        CrowdOf::Puppets => None,
    };
    let (mut doc, kind) = match &smpl_dir {
        Some(dir) => (smpl_crowd(dir, characters).map_err(|e| e.to_string())?, "SMPL body"),
        None => (puppet_crowd(characters), "puppet"),
    };
    // No shadows: the drawing (not what is measured) stays affordable on llvmpipe.
    doc.stage.shadows = false;
    doc.characters.iter_mut().for_each(|c| c.gpu_skinning = gpu_skinning);
    let mut app = crowd_app(smpl_dir.is_none());
    let pipelined_rendering = app.is_plugin_added::<PipelinedRenderingPlugin>();
    app.finish();
    app.cleanup();
    app.update();
    *app.world_mut().resource_mut::<PendingScene>() = PendingScene { doc: Some(doc), frame: true };
    warm_up(&mut app)?;
    let asset = first_character_asset(&mut app).ok_or("the crowd has no character")?;
    if !drawn {
        stop_drawing(&mut app);
    }
    let mut samples = Vec::with_capacity(frames);
    let mut bytes = 0;
    for _ in 0..frames {
        samples.push(timed_frame(&mut app));
        bytes += app.world().resource::<HandedOn>().0;
    }
    let kernel_mvps = kernel_speed(&asset);
    let measured = Measured::now(pipelined_rendering, drawn);
    let cores = measured.cores;
    let phase = |k: usize| median(samples.iter().map(|s| s[k]).collect());
    let frame: Vec<f64> = samples.iter().map(|s| s[1] + s[2] + s[3] + s[4] + s[5]).collect();
    let names = ["sampling", "fk", "skin", "extract", "upload", "render_world"];
    let whole = Percentiles::of(frame);
    let vertices_each = asset.vertex_count();
    let phases_ms = names
        .iter()
        .enumerate()
        .map(|(k, name)| (name.to_string(), Percentiles::of(samples.iter().map(|s| s[k + 1]).collect())))
        .chain([("frame".to_string(), whole)])
        .collect();
    Ok(BenchReport {
        measured,
        phases_ms,
        characters,
        kind: kind.to_string(),
        gpu_skinning,
        vertices_per_character: vertices_each,
        frames,
        frame_ms_p50: whole.p50,
        frame_ms_p95: whole.p95,
        sampling_ms_p50: phase(1),
        fk_ms_p50: phase(2),
        skin_ms_p50: phase(3),
        skin_over_ideal: phase(3) / ideal_skin_ms(characters, vertices_each, kernel_mvps, cores),
        extract_ms_p50: phase(4),
        upload_ms_p50: phase(5),
        render_world_ms_p50: phase(6),
        upload_bytes_per_frame: bytes / frames.max(1),
        kernel_mvps,
    })
}

/// The vertices of `characters` of `vertices_each` skinned at `kernel_mvps` on each of
/// `cores`, in milliseconds; on fewer cores where the phase has fewer tasks than cores (one
/// a character, one a chunk of a character larger than a chunk).
pub fn ideal_skin_ms(characters: usize, vertices_each: usize, kernel_mvps: f64, cores: usize) -> f64 {
    let tasks = characters * vertices_each.div_ceil(crate::scene::systems::SKIN_CHUNK_VERTICES);
    let used = cores.clamp(1, tasks.max(1));
    (characters * vertices_each) as f64 / (kernel_mvps * used as f64 * 1e6) * 1e3
}

/// Turns the cameras off once the renderer is ready: extraction and the upload go on, the
/// picture is no longer drawn.
fn stop_drawing(app: &mut App) {
    let world = app.world_mut();
    for mut camera in world.query::<&mut Camera>().iter_mut(world) {
        camera.is_active = false;
    }
}

/// The report as a table.
pub fn table(r: &BenchReport) -> String {
    let m = &r.measured;
    let profile = if m.debug_assertions {
        format!("{} profile, debug assertions on", m.profile)
    } else {
        format!("{} profile", m.profile)
    };
    let how = format!(
        "measured on {} cores, {profile}, pipelined rendering {}, kernels at level {}, picture {}\n",
        m.cores,
        if m.pipelined_rendering { "on" } else { "off" },
        m.kernel_level,
        if m.drawn { "drawn" } else { "not drawn (--no-draw)" }
    );
    how + &format!(
        "{} × {} ({} vertices each), {} frames, skinned {}\n\
         frame (CPU: main world + extraction + upload)  p50 {:.2} ms  p95 {:.2} ms\n\
         \x20 sampling {:.2} ms | FK {:.2} ms | skin {:.2} ms | extract {:.2} ms | upload {:.2} ms   (medians)\n\
         \x20 skin ÷ ideal (the vertices at the kernel's speed on every core it can use) {:.2}\n\
         \x20 render world besides the upload (drawing; CPU on llvmpipe) {:.2} ms\n\
         mesh data handed on per frame: {} bytes\n\
         kernel: {:.1} M vertices/s per core (the kernels against each other and ozz: `cargo bench`)",
        r.characters,
        r.kind,
        r.vertices_per_character,
        r.frames,
        if r.gpu_skinning { "by the GPU compute shader" } else { "on the CPU" },
        r.frame_ms_p50,
        r.frame_ms_p95,
        r.sampling_ms_p50,
        r.fk_ms_p50,
        r.skin_ms_p50,
        r.extract_ms_p50,
        r.upload_ms_p50,
        r.skin_over_ideal,
        r.render_world_ms_p50,
        r.upload_bytes_per_frame,
        r.kernel_mvps,
    )
}

/// The headless app: the editor's scene, stage and drawing, rendered into a small image
/// without pipelining (so each phase can be timed in order), with clocks at the phase
/// boundaries.
fn crowd_app(sway: bool) -> App {
    let mut app = App::new();
    app.add_plugins(crate::editor::cores::windowless_plugins().disable::<PipelinedRenderingPlugin>())
        .add_plugins((RigCorePlugin, SkinningPlugin, crate::editor::present::view::ViewPlugin))
        .init_resource::<MainClock>()
        .add_systems(Startup, spawn_offscreen_camera)
        .add_systems(PostUpdate, stamp::<0>.before(MarionetteSystems::Animate))
        .add_systems(PostUpdate, stamp::<1>.after(MarionetteSystems::Animate).before(MarionetteSystems::Solve))
        .add_systems(PostUpdate, stamp::<2>.after(MarionetteSystems::MatrixStack).before(MarionetteSystems::Skin))
        .add_systems(PostUpdate, stamp::<3>.after(MarionetteSystems::Skin));
    if sway {
        app.add_systems(PostUpdate, sway_puppets.in_set(MarionetteSystems::Animate));
    }
    let render = app.sub_app_mut(RenderApp);
    render.init_resource::<RenderClock>();
    render.add_systems(Render, render_stamp::<0>.before(RenderSystems::PrepareAssets));
    render.add_systems(Render, render_stamp::<1>.after(RenderSystems::PrepareMeshes).before(RenderSystems::Prepare));
    app
}

fn stamp<const K: usize>(mut clock: ResMut<MainClock>) {
    clock.0[K] = Some(Instant::now());
}

fn render_stamp<const K: usize>(mut clock: ResMut<RenderClock>) {
    clock.0[K] = Some(Instant::now());
}

fn spawn_offscreen_camera(mut commands: Commands, mut images: ResMut<Assets<Image>>) {
    let mut image = Image::new_target_texture(320, 240, TextureFormat::Rgba8UnormSrgb, None);
    image.texture_descriptor.usage |= TextureUsages::COPY_SRC;
    let target = images.add(image);
    let orbit = OrbitCamera::default();
    let slot = crate::editor::present::stage::slot_camera(crate::scene::Slot(0));
    commands.spawn((Camera3d::default(), RenderTarget::Image(target.into()), orbit, orbit.transform(), slot));
}

/// Puppets have no clips: every joint sways with time, so every puppet re-skins each frame.
fn sway_puppets(
    time: Res<Time>,
    characters: Query<&Character, Without<SmplCharacter>>,
    mut poses: Query<&mut JointPose>,
) {
    let t = time.elapsed_secs();
    for (i, character) in characters.iter().enumerate() {
        for (j, &joint) in character.joints.iter().enumerate().skip(1) {
            if let Ok(mut pose) = poses.get_mut(joint) {
                let a = 0.2 * (t * 2.0 + i as f32 * 0.7 + j as f32 * 0.3).sin();
                pose.0 = JointRotation::euler_xyz(a, 0.0, a * 0.5);
            }
        }
    }
}

/// Runs frames until every pipeline is compiled and every mesh is on the GPU (at most a
/// few minutes on llvmpipe), then a few more.
fn warm_up(app: &mut App) -> Result<(), String> {
    let started = Instant::now();
    while !app.world().get_resource::<CaptureGate>().is_some_and(CaptureGate::is_ready) {
        if started.elapsed() > Duration::from_secs(300) {
            return Err("the renderer was not ready within 300 s".to_string());
        }
        if let Some(exit) = app.should_exit()
            && exit != AppExit::Success
        {
            return Err("the app stopped while warming up".to_string());
        }
        app.update();
    }
    for _ in 0..10 {
        app.update();
    }
    Ok(())
}

fn first_character_asset(app: &mut App) -> Option<std::sync::Arc<CharacterAsset>> {
    let world = app.world_mut();
    world.query::<&Character>().iter(world).next().map(|c| c.asset.clone())
}

/// One frame, as `App::update` runs it, timed: [whole, sampling, FK, skin, extract, upload,
/// rest of the render world] in milliseconds.
fn timed_frame(app: &mut App) -> [f64; 7] {
    let start = Instant::now();
    let apps = app.sub_apps_mut();
    apps.main.run_default_schedule();
    let mut extract = Duration::ZERO;
    let mut render = Duration::ZERO;
    for sub_app in apps.sub_apps.values_mut() {
        let t = Instant::now();
        sub_app.extract(apps.main.world_mut());
        extract += t.elapsed();
        let t = Instant::now();
        sub_app.update();
        render += t.elapsed();
    }
    apps.main.world_mut().clear_trackers();
    let total = start.elapsed();
    wait_for_the_gpu(app);
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let clock = app.world().resource::<MainClock>().0;
    let between = |a: usize, b: usize| match (clock[a], clock[b]) {
        (Some(a), Some(b)) => ms(b.saturating_duration_since(a)),
        _ => 0.0,
    };
    let upload = app.sub_app(RenderApp).world().get_resource::<RenderClock>().map_or(0.0, |c| match c.0 {
        [Some(a), Some(b)] => ms(b.saturating_duration_since(a)),
        _ => 0.0,
    });
    [ms(total), between(0, 1), between(1, 2), between(2, 3), ms(extract), upload, (ms(render) - upload).max(0.0)]
}

/// Waits until the GPU has finished the frame: on llvmpipe its rasterising threads would
/// otherwise share the CPU with the next frame's measured work.
fn wait_for_the_gpu(app: &App) {
    if let Some(device) = app.sub_app(RenderApp).world().get_resource::<bevy::render::renderer::RenderDevice>() {
        let _ = device.poll(bevy::render::render_resource::PollType::wait_indefinitely());
    }
}

/// Calls of the kernel in a row in [`kernel_speed`], the first not timed.
const BURST: usize = 8;

/// The LBS kernel on one posed character, in M vertices per second: the median call of
/// bursts run for 300 ms (the first call of each burst not kept: it finds the memory where
/// the frame left it).
fn kernel_speed(asset: &CharacterAsset) -> f64 {
    let palette = posed_palette(asset);
    let skin = &asset.skin;
    let mut out = vec![Vec3::ZERO; asset.vertex_count()];
    let mut seconds = Vec::new();
    let started = Instant::now();
    while started.elapsed() < Duration::from_millis(300) {
        seconds.extend(burst(BURST - 1, || {
            crate::rig::lbs::skin(&skin.bind_positions, &skin.weights, &palette, &mut out)
        }));
    }
    skin.bind_positions.len() as f64 / median(seconds) / 1e6
}

/// `call` once, not timed (it finds its memory where other work left it), then `timed`
/// times, each timed: their seconds.
fn burst(timed: usize, mut call: impl FnMut()) -> Vec<f64> {
    call();
    (0..timed)
        .map(|_| {
            let t = Instant::now();
            call();
            t.elapsed().as_secs_f64()
        })
        .collect()
}

/// The character posed away from its bind pose: its palette.
fn posed_palette(asset: &CharacterAsset) -> Vec<Mat4> {
    let pose: Vec<JointRotation> =
        (0..asset.skeleton.len()).map(|i| JointRotation::euler_xyz(0.1 * i as f32, 0.05, -0.02)).collect();
    crate::rig::fk::posed_palette(&asset.skeleton, &asset.bind_world_to_joint, &pose, Mat4::IDENTITY)
}

fn median(v: Vec<f64>) -> f64 {
    percentile(v, 0.5)
}

/// The `q` quantile (nearest rank) of `v`.
fn percentile(mut v: Vec<f64>, q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let rank = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len());
    v[rank - 1]
}

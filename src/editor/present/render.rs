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
use crate::document::annotate;
use crate::document::annotate::controlnet::ControlNet;
use crate::document::drawing::{self, LightSetup};
use crate::document::frames::{FrameSequence, PictureRequest, Pictures, frame_path, sequence_path};
use crate::document::picture;
use crate::document::scenes::{read_scene, scene_path};
use crate::editor::present::data::{Beside, DataFrame, DataScene};
use crate::editor::present::readiness::{CaptureGate, DrawnFrames, WantedAssets};
use crate::editor::present::stage;
use crate::editor::present::view::{SceneToOpen, ViewPlugin};
use crate::editor::scene_doc::document::Library;
use crate::editor::state::camera::OrbitCamera;
use crate::editor::state::{Messages, StartupEdits, StartupPaths};
use crate::formats::scene::{Antialias, BackgroundDoc, BindingDoc, Clocked, SceneDoc, ShotDoc, SourceDoc};
use crate::formats::scene::{MotionSourceDoc, RetargetDoc};
use crate::scene::{RigCorePlugin, SkinningPlugin, Slot};

/// Seconds a picture may wait to be ready (from the start, or from the last picture
/// captured) before the render gives up, saying what was still pending.
const GIVE_UP_SECONDS: u64 = 300;

/// The render in progress: for each frame it waits for [`CaptureGate`] (every pipeline
/// compiled, every mesh on the GPU, every character skinned), captures and saves; then
/// puts the clips (and a turntable's camera) at the next frame's time.
#[derive(Resource)]
struct RenderJob {
    /// What each picture shows, its file and the rest of what it needs.
    frames: Vec<Frame>,
    /// The frame `next` shows what it should (its pose applied).
    set_up: bool,
    /// Rendered pixels a side of each saved one.
    samples: u32,
    /// The pictures in the order they are drawn: each once, and again at the end where its
    /// capture was of a frame not drawn whole.
    queue: Vec<usize>,
    /// The place in `queue` of the picture being set up or captured next (all are captured
    /// once it is the queue's length).
    next: usize,
    /// The scenes a frame draws, slot by slot.
    slots: Vec<SlotView>,
    /// How many pictures from `next` on are set up, in the slots from the first.
    drawing: usize,
    sequence: Option<FrameSequence>,
    /// The camera's yaw at the first frame (a turntable turns from it).
    first_yaw: Option<f32>,
    started: std::time::Instant,
    /// Pictures captured whose files are not written yet.
    in_flight: usize,
    /// What the threads writing pictures finished with: the picture's index, and its COCO
    /// image and annotations (with `--data`) or why it could not be written.
    written: Arc<Mutex<Vec<(usize, Result<Option<CocoPart>, String>)>>>,
    /// The first failure to write a picture's files.
    failed_save: Option<String>,
    /// When the first and the last pictures so far were captured, the app's updates between
    /// them, and how many pictures the first frame captured held.
    captures: Option<(std::time::Instant, std::time::Instant, u64, usize)>,
    /// The result of the whole render, once done.
    done: Option<Result<(), String>>,
    /// Where the result and the messages are left for the caller.
    outcome: Arc<Mutex<(Option<Result<(), String>>, Vec<String>)>>,
    /// `--data`: the COCO file's path and its images and annotations so far (the passes
    /// are written beside each picture as it is saved).
    data: Option<CocoSoFar>,
    /// Write the maps ControlNet reads beside each picture.
    controlnet: Option<ControlNet>,
    /// The saved picture's width and height.
    size: (u32, u32),
    /// Each picture's data carries a COCO file of its own (a data set's), not a share of one
    /// for the whole render.
    coco_per_picture: bool,
    /// Called with a picture's index once its files are written (a data set's manifest).
    on_written: Option<OnWritten>,
    /// The first picture shows the scene the app opened with (else each picture's scene
    /// is opened in place of the last, the first's too).
    opened: bool,
    /// Keep each picture in memory here instead of writing its files.
    kept: Option<KeptPictures>,
    /// The character files the pictures set up so far drew (kept from render to render).
    sources_drawn: std::collections::HashSet<SourceDoc>,
}

/// One of the scenes a frame draws: where its picture is drawn, and how the last scene
/// set up in it was lit (kept from render to render).
struct SlotView {
    target: Handle<Image>,
    last_lights: Option<LightSetup>,
}

/// What is called with a picture's index once its files are written.
pub type OnWritten = Box<dyn FnMut(usize) -> Result<(), String> + Send + Sync>;

/// One picture of a render: what it shows, its file, its COCO ids (the image's, the first
/// annotation's) and a picture to put behind it.
struct Frame {
    at: FrameAt,
    out: PathBuf,
    ids: (u64, u64),
    backdrop: Option<PathBuf>,
}

impl Frame {
    /// The `index`-th picture of a render: COCO ids numbered from it.
    fn new(at: FrameAt, out: PathBuf, index: usize) -> Self {
        Frame { at, out, ids: (index as u64 + 1, 0), backdrop: None }
    }

    /// The scene of its own it shows, if any.
    fn scene(&self) -> Option<&SceneDoc> {
        match &self.at {
            FrameAt::Scene(doc) => Some(doc),
            _ => None,
        }
    }
}

/// One picture of a data set: its scene (sources resolved), its file, its COCO ids (the
/// image's, the first annotation's) and a picture filling the frame behind it.
pub struct ScenePicture {
    pub scene: SceneDoc,
    pub out: PathBuf,
    pub ids: (u64, u64),
    pub backdrop: Option<PathBuf>,
}

/// A picture's COCO image and annotations.
type CocoPart = (serde_json::Value, Vec<serde_json::Value>);

/// A picture kept in memory ([`Renderer::draw`]): as its file would hold it, and what was
/// asked beside it.
pub struct Kept {
    pub picture: image::DynamicImage,
    pub beside: Option<crate::editor::present::data::KeptBeside>,
}

/// Where the pictures of [`Renderer::draw`] are kept as they are captured, by index.
type KeptPictures = Arc<Mutex<Vec<(usize, Kept)>>>;

/// A render's COCO file as it fills, a picture at a time.
#[derive(Default)]
struct CocoSoFar {
    path: PathBuf,
    images: Vec<serde_json::Value>,
    annotations: Vec<serde_json::Value>,
}

/// What one picture shows.
#[derive(Debug, Clone, PartialEq)]
enum FrameAt {
    /// The scene as it opens.
    AsOpened,
    /// Every clip paused at this time (seconds).
    Time(f32),
    /// Every character in this pose of the scene's library.
    Pose(String),
    /// This scene, in place of the last.
    Scene(Box<SceneDoc>),
}

/// Renders `paths` (a scene `.ron`, character files, or the default scene when empty) into
/// `out`: one picture, one per frame of a sequence, or a contact sheet of the scene's
/// poses; at the size and samples asked for (else the scene's shot; a sheet's cells).
/// Returns the notes and the picture's size, or what went wrong.
pub fn render(
    paths: Vec<PathBuf>,
    edits: StartupEdits,
    out: PathBuf,
    picture: PictureRequest,
    pictures: Pictures,
    data: bool,
) -> Result<(Vec<String>, ShotDoc), String> {
    render_with(Rendering { paths, edits, out, picture, pictures, data, controlnet: None }, None)
}

/// What [`render`] is asked for.
pub struct Rendering {
    pub paths: Vec<PathBuf>,
    pub edits: StartupEdits,
    pub out: PathBuf,
    pub picture: PictureRequest,
    pub pictures: Pictures,
    pub data: bool,
    /// `--controlnet`: the maps ControlNet reads beside each picture.
    pub controlnet: Option<ControlNet>,
}

/// [`render`], calling `on_written` with each picture's index once its files are written
/// (where given; else each picture's progress is said on standard error). The render stops
/// at the first call that fails, with its error.
pub fn render_with(
    Rendering { paths, mut edits, out, picture, pictures, data, controlnet }: Rendering,
    on_written: Option<OnWritten>,
) -> Result<(Vec<String>, ShotDoc), String> {
    let data = match (data, pictures) {
        (false, _) => None,
        (true, Pictures::PoseSheet) => return Err("--data: a contact sheet of poses carries no data".into()),
        (true, Pictures::Sequence(_)) => {
            Some(CocoSoFar { path: sequence_path(&out, "json").map_err(|e| e.to_string())?, ..default() })
        }
        (true, Pictures::Still) => Some(CocoSoFar { path: annotate::write::beside(&out, "json"), ..default() }),
    };
    let (library, mut shot, poses) = preload(&paths, &edits)?;
    if let Some(size) = edits.pose.fitted_picture_size() {
        (shot.width, shot.height) = size;
    }
    let cells = std::env::temp_dir().join(format!("marionette-sheet-{}", std::process::id()));
    let (frames, sequence): (Vec<(FrameAt, PathBuf)>, _) = match pictures {
        Pictures::Sequence(sequence) => {
            let times = sequence.times().map_err(|e| e.to_string())?;
            let paths = (0..times.len())
                .map(|n| frame_path(&out, n))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| e.to_string())?;
            edits.time = times.first().copied();
            (times.into_iter().map(FrameAt::Time).zip(paths).collect(), Some(sequence))
        }
        Pictures::Still => {
            edits.still = true;
            (vec![(FrameAt::AsOpened, out.clone())], None)
        }
        Pictures::PoseSheet => {
            // The scene's library, else the built-in body poses.
            let poses = match poses.is_empty() {
                true => crate::rig::body_poses::POSES.iter().map(|p| p.name.to_string()).collect(),
                false => poses,
            };
            std::fs::create_dir_all(&cells).map_err(|e| format!("{}: {e}", cells.display()))?;
            let at = |k: usize| cells.join(format!("pose_{k:04}.png"));
            (poses.iter().enumerate().map(|(k, name)| (FrameAt::Pose(name.clone()), at(k))).collect(), None)
        }
    };
    let picture = picture.resolved(&shot).map_err(|e| e.to_string())?;
    for out in frames.iter().map(|f| &f.1).chain([&out]) {
        crate::formats::error::refuse_overwriting_input(out).map_err(|e| e.to_string())?;
    }
    let cell_files: Vec<PathBuf> = frames.iter().map(|f| f.1.clone()).collect();
    let frames = frames.into_iter().enumerate().map(|(k, (at, out))| Frame::new(at, out, k)).collect();
    let setup = JobSetup {
        paths,
        library,
        edits,
        picture,
        frames,
        sequence,
        data,
        controlnet,
        coco_per_picture: false,
        on_written,
        scenes_a_frame: Some(1),
    };
    let done = run_job(setup);
    let done = match (pictures, done) {
        (Pictures::PoseSheet, Ok(messages)) => contact_sheet(&cell_files, &out).map(|()| messages),
        (_, done) => done,
    };
    if pictures == Pictures::PoseSheet {
        let _ = std::fs::remove_dir_all(&cells);
    }
    done.map(|messages| (messages, picture))
}

/// Renders a data set's pictures, each its own scene, in one app: `first_scene` (the file
/// of the first picture's scene) opens it; every picture after loads its scene in place of
/// the last, with what `beside` asks written beside it; `on_written` is called with a
/// picture's index once its files are written; `scenes_a_frame` of them drawn in each frame
/// (else as many as [`drawing::scenes_a_frame`] finds for their size). Returns the notes.
pub fn render_scenes(
    first_scene: PathBuf,
    library: AssetLibrary,
    pictures: Vec<ScenePicture>,
    scenes_a_frame: Option<usize>,
    picture: ShotDoc,
    beside: Beside,
    on_written: OnWritten,
) -> Result<Vec<String>, String> {
    let frames = pictures
        .into_iter()
        .map(|p| Frame { at: FrameAt::Scene(Box::new(p.scene)), out: p.out, ids: p.ids, backdrop: p.backdrop })
        .collect();
    let edits = StartupEdits { still: true, ..default() };
    let setup = JobSetup {
        paths: vec![first_scene],
        library,
        edits,
        picture,
        frames,
        sequence: None,
        data: beside.data.then(CocoSoFar::default),
        controlnet: beside.controlnet,
        coco_per_picture: true,
        on_written: Some(on_written),
        scenes_a_frame,
    };
    run_job(setup)
}

/// A renderer kept between renders in one process (the Python package's): its app starts
/// once, on the default scene; each render opens its pictures' scenes in place of the last
/// and draws them, so a render after the first costs its drawn frames.
pub struct Renderer {
    app: App,
    outcome: Outcome,
    picture: ShotDoc,
    /// Messages said before this render (each render returns its own).
    said: usize,
}

impl Renderer {
    /// A renderer of pictures of `picture`'s size and samples, reading files through
    /// `library`; started (its GPU work set up) before it returns.
    pub fn new(library: AssetLibrary, picture: ShotDoc) -> Result<Self, String> {
        picture.validate().map_err(|e| e.to_string())?;
        let setup = JobSetup {
            paths: Vec::new(),
            library,
            edits: StartupEdits { still: true, ..default() },
            picture,
            frames: Vec::new(),
            sequence: None,
            data: None,
            controlnet: None,
            coco_per_picture: true,
            // Said by the caller, not on standard error.
            on_written: Some(Box::new(|_| Ok(()))),
            scenes_a_frame: None,
        };
        let (mut app, outcome) = job_app(setup, false);
        while app.plugins_state() == bevy::app::PluginsState::Adding {
            bevy::tasks::tick_global_task_pools_on_main_thread();
        }
        app.finish();
        app.cleanup();
        let mut renderer = Self { app, outcome, picture, said: 0 };
        renderer.run()?;
        // One picture of the bare stage, kept nowhere: what the first capture sets up (its
        // read-back's pipeline) is ready before the caller's first picture.
        let stage = ScenePicture { scene: SceneDoc::default(), out: PathBuf::new(), ids: (1, 1), backdrop: None };
        renderer.draw(vec![stage], Default::default(), Beside::default())?;
        Ok(renderer)
    }

    /// The size and samples it draws.
    pub fn picture(&self) -> ShotDoc {
        self.picture
    }

    /// Draws `pictures` (each its own scene, framed from `view` where it has no camera),
    /// each written to its file with what `beside` asks beside it; returns the notes said
    /// meanwhile.
    pub fn render(
        &mut self,
        pictures: Vec<ScenePicture>,
        view: crate::formats::scene::CameraDoc,
        beside: Beside,
    ) -> Result<Vec<String>, String> {
        let world = self.app.world_mut();
        world.insert_resource(crate::editor::present::view::FramingView(view));
        let mut job = world.resource_mut::<RenderJob>();
        job.frames = pictures
            .into_iter()
            .map(|p| Frame { at: FrameAt::Scene(Box::new(p.scene)), out: p.out, ids: p.ids, backdrop: p.backdrop })
            .collect();
        job.queue = (0..job.frames.len()).collect();
        (job.next, job.set_up, job.done, job.captures, job.failed_save) = (0, false, None, None, None);
        job.started = std::time::Instant::now();
        job.data = beside.data.then(CocoSoFar::default);
        job.controlnet = beside.controlnet;
        // The first picture's scene opens in the first update, which may capture it.
        world.run_system_cached(scene_frame).map_err(|e| e.to_string())?;
        self.run()
    }

    /// Draws `pictures` as [`Self::render`] does, each kept in memory as its files would
    /// hold it (none is written); returns the notes said meanwhile and the pictures in
    /// their order.
    pub fn draw(
        &mut self,
        pictures: Vec<ScenePicture>,
        view: crate::formats::scene::CameraDoc,
        beside: Beside,
    ) -> Result<(Vec<String>, Vec<Kept>), String> {
        let kept = Arc::new(Mutex::new(Vec::new()));
        self.app.world_mut().resource_mut::<RenderJob>().kept = Some(kept.clone());
        let said = self.render(pictures, view, beside);
        self.app.world_mut().resource_mut::<RenderJob>().kept = None;
        let mut kept = std::mem::take(&mut *kept.lock().map_err(|_| "a picture's thread failed".to_string())?);
        kept.sort_by_key(|&(k, _)| k);
        said.map(|said| (said, kept.into_iter().map(|(_, k)| k).collect()))
    }

    /// Updates the app until its job is done: the notes said meanwhile, or what failed.
    fn run(&mut self) -> Result<Vec<String>, String> {
        loop {
            self.app.update();
            let done = self.outcome.lock().map(|mut o| (o.0.take(), std::mem::take(&mut o.1))).ok();
            if let Some((Some(done), messages)) = done {
                let said = messages.get(self.said..).unwrap_or_default().to_vec();
                self.said = messages.len();
                return done.map(|()| said);
            }
        }
    }
}

/// What a render's app is made from.
struct JobSetup {
    paths: Vec<PathBuf>,
    library: AssetLibrary,
    edits: StartupEdits,
    picture: ShotDoc,
    frames: Vec<Frame>,
    sequence: Option<FrameSequence>,
    /// With data: the COCO file all pictures share, as it fills.
    data: Option<CocoSoFar>,
    controlnet: Option<ControlNet>,
    /// Each picture's data has a COCO file of its own instead.
    coco_per_picture: bool,
    on_written: Option<OnWritten>,
    /// The scenes a frame draws, where asked (else chosen from the size).
    scenes_a_frame: Option<usize>,
}

/// Where a render's result and messages are left for the caller.
type Outcome = Arc<Mutex<(Option<Result<(), String>>, Vec<String>)>>;

/// Builds the render's app, runs it until every picture is written or it fails, and
/// returns the notes or what went wrong.
fn run_job(setup: JobSetup) -> Result<Vec<String>, String> {
    let (mut app, outcome) = job_app(setup, true);
    let exit = app.run();
    // `App::run` hands the world to the runner: the outcome comes back through `outcome`.
    let (done, messages) = outcome.lock().map(|o| o.clone()).unwrap_or_default();
    match (exit, done) {
        (AppExit::Success, Some(Ok(()))) => Ok(messages),
        (_, Some(Err(e))) => Err(e),
        _ => Err("the render stopped before a picture was captured".to_string()),
    }
}

/// The app of a render and where its outcome is left; `opened`: the first picture shows the
/// scene the app opens with (else every picture's scene is opened in place of the last).
fn job_app(setup: JobSetup, opened: bool) -> (App, Outcome) {
    let JobSetup {
        paths,
        library,
        edits,
        picture,
        frames,
        sequence,
        data,
        controlnet,
        coco_per_picture,
        on_written,
        scenes_a_frame: asked,
    } = setup;
    let (width, height) = (picture.width, picture.height);
    // A render in a process that logs already (the editor's frames) logs through its log;
    // a renderer kept in another program's process (Python's) does not log.
    let plugins = match bevy::log::tracing::dispatcher::has_been_set() || !opened {
        true => crate::editor::cores::windowless_plugins().disable::<bevy::log::LogPlugin>(),
        false => crate::editor::cores::windowless_plugins(),
    };
    let mut app = App::new();
    app.add_plugins(plugins);
    if opened {
        app.add_plugins(ScheduleRunnerPlugin::run_loop(Duration::from_millis(2)));
    }
    app.insert_resource(stage::BackgroundAfterCapture)
        .insert_resource(crate::editor::state::camera::FramingAspect(width as f32 / height as f32))
        .insert_resource(StartupPaths(paths))
        .insert_resource(Library(library))
        .insert_resource(edits)
        .add_plugins((RigCorePlugin, SkinningPlugin, ViewPlugin));
    let slots = SlotsAsked {
        size: (width * picture.samples, height * picture.samples),
        count: asked.map(|n| n.clamp(1, drawing::MAX_SCENES_A_FRAME)),
        antialias: picture.antialias,
    };
    let outcome = Arc::new(Mutex::new((None, Vec::new())));
    app.insert_resource(RenderJob {
        queue: drawing::drawing_order(&frames.iter().map(Frame::scene).collect::<Vec<_>>()),
        frames,
        set_up: false,
        samples: picture.samples,
        next: 0,
        slots: Vec::new(),
        drawing: 0,
        sequence,
        first_yaw: None,
        started: std::time::Instant::now(),
        in_flight: 0,
        written: Default::default(),
        failed_save: None,
        captures: None,
        done: None,
        outcome: outcome.clone(),
        data,
        controlnet,
        size: (width, height),
        coco_per_picture,
        on_written,
        opened,
        kept: None,
        sources_drawn: Default::default(),
    });
    // The sun's shadow map sized for the picture (the editor's is for a window).
    let shadow_map = stage::shadow_map_for(width * picture.samples, height * picture.samples);
    app.add_systems(PostStartup, move |mut commands: Commands| commands.insert_resource(shadow_map.clone()));
    app.insert_resource(slots).add_systems(Startup, (open_slots, cluster_lamps_by_layer));
    app.add_systems(
        Last,
        (capture_when_ready, report_when_done, next_frame, scene_frame, pose_frame)
            .chain()
            .after(crate::editor::present::readiness::UpdateCaptureGate),
    )
    .add_systems(First, draw_only_what_is_captured);
    (app, outcome)
}

/// The slots a render asks for: their pictures' size as drawn, how many (where asked) and
/// how their edges are smoothed.
#[derive(Resource)]
struct SlotsAsked {
    size: (u32, u32),
    count: Option<usize>,
    antialias: Antialias,
}

/// Opens the render's slots, as many as asked or as [`drawing::scenes_a_frame`] finds for the
/// renderer: each a target and a camera drawing into it, and (after the first, the
/// editor's) a stage of its own (reads `SlotsAsked`, `RenderAdapterInfo`; writes entities,
/// images, `RenderJob`).
fn open_slots(
    mut commands: Commands,
    asked: Res<SlotsAsked>,
    adapter: Option<Res<bevy::render::renderer::RenderAdapterInfo>>,
    mut job: ResMut<RenderJob>,
    mut assets: (
        ResMut<Assets<Image>>,
        ResMut<Assets<Mesh>>,
        ResMut<Assets<StandardMaterial>>,
        ResMut<Assets<GizmoAsset>>,
    ),
) {
    let (images, meshes, materials, gizmos) = (&mut assets.0, &mut assets.1, &mut assets.2, &mut assets.3);
    let on_cpu = adapter.is_some_and(|a| a.device_type == wgpu_types::DeviceType::Cpu);
    let (w, h) = asked.size;
    for k in 0..asked.count.unwrap_or_else(|| drawing::scenes_a_frame(w, h, on_cpu)) {
        let mut image = Image::new_target_texture(w, h, TextureFormat::Rgba8UnormSrgb, None);
        image.texture_descriptor.usage |= TextureUsages::COPY_SRC;
        let target = images.add(image);
        let orbit = OrbitCamera::default();
        let lens = (Camera3d::default(), RenderTarget::Image(target.clone().into()), orbit, orbit.transform());
        smoothed(&mut commands.spawn((lens, stage::slot_camera(Slot(k)), SceneToOpen::default())), asked.antialias);
        if k > 0 {
            stage::spawn_slot_stage(&mut commands, meshes, materials, gizmos, Slot(k));
        }
        job.slots.push(SlotView { target, last_lights: None });
    }
}

/// Assigns lamps to the parts of a view they light on the CPU, which leaves out the lamps of
/// other slots (Bevy's clustering on the GPU lights every view by every lamp), in every
/// render, so that a picture is the same however many scenes share its frame (writes
/// `GlobalClusterSettings`).
fn cluster_lamps_by_layer(settings: Option<ResMut<bevy::light::cluster::GlobalClusterSettings>>) {
    if let Some(mut settings) = settings {
        settings.gpu_clustering = None;
    }
}

/// Gives the render's camera the smoothing `antialias` asks for.
fn smoothed(camera: &mut EntityCommands, antialias: Antialias) {
    match antialias {
        Antialias::Multisample => camera.insert(Msaa::Sample4),
        Antialias::Fxaa => camera.insert((Msaa::Off, bevy::anti_alias::fxaa::Fxaa::default())),
        Antialias::Off => camera.insert(Msaa::Off),
    };
}

/// Loads everything the render will show before any window or GPU work, so that a missing
/// file, an unparsable scene, a character or a clip that fails to load is an error (and no
/// picture is written). Returns the loaded assets for the app to reuse.
fn preload(paths: &[PathBuf], edits: &StartupEdits) -> Result<(AssetLibrary, ShotDoc, Vec<String>), String> {
    let mut library = AssetLibrary::default();
    let mut shot = ShotDoc::default();
    let mut poses = Vec::new();
    // Each source and the clip file it plays, with what names it in a scene file (for the message).
    let mut sources: Vec<(SourceDoc, Option<BindingDoc>, Option<PathBuf>, String)> = match scene_path(paths) {
        Some(scene) => read_scene(scene)
            .map_err(|e| e.to_string())
            .inspect(|doc| (shot, poses) = (doc.shot, doc.poses.keys().cloned().collect()))?
            .characters
            .into_iter()
            .map(|c| {
                let clip = c.anim.filter(|a| a.keys.is_none() && a.retarget.is_none()).map(|a| a.file);
                (c.source, c.binding, clip, format!(" (character `{}` of {})", c.name, scene.display()))
            })
            .collect(),
        None => paths.iter().flat_map(|p| library.sources_of(p)).map(|s| (s, None, None, String::new())).collect(),
    };
    match edits.anim.as_ref().map(|a| (&a.retarget, &a.file)) {
        // `--retarget`: the file whose motion plays must load too.
        Some((Some(RetargetDoc { from: MotionSourceDoc::File { path, .. }, .. }), _)) => {
            sources.push((SourceDoc::File(path.clone()), None, None, " (--retarget)".into()));
        }
        Some((_, file)) => sources.iter_mut().for_each(|s| s.2 = Some(file.clone())),
        None => {}
    }
    let errors: Vec<String> = sources
        .iter()
        .filter_map(|(source, binding, clip, named_in)| {
            let loaded = library.load_bound(source, *binding).map(drop);
            let clip = clip.as_ref().map_or(Ok(()), |file| library.keyframe_clip(file).map(drop));
            loaded.and(clip).err().map(|e| format!("{e}{named_in}"))
        })
        .collect();
    if !errors.is_empty() {
        return Err(errors.join("\n"));
    }
    // The options as every command applies them: one that names what no character has fails
    // here, before the GPU starts.
    crate::editor::present::view::startup_scene(paths, edits, &mut library, &mut Vec::new())?;
    Ok((library, shot, poses))
}

/// Once the gate opens, captures the pictures set up, each slot's target once, and saves
/// them; gives up when a picture waits [`GIVE_UP_SECONDS`] or a pipeline failed, saying what
/// was pending. A capture of a frame the GPU did not draw whole is thrown away and its
/// picture drawn again after the others.
fn capture_when_ready(
    mut commands: Commands,
    mut job: ResMut<RenderJob>,
    gate: Res<CaptureGate>,
    wanted: Res<WantedAssets>,
    stages: Query<(&Slot, &stage::DrawnStage), With<OrbitCamera>>,
    scene: DataScene,
) {
    if job.done.is_some() {
        return;
    }
    if let Some(failed) = &gate.failed {
        job.done = Some(Err(format!("cannot render: {failed}")));
        return;
    }
    let waiting_since = job.captures.map_or(job.started, |(_, last, ..)| last);
    if waiting_since.elapsed().as_secs() > GIVE_UP_SECONDS {
        let pending = gate.last_reason.clone().unwrap_or_else(|| "nothing reported".into());
        job.done = Some(Err(format!("the render was not ready within {GIVE_UP_SECONDS} s; still pending: {pending}")));
        return;
    }
    collect_written(&mut job);
    if let Some(e) = job.failed_save.take() {
        job.done = Some(Err(e));
        return;
    }
    if job.next == job.queue.len() {
        if job.in_flight == 0 {
            job.done = Some(finish(&mut job));
        }
        return;
    }
    if let Some((_, _, updates, _)) = job.captures.as_mut() {
        *updates += 1;
    }
    if !job.set_up || !gate.is_ready() || job.in_flight >= MAX_IN_FLIGHT_A_SLOT * job.slots.len() {
        return;
    }
    let capture = Capture { generation: wanted.generation, speculative: gate.is_speculative() };
    for k in 0..job.drawing {
        let slot = Slot(k);
        let background = stages.iter().find(|s| *s.0 == slot).map(|s| s.1.0.background.clone()).unwrap_or_default();
        // What the data pictures show is taken now, with the frame the capture draws.
        let wants_data = job.data.is_some() || job.controlnet.is_some();
        match wants_data.then(|| scene.frame(slot, job.size.0, job.size.1)).transpose() {
            Ok(frame) => capture.picture(&mut commands, &job, k, frame, background),
            Err(e) => {
                job.done = Some(Err(e));
                return;
            }
        }
    }
    // These frames are the ones captured: the next pictures are set up from the next frame on.
    job.in_flight += job.drawing;
    let now = std::time::Instant::now();
    let first_frame = job.drawing;
    job.captures = Some(job.captures.map_or((now, now, 0, first_frame), |(first, _, u, n)| (first, now, u, n)));
    job.next += job.drawing;
    job.set_up = false;
}

/// What every capture of one frame shares: the main world's frame it draws, and whether it
/// was taken before the gate knew that frame drawn whole.
#[derive(Clone, Copy)]
struct Capture {
    generation: u64,
    speculative: bool,
}

impl Capture {
    /// Captures slot `k`'s target, the picture `k`-th from the job's next, with what the data
    /// pictures show (`frame`) and the background to put behind it; once captured it is
    /// encoded and written (or kept) on a thread of its own while the next pictures are
    /// drawn.
    fn picture(
        self,
        commands: &mut Commands,
        job: &RenderJob,
        k: usize,
        mut frame: Option<DataFrame>,
        background: BackgroundDoc,
    ) {
        let index = job.queue[job.next + k];
        let frame_now = &job.frames[index];
        let (out, ids, backdrop) = (frame_now.out.clone(), frame_now.ids, frame_now.backdrop.clone());
        let (samples, coco_per_picture, written) = (job.samples, job.coco_per_picture, job.written.clone());
        let beside = Beside { data: job.data.is_some(), controlnet: job.controlnet };
        let Capture { generation, speculative } = self;
        let on_captured = move |captured: On<ScreenshotCaptured>,
                                drawn: Res<DrawnFrames>,
                                mut job: ResMut<RenderJob>,
                                mut gate: ResMut<CaptureGate>| {
            if speculative && drawn.drawn_whole(generation) != Some(true) {
                // Drawn before all of it was on the GPU: again, once everything is.
                job.queue.push(index);
                job.in_flight -= 1;
                gate.restart();
                return;
            }
            let (image, out, frame, written) = (captured.image.clone(), out.clone(), frame.take(), written.clone());
            let (backdrop, background, kept) = (backdrop.clone(), background.clone(), job.kept.clone());
            std::thread::spawn(move || {
                let result =
                    composed(&image, samples, &background, backdrop.as_deref()).and_then(|picture| match kept {
                        Some(kept) => {
                            let name = out.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
                            let beside = frame.map(|f| f.keep_beside(&name, ids, &picture, beside));
                            kept.lock()
                                .map_err(|_| "a picture's thread failed")?
                                .push((index, Kept { picture, beside }));
                            Ok(None)
                        }
                        None => write_picture(&picture, &out, frame, ids, beside, coco_per_picture),
                    });
                if let Ok(mut written) = written.lock() {
                    written.push((index, result));
                }
            });
        };
        commands.spawn(Screenshot::image(job.slots[k].target.clone())).observe(on_captured);
    }
}

/// Draws frames while pictures are left to capture; once all are captured, the updates that
/// wait for their pixels and files draw nothing. In `First`: a camera drawing again (a kept
/// renderer's next render) is active before the lights are assigned to its view, so its
/// first frame is lit by the lamps of its own scene (writes the render camera's `Camera`).
fn draw_only_what_is_captured(job: Res<RenderJob>, mut cameras: Query<(&mut Camera, &Slot), With<OrbitCamera>>) {
    for (mut camera, slot) in &mut cameras {
        // The first slot draws the scene the app opens with; the others what is set up in them.
        let active = job.next < job.queue.len() && (slot.0 == 0 || slot.0 < job.drawing);
        if camera.is_active != active {
            camera.is_active = active;
        }
    }
}

/// Once the render is done (in the update that finished it): its result and the messages
/// left for the caller, and the app told to exit.
fn report_when_done(job: Res<RenderJob>, messages: Res<Messages>, mut exit: MessageWriter<AppExit>) {
    let Some(done) = job.done.clone() else { return };
    if let Ok(mut o) = job.outcome.lock() {
        *o = (Some(done), messages.0.clone());
    }
    exit.write(AppExit::Success);
}

/// Pictures captured and not yet written at most, a slot (their pixels held in memory).
const MAX_IN_FLIGHT_A_SLOT: usize = 4;

/// Once every picture is written: the COCO file of `--data`, and the pictures' rate.
fn finish(job: &mut RenderJob) -> Result<(), String> {
    if let Some((first, last, updates, first_frame)) = job.captures {
        let after_first = job.frames.len().saturating_sub(first_frame);
        let seconds = (last - first).as_secs_f64();
        if after_first > 0 && updates > 0 {
            eprintln!(
                "render: {:.2} pictures a second after the first frame's, a drawn frame {:.0} ms, {:.2} frames a picture",
                after_first as f64 / seconds,
                seconds / updates as f64 * 1e3,
                updates as f64 / after_first as f64
            );
        }
    }
    match job.data.take().filter(|_| !job.coco_per_picture) {
        Some(mut c) => {
            // Written in any order by the threads: in picture order, annotations numbered.
            c.images.sort_by_key(|i| i["id"].as_u64());
            c.annotations.sort_by_key(|a| a["image_id"].as_u64());
            for (k, annotation) in c.annotations.iter_mut().enumerate() {
                annotation["id"] = serde_json::json!(k + 1);
            }
            annotate::write::json(&c.path, &annotate::coco::file(c.images, c.annotations)).map_err(|e| e.to_string())
        }
        None => Ok(()),
    }
}

/// Takes in what the writing threads finished: a picture fewer in flight each, its COCO
/// part kept, the first failure kept; and says how far the pictures are.
fn collect_written(job: &mut RenderJob) {
    let finished = job.written.lock().map(|mut w| std::mem::take(&mut *w)).unwrap_or_default();
    for (index, result) in finished {
        job.in_flight -= 1;
        match result {
            Ok(Some((image, annotations))) => {
                if let Some(coco) = job.data.as_mut() {
                    coco.images.push(image);
                    coco.annotations.extend(annotations);
                }
            }
            Ok(None) => {}
            Err(e) => {
                job.failed_save.get_or_insert(e);
                continue;
            }
        }
        match job.on_written.as_mut() {
            Some(on_written) => {
                if let Err(e) = on_written(index) {
                    job.failed_save.get_or_insert(e);
                }
            }
            None => eprintln!("progress: {}/{}", index + 1, job.frames.len()),
        }
    }
}

/// The captured pixels averaged down from their samples, over the background (and over
/// `backdrop`, a picture filling the frame).
fn composed(
    image: &Image,
    samples: u32,
    background: &BackgroundDoc,
    backdrop: Option<&std::path::Path>,
) -> Result<image::DynamicImage, String> {
    let rendered = image.clone().try_into_dynamic().map_err(|e| format!("unreadable capture: {e}"))?.to_rgba8();
    let mut picture =
        picture::over_background(picture::downsampled(&rendered, samples), background).map_err(|e| e.to_string())?;
    if let Some(path) = backdrop {
        let behind = image::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
        picture = picture::over_picture(picture, &behind);
    }
    Ok(picture)
}

/// Writes `picture` as PNG at `out` and what `beside` asks beside it from `frame`; returns
/// its share of the render's COCO file (none when each picture has a file of its own).
fn write_picture(
    picture: &image::DynamicImage,
    out: &std::path::Path,
    frame: Option<DataFrame>,
    ids: (u64, u64),
    beside: Beside,
    coco_per_picture: bool,
) -> Result<Option<CocoPart>, String> {
    let mut bytes = Vec::new();
    picture.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).map_err(|e| e.to_string())?;
    crate::formats::write_atomically(out, |w| std::io::Write::write_all(w, &bytes))
        .map_err(|e| format!("{}: {e}", out.display()))?;
    let Some(frame) = frame else { return Ok(None) };
    let Some((image, annotations)) = frame.write_beside(out, ids, beside)? else { return Ok(None) };
    if !coco_per_picture {
        return Ok(Some((image, annotations)));
    }
    let coco = annotate::coco::file(vec![image], annotations);
    annotate::write::json(&annotate::write::beside(out, "json"), &coco).map(|()| None).map_err(|e| e.to_string())
}

/// Sets up the next picture of a sequence once the last was captured: every clip paused at
/// its time, a turntable's camera turned to it, and the gate told that only the new pose
/// must be drawn (writes `ClipPlayer`, `SmplCharacter`, `NodeClipPlayer`, `OrbitCamera`,
/// `CaptureGate`).
fn next_frame(
    mut job: ResMut<RenderJob>,
    mut gate: ResMut<CaptureGate>,
    mut keyframes: Query<&mut crate::scene::keyframes::ClipPlayer>,
    mut smpl: Query<&mut crate::scene::smpl::SmplCharacter>,
    mut node_clips: Query<&mut crate::scene::node_clips::NodeClipPlayer>,
    mut cameras: Query<&mut OrbitCamera>,
) {
    if job.set_up || job.next == 0 || job.next == job.queue.len() {
        return;
    }
    let first_yaw = *job.first_yaw.get_or_insert_with(|| cameras.iter().next().map_or(0.0, |c| c.0.yaw));
    let FrameAt::Time(t) = job.frames[job.queue[job.next]].at else { return };
    keyframes.iter_mut().for_each(|mut p| p.state.pause_at(t));
    smpl.iter_mut().filter(|b| b.state.clip.is_some()).for_each(|mut b| b.state.pause_at(t));
    node_clips.iter_mut().filter(|p| p.state.clip.is_some()).for_each(|mut p| p.state.pause_at(t));
    if let Some(sequence) = job.sequence.filter(|s| s.turntable.is_some()) {
        cameras.iter_mut().for_each(|mut c| c.0.yaw = first_yaw + sequence.turn_at(t));
    }
    gate.next_picture();
}

/// Sets up a data set's next pictures, one a slot: each scene opened in place of the
/// slot's last (the first picture's is the one the app opened with); where each is lit alike
/// to its slot's last and drawn as plain skins they are captured in the frame that first
/// draws them, else once the gate counts afresh (writes `PendingScene`, `SceneToOpen`,
/// `CaptureGate`).
fn scene_frame(
    mut job: ResMut<RenderJob>,
    mut gate: ResMut<CaptureGate>,
    mut pending: ResMut<crate::editor::scene_doc::document::PendingScene>,
    mut to_open: Query<(&Slot, &mut SceneToOpen)>,
) {
    if job.set_up || job.done.is_some() || job.next == job.queue.len() {
        return;
    }
    if !matches!(job.frames[job.queue[job.next]].at, FrameAt::Scene(_)) {
        return;
    }
    let count = drawing::drawn_together(job.queue[job.next..].iter().map(|&k| job.frames[k].scene()), job.slots.len());
    let (mut opened, mut lit_alike) = (false, true);
    for k in 0..count {
        let FrameAt::Scene(doc) = &job.frames[job.queue[job.next + k]].at else { continue };
        let lights = LightSetup::of(&doc.stage);
        let sources: Vec<SourceDoc> = doc.characters.iter().map(|c| c.source.clone()).collect();
        if job.next > 0 || k > 0 || !job.opened {
            // Lit by lamps the slot's last scene had (of this render, or of the renderer's
            // last), its characters drawn as plain skins, from files drawn before (a file's
            // first materials take frames of their own).
            let last = job.slots[k].last_lights.as_ref();
            let known = sources.iter().all(|s| job.sources_drawn.contains(s));
            lit_alike &=
                last.is_some_and(|last| drawing::lamps_kept(last, &lights)) && drawing::plainly_drawn(doc) && known;
            opened = true;
            let doc = doc.clone();
            match k {
                // A scene without a camera is framed as the command line frames it.
                0 => *pending = crate::editor::scene_doc::document::PendingScene { frame: true, doc: Some(*doc) },
                _ => to_open.iter_mut().filter(|o| o.0.0 == k).for_each(|mut o| o.1.0 = Some(doc.clone())),
            }
        }
        job.slots[k].last_lights = Some(lights);
        job.sources_drawn.extend(sources);
    }
    if opened {
        if lit_alike { gate.next_picture() } else { gate.restart() }
    }
    job.drawing = count;
    job.set_up = true;
}

/// Sets up the frame to render: a pose frame puts the pose on every character that has its
/// joints (as ordinary pose edits, applied next `Animate`), and the gate counts afresh;
/// other frames are set up already (writes `EditQueue`, `CaptureGate`).
fn pose_frame(
    mut job: ResMut<RenderJob>,
    mut gate: ResMut<CaptureGate>,
    library: Res<crate::editor::state::PoseLibrary>,
    characters: Query<(
        &crate::editor::scene_doc::document::SceneCharacter,
        &crate::scene::Character,
        Option<&crate::editor::scene_doc::document::HumanoidMapOf>,
        &crate::scene::Placement,
    )>,
    poses: Query<&crate::scene::JointPose>,
    mut edits: ResMut<crate::editor::edits::edit::EditQueue>,
    mut assets: ResMut<crate::editor::scene_doc::document::Library>,
) {
    if job.set_up || job.done.is_some() || job.next == job.queue.len() {
        return;
    }
    (job.set_up, job.drawing) = (true, 1);
    let FrameAt::Pose(name) = &job.frames[job.queue[job.next]].at else { return };
    let kept = library.0.get(name);
    let joints: Vec<_> = kept.iter().flat_map(|pose| pose.joints.iter().map(|(k, r)| (k.clone(), *r))).collect();
    let rig = kept.and_then(|pose| pose.rig.as_ref()).and_then(|rig| assets.rig(rig).ok());
    let from = rig.as_ref().map(|(a, m)| (&a.skeleton, &**m));
    // A pose of the scene's library, else the built-in body pose of that name.
    let body = crate::document::posing::BodyPoseSpec::new(name.clone(), false);
    for (sc, character, map, placement) in &characters {
        let map = map.map(|m| m.0.clone()).unwrap_or_default();
        let current: Vec<_> =
            character.joints.iter().map(|&e| poses.get(e).map_or(Default::default(), |p| p.0)).collect();
        let target = (&character.asset.skeleton, &map, &current[..]);
        use crate::editor::edits::pose_library::{apply_named_pose, body_pose_edits};
        match kept {
            Some(_) => edits.0.extend(apply_named_pose(sc.id, target, &joints, from, false)),
            None => {
                let target = (&*character.asset, &map, &current[..]);
                edits.0.extend(body_pose_edits(sc.id, target, placement.0, &body, 1.0).into_iter().flatten())
            }
        }
    }
    gate.restart();
}

/// The cells (all of one size) in a grid as near square as they fill, row by row, into
/// `out`.
fn contact_sheet(cells: &[PathBuf], out: &std::path::Path) -> Result<(), String> {
    let images = cells
        .iter()
        .map(|c| image::open(c).map_err(|e| format!("{}: {e}", c.display())))
        .collect::<Result<Vec<_>, _>>()?;
    let (w, h) = images.first().map_or((1, 1), |i| (i.width(), i.height()));
    let columns = (images.len() as f64).sqrt().ceil().max(1.0) as u32;
    let rows = (images.len() as u32).div_ceil(columns);
    let mut sheet = image::RgbaImage::new(w * columns, h * rows);
    for (k, cell) in images.iter().enumerate() {
        let (x, y) = ((k as u32 % columns) * w, (k as u32 / columns) * h);
        image::imageops::overlay(&mut sheet, &cell.to_rgba8(), i64::from(x), i64::from(y));
    }
    let mut bytes = Vec::new();
    image::DynamicImage::ImageRgba8(sheet)
        .write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png)
        .map_err(|e| e.to_string())?;
    crate::formats::write_atomically(out, |w| std::io::Write::write_all(w, &bytes))
        .map_err(|e| format!("{}: {e}", out.display()))
}

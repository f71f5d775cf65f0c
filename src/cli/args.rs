//! The command line's words: commands, their flags and what they parse into (clap). No
//! Bevy; `main.rs` parses these and dispatches.

use std::path::PathBuf;

use crate::document::posing::{HandSpec, IkSpec, LookAtSpec, PoseSpec, TwoBoneSpec};

/// The largest picture side `render` accepts (the texture limit of common GPUs).
pub const MAX_PICTURE_SIDE: i64 = 8192;

#[derive(clap::Parser)]
#[command(name = "marionette", version, about = "Build scenes of skinned characters: load, pose, see and export them.")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(clap::Subcommand)]
pub enum Command {
    /// Open the editor on characters (`Model1.skel` finds `Model1.obj` and `Model1.attach`).
    Edit(EditArgs),
    /// Print what a character file loads as: joints, vertices, triangles, weight checks.
    Info { path: PathBuf },
    /// Write the posed, skinned mesh as OBJ: one `v` per source vertex in source order,
    /// then the source faces.
    Export(ExportArgs),
    /// Bind a mesh without weights to a skeleton and write 6.837-style weights: by bone heat
    /// (weights diffused over the mesh from the bones each vertex sees), to the nearest
    /// bone, or smoothly to the nearest few.
    Bind(BindArgs),
    /// Render a scene (.ron) or characters offscreen to a PNG, without a window.
    Render(RenderArgs),
    /// The SMPL exercise: writes frame000.obj, frame001.obj, ... into --out.
    ///
    /// Tasks: 1 the shapes β0, β1, β2 (unskinned); 2 L_Elbow moved +0.2 in y, absolute
    /// (descendants stay); 3 the same, relative (descendants follow); 4 L_Shoulder rotated
    /// by (0, 0, -0.3827, 0.9239); 5 clip 7516 for β0, β1, β2 (480 frames).
    ///
    /// --sequence SPEC plays segments one after another: SPEC is CLIP[:FROM-TO][:BETA]
    /// joined by commas. CLIP is a clip file or the end of its name (7516); FROM-TO an
    /// inclusive frame range (40- runs to the end); BETA is 0, 1, 2 (the exercise's βs) or
    /// ten numbers joined by /. Consecutive segments overlap by --transition frames with
    /// α from 0 (first transition frame) to 1 (N-th); β blends linearly, rotations by
    /// normalised linear interpolation (or --slerp).
    /// Example: --sequence 7516:0-99:1,8806:20-:2 --transition 30
    #[command(verbatim_doc_comment)]
    Smpl(SmplArgs),
    /// A crowd of animated characters headless through the app and the render world:
    /// frame time (p50/p95) by phase, mesh data handed on, and the skinning kernel's speed.
    Bench(BenchArgs),
    /// Render a data set: pictures (and their data) of scenes drawn from a spec, each
    /// picture's depending only on the spec's seed and its number; sharded over machines,
    /// resumable. `generate --example` prints a spec to start from.
    Generate(GenerateArgs),
    /// Rebuild the project's own characters into a folder (normally `assets`).
    GenAssets {
        #[arg(default_value = "assets")]
        dir: PathBuf,
    },
}

/// `--skinning`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Skinning {
    /// Linear blend skinning.
    Lbs,
    /// Dual quaternion skinning.
    Dq,
}

impl From<Skinning> for crate::rig::dqs::SkinningMethod {
    fn from(s: Skinning) -> Self {
        match s {
            Skinning::Lbs => Self::Linear,
            Skinning::Dq => Self::DualQuaternion,
        }
    }
}

/// How `bind` computes weights.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum BindMethod {
    /// Bone heat (Baran and Popović 2007).
    Heat,
    /// Each vertex rigidly to its nearest bone.
    Nearest,
    /// The nearest few bones, falling off with distance.
    Smooth,
}

impl From<BindMethod> for crate::rig::bind::Binding {
    fn from(m: BindMethod) -> Self {
        match m {
            BindMethod::Heat => Self::Heat,
            BindMethod::Nearest => Self::Nearest,
            BindMethod::Smooth => Self::Smooth,
        }
    }
}

/// The picture: its size and samples (default: the scene's shot, else 1280×720, 1 sample),
/// background, view and lens.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct ShotArgs {
    /// Width in pixels.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_PICTURE_SIDE))]
    pub width: Option<u32>,
    /// Height in pixels.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_PICTURE_SIDE))]
    pub height: Option<u32>,
    /// Width and height at once, `WxH` (`512x768`; ControlNet's sizes are multiples of 64),
    /// in place of --width and --height.
    #[arg(long, value_name = "WxH", value_parser = parse_size, conflicts_with_all = ["width", "height"])]
    pub size: Option<(u32, u32)>,
    /// Supersampling: each pixel the mean of N×N rendered ones (1 to 4), on top of
    /// --antialias.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4))]
    pub samples: Option<u32>,
    /// How edges are smoothed: multisample (four samples a pixel, the default), fxaa (found
    /// and blended in the finished picture: much cheaper on a CPU renderer) or off.
    #[arg(long)]
    pub antialias: Option<crate::formats::scene::Antialias>,
    /// No background and no floor: a PNG with alpha.
    #[arg(long)]
    pub transparent: bool,
    /// Frame the characters from this side: front, back, right (or side), left, top,
    /// bottom, three-quarter.
    #[arg(long, value_parser = parse_view)]
    pub view: Option<crate::formats::scene::ViewName>,
    /// An orthographic lens, framed to the characters.
    #[arg(long)]
    pub ortho: bool,
    /// Write the picture's data beside it: depth (EXR and PNG), normals, instance and
    /// body-part masks, the OpenPose drawing and JSON, and a COCO keypoints file with the
    /// camera (one for a whole frame sequence).
    #[arg(long)]
    pub data: bool,
    /// Write the maps ControlNet reads beside the picture: `shot.cn-openpose.png` (drawn as
    /// the OpenPose annotator draws) and `.json` (18 points, the canvas size),
    /// `shot.cn-depth.png` (relative inverse depth, near white) and `shot.cn-normal.png`
    /// (Normal 1.1: red left, green up, blue toward the viewer).
    #[arg(long)]
    pub controlnet: bool,
    /// With --controlnet, also `shot.cn-canny.png`: the picture's edges as ControlNet's canny
    /// preprocessor (`cv2.Canny`) finds them, at thresholds LOW,HIGH (default 100,200).
    #[arg(long, value_name = "LOW,HIGH", num_args = 0..=1, default_missing_value = "100,200", requires = "controlnet")]
    pub canny: Option<crate::document::annotate::canny::Canny>,
}

/// `WxH`: two whole numbers of pixels, each 1 to [`MAX_PICTURE_SIDE`].
fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let expected = || format!("expected WxH (512x768), each 1 to {MAX_PICTURE_SIDE}, found {s:?}");
    let (w, h) = s.split_once(['x', 'X', '×']).ok_or_else(expected)?;
    let side = |t: &str| t.trim().parse::<u32>().ok().filter(|&v| v >= 1 && i64::from(v) <= MAX_PICTURE_SIDE);
    Ok((side(w).ok_or_else(expected)?, side(h).ok_or_else(expected)?))
}

fn parse_view(s: &str) -> Result<crate::formats::scene::ViewName, String> {
    s.parse()
}

impl ShotArgs {
    /// The size, samples and smoothing asked for (each none: the scene's).
    pub fn picture(&self) -> crate::document::frames::PictureRequest {
        let (width, height) = self.size.map_or((self.width, self.height), |(w, h)| (Some(w), Some(h)));
        crate::document::frames::PictureRequest { width, height, samples: self.samples, antialias: self.antialias }
    }
}

/// `--from A --to B --fps N`, `--turntable S`: a sequence of pictures.
#[derive(clap::Args, Debug, Clone)]
pub struct FrameArgs {
    /// With `--to`: render the frames from this time (seconds) to `--to`, one picture per
    /// frame of every clip of the scene, into the files `--out` numbers
    /// (`dir/frame_%04d.png`).
    #[arg(long, requires = "to", conflicts_with = "time", value_parser = finite_seconds)]
    pub from: Option<f32>,
    /// The last frame's time (seconds), with `--from`.
    #[arg(long, requires = "from", value_parser = finite_seconds)]
    pub to: Option<f32>,
    /// Frames per second of `--from`/`--to` and `--turntable` (default 24), and of
    /// `--fit-sequence`'s files (default 30).
    #[arg(long, value_parser = positive_fps)]
    pub fps: Option<f32>,
    /// The camera goes once round the scene in this many seconds: the frames of one turn
    /// (from `--from`, or 0), or the turn over `--from`/`--to`.
    #[arg(long, value_name = "SECONDS", value_parser = finite_seconds)]
    pub turntable: Option<f32>,
    /// A contact sheet into `--out`: every pose of the scene's library on its characters
    /// (the built-in body poses where it keeps none), one cell each (of
    /// `--width`×`--height`), in a grid.
    #[arg(long = "poses", id = "pose_sheet", conflicts_with_all = ["from", "turntable", "time"])]
    pub pose_sheet: bool,
}

impl FrameArgs {
    /// The pictures asked for: a sequence, a contact sheet of poses, or one.
    pub fn pictures(&self) -> crate::document::frames::Pictures {
        use crate::document::frames::Pictures;
        match self.sequence() {
            Some(sequence) => Pictures::Sequence(sequence),
            None if self.pose_sheet => Pictures::PoseSheet,
            None => Pictures::Still,
        }
    }

    /// The frames to render, if a sequence was asked for.
    pub fn sequence(&self) -> Option<crate::document::frames::FrameSequence> {
        let from = self.from.unwrap_or(0.0);
        // One turn without --to: every frame before the turn comes round to the first.
        let fps = self.fps.unwrap_or(24.0);
        let to = self.to.or_else(|| self.turntable.map(|s| from + s - 1.0 / fps))?;
        Some(crate::document::frames::FrameSequence { from, to, fps, turntable: self.turntable })
    }
}

/// `--anim FILE --time T`: pose characters from a keyframed clip.
#[derive(Debug, Clone, clap::Args)]
pub struct ClipArgs {
    /// A CSE169 `.anim` clip (channels 0-2 move the root, then x, y, z rotation per joint
    /// in the skeleton's order) or a `.bvh` (its joints by name), on every character whose
    /// skeleton it fits.
    #[arg(long, value_name = "FILE.anim|FILE.bvh")]
    pub anim: Option<PathBuf>,
    /// The time in seconds at which clips are sampled: `--anim`'s, `--clip`'s, and a
    /// scene's own keyframes, SMPL and glTF clips (extrapolated outside their keys as each
    /// clip says).
    #[arg(long, value_parser = finite_seconds)]
    pub time: Option<f32>,
    /// A glTF file's animation, by name or by index among the file's animations, on every
    /// character of the file it moves (without it the file's node transforms are the pose).
    #[arg(long, value_name = "NAME|INDEX")]
    pub clip: Option<String>,
    /// The motion of another humanoid, carried onto the characters through their humanoid
    /// maps: a glTF file (`--clip` picks its animation), an SMPL folder (`--clip 7516`), a
    /// `.bvh`, or a character file with `--anim FILE`.
    #[arg(long, value_name = "FILE")]
    pub retarget: Option<PathBuf>,
}

impl ClipArgs {
    /// `--clip` for the characters themselves (with `--retarget` it picks the source's).
    pub fn own_clip(&self) -> Option<String> {
        self.clip.clone().filter(|_| self.retarget.is_none())
    }

    pub fn anim_doc(&self, playing: bool) -> Option<crate::formats::scene::AnimDoc> {
        use crate::formats::scene::{AnimDoc, MotionSourceDoc, RetargetDoc};
        if let Some(path) = &self.retarget {
            let clip = self.anim.as_ref().map(|a| a.display().to_string()).or_else(|| self.clip.clone());
            let from = MotionSourceDoc::File { path: path.clone(), clip };
            let time = self.time.unwrap_or(0.0);
            return Some(AnimDoc { retarget: Some(RetargetDoc::of(from)), time, playing, ..AnimDoc::default() });
        }
        let file = self.anim.clone()?;
        Some(crate::formats::scene::AnimDoc {
            time: self.time.unwrap_or(0.0),
            playing,
            ..crate::formats::scene::AnimDoc::of(file)
        })
    }
}

/// `export`'s flags.
#[derive(clap::Args)]
pub struct ExportArgs {
    pub path: PathBuf,
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub pose: PoseArgs,
    /// Linear blend (`lbs`) or dual quaternion (`dq`) skinning for every character (without
    /// it, a scene's characters keep theirs; others are `lbs`).
    #[arg(long, value_enum)]
    pub skinning: Option<Skinning>,
    #[command(flatten)]
    pub clip: ClipArgs,
    /// With `--out X.glb`: the posed mesh without a skin, instead of a skinned mesh
    /// with its skeleton.
    #[arg(long)]
    pub bake: bool,
    /// With `--out X.glb`: every clip goes out as a glTF animation (keyframed clips, a
    /// scene's or `--anim`'s, as cubic splines keyed at their keys).
    #[arg(long)]
    pub animation: bool,
    /// Frames a second of `--fit-sequence`'s files (default 30).
    #[arg(long, requires = "fit_sequence", value_parser = positive_fps)]
    pub fps: Option<f32>,
}

/// `bind`'s flags.
#[derive(clap::Args)]
pub struct BindArgs {
    /// The mesh (.obj or .off).
    pub mesh: PathBuf,
    /// The skeleton (.skel of either course, or a Homer rig .json).
    pub skeleton: PathBuf,
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long, value_enum, default_value_t = BindMethod::Heat)]
    pub method: BindMethod,
    /// The same as `--method smooth` (kept for older scripts).
    #[arg(long, conflicts_with = "method")]
    pub smooth: bool,
    /// Weights to compare with (a 6.837 `.attach` for the same mesh and skeleton):
    /// prints how often the heaviest joint agrees and the mean L1 distance of the rows.
    #[arg(long, value_name = "F.attach")]
    pub against: Option<PathBuf>,
}

/// `smpl`'s flags.
#[derive(clap::Args)]
pub struct SmplArgs {
    /// The folder with smpl_00.obj ... smpl_skin.txt and the clips.
    #[arg(long)]
    pub data: PathBuf,
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=5), conflicts_with = "sequence", required_unless_present = "sequence")]
    pub task: Option<u32>,
    #[arg(long, value_name = "SPEC")]
    pub sequence: Option<String>,
    #[arg(long, default_value_t = 20)]
    pub transition: usize,
    #[arg(long)]
    pub slerp: bool,
    #[arg(long)]
    pub out: PathBuf,
    /// Use the straightforward single-threaded writer (for timing against it).
    #[arg(long)]
    pub naive: bool,
}

/// A finite number of seconds.
pub fn finite_seconds(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(t) if t.is_finite() => Ok(t),
        _ => Err(format!("expected a finite number of seconds, found `{text}`")),
    }
}

/// `generate`.
#[derive(clap::Args, Debug, Clone)]
pub struct GenerateArgs {
    /// The spec (RON): what varies from picture to picture and how.
    #[arg(required_unless_present_any = ["example", "merge"])]
    pub spec: Option<PathBuf>,
    /// The data set's folder: `000000.png` (and its data and scene) for picture 0, ...
    #[arg(long, required_unless_present_any = ["example", "merge"])]
    pub out: Option<PathBuf>,
    /// Render the pictures k with k mod N = I (I from 0). Without it: a Slurm job array's
    /// task (SLURM_ARRAY_TASK_ID of SLURM_ARRAY_TASK_COUNT), a Kubernetes Indexed Job's
    /// (JOB_COMPLETION_INDEX of --shards), else all.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// How many shards a Kubernetes Indexed Job runs (its completions).
    #[arg(long, value_name = "N")]
    pub shards: Option<usize>,
    /// How many pictures, in place of the spec's count.
    #[arg(long)]
    pub count: Option<usize>,
    /// The seed every picture is drawn from, in place of the spec's.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Print each picture's scene instead of rendering.
    #[arg(long)]
    pub dry_run: bool,
    /// Print a commented example spec (built-in puppets only) and exit.
    #[arg(long, conflicts_with_all = ["spec", "merge"])]
    pub example: bool,
    /// Join the COCO files of every picture a data set's folder holds (loose or in its
    /// tars) into DIR/coco.json.
    #[arg(long, value_name = "DIR", conflicts_with = "spec")]
    pub merge: Option<PathBuf>,
    /// How the set is written: `folder` (each picture's files in --out) or `webdataset`
    /// (tars of --shard-size pictures, `set-IIIIII-SSSSSS.tar` for the run's shard I, each
    /// picture's files under its key: `000042.png`, `000042.json`, …).
    #[arg(long, value_enum, default_value_t = SetFormat::Folder)]
    pub format: SetFormat,
    /// Pictures a WebDataset tar holds (the last of a shard may hold fewer).
    #[arg(long, value_name = "N", default_value_t = 1000, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub shard_size: u32,
    /// Scenes drawn in one frame, each its own picture (1 to 4; the pictures are the same
    /// however many). Default: on a GPU as many as fit 1280 × 960 drawn pixels, on the CPU one.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..=4))]
    pub scenes_a_frame: Option<u8>,
}

/// How `generate` writes a set.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SetFormat {
    /// Each picture's files in the folder.
    Folder,
    /// WebDataset tars.
    Webdataset,
}

/// The posing options every command takes, applied to every character that has the joint
/// (or, for `--hand`, mapped fingers), in this order: `--pose`, `--hand`, `--ik`,
/// `--two-bone`, `--look-at`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct PoseArgs {
    /// `NAME` or `NAME:mirrored`, either with `@BLEND` (0 to 1: that far from the pose it
    /// is put over, as `--time` has it): a built-in body pose on every humanoid (`t-pose`,
    /// `sit-chair`, `wave`, …; `marionette info` lists them), feet on the floor.
    #[arg(long = "preset", value_name = "NAME[:mirrored][@BLEND]")]
    pub preset: Option<crate::document::posing::BodyPoseSpec>,
    /// `JOINT=rx,ry,rz` in radians (x applied first); JOINT is a name or an index. Angles
    /// outside the joint's limits are clamped. Repeatable.
    #[arg(long = "pose", value_name = "JOINT=rx,ry,rz")]
    pub poses: Vec<PoseSpec>,
    /// `SIDE=NAME`: a hand preset on every humanoid with fingers (`left=fist`,
    /// `right=point`; relaxed, fist, open, spread, point, pinch, grip, peace, thumbs-up).
    #[arg(long = "hand", value_name = "SIDE=NAME")]
    pub hands: Vec<HandSpec>,
    /// `JOINT=x,y,z`: move JOINT to this world-space point by inverse kinematics (FABRIK).
    /// Repeatable.
    #[arg(long = "ik", value_name = "JOINT=x,y,z")]
    pub ik: Vec<IkSpec>,
    /// `JOINT=x,y,z[@x,y,z]`: the limb ending at JOINT (an ankle or a wrist) turned by
    /// two-bone IK to reach the target, its knee or elbow bending toward the pole (world
    /// metres). Repeatable.
    #[arg(long = "two-bone", value_name = "JOINT=x,y,z[@x,y,z]")]
    pub two_bone: Vec<TwoBoneSpec>,
    /// `JOINT=x,y,z`: JOINT (a head) turned so that its face points at this world point (a
    /// humanoid's head spreads the turn over its chest and neck). Repeatable.
    #[arg(long = "look-at", value_name = "JOINT=x,y,z")]
    pub look_at: Vec<LookAtSpec>,
    /// A pose detector's keypoints (OpenPose JSON, COCO keypoints, COCO-WholeBody or
    /// DWPose's 133): the first humanoid posed and the camera placed to match them, the
    /// picture's size from the file (and the picture behind, where it lies beside it).
    #[arg(long, value_name = "FILE.json", conflicts_with_all = ["preset", "fit_sequence"])]
    pub fit: Option<PathBuf>,
    /// A video's keypoints: a folder of per-frame files (OpenPose's `*_keypoints.json`, in
    /// name order) or a list of them, fitted into a clip on the first humanoid at `--fps`.
    #[arg(long, value_name = "DIR", conflicts_with = "preset")]
    pub fit_sequence: Option<PathBuf>,
    /// With `--fit` or `--fit-sequence`: the person of the file (from 0; default: the
    /// largest).
    #[arg(long, value_name = "N")]
    pub person: Option<usize>,
    /// With `--fit` or `--fit-sequence`: the camera's vertical field of view in degrees
    /// (default: estimated).
    #[arg(long, value_name = "DEG", value_parser = parse_fov)]
    pub fov: Option<f32>,
}

impl PoseArgs {
    /// The specs as every command applies them (`fps`: the frames a second of a
    /// `--fit-sequence`, 30 where not given).
    pub fn specs(&self, fps: Option<f32>) -> crate::document::options::PoseSpecs {
        use crate::document::fit::{FitSpec, SequenceSpec};
        crate::document::options::PoseSpecs {
            preset: self.preset.clone(),
            poses: self.poses.clone(),
            hands: self.hands.clone(),
            ik: self.ik.clone(),
            two_bone: self.two_bone.clone(),
            look_at: self.look_at.clone(),
            fit: self.fit.clone().map(|file| FitSpec { file, person: self.person, fov: self.fov }),
            fit_sequence: self.fit_sequence.clone().map(|frames| SequenceSpec {
                frames,
                fps: fps.unwrap_or(30.0),
                person: self.person,
                fov: self.fov,
            }),
        }
    }
}

/// A field of view in degrees, more than 0 and less than 180.
fn parse_fov(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v > 0.0 && v < 180.0 => Ok(v),
        _ => Err(format!("expected degrees between 0 and 180, found `{s}`")),
    }
}

/// What `edit` is given.
#[derive(clap::Args)]
pub struct EditArgs {
    /// Character files; none opens the default scene.
    pub paths: Vec<PathBuf>,
    #[command(flatten)]
    pub clip: ClipArgs,
    /// `--pose`, `--hand`, `--ik`, `--two-bone`, `--look-at` (the scene opens with
    /// unsaved changes).
    #[command(flatten)]
    pub pose: PoseArgs,
    /// Open the newest recovery file (what autosave or a crash left in
    /// `$XDG_STATE_HOME/marionette/recovery`).
    #[arg(long, conflicts_with = "paths")]
    pub recover: bool,
    /// Frames a second of `--fit-sequence`'s files (default 30).
    #[arg(long, requires = "fit_sequence", value_parser = positive_fps)]
    pub fps: Option<f32>,
}

/// Frames a second: a positive, finite number.
fn positive_fps(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v > 0.0 && v.is_finite() && v <= 1000.0 => Ok(v),
        _ => Err(format!("expected frames a second between 0 and 1000, found `{s}`")),
    }
}

/// What `render` is given.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// A scene file or character files; none renders the default scene.
    pub paths: Vec<PathBuf>,
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub shot: ShotArgs,
    #[command(flatten)]
    pub pose: PoseArgs,
    /// Skin every character by linear blend (`lbs`) or dual quaternion (`dq`) skinning
    /// (default: as the scene file says).
    #[arg(long, value_enum)]
    pub skinning: Option<Skinning>,
    /// Scale every character to the first one's height (as they stand, feet on the
    /// floor); characters named on the command line then stand side by side.
    #[arg(long)]
    pub match_height: bool,
    #[command(flatten)]
    pub clip: ClipArgs,
    #[command(flatten)]
    pub frames: FrameArgs,
}

/// What `bench` is given.
#[derive(clap::Args)]
pub struct BenchArgs {
    /// How many characters (SMPL bodies from the data folder, else puppets).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub characters: u32,
    /// Frames measured (after warming up).
    #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub frames: u32,
    /// The course data folder (with its `smpl`) or an SMPL folder itself; defaults to
    /// MARIONETTE_DATA. A folder without an SMPL body is refused.
    #[arg(long, conflicts_with = "puppets")]
    pub data: Option<PathBuf>,
    /// A crowd of the project's puppets instead of SMPL bodies.
    #[arg(long)]
    pub puppets: bool,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Skin the crowd with the GPU skinning compute shader instead of on the CPU.
    #[arg(long)]
    pub gpu: bool,
    /// Leave the picture undrawn while measuring (the camera off; extraction and upload
    /// go on): the frame's CPU work as on a machine whose GPU draws, without llvmpipe
    /// rasterising on the same cores between frames.
    #[arg(long)]
    pub no_draw: bool,
}

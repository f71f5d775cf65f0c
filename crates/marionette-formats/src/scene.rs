//! Scene files (RON): every character's source, name, placement, pose by joint name and
//! view options; the camera; the floor. Plain serde documents, no Bevy.

use std::collections::BTreeMap;
use std::io::BufRead;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::checks::{finite, is_invertible, is_normalisable, positive};
use super::error::FormatError;
use marionette_rig::{JointRotation, Skeleton};

/// Where a character comes from.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum SourceDoc {
    /// One of the project's own characters built into the binary (`"puppet"`).
    Embedded(String),
    /// A file or folder; relative to the scene file's folder when written in a scene.
    File(PathBuf),
    /// Character `n` (from 0) of a file that holds several (a glTF file with several
    /// skins); `File` is its first.
    Part(PathBuf, usize),
}

impl SourceDoc {
    /// This source with a relative path resolved against `dir`.
    pub fn resolved(&self, dir: &Path) -> Self {
        match self {
            SourceDoc::File(p) if p.is_relative() => SourceDoc::File(dir.join(p)),
            SourceDoc::Part(p, n) if p.is_relative() => SourceDoc::Part(dir.join(p), *n),
            other => other.clone(),
        }
    }

    /// This source with its path made relative to `dir` where it lies below it, or
    /// expressed with `..` steps when both are absolute.
    pub fn relative_to(&self, dir: &Path) -> Self {
        match self {
            SourceDoc::File(p) => SourceDoc::File(relative_path(p, dir)),
            SourceDoc::Part(p, n) => SourceDoc::Part(relative_path(p, dir), *n),
            other => other.clone(),
        }
    }

    pub fn label(&self) -> String {
        match self {
            SourceDoc::Embedded(name) => format!("{name} (built in)"),
            SourceDoc::File(p) => p.display().to_string(),
            SourceDoc::Part(p, n) => format!("{} (character {})", p.display(), n + 1),
        }
    }

    /// The file or folder it is read from (none: built in).
    pub fn path(&self) -> Option<&Path> {
        match self {
            SourceDoc::Embedded(_) => None,
            SourceDoc::File(p) | SourceDoc::Part(p, _) => Some(p),
        }
    }
}

/// `path` relative to `dir` (both made absolute first); `path` itself when that fails.
pub fn relative_path(path: &Path, dir: &Path) -> PathBuf {
    let abs = |p: &Path| {
        if p.is_absolute() { Some(p.to_path_buf()) } else { std::env::current_dir().ok().map(|c| c.join(p)) }
    };
    let (Some(path_abs), Some(dir_abs)) = (abs(path), abs(dir)) else {
        return path.to_path_buf();
    };
    let clean = |p: PathBuf| -> Vec<std::ffi::OsString> {
        let mut out: Vec<std::ffi::OsString> = Vec::new();
        for c in p.components() {
            match c {
                std::path::Component::ParentDir => {
                    out.pop();
                }
                std::path::Component::CurDir => {}
                other => out.push(other.as_os_str().to_owned()),
            }
        }
        out
    };
    let (p, d) = (clean(path_abs), clean(dir_abs));
    let common = p.iter().zip(&d).take_while(|(a, b)| a == b).count();
    if common == 0 {
        return path.to_path_buf();
    }
    let mut out = PathBuf::new();
    for _ in common..d.len() {
        out.push("..");
    }
    for c in &p[common..] {
        out.push(c);
    }
    out
}

/// Where a character or prop stands: model space → world is
/// `T(translation) · Ry(yaw) · tilt · S(scale)` (the editor holds this very type on the
/// character entity). Characters stand upright (`tilt` is the identity); a prop may lie in
/// any orientation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PlacementDoc {
    pub translation: glam::Vec3,
    /// Radians about the vertical axis.
    pub yaw: f32,
    /// Uniform scale.
    pub scale: f32,
    /// A turn before the yaw, off the vertical (files without it: upright).
    #[serde(default, skip_serializing_if = "is_upright")]
    pub tilt: glam::Quat,
}

fn is_upright(q: &glam::Quat) -> bool {
    *q == glam::Quat::IDENTITY
}

impl Default for PlacementDoc {
    fn default() -> Self {
        Self::new(glam::Vec3::ZERO, 0.0, 1.0)
    }
}

impl PlacementDoc {
    /// Upright at `translation`, turned by `yaw` about the vertical, scaled by `scale`.
    pub fn new(translation: glam::Vec3, yaw: f32, scale: f32) -> Self {
        Self { translation, yaw, scale, tilt: glam::Quat::IDENTITY }
    }

    /// The orientation: the yaw after the tilt.
    pub fn rotation(&self) -> glam::Quat {
        glam::Quat::from_rotation_y(self.yaw) * self.tilt.normalize()
    }

    /// The model-to-world matrix.
    pub fn to_mat4(&self) -> glam::Mat4 {
        glam::Mat4::from_scale_rotation_translation(glam::Vec3::splat(self.scale), self.rotation(), self.translation)
    }

    /// The placement whose matrix is `m` (a rigid motion with uniform scale, as a placement
    /// times a joint's transform gives): the turn about the vertical becomes the yaw, the
    /// rest the tilt.
    pub fn from_mat4(m: glam::Mat4) -> Self {
        let (scale, rotation, translation) = m.to_scale_rotation_translation();
        let rotation = rotation.normalize();
        // Twist about y: the rotation's y and w parts.
        let yaw = 2.0 * rotation.y.atan2(rotation.w);
        let tilt = (glam::Quat::from_rotation_y(-yaw) * rotation).normalize();
        Self { translation, yaw, scale: (scale.x + scale.y + scale.z) / 3.0, tilt }
    }
}

/// Whether a character shows its skin, its skeleton, or both.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum DisplayDoc {
    #[default]
    Mesh,
    Skeleton,
    Both,
}

impl DisplayDoc {
    /// The next mode in the cycle mesh → skeleton → both.
    pub fn next(self) -> Self {
        match self {
            DisplayDoc::Mesh => DisplayDoc::Skeleton,
            DisplayDoc::Skeleton => DisplayDoc::Both,
            DisplayDoc::Both => DisplayDoc::Mesh,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ViewDoc {
    pub display: DisplayDoc,
    pub visible: bool,
    pub weight_colors: bool,
    /// Show the selected joint's weights as a heat map.
    pub heat_of_selected: bool,
    pub tint: [f32; 3],
    /// How opaque the skin is drawn (1: solid; less: a ghost to draw over a reference).
    pub opacity: f32,
}

impl Default for ViewDoc {
    fn default() -> Self {
        Self {
            display: DisplayDoc::Mesh,
            visible: true,
            weight_colors: false,
            heat_of_selected: false,
            tint: [0.8, 0.62, 0.45],
            opacity: 1.0,
        }
    }
}

/// SMPL state of a character made from the SMPL folder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SmplDoc {
    pub betas: Vec<f32>,
    /// Clip file name in the SMPL folder, if one plays.
    pub clip: Option<String>,
    /// Playback time in seconds (the clip's frames are [`marionette_rig::smpl::CLIP_FPS`]
    /// a second apart); written as `seconds`.
    #[serde(rename = "seconds")]
    pub time: f32,
    /// The time in frames, as files written before `seconds` keep it (`time`); read only,
    /// turned into `time` when the scene is read.
    #[serde(rename = "time", skip_serializing, deserialize_with = "some_number")]
    pub legacy_frames: Option<f32>,
    pub playing: bool,
    pub speed: f32,
    pub looping: bool,
    /// A second clip blended in with `blend` (0 = first clip only).
    pub blend_clip: Option<String>,
    pub blend: f32,
    /// Stand the clip up: turn the root so the clip's first frame is upright (the mocap
    /// clips carry a global rotation from a z-up capture).
    pub upright: bool,
}

/// A number read as present (a field that was a plain number before it was optional).
fn some_number<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    f32::deserialize(d).map(Some)
}

impl SmplDoc {
    /// Takes a legacy time in frames into `time` (seconds).
    fn read_legacy_frames(&mut self) {
        if let Some(frames) = self.legacy_frames.take() {
            self.time = frames / marionette_rig::smpl::CLIP_FPS;
        }
    }
}

/// The playback state of a motion document — SMPL playback, a keyframed clip, a source's
/// own clips — as the one clock every kind of motion runs on (seconds).
pub trait Clocked {
    /// Its clock: time in seconds, playing, speed, looping.
    fn clock(&self) -> marionette_rig::playback::Clock;
    /// Stores the clock's time and whether it plays (speed and looping are the document's).
    fn set_clock(&mut self, clock: marionette_rig::playback::Clock);
    /// Paused at `t` seconds.
    fn pause_at(&mut self, t: f32) {
        self.set_clock(marionette_rig::playback::Clock { time: t, playing: false, ..self.clock() });
    }
}

/// The motion documents keep the clock's four fields under the same names.
macro_rules! clocked {
    ($($doc:ty),*) => {$(
        impl Clocked for $doc {
            fn clock(&self) -> marionette_rig::playback::Clock {
                marionette_rig::playback::Clock { time: self.time, playing: self.playing, speed: self.speed, looping: self.looping }
            }
            fn set_clock(&mut self, clock: marionette_rig::playback::Clock) {
                (self.time, self.playing) = (clock.time, clock.playing);
            }
        }
    )*};
}
clocked!(SmplDoc, AnimDoc, PlaybackDoc);

/// A character's stable id within a scene: saved in scene files, kept by undo and redo;
/// selections, pins and the history name characters by it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(transparent)]
pub struct CharacterId(pub u64);

impl std::fmt::Display for CharacterId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "#{}", self.0)
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CharacterDoc {
    /// The character's stable id in the scene; files without one get fresh ids when opened.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<CharacterId>,
    pub source: SourceDoc,
    pub name: String,
    #[serde(default)]
    pub placement: PlacementDoc,
    /// Rotations by joint name (`name#index` where a name is not unique); joints not
    /// listed keep the source's pose.
    #[serde(default)]
    pub pose: BTreeMap<String, JointRotation>,
    #[serde(default)]
    pub view: ViewDoc,
    #[serde(default)]
    pub smpl: Option<SmplDoc>,
    /// Weights computed from the bones instead of the source's.
    #[serde(default)]
    pub binding: Option<BindingDoc>,
    /// Linear blend or dual quaternion skinning (files without it: linear).
    #[serde(default, skip_serializing_if = "SkinningDoc::is_linear")]
    pub skinning: SkinningDoc,
    /// Skinned by the GPU skinning compute shader instead of on the CPU (files without
    /// it: the CPU).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub gpu_skinning: bool,
    /// A keyframed clip (CSE169 `.anim`) playing on the character.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anim: Option<AnimDoc>,
    /// Morph target weights, in the order of the source's targets.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub morphs: Vec<f32>,
    /// Playback of the source's own clips (a glTF file's animations).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub playback: Option<PlaybackDoc>,
    /// Held by a joint of another character (a sword in a hand): its placement follows
    /// that joint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub attached: Option<AttachDoc>,
    /// Standard bones assigned by hand (bone → pose key), over those found from the
    /// skeleton; an empty key takes the bone off.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub humanoid: BTreeMap<marionette_rig::humanoid::HumanBone, String>,
}

/// A prop (or character) held by a joint of another character: it follows the joint,
/// keeping the offset it had from it when it was attached.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AttachDoc {
    /// The character that holds it.
    pub to: CharacterId,
    /// The holding joint (its pose key: see [`pose_key`]).
    pub joint: String,
    /// Its model space → the joint's frame, as when it was attached.
    pub offset: glam::Mat4,
}

impl AttachDoc {
    /// Held by `joint` of `to`, whose world transform is `joint_world`, where it stands now
    /// at `placement`.
    pub fn holding(to: CharacterId, joint: String, joint_world: glam::Mat4, placement: &PlacementDoc) -> Self {
        Self { to, joint, offset: joint_world.inverse() * placement.to_mat4() }
    }

    /// Where it stands while the holding joint's world transform is `joint_world`.
    pub fn placement(&self, joint_world: glam::Mat4) -> PlacementDoc {
        PlacementDoc::from_mat4(joint_world * self.offset)
    }
}

/// Playback of a source's own clips (a glTF file's animations): which clip by name, the
/// time in seconds, and a second clip blended in on the same clock.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PlaybackDoc {
    pub clip: Option<String>,
    /// Playback time in seconds.
    pub time: f32,
    pub playing: bool,
    pub speed: f32,
    pub looping: bool,
    /// A second clip blended in with `blend` (0 = first clip only).
    pub blend_clip: Option<String>,
    pub blend: f32,
}

impl Default for PlaybackDoc {
    fn default() -> Self {
        Self { clip: None, time: 0.0, playing: false, speed: 1.0, looping: true, blend_clip: None, blend: 0.0 }
    }
}

/// A keyframed clip on a character: its keys (set in the editor, kept in the scene file)
/// or the `.anim` file they came from, the time (seconds) and playback.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AnimDoc {
    /// The `.anim` file (empty when the keys are the scene's own).
    #[serde(skip_serializing_if = "crate::scene::is_empty_path")]
    pub file: PathBuf,
    /// The keys themselves, once edited: these play, not the file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub keys: Option<marionette_rig::anim::Clip>,
    pub time: f32,
    pub playing: bool,
    pub looping: bool,
    pub speed: f32,
    /// For a clip of named joints (BVH): the character's joint name → the clip's, where
    /// they differ (e.g. `L_Knee: "LeftLeg"`).
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub names: BTreeMap<String, String>,
    /// The motion of another humanoid, carried onto this one through their humanoid maps
    /// (when there are no `keys`: keys edited or baked play instead).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub retarget: Option<RetargetDoc>,
}

/// Whose motion a retargeted clip plays, and how.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RetargetDoc {
    pub from: MotionSourceDoc,
    /// How rest poses are matched (files without it: bone directions).
    #[serde(default)]
    pub rest: marionette_rig::retarget::RestAlignment,
    /// Feet the source plants stay planted (files without it: yes).
    #[serde(default = "yes")]
    pub plant_feet: bool,
}

fn yes() -> bool {
    true
}

impl RetargetDoc {
    /// The motion of `from`, directions followed, feet planted.
    pub fn of(from: MotionSourceDoc) -> Self {
        Self { from, rest: Default::default(), plant_feet: true }
    }
}

/// A humanoid whose motion is retargeted: a character of the scene (its own motion), or a
/// file and its clip: a glTF clip by name or index, an SMPL clip by the end of its name
/// (`7516`), or an `.anim`/`.bvh` file played on the file's character (a `.bvh` plays its
/// own motion).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum MotionSourceDoc {
    Character(CharacterId),
    File {
        path: PathBuf,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        clip: Option<String>,
    },
}

impl MotionSourceDoc {
    /// Its file (and a motion file its clip names) found from `dir`, as a scene file's
    /// folder resolves its sources.
    pub fn resolved(&self, dir: &Path) -> Self {
        self.with_paths(|p| dir.join(p))
    }

    /// Its file (and a motion file its clip names) relative to `dir`, as a scene file
    /// keeps its sources.
    pub fn relative_to(&self, dir: &Path) -> Self {
        self.with_paths(|p| relative_path(p, dir))
    }

    fn with_paths(&self, path_of: impl Fn(&Path) -> PathBuf) -> Self {
        match self {
            MotionSourceDoc::Character(id) => MotionSourceDoc::Character(*id),
            MotionSourceDoc::File { path, clip } => MotionSourceDoc::File {
                path: path_of(path),
                clip: clip.as_ref().map(|c| match is_motion_file(Path::new(c)) {
                    true => path_of(Path::new(c)).to_string_lossy().into_owned(),
                    false => c.clone(),
                }),
            },
        }
    }
}

/// Whether a path names a motion file (a CSE169 `.anim` or a `.bvh`).
pub fn is_motion_file(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("anim") || e.eq_ignore_ascii_case("bvh"))
}

impl Default for AnimDoc {
    fn default() -> Self {
        Self {
            file: PathBuf::new(),
            keys: None,
            time: 0.0,
            playing: true,
            looping: true,
            speed: 1.0,
            names: BTreeMap::new(),
            retarget: None,
        }
    }
}

fn is_empty_path(p: &Path) -> bool {
    p.as_os_str().is_empty()
}

impl AnimDoc {
    /// The clip `file` from its start, playing in a loop.
    pub fn of(file: impl Into<PathBuf>) -> Self {
        Self { file: file.into(), ..Self::default() }
    }
}

impl CharacterDoc {
    /// A character of `source` named `name`, standing at the origin in its source's pose,
    /// with nothing else set.
    pub fn new(source: SourceDoc, name: impl Into<String>) -> Self {
        Self {
            id: None,
            source,
            name: name.into(),
            placement: PlacementDoc::default(),
            pose: BTreeMap::new(),
            view: ViewDoc::default(),
            smpl: None,
            binding: None,
            skinning: SkinningDoc::default(),
            gpu_skinning: false,
            anim: None,
            morphs: Vec::new(),
            playback: None,
            attached: None,
            humanoid: BTreeMap::new(),
        }
    }
}

/// How to bind a skin from its skeleton's bones (stored as `Nearest` or `Smooth`).
pub use marionette_rig::bind::Binding as BindingDoc;

/// How a character's vertices follow its joints (stored as `Linear` or `DualQuaternion`).
pub use marionette_rig::dqs::SkinningMethod as SkinningDoc;

pub use super::stage::{
    AmbientDoc, Antialias, BackgroundDoc, CameraDoc, LampDoc, MAX_LAMPS, ShotDoc, SpotDoc, StageDoc, SunDoc, ViewName,
};

#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct SceneDoc {
    pub characters: Vec<CharacterDoc>,
    #[serde(default)]
    pub camera: Option<CameraDoc>,
    #[serde(default)]
    pub stage: StageDoc,
    /// The scene's pose library, by name.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub poses: BTreeMap<String, LibraryPoseDoc>,
    /// Camera views kept by name.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub bookmarks: BTreeMap<String, CameraDoc>,
    /// The picture `render` takes: its size and samples.
    #[serde(default)]
    pub shot: ShotDoc,
}

/// A pose kept in the scene's library: rotations by joint name (applied to any character
/// with those names) and a thumbnail, the posed bones seen from the front as 2D segments
/// `[x0, y0, x1, y1]` in a unit square.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct LibraryPoseDoc {
    pub joints: BTreeMap<String, JointRotation>,
    pub thumbnail: Vec<[f32; 4]>,
    /// The character it was kept from, so that characters without its joint names take it
    /// through their humanoid maps.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rig: Option<SourceDoc>,
}

impl Default for SmplDoc {
    fn default() -> Self {
        Self {
            betas: Vec::new(),
            clip: None,
            time: 0.0,
            legacy_frames: None,
            playing: false,
            speed: 1.0,
            looping: true,
            blend_clip: None,
            blend: 0.0,
            upright: true,
        }
    }
}

/// The key a joint's pose is stored under: its name; `name#index` when another joint has
/// the same name (CSE169's dragon repeats names) or when the name itself reads as another
/// joint's `name#index` (a joint literally named `a#1`), so every key finds its own joint.
pub fn pose_key(skeleton: &Skeleton, joint: usize) -> String {
    let name = &skeleton.joint(joint).name;
    let repeated = skeleton.joints().iter().filter(|j| &j.name == name).count() > 1;
    let shadowed = joint_of_indexed_key(skeleton, name).is_some_and(|other| other != joint);
    if repeated || shadowed { format!("{name}#{joint}") } else { name.clone() }
}

/// Resolves a pose key back to a joint: `name#index` where joint `index` has that name,
/// otherwise the first joint of that name.
pub fn joint_of_pose_key(skeleton: &Skeleton, key: &str) -> Option<usize> {
    joint_of_indexed_key(skeleton, key).or_else(|| skeleton.find(key))
}

/// The joint a `name#index` key names, when joint `index` has that name.
fn joint_of_indexed_key(skeleton: &Skeleton, key: &str) -> Option<usize> {
    let (name, index) = key.rsplit_once('#')?;
    let i = index.parse::<usize>().ok()?;
    (i < skeleton.len() && skeleton.joint(i).name == name).then_some(i)
}

/// Reads a scene; syntax errors carry the line and column, bad numbers the field's path
/// (`characters[1].placement.scale`).
pub fn parse_scene(reader: impl BufRead, path: &Path) -> Result<SceneDoc, FormatError> {
    let text = super::error::read_text(reader, path)?;
    let mut doc: SceneDoc = ron::from_str(&text)
        .map_err(|e| FormatError::syntax_at(path, e.span.start.line.max(1), e.span.start.col.max(1), e.code))?;
    doc.validate().map_err(|e| FormatError::other(path, e))?;
    doc.characters.iter_mut().filter_map(|c| c.smpl.as_mut()).for_each(SmplDoc::read_legacy_frames);
    Ok(doc)
}

impl SceneDoc {
    /// Checks every number: finite, scales and the camera distance positive, quaternions
    /// not zero, blend weights in 0..=1. The error names the field (`characters[0].placement.scale`).
    pub fn validate(&self) -> Result<(), String> {
        for (i, c) in self.characters.iter().enumerate() {
            let at = |field: &str| format!("characters[{i}].{field}");
            if let SourceDoc::Part(_, n) = c.source
                && n >= MAX_PARTS
            {
                return Err(format!("{}: expected a character index below {MAX_PARTS}, found {n}", at("source")));
            }
            finite(&at("placement.translation"), &c.placement.translation.to_array())?;
            finite(&at("placement.yaw"), &[c.placement.yaw])?;
            finite(&at("placement.tilt"), &c.placement.tilt.to_array())?;
            if !is_normalisable(c.placement.tilt) {
                return Err(format!("{}: expected a rotation, found a zero quaternion", at("placement.tilt")));
            }
            if let Some(attached) = &c.attached {
                finite(&at("attached.offset"), &attached.offset.to_cols_array())?;
                if !is_invertible(&attached.offset) {
                    return Err(format!("{}: expected an invertible matrix", at("attached.offset")));
                }
            }
            positive(&at("placement.scale"), c.placement.scale)?;
            rotations(&at("pose"), &c.pose)?;
            finite(&at("view.tint"), &c.view.tint)?;
            if !(0.0..=1.0).contains(&c.view.opacity) {
                return Err(format!("{}: expected an opacity in 0..=1, found {}", at("view.opacity"), c.view.opacity));
            }
            if let Some(smpl) = &c.smpl {
                finite(&at("smpl.betas"), &smpl.betas)?;
                finite(&at("smpl.seconds"), &[smpl.time])?;
                finite(&at("smpl.time"), &smpl.legacy_frames.into_iter().collect::<Vec<_>>())?;
                finite(&at("smpl.speed"), &[smpl.speed])?;
                blend_weight(&at("smpl.blend"), smpl.blend)?;
            }
            if let Some(anim) = &c.anim {
                finite(&at("anim.time"), &[anim.time])?;
                finite(&at("anim.speed"), &[anim.speed])?;
                if let Some(keys) = &anim.keys {
                    keys.check().map_err(|e| format!("{}.{e}", at("anim.keys")))?;
                }
            }
            finite(&at("morphs"), &c.morphs)?;
            if let Some(playback) = &c.playback {
                finite(&at("playback.time"), &[playback.time])?;
                finite(&at("playback.speed"), &[playback.speed])?;
                blend_weight(&at("playback.blend"), playback.blend)?;
            }
        }
        if let Some(camera) = &self.camera {
            camera.validate("camera")?;
        }
        for (name, camera) in &self.bookmarks {
            camera.validate(&format!("bookmarks[{name:?}]"))?;
        }
        self.stage.validate()?;
        self.shot.validate()?;
        for (name, pose) in &self.poses {
            rotations(&format!("poses[{name:?}].joints"), &pose.joints)?;
            finite(&format!("poses[{name:?}].thumbnail"), pose.thumbnail.as_flattened())?;
        }
        Ok(())
    }
}

/// The most characters a scene may take from one file (`Part(file, n)`).
pub const MAX_PARTS: usize = 1 << 16;

/// Rotations by joint: finite, and quaternions not zero.
fn rotations(at: &str, pose: &BTreeMap<String, JointRotation>) -> Result<(), String> {
    for (key, rotation) in pose {
        let at = format!("{at}[{key:?}]");
        match rotation {
            JointRotation::Euler(angles, _) => finite(&at, &angles.to_array())?,
            JointRotation::Quat(q) => {
                finite(&at, &q.to_array())?;
                if !is_normalisable(*q) {
                    return Err(format!("{at}: expected a rotation, found a zero quaternion"));
                }
            }
        }
    }
    Ok(())
}

/// A blend weight: finite, in 0..=1.
fn blend_weight(at: &str, value: f32) -> Result<(), String> {
    if (0.0..=1.0).contains(&value) {
        Ok(())
    } else {
        Err(format!("{at}: expected a blend weight in 0..=1, found {value}"))
    }
}

/// The scene as pretty RON text; fails when a source path is not valid UTF-8 (RON text
/// cannot hold it).
pub fn scene_to_string(doc: &SceneDoc) -> Result<String, ron::Error> {
    ron::ser::to_string_pretty(doc, ron::ser::PrettyConfig::default())
}

/// Writes a scene whole or not at all (temporary file, then rename).
pub fn save_scene(path: &Path, doc: &SceneDoc) -> Result<(), FormatError> {
    // What we write must read back: no NaN, no zero quaternion, no overflowing key.
    doc.validate().map_err(|e| FormatError::other(path, format!("cannot be written: {e}")))?;
    let text = scene_to_string(doc).map_err(|e| FormatError::other(path, format!("cannot be written: {e}")))?;
    super::write_atomically(path, |w| std::io::Write::write_all(w, text.as_bytes()))
        .map_err(|e| FormatError::io(path, e))
}

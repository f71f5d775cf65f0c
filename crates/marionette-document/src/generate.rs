//! `marionette generate`: a data set's spec (what varies and how), the scene of each
//! picture drawn from it, shards, manifests and the merged COCO file. No Bevy: the app
//! renders the scenes this module makes.
//!
//! Picture `k` depends only on the spec and `(seed, k)`: its draws come from a generator
//! seeded with both, so any shard split renders the same files.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::Deserialize;

use marionette_formats::FormatError;
use marionette_formats::scene::{
    Antialias, BackgroundDoc, CameraDoc, CharacterDoc, PlacementDoc, PlaybackDoc, SceneDoc, ShotDoc, SmplDoc, SourceDoc,
};
use marionette_formats::stage::LightPreset;
use marionette_rig::JointRotation;

use super::AssetLibrary;

/// A spec's field that cannot be: its path in the spec (`camera.fov`) and what was expected.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{at}: {expected}")]
pub struct SpecError {
    pub at: String,
    pub expected: String,
}

impl SpecError {
    fn at(at: impl Into<String>, expected: String) -> Self {
        Self { at: at.into(), expected }
    }
}

/// What stops a data set: a shard that cannot be, a picture's scene, its files.
#[derive(Debug, thiserror::Error)]
pub enum GenerateError {
    #[error("--shard: expected I/N with 0 ≤ I < N, found {0:?}")]
    Shard(String),
    #[error("{name}: expected a whole number, found {value:?}")]
    Variable { name: &'static str, value: String },
    #[error("SLURM_ARRAY_TASK_ID is set without SLURM_ARRAY_TASK_COUNT")]
    NoSlurmCount,
    #[error("SLURM_ARRAY_TASK_ID {id} (from {first}) is not one of {count} tasks")]
    SlurmTask { id: usize, first: usize, count: usize },
    #[error("JOB_COMPLETION_INDEX is set: give the job's completions with --shards N")]
    NoShards,
    #[error("JOB_COMPLETION_INDEX {index} is not below --shards {count}")]
    CompletionIndex { index: usize, count: usize },
    #[error("picture {k}: {message}")]
    Picture { k: u64, message: String },
    #[error(transparent)]
    Format(#[from] FormatError),
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{}: {source}", path.display())]
    Json { path: PathBuf, source: serde_json::Error },
    #[error("{}: {source} (was it generated with data?)", path.display())]
    NoData { path: PathBuf, source: std::io::Error },
    #[error("{}: no manifest-*.jsonl: nothing generated here", .0.display())]
    NoManifest(PathBuf),
    #[error(transparent)]
    Write(#[from] super::annotate::write::WriteError),
}

/// The most characters a picture may hold (annotation ids are numbered within it).
pub const MAX_PER_PICTURE: usize = 100;

/// The most pictures a data set may have.
pub const MAX_PICTURES: usize = 10_000_000;

/// A commented example spec that uses only the built-in puppet, so it runs anywhere.
pub const EXAMPLE: &str = include_str!("../../../assets/generate_example.ron");

/// What a data set varies and how.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    /// With the picture's number, all that a picture's draws depend on.
    pub seed: u64,
    /// How many pictures.
    pub count: usize,
    #[serde(default = "default_width")]
    pub width: u32,
    #[serde(default = "default_height")]
    pub height: u32,
    /// How the pictures' edges are smoothed (multisampled where not said).
    #[serde(default)]
    pub antialias: Antialias,
    /// Write each picture's data (depth, normals, masks, keypoints, COCO) beside it.
    #[serde(default)]
    pub data: bool,
    /// Write the maps ControlNet reads beside each picture (`render --controlnet`'s).
    #[serde(default)]
    pub controlnet: bool,
    /// With `controlnet`, also the picture's canny edges at these thresholds
    /// (`render --canny`'s).
    #[serde(default)]
    pub canny: Option<crate::annotate::canny::Canny>,
    /// Who may stand in a picture, each drawn with its weight.
    pub characters: Vec<Choice<Who>>,
    /// How many characters a picture holds, at least and at most.
    pub per_picture: (usize, usize),
    /// The side of the square of floor the characters stand in (metres, centred on the origin).
    pub area: f32,
    /// The least distance between two characters' centres (metres).
    pub spacing: f32,
    /// Where each character faces (degrees about the vertical; 0 faces the camera at yaw 0).
    #[serde(default = "Draw::any_turn")]
    pub facing: Draw,
    /// The time into each character's clip (seconds), where it has one.
    #[serde(default = "Draw::zero")]
    pub time: Draw,
    pub camera: CameraSpec,
    #[serde(default)]
    pub lights: LightSpec,
    /// Behind the characters, each drawn with its weight (none: the sky).
    #[serde(default)]
    pub backgrounds: Vec<Choice<Background>>,
    /// Built-in body poses and hand presets put on each humanoid, drawn for each (none:
    /// the characters as they come).
    #[serde(default)]
    pub poses: Option<PosesSpec>,
    /// Each character's colour (the tint its materials are multiplied by), each channel
    /// drawn (none: the character's own).
    #[serde(default)]
    pub tint: Option<(Draw, Draw, Draw)>,
    /// Props from a folder put between the camera and the people, hiding parts of them.
    #[serde(default)]
    pub props: Option<PropsSpec>,
}

/// Props (OBJ meshes, metres, of a folder relative to the spec) as occluders: each picture
/// draws how many, and for each a file, a person it stands in front of, how far along the
/// floor from the camera to that person (0 the camera, 1 the person) and a turn.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct PropsSpec {
    pub folder: PathBuf,
    /// How many a picture: (least, most).
    #[serde(default = "one_prop")]
    pub per_picture: (usize, usize),
    /// Where along the way from the camera to its person each stands.
    #[serde(default = "halfway")]
    pub between: Draw,
}

fn one_prop() -> (usize, usize) {
    (1, 1)
}

fn halfway() -> Draw {
    Draw::Uniform(0.4, 0.7)
}

/// The props (OBJ meshes) of a folder, by name.
pub fn prop_files(folder: &Path) -> Vec<PathBuf> {
    files_ending(folder, &[".obj"])
}

impl PropsSpec {
    fn check(&self) -> Result<(), SpecError> {
        if prop_files(&self.folder).is_empty() {
            return Err(SpecError::at(
                "props.folder",
                format!("an empty distribution: no OBJ props in {}", self.folder.display()),
            ));
        }
        let (least, most) = self.per_picture;
        if least > most || most > MAX_PER_PICTURE {
            return Err(SpecError::at(
                "props.per_picture",
                format!("expected (least, most) with least ≤ most ≤ {MAX_PER_PICTURE}, found ({least}, {most})"),
            ));
        }
        self.between.check("props.between")
    }

    /// The props of a picture whose camera stands at `eye`, before the `people` (their
    /// places on the floor), their ids following theirs.
    fn draw(
        &self,
        rng: &mut Rng,
        library: &mut AssetLibrary,
        eye: Vec3,
        people: &[Vec3],
    ) -> Result<Vec<CharacterDoc>, GenerateError> {
        let files = prop_files(&self.folder);
        let (least, most) = self.per_picture;
        let n = least + rng.below(most - least + 1);
        let mut props = Vec::with_capacity(n);
        for i in 0..n {
            let file = files[rng.below(files.len())].clone();
            let person = people.get(rng.below(people.len().max(1))).copied().unwrap_or(Vec3::ZERO);
            let along = self.between.draw(rng).clamp(0.0, 1.0);
            let yaw = rng.unit() * std::f32::consts::TAU;
            let ground = Vec3::new(eye.x, 0.0, eye.z);
            let at = ground + (Vec3::new(person.x, 0.0, person.z) - ground) * along;
            let mut prop = CharacterDoc::new(SourceDoc::File(file), format!("prop {}", i + 1));
            prop.id = Some(marionette_formats::scene::CharacterId((people.len() + i) as u64 + 1));
            prop.placement = PlacementDoc::new(at, yaw, 1.0);
            stand_at(library, &mut prop, at)?;
            props.push(prop);
        }
        Ok(props)
    }
}

/// The body poses and hand presets a spec draws from for each humanoid: the body pose is put
/// over its clip's pose at the drawn time (the clip then stops), mirrored for a share of
/// them, and each hand takes one of `hands`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct PosesSpec {
    /// Names of the built-in body poses (`sit-chair`, `wave`, …); none: all of them.
    #[serde(default)]
    pub body: Vec<String>,
    /// The share of characters whose body pose is mirrored, 0 to 1.
    #[serde(default)]
    pub mirrored: f32,
    /// Hand presets (`fist`, `open`, `point`, …) each hand is drawn from; none: hands as
    /// they are.
    #[serde(default)]
    pub hands: Vec<String>,
    /// How far from the clip's pose at the drawn time to the body pose, drawn from 0 to 1
    /// (each joint turned the shortest way); none: all the way.
    #[serde(default)]
    pub blend: Option<Draw>,
}

impl PosesSpec {
    /// Names known and the share within 0 to 1; the error names the field.
    fn check(&self) -> Result<(), SpecError> {
        for (k, name) in self.body.iter().enumerate() {
            if marionette_rig::body_poses::body_pose(name).is_none() {
                let names: Vec<&str> = marionette_rig::body_poses::POSES.iter().map(|p| p.name).collect();
                return Err(SpecError::at(
                    format!("poses.body[{k}]"),
                    format!("expected one of {}, found {name:?}", names.join(", ")),
                ));
            }
        }
        for (k, name) in self.hands.iter().enumerate() {
            if marionette_rig::hands::preset(name).is_none() {
                let names: Vec<&str> = marionette_rig::hands::PRESETS.iter().map(|p| p.0).collect();
                return Err(SpecError::at(
                    format!("poses.hands[{k}]"),
                    format!("expected one of {}, found {name:?}", names.join(", ")),
                ));
            }
        }
        if !(0.0..=1.0).contains(&self.mirrored) {
            return Err(SpecError::at(
                "poses.mirrored",
                format!("expected a share from 0 to 1, found {}", self.mirrored),
            ));
        }
        if let Some(blend) = &self.blend {
            blend.check("poses.blend")?;
        }
        Ok(())
    }

    /// The body pose and the hands for one character, drawn (the same number of draws
    /// whatever is drawn).
    fn draw(&self, rng: &mut Rng) -> (crate::posing::BodyPoseSpec, Vec<crate::posing::HandSpec>) {
        let names: Vec<&str> = match self.body.is_empty() {
            true => marionette_rig::body_poses::POSES.iter().map(|p| p.name).collect(),
            false => self.body.iter().map(String::as_str).collect(),
        };
        let name = names[rng.below(names.len())].to_string();
        let mirrored = rng.unit() < self.mirrored;
        let hands = [true, false].map(|left| (left, rng.below(self.hands.len().max(1))));
        let hands = match self.hands.is_empty() {
            true => Vec::new(),
            false => hands.map(|(left, k)| crate::posing::HandSpec { left, preset: self.hands[k].clone() }).to_vec(),
        };
        let mut body = crate::posing::BodyPoseSpec::new(name, mirrored);
        if let Some(blend) = &self.blend {
            body.blend = blend.draw(rng).clamp(0.0, 1.0);
        }
        (body, hands)
    }
}

fn default_width() -> u32 {
    320
}

fn default_height() -> u32 {
    240
}

/// One of several things, drawn with a weight (relative to the others').
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Choice<T> {
    pub what: T,
    #[serde(default = "one")]
    pub weight: f32,
}

fn one() -> f32 {
    1.0
}

/// A kind of character.
#[derive(Debug, Clone, Deserialize)]
pub enum Who {
    /// The built-in puppet, its arms, legs and head turned a little at random.
    Puppet,
    /// A character file (relative to the spec), playing its own clip (glTF, FBX, BVH) or
    /// `anim` (a `.anim` file) at the drawn time; the file's first character. With
    /// `motions`, a folder of clips (BVH, glTF, FBX; relative to the spec): one drawn for
    /// each character and retargeted onto it through the humanoid maps (a Mixamo or VRM
    /// character walking CMU motion).
    File {
        path: PathBuf,
        #[serde(default)]
        anim: Option<PathBuf>,
        #[serde(default)]
        motions: Option<PathBuf>,
    },
    /// An SMPL body of the folder (relative to the spec), its ten β each drawn from `betas`,
    /// playing one of the folder's clips at the drawn time.
    Smpl { folder: PathBuf, betas: Draw },
}

/// A number drawn at random.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub enum Draw {
    Fixed(f32),
    /// Uniform from the first to the second.
    Uniform(f32, f32),
    Normal {
        mean: f32,
        sd: f32,
    },
}

impl Draw {
    fn any_turn() -> Self {
        Draw::Uniform(-180.0, 180.0)
    }

    fn zero() -> Self {
        Draw::Fixed(0.0)
    }

    /// Refused when not finite or empty (a uniform range backwards, a negative spread).
    fn check(&self, at: &str) -> Result<(), SpecError> {
        let numbers = match *self {
            Draw::Fixed(v) => vec![v],
            Draw::Uniform(a, b) => {
                if a > b {
                    return Err(SpecError::at(at, format!("an empty distribution: Uniform({a}, {b}) runs backwards")));
                }
                vec![a, b]
            }
            Draw::Normal { mean, sd } => {
                if sd < 0.0 {
                    return Err(SpecError::at(at, format!("expected a spread of 0 or more, found sd: {sd}")));
                }
                vec![mean, sd]
            }
        };
        match numbers.iter().find(|v| !v.is_finite()) {
            Some(v) => Err(SpecError::at(at, format!("expected a finite number, found {v}"))),
            None => Ok(()),
        }
    }

    fn draw(&self, rng: &mut Rng) -> f32 {
        match *self {
            Draw::Fixed(v) => v,
            Draw::Uniform(a, b) => a + (b - a) * rng.unit(),
            Draw::Normal { mean, sd } => mean + sd * rng.normal(),
        }
    }

    /// The least and most it draws (a normal's to four spreads).
    fn bounds(&self) -> (f32, f32) {
        match *self {
            Draw::Fixed(v) => (v, v),
            Draw::Uniform(a, b) => (a, b),
            Draw::Normal { mean, sd } => (mean - 4.0 * sd, mean + 4.0 * sd),
        }
    }
}

/// The camera: on an orbit round the group's centre.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// From the point it looks at (metres).
    pub distance: Draw,
    /// Its eye over the floor (metres).
    pub height: Draw,
    /// About the vertical (degrees; 0 looks along -z, at the characters' fronts at facing 0).
    pub yaw: Draw,
    /// Vertical field of view (degrees).
    pub fov: Draw,
    /// The height it looks at over the group's centre (metres).
    #[serde(default = "default_look_at")]
    pub look_at: f32,
}

fn default_look_at() -> f32 {
    0.9
}

/// The lights: a preset each picture, the sun turned.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LightSpec {
    /// Lighting presets by name (`default`, `studio`, `overcast`, `dusk`), one drawn a picture.
    pub presets: Vec<String>,
    /// The sun's azimuth (degrees); none: the preset's.
    pub sun_azimuth: Option<Draw>,
    /// The sun's elevation (degrees); none: the preset's.
    pub sun_elevation: Option<Draw>,
    /// Shadows' edges softened (else sharp: far cheaper where the renderer runs on the CPU).
    pub soft_shadows: bool,
}

impl Default for LightSpec {
    fn default() -> Self {
        Self { presets: vec!["default".into()], sun_azimuth: None, sun_elevation: None, soft_shadows: true }
    }
}

/// What is behind the characters.
#[derive(Debug, Clone, Deserialize)]
pub enum Background {
    Sky,
    /// A colour (sRGB), each channel drawn.
    Color(Draw, Draw, Draw),
    /// A vertical gradient between two colours (sRGB).
    Gradient {
        top: [f32; 3],
        bottom: [f32; 3],
    },
    /// One of the pictures (PNG or JPEG) of a folder (relative to the spec), filling the frame.
    Images(PathBuf),
}

/// The light presets by the names a spec uses.
fn preset_named(name: &str) -> Option<LightPreset> {
    match name {
        "default" => Some(LightPreset::Default),
        "studio" => Some(LightPreset::Studio),
        "overcast" => Some(LightPreset::Overcast),
        "dusk" => Some(LightPreset::Dusk),
        _ => None,
    }
}

/// Reads a spec: syntax errors with their line and column, then every field checked
/// ([`Spec::check`]); relative paths resolved against the spec's folder.
pub fn read_spec(path: &Path) -> Result<Spec, FormatError> {
    let text = marionette_formats::error::read_text(marionette_formats::error::open(path)?, path)?;
    parse_spec(&text, path)
}

/// A spec from its text ([`read_spec`]).
pub fn parse_spec(text: &str, path: &Path) -> Result<Spec, FormatError> {
    let mut spec: Spec = ron::from_str(text)
        .map_err(|e| FormatError::syntax_at(path, e.span.start.line.max(1), e.span.start.col.max(1), e.code))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    spec.resolve(dir);
    spec.check().map_err(|e| FormatError::other(path, e))?;
    Ok(spec)
}

impl Spec {
    fn resolve(&mut self, dir: &Path) {
        for c in &mut self.characters {
            match &mut c.what {
                Who::Puppet => {}
                Who::File { path, anim, motions } => {
                    *path = dir.join(&*path);
                    for file in [anim, motions].into_iter().flatten() {
                        *file = dir.join(&*file);
                    }
                }
                Who::Smpl { folder, .. } => *folder = dir.join(&*folder),
            }
        }
        for b in &mut self.backgrounds {
            if let Background::Images(folder) = &mut b.what {
                *folder = dir.join(&*folder);
            }
        }
        if let Some(props) = &mut self.props {
            props.folder = dir.join(&props.folder);
        }
    }

    /// The size each picture is drawn at (one sample a pixel).
    pub fn shot(&self) -> ShotDoc {
        ShotDoc { width: self.width, height: self.height, samples: 1, antialias: self.antialias }
    }

    /// Every field: sizes within what a picture may be, distributions not empty, weights
    /// positive, the characters that may be asked for fitting in the area `spacing` apart,
    /// presets known, files there. The error names the field (`camera.fov`).
    pub fn check(&self) -> Result<(), SpecError> {
        self.shot().validate().map_err(|e| match e.split_once(": ") {
            Some((at, expected)) => SpecError::at(at, expected.to_owned()),
            None => SpecError::at("shot", e),
        })?;
        if let Some(poses) = &self.poses {
            poses.check()?;
        }
        if let Some(props) = &self.props {
            props.check()?;
        }
        if let Some((r, g, b)) = &self.tint {
            r.check("tint.0")?;
            g.check("tint.1")?;
            b.check("tint.2")?;
        }
        if self.canny.is_some() && !self.controlnet {
            return Err(SpecError::at("canny", "the canny edges are a ControlNet map: set controlnet: true".into()));
        }
        if self.count == 0 || self.count > MAX_PICTURES {
            return Err(SpecError::at("count", format!("expected 1 to {MAX_PICTURES} pictures, found {}", self.count)));
        }
        weights("characters", self.characters.iter().map(|c| c.weight))?;
        for (k, c) in self.characters.iter().enumerate() {
            let at = format!("characters[{k}]");
            match &c.what {
                Who::Puppet => {}
                Who::File { path, anim, motions } => {
                    exists(&format!("{at}.path"), path)?;
                    if let Some(anim) = anim {
                        exists(&format!("{at}.anim"), anim)?;
                    }
                    if let Some(folder) = motions
                        && clip_files(folder).is_empty()
                    {
                        return Err(SpecError::at(
                            format!("{at}.motions"),
                            format!("an empty distribution: no BVH, glTF or FBX clips in {}", folder.display()),
                        ));
                    }
                }
                Who::Smpl { folder, betas } => {
                    exists(&format!("{at}.folder"), folder)?;
                    betas.check(&format!("{at}.betas"))?;
                }
            }
        }
        let (least, most) = self.per_picture;
        if least > most || most == 0 || most > MAX_PER_PICTURE {
            return Err(SpecError::at(
                "per_picture",
                format!(
                    "expected (least, most) with least ≤ most and 1 ≤ most ≤ {MAX_PER_PICTURE}, found \
                 ({least}, {most})"
                ),
            ));
        }
        positive("area", self.area)?;
        positive("spacing", self.spacing)?;
        let fits = places(self.area, self.spacing);
        if most > fits {
            return Err(SpecError::at(
                "spacing",
                format!(
                    "{most} characters {} m apart do not fit in a square of {} m (at most {fits}); widen \
                 `area`, narrow `spacing` or ask for fewer in `per_picture`",
                    self.spacing, self.area
                ),
            ));
        }
        self.facing.check("facing")?;
        self.time.check("time")?;
        let camera = &self.camera;
        for (name, draw) in [("distance", camera.distance), ("height", camera.height), ("yaw", camera.yaw)] {
            draw.check(&format!("camera.{name}"))?;
        }
        camera.fov.check("camera.fov")?;
        let (low, high) = camera.fov.bounds();
        if low <= 0.0 || high >= 180.0 {
            return Err(SpecError::at(
                "camera.fov",
                format!("expected degrees above 0 and below 180, found {low} to {high}"),
            ));
        }
        if camera.distance.bounds().0 <= 0.0 {
            return Err(SpecError::at(
                "camera.distance",
                format!("expected metres above 0, found {:?}", camera.distance),
            ));
        }
        if !camera.look_at.is_finite() {
            return Err(SpecError::at("camera.look_at", format!("expected a finite number, found {}", camera.look_at)));
        }
        if self.lights.presets.is_empty() {
            return Err(SpecError::at("lights.presets", "an empty distribution: name at least one preset".into()));
        }
        for (k, name) in self.lights.presets.iter().enumerate() {
            if preset_named(name).is_none() {
                return Err(SpecError::at(
                    format!("lights.presets[{k}]"),
                    format!("expected default, studio, overcast or dusk, found {name:?}"),
                ));
            }
        }
        for (name, draw) in [("sun_azimuth", self.lights.sun_azimuth), ("sun_elevation", self.lights.sun_elevation)] {
            draw.map_or(Ok(()), |d| d.check(&format!("lights.{name}")))?;
        }
        if !self.backgrounds.is_empty() {
            weights("backgrounds", self.backgrounds.iter().map(|b| b.weight))?;
        }
        for (k, b) in self.backgrounds.iter().enumerate() {
            let at = format!("backgrounds[{k}]");
            match &b.what {
                Background::Sky => {}
                Background::Color(r, g, b) => {
                    [r, g, b].iter().try_for_each(|d| d.check(&at))?;
                }
                Background::Gradient { top, bottom } => {
                    if top.iter().chain(bottom).any(|v| !v.is_finite()) {
                        return Err(SpecError::at(at, "expected finite colours".into()));
                    }
                }
                Background::Images(folder) => {
                    if image_files(folder).is_empty() {
                        return Err(SpecError::at(
                            at,
                            format!("an empty distribution: no PNG or JPEG pictures in {}", folder.display()),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// The folder of SMPL bodies, the character files it names, the clips retargeted onto
    /// them and the props, to load before rendering.
    pub fn sources(&self) -> Vec<SourceDoc> {
        self.characters
            .iter()
            .flat_map(|c| match &c.what {
                Who::Puppet => vec![SourceDoc::Embedded("puppet".into())],
                Who::File { path, motions, .. } => std::iter::once(path.clone())
                    .chain(motions.iter().flat_map(|folder| clip_files(folder)))
                    .map(SourceDoc::File)
                    .collect(),
                Who::Smpl { folder, .. } => vec![SourceDoc::File(folder.clone())],
            })
            .chain(self.props.iter().flat_map(|p| prop_files(&p.folder)).map(SourceDoc::File))
            .collect()
    }
}

fn positive(at: &str, v: f32) -> Result<(), SpecError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(SpecError::at(at, format!("expected a number above 0, found {v}")))
    }
}

fn exists(at: &str, path: &Path) -> Result<(), SpecError> {
    if path.exists() { Ok(()) } else { Err(SpecError::at(at, format!("{}: no such file or folder", path.display()))) }
}

/// Weights to draw by: at least one, each finite and 0 or more, not all 0.
fn weights(at: &str, weights: impl Iterator<Item = f32>) -> Result<(), SpecError> {
    let weights: Vec<f32> = weights.collect();
    if weights.is_empty() {
        return Err(SpecError::at(at, "an empty distribution: list at least one".into()));
    }
    if let Some(w) = weights.iter().find(|w| !(w.is_finite() && **w >= 0.0)) {
        return Err(SpecError::at(at, format!("expected weights of 0 or more, found {w}")));
    }
    if weights.iter().all(|&w| w == 0.0) {
        return Err(SpecError::at(at, "an empty distribution: every weight is 0".into()));
    }
    Ok(())
}

/// How many characters fit in a square of side `area`, `spacing` apart: the cells of a
/// grid whose cells are at least `spacing` wide.
fn places(area: f32, spacing: f32) -> usize {
    grid_side(area, spacing).pow(2)
}

/// The cells along a side of the square of side `area` cut into cells at least `spacing`
/// wide (at least one).
fn grid_side(area: f32, spacing: f32) -> usize {
    (area / spacing).floor().max(1.0) as usize
}

/// The pictures (PNG, JPEG) of a folder, by name.
pub fn image_files(folder: &Path) -> Vec<PathBuf> {
    files_ending(folder, &[".png", ".jpg", ".jpeg"])
}

/// The motion clips (BVH, glTF, FBX) of a folder, by name.
pub fn clip_files(folder: &Path) -> Vec<PathBuf> {
    files_ending(folder, &[".bvh", ".glb", ".gltf", ".fbx"])
}

/// The files of a folder whose names end, in any case, with one of `endings`, by name.
fn files_ending(folder: &Path, endings: &[&str]) -> Vec<PathBuf> {
    files_named(folder, |name| {
        let lower = name.to_ascii_lowercase();
        endings.iter().any(|e| lower.ends_with(e))
    })
}

/// The files of a folder whose names `keep` takes, by name (none where it cannot be read).
fn files_named(folder: &Path, keep: impl Fn(&str) -> bool) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.file_name().and_then(|n| n.to_str()).is_some_and(&keep))
        .collect();
    files.sort();
    files
}

/// A small generator of random numbers (SplitMix64): the same stream for the same seed on
/// every machine.
pub struct Rng(u64);

impl Rng {
    /// The stream of picture `k` of a data set seeded with `seed`.
    pub fn of_picture(seed: u64, k: u64) -> Self {
        let mut mixer = Rng(seed ^ 0x6d61_7269_6f6e_6574);
        let base = mixer.next_u64();
        Rng(base ^ k.wrapping_mul(0x9e37_79b9_7f4a_7c15))
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f32 {
        ((self.next_u64() >> 40) as f32) / (1u64 << 24) as f32
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f32 {
        let (u, v) = (1.0 - self.unit(), self.unit());
        (-2.0 * u.ln()).sqrt() * (std::f32::consts::TAU * v).cos()
    }

    /// An index below `n` (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.next_u64() >> 11) % n as u64) as usize
    }

    /// An index drawn by `weights` (not all zero).
    pub fn weighted(&mut self, weights: impl Iterator<Item = f32> + Clone) -> usize {
        let total: f32 = weights.clone().sum();
        let mut at = self.unit() * total;
        let mut last = 0;
        for (k, w) in weights.enumerate() {
            if w > 0.0 {
                last = k;
                if at < w {
                    return k;
                }
                at -= w;
            }
        }
        last
    }
}

/// The scene of picture `k`: its characters drawn, posed and stood on the floor `spacing`
/// apart in the area; the camera looking at their centre; the lights and background drawn;
/// the picture's size. Also the background picture to put behind it, if one was drawn.
pub fn scene_of(spec: &Spec, library: &mut AssetLibrary, k: u64) -> Result<(SceneDoc, Option<PathBuf>), GenerateError> {
    let mut rng = Rng::of_picture(spec.seed, k);
    let (least, most) = spec.per_picture;
    let n = least + rng.below(most - least + 1);
    let places = spots(&mut rng, n, spec.area, spec.spacing);
    let mut characters = Vec::with_capacity(n);
    for (i, at) in places.into_iter().enumerate() {
        let who = &spec.characters[rng.weighted(spec.characters.iter().map(|c| c.weight))].what;
        let yaw = spec.facing.draw(&mut rng).to_radians();
        let time = spec.time.draw(&mut rng).max(0.0);
        let mut c = character(who, library, &mut rng, time, format!("person {}", i + 1))?;
        c.id = Some(marionette_formats::scene::CharacterId(i as u64 + 1));
        c.placement = PlacementDoc::new(at, yaw, 1.0);
        if let Some(poses) = &spec.poses {
            let (body, hands) = poses.draw(&mut rng);
            c = posed_by_presets(library, c, body, hands).map_err(|message| GenerateError::Picture { k, message })?;
        }
        if let Some((r, g, b)) = &spec.tint {
            c.view.tint = [r, g, b].map(|d| d.draw(&mut rng).clamp(0.0, 1.0));
        }
        stand_at(library, &mut c, at)?;
        characters.push(c);
    }
    let centre = characters.iter().map(|c| c.placement.translation * Vec3::new(1.0, 0.0, 1.0)).sum::<Vec3>()
        / characters.len().max(1) as f32;
    let camera = &spec.camera;
    let (distance, height) = (camera.distance.draw(&mut rng).max(0.01), camera.height.draw(&mut rng));
    let focus = centre + Vec3::Y * camera.look_at;
    let pitch = -((height - focus.y) / distance).clamp(-0.99, 0.99).asin();
    let camera_doc = CameraDoc {
        focus,
        yaw: camera.yaw.draw(&mut rng).to_radians(),
        pitch,
        distance,
        fov: camera.fov.draw(&mut rng).clamp(1.0, 179.0),
        ortho: None,
    };
    let preset =
        preset_named(&spec.lights.presets[rng.below(spec.lights.presets.len())]).unwrap_or(LightPreset::Default);
    let mut stage = preset.lighting(&marionette_formats::scene::StageDoc::default());
    stage.soft_shadows = spec.lights.soft_shadows;
    if let Some(d) = spec.lights.sun_azimuth {
        stage.sun.azimuth = d.draw(&mut rng);
    }
    if let Some(d) = spec.lights.sun_elevation {
        stage.sun.elevation = d.draw(&mut rng).clamp(-90.0, 90.0);
    }
    let mut backdrop = None;
    if !spec.backgrounds.is_empty() {
        stage.background = match &spec.backgrounds[rng.weighted(spec.backgrounds.iter().map(|b| b.weight))].what {
            Background::Sky => BackgroundDoc::Sky,
            Background::Color(r, g, b) => BackgroundDoc::Color([r, g, b].map(|d| d.draw(&mut rng).clamp(0.0, 1.0))),
            Background::Gradient { top, bottom } => BackgroundDoc::Gradient { top: *top, bottom: *bottom },
            Background::Images(folder) => {
                let files = image_files(folder);
                backdrop = Some(files[rng.below(files.len())].clone());
                BackgroundDoc::Transparent
            }
        };
    }
    if let Some(props) = &spec.props {
        let people: Vec<Vec3> = characters.iter().map(|c| c.placement.translation).collect();
        let eye = camera_doc.eye();
        characters.extend(props.draw(&mut rng, library, eye, &people)?);
    }
    let scene = SceneDoc { characters, camera: Some(camera_doc), stage, shot: spec.shot(), ..SceneDoc::default() };
    scene.validate().map_err(|message| GenerateError::Picture { k, message })?;
    Ok((scene, backdrop))
}

/// `n` places in the square of side `area` round the origin, each at least `spacing` from
/// the others: distinct cells of a grid of cells at least `spacing` wide, each place moved
/// within its cell by no more than keeps it `spacing` from its neighbours'.
fn spots(rng: &mut Rng, n: usize, area: f32, spacing: f32) -> Vec<Vec3> {
    let side = grid_side(area, spacing);
    let cell = area / side as f32;
    let mut cells: Vec<usize> = (0..side * side).collect();
    // The first n of a shuffle.
    for i in 0..n.min(cells.len()) {
        let j = i + rng.below(cells.len() - i);
        cells.swap(i, j);
    }
    let play = (cell - spacing).max(0.0) / 2.0;
    cells[..n.min(cells.len())]
        .iter()
        .map(|&c| {
            let (row, col) = ((c / side) as f32, (c % side) as f32);
            let centre = |i: f32| -area / 2.0 + (i + 0.5) * cell;
            let jitter = |rng: &mut Rng| (rng.unit() * 2.0 - 1.0) * play;
            Vec3::new(centre(col) + jitter(rng), 0.0, centre(row) + jitter(rng))
        })
        .collect()
}

/// A character of kind `who`, at `time` seconds into its clip.
fn character(
    who: &Who,
    library: &mut AssetLibrary,
    rng: &mut Rng,
    time: f32,
    name: String,
) -> Result<CharacterDoc, GenerateError> {
    Ok(match who {
        Who::Puppet => {
            let mut c = CharacterDoc::new(SourceDoc::Embedded("puppet".into()), name);
            let mut turn = |scale: f32| (rng.unit() * 2.0 - 1.0) * scale;
            c.pose = [
                ("head", JointRotation::euler_xyz(turn(0.2), turn(0.5), 0.0)),
                ("l_shoulder", JointRotation::euler_xyz(0.0, turn(0.5), turn(0.9) - 0.5)),
                ("r_shoulder", JointRotation::euler_xyz(0.0, turn(0.5), turn(0.9) + 0.5)),
                ("l_elbow", JointRotation::euler_xyz(0.0, -0.8 * turn(1.0).abs(), 0.0)),
                ("r_elbow", JointRotation::euler_xyz(0.0, 0.0, -0.8 * turn(1.0).abs())),
                ("l_hip", JointRotation::euler_xyz(turn(0.4), 0.0, 0.05)),
                ("r_hip", JointRotation::euler_xyz(turn(0.4), 0.0, -0.05)),
                ("l_knee", JointRotation::euler_xyz(0.6 * turn(1.0).abs(), 0.0, 0.0)),
            ]
            .into_iter()
            .map(|(joint, rotation)| (joint.to_string(), rotation))
            .collect();
            c.view.tint = [0.45 + 0.4 * rng.unit(), 0.45 + 0.4 * rng.unit(), 0.45 + 0.4 * rng.unit()];
            c
        }
        Who::File { path, anim, motions } => {
            let source = SourceDoc::File(path.clone());
            let asset = library.load(&source)?;
            let mut c = CharacterDoc { name, ..library.new_character_doc(source.clone(), &asset) };
            if let Some(file) = anim {
                c.anim = Some(marionette_formats::scene::AnimDoc::of(file.clone()));
            }
            if let Some(folder) = motions {
                use marionette_formats::scene::{AnimDoc, MotionSourceDoc, RetargetDoc};
                let files = clip_files(folder);
                let from = MotionSourceDoc::File { path: files[rng.below(files.len())].clone(), clip: None };
                c.anim = Some(AnimDoc { retarget: Some(RetargetDoc::of(from)), ..AnimDoc::default() });
                c.playback = None;
            }
            if let Some(anim) = c.anim.as_mut() {
                (anim.time, anim.playing) = (time, false);
            } else if let Some(part) = library.part_of_source(&source)
                && !part.clips.is_empty()
            {
                let clip = &part.clips[rng.below(part.clips.len())];
                c.playback = Some(PlaybackDoc { clip: Some(clip.name.clone()), time, ..PlaybackDoc::default() });
            }
            c
        }
        Who::Smpl { folder, betas } => {
            let clips = marionette_formats::smpl::clip_paths(folder);
            let clip = (!clips.is_empty())
                .then(|| clips[rng.below(clips.len())].file_name().map(|n| n.to_string_lossy().into_owned()))
                .flatten();
            let smpl = SmplDoc { betas: (0..10).map(|_| betas.draw(rng)).collect(), time, clip, ..SmplDoc::default() };
            CharacterDoc { smpl: Some(smpl), ..CharacterDoc::new(SourceDoc::File(folder.clone()), name) }
        }
    })
}

/// `c` in the body pose `body` with the hands `hands`, through the options every command
/// poses with (over its pose at its clip's time; the clip then stops).
fn posed_by_presets(
    library: &mut AssetLibrary,
    c: CharacterDoc,
    body: crate::posing::BodyPoseSpec,
    hands: Vec<crate::posing::HandSpec>,
) -> Result<CharacterDoc, String> {
    let mut alone = SceneDoc { characters: vec![c], ..SceneDoc::default() };
    let specs = crate::options::PoseSpecs { preset: Some(body), hands, ..Default::default() };
    let options = crate::options::PoseOptions { specs, ..Default::default() };
    crate::options::apply_options(&mut alone, &options, library).map_err(|e| e.to_string())?;
    Ok(alone.characters.remove(0))
}

/// Moves `c` so that its skin, posed, is centred over `spot` (the middle of its box seen
/// from above: a clip that has carried the body away from its origin is brought back) and
/// its lowest point touches the floor.
fn stand_at(library: &mut AssetLibrary, c: &mut CharacterDoc, spot: Vec3) -> Result<(), GenerateError> {
    let alone = SceneDoc { characters: vec![c.clone()], ..SceneDoc::default() };
    let (positions, _) = super::export::scene_mesh_from(library, &alone)?;
    let (lo, hi) = super::layout::union(positions.iter().map(|&p| (p, p)));
    if lo.is_finite() && hi.is_finite() {
        let middle = (lo + hi) / 2.0;
        c.placement.translation += Vec3::new(spot.x - middle.x, -lo.y, spot.z - middle.z);
    }
    Ok(())
}

/// Which pictures a run renders: those whose number is `index` modulo `count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// `I/N` (I from 0).
    pub fn parse(text: &str) -> Result<Shard, GenerateError> {
        let bad = || GenerateError::Shard(text.to_owned());
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count) = (i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// The shard asked for: `--shard`, else a Slurm job array's task
    /// (`SLURM_ARRAY_TASK_ID` of `SLURM_ARRAY_TASK_COUNT`, ids counted from
    /// `SLURM_ARRAY_TASK_MIN`, 0 where unset), else a Kubernetes Indexed Job's
    /// (`JOB_COMPLETION_INDEX` of `--shards`), else the whole set.
    pub fn from_environment(
        flag: Option<&str>,
        shards: Option<usize>,
        env: impl Fn(&str) -> Option<String>,
    ) -> Result<Shard, GenerateError> {
        if let Some(text) = flag {
            return Shard::parse(text);
        }
        let number = |name: &'static str| -> Result<Option<usize>, GenerateError> {
            env(name)
                .map(|v| v.trim().parse::<usize>().map_err(|_| GenerateError::Variable { name, value: v.clone() }))
                .transpose()
        };
        if let Some(id) = number("SLURM_ARRAY_TASK_ID")? {
            let count = number("SLURM_ARRAY_TASK_COUNT")?.ok_or(GenerateError::NoSlurmCount)?;
            let first = number("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            return Shard::parse(&format!("{}/{count}", id.wrapping_sub(first)))
                .map_err(|_| GenerateError::SlurmTask { id, first, count });
        }
        if let Some(index) = number("JOB_COMPLETION_INDEX")? {
            let count = shards.ok_or(GenerateError::NoShards)?;
            return Shard::parse(&format!("{index}/{count}"))
                .map_err(|_| GenerateError::CompletionIndex { index, count });
        }
        Ok(Shard::WHOLE)
    }

    /// This shard's pictures of `count`.
    pub fn pictures(&self, count: usize) -> impl Iterator<Item = usize> + use<> {
        (self.index..count).step_by(self.count)
    }

    /// Its manifest's file name.
    pub fn manifest_name(&self) -> String {
        format!("manifest-{:04}-of-{:04}.jsonl", self.index, self.count)
    }
}

/// A picture's file stem in the data set's folder.
pub fn picture_stem(k: usize) -> String {
    format!("{k:06}")
}

/// A written picture's line in its shard's manifest.
#[derive(Debug, Clone, PartialEq, serde::Serialize, Deserialize)]
pub struct ManifestLine {
    pub picture: usize,
    /// The scene file that made it (open it with `marionette edit`).
    pub scene: String,
    /// Each file written for it, with its SHA-256.
    pub files: Vec<(String, String)>,
}

/// The pictures a data set's folder holds whole: listed in any manifest there, each of
/// their files present with the digest listed.
pub fn finished_pictures(dir: &Path) -> BTreeSet<usize> {
    manifest_lines(dir)
        .into_iter()
        .filter(|line| line.files.iter().all(|(name, digest)| sha256_of(&dir.join(name)).is_ok_and(|d| &d == digest)))
        .map(|line| line.picture)
        .collect()
}

/// Every line of every manifest in `dir` (a torn last line is left out).
pub fn manifest_lines(dir: &Path) -> Vec<ManifestLine> {
    let manifests = files_named(dir, |n| n.starts_with("manifest-") && n.ends_with(".jsonl"));
    manifests
        .iter()
        .filter_map(|m| std::fs::read_to_string(m).ok())
        .flat_map(|text| text.lines().filter_map(|l| serde_json::from_str(l).ok()).collect::<Vec<ManifestLine>>())
        .collect()
}

/// The manifest line of picture `k`: the files in `dir` named `STEM.*` (its picture, data and
/// scene), with their digests.
pub fn manifest_line(dir: &Path, k: usize) -> Result<ManifestLine, GenerateError> {
    let stem = picture_stem(k);
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map_err(|source| GenerateError::Io { path: dir.to_owned(), source })?
        .flatten()
        .filter_map(|e| e.file_name().to_str().map(str::to_string))
        .filter(|n| n.strip_prefix(&stem).is_some_and(|rest| rest.starts_with('.')) && !n.contains(".tmp"))
        .collect();
    names.sort();
    let files = names
        .into_iter()
        .map(|n| {
            let path = dir.join(&n);
            sha256_of(&path).map(|digest| (n, digest)).map_err(|source| GenerateError::Io { path, source })
        })
        .collect::<Result<Vec<_>, GenerateError>>()?;
    Ok(ManifestLine { picture: k, scene: format!("{stem}.scene.ron"), files })
}

/// Appends a line to a manifest, whole (one write of the line and its newline, synced).
pub fn append_manifest(path: &Path, line: &ManifestLine) -> Result<(), GenerateError> {
    use std::io::Write;
    let json = |source| GenerateError::Json { path: path.to_owned(), source };
    let text = serde_json::to_string(line).map_err(json)? + "\n";
    let io = |source| GenerateError::Io { path: path.to_owned(), source };
    let mut file = std::fs::OpenOptions::new().create(true).append(true).open(path).map_err(io)?;
    file.write_all(text.as_bytes()).and_then(|()| file.sync_data()).map_err(io)
}

/// A file's SHA-256, in hex.
pub fn sha256_of(path: &Path) -> std::io::Result<String> {
    use sha2::Digest;
    let bytes = std::fs::read(path)?;
    Ok(sha2::Sha256::digest(&bytes).iter().map(|b| format!("{b:02x}")).collect())
}

/// Joins the COCO files of every picture the manifests in `dir` list into `dir/coco.json`
/// (images and annotations in picture order, ids as each picture numbered them). Returns
/// the number of pictures joined.
pub fn merge(dir: &Path) -> Result<usize, GenerateError> {
    let mut lines = manifest_lines(dir);
    if lines.is_empty() {
        return Err(GenerateError::NoManifest(dir.to_owned()));
    }
    lines.sort_by_key(|l| l.picture);
    lines.dedup_by_key(|l| l.picture);
    let (mut images, mut annotations) = (Vec::new(), Vec::new());
    for line in &lines {
        let name = format!("{}.json", picture_stem(line.picture));
        let path = dir.join(&name);
        let text = read_set_file(dir, &name)?
            .ok_or_else(|| GenerateError::NoData { path: path.clone(), source: std::io::ErrorKind::NotFound.into() })?;
        let mut coco: serde_json::Value =
            serde_json::from_slice(&text).map_err(|source| GenerateError::Json { path: path.clone(), source })?;
        images.extend(coco["images"].as_array_mut().map(std::mem::take).unwrap_or_default());
        annotations.extend(coco["annotations"].as_array_mut().map(std::mem::take).unwrap_or_default());
    }
    super::annotate::write::json(&dir.join("coco.json"), &super::annotate::coco::file(images, annotations))?;
    Ok(lines.len())
}

/// The file `name` of a data set's folder: loose there, else a member of one of its
/// WebDataset tars (`set-*.tar`, see [`crate::webdataset`]).
pub fn read_set_file(dir: &Path, name: &str) -> Result<Option<Vec<u8>>, GenerateError> {
    let loose = dir.join(name);
    if loose.is_file() {
        return std::fs::read(&loose).map(Some).map_err(|source| GenerateError::Io { path: loose, source });
    }
    let mut tars: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|source| GenerateError::Io { path: dir.to_owned(), source })?
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with("set-") && n.ends_with(".tar"))
        })
        .collect();
    tars.sort();
    for tar in tars {
        let io = |source| GenerateError::Io { path: tar.clone(), source };
        let mut archive = tar::Archive::new(std::fs::File::open(&tar).map_err(io)?);
        for entry in archive.entries().map_err(io)? {
            let mut entry = entry.map_err(io)?;
            if entry.path().map_err(io)?.to_str() == Some(name) {
                let mut bytes = Vec::new();
                std::io::Read::read_to_end(&mut entry, &mut bytes).map_err(io)?;
                return Ok(Some(bytes));
            }
        }
    }
    Ok(None)
}

/// The COCO ids picture `k` uses: its image's, and its first annotation's.
pub fn coco_ids(k: usize) -> (u64, u64) {
    (k as u64 + 1, (k * MAX_PER_PICTURE) as u64 + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(text: &str) -> Result<Spec, String> {
        parse_spec(text, Path::new("spec.ron")).map_err(|e| e.to_string())
    }

    /// The example parses, and its pictures are the same for the same (seed, k) and differ
    /// between pictures; every character stands on the floor inside the area, `spacing` apart.
    #[test]
    fn pictures_depend_only_on_the_seed_and_their_number() {
        let spec = parse_spec(EXAMPLE, Path::new("example.ron")).unwrap();
        let mut library = AssetLibrary::default();
        let a = scene_of(&spec, &mut library, 5).unwrap();
        let b = scene_of(&spec, &mut AssetLibrary::default(), 5).unwrap();
        assert_eq!(a, b);
        assert_ne!(a.0, scene_of(&spec, &mut library, 6).unwrap().0);
        for k in 0..40 {
            let (scene, _) = scene_of(&spec, &mut library, k).unwrap();
            let n = scene.characters.len();
            assert!((spec.per_picture.0..=spec.per_picture.1).contains(&n));
            // Where each stands: the middle of its posed skin seen from above.
            let spots: Vec<Vec3> = scene
                .characters
                .iter()
                .map(|c| {
                    let alone = SceneDoc { characters: vec![c.clone()], ..SceneDoc::default() };
                    let (positions, _) = crate::export::scene_mesh_from(&mut library, &alone).unwrap();
                    let (lo, hi) = crate::layout::union(positions.iter().map(|&p| (p, p)));
                    assert!(lo.y.abs() < 1e-4, "picture {k}: lowest point {}", lo.y);
                    (lo + hi) / 2.0 * Vec3::new(1.0, 0.0, 1.0)
                })
                .collect();
            for (i, s) in spots.iter().enumerate() {
                assert!(s.x.abs() <= spec.area / 2.0 + 1e-4 && s.z.abs() <= spec.area / 2.0 + 1e-4, "{s}");
                for t in &spots[i + 1..] {
                    assert!(s.distance(*t) >= spec.spacing - 1e-4, "picture {k}: {s} and {t}");
                }
            }
        }
    }

    /// Shards split the pictures by their number; the engines' variables name them.
    #[test]
    fn shards_come_from_the_flag_slurm_or_kubernetes() {
        let none = |_: &str| None;
        assert_eq!(Shard::from_environment(Some("1/4"), None, none).unwrap(), Shard { index: 1, count: 4 });
        assert_eq!(Shard::from_environment(None, None, none).unwrap(), Shard::WHOLE);
        let slurm = |k: &str| match k {
            "SLURM_ARRAY_TASK_ID" => Some("3".to_string()),
            "SLURM_ARRAY_TASK_COUNT" => Some("4".to_string()),
            _ => None,
        };
        assert_eq!(Shard::from_environment(None, None, slurm).unwrap(), Shard { index: 3, count: 4 });
        let kube = |k: &str| (k == "JOB_COMPLETION_INDEX").then(|| "2".to_string());
        assert_eq!(Shard::from_environment(None, Some(4), kube).unwrap(), Shard { index: 2, count: 4 });
        assert!(Shard::from_environment(None, None, kube).unwrap_err().to_string().contains("--shards"));
        assert!(Shard::from_environment(None, Some(2), kube).unwrap_err().to_string().contains("not below"));
        for bad in ["4/4", "1", "a/2", "0/0"] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        let all: BTreeSet<usize> = (0..4).flat_map(|i| Shard { index: i, count: 4 }.pictures(10)).collect();
        assert_eq!(all, (0..10).collect());
    }

    /// Spec errors are refused with their place.
    #[test]
    fn bad_specs_are_refused_naming_the_field() {
        let base = EXAMPLE.to_string();
        let cases = [
            ("path: \"nowhere/x.glb\"", "Puppet", "characters[", "no such file"),
            ("Uniform(4.0, 6.0)", "Uniform(6.0, 4.0)", "camera.distance", "empty distribution"),
            ("per_picture: (1, 3)", "per_picture: (1, 40)", "spacing", "do not fit"),
            ("width: 320", "width: 0", "width", ""),
            ("\"studio\"", "\"disco\"", "lights.presets", "disco"),
        ];
        for (from, to, field, words) in cases {
            let text = if from.starts_with("path") {
                base.replacen("what: Puppet", "what: File(path: \"nowhere/x.glb\")", 1)
            } else {
                assert!(base.contains(from), "{from}");
                base.replacen(from, to, 1)
            };
            let e = spec(&text).unwrap_err();
            assert!(e.contains(field) && e.contains(words), "{from} → {to}: {e}");
        }
        let e = spec(&base.replacen("seed: 1", "sead: 1", 1)).unwrap_err();
        assert!(e.starts_with("spec.ron:"), "syntax errors carry their line: {e}");
        let empty = base.replacen("presets: [\"default\", \"studio\", \"overcast\", \"dusk\"]", "presets: []", 1);
        assert!(spec(&empty).unwrap_err().to_string().contains("lights.presets: an empty distribution"));
    }
}

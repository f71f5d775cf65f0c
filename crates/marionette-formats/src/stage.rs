//! The stage and the shot of a scene file: the camera and its lens, named views, the floor,
//! the lights (sun, ambient fill, up to three lamps) with presets, the background, and the
//! picture `render` takes. Plain serde documents, no Bevy: the editor holds these very types.

use serde::{Deserialize, Serialize};

use super::checks::{finite, positive};

/// The orbit camera: an orbit around `focus` (world space) at `distance`, with `yaw` and
/// `pitch` in radians; its lens: a vertical field of view, or an orthographic view of a
/// fixed height (the editor holds this very type on its camera).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CameraDoc {
    pub focus: glam::Vec3,
    pub yaw: f32,
    pub pitch: f32,
    pub distance: f32,
    /// Vertical field of view, degrees (files without it: 45).
    #[serde(default = "default_fov", skip_serializing_if = "is_default_fov")]
    pub fov: f32,
    /// Orthographic: the height of the view in metres, whatever the distance (none:
    /// perspective).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ortho: Option<f32>,
}

fn default_fov() -> f32 {
    45.0
}

fn is_default_fov(fov: &f32) -> bool {
    *fov == default_fov()
}

/// The height of the 35 mm film frame a focal length is given for (mm).
const FILM_HEIGHT_MM: f32 = 24.0;

impl Default for CameraDoc {
    fn default() -> Self {
        Self {
            focus: glam::Vec3::new(0.0, 0.5, 0.0),
            yaw: 0.0,
            pitch: -0.25,
            distance: 3.0,
            fov: default_fov(),
            ortho: None,
        }
    }
}

impl CameraDoc {
    /// The camera's orientation: yaw about the vertical, then pitch (it looks along -z).
    pub fn rotation(&self) -> glam::Quat {
        glam::Quat::from_euler(glam::EulerRot::YXZ, self.yaw, self.pitch, 0.0)
    }

    /// Where the camera stands.
    pub fn eye(&self) -> glam::Vec3 {
        self.focus + self.rotation() * glam::Vec3::new(0.0, 0.0, self.distance)
    }

    /// The focal length (mm) of the field of view on 35 mm film (24 mm high).
    pub fn focal_length_mm(&self) -> f32 {
        FILM_HEIGHT_MM / 2.0 / (self.fov.to_radians() / 2.0).tan()
    }

    /// The field of view (degrees) of a focal length on 35 mm film.
    pub fn fov_of_focal_length(mm: f32) -> f32 {
        2.0 * (FILM_HEIGHT_MM / 2.0 / mm).atan().to_degrees()
    }

    /// The height of the view at the focus: what the orthographic lens shows, or what the
    /// perspective one sees at the focus's distance.
    pub fn view_height(&self) -> f32 {
        self.ortho.unwrap_or_else(|| 2.0 * self.distance * (self.fov.to_radians() / 2.0).tan())
    }

    /// Switched between perspective and orthographic, showing the focus at the same size.
    pub fn toggled_ortho(self) -> Self {
        match self.ortho {
            Some(_) => Self { ortho: None, ..self },
            None => Self { ortho: Some(self.view_height()), ..self },
        }
    }

    /// Looking from `view`, same focus, distance and lens.
    pub fn looking_from(self, view: ViewName) -> Self {
        let (yaw, pitch) = view.yaw_pitch();
        Self { yaw, pitch, ..self }
    }

    /// Checks every number (the error names `at`'s field).
    pub fn validate(&self, at: &str) -> Result<(), String> {
        finite(&format!("{at}.focus"), &self.focus.to_array())?;
        finite(&format!("{at}.yaw"), &[self.yaw, self.pitch])?;
        positive(&format!("{at}.distance"), self.distance)?;
        if !(1.0..=170.0).contains(&self.fov) {
            return Err(format!("{at}.fov: expected a field of view of 1 to 170 degrees, found {}", self.fov));
        }
        if let Some(height) = self.ortho {
            positive(&format!("{at}.ortho"), height)?;
        }
        Ok(())
    }
}

/// The views on keys (the numpad's, as in Blender) and `render --view`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewName {
    Front,
    Back,
    Right,
    Left,
    Top,
    Bottom,
    ThreeQuarter,
}

impl ViewName {
    pub const ALL: [ViewName; 7] = [
        ViewName::Front,
        ViewName::Back,
        ViewName::Right,
        ViewName::Left,
        ViewName::Top,
        ViewName::Bottom,
        ViewName::ThreeQuarter,
    ];

    /// The camera's yaw and pitch (radians) for this view: the front looks along -z (at a
    /// character facing +z), the right side from +x, the top straight down.
    pub fn yaw_pitch(self) -> (f32, f32) {
        use std::f32::consts::{FRAC_PI_2, PI};
        match self {
            ViewName::Front => (0.0, 0.0),
            ViewName::Back => (PI, 0.0),
            ViewName::Right => (FRAC_PI_2, 0.0),
            ViewName::Left => (-FRAC_PI_2, 0.0),
            ViewName::Top => (0.0, -FRAC_PI_2),
            ViewName::Bottom => (0.0, FRAC_PI_2),
            ViewName::ThreeQuarter => (0.6, -0.3),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ViewName::Front => "front",
            ViewName::Back => "back",
            ViewName::Right => "right",
            ViewName::Left => "left",
            ViewName::Top => "top",
            ViewName::Bottom => "bottom",
            ViewName::ThreeQuarter => "three-quarter",
        }
    }
}

impl std::str::FromStr for ViewName {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let wanted = if s == "side" { "right" } else { s };
        Self::ALL.into_iter().find(|v| v.name() == wanted).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|v| v.name()).collect();
            format!("expected a view ({} or side), found `{s}`", names.join(", "))
        })
    }
}

/// The sun: a light from far away, from `azimuth` degrees (0: from the front, +z; 90: from
/// the right, +x) and `elevation` degrees above the horizon.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SunDoc {
    pub azimuth: f32,
    pub elevation: f32,
    /// Lux.
    pub illuminance: f32,
    /// Linear RGB.
    pub color: [f32; 3],
}

impl Default for SunDoc {
    fn default() -> Self {
        Self { azimuth: 34.0, elevation: 48.0, illuminance: 4000.0, color: [1.0; 3] }
    }
}

impl SunDoc {
    /// The unit direction towards the sun.
    pub fn toward(&self) -> glam::Vec3 {
        let (az, el) = (self.azimuth.to_radians(), self.elevation.to_radians());
        glam::Vec3::new(az.sin() * el.cos(), el.sin(), az.cos() * el.cos())
    }
}

/// Light from everywhere (the sky's fill).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AmbientDoc {
    pub color: [f32; 3],
    /// Bevy's ambient brightness (candela per square metre).
    pub brightness: f32,
}

impl Default for AmbientDoc {
    fn default() -> Self {
        Self { color: [1.0; 3], brightness: 350.0 }
    }
}

/// A point light, or a spot light where it has a `spot`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LampDoc {
    pub position: glam::Vec3,
    /// Lumens.
    pub intensity: f32,
    pub color: [f32; 3],
    pub shadows: bool,
    pub spot: Option<SpotDoc>,
}

impl Default for LampDoc {
    fn default() -> Self {
        Self {
            position: glam::Vec3::new(1.5, 2.0, 1.5),
            intensity: 200_000.0,
            color: [1.0; 3],
            shadows: false,
            spot: None,
        }
    }
}

/// A spot light's aim and cone.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpotDoc {
    /// The point it shines at.
    pub aim: glam::Vec3,
    /// The cone's half angle, degrees.
    pub angle: f32,
}

/// The most lamps a scene has besides the sun.
pub const MAX_LAMPS: usize = 3;

/// Behind everything: the sky colour, a colour, a vertical gradient, nothing (a PNG
/// with alpha), or a reference picture.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub enum BackgroundDoc {
    #[default]
    Sky,
    Color([f32; 3]),
    Gradient {
        top: [f32; 3],
        bottom: [f32; 3],
    },
    Transparent,
    /// A picture file (PNG, JPEG), scaled to fit inside the frame (the sky around it) or,
    /// with `fill`, to cover it (its middle kept).
    Image {
        path: std::path::PathBuf,
        #[serde(default)]
        fill: bool,
    },
}

/// The sky's colour (sRGB).
pub const SKY: [f32; 3] = [0.62, 0.7, 0.78];

impl BackgroundDoc {
    /// The colour (sRGB) at height `v` of the picture (0 top, 1 bottom) and its alpha.
    pub fn at(&self, v: f32) -> ([f32; 3], f32) {
        match *self {
            BackgroundDoc::Sky => (SKY, 1.0),
            BackgroundDoc::Color(c) => (c, 1.0),
            BackgroundDoc::Gradient { top, bottom } => {
                (std::array::from_fn(|k| top[k] + (bottom[k] - top[k]) * v), 1.0)
            }
            BackgroundDoc::Transparent => ([0.0; 3], 0.0),
            // Around a picture that fits inside the frame.
            BackgroundDoc::Image { .. } => (SKY, 1.0),
        }
    }
}

/// Scene-wide view settings (the editor holds this very type as its stage resource).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct StageDoc {
    /// Draw the floor (and its grid).
    pub floor: bool,
    /// The sun casts shadows.
    pub shadows: bool,
    /// Shadows' edges softened (filtered over many texels of the shadow map); else sharp
    /// (four texels: far cheaper where the renderer runs on the CPU).
    pub soft_shadows: bool,
    /// Draw the world axes.
    pub axes: bool,
    /// Height of the floor plane (world y).
    pub floor_height: f32,
    /// The floor's side, metres (none: it grows with the scene).
    pub floor_size: Option<f32>,
    /// The floor's colour (sRGB).
    pub floor_color: [f32; 3],
    pub sun: SunDoc,
    pub ambient: AmbientDoc,
    /// Lights besides the sun, at most [`MAX_LAMPS`].
    pub lamps: Vec<LampDoc>,
    pub background: BackgroundDoc,
}

impl Default for StageDoc {
    fn default() -> Self {
        Self {
            floor: true,
            shadows: true,
            soft_shadows: true,
            axes: false,
            floor_height: 0.0,
            floor_size: None,
            floor_color: [0.55, 0.57, 0.6],
            sun: SunDoc::default(),
            ambient: AmbientDoc::default(),
            lamps: Vec::new(),
            background: BackgroundDoc::Sky,
        }
    }
}

/// Lightings to start from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LightPreset {
    /// The editor's own: a high sun from the front right, a soft fill.
    Default,
    /// Studio three-point: a key from the front left, a fill from the right, a rim light
    /// from behind.
    Studio,
    /// Overcast: a dim high sun without shadows, a bright fill.
    Overcast,
    /// Dusk: a low orange sun, a blue fill.
    Dusk,
}

impl LightPreset {
    pub const ALL: [LightPreset; 4] =
        [LightPreset::Default, LightPreset::Studio, LightPreset::Overcast, LightPreset::Dusk];

    pub fn name(self) -> &'static str {
        match self {
            LightPreset::Default => "default",
            LightPreset::Studio => "studio three-point",
            LightPreset::Overcast => "overcast",
            LightPreset::Dusk => "dusk",
        }
    }

    /// `stage` lit this way (floor, background and the rest kept).
    pub fn lighting(self, stage: &StageDoc) -> StageDoc {
        let lit = |shadows, sun, ambient, lamps| StageDoc { shadows, sun, ambient, lamps, ..stage.clone() };
        match self {
            LightPreset::Default => lit(true, SunDoc::default(), AmbientDoc::default(), Vec::new()),
            LightPreset::Studio => lit(
                true,
                SunDoc { azimuth: -40.0, elevation: 35.0, illuminance: 5000.0, color: [1.0, 0.97, 0.92] },
                AmbientDoc { color: [1.0; 3], brightness: 120.0 },
                vec![
                    LampDoc { position: glam::Vec3::new(2.5, 1.6, 2.0), intensity: 400_000.0, ..LampDoc::default() },
                    LampDoc {
                        position: glam::Vec3::new(-1.0, 2.8, -2.5),
                        intensity: 1_500_000.0,
                        color: [0.9, 0.95, 1.0],
                        spot: Some(SpotDoc { aim: glam::Vec3::new(0.0, 1.2, 0.0), angle: 35.0 }),
                        ..LampDoc::default()
                    },
                ],
            ),
            LightPreset::Overcast => lit(
                false,
                SunDoc { azimuth: 0.0, elevation: 80.0, illuminance: 1200.0, color: [0.95, 0.97, 1.0] },
                AmbientDoc { color: [0.92, 0.95, 1.0], brightness: 900.0 },
                Vec::new(),
            ),
            LightPreset::Dusk => lit(
                true,
                SunDoc { azimuth: 70.0, elevation: 8.0, illuminance: 3000.0, color: [1.0, 0.55, 0.3] },
                AmbientDoc { color: [0.45, 0.5, 0.8], brightness: 180.0 },
                Vec::new(),
            ),
        }
    }
}

impl StageDoc {
    /// Checks every number (the error names the field: `stage.sun.elevation`).
    pub fn validate(&self) -> Result<(), String> {
        finite("stage.floor_height", &[self.floor_height])?;
        if let Some(size) = self.floor_size {
            positive("stage.floor_size", size)?;
        }
        unit_color("stage.floor_color", self.floor_color)?;
        finite("stage.sun.azimuth", &[self.sun.azimuth])?;
        if !(-90.0..=90.0).contains(&self.sun.elevation) {
            return Err(format!("stage.sun.elevation: expected -90 to 90 degrees, found {}", self.sun.elevation));
        }
        not_negative("stage.sun.illuminance", self.sun.illuminance)?;
        not_negative_color("stage.sun.color", self.sun.color)?;
        not_negative("stage.ambient.brightness", self.ambient.brightness)?;
        not_negative_color("stage.ambient.color", self.ambient.color)?;
        if self.lamps.len() > MAX_LAMPS {
            return Err(format!("stage.lamps: expected at most {MAX_LAMPS} lamps, found {}", self.lamps.len()));
        }
        for (i, lamp) in self.lamps.iter().enumerate() {
            let at = |field: &str| format!("stage.lamps[{i}].{field}");
            finite(&at("position"), &lamp.position.to_array())?;
            not_negative(&at("intensity"), lamp.intensity)?;
            not_negative_color(&at("color"), lamp.color)?;
            if let Some(spot) = lamp.spot {
                finite(&at("spot.aim"), &spot.aim.to_array())?;
                if !(0.5..=89.0).contains(&spot.angle) {
                    return Err(format!("{}: expected 0.5 to 89 degrees, found {}", at("spot.angle"), spot.angle));
                }
            }
        }
        match &self.background {
            BackgroundDoc::Color(c) => unit_color("stage.background", *c),
            BackgroundDoc::Gradient { top, bottom } => {
                unit_color("stage.background.top", *top)?;
                unit_color("stage.background.bottom", *bottom)
            }
            BackgroundDoc::Image { path, .. } if path.as_os_str().is_empty() => {
                Err("stage.background.path: expected a picture file, found none".into())
            }
            BackgroundDoc::Sky | BackgroundDoc::Transparent | BackgroundDoc::Image { .. } => Ok(()),
        }
    }
}

/// The picture `render` takes when no flag says otherwise: its size, samples and how its
/// edges are smoothed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ShotDoc {
    pub width: u32,
    pub height: u32,
    /// Supersampling: each pixel the mean of `samples`² rendered ones (1: none), on top of
    /// `antialias`.
    pub samples: u32,
    pub antialias: Antialias,
}

impl Default for ShotDoc {
    fn default() -> Self {
        Self { width: 1280, height: 720, samples: 1, antialias: Antialias::default() }
    }
}

/// How a picture's edges are smoothed as it is drawn.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Antialias {
    /// Four samples a pixel (multisampling): the smoothest edges.
    #[default]
    Multisample,
    /// One sample a pixel, edges found and blended in the finished picture (FXAA): softer
    /// edges for a fraction of multisampling's cost where the renderer runs on the CPU.
    Fxaa,
    /// One sample a pixel, nothing smoothed.
    Off,
}

impl Antialias {
    pub const ALL: [Antialias; 3] = [Antialias::Multisample, Antialias::Fxaa, Antialias::Off];

    /// Its name on the command line and in the editor.
    pub fn name(self) -> &'static str {
        match self {
            Antialias::Multisample => "multisample",
            Antialias::Fxaa => "fxaa",
            Antialias::Off => "off",
        }
    }
}

impl std::str::FromStr for Antialias {
    type Err = String;

    /// The one [`Antialias::name`] names (any case).
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL.into_iter().find(|a| a.name().eq_ignore_ascii_case(s)).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|a| a.name()).collect();
            format!("expected {}, found `{s}`", names.join(", "))
        })
    }
}

/// The longest side of a picture, rendered samples included (a GPU's usual texture limit).
pub const MAX_PICTURE_SIDE: u32 = 8192;

/// The most samples a side of a pixel takes.
pub const MAX_SAMPLES: u32 = 4;

/// Common picture sizes, by name.
pub const RESOLUTION_PRESETS: [(&str, u32, u32); 10] = [
    ("ControlNet 512×512", 512, 512),
    ("ControlNet 512×768", 512, 768),
    ("ControlNet 768×512", 768, 512),
    ("ControlNet 1024×1024", 1024, 1024),
    ("HD 720p", 1280, 720),
    ("Full HD 1080p", 1920, 1080),
    ("4K UHD", 3840, 2160),
    ("Square 1080", 1080, 1080),
    ("Portrait 1080×1920", 1080, 1920),
    ("A4 at 150 dpi", 1754, 1240),
];

impl ShotDoc {
    /// Checks the size and samples: the rendered picture stays within [`MAX_PICTURE_SIDE`].
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=MAX_SAMPLES).contains(&self.samples) {
            return Err(format!("shot.samples: expected 1 to {MAX_SAMPLES}, found {}", self.samples));
        }
        for (field, side) in [("width", self.width), ("height", self.height)] {
            if side == 0 || side.saturating_mul(self.samples) > MAX_PICTURE_SIDE {
                return Err(format!(
                    "shot.{field}: expected 1 to {} pixels at {} samples, found {side}",
                    MAX_PICTURE_SIDE / self.samples,
                    self.samples
                ));
            }
        }
        Ok(())
    }
}

fn not_negative(at: &str, value: f32) -> Result<(), String> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(format!("{at}: expected a finite number not below 0, found {value}"))
    }
}

fn not_negative_color(at: &str, color: [f32; 3]) -> Result<(), String> {
    color.iter().try_for_each(|&c| not_negative(at, c))
}

fn unit_color(at: &str, color: [f32; 3]) -> Result<(), String> {
    match color.iter().find(|c| !(0.0..=1.0).contains(*c)) {
        Some(c) => Err(format!("{at}: expected colour parts in 0..=1, found {c}")),
        None => Ok(()),
    }
}

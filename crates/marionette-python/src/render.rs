//! `mt.Scene` and `mt.render`: pictures drawn in-process by one renderer kept alive between
//! calls (its first call pays the start, later ones their drawn frames), handed over as
//! arrays of what the files of `render --data` would hold; a data set's pictures
//! (`mt.generate`) are the files `generate` writes, read back.

use std::cell::RefCell;
use std::mem::ManuallyDrop;
use std::path::{Path, PathBuf};

use numpy::IntoPyArray;
use numpy::ndarray::{Array2, Array3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use marionette::document::AssetLibrary;
use marionette::document::annotate::controlnet::ControlNet;
use marionette::document::annotate::controlnet::Maps as ControlNetMaps;
use marionette::document::options::{PoseOptions, apply_options};
use marionette::editor::present::data::Beside;
use marionette::editor::present::render::{Kept, Renderer, ScenePicture};
use marionette::editor::present::view::{FramingView, startup_view};
use marionette::formats::scene::{Antialias, BackgroundDoc, PlacementDoc, SceneDoc, ShotDoc, ViewName};

use super::{Character, Error, SpecError, file_error, options_error};

/// A scene to render: a scene file's, or characters placed.
#[pyclass(module = "marionette", frozen)]
pub struct Scene {
    doc: SceneDoc,
}

#[pymethods]
impl Scene {
    /// The characters as loaded or posed (their betas, their poses), each moved by its
    /// placement's `(x, y, z)` from where it stands (a posed character stands on the floor).
    #[new]
    #[pyo3(signature = (characters, placements=None))]
    fn new(characters: Vec<PyRef<'_, Character>>, placements: Option<Vec<(f32, f32, f32)>>) -> PyResult<Self> {
        let placements = placements.unwrap_or_default();
        if !placements.is_empty() && placements.len() != characters.len() {
            let (want, found) = (characters.len(), placements.len());
            return Err(PyValueError::new_err(format!("placements: expected {want}, found {found}")));
        }
        let mut doc = SceneDoc::default();
        for (k, c) in characters.iter().enumerate() {
            let mut c = c.doc.clone();
            if let Some(&(x, y, z)) = placements.get(k) {
                let translation = c.placement.translation + glam::Vec3::new(x, y, z);
                c.placement = PlacementDoc { translation, ..c.placement };
            }
            doc.characters.push(c);
        }
        Ok(Self { doc })
    }

    /// A scene file (`.ron`), its characters' files found beside it.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let doc = py.detach(|| marionette::document::scenes::read_scene(&path)).map_err(file_error)?;
        Ok(Self { doc })
    }

    fn __repr__(&self) -> String {
        format!("<marionette.Scene of {} characters>", self.doc.characters.len())
    }
}

thread_local! {
    /// The renderer of this thread, kept between calls (its app is not to be moved). Never
    /// dropped as the thread ends: the GPU's own thread-locals are gone by then, and the
    /// process is ending.
    static RENDERER: RefCell<ManuallyDrop<Option<Renderer>>> = const { RefCell::new(ManuallyDrop::new(None)) };
}

/// Runs `draw` with this thread's renderer of pictures of `shot` (made from `library` where
/// there is none of that size; one of another size is dropped first).
fn with_renderer<T>(
    shot: ShotDoc,
    library: AssetLibrary,
    draw: impl FnOnce(&mut Renderer) -> Result<T, String>,
) -> PyResult<T> {
    RENDERER.with_borrow_mut(|renderer| {
        if renderer.as_ref().is_some_and(|r| r.picture() != shot) {
            drop(std::mem::take(&mut **renderer));
        }
        if renderer.is_none() {
            **renderer = Some(Renderer::new(library, shot).map_err(Error::new_err)?);
        }
        draw(renderer.as_mut().expect("made above")).map_err(Error::new_err)
    })
}

/// A render's picture and data, as arrays.
struct Drawn {
    rgb: (Vec<u8>, u32, u32, usize),
    data: Option<Data>,
    controlnet: Option<ControlNetMaps>,
    notes: Vec<String>,
}

struct Data {
    depth: Vec<f32>,
    normal: Vec<f32>,
    mask: Vec<u16>,
    coco: String,
}

impl Drawn {
    /// A picture kept in memory: the picture as its file holds it, the passes and maps as
    /// the files beside it hold them (normals at full precision).
    fn from_kept(kept: Kept, notes: Vec<String>) -> Self {
        use marionette::document::annotate::write::{mask_id, normal_of_map};
        let rgb = pixels(&kept.picture);
        let (data, controlnet) = kept.beside.map_or((None, None), |b| {
            let data = b.coco.map(|coco| Data {
                normal: b.passes.normal.iter().flat_map(|&n| normal_of_map(n).to_array()).collect(),
                mask: b.passes.instance.iter().map(|&i| mask_id(i)).collect(),
                depth: b.passes.depth,
                coco: coco.to_string(),
            });
            (data, b.controlnet)
        });
        Self { rgb, data, controlnet, notes }
    }
}

/// A picture's bytes, width, height and channels (4 where it has alpha, else 3).
fn pixels(picture: &image::DynamicImage) -> (Vec<u8>, u32, u32, usize) {
    let (w, h) = (picture.width(), picture.height());
    match picture.color().has_alpha() {
        true => (picture.to_rgba8().into_raw(), w, h, 4),
        false => (picture.to_rgb8().into_raw(), w, h, 3),
    }
}

/// The scene drawn as `render SCENE --width W --height H [--samples N] [--antialias A]
/// [--data] [--controlnet] [--view V] [--transparent] --out shot.png` draws it: a dict of
/// `rgb` (uint8 (H, W, 3), or (H, W, 4) with `transparent`), and with `data` `depth`
/// (float32 (H, W) metres along the view axis, inf where nothing), `normal` (float32
/// (H, W, 3), the camera frame `--data` documents),
/// `mask` (uint16 (H, W) instance ids), `coco` (the COCO dict) and `camera` (`K`,
/// `world_to_camera`: float64); with `controlnet` `controlnet`, the maps as their files hold
/// them (`openpose`, `depth`, `normal`: uint8 arrays; `openpose_json`: a dict); and `notes`.
/// Nothing is written to disk.
#[pyfunction]
#[pyo3(signature = (scene, *, width=640, height=480, samples=1, antialias="multisample", data=false, controlnet=false, view=None, transparent=false))]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    scene: &Scene,
    width: u32,
    height: u32,
    samples: u32,
    antialias: &str,
    data: bool,
    controlnet: bool,
    view: Option<String>,
    transparent: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let view: Option<ViewName> = view.map(|v| v.parse().map_err(PyValueError::new_err)).transpose()?;
    let antialias: Antialias = antialias.parse().map_err(|e| PyValueError::new_err(format!("antialias: {e}")))?;
    let shot = ShotDoc { width, height, samples, antialias };
    shot.validate().map_err(|e| PyValueError::new_err(e.to_string()))?;
    let mut doc = scene.doc.clone();
    let drawn = py.detach(|| -> PyResult<Drawn> {
        let mut library = AssetLibrary::default();
        // A still, as the command line draws one: every clip paused where it is.
        let options = PoseOptions { still: true, ..PoseOptions::default() };
        let mut notes = apply_options(&mut doc, &options, &mut library).map_err(options_error)?;
        if transparent {
            doc.stage.background = BackgroundDoc::Transparent;
            doc.stage.floor = false;
        }
        let framing = startup_view(&mut doc, view, false).unwrap_or(FramingView::default().0);
        let picture = ScenePicture { scene: doc, out: PathBuf::from("shot.png"), ids: (1, 1), backdrop: None };
        let beside = Beside { data, controlnet: controlnet.then_some(ControlNet { canny: None }) };
        let (said, mut kept) = with_renderer(shot, library, |r| r.draw(vec![picture], framing, beside))?;
        notes.extend(said);
        let kept = kept.pop().ok_or_else(|| Error::new_err("the picture was not drawn"))?;
        Ok(Drawn::from_kept(kept, notes))
    })?;
    drawn_dict(py, drawn)
}

/// A render read back as the dict [`render`] gives.
fn drawn_dict(py: Python<'_>, drawn: Drawn) -> PyResult<Bound<'_, PyDict>> {
    let out = PyDict::new(py);
    let (rgba, w, h, channels) = drawn.rgb;
    let (w, h) = (w as usize, h as usize);
    let rgb = Array3::from_shape_vec((h, w, channels), rgba).expect("a picture's pixels");
    out.set_item("rgb", rgb.into_pyarray(py))?;
    if let Some(d) = drawn.data {
        out.set_item("depth", Array2::from_shape_vec((h, w), d.depth).expect("a pass").into_pyarray(py))?;
        out.set_item("normal", Array3::from_shape_vec((h, w, 3), d.normal).expect("a pass").into_pyarray(py))?;
        out.set_item("mask", Array2::from_shape_vec((h, w), d.mask).expect("a pass").into_pyarray(py))?;
        let coco = py.import("json")?.call_method1("loads", (d.coco,))?;
        let numpy = py.import("numpy")?;
        let camera = PyDict::new(py);
        for key in ["K", "world_to_camera"] {
            let rows = coco.get_item("camera")?.get_item(key)?;
            camera.set_item(key, numpy.call_method1("array", (rows, "float64"))?)?;
        }
        for key in ["width", "height"] {
            camera.set_item(key, coco.get_item("camera")?.get_item(key)?)?;
        }
        out.set_item("coco", coco)?;
        out.set_item("camera", camera)?;
    }
    if let Some(maps) = drawn.controlnet {
        let image = |bytes: Vec<u8>, channels: usize| Array3::from_shape_vec((h, w, channels), bytes).expect("a map");
        let controlnet = PyDict::new(py);
        controlnet.set_item("openpose", image(maps.openpose.into_raw(), 3).into_pyarray(py))?;
        controlnet
            .set_item("openpose_json", py.import("json")?.call_method1("loads", (maps.openpose_json.to_string(),))?)?;
        let depth = Array2::from_shape_vec((h, w), maps.depth.into_raw()).expect("a map");
        controlnet.set_item("depth", depth.into_pyarray(py))?;
        controlnet.set_item("normal", image(maps.normal.into_raw(), 3).into_pyarray(py))?;
        out.set_item("controlnet", controlnet)?;
    }
    out.set_item("notes", drawn.notes)?;
    Ok(out)
}

/// A spec read as `generate` reads it: the file's errors as `FileError`, the spec's as
/// `SpecError`; `count` in place of its count.
fn read_spec(path: &Path, count: Option<usize>) -> PyResult<marionette::document::generate::Spec> {
    use marionette::formats::error::{open, read_text};
    let text = open(path).and_then(|f| read_text(f, path)).map_err(file_error)?;
    let mut spec =
        marionette::document::generate::parse_spec(&text, path).map_err(|e| SpecError::new_err(e.to_string()))?;
    if let Some(count) = count {
        spec.count = count;
        spec.check().map_err(|e| SpecError::new_err(format!("count: {}", e.expected)))?;
    }
    Ok(spec)
}

/// How many pictures the spec at `spec` makes (`count` in place of its own).
#[pyfunction]
#[pyo3(signature = (spec, count=None))]
pub fn spec_count(spec: PathBuf, count: Option<usize>) -> PyResult<usize> {
    Ok(read_spec(&spec, count)?.count)
}

/// Draws the pictures of the spec at `spec` (the shard `shard`, `I/N`, of them; `count` and
/// `seed` in place of the spec's) into the folder `out` as `generate SPEC --out OUT` does,
/// with this thread's renderer; returns every picture's key of the shard and whether the
/// pictures carry data.
#[pyfunction]
#[pyo3(signature = (spec, out, shard=None, count=None, seed=None))]
pub fn generate_pictures(
    py: Python<'_>,
    spec: PathBuf,
    out: PathBuf,
    shard: Option<String>,
    count: Option<usize>,
    seed: Option<u64>,
) -> PyResult<(Vec<String>, bool)> {
    use marionette::cli::args::{GenerateArgs, SetFormat};
    use marionette::document::generate::{coco_ids, picture_stem};
    read_spec(&spec, count)?;
    py.detach(|| {
        let args = GenerateArgs {
            spec: Some(spec),
            out: Some(out),
            shard,
            shards: None,
            count,
            seed,
            dry_run: false,
            example: false,
            merge: None,
            format: SetFormat::Folder,
            shard_size: 1000,
            scenes_a_frame: None,
        };
        let mut plan = marionette::cli::generate::plan(&args)
            .map_err(|e| SpecError::new_err(format!("{e:#}")))?
            .ok_or_else(|| Error::new_err("generate: nothing to draw"))?;
        let keys = plan.shard.pictures(plan.spec.count).map(picture_stem).collect();
        let beside = Beside::of_spec(&plan.spec);
        let pictures: Vec<ScenePicture> = std::mem::take(&mut plan.pictures)
            .into_iter()
            .map(|(k, scene, backdrop)| ScenePicture { scene, out: plan.out(k), ids: coco_ids(k), backdrop })
            .collect();
        if !pictures.is_empty() {
            let (shot, library) = (plan.picture(), std::mem::take(&mut plan.library));
            with_renderer(shot, library, |r| r.render(pictures, FramingView::default().0, beside))?;
        }
        Ok((keys, plan.spec.data))
    })
}

/// A picture `generate` or `render` wrote at `path`, and with `data` the passes and COCO
/// file beside it, as the dict [`render`] gives.
#[pyfunction]
pub fn read_picture(py: Python<'_>, path: PathBuf, data: bool) -> PyResult<Bound<'_, PyDict>> {
    let drawn = py.detach(|| read_back(&path, data, Vec::new()))?;
    drawn_dict(py, drawn)
}

/// The picture at `out` and (with `data`) the passes and COCO file beside it.
fn read_back(out: &Path, data: bool, notes: Vec<String>) -> PyResult<Drawn> {
    use marionette::document::annotate::write::beside;
    let failed = |path: &Path, e: &dyn std::fmt::Display| Error::new_err(format!("{}: {e}", path.display()));
    let rgb = pixels(&image::open(out).map_err(|e| failed(out, &e))?);
    if !data {
        return Ok(Drawn { rgb, data: None, controlnet: None, notes });
    }
    let depth_path = beside(out, "depth.exr");
    let depth = exr_depth(&depth_path).map_err(|e| failed(&depth_path, &e))?;
    let normal_path = beside(out, "normal.png");
    let normal = image::open(&normal_path).map_err(|e| failed(&normal_path, &e))?.to_rgb8();
    // As `--data` writes them: n · 0.5 + 0.5 a byte a component, black where nothing.
    let normal = normal
        .pixels()
        .flat_map(|p| match p.0 {
            [0, 0, 0] => [0.0; 3],
            c => c.map(|v| f32::from(v) / 255.0 * 2.0 - 1.0),
        })
        .collect();
    let mask_path = beside(out, "mask.png");
    let mask = image::open(&mask_path).map_err(|e| failed(&mask_path, &e))?.to_luma16().into_raw();
    let coco_path = beside(out, "json");
    let coco = std::fs::read_to_string(&coco_path).map_err(|e| failed(&coco_path, &e))?;
    Ok(Drawn { rgb, data: Some(Data { depth, normal, mask, coco }), controlnet: None, notes })
}

/// The `Z` channel of a depth EXR, row by row.
fn exr_depth(path: &Path) -> Result<Vec<f32>, exr::error::Error> {
    let image = exr::prelude::read_first_flat_layer_from_file(path)?;
    let channel = image.layer_data.channel_data.list.iter().find(|c| c.name == *"Z");
    Ok(channel.map(|c| c.sample_data.values_as_f32().collect()).unwrap_or_default())
}

/// A data set's pictures drawn in memory, a few at a time, by this thread's renderer: the
/// pictures `generate` makes (each scene as its file reads back), none written to disk.
#[pyclass(module = "marionette", unsendable)]
pub struct SetPictures {
    spec: marionette::document::generate::Spec,
    /// The pictures of the shard not drawn yet, in order.
    todo: std::collections::VecDeque<usize>,
    library: AssetLibrary,
}

#[pymethods]
impl SetPictures {
    /// The pictures of the spec at `spec` (the shard `i/n` of them; `count` and `seed` in
    /// place of the spec's).
    #[new]
    #[pyo3(signature = (spec, shard=None, count=None, seed=None))]
    fn new(spec: PathBuf, shard: Option<String>, count: Option<usize>, seed: Option<u64>) -> PyResult<Self> {
        use marionette::document::generate::Shard;
        let mut spec = read_spec(&spec, count)?;
        if let Some(seed) = seed {
            spec.seed = seed;
        }
        let shard = Shard::from_environment(shard.as_deref(), None, |_| None)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(Self { todo: shard.pictures(spec.count).collect(), spec, library: AssetLibrary::default() })
    }

    /// The keys of the pictures not drawn yet ("000042").
    fn keys(&self) -> Vec<String> {
        self.todo.iter().map(|&k| marionette::document::generate::picture_stem(k)).collect()
    }

    /// The next `n` pictures (fewer at the end), as dicts of [`render`]'s with their `key`.
    fn draw<'py>(&mut self, py: Python<'py>, n: usize) -> PyResult<Vec<Bound<'py, PyDict>>> {
        use marionette::document::generate::{coco_ids, picture_stem, scene_of};
        if n == 0 {
            return Err(PyValueError::new_err("batch: expected at least 1 picture, found 0"));
        }
        let ks: Vec<usize> = (0..n).map_while(|_| self.todo.pop_front()).collect();
        let (spec, library) = (&self.spec, &mut self.library);
        let kept = py.detach(|| -> PyResult<Vec<(String, Kept)>> {
            let mut pictures = Vec::new();
            for &k in &ks {
                let (scene, backdrop) =
                    scene_of(spec, library, k as u64).map_err(|e| SpecError::new_err(e.to_string()))?;
                let out = PathBuf::from(format!("{}.png", picture_stem(k)));
                pictures.push(ScenePicture { scene: as_read_back(&scene)?, out, ids: coco_ids(k), backdrop });
            }
            if pictures.is_empty() {
                return Ok(Vec::new());
            }
            let (shot, beside, library) = (spec.shot(), Beside::of_spec(spec), std::mem::take(library));
            let (_, kept) = with_renderer(shot, library, |r| r.draw(pictures, FramingView::default().0, beside))?;
            Ok(ks.iter().map(|&k| picture_stem(k)).zip(kept).collect())
        })?;
        kept.into_iter()
            .map(|(key, kept)| {
                let sample = drawn_dict(py, Drawn::from_kept(kept, Vec::new()))?;
                sample.set_item("key", key)?;
                Ok(sample)
            })
            .collect()
    }
}

/// A scene as its file reads back (what `generate` draws: the file it writes beside the
/// picture, read again).
fn as_read_back(scene: &SceneDoc) -> PyResult<SceneDoc> {
    use marionette::formats::scene::{parse_scene, scene_to_string};
    let text = scene_to_string(scene).map_err(|e| Error::new_err(e.to_string()))?;
    parse_scene(text.as_bytes(), Path::new("scene.ron")).map_err(file_error)
}

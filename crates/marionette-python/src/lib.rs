//! Marionette from Python: `import marionette as mt`. Characters are read, shaped and posed
//! by the same Rust code the binary runs (the Bevy-free layers), in-process: numpy arrays
//! come back (handed over without copying), errors are exceptions with the command line's
//! messages, and the interpreter's lock is released while Rust works.
//!
//! ```python
//! c = mt.load("xbot.glb")
//! p = c.pose(preset="sit-chair", hands={"left": "fist"})
//! p.vertices                # float32 (V, 3), skinned, world metres
//! ```

use std::collections::BTreeMap;
use std::path::PathBuf;

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use marionette_document::AssetLibrary;
use marionette_document::options::{OptionsError, PoseOptions, PoseSpecs, apply_options};
use marionette_formats::FormatError;
use marionette_formats::scene::{CharacterDoc, SceneDoc, SourceDoc};
use marionette_rig::dqs::SkinningMethod;

mod render;

create_exception!(marionette, Error, PyException, "What Marionette could not do, with the command line's message.");
create_exception!(marionette, FileError, Error, "A file that cannot be read: `file:line: …`.");
create_exception!(marionette, SpecError, Error, "A data-set spec that cannot be used: its field's path and why.");
create_exception!(
    marionette,
    PoseError,
    Error,
    "A pose that cannot be made: a joint, preset or clip no character has."
);

/// A file's error as `FileError`.
pub(crate) fn file_error(e: FormatError) -> PyErr {
    FileError::new_err(e.to_string())
}

/// A posing option's error: the file's as `FileError`, the rest as `PoseError`.
pub(crate) fn options_error(e: OptionsError) -> PyErr {
    match e {
        OptionsError::Format(e) => file_error(e),
        other => PoseError::new_err(other.to_string()),
    }
}

/// A character read from a file (the first of the file's characters), or an SMPL folder.
#[pyclass(module = "marionette", unsendable)]
pub(crate) struct Character {
    library: AssetLibrary,
    doc: CharacterDoc,
}

impl Character {
    fn asset(&mut self) -> PyResult<std::sync::Arc<marionette_rig::CharacterAsset>> {
        self.library.shaped(&self.doc).map_err(file_error)
    }
}

/// The pose a character is put in: its skin's vertices and its joints' transforms in the
/// world, and what the command line would say of it.
#[pyclass(module = "marionette", frozen)]
struct Pose {
    #[pyo3(get)]
    vertices: Py<PyArray2<f32>>,
    #[pyo3(get)]
    joint_matrices: Py<PyArray3<f32>>,
    #[pyo3(get)]
    notes: Vec<String>,
}

/// `(V, 3)` float32 from points.
fn points_array(py: Python<'_>, points: &[glam::Vec3]) -> Py<PyArray2<f32>> {
    let flat: Vec<f32> = points.iter().flat_map(|p| p.to_array()).collect();
    let array = Array2::from_shape_vec((points.len(), 3), flat).expect("three numbers a point");
    array.into_pyarray(py).unbind()
}

#[pymethods]
impl Character {
    /// The character's name (its file's stem).
    #[getter]
    fn name(&self) -> String {
        self.doc.name.clone()
    }

    /// Each joint's name, in the skeleton's order.
    #[getter]
    fn joint_names(&mut self) -> PyResult<Vec<String>> {
        Ok(self.asset()?.skeleton.joints().iter().map(|j| j.name.clone()).collect())
    }

    /// Each joint's parent's index, -1 for the root: int32 (J,).
    #[getter]
    fn parents<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<i32>>> {
        let asset = self.asset()?;
        let parents = asset.skeleton.joints().iter().map(|j| j.parent.map_or(-1, |p| p as i32));
        Ok(Array1::from_iter(parents).into_pyarray(py))
    }

    /// The humanoid map: each standard bone (`"LeftUpperArm"`) the rig has, and its joint's
    /// name.
    #[getter]
    fn humanoid(&mut self) -> PyResult<BTreeMap<String, String>> {
        let asset = self.asset()?;
        let map = marionette_document::retarget::humanoid_map(&asset, &self.doc.humanoid);
        Ok(map.iter().map(|(bone, &j)| (format!("{bone:?}"), asset.skeleton.joint(j).name.clone())).collect())
    }

    /// The skin's triangles: uint32 (F, 3).
    #[getter]
    fn faces<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let asset = self.asset()?;
        let flat: Vec<u32> = asset.skin.triangles.iter().flatten().copied().collect();
        let array = Array2::from_shape_vec((asset.skin.triangles.len(), 3), flat).expect("three corners a triangle");
        Ok(array.into_pyarray(py))
    }

    /// The skin's vertices at rest (bind pose, model space): float32 (V, 3).
    #[getter]
    fn rest_vertices(&mut self, py: Python<'_>) -> PyResult<Py<PyArray2<f32>>> {
        let asset = self.asset()?;
        Ok(points_array(py, &asset.skin.bind_positions))
    }

    /// The clips the character's source carries: a glTF or FBX file's animations, an SMPL
    /// folder's clip files.
    #[getter]
    fn clips(&mut self) -> PyResult<Vec<String>> {
        if let (Some(_), SourceDoc::File(dir)) = (&self.doc.smpl, &self.doc.source) {
            let set = self.library.smpl(dir).map_err(file_error)?;
            return Ok(set.clips.iter().map(|(name, _)| name.clone()).collect());
        }
        let part = self.library.part_of_source(&self.doc.source);
        Ok(part.map(|p| p.clips.iter().map(|k| k.name.clone()).collect()).unwrap_or_default())
    }

    /// An SMPL body's shape coefficients.
    #[getter]
    fn betas(&self) -> PyResult<Vec<f32>> {
        Ok(self.smpl_doc()?.betas.clone())
    }

    #[setter]
    fn set_betas(&mut self, betas: Vec<f32>) -> PyResult<()> {
        if let Some(b) = betas.iter().find(|b| !b.is_finite()) {
            return Err(PyValueError::new_err(format!("betas: expected finite numbers, found {b}")));
        }
        let smpl = self.smpl_doc_mut()?;
        if betas.len() != smpl.betas.len() {
            let (want, found) = (smpl.betas.len(), betas.len());
            return Err(PyValueError::new_err(format!("betas: expected {want} numbers, found {found}")));
        }
        smpl.betas = betas;
        Ok(())
    }

    /// The character posed: at `time` seconds of its clip `clip` (a file's animation by
    /// name or index, an SMPL folder's clip), in the built-in body pose `preset` (mirrored
    /// on request), with hand presets (`{"left": "fist"}`), joint rotations (`{"joint":
    /// (rx, ry, rz)}`, radians, x first), two-bone reaches (`{"hand": (target, pole)}`,
    /// pole optional) and look-ats (`{"head": target}`), skinned by `"lbs"` or `"dq"`:
    /// as `export FILE --clip … --time … --preset … --hand … --pose … --two-bone …
    /// --look-at … --skinning …` poses it.
    #[pyo3(signature = (**arguments))]
    fn pose(&mut self, py: Python<'_>, arguments: Option<&Bound<'_, PyDict>>) -> PyResult<Pose> {
        let options = PoseRequest::options(py, arguments)?;
        let (doc, notes) = self.posed_doc(py, &options)?;
        let mut scene = SceneDoc::default();
        scene.characters.push(doc);
        let library = &mut self.library;
        let posed = py.detach(|| marionette_document::export::scene_posed(library, &scene)).map_err(file_error)?;
        let posed = posed.into_iter().next().ok_or_else(|| Error::new_err("the character was not posed"))?;
        let matrices: Vec<f32> = posed.joint_to_world.iter().flat_map(|m| m.transpose().to_cols_array()).collect();
        let joints = posed.joint_to_world.len();
        let joint_matrices = Array3::from_shape_vec((joints, 4, 4), matrices).expect("16 numbers a matrix");
        Ok(Pose {
            vertices: points_array(py, &posed.vertices),
            joint_matrices: joint_matrices.into_pyarray(py).unbind(),
            notes,
        })
    }

    /// A copy of the character that stands in this pose (the arguments of
    /// [`pose`](Self::pose)), for a scene: `mt.Scene([c.posed(preset="wave")])`.
    #[pyo3(signature = (**arguments))]
    fn posed(&mut self, py: Python<'_>, arguments: Option<&Bound<'_, PyDict>>) -> PyResult<Character> {
        let options = PoseRequest::options(py, arguments)?;
        let (doc, _) = self.posed_doc(py, &options)?;
        Ok(Character { library: AssetLibrary::default(), doc })
    }

    fn __repr__(&self) -> String {
        format!("<marionette.Character {:?}>", self.doc.name)
    }
}

impl Character {
    /// Its document with `options` applied as the command line applies them (a still pose
    /// baked in), and what they said.
    fn posed_doc(&mut self, py: Python<'_>, options: &PoseOptions) -> PyResult<(CharacterDoc, Vec<String>)> {
        let mut doc = self.doc.clone();
        let mut options = options.clone();
        // An SMPL body plays its folder's clip (named whole, or by its name's end: `7516`).
        if let (Some(smpl), SourceDoc::File(dir), Some(wanted)) = (&mut doc.smpl, &self.doc.source, &options.clip) {
            let set = self.library.smpl(dir).map_err(file_error)?;
            let names: Vec<&str> = set.clips.iter().map(|(n, _)| n.as_str()).collect();
            let stem = |n: &str| n.strip_suffix(".txt").unwrap_or(n).to_string();
            let found =
                names.iter().find(|n| **n == wanted || stem(n) == *wanted || stem(n).ends_with(wanted.as_str()));
            let Some(name) = found else {
                let message = format!("{}: no clip `{wanted}` (its clips: {})", dir.display(), names.join(", "));
                return Err(PoseError::new_err(message));
            };
            smpl.clip = Some(name.to_string());
            options.clip = None;
        }
        let mut scene = SceneDoc::default();
        scene.characters.push(doc);
        let library = &mut self.library;
        let notes = py.detach(|| apply_options(&mut scene, &options, library)).map_err(options_error)?;
        let doc = scene.characters.pop().ok_or_else(|| Error::new_err("the character was not posed"))?;
        Ok((doc, notes))
    }

    fn smpl_doc(&self) -> PyResult<&marionette_formats::scene::SmplDoc> {
        self.doc.smpl.as_ref().ok_or_else(|| PoseError::new_err(format!("{}: betas: not an SMPL body", self.doc.name)))
    }

    fn smpl_doc_mut(&mut self) -> PyResult<&mut marionette_formats::scene::SmplDoc> {
        let name = self.doc.name.clone();
        self.doc.smpl.as_mut().ok_or_else(|| PoseError::new_err(format!("{name}: betas: not an SMPL body")))
    }
}

/// A two-bone goal: a target, or a target and a pole.
#[derive(FromPyObject)]
enum TwoBoneGoal {
    WithPole((f32, f32, f32), (f32, f32, f32)),
    Target((f32, f32, f32)),
}

/// The arguments of [`Character::pose`] and [`Character::posed`] as the command line's
/// posing options, each parsed as the command line parses it.
#[pyclass(module = "marionette", frozen)]
struct PoseRequest {
    options: PoseOptions,
}

impl PoseRequest {
    /// The options keyword `arguments` ask for (a `TypeError` for an argument of another
    /// name or type).
    fn options(py: Python<'_>, arguments: Option<&Bound<'_, PyDict>>) -> PyResult<PoseOptions> {
        let request = py.get_type::<PoseRequest>().call((), arguments)?;
        Ok(request.extract::<PyRef<'_, PoseRequest>>()?.options.clone())
    }
}

#[pymethods]
impl PoseRequest {
    #[new]
    #[pyo3(signature = (*, time=None, clip=None, preset=None, mirrored=false, hands=None, rotations=None, two_bone=None, look_at=None, skinning=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        time: Option<f32>,
        clip: Option<String>,
        preset: Option<String>,
        mirrored: bool,
        hands: Option<BTreeMap<String, String>>,
        rotations: Option<BTreeMap<String, (f32, f32, f32)>>,
        two_bone: Option<BTreeMap<String, TwoBoneGoal>>,
        look_at: Option<BTreeMap<String, (f32, f32, f32)>>,
        skinning: Option<String>,
    ) -> PyResult<Self> {
        let specs = PoseSpecs {
            preset: preset
                .map(|name| parsed(&format!("{name}{}", if mirrored { ":mirrored" } else { "" })))
                .transpose()?,
            poses: spec_list(rotations, |(joint, (x, y, z))| format!("{joint}={x},{y},{z}"))?,
            hands: hands
                .unwrap_or_default()
                .into_iter()
                .map(|(side, name)| match side.as_str() {
                    "left" | "right" => parsed(&format!("{side}={name}")),
                    other => {
                        Err(PyValueError::new_err(format!("hands: expected \"left\" or \"right\", found {other:?}")))
                    }
                })
                .collect::<PyResult<_>>()?,
            ik: Vec::new(),
            two_bone: spec_list(two_bone, |(joint, goal)| match goal {
                TwoBoneGoal::Target((x, y, z)) => format!("{joint}={x},{y},{z}"),
                TwoBoneGoal::WithPole((x, y, z), (a, b, c)) => format!("{joint}={x},{y},{z}@{a},{b},{c}"),
            })?,
            look_at: spec_list(look_at, |(joint, (x, y, z))| format!("{joint}={x},{y},{z}"))?,
            ..PoseSpecs::default()
        };
        let skinning = match skinning.as_deref() {
            None => None,
            Some("lbs") => Some(SkinningMethod::Linear),
            Some("dq") => Some(SkinningMethod::DualQuaternion),
            Some(other) => {
                return Err(PyValueError::new_err(format!("skinning: expected \"lbs\" or \"dq\", found {other:?}")));
            }
        };
        Ok(Self { options: PoseOptions { specs, skinning, clip, time, still: true, ..PoseOptions::default() } })
    }
}

/// A command-line spec parsed as the command line parses it (its message on failure).
fn parsed<T: std::str::FromStr>(spec: &str) -> PyResult<T>
where
    T::Err: std::fmt::Display,
{
    spec.parse().map_err(|e: T::Err| PoseError::new_err(e.to_string()))
}

/// A dict of specs, each written as the command line's and parsed as it parses them.
fn spec_list<K, V, T>(specs: Option<BTreeMap<K, V>>, write: impl Fn((K, V)) -> String) -> PyResult<Vec<T>>
where
    T: std::str::FromStr,
    T::Err: std::fmt::Display,
{
    specs.unwrap_or_default().into_iter().map(|entry| parsed(&write(entry))).collect()
}

/// Reads the character a file brings (the first of its characters; an SMPL folder's body).
#[pyfunction]
fn load(py: Python<'_>, path: PathBuf) -> PyResult<Character> {
    py.detach(|| {
        let mut library = AssetLibrary::default();
        let scene = marionette_document::scenes::file_doc(&mut library, &path)?;
        let mut doc = scene
            .characters
            .into_iter()
            .next()
            .ok_or_else(|| FormatError::other(&path, "expected a character in the file, found none"))?;
        // An SMPL folder's body: its shape is the document's betas (zero at first).
        if path.is_dir()
            && let Ok(set) = library.smpl(&path)
        {
            let betas = vec![0.0; set.model.shape_count()];
            doc.smpl.get_or_insert_with(Default::default).betas = betas;
        }
        library.shaped(&doc)?;
        Ok(Character { library, doc })
    })
    .map_err(file_error)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(render::generate_pictures, m)?)?;
    m.add_function(wrap_pyfunction!(render::read_picture, m)?)?;
    m.add_function(wrap_pyfunction!(render::spec_count, m)?)?;
    m.add_class::<render::Scene>()?;
    m.add_class::<render::SetPictures>()?;
    m.add_class::<Character>()?;
    m.add_class::<Pose>()?;
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    m.add("FileError", py.get_type::<FileError>())?;
    m.add("SpecError", py.get_type::<SpecError>())?;
    m.add("PoseError", py.get_type::<PoseError>())?;
    Ok(())
}

//! Loading a character from a path whose siblings complete it: `Model1.skel` finds
//! `Model1.obj` and `Model1.attach`; a CSE169 `.skel` finds its `.skin` (without one it
//! becomes bone boxes), and a `.skin` its `.skel`.

use std::path::{Path, PathBuf};

use super::error::{FormatError, open};
use super::{cse169, mit6837, obj};
use marionette_rig::{CharacterAsset, Skeleton, Skin};

/// Which reader a path goes to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CharacterSource {
    /// 6.837 `.skel` (+ `.obj` + `.attach` beside it, when present).
    Mit6837 { skel: PathBuf, obj: Option<PathBuf>, attach: Option<PathBuf> },
    /// CSE169 `.skel`, with the `.skin` beside it (bone boxes without one).
    Cse169 { skel: PathBuf, skin: Option<PathBuf> },
    /// A folder with the SMPL exercise's files.
    Smpl { dir: PathBuf },
    /// Homer's rig JSON (+ an OFF mesh beside it).
    Homer { json: PathBuf },
    /// A BVH motion capture file: its skeleton as bone boxes.
    Bvh { path: PathBuf },
    /// A file of parts, characters and props with their own clips: glTF 2.0 (`.glb`,
    /// `.gltf`) or FBX.
    Parts { path: PathBuf },
    /// An OBJ mesh with no skeleton beside it: a prop, carried rigidly by one joint.
    Prop { obj: PathBuf },
}

impl CharacterSource {
    /// Recognises a path by its extension and content, and finds its companions.
    pub fn detect(path: &Path) -> Result<Self, FormatError> {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("skel") => {
                if is_cse169_skel(path)? {
                    let skin = Some(path.with_extension("skin")).filter(|p| p.is_file());
                    Ok(Self::Cse169 { skel: path.to_path_buf(), skin })
                } else {
                    let sibling = |e: &str| Some(path.with_extension(e)).filter(|p| p.is_file());
                    Ok(Self::Mit6837 { skel: path.to_path_buf(), obj: sibling("obj"), attach: sibling("attach") })
                }
            }
            Some("json") => Ok(Self::Homer { json: path.to_path_buf() }),
            Some("bvh") => Ok(Self::Bvh { path: path.to_path_buf() }),
            Some("glb" | "gltf" | "vrm" | "fbx") => Ok(Self::Parts { path: path.to_path_buf() }),
            Some("skin") => {
                let skel = path.with_extension("skel");
                if !skel.is_file() {
                    return Err(FormatError::other(
                        path,
                        format!("expected a skeleton beside it at {}, found none", skel.display()),
                    ));
                }
                Ok(Self::Cse169 { skel, skin: Some(path.to_path_buf()) })
            }
            Some("obj") if !path.with_extension("skel").is_file() => Ok(Self::Prop { obj: path.to_path_buf() }),
            Some("obj") | Some("attach") => {
                let skel = path.with_extension("skel");
                if !skel.is_file() {
                    return Err(FormatError::other(
                        path,
                        format!("expected a skeleton beside it at {}, found none", skel.display()),
                    ));
                }
                Self::detect(&skel)
            }
            _ if super::smpl::is_smpl_dir(path) => Ok(Self::Smpl { dir: path.to_path_buf() }),
            _ if path.is_dir() => Err(FormatError::other(
                path,
                "expected a character file (.skel, .obj), found a folder without one (nor the SMPL files smpl_00.obj, smpl_skin.txt)",
            )),
            _ => Err(FormatError::other(
                path,
                "expected a character file (.skel, .obj, .attach, .bvh, .json, .glb, .gltf, .vrm, .fbx), found an unknown extension",
            )),
        }
    }
}

/// Whether a `.skel` is the CSE169 kind (its first word is `balljoint`).
fn is_cse169_skel(path: &Path) -> Result<bool, FormatError> {
    use std::io::Read;
    // The first word is in the first few kilobytes of any real file.
    let mut head = Vec::new();
    open(path)?.take(64 << 10).read_to_end(&mut head).map_err(|e| FormatError::io(path, e))?;
    let text = String::from_utf8_lossy(&head);
    Ok(text.split_whitespace().next().is_some_and(|w| w.starts_with("balljoint")))
}

/// The skeleton alone of a `.skel` of either course or of a Homer rig `.json`.
pub fn load_skeleton(path: &Path) -> Result<Skeleton, FormatError> {
    match CharacterSource::detect(path)? {
        CharacterSource::Cse169 { skel, .. } => cse169::parse_skel(open(&skel)?, &skel),
        CharacterSource::Mit6837 { skel, .. } => mit6837::parse_skel(open(&skel)?, &skel),
        CharacterSource::Homer { json } => Ok(super::homer::parse_rig(open(&json)?, &json)?.skeleton),
        CharacterSource::Smpl { dir } => Ok(super::smpl::load_smpl_dir(&dir)?.0.skeleton),
        CharacterSource::Bvh { path } => Ok(super::bvh::parse_bvh(open(&path)?, &path)?.skeleton),
        CharacterSource::Parts { path } => Ok(first_part(&path)?.skeleton),
        CharacterSource::Prop { obj } => Ok(load_prop(&obj)?.skeleton),
    }
}

/// The first part of a glTF or FBX file.
fn first_part(path: &Path) -> Result<CharacterAsset, FormatError> {
    let mut parts = load_parts(path)?;
    Ok(parts.swap_remove(0).asset)
}

/// Whether a file holds parts (characters and props with their own clips): glTF or FBX.
pub fn has_parts(path: &Path) -> bool {
    super::gltf_import::is_gltf(path) || super::fbx::is_fbx(path)
}

/// Every part of a glTF or FBX file (at least one).
pub fn load_parts(path: &Path) -> Result<Vec<super::part::Part>, FormatError> {
    if super::fbx::is_fbx(path) { super::fbx::load_fbx(path) } else { super::gltf_import::load_gltf(path) }
}

/// Loads whatever character `path` names (the first, where a glTF file holds several).
pub fn load_character(path: &Path) -> Result<CharacterAsset, FormatError> {
    let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("character").to_string();
    match CharacterSource::detect(path)? {
        CharacterSource::Cse169 { skel, skin: None } => {
            let skeleton = cse169::parse_skel(open(&skel)?, &skel)?;
            Ok(CharacterAsset::with_bone_boxes(name, skeleton, Vec::new()))
        }
        CharacterSource::Cse169 { skel, skin: Some(skin_path) } => {
            let skeleton = cse169::parse_skel(open(&skel)?, &skel)?;
            load_cse169_skin(name, skeleton, &skin_path)
        }
        CharacterSource::Homer { json } => super::homer::load_homer(&json),
        CharacterSource::Bvh { path } => {
            let bvh = super::bvh::parse_bvh(open(&path)?, &path)?;
            Ok(CharacterAsset::with_bone_boxes(name, bvh.skeleton, Vec::new()))
        }
        CharacterSource::Parts { path } => first_part(&path),
        CharacterSource::Prop { obj } => load_prop(&obj),
        CharacterSource::Smpl { dir } => {
            let (model, warnings) = super::smpl::load_smpl_dir(&dir)?;
            let mut asset = model.asset(&name, &[]).map_err(|e| FormatError::rig(&dir, e))?;
            asset.warnings = warnings;
            Ok(asset)
        }
        CharacterSource::Mit6837 { skel, obj, attach } => {
            let skeleton = mit6837::parse_skel(open(&skel)?, &skel)?;
            match (obj, attach) {
                (Some(obj_path), Some(attach_path)) => load_6837_skin(name, skeleton, &obj_path, &attach_path),
                (None, _) => Ok(CharacterAsset::with_bone_boxes(
                    name,
                    skeleton,
                    vec![format!("no {} beside it: drawing bone boxes", skel.with_extension("obj").display())],
                )),
                (Some(_), None) => Err(FormatError::other(
                    &skel,
                    format!("expected weights at {}, found none", skel.with_extension("attach").display()),
                )),
            }
        }
    }
}

/// An OBJ mesh as a prop: its vertices carried by one joint at the origin.
fn load_prop(path: &Path) -> Result<CharacterAsset, FormatError> {
    let mesh = obj::parse_obj(open(path)?, path)?;
    if mesh.positions.is_empty() {
        return Err(FormatError::other(path, "expected a mesh (`v` lines), found none"));
    }
    let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("prop");
    CharacterAsset::rigid(name, mesh.positions, mesh.triangles).map_err(|e| FormatError::rig(path, e))
}

/// A CSE169 skeleton with its `.skin`: bound by the skin's own bind matrices.
fn load_cse169_skin(name: String, skeleton: Skeleton, path: &Path) -> Result<CharacterAsset, FormatError> {
    let file = super::cse169_skin::parse_skin(open(path)?, path)?;
    if file.bindings.len() != skeleton.len() {
        return Err(FormatError::other(
            path,
            format!(
                "expected a binding for each of the skeleton's {} joints, found {}",
                skeleton.len(),
                file.bindings.len()
            ),
        ));
    }
    let singular = file.bindings.iter().position(|m| !crate::checks::is_invertible(m));
    if let Some(j) = singular {
        return Err(FormatError::other(
            path,
            format!("binding {j} (joint `{}`) cannot be inverted", skeleton.joint(j).name),
        ));
    }
    let (weights, normalised) =
        marionette_rig::SkinWeights::from_rows(file.weights, skeleton.len()).map_err(|e| FormatError::rig(path, e))?;
    let mut warnings = super::weight_warnings::normalised_warnings(path, &normalised);
    let inverse_binds = file.bindings.iter().map(|m| m.inverse()).collect();
    let morphs = morphs_beside(path, &file.positions)?;
    let textured = file.texcoords.len() == file.positions.len();
    let texture = file.texture.filter(|t| {
        let found = t.is_file() && textured;
        if !found {
            warnings.push(format!(
                "{}: its texture {} is not shown (no such file, or no texcoords)",
                path.display(),
                t.display()
            ));
        }
        found
    });
    // CSE169 counts v from the image's bottom row, as OpenGL does; ours from its top.
    let texcoords = match texture {
        Some(_) => file.texcoords.iter().map(|t| glam::Vec2::new(t.x, 1.0 - t.y)).collect(),
        None => Vec::new(),
    };
    let skin = Skin { texcoords, ..Skin::untextured(file.positions, file.triangles, weights) };
    let asset = CharacterAsset::with_inverse_binds(name, skeleton, skin, inverse_binds, warnings)
        .map_err(|e| FormatError::rig(path, e))?;
    let materials = texture
        .map(|t| marionette_rig::material::Material::textured("texture", marionette_rig::SkinTexture::File(t)))
        .into_iter()
        .collect();
    Ok(CharacterAsset { morphs, materials, ..asset })
}

/// The `.morph` files beside a skin whose names start with the skin's (`head1.morph` and
/// `head2.morph` for `head.skin`), in name order, as moves from the skin's positions (the
/// files give where the vertices go).
fn morphs_beside(skin: &Path, positions: &[glam::Vec3]) -> Result<Vec<marionette_rig::MorphTarget>, FormatError> {
    let Some(stem) = skin.file_stem().and_then(|s| s.to_str()) else { return Ok(Vec::new()) };
    // `head.skin` (no folder in the path) has its siblings in the working folder.
    let dir = skin.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|entries| entries.filter_map(|e| Some(e.ok()?.path())).collect())
        .unwrap_or_default();
    files.retain(|p| {
        p.extension().is_some_and(|e| e == "morph")
            && p.file_stem().and_then(|s| s.to_str()).is_some_and(|s| s.starts_with(stem))
    });
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let morph = super::cse169_skin::parse_morph(open(&p)?, &p, positions.len())?;
            let deltas = morph.positions.iter().map(|&(v, to)| (v as u32, to - positions[v])).collect();
            let name = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            Ok(marionette_rig::MorphTarget { name, deltas })
        })
        .collect()
}

fn load_6837_skin(
    name: String,
    skeleton: Skeleton,
    obj_path: &Path,
    attach_path: &Path,
) -> Result<CharacterAsset, FormatError> {
    let mesh = obj::parse_obj(open(obj_path)?, obj_path)?;
    let (weights, normalised) =
        mit6837::parse_attach(open(attach_path)?, attach_path, skeleton.len(), mesh.positions.len())?;
    let warnings = super::weight_warnings::normalised_warnings(attach_path, &normalised);
    let skin = Skin::untextured(mesh.positions, mesh.triangles, weights);
    CharacterAsset::new(name, skeleton, skin, warnings).map_err(|e| FormatError::rig(obj_path, e))
}

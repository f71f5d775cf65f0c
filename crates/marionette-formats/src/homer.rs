//! Homer's rig (Ursinus CS 476 character-animation exercise): a JSON object mapping joint
//! names to `{"pos": [x, y, z], "children": [...], "weights": {"vertex": w, ...}}`
//! (absolute positions; keys not in hierarchy order; weights optional, sparse, and not
//! normalised), with an OFF mesh beside it.

use std::collections::{BTreeMap, HashMap};
use std::io::BufRead;
use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::Deserialize;

use super::error::{FormatError, open};
use super::off::parse_off;
use marionette_rig::bind::{Binding, bind_to_bones, bones};
use marionette_rig::{CharacterAsset, RawJoint, Skeleton, Skin, SkinWeights};

#[derive(Debug, Deserialize)]
struct RawHomerJoint {
    pos: [f32; 3],
    #[serde(default)]
    children: Vec<String>,
    #[serde(default)]
    weights: Option<BTreeMap<String, f32>>,
}

/// A parsed rig: the skeleton (depth-first from the root, children in file order), the
/// absolute joint positions in that order, and the sparse weights per joint if present.
#[derive(Debug, Clone)]
pub struct HomerRig {
    pub skeleton: Skeleton,
    pub positions: Vec<Vec3>,
    /// `(joint, vertex, weight)` triples.
    pub weights: Option<Vec<(usize, usize, f32)>>,
}

/// An error at a place in the JSON document (`$["joint"].children[2]`).
fn json_error(path: &Path, at: &str, message: impl std::fmt::Display) -> FormatError {
    FormatError::other(path, format!("at {at}: {message}"))
}

/// Parses a Homer rig JSON. Positions and weights must be finite; errors name the JSON
/// path (`$["joint"].pos`) or the line.
pub fn parse_rig(reader: impl BufRead, path: &Path) -> Result<HomerRig, FormatError> {
    let text = super::error::read_text(reader, path)?;
    let raw: BTreeMap<String, RawHomerJoint> = serde_json::from_str(&text).map_err(|e| {
        let (line, column) = (e.line().max(1), e.column().max(1));
        // serde_json's message ends with its own "at line L column C".
        let message = e.to_string();
        let message = message.strip_suffix(&format!(" at line {} column {}", e.line(), e.column())).unwrap_or(&message);
        FormatError::syntax_at(path, line, column, message)
    })?;
    if raw.is_empty() {
        return Err(json_error(path, "$", "expected at least one joint, found an empty object"));
    }
    if raw.len() > marionette_rig::MAX_JOINTS {
        return Err(json_error(
            path,
            "$",
            format!("expected at most {} joints, found {}", marionette_rig::MAX_JOINTS, raw.len()),
        ));
    }
    let names: Vec<&String> = raw.keys().collect();
    let index: HashMap<&str, usize> = names.iter().enumerate().map(|(i, n)| (n.as_str(), i)).collect();
    let mut parent: Vec<Option<usize>> = vec![None; names.len()];
    for (p, (name, joint)) in raw.iter().enumerate() {
        if let Some(bad) = joint.pos.iter().find(|v| !v.is_finite()) {
            return Err(json_error(path, &format!("$[{name:?}].pos"), format!("expected finite numbers, found {bad}")));
        }
        for (k, child) in joint.children.iter().enumerate() {
            let at = || format!("$[{name:?}].children[{k}]");
            let c = *index.get(child.as_str()).ok_or_else(|| {
                json_error(
                    path,
                    &at(),
                    format!("expected a joint name, found `{}`, which is not defined", super::error::excerpt(child)),
                )
            })?;
            if let Some(other) = parent[c] {
                return Err(json_error(
                    path,
                    &at(),
                    format!("joint `{child}` is a child of both `{}` and `{name}`", names[other]),
                ));
            }
            parent[c] = Some(p);
        }
    }
    let joints: Vec<RawJoint> = raw
        .iter()
        .enumerate()
        .map(|(i, (name, j))| {
            let pos = Vec3::from(j.pos);
            let offset = parent[i].map_or(pos, |p| pos - Vec3::from(raw[names[p]].pos));
            RawJoint::new(name.clone(), parent[i], offset)
        })
        .collect();
    let (skeleton, new_index) = Skeleton::build_reordered(joints)
        .map_err(|e| json_error(path, "$", format!("{e} (from the `children` lists)")))?;
    let mut positions = vec![Vec3::ZERO; names.len()];
    let mut weights: Option<Vec<(usize, usize, f32)>> = None;
    for (old, (name, j)) in raw.iter().enumerate() {
        positions[new_index[old]] = Vec3::from(j.pos);
        if let Some(w) = &j.weights {
            let list = weights.get_or_insert_with(Vec::new);
            for (vertex, weight) in w {
                let at = || format!("$[{name:?}].weights[{vertex:?}]");
                let v: usize = vertex.parse().map_err(|_| {
                    json_error(
                        path,
                        &at(),
                        format!("expected a vertex index as key, found `{}`", super::error::excerpt(vertex)),
                    )
                })?;
                if !(weight.is_finite() && *weight >= 0.0) {
                    return Err(json_error(path, &at(), format!("expected a finite weight >= 0, found {weight}")));
                }
                list.push((new_index[old], v, *weight));
            }
        }
    }
    Ok(HomerRig { skeleton, positions, weights })
}

/// The mesh beside a rig: `homer.off` for a rig with weights, otherwise the denser
/// `homer3x.off` when present.
pub fn mesh_beside(rig_path: &Path, has_weights: bool) -> Option<PathBuf> {
    let dir = rig_path.parent().unwrap_or(Path::new("."));
    let candidates: &[&str] = if has_weights { &["homer.off"] } else { &["homer3x.off", "homer.off"] };
    let stem = rig_path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    std::iter::once(rig_path.with_extension("off"))
        .chain(candidates.iter().map(|c| dir.join(c)))
        .find(|p| p.is_file() && !p.ends_with(format!("{stem}.json")))
}

/// Loads a Homer rig and its mesh. Without weights in the file, the skin is bound
/// smoothly from the distance to the bones (and a warning says so).
pub fn load_homer(path: &Path) -> Result<CharacterAsset, FormatError> {
    let rig = parse_rig(open(path)?, path)?;
    let mesh_path = mesh_beside(path, rig.weights.is_some()).ok_or_else(|| {
        FormatError::other(path, "expected an OFF mesh beside it (homer.off or homer3x.off), found none")
    })?;
    let mesh = parse_off(open(&mesh_path)?, &mesh_path)?;
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "homer".into());
    homer_character(name, rig, mesh, path)
}

/// A character from a parsed rig and its mesh: the rig's weights (normalised, each vertex
/// needing one), or, without weights, a smooth binding to the bones. Errors name the rig's
/// JSON path.
pub fn homer_character(
    name: String,
    rig: HomerRig,
    mesh: super::obj::ObjMesh,
    rig_path: &Path,
) -> Result<CharacterAsset, FormatError> {
    let n = mesh.positions.len();
    let mut warnings = Vec::new();
    let weights = match &rig.weights {
        Some(triples) => {
            let mut rows: Vec<Vec<(usize, f32)>> = vec![Vec::new(); n];
            for &(j, v, w) in triples {
                let row = rows.get_mut(v).ok_or_else(|| {
                    let joint = &rig.skeleton.joint(j).name;
                    json_error(
                        rig_path,
                        &format!("$[{joint:?}].weights[\"{v}\"]"),
                        format!("expected a vertex index below {n} (the mesh's count), found {v}"),
                    )
                })?;
                row.push((j, w));
            }
            let (weights, normalised) =
                SkinWeights::from_rows(rows, rig.skeleton.len()).map_err(|e| json_error(rig_path, "$", e))?;
            warnings.extend(super::weight_warnings::normalised_warnings(rig_path, &normalised));
            weights
        }
        None => {
            warnings.push(format!(
                "{}: no weights in the rig; bound smoothly from the distance to the bones",
                rig_path.display()
            ));
            bind_to_bones(&mesh.positions, &bones(&rig.skeleton, &rig.positions), rig.skeleton.len(), Binding::Smooth)
        }
    };
    let skin = Skin::untextured(mesh.positions, mesh.triangles, weights);
    CharacterAsset::new(name, rig.skeleton, skin, warnings).map_err(|e| json_error(rig_path, "$", e))
}

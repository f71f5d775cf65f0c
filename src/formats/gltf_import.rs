//! glTF 2.0 import (`.glb`, `.gltf` with its `.bin` files), read with the `gltf` crate: the
//! first skin becomes a character. Its joints (names, hierarchy, each node's translation as
//! the rest offset and its rotation as the joint's pose from the file), the file's inverse
//! bind matrices, and every primitive of the mesh that uses the skin (merged), with all
//! `JOINTS_n`/`WEIGHTS_n` sets, normalised. Transforms of nodes above the skeleton are folded
//! into its root. Joint scales are not carried (a warning says where they are not 1).

use std::path::Path;

use glam::{Mat4, Quat, Vec3};

use super::error::FormatError;
use crate::rig::{CharacterAsset, JointRotation, RawJoint, Skeleton, Skin, SkinWeights};

/// Loads the first skinned mesh of a glTF file as a character.
pub fn load_gltf(path: &Path) -> Result<CharacterAsset, FormatError> {
    let bytes = std::fs::read(path).map_err(|e| FormatError::io(path, e))?;
    parse_gltf(&bytes, path)
}

/// The first skinned mesh of a glTF file's bytes (`.bin` files are looked for beside
/// `path`).
pub fn parse_gltf(bytes: &[u8], path: &Path) -> Result<CharacterAsset, FormatError> {
    let gltf =
        gltf::Gltf::from_slice(bytes).map_err(|e| FormatError::other(path, format!("at $: expected glTF 2.0, {e}")))?;
    if let Some(ext) = gltf.extensions_required().next() {
        return Err(FormatError::other(path, format!("at $.extensionsRequired: needs `{ext}`, which is not read")));
    }
    let buffers = buffers(&gltf, path)?;
    let data = |b: gltf::Buffer| buffers.get(b.index()).map(Vec::as_slice);
    let skin = gltf
        .skins()
        .next()
        .ok_or_else(|| FormatError::other(path, "at $.skins[0]: expected a skinned mesh, found none"))?;
    let mesh = gltf
        .nodes()
        .find(|n| n.skin().is_some_and(|s| s.index() == skin.index()) && n.mesh().is_some())
        .and_then(|n| n.mesh())
        .ok_or_else(|| {
            FormatError::other(path, format!("at $.skins[{}]: expected a mesh node using it, found none", skin.index()))
        })?;

    let mut parent = vec![None; gltf.nodes().len()];
    for n in gltf.nodes() {
        for c in n.children() {
            parent[c.index()] = Some(n.index());
        }
    }
    let joints: Vec<gltf::Node> = skin.joints().collect();
    let joint_of = |node: usize| joints.iter().position(|j| j.index() == node);
    let mut warnings = Vec::new();
    let mut raw = Vec::with_capacity(joints.len());
    for (j, node) in joints.iter().enumerate() {
        let (t, r, s) = node.transform().decomposed();
        if (Vec3::from(s) - Vec3::ONE).abs().max_element() > 1e-4 {
            warnings.push(format!(
                "{}: nodes[{}] scales by {s:?}; joint scales are not carried",
                path.display(),
                node.index()
            ));
        }
        let up = parent[node.index()];
        let mut local = Mat4::from_rotation_translation(Quat::from_array(r), Vec3::from(t));
        if up.and_then(joint_of).is_none() {
            // A skeleton root: the nodes above it place it.
            local = global(&gltf, &parent, up) * local;
        }
        let (_, rotation, translation) = local.to_scale_rotation_translation();
        let name = node.name().map_or_else(|| format!("joint {j}"), str::to_string);
        let mut joint = RawJoint::new(name, up.and_then(joint_of), translation);
        joint.initial_rotation = JointRotation::Quat(rotation.normalize());
        raw.push(joint);
    }
    let (skeleton, new_index) = Skeleton::build_reordered(raw)
        .map_err(|e| FormatError::other(path, format!("at $.skins[{}].joints: {e}", skin.index())))?;

    let mut inverse = vec![Mat4::IDENTITY; skeleton.len()];
    if let Some(ibm) = skin.reader(data).read_inverse_bind_matrices() {
        for (j, m) in ibm.enumerate().take(skeleton.len()) {
            inverse[new_index[j]] = Mat4::from_cols_array_2d(&m);
        }
    }

    let (mut positions, mut triangles, mut rows) = (Vec::new(), Vec::new(), Vec::new());
    for (p, primitive) in mesh.primitives().enumerate() {
        let at = format!("at $.meshes[{}].primitives[{p}]", mesh.index());
        if primitive.mode() != gltf::mesh::Mode::Triangles {
            warnings.push(format!("{}: {at} is not triangles and was skipped", path.display()));
            continue;
        }
        let reader = primitive.reader(data);
        let first = positions.len() as u32;
        let points: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| {
                FormatError::other(path, format!("{at}.attributes.POSITION: expected positions, found none"))
            })?
            .map(Vec3::from)
            .collect();
        let count = points.len();
        positions.extend(points);
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..count as u32).collect(),
        };
        if let Some(bad) = indices.iter().find(|&&i| i as usize >= count) {
            return Err(FormatError::other(path, format!("{at}.indices: index {bad} is beyond its {count} vertices")));
        }
        triangles.extend(indices.chunks_exact(3).map(|t| [first + t[0], first + t[1], first + t[2]]));
        let mut influences: Vec<Vec<(usize, f32)>> = vec![Vec::new(); count];
        let mut set = 0;
        while let (Some(js), Some(ws)) = (reader.read_joints(set), reader.read_weights(set)) {
            for (v, (j, w)) in js.into_u16().zip(ws.into_f32()).enumerate().take(count) {
                for k in 0..4 {
                    if w[k] > 0.0 {
                        let joint = *new_index.get(j[k] as usize).ok_or_else(|| {
                            FormatError::other(
                                path,
                                format!(
                                    "{at}.attributes.JOINTS_{set}: vertex {v} names joint {} of {}",
                                    j[k],
                                    skeleton.len()
                                ),
                            )
                        })?;
                        influences[v].push((joint, w[k]));
                    }
                }
            }
            set += 1;
        }
        if set == 0 {
            return Err(FormatError::other(
                path,
                format!("{at}.attributes: expected JOINTS_0 and WEIGHTS_0, found none"),
            ));
        }
        rows.extend(influences);
    }
    let (weights, normalised) = SkinWeights::from_rows(rows, skeleton.len())
        .map_err(|e| FormatError::other(path, format!("at $.meshes[{}] (JOINTS_n, WEIGHTS_n): {e}", mesh.index())))?;
    warnings.extend(super::character::normalised_warnings(path, &normalised));
    let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("gltf").to_string();
    let skin = Skin { bind_positions: positions, triangles, weights, texcoords: Vec::new() };
    CharacterAsset::with_inverse_binds(name, skeleton, skin, inverse, warnings).map_err(|e| FormatError::rig(path, e))
}

/// The global transform of `node` (identity for none), from its parents.
fn global(gltf: &gltf::Gltf, parent: &[Option<usize>], node: Option<usize>) -> Mat4 {
    let mut m = Mat4::IDENTITY;
    let mut at = node;
    while let Some(n) = at {
        let node = gltf.nodes().nth(n).expect("a node of the file");
        m = Mat4::from_cols_array_2d(&node.transform().matrix()) * m;
        at = parent[n];
    }
    m
}

/// The file's buffers: the GLB's binary chunk, or `.bin` files beside a `.gltf`.
fn buffers(gltf: &gltf::Gltf, path: &Path) -> Result<Vec<Vec<u8>>, FormatError> {
    gltf.buffers()
        .map(|b| {
            let at = format!("at $.buffers[{}]", b.index());
            let data = match b.source() {
                gltf::buffer::Source::Bin => gltf.blob.clone().ok_or_else(|| {
                    FormatError::other(path, format!("{at}: expected the GLB's binary chunk, found none"))
                })?,
                gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                    return Err(FormatError::other(
                        path,
                        format!("{at}: embedded data URIs are not read; use .glb or a .bin file"),
                    ));
                }
                gltf::buffer::Source::Uri(uri) => {
                    let file = path.parent().unwrap_or(Path::new(".")).join(uri);
                    std::fs::read(&file).map_err(|e| FormatError::io(&file, e))?
                }
            };
            if data.len() < b.length() {
                return Err(FormatError::other(
                    path,
                    format!("{at}: expected {} bytes, found {}", b.length(), data.len()),
                ));
            }
            Ok(data)
        })
        .collect()
}

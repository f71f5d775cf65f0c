//! glTF 2.0 import (`.glb`, `.gltf` with its `.bin` files), read with the `gltf` crate:
//! every skin with a mesh becomes a character. Its joints (names, hierarchy, each node's
//! translation as the rest offset, its scale as the rest scale, its rotation as the
//! joint's pose from the file), the file's inverse bind matrices, every primitive of the
//! meshes that use the skin (merged, in file order) with all `JOINTS_n`/`WEIGHTS_n` sets,
//! normalised; morph targets; the base colour factor and texture; and the file's animations of the
//! skin's joints as clips. Transforms of nodes above the skeleton are folded into its root.

use std::borrow::Cow;
use std::path::Path;

use glam::{Mat4, Quat, Vec2, Vec3};

use super::error::FormatError;
use crate::rig::node_clip::{Interpolation, JointTracks, NodeClip, Track};
use crate::rig::{
    CharacterAsset, JointRotation, MorphTarget, Picture, RawJoint, Skeleton, Skin, SkinTexture, SkinWeights,
};

/// One character of a glTF file: its asset, the file's animations of its joints, and the
/// base colour of its first primitive's material (none: the file gives no material).
#[derive(Debug, Clone)]
pub struct ImportedCharacter {
    pub asset: CharacterAsset,
    pub clips: Vec<NodeClip>,
    pub base_color: Option<[f32; 4]>,
    /// The morph targets' weights as the file sets them (`mesh.weights`; 0 where unset).
    pub morph_weights: Vec<f32>,
}

/// Whether `path` names a glTF file (`.glb`, `.gltf`).
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"))
}

/// Loads every skinned character of a glTF file, in the order of its skins.
pub fn load_gltf(path: &Path) -> Result<Vec<ImportedCharacter>, FormatError> {
    let bytes = super::error::read_file(path)?;
    parse_gltf(&bytes, path)
}

/// The skinned characters of a glTF file's bytes (`.bin` files are looked for beside
/// `path`), one per skin that a mesh uses, in the order of the skins.
pub fn parse_gltf(bytes: &[u8], path: &Path) -> Result<Vec<ImportedCharacter>, FormatError> {
    let (gltf, bin) = validated(bytes).map_err(|e| FormatError::other(path, e))?;
    if let Some(ext) = gltf.extensions_required().next() {
        return Err(FormatError::other(path, format!("at $.extensionsRequired: needs `{ext}`, which is not read")));
    }
    let buffers = buffers(&gltf, bin, path)?;
    let file = File { gltf: &gltf, buffers: &buffers, path, parent: parents(&gltf) };
    let mut characters = Vec::new();
    for skin in gltf.skins() {
        let meshes: Vec<gltf::Mesh> = gltf
            .nodes()
            .filter(|n| n.skin().is_some_and(|s| s.index() == skin.index()))
            .filter_map(|n| n.mesh())
            .collect();
        if !meshes.is_empty() {
            characters.push(file.character(&skin, &meshes, gltf.skins().len())?);
        }
    }
    if characters.is_empty() {
        let what = if gltf.skins().len() == 0 {
            "at $.skins[0]: expected a skinned mesh"
        } else {
            "at $.skins: expected a skin that a mesh node uses"
        };
        return Err(FormatError::other(path, format!("{what}, found none")));
    }
    Ok(characters)
}

/// A parsed file: its JSON, its buffers and each node's parent.
struct File<'a> {
    gltf: &'a gltf::Gltf,
    buffers: &'a [Cow<'a, [u8]>],
    path: &'a Path,
    parent: Vec<Option<usize>>,
}

impl File<'_> {
    fn error(&self, message: String) -> FormatError {
        FormatError::other(self.path, message)
    }

    fn data<'s>(&'s self) -> impl Clone + Fn(gltf::Buffer) -> Option<&'s [u8]> {
        |b: gltf::Buffer| self.buffers.get(b.index()).map(|data| &**data)
    }

    /// The character of `skin`, drawn by `meshes`.
    fn character(
        &self,
        skin: &gltf::Skin,
        meshes: &[gltf::Mesh],
        skin_count: usize,
    ) -> Result<ImportedCharacter, FormatError> {
        let mut warnings = Vec::new();
        let joints: Vec<gltf::Node> = skin.joints().collect();
        let (skeleton, new_index, root_parent) = self.skeleton(skin, &joints)?;
        let mut inverse = vec![Mat4::IDENTITY; skeleton.len()];
        if let Some(ibm) = skin.reader(self.data()).read_inverse_bind_matrices() {
            for (j, m) in ibm.enumerate().take(skeleton.len()) {
                let m = Mat4::from_cols_array_2d(&m);
                if !m.is_finite() || m.determinant().abs() < 1e-12 || !m.inverse().is_finite() {
                    let what = if m.is_finite() { "a singular matrix" } else { "numbers that are not finite" };
                    return Err(self.error(format!(
                        "at $.skins[{}].inverseBindMatrices: expected an invertible matrix for joint {j}, found {what}",
                        skin.index()
                    )));
                }
                inverse[new_index[j]] = m;
            }
        }
        let mut skin_data = Skin::default();
        let mut rows = Vec::new();
        let mut morphs = Vec::new();
        let mut base_color = None;
        let (mut texture, mut texcoords) = (None, Vec::new());
        for mesh in meshes {
            for (p, primitive) in mesh.primitives().enumerate() {
                let at = format!("at $.meshes[{}].primitives[{p}]", mesh.index());
                if primitive.mode() != gltf::mesh::Mode::Triangles {
                    warnings.push(format!("{}: {at} is not triangles and was skipped", self.path.display()));
                    continue;
                }
                let pbr = primitive.material().pbr_metallic_roughness();
                if primitive.material().index().is_some() {
                    // A primitive without a material has glTF's default (white): no tint.
                    base_color.get_or_insert(pbr.base_color_factor());
                }
                let first = skin_data.bind_positions.len();
                self.primitive(&primitive, &at, &new_index, &mut skin_data, &mut rows)?;
                if let Some(info) = pbr.base_color_texture() {
                    texture = texture.or_else(|| self.texture(&info.texture(), &mut warnings));
                    let uv = primitive.reader(self.data()).read_tex_coords(info.tex_coord());
                    texcoords.resize(first, Vec2::ZERO);
                    texcoords.extend(uv.into_iter().flat_map(|t| t.into_f32()).map(Vec2::from));
                    if let Some(v) = texcoords[first..].iter().position(|t| !t.is_finite()) {
                        return Err(self.error(format!(
                            "{at}.attributes.TEXCOORD_{}: expected finite numbers, found vertex {v}'s {}",
                            info.tex_coord(),
                            texcoords[first + v]
                        )));
                    }
                }
                self.morph_targets(mesh, &primitive, &at, first, &mut morphs)?;
            }
        }
        let (weights, normalised) = SkinWeights::from_rows(rows, skeleton.len())
            .map_err(|e| self.error(format!("at $.skins[{}] meshes (JOINTS_n, WEIGHTS_n): {e}", skin.index())))?;
        warnings.extend(super::weight_warnings::normalised_warnings(self.path, &normalised));
        skin_data.weights = weights;
        if texture.is_some() {
            texcoords.resize(skin_data.bind_positions.len(), Vec2::ZERO);
            skin_data.texcoords = texcoords;
        }
        let clips = self.clips(&joints, &new_index, root_parent, &mut warnings)?;
        let stem = self.path.file_stem().and_then(|s| s.to_str()).unwrap_or("gltf");
        let name = match (skin_count, meshes[0].name()) {
            (1, _) => stem.to_string(),
            (_, Some(mesh)) => mesh.to_string(),
            _ => format!("{stem} {}", skin.index()),
        };
        let mut asset = CharacterAsset::with_inverse_binds(name, skeleton, skin_data, inverse, warnings)
            .map_err(|e| FormatError::rig(self.path, e))?;
        // Each morph's weight from the first mesh that names it.
        let morph_weights = morphs
            .iter()
            .map(|m| {
                meshes.iter().find_map(|mesh| {
                    let k = target_names(mesh).iter().position(|n| *n == m.name)?;
                    mesh.weights()?.get(k).copied()
                })
            })
            .map(|w| w.filter(|w| w.is_finite()).unwrap_or(0.0))
            .collect();
        asset.morphs = morphs;
        asset.texture = texture;
        Ok(ImportedCharacter { asset, clips, base_color, morph_weights })
    }

    /// The skin's joints as a skeleton (reordered parents first: `new_index[file joint]`)
    /// and the transform of the nodes above its root.
    fn skeleton(&self, skin: &gltf::Skin, joints: &[gltf::Node]) -> Result<(Skeleton, Vec<usize>, Mat4), FormatError> {
        let joint_of = joint_of_node(self.gltf, joints);
        let joint_of = |node: usize| joint_of[node];
        let mut raw = Vec::with_capacity(joints.len());
        let mut root_parent = Mat4::IDENTITY;
        for (j, node) in joints.iter().enumerate() {
            let up = self.parent[node.index()];
            let mut local = Mat4::from_cols_array_2d(&node.transform().matrix());
            if up.and_then(joint_of).is_none() {
                // A skeleton root: the nodes above it place it.
                root_parent = self.global(up);
                local = root_parent * local;
            }
            let (scale, rotation, translation) = local.to_scale_rotation_translation();
            let name = node.name().map_or_else(|| format!("joint {j}"), str::to_string);
            let mut joint = RawJoint::new(name, up.and_then(joint_of), translation);
            joint.initial_rotation = JointRotation::Quat(rotation.normalize());
            if (scale - Vec3::ONE).abs().max_element() > 1e-6 {
                joint.rest_scale = scale;
            }
            raw.push(joint);
        }
        let (skeleton, new_index) = Skeleton::build_reordered(raw)
            .map_err(|e| self.error(format!("at $.skins[{}].joints: {e}", skin.index())))?;
        Ok((skeleton, new_index, root_parent))
    }

    /// Appends one triangle primitive: its positions, triangles and influence rows.
    fn primitive(
        &self,
        primitive: &gltf::Primitive,
        at: &str,
        new_index: &[usize],
        skin: &mut Skin,
        rows: &mut Vec<Vec<(usize, f32)>>,
    ) -> Result<(), FormatError> {
        let reader = primitive.reader(self.data());
        let first = skin.bind_positions.len() as u32;
        let points: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| self.error(format!("{at}.attributes.POSITION: expected positions, found none")))?
            .map(Vec3::from)
            .collect();
        if let Some(v) = points.iter().position(|p| !p.is_finite()) {
            return Err(self.error(format!(
                "{at}.attributes.POSITION: expected finite numbers, found vertex {v} at {}",
                points[v]
            )));
        }
        let count = points.len();
        skin.bind_positions.extend(points);
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..count as u32).collect(),
        };
        if let Some(bad) = indices.iter().find(|&&i| i as usize >= count) {
            return Err(self.error(format!("{at}.indices: index {bad} is beyond its {count} vertices")));
        }
        skin.triangles.extend(indices.chunks_exact(3).map(|t| [first + t[0], first + t[1], first + t[2]]));
        let mut influences: Vec<Vec<(usize, f32)>> = vec![Vec::new(); count];
        let mut set = 0;
        while let (Some(js), Some(ws)) = (reader.read_joints(set), reader.read_weights(set)) {
            for (v, (j, w)) in js.into_u16().zip(ws.into_f32()).enumerate().take(count) {
                if let Some(bad) = w.iter().find(|w| !(w.is_finite() && **w >= 0.0)) {
                    return Err(self.error(format!(
                        "{at}.attributes.WEIGHTS_{set}: expected weights that are finite and not negative, found {bad} at vertex {v}"
                    )));
                }
                for k in 0..4 {
                    if w[k] > 0.0 {
                        let joint = *new_index.get(j[k] as usize).ok_or_else(|| {
                            self.error(format!(
                                "{at}.attributes.JOINTS_{set}: vertex {v} names joint {} of {}",
                                j[k],
                                new_index.len()
                            ))
                        })?;
                        influences[v].push((joint, w[k]));
                    }
                }
            }
            set += 1;
        }
        if set == 0 {
            return Err(self.error(format!("{at}.attributes: expected JOINTS_0 and WEIGHTS_0, found none")));
        }
        rows.extend(influences);
        Ok(())
    }

    /// Adds the primitive's morph targets (position deltas of its vertices, which start
    /// at `first`) to `morphs`, target k of every primitive of a mesh into one morph.
    fn morph_targets(
        &self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        at_primitive: &str,
        first: usize,
        morphs: &mut Vec<MorphTarget>,
    ) -> Result<(), FormatError> {
        let names = target_names(mesh);
        let reader = primitive.reader(self.data());
        for (k, (positions, _, _)) in reader.read_morph_targets().enumerate() {
            let name = names.get(k).cloned().unwrap_or_else(|| format!("{} target {k}", mesh.name().unwrap_or("mesh")));
            let index = match morphs.iter().position(|m| m.name == name) {
                Some(index) => index,
                None => {
                    morphs.push(MorphTarget { name, deltas: Vec::new() });
                    morphs.len() - 1
                }
            };
            let deltas: Vec<(usize, [f32; 3])> =
                positions.into_iter().flatten().enumerate().filter(|(_, d)| *d != [0.0; 3]).collect();
            if let Some((v, _)) = deltas.iter().find(|(_, d)| !d.iter().all(|x| x.is_finite())) {
                return Err(self.error(format!(
                    "{at_primitive}.targets[{k}].POSITION: expected finite numbers, found a move of vertex {v} that is not"
                )));
            }
            morphs[index].deltas.extend(deltas.into_iter().map(|(v, d)| ((first + v) as u32, Vec3::from(d))));
        }
        Ok(())
    }

    /// A texture's image, decoded (PNG or JPEG, from the file's buffers or a file beside
    /// it); a warning and none when it cannot be read.
    fn texture(&self, texture: &gltf::Texture, warnings: &mut Vec<String>) -> Option<SkinTexture> {
        let image = texture.source();
        let at = format!("{}: at $.images[{}]", self.path.display(), image.index());
        let bytes = match image.source() {
            gltf::image::Source::View { view, .. } => {
                let buffer = self.buffers.get(view.buffer().index())?;
                buffer.get(view.offset()..view.offset() + view.length()).map(<[u8]>::to_vec)
            }
            gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => {
                match super::uri::beside_uri(self.path, uri)
                    .and_then(|f| super::error::read_file(&f).map_err(|e| e.to_string()))
                {
                    Ok(bytes) => Some(bytes),
                    Err(e) => {
                        warnings.push(format!("{at}.uri: the base colour texture is not shown ({e})"));
                        return None;
                    }
                }
            }
            gltf::image::Source::Uri { .. } => None,
        };
        let decoded = bytes
            .ok_or_else(|| "its bytes cannot be read".to_string())
            .and_then(|b| image::load_from_memory(&b).map_err(|e| e.to_string()));
        match decoded {
            Ok(decoded) => {
                let rgba = decoded.to_rgba8();
                let picture = Picture { width: rgba.width(), height: rgba.height(), pixels: rgba.into_raw() };
                Some(SkinTexture::Picture { key: at, picture: std::sync::Arc::new(picture) })
            }
            Err(e) => {
                warnings.push(format!("{at}: the base colour texture is not shown ({e})"));
                None
            }
        }
    }

    /// The file's animations that move the skin's joints, as clips by joint index.
    fn clips(
        &self,
        joints: &[gltf::Node],
        new_index: &[usize],
        root_parent: Mat4,
        warnings: &mut Vec<String>,
    ) -> Result<Vec<NodeClip>, FormatError> {
        let mut clips = Vec::new();
        let joint_of = joint_of_node(self.gltf, joints);
        for animation in self.gltf.animations() {
            let mut tracks = vec![JointTracks::default(); joints.len()];
            let mut moved = false;
            for (c, channel) in animation.channels().enumerate() {
                let node = channel.target().node().index();
                let Some(j) = joint_of[node] else { continue };
                let at = format!("at $.animations[{}].channels[{c}]", animation.index());
                let sampler = format!("at $.animations[{}].samplers[{}]", animation.index(), channel.sampler().index());
                let reader = channel.reader(self.data());
                let times: Vec<f32> = reader
                    .read_inputs()
                    .ok_or_else(|| self.error(format!("{sampler}.input: expected key times, found none")))?
                    .collect();
                if let Some(k) = times.iter().position(|t| !t.is_finite()) {
                    return Err(self
                        .error(format!("{sampler}.input: expected finite key times, found {} at key {k}", times[k])));
                }
                if let Some(k) = times.windows(2).position(|w| w[0].partial_cmp(&w[1]).is_none_or(|o| o.is_gt())) {
                    return Err(self.error(format!(
                        "{sampler}.input: key time {} follows {} (times must increase and be numbers)",
                        times[k + 1],
                        times[k]
                    )));
                }
                let interpolation = match channel.sampler().interpolation() {
                    gltf::animation::Interpolation::Step => Interpolation::Step,
                    gltf::animation::Interpolation::Linear => Interpolation::Linear,
                    gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
                };
                let outputs = reader
                    .read_outputs()
                    .ok_or_else(|| self.error(format!("{sampler}.output: expected key values, found none")))?;
                let joint = &mut tracks[new_index[j]];
                let incomplete = || {
                    self.error(format!("{sampler}: expected a value per key time (three for CUBICSPLINE) and a key, found {} key times", times.len()))
                };
                use gltf::animation::util::ReadOutputs;
                match outputs {
                    ReadOutputs::Translations(v) => {
                        let values: Vec<Vec3> = v.map(Vec3::from).collect();
                        finite_keys(values.iter().map(|v| v.is_finite()), &sampler).map_err(|e| self.error(e))?;
                        let track = Track { times: times.clone(), values, interpolation };
                        joint.translation = Some(track).filter(Track::is_complete).ok_or_else(incomplete).map(Some)?;
                    }
                    ReadOutputs::Rotations(v) => {
                        let values: Vec<Quat> = v.into_f32().map(Quat::from_array).collect();
                        // CUBICSPLINE tangents may be zero; values must be rotations.
                        let rotation = |k: usize, q: &Quat| {
                            q.is_finite()
                                && (interpolation == Interpolation::CubicSpline && k % 3 != 1
                                    || q.length_squared() > 1e-12)
                        };
                        finite_keys(values.iter().enumerate().map(|(k, q)| rotation(k, q)), &sampler)
                            .map_err(|e| self.error(format!("{e} (a rotation that is not zero)")))?;
                        let track = Track { times: times.clone(), values, interpolation };
                        joint.rotation = Some(track).filter(Track::is_complete).ok_or_else(incomplete).map(Some)?;
                    }
                    ReadOutputs::Scales(v) => {
                        let values: Vec<Vec3> = v.map(Vec3::from).collect();
                        finite_keys(values.iter().map(|v| v.is_finite()), &sampler).map_err(|e| self.error(e))?;
                        let track = Track { times: times.clone(), values, interpolation };
                        joint.scale = Some(track).filter(Track::is_complete).ok_or_else(incomplete).map(Some)?;
                    }
                    ReadOutputs::MorphTargetWeights(_) => {
                        warnings.push(format!("{}: {at} keys morph weights, which do not play", self.path.display()));
                        continue;
                    }
                }
                moved = true;
            }
            if moved {
                let name = animation.name().map_or_else(|| format!("animation {}", animation.index()), str::to_string);
                clips.push(NodeClip { name, index: animation.index(), tracks, root_parent });
            }
        }
        Ok(clips)
    }

    /// The global transform of `node` (identity for none), from its parents.
    fn global(&self, node: Option<usize>) -> Mat4 {
        global(self.gltf, &self.parent, node)
    }
}

/// The file split (GLB), parsed, checked by [`gltf_check`](super::gltf_check) and then
/// by the `gltf` crate's own validation: nothing is read through the crate before every
/// index, layout and type it relies on was checked. The binary chunk is returned as a slice
/// of `bytes` (not copied).
fn validated(bytes: &[u8]) -> Result<(gltf::Gltf, Option<&[u8]>), String> {
    let (json, bin) = super::gltf_check::split_glb(bytes)?;
    let root = gltf::json::Root::from_slice(json).map_err(|e| format!("at $: expected glTF 2.0 JSON, {e}"))?;
    super::gltf_check::check(&root, bin)?;
    let document = gltf::Document::from_json(root).map_err(|e| format!("at $: expected valid glTF 2.0, {e}"))?;
    Ok((gltf::Gltf { document, blob: None }, bin))
}

/// `sampler.output: expected finite key values, found … at value k` for the first value
/// that fails.
fn finite_keys(mut good: impl Iterator<Item = bool>, sampler: &str) -> Result<(), String> {
    match good.position(|g| !g) {
        Some(k) => Err(format!("{sampler}.output: expected finite key values, found an unusable one at value {k}")),
        None => Ok(()),
    }
}

/// Each node's joint of the skin `joints` (none for the nodes that are not its joints).
fn joint_of_node(gltf: &gltf::Gltf, joints: &[gltf::Node]) -> Vec<Option<usize>> {
    let mut joint = vec![None; gltf.nodes().len()];
    for (j, node) in joints.iter().enumerate() {
        joint[node.index()] = Some(j);
    }
    joint
}

/// Each node's parent (none for a scene root).
fn parents(gltf: &gltf::Gltf) -> Vec<Option<usize>> {
    let mut parent = vec![None; gltf.nodes().len()];
    for n in gltf.nodes() {
        for c in n.children() {
            parent[c.index()] = Some(n.index());
        }
    }
    parent
}

/// A mesh's morph target names (`extras.targetNames`, as Blender writes them).
fn target_names(mesh: &gltf::Mesh) -> Vec<String> {
    mesh.extras()
        .as_ref()
        .and_then(|raw| serde_json::from_str::<serde_json::Value>(raw.get()).ok())
        .and_then(|v| serde_json::from_value(v.get("targetNames")?.clone()).ok())
        .unwrap_or_default()
}

/// The global transform of `node` (identity for none), from its parents.
fn global(gltf: &gltf::Gltf, parent: &[Option<usize>], node: Option<usize>) -> Mat4 {
    let mut m = Mat4::IDENTITY;
    let mut at = node;
    while let Some(n) = at {
        // The nodes are a forest (checked): the walk ends at a root.
        let Some(node) = gltf.document.nodes().nth(n) else { break };
        m = Mat4::from_cols_array_2d(&node.transform().matrix()) * m;
        at = parent[n];
    }
    m
}

/// The file's buffers: the GLB's binary chunk (borrowed), or `.bin` files beside a `.gltf`.
fn buffers<'a>(gltf: &gltf::Gltf, bin: Option<&'a [u8]>, path: &Path) -> Result<Vec<Cow<'a, [u8]>>, FormatError> {
    gltf.buffers()
        .map(|b| {
            let at = format!("at $.buffers[{}]", b.index());
            let data = match b.source() {
                gltf::buffer::Source::Bin => Cow::Borrowed(bin.ok_or_else(|| {
                    FormatError::other(path, format!("{at}: expected the GLB's binary chunk, found none"))
                })?),
                gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                    return Err(FormatError::other(
                        path,
                        format!("{at}: embedded data URIs are not read; use .glb or a .bin file"),
                    ));
                }
                gltf::buffer::Source::Uri(uri) => {
                    let read = super::uri::beside_uri(path, uri)
                        .and_then(|file| super::error::read_file(&file).map_err(|e| e.to_string()));
                    Cow::Owned(read.map_err(|e| FormatError::other(path, format!("{at}.uri: {e}")))?)
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

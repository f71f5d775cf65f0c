//! FBX import (binary and ASCII), read with the `ufbx` crate: the file's units and axes
//! converted to ours (metres, right-handed, y up), then as glTF import does it: one part
//! whose skeleton is every node a mesh depends on (the skin clusters' bones and the nodes
//! above them, unskinned meshes' nodes, which carry their mesh rigidly), a common root
//! where the file has several root nodes; the clusters' bind matrices; every mesh's
//! polygons triangulated (a vertex per position and texture coordinate), with its skin
//! weights, its blend shapes as morph targets and its materials (base colour, texture,
//! metalness, roughness) as surfaces; each animation stack as a clip (ufbx's baked keys,
//! linear), with blend shape weights where they are keyed.

use std::collections::HashMap;
use std::path::Path;

use glam::{Mat4, Quat, Vec2, Vec3};

use super::checks::is_normalisable;
use super::error::FormatError;
use super::node_tree::{Binding, Tree, TreeNode, TreeSkeleton, tree_skeleton};
use super::part::Part;
use marionette_rig::material::{Material, Surface, TextureRef};
use marionette_rig::node_clip::{Interpolation, JointTracks, NodeClip, Track};
use marionette_rig::{CharacterAsset, MorphTarget, Picture, Skin, SkinTexture, SkinWeights};

/// Whether `path` names an FBX file.
pub fn is_fbx(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("fbx"))
}

/// Loads an FBX file's character (or prop).
pub fn load_fbx(path: &Path) -> Result<Vec<Part>, FormatError> {
    let bytes = super::error::read_file(path)?;
    parse_fbx(&bytes, path)
}

/// The character of an FBX file's bytes (textures are looked for beside `path`).
pub fn parse_fbx(bytes: &[u8], path: &Path) -> Result<Vec<Part>, FormatError> {
    let opts = ufbx::LoadOpts {
        target_axes: ufbx::CoordinateAxes::right_handed_y_up(),
        target_unit_meters: 1.0,
        space_conversion: ufbx::SpaceConversion::ModifyGeometry,
        geometry_transform_handling: ufbx::GeometryTransformHandling::ModifyGeometry,
        inherit_mode_handling: ufbx::InheritModeHandling::Compensate,
        load_external_files: false,
        // A hostile file may ask for any amount of memory: at most 32 MB and 64 bytes a byte
        // of the file for each of ufbx's two allocators.
        temp_allocator: memory_limit(bytes.len()),
        result_allocator: memory_limit(bytes.len()),
        ..Default::default()
    };
    let scene = ufbx::load_memory(bytes, opts)
        .map_err(|e| FormatError::other(path, format!("expected an FBX file, {}", e.description)))?;
    let file = Fbx { scene: &scene, path };
    Ok(vec![file.part()?])
}

fn memory_limit(file_bytes: usize) -> ufbx::AllocatorOpts {
    ufbx::AllocatorOpts { memory_limit: (32 << 20) + 64 * file_bytes, ..Default::default() }
}

struct Fbx<'a> {
    scene: &'a ufbx::Scene,
    path: &'a Path,
}

fn vec3(v: ufbx::Vec3) -> Vec3 {
    Vec3::new(v.x as f32, v.y as f32, v.z as f32)
}

fn quat(q: ufbx::Quat) -> Quat {
    Quat::from_xyzw(q.x as f32, q.y as f32, q.z as f32, q.w as f32)
}

/// A ufbx 3 × 4 affine matrix as ours.
fn mat4(m: &ufbx::Matrix) -> Mat4 {
    Mat4::from_cols_array(&[
        m.m00 as f32,
        m.m10 as f32,
        m.m20 as f32,
        0.0,
        m.m01 as f32,
        m.m11 as f32,
        m.m21 as f32,
        0.0,
        m.m02 as f32,
        m.m12 as f32,
        m.m22 as f32,
        0.0,
        m.m03 as f32,
        m.m13 as f32,
        m.m23 as f32,
        1.0,
    ])
}

/// How a mesh's vertices follow the joints, and the transform that takes them from the
/// mesh's geometry into the asset's bind space.
enum Placed {
    /// By its skin clusters; the transform is the mesh's at rest, the joint the one its
    /// unweighted vertices follow.
    Skinned(Mat4, usize),
    /// Rigidly on a joint, into its bind frame.
    Rigid(usize, Mat4),
}

impl Placed {
    fn to(&self) -> Mat4 {
        match *self {
            Placed::Skinned(m, _) | Placed::Rigid(_, m) => m,
        }
    }
}

/// One mesh corner's vertex: its control point and its texture coordinate's index.
type CornerKey = (u32, u32);

impl Fbx<'_> {
    fn error(&self, message: String) -> FormatError {
        FormatError::other(self.path, message)
    }

    fn node(&self, typed_id: u32) -> &ufbx::Node {
        &self.scene.nodes[typed_id as usize]
    }

    /// The node's parent, none for the children of the scene's root.
    fn parent(&self, node: &ufbx::Node) -> Option<u32> {
        node.parent.as_ref().filter(|p| !p.is_root).map(|p| p.element.typed_id)
    }

    /// The joint a mesh node's unweighted vertices follow: the node's own, or its nearest
    /// ancestor's in the skeleton (the root's where none is).
    fn holder(&self, node: u32, joint_of_node: &[Option<usize>]) -> usize {
        let mut at = Some(node);
        while let Some(n) = at {
            if let Some(j) = joint_of_node[n as usize] {
                return j;
            }
            at = self.parent(self.node(n));
        }
        0
    }

    fn part(&self) -> Result<Part, FormatError> {
        let n = self.scene.nodes.len();
        let mesh_nodes: Vec<u32> =
            self.scene.nodes.iter().filter(|n| n.mesh.is_some() && !n.is_root).map(|n| n.element.typed_id).collect();
        if mesh_nodes.is_empty() {
            return Err(self.error("expected a node with a mesh, found none".into()));
        }
        let mut relevant = vec![false; n];
        let mut mark = |mut at: Option<u32>| {
            while let Some(node) = at.filter(|&t| !relevant[t as usize]) {
                relevant[node as usize] = true;
                at = self.parent(self.node(node));
            }
        };
        for &m in &mesh_nodes {
            let mesh = self.node(m).mesh.as_ref().expect("a mesh node");
            match mesh.skin_deformers.first() {
                Some(skin) => skin
                    .clusters
                    .iter()
                    .filter_map(|c| c.bone_node.as_ref())
                    .for_each(|b| mark(Some(b.element.typed_id))),
                None => mark(Some(m)),
            }
        }
        let stem = self.path.file_stem().and_then(|s| s.to_str()).unwrap_or("fbx").to_string();
        let (clusters, bindings) = self.bindings(&mesh_nodes);
        let roots: Vec<usize> = (0..n).filter(|&t| relevant[t] && self.parent(self.node(t as u32)).is_none()).collect();
        let tree = Tree { name: &stem, node_count: n, roots: &roots, at: "the node tree" };
        let children = |t: usize| {
            self.node(t as u32).children.iter().map(|c| c.element.typed_id as usize).filter(|&c| relevant[c]).collect()
        };
        let TreeSkeleton { skeleton, bind, joint_of_node, skin_joints } =
            tree_skeleton(&tree, |t| Ok(self.tree_node(t as u32)), children, &bindings).map_err(|e| self.error(e))?;
        let cluster_joint: HashMap<u32, usize> = clusters.into_iter().zip(skin_joints.iter().map(|j| j[0])).collect();

        let mut geometry = Geometry::default();
        for &m in &mesh_nodes {
            let node = self.node(m);
            let mesh = node.mesh.as_ref().expect("a mesh node");
            // Skinned vertices go into the model's space at rest; rigid ones into their
            // joint's bind frame.
            let to_model = match joint_of_node[m as usize].filter(|_| mesh.skin_deformers.is_empty()) {
                Some(j) => Placed::Rigid(j, bind[j].inverse()),
                None => Placed::Skinned(mat4(&node.geometry_to_world), self.holder(m, &joint_of_node)),
            };
            self.mesh(node, mesh, &to_model, &cluster_joint, &mut geometry)?;
            if geometry.non_finite || !to_model.to().is_finite() {
                return Err(self.error(format!("mesh `{}`: expected finite vertex positions", node.element.name)));
            }
        }
        let Geometry {
            mut skin,
            texcoords,
            unweighted,
            rows,
            morphs,
            morph_weights,
            morph_channels,
            materials,
            surfaces,
            skinned,
            textured,
            ..
        } = geometry;
        // Coordinates matter where a material shows a texture (as glTF import keeps them).
        if textured && materials.iter().any(|m| m.textures().next().is_some()) {
            skin.texcoords = texcoords;
        }
        let (weights, normalised) =
            SkinWeights::from_rows(rows, skeleton.len()).map_err(|e| self.error(format!("the skin weights: {e}")))?;
        let mut warnings = super::weight_warnings::normalised_warnings(self.path, &normalised);
        for (mesh, count) in unweighted {
            warnings.push(format!(
                "{}: mesh `{mesh}`: {count} vertices have no skin weight; they follow the mesh's node",
                self.path.display()
            ));
        }
        skin.weights = weights;
        let clips = self.clips(&joint_of_node, skeleton.len(), &morph_channels)?;
        let mut asset = CharacterAsset::with_inverse_binds(stem, skeleton, skin, bind, warnings)
            .map_err(|e| FormatError::rig(self.path, e))?;
        if !skinned {
            asset.skin_kind = marionette_rig::character::SkinKind::Rigid;
        }
        asset.morphs = morphs;
        asset.materials = materials;
        asset.surfaces = surfaces;
        Ok(Part { asset, clips, morph_weights })
    }

    /// Each skin cluster of the mesh nodes, as a binding of its bone: the clusters' ids and
    /// bindings in turn.
    fn bindings(&self, mesh_nodes: &[u32]) -> (Vec<u32>, Vec<Binding>) {
        let (mut clusters, mut bindings) = (Vec::new(), Vec::new());
        for &m in mesh_nodes {
            let mesh = self.node(m).mesh.as_ref().expect("a mesh node");
            for cluster in mesh.skin_deformers.first().into_iter().flat_map(|s| s.clusters.iter()) {
                let Some(bone) = cluster.bone_node.as_ref() else { continue };
                // The mesh's vertices go into the model's space (`mesh`), so its binds
                // start from there.
                let mut bind = mat4(&cluster.geometry_to_bone) * mat4(&self.node(m).geometry_to_world).inverse();
                // Affine by construction: its last row exactly so.
                (bind.x_axis.w, bind.y_axis.w, bind.z_axis.w, bind.w_axis.w) = (0.0, 0.0, 0.0, 1.0);
                clusters.push(cluster.element.typed_id);
                let name = &cluster.element.name;
                let (label, at) = (format!("cluster {name}"), format!("the bind matrix of skin cluster `{name}`"));
                bindings.push(Binding { label, at, joints: vec![(bone.element.typed_id as usize, bind)] });
            }
        }
        (clusters, bindings)
    }

    /// A node's name and its local transform.
    fn tree_node(&self, t: u32) -> TreeNode {
        let node = self.node(t);
        let local = &node.local_transform;
        TreeNode {
            name: if node.element.name.is_empty() { format!("node {t}") } else { node.element.name.to_string() },
            translation: vec3(local.translation),
            rotation: quat(local.rotation),
            scale: vec3(local.scale),
        }
    }

    /// Appends a mesh: its corners' vertices (split by texture coordinate), triangles by
    /// material, weights (its clusters', or rigidly `placed` on a joint with the transform
    /// into that joint's bind frame), blend shapes and materials.
    fn mesh(
        &self,
        node: &ufbx::Node,
        mesh: &ufbx::Mesh,
        placed: &Placed,
        cluster_joint: &HashMap<u32, usize>,
        out: &mut Geometry,
    ) -> Result<(), FormatError> {
        let first = out.skin.bind_positions.len();
        out.textured |= mesh.vertex_uv.exists;
        let mut vertex_of: HashMap<CornerKey, u32> = HashMap::new();
        let mut corners_of_point: Vec<Vec<u32>> = vec![Vec::new(); mesh.vertices.len()];
        let has_uv = mesh.vertex_uv.exists;
        let mut corner = |index: usize, vertex_of: &mut HashMap<CornerKey, u32>, out: &mut Geometry| -> u32 {
            let point = mesh.vertex_indices[index];
            let uv = if has_uv { mesh.vertex_uv.indices[index] } else { 0 };
            *vertex_of.entry((point, uv)).or_insert_with(|| {
                let p = vec3(mesh.vertices[point as usize]);
                out.non_finite |= !p.is_finite();
                let v = out.skin.bind_positions.len() as u32;
                out.skin.bind_positions.push(placed.to().transform_point3(p));
                // FBX counts v from the image's bottom row; ours from its top.
                let t = if has_uv { mesh.vertex_uv.values[uv as usize] } else { ufbx::Vec2 { x: 0.0, y: 1.0 } };
                out.texcoords.push(Vec2::new(t.x as f32, 1.0 - t.y as f32));
                corners_of_point[point as usize].push(v);
                v
            })
        };
        // Triangles, material by material (a surface each).
        let mut scratch = vec![0u32; mesh.max_face_triangles * 3];
        let parts: Vec<(Option<usize>, Vec<u32>)> = if mesh.material_parts.is_empty() {
            vec![(None, (0..mesh.faces.len() as u32).collect())]
        } else {
            mesh.material_parts.iter().map(|p| (Some(p.index as usize), p.face_indices.to_vec())).collect()
        };
        for (material, faces) in parts {
            // Each surface has its own vertices.
            vertex_of.clear();
            let ours = material.and_then(|m| mesh.materials.get(m)).map(|m| out.material(self, m));
            let (v0, t0) = (out.skin.bind_positions.len() as u32, out.skin.triangles.len() as u32);
            for f in faces {
                let face = mesh.faces[f as usize];
                let count = mesh.triangulate_face(&mut scratch, face) as usize;
                for t in scratch[..3 * count].chunks_exact(3) {
                    let tri = [t[0], t[1], t[2]].map(|i| corner(i as usize, &mut vertex_of, out));
                    out.skin.triangles.push(tri);
                }
            }
            let vertices = v0..out.skin.bind_positions.len() as u32;
            let triangles = t0..out.skin.triangles.len() as u32;
            marionette_rig::material::push_surface(&mut out.surfaces, Surface { vertices, triangles, material: ours });
        }
        let count = out.skin.bind_positions.len() - first;
        let mut rows: Vec<Vec<(usize, f32)>> = vec![Vec::new(); count];
        match (placed, mesh.skin_deformers.first()) {
            (&Placed::Rigid(joint, _), _) => rows.iter_mut().for_each(|r| r.push((joint, 1.0))),
            (&Placed::Skinned(_, holder), Some(skin)) => {
                out.skinned = true;
                for (point, corners) in corners_of_point.iter().enumerate() {
                    let Some(sv) = skin.vertices.get(point) else { continue };
                    let weights = (sv.weight_begin..sv.weight_begin.saturating_add(sv.num_weights))
                        .filter_map(|i| skin.weights.get(i as usize));
                    for w in weights {
                        let cluster = &skin.clusters[w.cluster_index as usize];
                        let Some(&joint) = cluster_joint.get(&cluster.element.typed_id) else { continue };
                        if w.weight > 0.0 {
                            for &v in corners {
                                rows[v as usize - first].push((joint, w.weight as f32));
                            }
                        }
                    }
                }
                let unweighted = rows.iter().filter(|r| r.is_empty()).count();
                if unweighted > 0 {
                    rows.iter_mut().filter(|r| r.is_empty()).for_each(|r| r.push((holder, 1.0)));
                    out.unweighted.push((node.element.name.to_string(), unweighted));
                }
            }
            (Placed::Skinned(..), None) => {
                return Err(self.error(format!("mesh `{}`: expected a skin or a node", node.element.name)));
            }
        }
        out.rows.extend(rows);
        self.blend_shapes(mesh, &corners_of_point, placed.to(), out);
        Ok(())
    }

    /// The mesh's blend channels as morph targets (each channel's full-weight shape, moved
    /// onto every vertex of its control points) with their weights.
    fn blend_shapes(&self, mesh: &ufbx::Mesh, corners: &[Vec<u32>], to: Mat4, out: &mut Geometry) {
        for deformer in mesh.blend_deformers.iter() {
            for channel in deformer.channels.iter() {
                let Some(key) = channel.keyframes.last() else { continue };
                let shape = &key.shape;
                let mut deltas = Vec::new();
                for (i, &point) in shape.offset_vertices.iter().enumerate() {
                    let d = vec3(shape.position_offsets[i]);
                    let d = to.transform_vector3(d);
                    if d != Vec3::ZERO && d.is_finite() {
                        deltas.extend(corners.get(point as usize).into_iter().flatten().map(|&v| (v, d)));
                    }
                }
                deltas.sort_by_key(|&(v, _)| v);
                out.morph_channels.push((channel.element.element_id, out.morphs.len()));
                out.morphs.push(MorphTarget { name: channel.element.name.to_string(), deltas });
                let w = channel.weight as f32;
                out.morph_weights.push(if w.is_finite() { w } else { 0.0 });
            }
        }
    }

    /// Each animation stack as a clip: ufbx's baked keys of the part's nodes (linear)
    /// and of the blend channels' weights (`DeformPercent`).
    fn clips(
        &self,
        joint_of_node: &[Option<usize>],
        joints: usize,
        morph_channels: &[(u32, usize)],
    ) -> Result<Vec<NodeClip>, FormatError> {
        let mut clips = Vec::new();
        for stack in self.scene.anim_stacks.iter() {
            let opts = ufbx::BakeOpts { trim_start_time: true, ..Default::default() };
            let baked = ufbx::bake_anim(self.scene, &stack.anim, opts)
                .map_err(|e| self.error(format!("animation stack `{}`: {}", stack.element.name, e.description)))?;
            let mut tracks = vec![JointTracks::default(); joints];
            // Baked from the stack's start (`trim_start_time`).
            let time = |t: f64| t as f32;
            for node in baked.nodes.iter() {
                let Some(j) = joint_of_node.get(node.typed_id as usize).copied().flatten() else { continue };
                // A curve of one key is constant, yet it sets the node's value: a track
                // wherever its value is not the node's own.
                let local = &self.node(node.typed_id).local_transform;
                let moves_from = |keys: &[ufbx::BakedVec3], own: ufbx::Vec3| {
                    keys.iter().any(|k| vec3(k.value).distance(vec3(own)) > 1e-6 * vec3(own).length().max(1.0))
                };
                let turns_from = |keys: &[ufbx::BakedQuat], own: ufbx::Quat| {
                    keys.iter().any(|k| quat(k.value).dot(quat(own)).abs() < 1.0 - 1e-7)
                };
                if !node.constant_translation || moves_from(&node.translation_keys, local.translation) {
                    let keys = &node.translation_keys;
                    tracks[j].translation = Some(linear_track(
                        keys.iter().map(|k| time(k.time)).collect(),
                        keys.iter().map(|k| vec3(k.value)).collect(),
                    ));
                }
                if !node.constant_rotation || turns_from(&node.rotation_keys, local.rotation) {
                    let keys = &node.rotation_keys;
                    tracks[j].rotation = Some(linear_track(
                        keys.iter().map(|k| time(k.time)).collect(),
                        keys.iter().map(|k| quat(k.value)).collect(),
                    ));
                }
                if !node.constant_scale || moves_from(&node.scale_keys, local.scale) {
                    let keys = &node.scale_keys;
                    tracks[j].scale = Some(linear_track(
                        keys.iter().map(|k| time(k.time)).collect(),
                        keys.iter().map(|k| vec3(k.value)).collect(),
                    ));
                }
            }
            let mut weights = vec![None; morph_channels.len()];
            for element in baked.elements.iter() {
                let Some(&(_, m)) = morph_channels.iter().find(|(id, _)| *id == element.element_id) else { continue };
                if let Some(prop) = element.props.iter().find(|p| p.name == "DeformPercent" && !p.constant_value) {
                    let times = prop.keys.iter().map(|k| time(k.time)).collect();
                    weights[m] = Some(Track {
                        times,
                        values: prop.keys.iter().map(|k| k.value.x as f32 / 100.0).collect(),
                        interpolation: Interpolation::Linear,
                    });
                }
            }
            let tracks_ok = tracks.iter().all(|t| {
                t.translation.as_ref().is_none_or(|k| k.is_complete() && k.values.iter().all(|v| v.is_finite()))
                    && t.rotation
                        .as_ref()
                        .is_none_or(|k| k.is_complete() && k.values.iter().all(|q| is_normalisable(*q)))
                    && t.scale.as_ref().is_none_or(|k| k.is_complete() && k.values.iter().all(|v| v.is_finite()))
            });
            let times_ok = tracks
                .iter()
                .flat_map(|t| {
                    [
                        t.translation.as_ref().map(|k| &k.times),
                        t.rotation.as_ref().map(|k| &k.times),
                        t.scale.as_ref().map(|k| &k.times),
                    ]
                })
                .flatten()
                .all(|ts| ts.iter().all(|t| t.is_finite()) && ts.windows(2).all(|w| w[0] <= w[1]));
            if !tracks_ok || !times_ok {
                return Err(self.error(format!(
                    "animation stack `{}`: expected finite keys at increasing times",
                    stack.element.name
                )));
            }
            // Numbered among the clips kept (as a glTF file's animations are), from 0.
            let number = clips.len();
            let name = if stack.element.name.is_empty() {
                format!("animation {number}")
            } else {
                stack.element.name.to_string()
            };
            let moves = tracks.iter().any(|t| t != &JointTracks::default()) || weights.iter().any(Option::is_some);
            if moves {
                clips.push(NodeClip { name, index: number, tracks, weights, root_parent: Mat4::IDENTITY });
            }
        }
        Ok(clips)
    }
}

/// What the meshes add up to, gathered mesh by mesh.
#[derive(Default)]
struct Geometry {
    skin: Skin,
    texcoords: Vec<Vec2>,
    rows: Vec<Vec<(usize, f32)>>,
    morphs: Vec<MorphTarget>,
    morph_weights: Vec<f32>,
    /// Each blend channel's element id and morph.
    morph_channels: Vec<(u32, usize)>,
    materials: Vec<Material>,
    /// Our material of each of the file's, by element id.
    material_of: HashMap<u32, usize>,
    surfaces: Vec<Surface>,
    skinned: bool,
    /// Whether a mesh has texture coordinates.
    textured: bool,
    /// Whether a vertex position was not finite.
    non_finite: bool,
    /// Per mesh with vertices no cluster weighs: its name and how many.
    unweighted: Vec<(String, usize)>,
}

impl Geometry {
    /// Our material for the file's `m` (made once).
    fn material(&mut self, file: &Fbx, m: &ufbx::Material) -> usize {
        if let Some(&ours) = self.material_of.get(&m.element.element_id) {
            return ours;
        }
        let pbr = &m.pbr;
        let c = pbr.base_color.value_vec4;
        let factor = if pbr.base_factor.has_value { pbr.base_factor.value_vec4.x as f32 } else { 1.0 };
        let number = |map: &ufbx::MaterialMap, default: f32| {
            let v = map.value_vec4.x as f32;
            if map.has_value && v.is_finite() { v } else { default }
        };
        let mut base_color = [c.x as f32 * factor, c.y as f32 * factor, c.z as f32 * factor, 1.0];
        if !base_color.iter().all(|x| x.is_finite()) {
            base_color = [1.0; 4];
        }
        let material = Material {
            name: m.element.name.to_string(),
            base_color,
            base_color_texture: pbr.base_color.texture.as_ref().and_then(|t| file.texture(t)).map(TextureRef::plain),
            metallic: number(&pbr.metalness, 0.0),
            roughness: number(&pbr.roughness, 0.5),
            ..Material::default()
        };
        self.materials.push(material);
        self.material_of.insert(m.element.element_id, self.materials.len() - 1);
        self.materials.len() - 1
    }
}

impl Fbx<'_> {
    /// A texture's image: embedded in the file, or a file beside it; none when neither
    /// can be read.
    fn texture(&self, t: &ufbx::Texture) -> Option<SkinTexture> {
        let bytes = if t.content.size > 0 {
            t.content.to_vec()
        } else {
            let file = super::uri::inside_folder(self.path, &t.relative_filename.replace('\\', "/")).ok()?;
            super::error::read_file(&file).ok()?
        };
        let rgba = image::load_from_memory(&bytes).ok()?.to_rgba8();
        let picture = Picture { width: rgba.width(), height: rgba.height(), pixels: rgba.into_raw() };
        let key = format!("{}: texture {}", self.path.display(), t.element.element_id);
        Some(SkinTexture::Picture { key, picture: std::sync::Arc::new(picture) })
    }
}

/// A linear track of `values` at `times`.
fn linear_track<T>(times: Vec<f32>, values: Vec<T>) -> Track<T> {
    Track { times, values, interpolation: Interpolation::Linear }
}

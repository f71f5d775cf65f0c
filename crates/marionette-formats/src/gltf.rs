//! glTF 2.0 export (`.glb`): every character as a skinned mesh with its skeleton — joints
//! as nodes in their hierarchy, the pose as their rotations, inverse bind matrices, all
//! influences as `JOINTS_n`/`WEIGHTS_n` sets of four — under a node that places it, its tint
//! as its material. Or, baked, the posed mesh alone. Written with `serde_json`: the format
//! is plain JSON and one binary buffer.

use glam::{Mat4, Quat, Vec3};
use serde_json::{Value, json};

use marionette_rig::node_clip::{Interpolation, NodeClip, Track};
use marionette_rig::{CharacterAsset, JointRotation};

/// One character to write.
pub struct GltfCharacter<'a> {
    pub name: &'a str,
    pub asset: &'a CharacterAsset,
    pub pose: &'a [JointRotation],
    /// The root joint's translation in model space (its offset unless a clip moves it).
    pub root: Vec3,
    /// Rest offsets and scales a clip keys, in place of the skeleton's (the root's offset
    /// is `root`).
    pub rest: marionette_rig::fk::RestOverride<'a>,
    /// Model space → world.
    pub placement: crate::scene::PlacementDoc,
    pub tint: [f32; 3],
    /// Poses over time, written as a glTF animation of the joints (skinned meshes only),
    /// under `motion_name` (the character's name when empty).
    pub motion: Option<Motion>,
    pub motion_name: String,
    /// Clips of the joints and morph weights, each written key for key as its own
    /// animation (skinned meshes only).
    pub clips: &'a [NodeClip],
    /// The morph targets' weights (the mesh's `weights`; missing ones are 0).
    pub morph_weights: &'a [f32],
}

impl<'a> GltfCharacter<'a> {
    /// `asset` in `pose` at the origin (unturned, unscaled, its root at its offset), in the
    /// editor's default skin colour, without motion.
    pub fn new(name: &'a str, asset: &'a CharacterAsset, pose: &'a [JointRotation]) -> Self {
        let root = asset.skeleton.joints().first().map_or(Vec3::ZERO, |j| j.rest_offset);
        Self {
            name,
            asset,
            pose,
            root,
            rest: Default::default(),
            placement: Default::default(),
            tint: [0.85, 0.75, 0.62],
            motion: None,
            motion_name: String::new(),
            clips: &[],
            morph_weights: &[],
        }
    }
}

/// A character's motion sampled at `times` (seconds): each time's pose (one rotation per
/// joint) and root translation.
#[derive(Debug, Clone, Default)]
pub struct Motion {
    pub times: Vec<f32>,
    pub poses: Vec<Vec<JointRotation>>,
    pub roots: Vec<Vec3>,
    /// Each time's rest offsets and scales of every joint, where the clip keys them (empty:
    /// the skeleton's; the root's offset is `roots`).
    pub rests: Vec<(Vec<Vec3>, Vec<Vec3>)>,
}

/// How the meshes go out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GltfMesh {
    /// Bind mesh, skin and skeleton: it deforms wherever it is opened.
    Skinned,
    /// The skinned, posed vertices and no skin.
    Baked,
}

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;

/// The JSON document and its binary buffer, filled together.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    nodes: Vec<Value>,
    /// The first float accessor that holds a number that is not finite.
    non_finite: Option<usize>,
}

impl Builder {
    /// Appends `bytes` as a buffer view (4-byte aligned) and an accessor over it; returns
    /// the accessor's index.
    fn accessor(&mut self, bytes: &[u8], target: Option<u32>, mut accessor: Value) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut view = json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len() });
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        if accessor["componentType"] == json!(FLOAT)
            && self.non_finite.is_none()
            && bytes.chunks_exact(4).any(|f| !f32::from_le_bytes([f[0], f[1], f[2], f[3]]).is_finite())
        {
            self.non_finite = Some(self.accessors.len());
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(view);
        accessor["bufferView"] = json!(self.views.len() - 1);
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Appends `bytes` as a buffer view (4-byte aligned, no accessor: an image); returns
    /// its index.
    fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len() }));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    fn positions(&mut self, points: &[Vec3]) -> usize {
        let (lo, hi) = marionette_rig::skinning::bounds(points);
        let bytes: Vec<u8> = points.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
        let accessor = json!({ "componentType": FLOAT, "count": points.len(), "type": "VEC3",
            "min": lo.to_array(), "max": hi.to_array() });
        self.accessor(&bytes, Some(ARRAY_BUFFER), accessor)
    }

    fn node(&mut self, node: Value) -> usize {
        self.nodes.push(node);
        self.nodes.len() - 1
    }
}

/// The characters as one binary glTF file, or where it would hold a number that is not
/// finite (a NaN pose or position: nothing is written then).
pub fn write_glb(characters: &[GltfCharacter], mesh: GltfMesh) -> Result<Vec<u8>, String> {
    let mut b = Builder::default();
    let (mut meshes, mut skins, mut roots) = (Vec::new(), Vec::new(), Vec::new());
    let mut looks = super::gltf_out_materials::Materials::default();
    let mut animations = Vec::new();
    for c in characters {
        let placement = b.node(json!({
            "name": c.name,
            "translation": c.placement.translation.to_array(),
            "rotation": c.placement.rotation().to_array(),
            "scale": Vec3::splat(c.placement.scale).to_array(),
        }));
        roots.push(placement);
        let skin = &c.asset.skin;
        let mut children = Vec::new();
        let mut mesh_node = json!({ "name": format!("{} mesh", c.name), "mesh": meshes.len() });
        let positions = match mesh {
            GltfMesh::Baked => {
                let (skeleton, binds) = (&c.asset.skeleton, &c.asset.bind_world_to_joint);
                let palette =
                    marionette_rig::fk::posed_palette_with_rest(skeleton, binds, c.pose, c.rest, root_origin(c));
                let mut posed = vec![Vec3::ZERO; skin.bind_positions.len()];
                marionette_rig::lbs::skin(&skin.bind_positions, &skin.weights, &palette, &mut posed);
                std::borrow::Cow::Owned(posed)
            }
            GltfMesh::Skinned if is_prop(c.asset) => {
                let (top, joints) = skeleton_nodes(&mut b, c);
                children.push(top);
                let morph_nodes = prop_meshes(&mut b, &mut looks, c, &joints, &mut meshes);
                for clip in c.clips {
                    animations.push(clip_animation(&mut b, clip, &joints, &morph_nodes, c.morph_weights));
                }
                b.nodes[placement]["children"] = json!(children);
                continue;
            }
            GltfMesh::Skinned => {
                let (top, joints) = skeleton_nodes(&mut b, c);
                children.push(top);
                // Inverse binds are affine: their last row goes out exactly (0, 0, 0, 1).
                let affine = |m: &Mat4| Mat4::from(glam::Affine3A::from_mat4(*m)).to_cols_array();
                let inverse: Vec<u8> =
                    c.asset.bind_world_to_joint.iter().flat_map(affine).flat_map(f32::to_le_bytes).collect();
                let ibm = b.accessor(
                    &inverse,
                    None,
                    json!({ "componentType": FLOAT, "count": joints.len(), "type": "MAT4" }),
                );
                if let Some(motion) = c.motion.as_ref().filter(|m| !m.times.is_empty()) {
                    let name = if c.motion_name.is_empty() { c.name } else { &c.motion_name };
                    animations.push(animation(&mut b, name, motion, &joints));
                }
                // The mesh node is the next node written.
                let morph_nodes = [MorphNode { node: b.nodes.len(), morphs: (0..c.asset.morphs.len()).collect() }];
                for clip in c.clips {
                    animations.push(clip_animation(&mut b, clip, &joints, &morph_nodes, c.morph_weights));
                }
                mesh_node["skin"] = json!(skins.len());
                skins.push(
                    json!({ "name": c.name, "joints": joints, "skeleton": joints[0], "inverseBindMatrices": ibm }),
                );
                std::borrow::Cow::Borrowed(&skin.bind_positions[..])
            }
        };
        let all = Piece {
            vertices: 0..positions.len(),
            to_node: Mat4::IDENTITY,
            morphs: (0..c.asset.morphs.len()).collect(),
        };
        let morphs = if mesh == GltfMesh::Skinned { &all.morphs[..] } else { &[] };
        let primitives =
            surface_primitives(&mut b, &mut looks, c, &positions, mesh, &Piece { morphs: morphs.to_vec(), ..all });
        meshes.push(mesh_json(c, primitives, morphs));
        // A skinned mesh's node sits at the scene's root (its skeleton places it); a baked
        // one under the placement.
        let mesh_index = b.node(mesh_node);
        match mesh {
            GltfMesh::Skinned => roots.push(mesh_index),
            GltfMesh::Baked => children.push(mesh_index),
        }
        if !children.is_empty() {
            b.nodes[placement]["children"] = json!(children);
        }
    }
    let mut doc = json!({
        "asset": { "version": "2.0", "generator": "marionette" },
        "scene": 0,
        "scenes": [{ "nodes": roots }],
        "nodes": b.nodes,
        "meshes": meshes,
        "materials": looks.materials,
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{ "byteLength": b.bin.len() }],
    });
    if !skins.is_empty() {
        doc["skins"] = json!(skins);
    }
    if !animations.is_empty() {
        doc["animations"] = json!(animations);
    }
    for (key, list) in [("textures", looks.textures), ("images", looks.images), ("samplers", looks.samplers)] {
        if !list.is_empty() {
            doc[key] = json!(list);
        }
    }
    let used: Vec<&str> = [("KHR_texture_transform", looks.transformed), ("KHR_materials_unlit", looks.unlit)]
        .into_iter()
        .filter_map(|(name, used)| used.then_some(name))
        .collect();
    if !used.is_empty() {
        doc["extensionsUsed"] = json!(used);
    }
    if let Some(a) = b.non_finite {
        return Err(format!("at $.accessors[{a}]: the glTF would hold a number that is not finite"));
    }
    // serde_json writes a NaN or infinite number as null: no array of a glTF file holds one.
    if let Some(at) = null_in_array(&doc, "$") {
        return Err(format!("at {at}: the glTF would hold a number that is not finite"));
    }
    Ok(glb(&serde_json::to_vec(&doc).expect("a JSON value serialises"), &b.bin))
}

/// The path of the first null inside an array of `value` (where a non-finite number went).
fn null_in_array(value: &Value, at: &str) -> Option<String> {
    match value {
        Value::Array(items) => items.iter().enumerate().find_map(|(i, v)| match v {
            Value::Null => Some(format!("{at}[{i}]")),
            v => null_in_array(v, &format!("{at}[{i}]")),
        }),
        Value::Object(fields) => fields.iter().find_map(|(k, v)| null_in_array(v, &format!("{at}.{k}"))),
        _ => None,
    }
}

/// A glTF animation of the joint nodes `joints`: every joint's rotation and the root's
/// translation at the motion's times, linear between them.
fn animation(b: &mut Builder, name: &str, motion: &Motion, joints: &[usize]) -> Value {
    let floats = |v: &mut dyn Iterator<Item = f32>| v.flat_map(f32::to_le_bytes).collect::<Vec<u8>>();
    let (first, last) = (motion.times[0], motion.times[motion.times.len() - 1]);
    let input = b.accessor(
        &floats(&mut motion.times.iter().copied()),
        None,
        json!({ "componentType": FLOAT, "count": motion.times.len(), "type": "SCALAR", "min": [first], "max": [last] }),
    );
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    let mut add = |b: &mut Builder, node: usize, path: &str, values: Vec<u8>, kind: &str| {
        let output =
            b.accessor(&values, None, json!({ "componentType": FLOAT, "count": motion.times.len(), "type": kind }));
        samplers.push(json!({ "input": input, "output": output, "interpolation": "LINEAR" }));
        channels.push(json!({ "sampler": samplers.len() - 1, "target": { "node": node, "path": path } }));
    };
    add(b, joints[0], "translation", floats(&mut motion.roots.iter().flat_map(|r| r.to_array())), "VEC3");
    for (j, &node) in joints.iter().enumerate() {
        // Each quaternion on the side of the previous one: linear blending takes the short way.
        let mut previous = Quat::IDENTITY;
        let rotations = motion.poses.iter().map(|pose| {
            let q = pose.get(j).map_or(Quat::IDENTITY, JointRotation::to_quat);
            previous = if q.dot(previous) < 0.0 { -q } else { q };
            previous
        });
        let bytes = floats(&mut rotations.flat_map(|q| q.to_array()));
        add(b, node, "rotation", bytes, "VEC4");
        if !motion.rests.is_empty() {
            if j > 0 {
                let offsets = motion.rests.iter().flat_map(|(o, _)| o[j].to_array());
                add(b, node, "translation", floats(&mut offsets.into_iter()), "VEC3");
            }
            let scales = motion.rests.iter().flat_map(|(_, s)| s[j].to_array());
            add(b, node, "scale", floats(&mut scales.into_iter()), "VEC3");
        }
    }
    json!({ "name": name, "samplers": samplers, "channels": channels })
}

/// Where the matrix stack starts for a character: its root moved from its offset to `root`.
fn root_origin(c: &GltfCharacter) -> Mat4 {
    Mat4::from_translation(c.root - c.asset.skeleton.joint(0).rest_offset)
}

/// The joints as nodes (translation: the rest offset, the root's at `root`; rotation: the
/// pose; scale: the rest scale; a clip's keyed rest in their place), linked parent to
/// child: the node at their top and their node indices in joint order. Where the clips key
/// the root in a frame of nodes folded into it on import (`NodeClip::root_parent`), that
/// frame goes out as a node above the root, so its keys go out as they are.
fn skeleton_nodes(b: &mut Builder, c: &GltfCharacter) -> (usize, Vec<usize>) {
    let skeleton = &c.asset.skeleton;
    let frame = c.clips.first().map_or(Mat4::IDENTITY, |k| k.root_parent);
    let framed = frame != Mat4::IDENTITY;
    let first = b.nodes.len() + usize::from(framed);
    if framed {
        let (s, r, t) = frame.to_scale_rotation_translation();
        b.node(json!({ "name": format!("{} frame", c.name), "translation": t.to_array(),
            "rotation": r.to_array(), "scale": s.to_array(), "children": [first] }));
    }
    for (j, def) in skeleton.joints().iter().enumerate() {
        let translation = if j == 0 { c.root } else { c.rest.offsets.map_or(def.rest_offset, |o| o[j]) };
        let scale = c.rest.scales.map_or(def.rest_scale, |s| s[j]);
        let rotation = c.pose.get(j).map_or(Quat::IDENTITY, JointRotation::to_quat);
        let (scale, rotation, translation) = if j == 0 && framed {
            let local = Mat4::from_scale_rotation_translation(scale, rotation, translation);
            (frame.inverse() * local).to_scale_rotation_translation()
        } else {
            (scale, rotation, translation)
        };
        let mut node =
            json!({ "name": def.name, "translation": translation.to_array(), "rotation": rotation.to_array() });
        if scale != Vec3::ONE {
            node["scale"] = json!(scale.to_array());
        }
        let children: Vec<usize> = skeleton.children(j).iter().map(|&k| first + k).collect();
        if !children.is_empty() {
            node["children"] = json!(children);
        }
        b.node(node);
    }
    (first - usize::from(framed), (first..first + skeleton.len()).collect())
}

/// One primitive per surface of the character: its own vertices (`positions`, with
/// weights, coordinates, colours and morph deltas for a skinned mesh), its triangles
/// counted from its first vertex, and its material (the asset's, or the tint).
fn surface_primitives(
    b: &mut Builder,
    looks: &mut super::gltf_out_materials::Materials,
    c: &GltfCharacter,
    positions: &[Vec3],
    mesh: GltfMesh,
    piece: &Piece,
) -> Vec<Value> {
    let skin = &c.asset.skin;
    let skinned = mesh == GltfMesh::Skinned && !is_prop(c.asset);
    let sets = if skinned { influence_sets(c.asset) } else { Vec::new() };
    let mut ours: std::collections::HashMap<Option<usize>, usize> = std::collections::HashMap::new();
    let mut primitives = Vec::new();
    // A surface without triangles draws nothing (and glTF has no empty accessors).
    for surface in c.asset.surfaces().iter().filter(|s| !s.triangles.is_empty() && !s.vertices.is_empty()) {
        let first = (surface.vertices.start as usize).max(piece.vertices.start);
        let end = (surface.vertices.end as usize).min(piece.vertices.end);
        if first >= end {
            continue;
        }
        let count = end - first;
        let mut attributes = serde_json::Map::new();
        let local: Vec<Vec3> = positions[first..end].iter().map(|&p| piece.to_node.transform_point3(p)).collect();
        attributes.insert("POSITION".into(), json!(b.positions(&local)));
        for (set, (joints, weights)) in sets.iter().enumerate() {
            let j = b.accessor(
                &joints[first * 8..end * 8],
                Some(ARRAY_BUFFER),
                json!({ "componentType": UNSIGNED_SHORT, "count": count, "type": "VEC4" }),
            );
            let w = b.accessor(
                &weights[first * 16..end * 16],
                Some(ARRAY_BUFFER),
                json!({ "componentType": FLOAT, "count": count, "type": "VEC4" }),
            );
            attributes.insert(format!("JOINTS_{set}"), json!(j));
            attributes.insert(format!("WEIGHTS_{set}"), json!(w));
        }
        if let Some(uv) = skin.texcoords.get(first..end) {
            let bytes: Vec<u8> = uv.iter().flat_map(|t| t.to_array()).flat_map(f32::to_le_bytes).collect();
            let a = b.accessor(
                &bytes,
                Some(ARRAY_BUFFER),
                json!({ "componentType": FLOAT, "count": count, "type": "VEC2" }),
            );
            attributes.insert("TEXCOORD_0".into(), json!(a));
        }
        if let Some(colors) = skin.colors.get(first..end) {
            let bytes: Vec<u8> = colors.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
            let a = b.accessor(
                &bytes,
                Some(ARRAY_BUFFER),
                json!({ "componentType": FLOAT, "count": count, "type": "VEC4" }),
            );
            attributes.insert("COLOR_0".into(), json!(a));
        }
        // The surface's triangles among this piece's vertices.
        let triangles: Vec<&[u32; 3]> = skin.triangles
            [surface.triangles.start as usize..surface.triangles.end as usize]
            .iter()
            .filter(|t| (first..end).contains(&(t[0] as usize)))
            .collect();
        if triangles.is_empty() {
            continue;
        }
        let indices: Vec<u8> =
            triangles.iter().flat_map(|t| t.iter()).flat_map(|&i| (i - first as u32).to_le_bytes()).collect();
        let index_accessor = b.accessor(
            &indices,
            Some(ELEMENT_ARRAY_BUFFER),
            json!({ "componentType": UNSIGNED_INT, "count": triangles.len() * 3, "type": "SCALAR" }),
        );
        let material = *ours.entry(surface.material).or_insert_with(|| {
            match surface.material.and_then(|m| c.asset.materials.get(m)) {
                Some(m) => looks.material(m, &mut |bytes| b.view(bytes)),
                None => looks.tint(c.name, c.tint),
            }
        });
        let mut primitive = json!({ "attributes": attributes, "indices": index_accessor, "material": material });
        if !piece.morphs.is_empty() {
            primitive["targets"] = json!(morph_targets(b, c.asset, piece, first..end));
        }
        primitives.push(primitive);
    }
    primitives
}

/// The piece's morph targets as glTF targets: each one's position deltas for the vertices
/// `range`, in the piece's node frame.
fn morph_targets(b: &mut Builder, asset: &CharacterAsset, piece: &Piece, range: std::ops::Range<usize>) -> Vec<Value> {
    piece
        .morphs
        .iter()
        .map(|&m| {
            let mut deltas = vec![Vec3::ZERO; range.len()];
            for &(v, d) in asset.morphs[m].deltas.iter().filter(|(v, _)| range.contains(&(*v as usize))) {
                deltas[v as usize - range.start] = piece.to_node.transform_vector3(d);
            }
            json!({ "POSITION": b.positions(&deltas) })
        })
        .collect()
}

/// Vertices of an asset that go out as one glTF mesh: their range, the transform from the
/// asset's bind space into the frame of the node that carries them, and the morphs they have.
struct Piece {
    vertices: std::ops::Range<usize>,
    to_node: Mat4,
    morphs: Vec<usize>,
}

/// A mesh of `primitives` with the morphs' weights and names (`extras.targetNames`).
fn mesh_json(c: &GltfCharacter, primitives: Vec<Value>, morphs: &[usize]) -> Value {
    let mut mesh = json!({ "name": c.name, "primitives": primitives });
    if !morphs.is_empty() {
        let weights: Vec<f32> = morphs.iter().map(|&m| c.morph_weights.get(m).copied().unwrap_or(0.0)).collect();
        mesh["weights"] = json!(weights);
        mesh["extras"] = json!({ "targetNames": morphs.iter().map(|&m| &c.asset.morphs[m].name).collect::<Vec<_>>() });
    }
    mesh
}

/// Whether `asset` is a prop: meshes carried rigidly by their nodes (one influence of
/// weight 1 per vertex; a prop rebound by bone heat is skinned).
fn is_prop(asset: &CharacterAsset) -> bool {
    asset.skin_kind == marionette_rig::character::SkinKind::Rigid && asset.skin.weights.max_influences() <= 1
}

/// A prop's meshes, unskinned, each on the node of the joint that carries its vertices (in
/// that joint's frame: its inverse bind applied), as the file it came from had them; the
/// nodes whose meshes have morph targets.
fn prop_meshes(
    b: &mut Builder,
    looks: &mut super::gltf_out_materials::Materials,
    c: &GltfCharacter,
    joints: &[usize],
    meshes: &mut Vec<Value>,
) -> Vec<MorphNode> {
    let asset = c.asset;
    let joint_of = |v: usize| asset.skin.weights.of_vertex(v).first().map_or(0, |i| i.joint as usize);
    // Each joint's runs of vertices, joints in the order their vertices come.
    let mut runs: Vec<(usize, Vec<std::ops::Range<usize>>)> = Vec::new();
    let mut start = 0;
    while start < asset.vertex_count() {
        let joint = joint_of(start);
        let end = (start..asset.vertex_count()).find(|&v| joint_of(v) != joint).unwrap_or(asset.vertex_count());
        match runs.iter_mut().find(|(j, _)| *j == joint) {
            Some((_, ranges)) => ranges.push(start..end),
            None => runs.push((joint, std::iter::once(start..end).collect())),
        }
        start = end;
    }
    let mut morph_nodes = Vec::new();
    for (joint, ranges) in runs {
        let within = |v: u32| ranges.iter().any(|r| r.contains(&(v as usize)));
        let morphs: Vec<usize> = (0..asset.morphs.len())
            .filter(|&m| asset.morphs[m].deltas.first().is_some_and(|(v, _)| within(*v)))
            .collect();
        let to_node = asset.bind_world_to_joint[joint];
        let primitives: Vec<Value> = ranges
            .iter()
            .flat_map(|r| {
                let piece = Piece { vertices: r.clone(), to_node, morphs: morphs.clone() };
                surface_primitives(b, looks, c, &asset.skin.bind_positions, GltfMesh::Skinned, &piece)
            })
            .collect();
        if primitives.is_empty() {
            continue;
        }
        b.nodes[joints[joint]]["mesh"] = json!(meshes.len());
        meshes.push(mesh_json(c, primitives, &morphs));
        if !morphs.is_empty() {
            morph_nodes.push(MorphNode { node: joints[joint], morphs });
        }
    }
    morph_nodes
}

/// A node that carries a mesh with morph targets, and the asset's morphs its mesh has.
struct MorphNode {
    node: usize,
    morphs: Vec<usize>,
}

/// A clip as a glTF animation, key for key: each track with its own key times and
/// interpolation; the morph weights as one channel per node whose mesh has them (their
/// tracks combined: each keyed at the union of their key times, the unkeyed at `weights`).
fn clip_animation(
    b: &mut Builder,
    clip: &NodeClip,
    joints: &[usize],
    morph_nodes: &[MorphNode],
    weights: &[f32],
) -> Value {
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    let mut add =
        |b: &mut Builder, node: usize, path: &str, times: &[f32], values: Vec<f32>, kind: &str, i: Interpolation| {
            let (first, last) = (times[0], times[times.len() - 1]);
            let input = b.accessor(
            &times.iter().flat_map(|t| t.to_le_bytes()).collect::<Vec<u8>>(),
            None,
            json!({ "componentType": FLOAT, "count": times.len(), "type": "SCALAR", "min": [first], "max": [last] }),
        );
            let width = if kind == "VEC4" {
                4
            } else if kind == "VEC3" {
                3
            } else {
                1
            };
            let count = if kind == "SCALAR" { values.len() } else { values.len() / width };
            let output = b.accessor(
                &values.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>(),
                None,
                json!({ "componentType": FLOAT, "count": count, "type": kind }),
            );
            samplers.push(json!({ "input": input, "output": output, "interpolation": interpolation_name(i) }));
            channels.push(json!({ "sampler": samplers.len() - 1, "target": { "node": node, "path": path } }));
        };
    for (tracks, &node) in clip.tracks.iter().zip(joints) {
        let flat = |values: &mut dyn Iterator<Item = f32>| values.collect::<Vec<f32>>();
        let keyed = [
            tracks.translation.as_ref().map(|t| {
                (
                    "translation",
                    &t.times,
                    flat(&mut t.values.iter().flat_map(|v| v.to_array())),
                    "VEC3",
                    t.interpolation,
                )
            }),
            tracks.rotation.as_ref().map(|t| {
                ("rotation", &t.times, flat(&mut t.values.iter().flat_map(|q| q.to_array())), "VEC4", t.interpolation)
            }),
            tracks.scale.as_ref().map(|t| {
                ("scale", &t.times, flat(&mut t.values.iter().flat_map(|v| v.to_array())), "VEC3", t.interpolation)
            }),
        ];
        for (path, times, values, kind, interpolation) in keyed.into_iter().flatten() {
            add(b, node, path, times, values, kind, interpolation);
        }
    }
    for group in morph_nodes {
        let tracks: Vec<Option<Track<f32>>> =
            group.morphs.iter().map(|&m| clip.weights.get(m).cloned().flatten()).collect();
        let base: Vec<f32> = group.morphs.iter().map(|&m| weights.get(m).copied().unwrap_or(0.0)).collect();
        if let Some((times, values, interpolation)) = combined_weights(&tracks, &base) {
            add(b, group.node, "weights", &times, values, "SCALAR", interpolation);
        }
    }
    json!({ "name": clip.name, "samplers": samplers, "channels": channels })
}

/// The morph weight tracks as one glTF sampler (times, values target by target within
/// each key, interpolation): as they are when the keyed ones share their times and
/// interpolation (the unkeyed held at `base`, with flat tangents), else sampled linearly at
/// the union of their key times. None when no weight is keyed.
fn combined_weights(tracks: &[Option<Track<f32>>], base: &[f32]) -> Option<(Vec<f32>, Vec<f32>, Interpolation)> {
    let keyed: Vec<&Track<f32>> = tracks.iter().flatten().collect();
    let first = keyed.first()?;
    let shared = keyed.iter().all(|t| t.times == first.times && t.interpolation == first.interpolation);
    let (times, interpolation) = if shared {
        (first.times.clone(), first.interpolation)
    } else {
        let mut times: Vec<f32> = keyed.iter().flat_map(|t| t.times.iter().copied()).collect();
        times.sort_by(f32::total_cmp);
        times.dedup();
        (times, Interpolation::Linear)
    };
    let per_key = if interpolation == Interpolation::CubicSpline { 3 } else { 1 };
    let mut values = Vec::with_capacity(times.len() * per_key * tracks.len());
    for (k, &t) in times.iter().enumerate() {
        for part in 0..per_key {
            for (m, track) in tracks.iter().enumerate() {
                let held = base.get(m).copied().unwrap_or(0.0);
                values.push(match track {
                    Some(track) if shared => track.values[k * per_key + part],
                    Some(track) => track.sample(t),
                    // A tangent of a weight held still is 0.
                    None if per_key == 3 && part != 1 => 0.0,
                    None => held,
                });
            }
        }
    }
    Some((times, values, interpolation))
}

fn interpolation_name(i: Interpolation) -> &'static str {
    match i {
        Interpolation::Step => "STEP",
        Interpolation::Linear => "LINEAR",
        Interpolation::CubicSpline => "CUBICSPLINE",
    }
}

/// Every vertex's influences, four to a set, zero-padded: the bytes of `JOINTS_n` (u16)
/// and `WEIGHTS_n` (f32) for each set.
fn influence_sets(asset: &CharacterAsset) -> Vec<(Vec<u8>, Vec<u8>)> {
    let weights = &asset.skin.weights;
    let sets = weights.max_influences().div_ceil(4).max(1);
    (0..sets)
        .map(|s| {
            let (mut joints, mut values) = (Vec::new(), Vec::new());
            for v in 0..weights.vertex_count() {
                let row = weights.of_vertex(v);
                for k in 4 * s..4 * s + 4 {
                    let (j, w) = row.get(k).map_or((0, 0.0), |i| (i.joint, i.weight));
                    joints.extend(j.to_le_bytes());
                    values.extend(w.to_le_bytes());
                }
            }
            (joints, values)
        })
        .collect()
}

/// The GLB container: header, JSON chunk (space-padded), BIN chunk (zero-padded).
fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |n: usize| n.div_ceil(4) * 4;
    let (json_len, bin_len) = (pad(json.len()), pad(bin.len()));
    let total = 12 + 8 + json_len + 8 + bin_len;
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json_len as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.resize(12 + 8 + json_len, b' ');
    out.extend((bin_len as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out.resize(total, 0);
    out
}

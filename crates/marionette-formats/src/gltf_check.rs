//! Checks a glTF file before anything is read through it: the GLB container's header and
//! chunks, then the JSON's every index, every accessor's layout against its buffer view
//! and buffer (checked arithmetic), every accessor against what the spec allows for its use
//! (attributes, indices, inverse binds, sampler inputs and outputs, morph targets), the node
//! graph a forest, and the numbers of the nodes finite and usable. The `gltf` crate reads
//! the file only after this passed: its readers trust what is checked here (it panics, or
//! reads garbage, on a stride smaller than an element, a component type its reader does
//! not expect, or a count of 0).
//!
//! Errors are `at $.path: expected …, found …` (a byte offset for the GLB container).

use gltf::json::accessor::{ComponentType, Type};
use gltf::json::validation::Checked;
use gltf::json::{self, Root};

use super::limits::MAX_VERTICES;

/// The JSON and binary chunk of a `.glb` (the whole input and none for a `.gltf`).
pub fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    const MAGIC: &[u8] = b"glTF";
    const JSON_CHUNK: u32 = 0x4E4F_534A;
    const BIN_CHUNK: u32 = 0x004E_4942;
    if !bytes.starts_with(MAGIC) {
        return Ok((bytes, None));
    }
    let word = |at: usize| -> Result<u32, String> {
        let b = bytes
            .get(at..at + 4)
            .ok_or_else(|| format!("at byte {at}: expected 4 bytes, found the end of the file"))?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let version = word(4)?;
    if version != 2 {
        return Err(format!("at byte 4: expected binary glTF (GLB) version 2, found {version}"));
    }
    let length = word(8)? as usize;
    if length < 20 || length > bytes.len() {
        return Err(format!(
            "at byte 8: expected a GLB length from 20 to the file's {} bytes, found {length}",
            bytes.len()
        ));
    }
    let bytes = &bytes[..length];
    // A chunk at `at`: its type and its data, which must lie within the file.
    let chunk = |at: usize| -> Result<(u32, &[u8]), String> {
        let len = word(at)? as usize;
        let kind = word(at + 4)?;
        let data = (at + 8)
            .checked_add(len)
            .and_then(|end| bytes.get(at + 8..end))
            .ok_or_else(|| format!("at byte {at}: a chunk of {len} bytes runs past the file's {length}"))?;
        Ok((kind, data))
    };
    let (kind, json) = chunk(12)?;
    if kind != JSON_CHUNK {
        return Err(format!("at byte 16: expected the JSON chunk first, found chunk type 0x{kind:08x}"));
    }
    let next = 20 + json.len().next_multiple_of(4);
    if next + 8 > length {
        return Ok((json, None));
    }
    let (kind, bin) = chunk(next)?;
    Ok((json, (kind == BIN_CHUNK).then_some(bin)))
}

/// Checks the whole document; `bin` is the GLB's binary chunk, if any.
pub fn check(root: &Root, bin: Option<&[u8]>) -> Result<(), String> {
    buffers(root, bin)?;
    views(root)?;
    for (i, accessor) in root.accessors.iter().enumerate() {
        counted(accessor, &format!("$.accessors[{i}]"))?;
    }
    // Each use next (its message names what the accessor is for), then every layout.
    meshes(root)?;
    skins(root)?;
    nodes(root)?;
    animations(root)?;
    textures(root)?;
    for (i, accessor) in root.accessors.iter().enumerate() {
        layout(root, accessor, &format!("$.accessors[{i}]"))?;
    }
    for (s, scene) in root.scenes.iter().enumerate() {
        for (k, n) in scene.nodes.iter().enumerate() {
            index(n.value(), root.nodes.len(), &format!("$.scenes[{s}].nodes[{k}]"), "node")?;
        }
    }
    if let Some(s) = root.scene {
        index(s.value(), root.scenes.len(), "$.scene", "scene")?;
    }
    Ok(())
}

/// `i` names one of `len` things, or `at $.path: expected a {what} index below len, found i`.
fn index(i: usize, len: usize, at: &str, what: &str) -> Result<(), String> {
    if i < len { Ok(()) } else { Err(format!("at {at}: expected a {what} index below {len}, found {i}")) }
}

fn buffers(root: &Root, bin: Option<&[u8]>) -> Result<(), String> {
    for (i, buffer) in root.buffers.iter().enumerate() {
        let at = format!("$.buffers[{i}]");
        let length = buffer.byte_length.0;
        if length == 0 {
            return Err(format!("at {at}.byteLength: expected at least 1 byte, found 0"));
        }
        if buffer.uri.is_none() {
            let found = bin.map(|b| b.len() as u64);
            if i != 0 || found.is_none_or(|f| f < length) {
                return Err(format!(
                    "at {at}: expected the GLB's binary chunk of at least {length} bytes, found {}",
                    found.map_or("none".to_string(), |f| format!("{f} bytes"))
                ));
            }
        }
    }
    Ok(())
}

fn views(root: &Root) -> Result<(), String> {
    for (i, view) in root.buffer_views.iter().enumerate() {
        let at = format!("$.bufferViews[{i}]");
        index(view.buffer.value(), root.buffers.len(), &format!("{at}.buffer"), "buffer")?;
        let buffer = root.buffers[view.buffer.value()].byte_length.0;
        let (offset, length) = (view.byte_offset.map_or(0, |o| o.0), view.byte_length.0);
        if length == 0 {
            return Err(format!("at {at}.byteLength: expected at least 1 byte, found 0"));
        }
        if offset.checked_add(length).is_none_or(|end| end > buffer) {
            return Err(format!(
                "at {at}: expected bytes within its buffer's {buffer}, found {length} from byte {offset}"
            ));
        }
        if let Some(stride) = view.byte_stride
            && (stride.0 < 4 || stride.0 > 252 || stride.0 % 4 != 0)
        {
            return Err(format!("at {at}.byteStride: expected a multiple of 4 from 4 to 252, found {}", stride.0));
        }
    }
    Ok(())
}

/// An accessor's component type and type, or why it has none.
fn kinds(accessor: &json::Accessor, at: &str) -> Result<(ComponentType, Type), String> {
    let component = match accessor.component_type {
        Checked::Valid(c) => c.0,
        Checked::Invalid => return Err(format!("at {at}.componentType: expected a glTF component type")),
    };
    let kind = match accessor.type_ {
        Checked::Valid(t) => t,
        Checked::Invalid => return Err(format!("at {at}.type: expected SCALAR, VEC2-4 or MAT2-4")),
    };
    Ok((component, kind))
}

/// The bytes one element takes: matrix columns start on 4-byte boundaries.
fn element_size(component: ComponentType, kind: Type) -> usize {
    let columns = match kind {
        Type::Mat2 => 2,
        Type::Mat3 => 3,
        Type::Mat4 => 4,
        _ => return component.size() * kind.multiplicity(),
    };
    let rows = kind.multiplicity() / columns;
    columns * (rows * component.size()).next_multiple_of(4)
}

/// The accessor's types, its count within the limit and its normalisation possible.
fn counted(accessor: &json::Accessor, at: &str) -> Result<(), String> {
    let (component, _) = kinds(accessor, at)?;
    let count = accessor.count.0;
    if count == 0 || count > MAX_VERTICES as u64 {
        return Err(format!("at {at}.count: expected 1 to {MAX_VERTICES} elements, found {count}"));
    }
    if accessor.normalized && matches!(component, ComponentType::F32 | ComponentType::U32) {
        return Err(format!(
            "at {at}.normalized: expected an 8- or 16-bit integer component type for normalised values"
        ));
    }
    Ok(())
}

/// The accessor's layout against its buffer view (and its sparse part's); its count and
/// types were [`counted`].
fn layout(root: &Root, accessor: &json::Accessor, at: &str) -> Result<(), String> {
    let (component, kind) = kinds(accessor, at)?;
    let count = accessor.count.0;
    let size = element_size(component, kind) as u64;
    let offset = accessor.byte_offset.map_or(0, |o| o.0);
    if let Some(view) = accessor.buffer_view {
        fits(root, view.value(), offset, count, size, component.size() as u64, at)?;
    } else if offset != 0 {
        return Err(format!("at {at}.byteOffset: expected none without a buffer view, found {offset}"));
    }
    if let Some(sparse) = &accessor.sparse {
        let at = format!("{at}.sparse");
        let n = sparse.count.0;
        if n == 0 || n > count {
            return Err(format!("at {at}.count: expected 1 to the accessor's {count}, found {n}"));
        }
        let index_type = match sparse.indices.component_type {
            Checked::Valid(c) if matches!(c.0, ComponentType::U8 | ComponentType::U16 | ComponentType::U32) => c.0,
            _ => return Err(format!("at {at}.indices.componentType: expected UNSIGNED_BYTE, SHORT or INT")),
        };
        let indices = &sparse.indices;
        let isize = index_type.size() as u64;
        fits(root, indices.buffer_view.value(), indices.byte_offset.0, n, isize, isize, &format!("{at}.indices"))?;
        let values = &sparse.values;
        fits(
            root,
            values.buffer_view.value(),
            values.byte_offset.0,
            n,
            size,
            component.size() as u64,
            &format!("{at}.values"),
        )?;
    }
    Ok(())
}

/// `count` elements of `size` bytes from `offset` in buffer view `view` (at its stride)
/// lie within it, aligned to their component.
fn fits(root: &Root, view: usize, offset: u64, count: u64, size: u64, align: u64, at: &str) -> Result<(), String> {
    index(view, root.buffer_views.len(), &format!("{at}.bufferView"), "buffer view")?;
    let v = &root.buffer_views[view];
    let stride = v.byte_stride.map_or(size, |s| s.0 as u64);
    if stride < size {
        return Err(format!(
            "at $.bufferViews[{view}].byteStride: expected at least the {size} bytes of an element of {at}, found {stride}"
        ));
    }
    let start = v.byte_offset.map_or(0, |o| o.0).checked_add(offset);
    if !offset.is_multiple_of(align) || start.is_none_or(|s| !s.is_multiple_of(align)) {
        return Err(format!(
            "at {at}.byteOffset: expected a multiple of {align} (the component's size), found {offset}"
        ));
    }
    let end = (count - 1).checked_mul(stride).and_then(|e| e.checked_add(size)).and_then(|e| e.checked_add(offset));
    let length = v.byte_length.0;
    if end.is_none_or(|e| e > length) {
        return Err(format!(
            "at {at}: expected {count} elements of {size} bytes from byte {offset} (stride {stride}) within \
             $.bufferViews[{view}]'s {length} bytes"
        ));
    }
    Ok(())
}

/// What a use allows of an accessor: its types, and its component types with whether each
/// is normalised.
struct Allowed {
    kinds: &'static [Type],
    components: &'static [(ComponentType, bool)],
    what: &'static str,
}

const FLOAT: &[(ComponentType, bool)] = &[(ComponentType::F32, false)];
const FLOAT_OR_UNORM: &[(ComponentType, bool)] =
    &[(ComponentType::F32, false), (ComponentType::U8, true), (ComponentType::U16, true)];
const FLOAT_OR_NORM: &[(ComponentType, bool)] = &[
    (ComponentType::F32, false),
    (ComponentType::I8, true),
    (ComponentType::U8, true),
    (ComponentType::I16, true),
    (ComponentType::U16, true),
];

const POSITIONS: Allowed = Allowed { kinds: &[Type::Vec3], components: FLOAT, what: "VEC3 of FLOAT" };
const NORMALS: Allowed = POSITIONS;
const TANGENTS: Allowed = Allowed { kinds: &[Type::Vec4], components: FLOAT, what: "VEC4 of FLOAT" };
const TEXCOORDS: Allowed = Allowed {
    kinds: &[Type::Vec2],
    components: FLOAT_OR_UNORM,
    what: "VEC2 of FLOAT or normalised UNSIGNED_BYTE/SHORT",
};
const COLORS: Allowed = Allowed {
    kinds: &[Type::Vec3, Type::Vec4],
    components: FLOAT_OR_UNORM,
    what: "VEC3 or VEC4 of FLOAT or normalised UNSIGNED_BYTE/SHORT",
};
const JOINTS: Allowed = Allowed {
    kinds: &[Type::Vec4],
    components: &[(ComponentType::U8, false), (ComponentType::U16, false)],
    what: "VEC4 of UNSIGNED_BYTE or UNSIGNED_SHORT",
};
const WEIGHTS: Allowed = Allowed {
    kinds: &[Type::Vec4],
    components: FLOAT_OR_UNORM,
    what: "VEC4 of FLOAT or normalised UNSIGNED_BYTE/SHORT",
};
const INDICES: Allowed = Allowed {
    kinds: &[Type::Scalar],
    components: &[(ComponentType::U8, false), (ComponentType::U16, false), (ComponentType::U32, false)],
    what: "SCALAR of UNSIGNED_BYTE, SHORT or INT",
};
const INVERSE_BINDS: Allowed = Allowed { kinds: &[Type::Mat4], components: FLOAT, what: "MAT4 of FLOAT" };
const KEY_TIMES: Allowed = Allowed { kinds: &[Type::Scalar], components: FLOAT, what: "SCALAR of FLOAT" };
const VEC3_KEYS: Allowed = POSITIONS;
const ROTATION_KEYS: Allowed =
    Allowed { kinds: &[Type::Vec4], components: FLOAT_OR_NORM, what: "VEC4 of FLOAT or normalised integers" };
const WEIGHT_KEYS: Allowed =
    Allowed { kinds: &[Type::Scalar], components: FLOAT_OR_NORM, what: "SCALAR of FLOAT or normalised integers" };

/// The accessor `i` used as `allowed` says (at `at`), and its count.
fn used_as(root: &Root, i: usize, at: &str, allowed: &Allowed) -> Result<u64, String> {
    index(i, root.accessors.len(), at, "accessor")?;
    let accessor = &root.accessors[i];
    let (component, kind) = kinds(accessor, &format!("$.accessors[{i}]"))?;
    if !allowed.kinds.contains(&kind) || !allowed.components.contains(&(component, accessor.normalized)) {
        let norm = if accessor.normalized { "normalised " } else { "" };
        return Err(format!(
            "at {at}: expected an accessor of {}, found $.accessors[{i}], {kind:?} of {norm}{component:?}",
            allowed.what
        ));
    }
    Ok(accessor.count.0)
}

fn meshes(root: &Root) -> Result<(), String> {
    use json::mesh::Semantic;
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let at = format!("$.meshes[{m}].primitives[{p}]");
            let mut vertices = None;
            for (semantic, accessor) in &primitive.attributes {
                let Checked::Valid(semantic) = semantic else { continue };
                let at = format!("{at}.attributes.{}", semantic_name(semantic));
                let allowed = match semantic {
                    Semantic::Positions => &POSITIONS,
                    Semantic::Normals => &NORMALS,
                    Semantic::Tangents => &TANGENTS,
                    Semantic::TexCoords(_) => &TEXCOORDS,
                    Semantic::Colors(_) => &COLORS,
                    Semantic::Joints(_) => &JOINTS,
                    Semantic::Weights(_) => &WEIGHTS,
                    Semantic::Extras(_) => {
                        index(accessor.value(), root.accessors.len(), &at, "accessor")?;
                        continue;
                    }
                };
                let count = used_as(root, accessor.value(), &at, allowed)?;
                same_count(&mut vertices, count, &at)?;
            }
            if let Some(indices) = primitive.indices {
                used_as(root, indices.value(), &format!("{at}.indices"), &INDICES)?;
            }
            if let Some(material) = primitive.material {
                index(material.value(), root.materials.len(), &format!("{at}.material"), "material")?;
            }
            for (t, target) in primitive.targets.iter().flatten().enumerate() {
                let at = format!("{at}.targets[{t}]");
                let parts =
                    [(&target.positions, "POSITION"), (&target.normals, "NORMAL"), (&target.tangents, "TANGENT")];
                for (accessor, name) in parts {
                    if let Some(accessor) = accessor {
                        let at = format!("{at}.{name}");
                        let count = used_as(root, accessor.value(), &at, &VEC3_KEYS)?;
                        same_count(&mut vertices, count, &at)?;
                    }
                }
            }
        }
        finite_numbers(mesh.weights.iter().flatten(), &format!("$.meshes[{m}].weights"))?;
    }
    Ok(())
}

/// Every attribute of a primitive has as many elements as the first.
fn same_count(vertices: &mut Option<u64>, count: u64, at: &str) -> Result<(), String> {
    match *vertices.get_or_insert(count) {
        n if n == count => Ok(()),
        n => Err(format!("at {at}: expected {n} elements like the primitive's other attributes, found {count}")),
    }
}

fn semantic_name(semantic: &json::mesh::Semantic) -> String {
    use json::mesh::Semantic;
    match semantic {
        Semantic::Positions => "POSITION".into(),
        Semantic::Normals => "NORMAL".into(),
        Semantic::Tangents => "TANGENT".into(),
        Semantic::TexCoords(n) => format!("TEXCOORD_{n}"),
        Semantic::Colors(n) => format!("COLOR_{n}"),
        Semantic::Joints(n) => format!("JOINTS_{n}"),
        Semantic::Weights(n) => format!("WEIGHTS_{n}"),
        Semantic::Extras(name) => name.clone(),
    }
}

fn skins(root: &Root) -> Result<(), String> {
    for (s, skin) in root.skins.iter().enumerate() {
        let at = format!("$.skins[{s}]");
        if skin.joints.is_empty() {
            return Err(format!("at {at}.joints: expected at least one joint, found none"));
        }
        let mut seen = vec![false; root.nodes.len()];
        for (k, joint) in skin.joints.iter().enumerate() {
            let at = format!("{at}.joints[{k}]");
            index(joint.value(), root.nodes.len(), &at, "node")?;
            if std::mem::replace(&mut seen[joint.value()], true) {
                return Err(format!("at {at}: expected each node once, found node {} again", joint.value()));
            }
        }
        if let Some(skeleton) = skin.skeleton {
            index(skeleton.value(), root.nodes.len(), &format!("{at}.skeleton"), "node")?;
        }
        if let Some(ibm) = skin.inverse_bind_matrices {
            let at = format!("{at}.inverseBindMatrices");
            let count = used_as(root, ibm.value(), &at, &INVERSE_BINDS)?;
            if count < skin.joints.len() as u64 {
                return Err(format!(
                    "at {at}: expected a matrix for each of its {} joints, found {count}",
                    skin.joints.len()
                ));
            }
        }
    }
    Ok(())
}

/// The nodes' indices, their numbers, and the graph a forest: one parent each, no cycle.
fn nodes(root: &Root) -> Result<(), String> {
    let n = root.nodes.len();
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for (i, node) in root.nodes.iter().enumerate() {
        let at = format!("$.nodes[{i}]");
        for (k, child) in node.children.iter().flatten().enumerate() {
            let c = child.value();
            let at = format!("{at}.children[{k}]");
            index(c, n, &at, "node")?;
            if c == i {
                return Err(format!("at {at}: expected another node, found the node itself"));
            }
            if let Some(other) = parent[c].replace(i) {
                return Err(format!(
                    "at {at}: expected a node with one parent, found node {c}, a child of node {other} too"
                ));
            }
        }
        if let Some(mesh) = node.mesh {
            index(mesh.value(), root.meshes.len(), &format!("{at}.mesh"), "mesh")?;
        }
        if let Some(skin) = node.skin {
            index(skin.value(), root.skins.len(), &format!("{at}.skin"), "skin")?;
        }
        if let Some(camera) = node.camera {
            index(camera.value(), root.cameras.len(), &format!("{at}.camera"), "camera")?;
        }
        node_numbers(node, &at)?;
    }
    // Walk up from each node; meeting a node of the walk in progress is a cycle.
    let mut state = vec![0u8; n]; // 0 unseen, 1 on the current walk, 2 done
    for start in 0..n {
        let mut walk = Vec::new();
        let mut at = Some(start);
        while let Some(i) = at {
            match state[i] {
                2 => break,
                1 => return Err(format!("at $.nodes[{i}].children: expected a tree, found a cycle through node {i}")),
                _ => {
                    state[i] = 1;
                    walk.push(i);
                    at = parent[i];
                }
            }
        }
        walk.into_iter().for_each(|i| state[i] = 2);
    }
    Ok(())
}

/// A node's transform: finite, its rotation a quaternion that can be normalised, its scale
/// not zero on any axis.
fn node_numbers(node: &json::Node, at: &str) -> Result<(), String> {
    if let Some(matrix) = &node.matrix {
        finite_numbers(matrix, &format!("{at}.matrix"))?;
        if !crate::checks::is_invertible(&glam::Mat4::from_cols_array(matrix)) {
            return Err(format!("at {at}.matrix: expected an invertible transform, found a singular matrix"));
        }
    }
    if let Some(t) = &node.translation {
        finite_numbers(t, &format!("{at}.translation"))?;
    }
    if let Some(r) = &node.rotation {
        finite_numbers(&r.0, &format!("{at}.rotation"))?;
        if r.0.iter().map(|v| v * v).sum::<f32>() < 1e-12 {
            return Err(format!("at {at}.rotation: expected a rotation, found a zero quaternion"));
        }
    }
    if let Some(s) = &node.scale {
        finite_numbers(s, &format!("{at}.scale"))?;
        if s.contains(&0.0) {
            return Err(format!("at {at}.scale: expected a scale that is not zero on any axis, found {s:?}"));
        }
    }
    finite_numbers(node.weights.iter().flatten(), &format!("{at}.weights"))
}

/// Every number finite, or `at $.path: expected finite numbers, found inf`.
fn finite_numbers<'a>(values: impl IntoIterator<Item = &'a f32>, at: &str) -> Result<(), String> {
    match values.into_iter().find(|v| !v.is_finite()) {
        Some(v) => Err(format!("at {at}: expected finite numbers, found {v}")),
        None => Ok(()),
    }
}

fn animations(root: &Root) -> Result<(), String> {
    use json::animation::Property;
    for (a, animation) in root.animations.iter().enumerate() {
        let at = format!("$.animations[{a}]");
        for (s, sampler) in animation.samplers.iter().enumerate() {
            let at = format!("{at}.samplers[{s}]");
            used_as(root, sampler.input.value(), &format!("{at}.input"), &KEY_TIMES)?;
            index(sampler.output.value(), root.accessors.len(), &format!("{at}.output"), "accessor")?;
            if let Checked::Invalid = sampler.interpolation {
                return Err(format!("at {at}.interpolation: expected LINEAR, STEP or CUBICSPLINE"));
            }
        }
        for (c, channel) in animation.channels.iter().enumerate() {
            let at = format!("{at}.channels[{c}]");
            index(channel.sampler.value(), animation.samplers.len(), &format!("{at}.sampler"), "sampler")?;
            index(channel.target.node.value(), root.nodes.len(), &format!("{at}.target.node"), "node")?;
            let allowed = match channel.target.path {
                Checked::Valid(Property::Translation | Property::Scale) => &VEC3_KEYS,
                Checked::Valid(Property::Rotation) => &ROTATION_KEYS,
                Checked::Valid(Property::MorphTargetWeights) => &WEIGHT_KEYS,
                Checked::Invalid => {
                    return Err(format!("at {at}.target.path: expected translation, rotation, scale or weights"));
                }
            };
            let output = animation.samplers[channel.sampler.value()].output.value();
            used_as(root, output, &format!("$.animations[{a}].samplers[{}].output", channel.sampler.value()), allowed)?;
        }
    }
    Ok(())
}

fn textures(root: &Root) -> Result<(), String> {
    for (i, image) in root.images.iter().enumerate() {
        match (image.buffer_view, &image.uri) {
            (Some(view), _) => {
                index(view.value(), root.buffer_views.len(), &format!("$.images[{i}].bufferView"), "buffer view")?;
                if image.mime_type.is_none() {
                    return Err(format!(
                        "at $.images[{i}].mimeType: expected the MIME type an image in a buffer view needs"
                    ));
                }
            }
            (None, None) => return Err(format!("at $.images[{i}]: expected a uri or a bufferView, found neither")),
            (None, Some(_)) => {}
        }
    }
    for (t, texture) in root.textures.iter().enumerate() {
        index(texture.source.value(), root.images.len(), &format!("$.textures[{t}].source"), "image")?;
        if let Some(sampler) = texture.sampler {
            index(sampler.value(), root.samplers.len(), &format!("$.textures[{t}].sampler"), "sampler")?;
        }
    }
    for (m, material) in root.materials.iter().enumerate() {
        let at = format!("$.materials[{m}]");
        let pbr = &material.pbr_metallic_roughness;
        let infos = [
            (pbr.base_color_texture.as_ref().map(|t| t.index.value()), "pbrMetallicRoughness.baseColorTexture"),
            (
                pbr.metallic_roughness_texture.as_ref().map(|t| t.index.value()),
                "pbrMetallicRoughness.metallicRoughnessTexture",
            ),
            (material.normal_texture.as_ref().map(|t| t.index.value()), "normalTexture"),
            (material.occlusion_texture.as_ref().map(|t| t.index.value()), "occlusionTexture"),
            (material.emissive_texture.as_ref().map(|t| t.index.value()), "emissiveTexture"),
        ];
        for (texture, name) in infos {
            if let Some(t) = texture {
                index(t, root.textures.len(), &format!("{at}.{name}.index"), "texture")?;
            }
        }
        finite_numbers(&pbr.base_color_factor.0, &format!("{at}.pbrMetallicRoughness.baseColorFactor"))?;
    }
    Ok(())
}

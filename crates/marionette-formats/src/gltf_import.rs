//! glTF 2.0 import (`.glb`, `.gltf` with its `.bin` files or `data:` URIs), read with the
//! `gltf` crate. The node tree is the truth: each tree of nodes that carries meshes becomes
//! one part (a character, or a prop when none of its meshes is skinned). Its skeleton is
//! every node of the tree that a mesh depends on: the skins' joints, the nodes above and
//! between them (so a skeleton may hang under another skin's joint), and the nodes of
//! unskinned meshes, which ride rigidly on their node. Static nodes above the tree's first
//! branching node are folded into it. Each node's translation is its rest offset, its
//! rotation its pose, its scale its rest scale; the skins' inverse bind matrices bind the
//! joints (a joint bound differently by two skins gets a second, fixed joint for the
//! second binding). Every primitive of the part's meshes, merged in file order, with all
//! `JOINTS_n`/`WEIGHTS_n` sets, normalised; morph targets per mesh node; each primitive's
//! material and surface ([`gltf_materials`](super::gltf_materials)); and the file's animations of the part's nodes and morph weights as
//! clips.

use std::borrow::Cow;
use std::path::Path;

use glam::{Mat4, Quat, Vec3};

use super::error::FormatError;
use super::node_tree::{Binding, Tree, TreeNode, TreeSkeleton, tree_skeleton};
use super::part::Part;
use marionette_rig::node_clip::{Interpolation, JointTracks, NodeClip, Track};
use marionette_rig::{CharacterAsset, MorphTarget, Skin, SkinWeights};

/// Whether `path` names a glTF file (`.glb`, `.gltf`).
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| ["glb", "gltf", "vrm"].iter().any(|g| e.eq_ignore_ascii_case(g)))
}

/// Loads every part (character or prop) of a glTF file.
pub fn load_gltf(path: &Path) -> Result<Vec<Part>, FormatError> {
    let bytes = super::error::read_file(path)?;
    parse_gltf(&bytes, path)
}

/// The parts of a glTF file's bytes (`.bin` files are looked for beside `path`): one per
/// tree of nodes that carries a mesh, in the order of their first mesh node.
pub fn parse_gltf(bytes: &[u8], path: &Path) -> Result<Vec<Part>, FormatError> {
    let (gltf, bin) = validated(bytes).map_err(|e| FormatError::other(path, e))?;
    if let Some(ext) = gltf.extensions_required().next() {
        return Err(FormatError::other(path, format!("at $.extensionsRequired: needs `{ext}`, which is not read")));
    }
    let buffers = buffers(&gltf, bin, path)?;
    let mut file = File::new(&gltf, &buffers, path);
    if gltf.extensions_used().any(|e| e == "VRMC_vrm" || e == "VRM") {
        let (json, _) = super::gltf_check::split_glb(bytes).map_err(|e| FormatError::other(path, e))?;
        let json: serde_json::Value =
            serde_json::from_slice(json).map_err(|e| FormatError::other(path, format!("at $: {e}")))?;
        let vrm = super::vrm::read(&json).map_err(|e| FormatError::other(path, e))?;
        if let Some(vrm) = &vrm {
            vrm.check(gltf.nodes().len(), gltf.meshes().len()).map_err(|e| FormatError::other(path, e))?;
        }
        file.vrm = vrm;
    }
    let parts = file.parts();
    if parts.is_empty() {
        return Err(file.error("at $.nodes: expected a node with a mesh, found none".into()));
    }
    let mut vertices = 0usize;
    parts
        .iter()
        .enumerate()
        .map(|(n, part)| {
            let imported = file.part(part, n, parts.len())?;
            vertices += imported.asset.vertex_count();
            if vertices > super::limits::MAX_VERTICES {
                return Err(file.error(format!(
                    "at $.nodes: the meshes hold more than the {} vertices a file may (MAX_VERTICES)",
                    super::limits::MAX_VERTICES
                )));
            }
            Ok(imported)
        })
        .collect()
}

/// A parsed file: its JSON, its buffers, each node's parent and what its animations key.
struct File<'a> {
    gltf: &'a gltf::Gltf,
    buffers: &'a [Cow<'a, [u8]>],
    path: &'a Path,
    parent: Vec<Option<usize>>,
    /// Whether an animation keys the node's translation, rotation or scale.
    animated: Vec<bool>,
    /// Whether the node is in the scene the file shows (`scene`, else its first; every
    /// node when it has no scenes).
    shown: Vec<bool>,
    /// Whether a mesh depends on the node (a skin's joint, an unskinned mesh's node).
    seed: Vec<bool>,
    /// Whether the node is one of `seed`'s or above one.
    relevant: Vec<bool>,
    /// The images decoded so far.
    images: std::cell::RefCell<super::gltf_materials::Images>,
    /// A VRM avatar's humanoid bones and expressions.
    vrm: Option<super::vrm::Vrm>,
}

/// The nodes of one part: its roots, and its mesh nodes in file order.
struct PartNodes {
    roots: Vec<usize>,
    meshes: Vec<usize>,
}

/// How a primitive's vertices follow the joints.
enum Bound<'m> {
    /// By their `JOINTS_n`/`WEIGHTS_n`, skin joint k being joint `joints[k]`.
    Skinned(&'m [usize]),
    /// Rigidly on `joint`, the vertices taken into its bind frame by `to_bind`.
    Rigid { joint: usize, to_bind: Mat4 },
}

impl<'a> File<'a> {
    fn new(gltf: &'a gltf::Gltf, buffers: &'a [Cow<'a, [u8]>], path: &'a Path) -> Self {
        let n = gltf.nodes().len();
        let parent = parents(gltf);
        let mut animated = vec![false; n];
        for channel in gltf.animations().flat_map(|a| a.channels().collect::<Vec<_>>()) {
            if channel.target().property() != gltf::animation::Property::MorphTargetWeights {
                animated[channel.target().node().index()] = true;
            }
        }
        let shown = shown_nodes(gltf, &parent);
        let mut seed = vec![false; n];
        for node in gltf.nodes().filter(|n| n.mesh().is_some() && shown[n.index()]) {
            match node.skin() {
                Some(skin) => skin.joints().for_each(|j| seed[j.index()] = true),
                None => seed[node.index()] = true,
            }
        }
        let mut relevant = vec![false; n];
        for s in (0..n).filter(|&s| seed[s]) {
            let mut at = Some(s);
            // The nodes are a forest (checked): the walk ends at a root or a marked node.
            while let Some(node) = at.filter(|&node| !relevant[node]) {
                relevant[node] = true;
                at = parent[node];
            }
        }
        Self { gltf, buffers, path, parent, animated, shown, seed, relevant, images: Default::default(), vrm: None }
    }

    /// The nodes with a mesh in the scene shown, in file order.
    fn mesh_nodes(&self) -> impl Iterator<Item = gltf::Node<'a>> + '_ {
        self.gltf.nodes().filter(|n| n.mesh().is_some() && self.shown[n.index()])
    }

    fn error(&self, message: String) -> FormatError {
        FormatError::other(self.path, message)
    }

    fn data<'s>(&'s self) -> impl Clone + Fn(gltf::Buffer) -> Option<&'s [u8]> {
        |b: gltf::Buffer| self.buffers.get(b.index()).map(|data| &**data)
    }

    fn node(&self, index: usize) -> gltf::Node<'a> {
        self.gltf.nodes().nth(index).expect("node indices were checked")
    }

    fn root_of(&self, mut node: usize) -> usize {
        while let Some(up) = self.parent[node] {
            node = up;
        }
        node
    }

    /// The node's relevant children, in file order.
    fn relevant_children(&self, node: usize) -> Vec<usize> {
        self.node(node).children().map(|c| c.index()).filter(|&c| self.relevant[c]).collect()
    }

    /// The file's parts: the node trees that carry meshes, a skin whose joints lie in
    /// several trees joining them, in the order of their first mesh node.
    fn parts(&self) -> Vec<PartNodes> {
        let n = self.parent.len();
        // Union-find over the roots.
        let mut group: Vec<usize> = (0..n).collect();
        fn find(group: &mut [usize], mut x: usize) -> usize {
            while group[x] != x {
                group[x] = group[group[x]];
                x = group[x];
            }
            x
        }
        let mesh_root = |node: &gltf::Node| match node.skin() {
            Some(skin) => skin.joints().next().map(|j| self.root_of(j.index())),
            None => Some(self.root_of(node.index())),
        };
        for node in self.mesh_nodes() {
            if let Some(skin) = node.skin() {
                let mut roots = skin.joints().map(|j| self.root_of(j.index()));
                if let Some(first) = roots.next() {
                    for other in roots {
                        let (a, b) = (find(&mut group, first), find(&mut group, other));
                        group[b] = a;
                    }
                }
            }
        }
        let mut parts: Vec<(usize, PartNodes)> = Vec::new();
        for node in self.mesh_nodes() {
            let Some(root) = mesh_root(&node) else { continue };
            let id = find(&mut group, root);
            match parts.iter_mut().find(|(g, _)| *g == id) {
                Some((_, part)) => part.meshes.push(node.index()),
                None => parts.push((id, PartNodes { roots: Vec::new(), meshes: vec![node.index()] })),
            }
        }
        for root in (0..n).filter(|&r| self.parent[r].is_none() && self.relevant[r]) {
            let id = find(&mut group, root);
            if let Some((_, part)) = parts.iter_mut().find(|(g, _)| *g == id) {
                part.roots.push(root);
            }
        }
        parts.into_iter().map(|(_, part)| part).collect()
    }

    /// The part's name: the file's stem when it is the only one, else its first mesh
    /// node's mesh name, its root node's name, or the stem and its number.
    fn part_name(&self, part: &PartNodes, n: usize, count: usize) -> String {
        let stem = self.path.file_stem().and_then(|s| s.to_str()).unwrap_or("gltf");
        if count == 1 {
            return stem.to_string();
        }
        let mesh = part.meshes.iter().find_map(|&m| self.node(m).mesh()?.name().map(str::to_string));
        let root = || (part.roots.len() == 1).then(|| self.node(part.roots[0]).name().map(str::to_string)).flatten();
        mesh.or_else(root).unwrap_or_else(|| format!("{stem} {}", n + 1))
    }

    /// One part: its skeleton, bindings, meshes, morphs and clips.
    fn part(&self, part: &PartNodes, n: usize, count: usize) -> Result<Part, FormatError> {
        let mut warnings = Vec::new();
        let name = self.part_name(part, n, count);
        let (top, root_parent) = self.folded_top(part);
        let (skins, bindings) = self.skins_of(part);
        let roots = top.map_or_else(|| part.roots.clone(), |top| vec![top]);
        let at = format!("at $.nodes (the tree of node {})", part.roots[0]);
        let tree = Tree { name: &name, node_count: self.parent.len(), roots: &roots, at: &at };
        let fold = |index| (Some(index) == top && root_parent != Mat4::IDENTITY).then_some(root_parent);
        let TreeSkeleton { skeleton, bind, joint_of_node, skin_joints } = tree_skeleton(
            &tree,
            |index| self.tree_node(index, fold(index)),
            |index| self.relevant_children(index),
            &bindings,
        )
        .map_err(|e| self.error(e))?;

        let mut skin_data = Skin::default();
        let mut rows = Vec::new();
        let mut morphs = Vec::new();
        let mut morph_weights = Vec::new();
        let mut morph_of = Vec::new();
        let mut looks = super::gltf_materials::Looks::default();
        let source = super::gltf_materials::Source { buffers: self.buffers, path: self.path };
        let mut skinned = false;
        for &node_index in &part.meshes {
            let node = self.node(node_index);
            let Some(mesh) = node.mesh() else { continue };
            let bound = match node.skin() {
                Some(skin) => {
                    skinned = true;
                    let k = skins.iter().position(|&s| s == skin.index()).expect("every skin of the part is bound");
                    Bound::Skinned(&skin_joints[k])
                }
                None => {
                    let joint = joint_of_node[node_index].expect("a mesh node is a joint");
                    Bound::Rigid { joint, to_bind: bind[joint].inverse() }
                }
            };
            let first_morph = morphs.len();
            for (p, primitive) in mesh.primitives().enumerate() {
                let at = format!("at $.meshes[{}].primitives[{p}]", mesh.index());
                if primitive.mode() != gltf::mesh::Mode::Triangles {
                    warnings.push(format!("{}: {at} is not triangles and was skipped", self.path.display()));
                    continue;
                }
                let first = skin_data.bind_positions.len();
                let first_triangle = skin_data.triangles.len() as u32;
                self.primitive(&primitive, &at, &bound, &mut skin_data, &mut rows)?;
                let count = skin_data.bind_positions.len() - first;
                let triangles = first_triangle..skin_data.triangles.len() as u32;
                looks
                    .add(
                        &source,
                        &mut self.images.borrow_mut(),
                        &primitive,
                        &at,
                        first,
                        count,
                        triangles,
                        &mut warnings,
                    )
                    .map_err(|e| self.error(e))?;
                self.morph_targets(&node, &mesh, &primitive, &at, first, &bound, first_morph, &mut morphs)?;
            }
            // This node's targets, in order, and the weights the file sets for them.
            let targets = morphs.len() - first_morph;
            let set = node.weights().or_else(|| mesh.weights()).unwrap_or(&[]);
            morph_weights.extend((0..targets).map(|k| set.get(k).copied().filter(|w| w.is_finite()).unwrap_or(0.0)));
            morph_of.push((node_index, first_morph, targets));
        }
        let (weights, normalised) = SkinWeights::from_rows(rows, skeleton.len())
            .map_err(|e| self.error(format!("at $.nodes (the meshes of part `{name}`, JOINTS_n, WEIGHTS_n): {e}")))?;
        warnings.extend(super::weight_warnings::normalised_warnings(self.path, &normalised));
        skin_data.weights = weights;
        looks.finish(&mut skin_data);
        let clips = self.clips(&joint_of_node, skeleton.len(), &morph_of, morphs.len(), root_parent)?;
        let mut asset = CharacterAsset::with_inverse_binds(name, skeleton, skin_data, bind, warnings)
            .map_err(|e| FormatError::rig(self.path, e))?;
        if !skinned {
            asset.skin_kind = marionette_rig::character::SkinKind::Rigid;
        }
        asset.morphs = morphs;
        asset.materials = looks.materials;
        asset.surfaces = looks.surfaces;
        if let Some(vrm) = &self.vrm {
            self.add_vrm(vrm, &joint_of_node, &morph_of, &mut asset);
        }
        Ok(Part { asset, clips, morph_weights })
    }

    /// A VRM avatar's humanoid bones (those in the part) and its expressions (the morph
    /// targets of the part's meshes they set).
    fn add_vrm(
        &self,
        vrm: &super::vrm::Vrm,
        joint_of_node: &[Option<usize>],
        morph_of: &[(usize, usize, usize)],
        asset: &mut CharacterAsset,
    ) {
        use super::vrm::BindTarget;
        for &(bone, node) in &vrm.bones {
            if let Some(j) = joint_of_node.get(node).copied().flatten() {
                asset.humanoid.insert(bone, j);
            }
        }
        for expression in &vrm.expressions {
            let mut weights = Vec::new();
            for bind in &expression.binds {
                for &(node, first, count) in morph_of {
                    let named = match bind.on {
                        BindTarget::Node(n) => n == node,
                        BindTarget::Mesh(m) => self.node(node).mesh().is_some_and(|mesh| mesh.index() == m),
                    };
                    if named && bind.index < count {
                        weights.push((first + bind.index, bind.weight));
                    }
                }
            }
            asset.expressions.push(marionette_rig::character::Expression { name: expression.name.clone(), weights });
        }
    }

    /// The node the part's skeleton starts at and the transform of the static nodes above
    /// it folded into it: from a single root, down while a node is not keyed, carries no
    /// mesh, is no joint and has one relevant child (and the fold keeps its transform
    /// exactly a translation, rotation and scale).
    fn folded_top(&self, part: &PartNodes) -> (Option<usize>, Mat4) {
        let [root] = part.roots[..] else { return (None, Mat4::IDENTITY) };
        let (mut top, mut fold) = (root, Mat4::IDENTITY);
        loop {
            let children = self.relevant_children(top);
            let [next] = children[..] else { break };
            if self.animated[top] || self.seed[top] {
                break;
            }
            let folded = fold * local_matrix(&self.node(top));
            if !is_trs(folded * local_matrix(&self.node(next))) {
                break;
            }
            (top, fold) = (next, folded);
        }
        (Some(top), fold)
    }

    /// A node's name and transform in its parent's frame, `fold` (the static nodes above the
    /// part's top) put before it.
    fn tree_node(&self, index: usize, fold: Option<Mat4>) -> Result<TreeNode, String> {
        let node = self.node(index);
        let (translation, rotation, scale) = match (fold, node.transform()) {
            (None, gltf::scene::Transform::Decomposed { translation, rotation, scale }) => {
                (Vec3::from(translation), Quat::from_array(rotation), Vec3::from(scale))
            }
            (fold, _) => {
                let local = fold.unwrap_or(Mat4::IDENTITY) * local_matrix(&node);
                if !is_trs(local) {
                    return Err(format!(
                        "at $.nodes[{index}].matrix: expected a translation, rotation and scale, found a shear"
                    ));
                }
                let (scale, rotation, translation) = local.to_scale_rotation_translation();
                (translation, rotation, scale)
            }
        };
        let name = node.name().map_or_else(|| format!("node {index}"), str::to_string);
        Ok(TreeNode { name, translation, rotation, scale })
    }

    /// The skins of the part's meshes (once each, in the order they are first used): their
    /// indices, and their joints' nodes with their inverse bind matrices (identity where the
    /// file gives none).
    fn skins_of(&self, part: &PartNodes) -> (Vec<usize>, Vec<Binding>) {
        let (mut skins, mut bindings) = (Vec::new(), Vec::new());
        for skin in part.meshes.iter().filter_map(|&m| self.node(m).skin()) {
            if skins.contains(&skin.index()) {
                continue;
            }
            let mut ibms: Vec<Mat4> = vec![Mat4::IDENTITY; skin.joints().len()];
            if let Some(read) = skin.reader(self.data()).read_inverse_bind_matrices() {
                ibms.iter_mut().zip(read).for_each(|(ibm, m)| *ibm = Mat4::from_cols_array_2d(&m));
            }
            let joints = skin.joints().map(|j| j.index()).zip(ibms).collect();
            skins.push(skin.index());
            let (label, at) =
                (format!("skin {}", skin.index()), format!("at $.skins[{}].inverseBindMatrices", skin.index()));
            bindings.push(Binding { label, at, joints });
        }
        (skins, bindings)
    }

    /// Appends one triangle primitive: its positions, triangles and influence rows.
    fn primitive(
        &self,
        primitive: &gltf::Primitive,
        at: &str,
        bound: &Bound,
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
        let normals: Vec<Vec3> = reader.read_normals().into_iter().flatten().map(Vec3::from).collect();
        if let Some(v) = normals.iter().position(|n| !n.is_finite()) {
            return Err(self.error(format!("{at}.attributes.NORMAL: expected finite numbers, found vertex {v}'s")));
        }
        // Zero where the primitive has none (or fewer than positions): lit flat there.
        let normals = normals.into_iter().chain(std::iter::repeat(Vec3::ZERO)).take(count);
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..count as u32).collect(),
        };
        if let Some(bad) = indices.iter().find(|&&i| i as usize >= count) {
            return Err(self.error(format!("{at}.indices: index {bad} is beyond its {count} vertices")));
        }
        skin.triangles.extend(indices.chunks_exact(3).map(|t| [first + t[0], first + t[1], first + t[2]]));
        match *bound {
            Bound::Rigid { joint, to_bind } => {
                skin.bind_positions.extend(points.iter().map(|&p| to_bind.transform_point3(p)));
                let turn = normal_matrix(&to_bind);
                skin.normals.extend(normals.map(|n| turn * n));
                rows.extend(std::iter::repeat_n(vec![(joint, 1.0)], count));
                return Ok(());
            }
            Bound::Skinned(_) => {
                skin.bind_positions.extend(points);
                skin.normals.extend(normals);
            }
        }
        let Bound::Skinned(joints) = *bound else { unreachable!("rigid primitives returned") };
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
                        let joint = *joints.get(j[k] as usize).ok_or_else(|| {
                            self.error(format!(
                                "{at}.attributes.JOINTS_{set}: vertex {v} names joint {} of {}",
                                j[k],
                                joints.len()
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
    /// at `first`) to `morphs`: target k of the node's mesh is morph `first_morph + k`, for
    /// every primitive of the mesh. A name that an earlier node's target has gets the
    /// node's name after it.
    #[allow(clippy::too_many_arguments)]
    fn morph_targets(
        &self,
        node: &gltf::Node,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        at_primitive: &str,
        first: usize,
        bound: &Bound,
        first_morph: usize,
        morphs: &mut Vec<MorphTarget>,
    ) -> Result<(), FormatError> {
        let names = target_names(mesh);
        let reader = primitive.reader(self.data());
        for (k, (positions, _, _)) in reader.read_morph_targets().enumerate() {
            if morphs.len() <= first_morph + k {
                let mut name =
                    names.get(k).cloned().unwrap_or_else(|| format!("{} target {k}", mesh.name().unwrap_or("mesh")));
                if morphs[..first_morph].iter().any(|m| m.name == name) {
                    name = format!(
                        "{name} ({})",
                        node.name().map_or_else(|| format!("node {}", node.index()), str::to_string)
                    );
                }
                morphs.push(MorphTarget { name, deltas: Vec::new() });
            }
            let deltas: Vec<(usize, [f32; 3])> =
                positions.into_iter().flatten().enumerate().filter(|(_, d)| *d != [0.0; 3]).collect();
            if let Some((v, _)) = deltas.iter().find(|(_, d)| !d.iter().all(|x| x.is_finite())) {
                return Err(self.error(format!(
                    "{at_primitive}.targets[{k}].POSITION: expected finite numbers, found a move of vertex {v} that is not"
                )));
            }
            let to_bind = match *bound {
                Bound::Rigid { to_bind, .. } => to_bind,
                Bound::Skinned(_) => Mat4::IDENTITY,
            };
            morphs[first_morph + k].deltas.extend(
                deltas.into_iter().map(|(v, d)| ((first + v) as u32, to_bind.transform_vector3(Vec3::from(d)))),
            );
        }
        Ok(())
    }

    /// The file's animations that move the part's nodes or morph weights, as clips by
    /// joint index and morph index (`morph_of`: each mesh node's first morph and count).
    fn clips(
        &self,
        joint_of_node: &[Option<usize>],
        joint_count: usize,
        morph_of: &[(usize, usize, usize)],
        morph_count: usize,
        root_parent: Mat4,
    ) -> Result<Vec<NodeClip>, FormatError> {
        let mut clips = Vec::new();
        for animation in self.gltf.animations() {
            let mut tracks = vec![JointTracks::default(); joint_count];
            let mut weights = vec![None; morph_count];
            let mut moved = false;
            for channel in animation.channels() {
                let node = channel.target().node().index();
                let morphs = morph_of.iter().find(|m| m.0 == node).filter(|m| m.2 > 0);
                let joint = joint_of_node[node];
                let keys_weights = channel.target().property() == gltf::animation::Property::MorphTargetWeights;
                if (keys_weights && morphs.is_none()) || (!keys_weights && joint.is_none()) {
                    continue;
                }
                let sampler = format!("at $.animations[{}].samplers[{}]", animation.index(), channel.sampler().index());
                let reader = channel.reader(self.data());
                let times = self.key_times(reader.read_inputs(), &sampler)?;
                let interpolation = match channel.sampler().interpolation() {
                    gltf::animation::Interpolation::Step => Interpolation::Step,
                    gltf::animation::Interpolation::Linear => Interpolation::Linear,
                    gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
                };
                let outputs = reader
                    .read_outputs()
                    .ok_or_else(|| self.error(format!("{sampler}.output: expected key values, found none")))?;
                let incomplete = || {
                    self.error(format!("{sampler}: expected a value per key time (three for CUBICSPLINE) and a key, found {} key times", times.len()))
                };
                use gltf::animation::util::ReadOutputs;
                match (outputs, joint, morphs) {
                    (ReadOutputs::Translations(v), Some(j), _) => {
                        let values: Vec<Vec3> = v.map(Vec3::from).collect();
                        finite_keys(values.iter().map(|v| v.is_finite()), &sampler).map_err(|e| self.error(e))?;
                        tracks[j].translation = Some(complete(&times, values, interpolation).ok_or_else(incomplete)?);
                    }
                    (ReadOutputs::Rotations(v), Some(j), _) => {
                        let values: Vec<Quat> = v.into_f32().map(Quat::from_array).collect();
                        // CUBICSPLINE tangents may be zero; values must be rotations.
                        let rotation = |k: usize, q: &Quat| {
                            q.is_finite()
                                && (interpolation == Interpolation::CubicSpline && k % 3 != 1
                                    || crate::checks::is_normalisable(*q))
                        };
                        finite_keys(values.iter().enumerate().map(|(k, q)| rotation(k, q)), &sampler)
                            .map_err(|e| self.error(format!("{e} (a rotation that is not zero)")))?;
                        tracks[j].rotation = Some(complete(&times, values, interpolation).ok_or_else(incomplete)?);
                    }
                    (ReadOutputs::Scales(v), Some(j), _) => {
                        let values: Vec<Vec3> = v.map(Vec3::from).collect();
                        finite_keys(values.iter().map(|v| v.is_finite()), &sampler).map_err(|e| self.error(e))?;
                        tracks[j].scale = Some(complete(&times, values, interpolation).ok_or_else(incomplete)?);
                    }
                    (ReadOutputs::MorphTargetWeights(v), _, Some(&(_, first, count))) => {
                        let flat: Vec<f32> = v.into_f32().collect();
                        finite_keys(flat.iter().map(|w| w.is_finite()), &sampler).map_err(|e| self.error(e))?;
                        if !flat.len().is_multiple_of(count) {
                            return Err(self.error(format!(
                                "{sampler}.output: expected a weight for each of the {count} morph targets per value, found {} weights",
                                flat.len()
                            )));
                        }
                        for k in 0..count {
                            let values: Vec<f32> = flat.iter().skip(k).step_by(count).copied().collect();
                            weights[first + k] = Some(complete(&times, values, interpolation).ok_or_else(incomplete)?);
                        }
                    }
                    _ => continue,
                }
                moved = true;
            }
            if moved {
                let name = animation.name().map_or_else(|| format!("animation {}", animation.index()), str::to_string);
                clips.push(NodeClip { name, index: animation.index(), tracks, weights, root_parent });
            }
        }
        Ok(clips)
    }

    /// A sampler's key times: finite and increasing.
    fn key_times(&self, read: Option<gltf::accessor::Iter<f32>>, sampler: &str) -> Result<Vec<f32>, FormatError> {
        let times: Vec<f32> =
            read.ok_or_else(|| self.error(format!("{sampler}.input: expected key times, found none")))?.collect();
        if let Some(k) = times.iter().position(|t| !t.is_finite()) {
            return Err(
                self.error(format!("{sampler}.input: expected finite key times, found {} at key {k}", times[k]))
            );
        }
        if let Some(k) = times.windows(2).position(|w| w[0].partial_cmp(&w[1]).is_none_or(|o| o.is_gt())) {
            return Err(self.error(format!(
                "{sampler}.input: key time {} follows {} (times must increase and be numbers)",
                times[k + 1],
                times[k]
            )));
        }
        Ok(times)
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

/// Whether each node is in the scene the file shows: under a root node of its `scene` (else
/// its first scene); every node when the file has no scenes.
fn shown_nodes(gltf: &gltf::Gltf, parent: &[Option<usize>]) -> Vec<bool> {
    let Some(scene) = gltf.default_scene().or_else(|| gltf.scenes().next()) else {
        return vec![true; parent.len()];
    };
    let mut shown: Vec<Option<bool>> = vec![None; parent.len()];
    for root in (0..parent.len()).filter(|&n| parent[n].is_none()) {
        shown[root] = Some(false);
    }
    // A scene's nodes should be roots; one that is not marks nothing (its root decides).
    for root in scene.nodes().filter(|n| parent[n.index()].is_none()) {
        shown[root.index()] = Some(true);
    }
    // Each node takes its root's answer: up to the first node that knows, then down the
    // path (each node is walked once, however deep the tree).
    let mut path = Vec::new();
    for start in 0..parent.len() {
        let mut node = start;
        while shown[node].is_none() {
            path.push(node);
            node = parent[node].expect("a node without an answer has a parent");
        }
        let answer = shown[node];
        path.drain(..).for_each(|n| shown[n] = answer);
    }
    shown.into_iter().map(|s| s == Some(true)).collect()
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

/// A track of `values` at `times`, when there are as many as its interpolation needs.
fn complete<T: marionette_rig::node_clip::Keyed>(
    times: &[f32],
    values: Vec<T>,
    interpolation: Interpolation,
) -> Option<Track<T>> {
    Some(Track { times: times.to_vec(), values, interpolation }).filter(Track::is_complete)
}

/// A node's transform in its parent's frame.
fn local_matrix(node: &gltf::Node) -> Mat4 {
    Mat4::from_cols_array_2d(&node.transform().matrix())
}

/// Whether `m` is a translation, rotation and scale (recomposed within 1e-5 of its size:
/// a file's rotations are unit only to single precision).
fn is_trs(m: Mat4) -> bool {
    let (s, r, t) = m.to_scale_rotation_translation();
    let back = Mat4::from_scale_rotation_translation(s, r, t);
    let size = m.to_cols_array().iter().fold(1.0f32, |a, x| a.max(x.abs()));
    back.abs_diff_eq(m, 1e-5 * size)
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
                gltf::buffer::Source::Uri(uri) => Cow::Owned(
                    super::uri::bytes(path, uri).map_err(|e| FormatError::other(path, format!("{at}.uri: {e}")))?,
                ),
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

/// The matrix that turns normals as `m` turns points: the inverse transpose of its 3×3
/// part (the part itself where that cannot be inverted).
fn normal_matrix(m: &Mat4) -> glam::Mat3 {
    let part = glam::Mat3::from_mat4(*m);
    if part.determinant().abs() > f32::MIN_POSITIVE { part.inverse().transpose() } else { part }
}

//! A loaded character: a skeleton, its skin and its bind matrices. Shared (in an `Arc`)
//! by every scene character made from the same files.

use glam::{Mat4, Vec3};

use super::RigError;
use super::fk::{bind_world_to_joint, forward_kinematics};
use super::material::{Material, SkinTexture, Surface};
use super::skeleton::{BoneBox, Skeleton};
use super::skinning::SkinWeights;

/// A triangle mesh in the bind (model) space and its weights.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Skin {
    /// Bind-pose vertex positions, model space.
    pub bind_positions: Vec<Vec3>,
    /// Triangles as indices into `bind_positions`, counter-clockwise front faces.
    pub triangles: Vec<[u32; 3]>,
    /// One row of influences per vertex.
    pub weights: SkinWeights,
    /// Texture coordinates, one per vertex (empty: none).
    pub texcoords: Vec<glam::Vec2>,
    /// Vertex colours (linear RGBA, glTF's `COLOR_0`), one per vertex (empty: white).
    pub colors: Vec<[f32; 4]>,
    /// Bind-pose normals, one per vertex (glTF's `NORMAL`, zero where a primitive has none),
    /// kept only for a skin whose material has a normal map: such a skin's normals are
    /// skinned with its positions and bent by the map. Empty: the skin is lit with each
    /// triangle's own normal, taken from its positions where it is drawn.
    pub normals: Vec<Vec3>,
}

impl Skin {
    /// A skin of positions, triangles and weights, without texture coordinates or colours.
    pub fn untextured(bind_positions: Vec<Vec3>, triangles: Vec<[u32; 3]>, weights: SkinWeights) -> Self {
        Self { bind_positions, triangles, weights, texcoords: Vec::new(), colors: Vec::new(), normals: Vec::new() }
    }

    /// Checks that weights and triangles fit the vertices.
    pub fn validate(&self) -> Result<(), RigError> {
        let count = self.bind_positions.len();
        if self.weights.vertex_count() != count {
            return Err(RigError::WeightCountMismatch { mesh: count, weights: self.weights.vertex_count() });
        }
        if !self.normals.is_empty() && self.normals.len() != count {
            return Err(RigError::NormalCountMismatch { mesh: count, normals: self.normals.len() });
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i as usize >= count) {
                return Err(RigError::TriangleIndexOutOfRange { triangle: t, index, count });
            }
        }
        Ok(())
    }
}

/// How a character's skin was made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SkinKind {
    /// A mesh with weights from the source files.
    Mesh,
    /// No mesh in the source: one box per joint, rigidly attached.
    BoneBoxes,
    /// Meshes carried rigidly by their nodes, none skinned: a prop.
    Rigid,
}

/// Everything loaded for one character.
#[derive(Debug, Clone, PartialEq)]
pub struct CharacterAsset {
    pub name: String,
    pub skeleton: Skeleton,
    pub skin: Skin,
    pub skin_kind: SkinKind,
    /// Inverse of each joint's model-space transform at the bind pose.
    pub bind_world_to_joint: Vec<Mat4>,
    /// Things the loader fixed and the user should know (normalised weight rows, ...).
    pub warnings: Vec<String>,
    /// Shapes the bind mesh can blend towards before skinning (CSE169 `.morph`).
    pub morphs: Vec<MorphTarget>,
    /// The materials the surfaces use (a glTF file's, a CSE169 skin's texture).
    pub materials: Vec<Material>,
    /// The runs of the mesh drawn with one material each (empty: one run, drawn with the
    /// first material if there is one, else the character's tint).
    pub surfaces: Vec<Surface>,
    /// The humanoid bones the file names (a VRM avatar's); empty where it names none.
    pub humanoid: super::humanoid::HumanoidMap,
    /// Named sets of morph weights (a VRM avatar's expressions).
    pub expressions: Vec<Expression>,
}

/// A named set of morph weights: each listed morph target at its weight, the rest at 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Expression {
    pub name: String,
    pub weights: Vec<(usize, f32)>,
}

impl Expression {
    /// The weights of `morphs` morph targets the expression sets.
    pub fn morph_weights(&self, morphs: usize) -> Vec<f32> {
        let mut out = vec![0.0; morphs];
        for &(m, w) in &self.weights {
            if let Some(slot) = out.get_mut(m) {
                *slot = (*slot + w).min(1.0);
            }
        }
        out
    }
}

/// A morph target: how far some vertices move (bind space) at full weight.
#[derive(Debug, Clone, PartialEq)]
pub struct MorphTarget {
    pub name: String,
    pub deltas: Vec<(u32, Vec3)>,
}

impl CharacterAsset {
    /// A skinned character whose bind pose is the skeleton's rest pose.
    pub fn new(
        name: impl Into<String>,
        skeleton: Skeleton,
        skin: Skin,
        warnings: Vec<String>,
    ) -> Result<Self, RigError> {
        skin.validate()?;
        let bind_world_to_joint = bind_world_to_joint(&skeleton, None);
        Ok(Self {
            name: name.into(),
            skeleton,
            skin,
            skin_kind: SkinKind::Mesh,
            bind_world_to_joint,
            warnings,
            morphs: Vec::new(),
            materials: Vec::new(),
            surfaces: Vec::new(),
            humanoid: Default::default(),
            expressions: Vec::new(),
        })
    }

    /// A skinned character bound by its own inverse bind matrices (one per joint), not
    /// by the skeleton's rest pose.
    pub fn with_inverse_binds(
        name: impl Into<String>,
        skeleton: Skeleton,
        skin: Skin,
        bind_world_to_joint: Vec<Mat4>,
        warnings: Vec<String>,
    ) -> Result<Self, RigError> {
        debug_assert_eq!(bind_world_to_joint.len(), skeleton.len());
        Self::new(name, skeleton, skin, warnings).map(|asset| Self { bind_world_to_joint, ..asset })
    }

    /// A prop: one mesh carried rigidly by a single joint at the origin (named after the
    /// prop), drawn with its tint.
    pub fn rigid(name: &str, positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, RigError> {
        let skeleton = Skeleton::build(vec![super::skeleton::RawJoint::new(name, None, Vec3::ZERO)])?;
        let weights = SkinWeights::rigid(&vec![0; positions.len()]);
        let asset = Self::new(name, skeleton, Skin::untextured(positions, triangles, weights), Vec::new())?;
        Ok(Self { skin_kind: SkinKind::Rigid, ..asset })
    }

    /// A character without a mesh: each joint's bone box (its own, or ±0.1) rigidly
    /// bound to that joint.
    pub fn with_bone_boxes(name: impl Into<String>, skeleton: Skeleton, warnings: Vec<String>) -> Self {
        let skin = bone_box_skin(&skeleton);
        let bind_world_to_joint = bind_world_to_joint(&skeleton, None);
        Self {
            name: name.into(),
            skeleton,
            skin,
            skin_kind: SkinKind::BoneBoxes,
            bind_world_to_joint,
            warnings,
            morphs: Vec::new(),
            materials: Vec::new(),
            surfaces: Vec::new(),
            humanoid: Default::default(),
            expressions: Vec::new(),
        }
    }

    /// The bind positions with the morph targets blended in by `weights` (one per target;
    /// missing ones are 0).
    pub fn morphed_positions(&self, weights: &[f32]) -> Vec<Vec3> {
        let mut positions = Vec::new();
        self.morph_into(weights, &mut positions);
        positions
    }

    /// [`Self::morphed_positions`] written into `positions` (its allocation reused).
    pub fn morph_into(&self, weights: &[f32], positions: &mut Vec<Vec3>) {
        positions.clear();
        positions.extend_from_slice(&self.skin.bind_positions);
        for (target, &w) in self.morphs.iter().zip(weights) {
            if w == 0.0 {
                continue;
            }
            for &(v, d) in &target.deltas {
                if let Some(p) = positions.get_mut(v as usize) {
                    *p += d * w;
                }
            }
        }
    }

    /// The surfaces to draw: its own, or one over the whole mesh.
    pub fn surfaces(&self) -> std::borrow::Cow<'_, [Surface]> {
        if !self.surfaces.is_empty() {
            return std::borrow::Cow::Borrowed(&self.surfaces);
        }
        let whole = Surface {
            vertices: 0..self.vertex_count() as u32,
            triangles: 0..self.triangle_count() as u32,
            material: (!self.materials.is_empty()).then_some(0),
        };
        std::borrow::Cow::Owned(vec![whole])
    }

    /// The first base colour texture of its materials.
    pub fn base_color_texture(&self) -> Option<&SkinTexture> {
        self.materials.iter().find_map(|m| m.base_color_texture.as_ref()).map(|t| &t.image)
    }

    pub fn vertex_count(&self) -> usize {
        self.skin.bind_positions.len()
    }

    pub fn triangle_count(&self) -> usize {
        self.skin.triangles.len()
    }

    /// Axis-aligned bounds of the bind-pose mesh (model space).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        super::skinning::bounds(&self.skin.bind_positions)
    }
}

/// The 12 triangles of a box, counter-clockwise seen from outside; corner `i` has
/// x from bit 0, y from bit 1, z from bit 2 (0 = min, 1 = max).
pub const BOX_TRIANGLES: [[u32; 3]; 12] = [
    [0, 2, 1],
    [1, 2, 3], // -z
    [4, 5, 6],
    [5, 7, 6], // +z
    [0, 1, 4],
    [1, 5, 4], // -y
    [2, 6, 3],
    [3, 6, 7], // +y
    [0, 4, 2],
    [2, 4, 6], // -x
    [1, 3, 5],
    [3, 7, 5], // +x
];

/// Corners of a box in the order [`BOX_TRIANGLES`] expects.
pub fn box_corners(b: &BoneBox) -> [Vec3; 8] {
    std::array::from_fn(|i| {
        Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        )
    })
}

/// One box per joint, placed at the joint's rest (file pose) frame, weighted 1 to it.
fn bone_box_skin(skeleton: &Skeleton) -> Skin {
    let mut rest = vec![Mat4::IDENTITY; skeleton.len()];
    forward_kinematics(skeleton, &skeleton.rest_pose(), Mat4::IDENTITY, &mut rest);
    let mut skin = Skin::default();
    let mut joint_of_vertex = Vec::new();
    let default_box = BoneBox { min: Vec3::splat(-0.1), max: Vec3::splat(0.1) };
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let first = skin.bind_positions.len() as u32;
        let b = joint.bone_box.unwrap_or(default_box);
        skin.bind_positions.extend(box_corners(&b).iter().map(|c| rest[j].transform_point3(*c)));
        skin.triangles.extend(BOX_TRIANGLES.iter().map(|t| t.map(|i| first + i)));
        joint_of_vertex.extend(std::iter::repeat_n(j as u16, 8));
    }
    skin.weights = SkinWeights::rigid(&joint_of_vertex);
    skin
}

//! Components of characters and joints.

use std::sync::Arc;

use bevy::prelude::*;

use crate::formats::scene::{PlacementDoc, ViewDoc};
use crate::rig::{CharacterAsset, DofLimits, JointRotation};

/// Which of the scenes drawn in one frame an entity belongs to: a camera that draws it,
/// its characters, its floor, sun and lamps; each slot on the render layer of its number.
/// The editor draws one scene, slot 0 (Bevy's default layer); a data set's render draws
/// several a frame, one a slot.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Slot(pub usize);

impl Slot {
    /// What marks an entity as the slot's: the slot, and its render layer.
    pub fn marks(self) -> (Self, bevy::camera::visibility::RenderLayers) {
        (self, bevy::camera::visibility::RenderLayers::layer(self.0))
    }
}

/// A character: the loaded asset it was made from (shared by every character made from
/// the same files), its joint entities by joint index and the entity that draws its skin.
#[derive(Component, Clone)]
#[require(
    Placement,
    CharacterView,
    CharacterSkinning,
    HeatJoint,
    PoseDirty,
    Transform,
    Visibility,
    RestOverrides,
    super::handoff::SkinUpload,
    super::handoff::SkinAttributes,
    SkinOnGpu,
    super::handoff::GpuSkinJob,
    Slot
)]
pub struct Character {
    pub asset: Arc<CharacterAsset>,
    /// `joints[i]` is the entity of joint `i` of `asset.skeleton`.
    pub joints: Vec<Entity>,
    /// The child entities that draw its skin: one per surface of the asset.
    pub skins: Vec<SkinPart>,
}

/// One surface of a character's skin as drawn: its entity, its render mesh (the
/// surface's own vertices) and the range of the skin's vertices it shows.
#[derive(Clone, Debug)]
pub struct SkinPart {
    pub entity: Entity,
    pub mesh: Handle<Mesh>,
    pub vertices: std::ops::Range<u32>,
    /// The asset's material it is drawn with (none: the character's tint alone).
    pub material: Option<usize>,
}

/// Where a character stands in the world (the scene file's own `PlacementDoc`: model
/// space → world is `T(translation) · Ry(yaw) · S(scale)`), on the character entity.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Deref, DerefMut)]
pub struct Placement(pub PlacementDoc);

impl Placement {
    pub fn new(translation: Vec3, yaw: f32, scale: f32) -> Self {
        Self(PlacementDoc::new(translation, yaw, scale))
    }

    pub fn at(translation: Vec3) -> Self {
        Self::new(translation, 0.0, 1.0)
    }

    /// The character's `Transform`: what places its joints and skin in the world.
    pub fn to_transform(&self) -> Transform {
        Transform { translation: self.translation, rotation: self.rotation(), scale: Vec3::splat(self.scale) }
    }
}

/// How a character is shown: skin, skeleton or both, visible, tint, weight colours, heat
/// map of the selected joint (the scene file's own `ViewDoc`, on the character entity).
#[derive(Component, Clone, Debug, Default, PartialEq, Deref, DerefMut)]
pub struct CharacterView(pub ViewDoc);

/// Linear blend or dual quaternion skinning: the scene file's own `SkinningDoc`, on the
/// character entity.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq, Deref, DerefMut)]
pub struct CharacterSkinning(pub crate::rig::dqs::SkinningMethod);

/// Whether the character is skinned by the GPU skinning compute shader instead of on the
/// CPU (the default); on the character entity.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq, Deref, DerefMut)]
pub struct SkinOnGpu(pub bool);

/// The joint whose weights the skin shows as a heat map (overrides weight colours); set
/// from the selection where the view asks for it.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HeatJoint(pub Option<usize>);

/// Set when a character's pose, placement or view changed and its skin must be redone.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PoseDirty {
    /// Joint matrices must be recomputed (pose or placement changed).
    pub matrices: bool,
    /// Bind matrices must be taken again from the asset (its rest pose was rebuilt).
    pub bind: bool,
    /// Vertex colours must be rewritten.
    pub colors: bool,
}

impl PoseDirty {
    pub const ALL: Self = Self { matrices: true, bind: true, colors: true };
}

/// Rest offsets and scales of a character's joints where a clip keys them, by joint index
/// (empty: the skeleton's own), on the character entity.
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct RestOverrides {
    pub offsets: Vec<Vec3>,
    pub scales: Vec<Vec3>,
}

impl RestOverrides {
    /// What the matrix stack takes in place of the skeleton's rest (only lists with one
    /// entry per joint).
    pub fn for_joints(&self, joints: usize) -> crate::rig::fk::RestOverride<'_> {
        fn fits(v: &[Vec3], joints: usize) -> Option<&[Vec3]> {
            (v.len() == joints).then_some(v)
        }
        crate::rig::fk::RestOverride { offsets: fits(&self.offsets, joints), scales: fits(&self.scales, joints) }
    }
}

/// A joint of a character.
#[derive(Component, Clone, Debug)]
#[require(JointPose, JointLimits, BindWorldToJoint, CurrentJointToWorld)]
pub struct Joint {
    /// Index in the character's skeleton (and in its weights).
    pub index: usize,
    pub name: String,
    /// The character entity this joint belongs to.
    pub character: Entity,
}

/// The joint's rotation relative to its parent, kept within its limits.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct JointPose(pub JointRotation);

/// The joint's rotation limits (radians).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct JointLimits(pub DofLimits);

/// Inverse of the joint's model-space transform at the bind (rest) pose.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct BindWorldToJoint(pub Mat4);

impl Default for BindWorldToJoint {
    fn default() -> Self {
        Self(Mat4::IDENTITY)
    }
}

/// The joint's current transform in the character's model space (the character's
/// `Transform`, its placement, takes it to the world: see [`Self::world`]).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct CurrentJointToWorld(pub Mat4);

impl Default for CurrentJointToWorld {
    fn default() -> Self {
        Self(Mat4::IDENTITY)
    }
}

impl CurrentJointToWorld {
    /// The joint's position in model space.
    pub fn position(&self) -> Vec3 {
        self.0.w_axis.truncate()
    }

    /// The joint's transform in the world, for a character at `placement`.
    pub fn world(&self, placement: &Placement) -> Mat4 {
        placement.to_mat4() * self.0
    }

    /// The joint's position in the world, for a character at `placement`.
    pub fn world_position(&self, placement: &Placement) -> Vec3 {
        placement.to_mat4().transform_point3(self.position())
    }
}

/// Marks the entity that draws a character's skin.
#[derive(Component, Clone, Copy, Debug)]
pub struct SkinMesh {
    pub character: Entity,
    /// Its index in the character's `skins`.
    pub part: usize,
}

/// The matrix-stack pass's output and scratch, by joint index (no allocation per frame):
/// `matrices` are the joints' current model-space matrices, which the skinning reads (the
/// joint entities' `CurrentJointToWorld` get the same, for picking and drawing).
#[derive(Component, Default)]
pub struct JointScratch {
    pub pose: Vec<crate::rig::JointRotation>,
    pub matrices: Vec<Mat4>,
}

/// Scratch buffers reused by the skinning system (no allocation per frame).
#[derive(Component, Default)]
pub struct SkinScratch {
    pub palette: Vec<Mat4>,
    /// The skinned vertices, model space; shared with the render world while it writes
    /// them into the mesh (see [`reclaimed`](super::handoff::reclaimed)).
    pub positions: Arc<Vec<Vec3>>,
    /// The skinned normals (not normalised) of a skin that has normals (`Skin::normals`),
    /// shared like the positions; empty otherwise.
    pub normals: Arc<Vec<Vec3>>,
    /// The vertex colours.
    pub colors: Vec<[f32; 4]>,
    /// The skinned vertices' box.
    pub bounds: (Vec3, Vec3),
    /// The palette as dual quaternions (dual quaternion skinning).
    pub dual_quaternions: Vec<crate::rig::dqs::DualQuat>,
    /// What the mesh's colours were last written from.
    pub colored_with: Option<Coloring>,
    /// Each joint's box of the bind vertices it moves, and the asset they were taken from
    /// (GPU-skinned characters' bounds; see [`SkinScratch::influence_hull_bounds`]).
    influence_boxes: Option<(Arc<CharacterAsset>, Vec<(Vec3, Vec3)>)>,
}

impl SkinScratch {
    /// A box that holds the skin posed by `palette` (linear blend) without skinning it:
    /// the hull of the joints' influence boxes of `asset`, taken again when the asset
    /// changed (a reshape, a rebind, a morph).
    pub fn influence_hull_bounds(&mut self, asset: &Arc<CharacterAsset>) -> (Vec3, Vec3) {
        if !self.influence_boxes.as_ref().is_some_and(|(of, _)| Arc::ptr_eq(of, asset)) {
            let skin = &asset.skin;
            let boxes =
                crate::rig::skinning::influence_boxes(&skin.bind_positions, &skin.weights, asset.skeleton.len());
            self.influence_boxes = Some((asset.clone(), boxes));
        }
        let boxes = self.influence_boxes.as_ref().map_or(&[][..], |(_, b)| b);
        crate::rig::skinning::influence_hull_bounds(boxes, &self.palette)
    }
}

/// What a skin's colours depend on: a view change that leaves this alone (display mode,
/// visibility) rewrites no colours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coloring {
    tint: [f32; 3],
    weight_colors: bool,
    heat_joint: Option<usize>,
}

impl Coloring {
    pub fn of(view: &CharacterView, heat: &HeatJoint) -> Self {
        Self { tint: view.tint, weight_colors: view.weight_colors, heat_joint: heat.0 }
    }
}

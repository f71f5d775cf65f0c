//! The rig core: skeletons, the matrix stack, poses, forward kinematics and skinning.
//! Pure data and math; no Bevy.

pub mod anim;
#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx512;
pub mod bind;
pub mod body_poses;
pub mod bones;
pub mod character;
pub mod dqs;
pub mod fk;
pub mod hands;
pub mod heat;
pub mod humanoid;
pub mod ik;
pub mod influences;
pub mod keyframe_splines;
#[cfg(target_arch = "x86_64")]
mod lanes;
pub mod lbs;
pub mod look_at;
pub mod material;
pub mod matrix_stack;
pub mod mirror;
pub mod node_clip;
pub mod playback;
pub mod pose;
pub mod retarget;
pub mod simd;
pub mod skeleton;
pub mod skinning;
pub mod smpl;
pub mod triangle_tree;
pub mod turn;
pub mod two_bone;

pub use character::{CharacterAsset, MorphTarget, Skin};
pub use fk::{bind_world_to_joint, forward_kinematics, skinning_palette};
pub use material::{Picture, SkinTexture};
pub use matrix_stack::MatrixStack;
pub use pose::{DofLimits, EulerOrder, JointRotation};
pub use skeleton::{BoneBox, JointDef, RawJoint, Skeleton};
pub use skinning::{Influence, SkinWeights};

/// The most joints a skeleton may have: influences name their joint in 16 bits.
pub const MAX_JOINTS: usize = 1 << 16;

/// What can be wrong with a rig, independent of the file it came from.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RigError {
    #[error("the skeleton has no joints")]
    EmptySkeleton,
    #[error("the skeleton has {count} joints, more than the {MAX_JOINTS} a skin can address")]
    TooManyJoints { count: usize },
    #[error("joint {joint}: parent index {parent} is out of range (the skeleton has {count} joints)")]
    ParentOutOfRange { joint: usize, parent: usize, count: usize },
    #[error("the skeleton has several roots: {}", roots.join(", "))]
    SeveralRoots { roots: Vec<String> },
    #[error("joint `{joint}` is on a cycle of parents")]
    Cycle { joint: String },
    #[error("joint `{joint}` (index {index}) comes before its parent {parent}")]
    NotParentFirst { joint: String, index: usize, parent: usize },
    #[error("vertex {vertex}: joint {joint} is out of range (the skeleton has {count} joints)")]
    InfluenceJointOutOfRange { vertex: usize, joint: usize, count: usize },
    #[error("vertex {vertex}: weight {weight} for joint {joint} is negative or not a number")]
    BadWeight { vertex: usize, joint: usize, weight: f32 },
    #[error("the skin has more than 2^32 influences")]
    TooManyInfluences,
    #[error("vertex {vertex} has no positive weight")]
    NoInfluence { vertex: usize },
    #[error("the mesh has {mesh} vertices but the weights cover {weights}")]
    WeightCountMismatch { mesh: usize, weights: usize },
    #[error("triangle {triangle} uses vertex {index}, but the mesh has {count}")]
    TriangleIndexOutOfRange { triangle: usize, index: u32, count: usize },
    #[error("the mesh has {mesh} vertices but {normals} normals")]
    NormalCountMismatch { mesh: usize, normals: usize },
}

#[cfg(test)]
mod tests;

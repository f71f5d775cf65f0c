//! The ECS: characters and joints as entities, our matrix-stack system and CPU skinning.
//!
//! System order, configured once in [`RigCorePlugin`] (all in `PostUpdate`, before Bevy's
//! transform propagation, which plays no part in joint matrices):
//!
//! `Animate` (edits, SMPL and keyframed clips) → `Solve` (IK, limits) → `MatrixStack` (place, mark, bind,
//! FK) → `Skin` (LBS or DQ, colours, bounds, packed vertices) → `Draw` (skeleton gizmos,
//! overlays).
//!
//! Joint matrices and skins are in each character's model space; its `Transform` (set from
//! `Placement`) places it, so moving a character re-skins nothing. Forward kinematics is
//! `rig::fk` over the asset's skeleton (the one source of rest offsets); inverse binds are
//! the asset's, shared by its instances. Skinning runs in parallel and hands its packed
//! vertices straight to each mesh's GPU slot ([`upload`]); skins carry no normals (the
//! skin material lights each triangle with its own).

pub mod components;
pub mod gpu_skinning;
pub mod handoff;
pub mod keyframes;
pub mod morphs;
pub mod motion;
pub mod node_clips;
pub mod smpl;
pub mod spawn;
pub mod systems;
pub mod upload;

use bevy::prelude::*;

pub use components::*;
pub use spawn::{despawn_character, spawn_character, spawn_character_posed};

/// The ordered steps of a frame.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MarionetteSystems {
    /// Motion playback and user edits write `JointPose`.
    Animate,
    /// Inverse kinematics and limit clamping adjust `JointPose`.
    Solve,
    /// Placement to `Transform`; bind pass and matrix stack write `BindWorldToJoint` and
    /// `CurrentJointToWorld` (model space).
    MatrixStack,
    /// Skinning packs the vertices handed to the GPU (see [`upload`]).
    Skin,
    /// Drawing of skeletons and overlays.
    Draw,
}

/// The steps of `Animate`, in the order they run (declared here, once): what builds the
/// scene and applies its edits, then motion (every clock, then every character's pose by
/// the one motion service: SMPL playback, keyframed clips, the sources' own clips), and
/// last the morph weights that motion and the edits set, so a shape never lags its pose by
/// a frame.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AnimateSteps {
    Document,
    Motion,
    Morphs,
}

/// Every kind of playback in `Animate`: motion (SMPL clips, keyframed clips, a glTF
/// file's own clips) and morph weights.
pub struct PlaybackPlugin;

impl Plugin for PlaybackPlugin {
    fn build(&self, app: &mut App) {
        app.add_plugins((motion::MotionPlugin, morphs::MorphPlugin));
    }
}

/// Configures the set chain (once) and runs the matrix stack.
pub struct RigCorePlugin;

impl Plugin for RigCorePlugin {
    fn build(&self, app: &mut App) {
        app.configure_sets(
            PostUpdate,
            (
                MarionetteSystems::Animate,
                MarionetteSystems::Solve,
                MarionetteSystems::MatrixStack,
                MarionetteSystems::Skin,
                MarionetteSystems::Draw,
            )
                .chain()
                .before(bevy::transform::TransformSystems::Propagate),
        )
        .configure_sets(
            PostUpdate,
            (AnimateSteps::Document, AnimateSteps::Motion, AnimateSteps::Morphs)
                .chain()
                .in_set(MarionetteSystems::Animate),
        )
        .add_systems(PostUpdate, systems::clamp_poses_to_limits.in_set(MarionetteSystems::Solve))
        .add_systems(
            PostUpdate,
            (
                systems::place_characters,
                systems::mark_changed_characters,
                systems::bind_rest_pose,
                systems::compute_joint_to_world,
            )
                .chain()
                .in_set(MarionetteSystems::MatrixStack),
        );
    }
}

/// Skinning of changed characters: on the CPU (in parallel), handed straight to their
/// meshes' GPU slots, or by the GPU skinning compute shader where a character asks for it.
pub struct SkinningPlugin;

impl Plugin for SkinningPlugin {
    fn build(&self, app: &mut App) {
        app.add_plugins((upload::SkinUploadPlugin, gpu_skinning::GpuSkinningPlugin))
            .add_systems(PostUpdate, systems::skin_changed_characters.in_set(MarionetteSystems::Skin));
    }
}

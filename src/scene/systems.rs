//! The systems of the rig chain: mark what changed, bind, run the matrix stack, skin.

use bevy::camera::primitives::Aabb;
use bevy::prelude::*;

use super::components::*;
use super::handoff::{GpuSkinJob, SkinAttributes, SkinUpload};
use crate::rig::JointRotation;
use crate::rig::fk::forward_kinematics_with_rest;
use crate::rig::skinning::{Bounds, bounds, heat_colors, joint_colors, weight_colors};
use crate::rig::{dqs, lbs};

/// Clamps changed joint poses to their limits (reads `JointLimits`, writes `JointPose`).
pub fn clamp_poses_to_limits(mut joints: Query<(&mut JointPose, &JointLimits), Changed<JointPose>>) {
    for (mut pose, limits) in &mut joints {
        let clamped = pose.0.clamped(&limits.0);
        pose.set_if_neq(JointPose(clamped));
    }
}

/// Marks characters whose joints' poses or whose colouring (tint, weight colours, heat
/// joint; not the display mode or visibility) changed (reads change ticks, writes
/// `PoseDirty`). A new placement is no reason: joints and skin live in the character's
/// model space, and its `Transform` places them. Whoever rebuilds the rest pose (an SMPL
/// reshape) sets `PoseDirty::bind` itself.
pub fn mark_changed_characters(
    posed: Query<&Joint, Changed<JointPose>>,
    mut characters: Query<(
        &CharacterView,
        &HeatJoint,
        &SkinScratch,
        Ref<CharacterSkinning>,
        Ref<SkinOnGpu>,
        Ref<super::keyframes::RootTranslation>,
        Ref<RestOverrides>,
        &mut PoseDirty,
    )>,
) {
    for joint in &posed {
        if let Ok((.., mut dirty)) = characters.get_mut(joint.character) {
            dirty.matrices = true;
        }
    }
    for (view, heat, scratch, method, on_gpu, root, rest, mut dirty) in &mut characters {
        if scratch.colored_with != Some(Coloring::of(view, heat)) {
            dirty.colors = true;
        }
        if method.is_changed() || on_gpu.is_changed() || root.is_changed() || rest.is_changed() {
            dirty.matrices = true;
        }
    }
}

/// Places each moved character: its `Transform` is its placement (reads `Placement`;
/// writes `Transform`). Nothing is re-skinned.
pub fn place_characters(mut characters: Query<(&Placement, &mut Transform), Changed<Placement>>) {
    for (placement, mut transform) in &mut characters {
        transform.set_if_neq(placement.to_transform());
    }
}

/// The bind pass, for characters whose rest pose was rebuilt (an SMPL reshape swaps in a
/// new asset): each joint takes the asset's inverse bind, computed once when the asset
/// was built and shared by its instances (reads `Character`; writes `BindWorldToJoint`).
pub fn bind_rest_pose(characters: Query<(&Character, &PoseDirty)>, mut binds: Query<&mut BindWorldToJoint>) {
    for (character, dirty) in &characters {
        if !dirty.bind {
            continue;
        }
        for (&entity, &inverse) in character.joints.iter().zip(&character.asset.bind_world_to_joint) {
            if let Ok(mut bind) = binds.get_mut(entity) {
                bind.0 = inverse;
            }
        }
    }
}

/// The matrix-stack pass: for characters marked dirty, gathers the joints' poses by joint
/// index and runs the one forward kinematics of `rig` over the asset's skeleton (the
/// matrix stack: push `T(offset) · R(pose) · S(scale)`, write the top, descend, pop) from
/// the model-space origin, with the rest a clip keys (reads `JointPose`, `Character`,
/// `RestOverrides`; writes `CurrentJointToWorld`).
pub fn compute_joint_to_world(
    mut characters: Query<(
        &Character,
        &PoseDirty,
        &super::keyframes::RootTranslation,
        &RestOverrides,
        &mut JointScratch,
    )>,
    poses: Query<&JointPose>,
    mut currents: Query<&mut CurrentJointToWorld>,
) {
    for (character, dirty, root, rest, mut scratch) in &mut characters {
        if !dirty.matrices && !dirty.bind {
            continue;
        }
        let JointScratch { pose, matrices } = &mut *scratch;
        pose.clear();
        pose.extend(character.joints.iter().map(|&e| poses.get(e).map_or(JointRotation::IDENTITY, |p| p.0)));
        matrices.resize(character.joints.len(), Mat4::IDENTITY);
        let skeleton = &character.asset.skeleton;
        let origin = root.origin(skeleton.joints().first().map_or(Vec3::ZERO, |j| j.rest_offset));
        forward_kinematics_with_rest(skeleton, pose, rest.for_joints(skeleton.len()), origin, matrices);
        for (&entity, &m) in character.joints.iter().zip(matrices.iter()) {
            if let Ok(mut current) = currents.get_mut(entity) {
                current.0 = m;
            }
        }
    }
}

/// Batches of characters a thread the skin phase splits the crowd into: a few characters a
/// batch, so that a thread held up elsewhere leaves its share to the others (Bevy's default
/// of one batch a thread left the phase a third longer).
pub const SKIN_BATCHES_PER_THREAD: usize = 8;

/// Skins characters marked dirty, in model space and in parallel on Bevy's compute task
/// pool: palette `current · bind` from the matrix stack's output (`JointScratch`) and the
/// asset's shared inverse binds, the LBS or DQ kernel of the bind vertices and their
/// bounds; the colours and texture coordinates when the colours changed, packed for the
/// skin material (see `SkinAttributes`). Characters skinned on the GPU hand over the
/// palette instead. Then [`finish_skinned_characters`], in the same system: a system of
/// its own cost the phase a hand-over between threads each frame (reads `JointScratch`,
/// `Character`; writes `SkinScratch`, `SkinUpload`, `SkinAttributes`, `GpuSkinJob`,
/// `PoseDirty`, the skins' `Aabb`).
pub fn skin_changed_characters(
    mut characters: Query<(
        &Character,
        &CharacterView,
        &CharacterSkinning,
        &SkinOnGpu,
        &HeatJoint,
        &mut PoseDirty,
        &mut SkinScratch,
        &mut SkinUpload,
        &mut SkinAttributes,
        &mut GpuSkinJob,
        &JointScratch,
    )>,
    mut skin_bounds: Query<&mut Aabb, With<SkinMesh>>,
) {
    let batches = bevy::ecs::batching::BatchingStrategy::new().batches_per_thread(SKIN_BATCHES_PER_THREAD);
    characters.par_iter_mut().batching_strategy(batches).for_each(
        |(character, view, method, on_gpu, heat, dirty, mut scratch, mut upload, mut attributes, mut job, joints)| {
            if *dirty == PoseDirty::default() {
                return;
            }
            let skin = &character.asset.skin;
            let scratch = &mut *scratch;
            let never_skinned = scratch.positions.len() != skin.bind_positions.len();
            let moved = dirty.matrices || dirty.bind || never_skinned;
            if moved {
                // The matrix stack's own output and the asset's shared inverse binds: no
                // joint entity is read back.
                let current = |j: usize| joints.matrices.get(j).copied().unwrap_or(Mat4::IDENTITY);
                let binds = &character.asset.bind_world_to_joint;
                scratch.palette.clear();
                scratch.palette.extend(binds.iter().enumerate().map(|(j, bind)| current(j) * *bind));
            }
            let recolored = dirty.colors || scratch.colors.len() != skin.bind_positions.len();
            if recolored {
                vertex_colors(character, view, heat.0, &mut scratch.colors);
                attributes.pack(&skin.texcoords, &scratch.colors);
            }
            // The compute shader writes one mesh's positions: characters drawn in several
            // surfaces, or with normals, are skinned here.
            if on_gpu.0 && character.skins.len() == 1 && skin.normals.is_empty() {
                // The first skin is done here as well: its positions frame the scene and
                // stand the characters on the floor when it opens.
                if never_skinned {
                    skin_on_cpu(skin, method.0, scratch);
                } else if moved {
                    scratch.bounds = scratch.influence_hull_bounds(&character.asset);
                }
                super::gpu_skinning::hand_over(&mut job, character, method.0, scratch);
                return;
            }
            if job.0.is_some() {
                job.0 = None;
            }
            if moved {
                skin_on_cpu(skin, method.0, scratch);
                // Marks the upload changed: the render world takes the new positions.
                upload.vertex_count = skin.bind_positions.len();
                upload.with_normals = !skin.normals.is_empty();
            }
        },
    );
    let finished = characters.iter_mut().map(|(c, v, _, _, h, d, s, ..)| (c, v, h, d, s));
    finish_skinned_characters(finished, &mut skin_bounds);
}

/// The LBS or DQ kernel of the skin into `scratch.positions` (and its normals into
/// `scratch.normals` where it has them), and their bounds (grown as the linear kernel
/// writes them).
fn skin_on_cpu(skin: &crate::rig::Skin, method: dqs::SkinningMethod, scratch: &mut SkinScratch) {
    let SkinScratch { palette, dual_quaternions, positions, normals, .. } = scratch;
    let positions = super::handoff::reclaimed(positions);
    positions.resize(skin.bind_positions.len(), Vec3::ZERO);
    let normals = super::handoff::reclaimed(normals);
    normals.resize(skin.normals.len(), Vec3::ZERO);
    scratch.bounds = if method.is_linear() && !normals.is_empty() {
        let normals = lbs::Normals { bind: &skin.normals, out: normals };
        lbs::skin_with_normals(&skin.bind_positions, &skin.weights, palette, positions, normals).pair()
    } else if method.is_linear() {
        skin_in_chunks(skin, palette, positions).pair()
    } else {
        dqs::dual_quaternion_palette(palette, dual_quaternions);
        if normals.is_empty() {
            dqs::skin_dq(&skin.bind_positions, &skin.weights, dual_quaternions, positions);
        } else {
            let normals = lbs::Normals { bind: &skin.normals, out: normals };
            dqs::skin_dq_with_normals(&skin.bind_positions, &skin.weights, dual_quaternions, positions, normals);
        }
        bounds(positions)
    };
}

/// Vertices per task when one mesh is skinned on several threads.
pub const SKIN_CHUNK_VERTICES: usize = 16_384;

/// Skins a mesh, in chunks of [`SKIN_CHUNK_VERTICES`] on the compute task pool when it is
/// larger than one; returns the box of its vertices.
fn skin_in_chunks(skin: &crate::rig::Skin, palette: &[Mat4], out: &mut [Vec3]) -> Bounds {
    if out.len() <= SKIN_CHUNK_VERTICES {
        return lbs::skin_bounded(&skin.bind_positions, &skin.weights, palette, out);
    }
    let chunks = bevy::tasks::ComputeTaskPool::get().scope(|scope| {
        for (k, chunk) in out.chunks_mut(SKIN_CHUNK_VERTICES).enumerate() {
            scope.spawn(async move {
                lbs::skin_chunk(&skin.bind_positions, &skin.weights, palette, k * SKIN_CHUNK_VERTICES, chunk)
            });
        }
    });
    chunks.into_iter().fold(Bounds::EMPTY, Bounds::union)
}

/// Keeps each re-skinned character's bounds right (so culling follows the deformed mesh),
/// notes what its colours were made from and clears `PoseDirty`.
fn finish_skinned_characters<'a>(
    characters: impl Iterator<
        Item = (&'a Character, &'a CharacterView, &'a HeatJoint, Mut<'a, PoseDirty>, Mut<'a, SkinScratch>),
    >,
    skin_bounds: &mut Query<&mut Aabb, With<SkinMesh>>,
) {
    for (character, view, heat, mut dirty, mut scratch) in characters {
        if *dirty == PoseDirty::default() {
            continue;
        }
        for part in &character.skins {
            if let Ok(mut aabb) = skin_bounds.get_mut(part.entity) {
                let (lo, hi) = scratch.bounds;
                aabb.set_if_neq(Aabb::from_min_max(lo, hi));
            }
        }
        scratch.colored_with = Some(Coloring::of(view, heat));
        *dirty = PoseDirty::default();
    }
}

/// The vertex colours: the tint, the weight colours or a joint's heat map.
fn vertex_colors(character: &Character, view: &CharacterView, heat_joint: Option<usize>, out: &mut Vec<[f32; 4]>) {
    let skin = &character.asset.skin;
    let mut per_vertex = vec![view.tint; skin.bind_positions.len()];
    if let Some(j) = heat_joint.filter(|&j| j < character.joints.len()) {
        heat_colors(&skin.weights, j, &mut per_vertex);
    } else if view.weight_colors {
        weight_colors(&skin.weights, &joint_colors(character.joints.len()), &mut per_vertex);
    }
    out.clear();
    out.extend(per_vertex.into_iter().map(|[r, g, b]| [r, g, b, 1.0]));
    // The file's own vertex colours, under the tint (not under weights or heat).
    if heat_joint.is_none() && !view.weight_colors && skin.colors.len() == out.len() {
        out.iter_mut().zip(&skin.colors).for_each(|(c, v)| *c = std::array::from_fn(|k| c[k] * v[k]));
    }
}

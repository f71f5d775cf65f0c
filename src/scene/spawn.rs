//! Spawning a character: one character entity, one entity per joint (a `ChildOf` tree under
//! the character), and a child entity with the render mesh.

use std::sync::Arc;

use bevy::asset::RenderAssetUsages;
use bevy::camera::primitives::Aabb;
use bevy::camera::visibility::NoAutoAabb;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;

use super::components::*;
use crate::rig::{CharacterAsset, JointRotation};

/// Spawns a character made from `asset` at `placement`, in the file's initial pose.
/// Returns the character entity. Joint and skin matrices are filled by the next update.
pub fn spawn_character(
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    asset: Arc<CharacterAsset>,
    placement: Placement,
) -> Entity {
    let pose = asset.skeleton.initial_pose();
    spawn_character_posed(commands, meshes, asset, placement, &pose)
}

/// As [`spawn_character`], in `pose` (one rotation per joint, clamped to the limits).
///
/// # Panics
/// When `pose` does not have one entry per joint.
pub fn spawn_character_posed(
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    asset: Arc<CharacterAsset>,
    placement: Placement,
    pose: &[JointRotation],
) -> Entity {
    assert_eq!(pose.len(), asset.skeleton.len(), "one pose entry per joint");
    let character = commands.spawn((Name::new(asset.name.clone()), placement, placement.to_transform())).id();
    let skeleton = &asset.skeleton;
    let mut joints: Vec<Entity> = Vec::with_capacity(skeleton.len());
    for (index, def) in skeleton.joints().iter().enumerate() {
        let parent = def.parent.map_or(character, |p| joints[p]);
        let joint = commands
            .spawn((
                Joint { index, name: def.name.clone(), character },
                Name::new(def.name.clone()),
                // The asset's inverse binds, shared by every instance (the bind pass runs
                // only when the rest pose is rebuilt, e.g. SMPL β).
                BindWorldToJoint(asset.bind_world_to_joint[index]),
                JointPose(pose[index].clamped(&def.limits)),
                JointLimits(def.limits),
                ChildOf(parent),
            ))
            .id();
        joints.push(joint);
    }
    let skins = asset
        .surfaces()
        .iter()
        .enumerate()
        .map(|(part, surface)| {
            let mesh = meshes.add(surface_mesh(&asset.skin, surface));
            let entity = commands
                // The skinning system keeps the bounds right as the mesh deforms (model space).
                .spawn((
                    SkinMesh { character, part },
                    Mesh3d(mesh.clone()),
                    Transform::IDENTITY,
                    Aabb::default(),
                    NoAutoAabb,
                    ChildOf(character),
                ))
                .id();
            SkinPart { entity, mesh, vertices: surface.vertices.clone(), material: surface.material }
        })
        .collect();
    commands.entity(character).insert((
        Character { asset, joints, skins },
        super::keyframes::RootTranslation::default(),
        SkinScratch::default(),
        JointScratch::default(),
        PoseDirty { matrices: true, bind: false, colors: true },
    ));
    character
}

/// The render mesh of one surface of a skin: its vertices, and its triangles with their
/// indices counted from its first vertex.
fn surface_mesh(skin: &crate::rig::Skin, surface: &crate::rig::material::Surface) -> Mesh {
    let (first, end) = (surface.vertices.start, surface.vertices.end);
    let triangles: Vec<[u32; 3]> = skin.triangles[surface.triangles.start as usize..surface.triangles.end as usize]
        .iter()
        .map(|t| t.map(|i| i - first))
        .collect();
    empty_skin_mesh(&triangles, (end - first) as usize, !skin.normals.is_empty())
}

/// A render mesh of the skin's own vertices and triangles, positions only: no normals (the
/// skin material lights each triangle with its own normal, from the derivatives of the
/// position), and texture coordinates and colours in the skin materials' buffer
/// ([`SkinAttributes`](super::handoff::SkinAttributes)), so that a moving character hands
/// the GPU 12 bytes a vertex. A skin `with_normals` (a normal-mapped one) has them after
/// each position: 24 bytes a vertex.
pub fn empty_skin_mesh(triangles: &[[u32; 3]], vertex_count: usize, with_normals: bool) -> Mesh {
    // Only the render world keeps it: the skinning system writes positions straight into its
    // GPU slot (see `upload`), never into this asset.
    let mesh = Mesh::new(PrimitiveTopology::TriangleList, RenderAssetUsages::RENDER_WORLD)
        .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, vec![[0.0f32; 3]; vertex_count])
        .with_inserted_indices(Indices::U32(triangles.iter().flatten().copied().collect()));
    match with_normals {
        true => mesh.with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0f32; 3]; vertex_count]),
        false => mesh,
    }
}

/// Despawns a character, its joints leaves first and its skin mesh entity. Bevy's
/// recursive despawn would go as deep as the joint tree (a 50,000-joint chain overflows
/// the stack); joints are stored parents first, so in reverse each one is a leaf when it
/// goes.
pub fn despawn_character(commands: &mut Commands, entity: Entity, character: &Character) {
    for &joint in character.joints.iter().rev() {
        commands.entity(joint).try_despawn();
    }
    commands.entity(entity).try_despawn();
}

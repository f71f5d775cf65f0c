//! Finding a character's entity, components and joints in the world by its scene id, for
//! the commands.

use bevy::prelude::*;

use crate::editor::scene_doc::document::CharacterIndex;
use crate::formats::scene::CharacterId;
use crate::rig::{DofLimits, JointRotation};
use crate::scene::{Character, JointLimits, JointPose};

pub fn missing(id: CharacterId) -> String {
    format!("character {id} is not in the scene")
}

pub fn entity_of(world: &World, id: CharacterId) -> Result<Entity, String> {
    world.resource::<CharacterIndex>().get(id).ok_or_else(|| missing(id))
}

pub fn character_of(world: &World, id: CharacterId) -> Result<Character, String> {
    component::<Character>(world, id).cloned()
}

pub fn component<C: Component>(world: &World, id: CharacterId) -> Result<&C, String> {
    world.get::<C>(entity_of(world, id)?).ok_or_else(|| missing(id))
}

pub fn component_mut<C: Component<Mutability = bevy::ecs::component::Mutable>>(
    world: &mut World,
    id: CharacterId,
) -> Result<Mut<'_, C>, String> {
    let entity = entity_of(world, id)?;
    world.get_mut::<C>(entity).ok_or_else(|| missing(id))
}

/// A joint's pose and limits.
pub fn joint_state(world: &World, character: &Character, j: usize) -> Result<(JointRotation, DofLimits), String> {
    let no_joint = || format!("{} has no joint {j}", character.asset.name);
    let &entity = character.joints.get(j).ok_or_else(no_joint)?;
    let pose = world.get::<JointPose>(entity).ok_or_else(no_joint)?.0;
    let limits = world.get::<JointLimits>(entity).ok_or_else(no_joint)?.0;
    Ok((pose, limits))
}

/// The rotations that mirror a pose edit's joints onto their twins across the body (see
/// `rig::mirror::mirrored_joint`), each worked out with the edit's own joints turned; none
/// for joints on the middle, twins the edit sets itself, or a character without hips and
/// legs in its humanoid map.
pub fn twins_of(
    world: &World,
    character: CharacterId,
    joints: &[(usize, JointRotation)],
) -> Result<Vec<(usize, JointRotation)>, String> {
    let found = character_of(world, character)?;
    let entity = entity_of(world, character)?;
    let Some(map) = world.get::<crate::editor::scene_doc::document::HumanoidMapOf>(entity) else {
        return Ok(Vec::new());
    };
    let skeleton = &found.asset.skeleton;
    let Some(frame) = crate::rig::body_poses::facing_frame(skeleton, &map.0) else { return Ok(Vec::new()) };
    let mut pose =
        (0..found.joints.len()).map(|j| Ok(joint_state(world, &found, j)?.0)).collect::<Result<Vec<_>, String>>()?;
    for &(j, rotation) in joints {
        let (_, limits) = joint_state(world, &found, j)?;
        pose[j] = rotation.clamped(&limits);
    }
    let twin = crate::rig::mirror::counterparts(skeleton, &map.0);
    let set: Vec<usize> = joints.iter().map(|&(j, _)| j).collect();
    let mut mirrored: Vec<usize> = set.iter().copied().filter(|&j| !set.contains(&twin[j])).collect();
    // Parents' twins first: each twin turns under its parent as already mirrored.
    mirrored.sort_by_key(|&j| twin[j]);
    mirrored.dedup();
    let mut twins = Vec::new();
    for j in mirrored {
        if let Some((k, rotation)) =
            crate::rig::mirror::mirrored_joint(skeleton, &twin, &pose, j, frame * glam::Vec3::X)
        {
            pose[k] = rotation;
            twins.push((k, rotation));
        }
    }
    Ok(twins)
}

//! Finding a character's entity, components and joints in the world by its scene id, for
//! the commands.

use bevy::prelude::*;

use crate::editor::edits::edit::{self, Edit};
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

/// A pose edit that sets every joint of a character to its rotation now.
pub fn current_pose(world: &World, id: CharacterId) -> Result<Edit, String> {
    let found = character_of(world, id)?;
    let joints =
        (0..found.joints.len()).map(|j| Ok((j, joint_state(world, &found, j)?.0))).collect::<Result<_, String>>()?;
    Ok(edit::Pose { character: id, joints }.into())
}

//! Edits as commands. Every user action — from the panels, the shortcuts, a drag in the
//! viewport — is an [`Edit`] pushed to the [`EditQueue`]; [`apply_edits`] applies them to
//! the live ECS in `Animate` (so an edit is skinned the frame it is made) and records what
//! undoes each: its inverse, an `Edit` too. Undo and redo apply those inverses, so entities
//! and ids stay; only adding and removing spawn or despawn.

use bevy::ecs::system::SystemState;
use bevy::prelude::*;

pub use crate::editor::edits::edit::{Edit, EditQueue, GestureHold};
use crate::editor::edits::history::History;
use crate::editor::scene_doc::attach::Attached;
use crate::editor::scene_doc::document::{
    CharacterIndex, HumanoidBones, Library, NextCharacterId, SceneCharacter, SceneReader, spawn_from_doc,
};
use crate::editor::state::Messages;
use crate::editor::state::PoseLibrary;
use crate::editor::state::camera::Bookmarks;
use crate::editor::state::{ShotSettings, StageSettings};
use crate::formats::scene::{AnimDoc, BindingDoc, CharacterDoc, CharacterId};
use crate::rig::JointRotation;
use crate::scene::keyframes::ClipPlayer;
use crate::scene::node_clips::NodeClipPlayer;
use crate::scene::smpl::SmplCharacter;
use crate::scene::{
    Character, CharacterSkinning, CharacterView, JointLimits, JointPose, Placement, PoseDirty, SkinOnGpu,
};

/// Edits as commands, and their history.
pub struct CommandsPlugin;

impl Plugin for CommandsPlugin {
    fn build(&self, app: &mut App) {
        crate::editor::order::add_editor_order(app);
        app.init_resource::<EditQueue>()
            .init_resource::<History>()
            .init_resource::<crate::editor::state::SavedState>()
            .init_resource::<GestureHold>()
            .init_resource::<CharacterIndex>()
            .init_resource::<NextCharacterId>()
            .add_systems(PostUpdate, apply_edits.in_set(crate::editor::order::EditorSystems::Edits));
    }
}

/// Applies the queued edits and serves undo/redo, recording what undoes each edit into the
/// gesture under way. A gesture ends in the first frame no mouse button or widget is held,
/// and is judged (what changed) in the next, once that frame's chain has run: a clip's
/// pose is only written by playback. Exclusive: edits may spawn and despawn.
pub fn apply_edits(world: &mut World) {
    record_save(world);
    if world.resource::<History>().gesture_ended {
        close_gesture(world);
    }
    let queue = std::mem::take(&mut world.resource_mut::<EditQueue>().0);
    let request = world.resource_mut::<History>().request.take();
    if queue.is_empty() && request.is_none() && !world.resource::<History>().gesture_open() {
        return;
    }
    for edit in queue {
        for inverse in apply_reporting(world, edit) {
            world.resource_mut::<History>().record(inverse);
        }
    }
    let held = world.get_resource::<ButtonInput<MouseButton>>().is_some_and(|b| b.get_pressed().next().is_some())
        || world.resource::<GestureHold>().held();
    world.resource_mut::<History>().gesture_ended = !held;
    if request.is_some() {
        // What is undone must be a step first.
        close_gesture(world);
    }
    if let Some(request) = request
        && let Some((id, step)) = world.resource_mut::<History>().pop(request)
    {
        let back = replay(world, step);
        world.resource_mut::<History>().push_opposite(request, (id, back));
    }
}

/// A save made since the last frame marks the history's state as the file's.
fn record_save(world: &mut World) {
    let state = world.resource::<History>().state();
    if let Some(mut saved) = world.get_resource_mut::<crate::editor::state::SavedState>()
        && saved.saved_now
    {
        *saved = crate::editor::state::SavedState { at: state, changed_at_start: false, saved_now: false };
    }
}

/// Ends the gesture under way: what undoes it becomes one undo step, less what would
/// change nothing now (a drag that came back, a click that only selected).
fn close_gesture(world: &mut World) {
    let mut step = world.resource_mut::<History>().take_gesture();
    step.retain(|inverse| matches!(inverse_of(world, inverse), Ok(Some(_))));
    if !step.is_empty() {
        world.resource_mut::<History>().commit(step);
    }
}

/// Applies a step's edits last first; returns what undoes the replay.
fn replay(world: &mut World, step: Vec<Edit>) -> Vec<Edit> {
    step.into_iter().rev().flat_map(|edit| apply_reporting(world, edit)).collect()
}

fn apply_reporting(world: &mut World, edit: Edit) -> Vec<Edit> {
    apply(world, edit).unwrap_or_else(|message| {
        world.resource_mut::<Messages>().push(message);
        Vec::new()
    })
}

/// Applies `edit` to the live scene. Returns what undoes it, to be applied last first
/// (empty when it changed nothing), or why it could not be applied.
pub fn apply(world: &mut World, mut edit: Edit) -> Result<Vec<Edit>, String> {
    if let Edit::Add(doc) = &mut edit
        && doc.id.is_none()
    {
        doc.id = Some(world.resource_mut::<NextCharacterId>().take());
    }
    let Some(inverse) = inverse_of(world, &edit)? else { return Ok(Vec::new()) };
    let mut undo = Vec::with_capacity(2);
    if let Edit::Smpl { character, .. } | Edit::Playback { character, .. } = &edit {
        // Playback poses the joints from the clip; without a clip to return to, undo must
        // give the joints back their rotations.
        undo.push(current_pose(world, *character)?);
    }
    undo.push(inverse);
    write(world, edit)?;
    Ok(undo)
}

/// A pose edit that sets every joint of a character to its rotation now.
fn current_pose(world: &World, id: CharacterId) -> Result<Edit, String> {
    let found = character_of(world, id)?;
    let joints =
        (0..found.joints.len()).map(|j| Ok((j, joint_state(world, &found, j)?.0))).collect::<Result<_, String>>()?;
    Ok(Edit::Pose { character: id, joints })
}

/// What would undo `edit` in the scene as it is: `None` when `edit` would change nothing.
pub fn inverse_of(world: &mut World, edit: &Edit) -> Result<Option<Edit>, String> {
    let unless = |same: bool, undo: Edit| (!same).then_some(undo);
    Ok(match edit {
        Edit::Pose { character, joints } => {
            let found = character_of(world, *character)?;
            let mut undo: Vec<(usize, JointRotation)> = Vec::new();
            for &(j, rotation) in joints {
                let (pose, limits) = joint_state(world, &found, j)?;
                if pose != rotation.clamped(&limits) && !undo.iter().any(|&(k, _)| k == j) {
                    undo.push((j, pose));
                }
            }
            (!undo.is_empty()).then_some(Edit::Pose { character: *character, joints: undo })
        }
        Edit::Place { character, placement } => {
            let old = component::<Placement>(world, *character)?.0;
            unless(old == *placement, Edit::Place { character: *character, placement: old })
        }
        Edit::View { character, view } => {
            let old = component::<CharacterView>(world, *character)?.0.clone();
            unless(old == *view, Edit::View { character: *character, view: old })
        }
        Edit::Rename { character, name } => {
            let old = component::<SceneCharacter>(world, *character)?.name.clone();
            unless(old == *name, Edit::Rename { character: *character, name: old })
        }
        Edit::Smpl { character, state } => {
            let old = component::<SmplCharacter>(world, *character)?.state.clone();
            unless(old == *state, Edit::Smpl { character: *character, state: old })
        }
        Edit::Rebind { character, binding } => {
            let old = component::<SceneCharacter>(world, *character)?.binding;
            unless(old == *binding, Edit::Rebind { character: *character, binding: old })
        }
        Edit::Skinning { character, method } => {
            let old = component::<CharacterSkinning>(world, *character)?.0;
            unless(old == *method, Edit::Skinning { character: *character, method: old })
        }
        Edit::SkinOnGpu { character, on } => {
            let old = component::<SkinOnGpu>(world, *character)?.0;
            unless(old == *on, Edit::SkinOnGpu { character: *character, on: old })
        }
        Edit::Clip { character, anim } => {
            let old = world.get::<ClipPlayer>(entity_of(world, *character)?).map(|p| p.state.clone());
            unless(old == *anim, Edit::Clip { character: *character, anim: old })
        }
        Edit::Playback { character, state } => {
            let old = component::<NodeClipPlayer>(world, *character)?.state.clone();
            unless(old == *state, Edit::Playback { character: *character, state: old })
        }
        Edit::Morph { character, weights } => {
            let old = component::<crate::scene::morphs::Morphs>(world, *character)?.weights.clone();
            unless(old == *weights, Edit::Morph { character: *character, weights: old })
        }
        Edit::Attach { character, attached, placement } => {
            let old = world.get::<Attached>(entity_of(world, *character)?).map(|a| a.0.clone());
            let old_placement = component::<Placement>(world, *character)?.0;
            let undo = Edit::Attach { character: *character, attached: old, placement: old_placement };
            unless(
                undo == Edit::Attach { character: *character, attached: attached.clone(), placement: *placement },
                undo,
            )
        }
        Edit::Humanoid { character, bones } => {
            let old =
                world.get::<HumanoidBones>(entity_of(world, *character)?).map(|h| h.0.clone()).unwrap_or_default();
            unless(old == *bones, Edit::Humanoid { character: *character, bones: old })
        }
        Edit::Library { name, pose } => {
            let old = world.resource::<PoseLibrary>().0.get(name).cloned();
            unless(old == *pose, Edit::Library { name: name.clone(), pose: old })
        }
        Edit::Stage(stage) => {
            let old = world.resource::<StageSettings>().0.clone();
            unless(old == *stage, Edit::Stage(old))
        }
        Edit::Shot(shot) => {
            let old = world.resource::<ShotSettings>().0;
            unless(old == *shot, Edit::Shot(old))
        }
        Edit::Bookmark { name, camera } => {
            let old = world.resource::<Bookmarks>().0.get(name).copied();
            unless(old == *camera, Edit::Bookmark { name: name.clone(), camera: old })
        }
        Edit::Add(doc) => {
            let id = doc.id.ok_or("a character to add has an id")?;
            if world.resource::<CharacterIndex>().get(id).is_some() {
                return Err(format!("character {id} is already in the scene"));
            }
            Some(Edit::Remove(id))
        }
        Edit::Remove(id) => {
            let entity = entity_of(world, *id)?;
            let mut reader = SystemState::<SceneReader>::new(world);
            let doc =
                reader.get(world).map_err(|e| e.to_string())?.character_doc(entity).ok_or_else(|| missing(*id))?;
            Some(Edit::Add(Box::new(doc)))
        }
    })
}

/// Writes `edit` into the live scene.
fn write(world: &mut World, edit: Edit) -> Result<(), String> {
    match edit {
        Edit::Pose { character, joints } => {
            let found = character_of(world, character)?;
            // Not clamped here: `Solve` clamps every changed pose (once).
            for (j, rotation) in joints {
                joint_state(world, &found, j)?;
                if let Some(mut pose) = world.get_mut::<JointPose>(found.joints[j]) {
                    pose.set_if_neq(JointPose(rotation));
                }
            }
        }
        Edit::Place { character, placement } => component_mut::<Placement>(world, character)?.0 = placement,
        Edit::View { character, view } => component_mut::<CharacterView>(world, character)?.0 = view,
        Edit::Rename { character, name } => {
            let entity = entity_of(world, character)?;
            world.entity_mut(entity).insert(Name::new(name.clone()));
            component_mut::<SceneCharacter>(world, character)?.name = name;
        }
        Edit::Smpl { character, state } => component_mut::<SmplCharacter>(world, character)?.state = state,
        Edit::Playback { character, state } => component_mut::<NodeClipPlayer>(world, character)?.state = state,
        Edit::Rebind { character, binding } => rebind_character(world, character, binding)?,
        Edit::Skinning { character, method } => component_mut::<CharacterSkinning>(world, character)?.0 = method,
        Edit::SkinOnGpu { character, on } => component_mut::<SkinOnGpu>(world, character)?.0 = on,
        Edit::Clip { character, anim } => set_clip(world, character, anim)?,
        Edit::Morph { character, weights } => {
            component_mut::<crate::scene::morphs::Morphs>(world, character)?.weights = weights;
        }
        Edit::Library { name, pose } => {
            let mut library = world.resource_mut::<PoseLibrary>();
            match pose {
                Some(pose) => library.0.insert(name, pose),
                None => library.0.remove(&name),
            };
        }
        Edit::Attach { character, attached, placement } => {
            let entity = entity_of(world, character)?;
            component_mut::<Placement>(world, character)?.0 = placement;
            match attached {
                Some(attached) => world.entity_mut(entity).insert(Attached(attached)),
                None => world.entity_mut(entity).remove::<Attached>(),
            };
        }
        Edit::Humanoid { character, bones } => {
            let entity = entity_of(world, character)?;
            match bones.is_empty() {
                true => world.entity_mut(entity).remove::<HumanoidBones>(),
                false => world.entity_mut(entity).insert(HumanoidBones(bones)),
            };
        }
        Edit::Stage(stage) => world.resource_mut::<StageSettings>().0 = stage,
        Edit::Shot(shot) => world.resource_mut::<ShotSettings>().0 = shot,
        Edit::Bookmark { name, camera } => {
            let mut bookmarks = world.resource_mut::<Bookmarks>();
            match camera {
                Some(camera) => bookmarks.0.insert(name, camera),
                None => bookmarks.0.remove(&name),
            };
        }
        Edit::Add(doc) => add_character(world, &doc)?,
        Edit::Remove(id) => {
            let entity = entity_of(world, id)?;
            let found = character_of(world, id)?;
            crate::scene::despawn_character(&mut world.commands(), entity, &found);
            world.flush();
        }
    }
    Ok(())
}

/// Spawns a character from its document (same entity layout as any scene character).
fn add_character(world: &mut World, doc: &CharacterDoc) -> Result<(), String> {
    let id = doc.id.ok_or("a character to add has an id")?;
    let spawned = world.resource_scope(|world, mut library: Mut<Library>| {
        world.resource_scope(|world, mut meshes: Mut<Assets<Mesh>>| {
            spawn_from_doc(&mut world.commands(), &mut meshes, &mut library, doc, id)
        })
    });
    world.flush();
    let (_, notes) = spawned.map_err(|e| e.to_string())?;
    let mut messages = world.resource_mut::<Messages>();
    notes.into_iter().for_each(|m| messages.push(m));
    Ok(())
}

/// Sets a character's keyframed clip state; a new file is loaded and put on, none takes
/// the clip off (the pose stays where the clip left it).
fn set_clip(world: &mut World, id: CharacterId, anim: Option<AnimDoc>) -> Result<(), String> {
    let entity = entity_of(world, id)?;
    let Some(anim) = anim else {
        world.entity_mut(entity).remove::<ClipPlayer>();
        return Ok(());
    };
    if let Some(mut player) = world.get_mut::<ClipPlayer>(entity)
        && player.state.file == anim.file
        && player.state.keys == anim.keys
        && player.state.retarget == anim.retarget
    {
        player.state = anim;
        return Ok(());
    }
    let found = character_of(world, id)?;
    let name = component::<SceneCharacter>(world, id)?.name.clone();
    let (player, note) = crate::editor::scene_doc::document::clip_player(
        &mut world.resource_mut::<Library>(),
        &found.asset,
        &name,
        &anim,
    )
    .map_err(|e| e.to_string())?;
    if let Some(note) = note {
        world.resource_mut::<Messages>().push(note);
    }
    // A retargeting is worked out afresh for the new player.
    world.entity_mut(entity).insert(player).remove::<crate::editor::scene_doc::retarget::RetargetedFrom>();
    Ok(())
}

/// Swaps in the asset with the wanted weights (same skeleton, same mesh): re-skinned and
/// recoloured this frame.
fn rebind_character(world: &mut World, id: CharacterId, binding: Option<BindingDoc>) -> Result<(), String> {
    let entity = entity_of(world, id)?;
    let source = component::<SceneCharacter>(world, id)?.source.clone();
    let asset = world.resource_mut::<Library>().load_bound(&source, binding).map_err(|e| e.to_string())?;
    let mut character = world.entity_mut(entity);
    if let Some(mut morphs) = character.get_mut::<crate::scene::morphs::Morphs>() {
        // The morphs blend from the rebound asset (and put it on the character).
        morphs.base = asset.clone();
    }
    if let Some(mut c) = character.get_mut::<Character>() {
        c.asset = asset;
    }
    if let Some(mut dirty) = character.get_mut::<PoseDirty>() {
        dirty.matrices = true;
        dirty.colors = true;
    }
    if let Some(mut sc) = character.get_mut::<SceneCharacter>() {
        sc.binding = binding;
    }
    Ok(())
}

fn missing(id: CharacterId) -> String {
    format!("character {id} is not in the scene")
}

fn entity_of(world: &World, id: CharacterId) -> Result<Entity, String> {
    world.resource::<CharacterIndex>().get(id).ok_or_else(|| missing(id))
}

fn character_of(world: &World, id: CharacterId) -> Result<Character, String> {
    component::<Character>(world, id).cloned()
}

fn component<C: Component>(world: &World, id: CharacterId) -> Result<&C, String> {
    world.get::<C>(entity_of(world, id)?).ok_or_else(|| missing(id))
}

fn component_mut<C: Component<Mutability = bevy::ecs::component::Mutable>>(
    world: &mut World,
    id: CharacterId,
) -> Result<Mut<'_, C>, String> {
    let entity = entity_of(world, id)?;
    world.get_mut::<C>(entity).ok_or_else(|| missing(id))
}

/// A joint's pose and limits.
fn joint_state(
    world: &World,
    character: &Character,
    j: usize,
) -> Result<(JointRotation, crate::rig::DofLimits), String> {
    let no_joint = || format!("{} has no joint {j}", character.asset.name);
    let &entity = character.joints.get(j).ok_or_else(no_joint)?;
    let pose = world.get::<JointPose>(entity).ok_or_else(no_joint)?.0;
    let limits = world.get::<JointLimits>(entity).ok_or_else(no_joint)?.0;
    Ok((pose, limits))
}

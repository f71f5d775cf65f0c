//! The commands: on one character (its pose, placement, view, name, motion, weights,
//! skinning, morphs, attachment and humanoid bones; adding and removing it), and on the
//! scene as a whole (the pose library, the stage, the shot, the camera's bookmarks).

use std::collections::BTreeMap;

use bevy::ecs::system::SystemState;
use bevy::prelude::*;

use crate::editor::edits::access::{character_of, component, component_mut, entity_of, joint_state, missing};
use crate::editor::edits::edit::{Command, Edit, Setter};
use crate::editor::scene_doc::attach::Attached;
use crate::editor::scene_doc::document::{
    CharacterIndex, HumanoidBones, Library as LoadedAssets, SceneCharacter, SceneReader, clip_player, spawn_from_doc,
};
use crate::editor::scene_doc::retarget::RetargetedFrom;
use crate::editor::state::camera::Bookmarks;
use crate::editor::state::{Messages, PoseLibrary, ShotSettings, StageSettings};
use crate::formats::scene::{
    AnimDoc, AttachDoc, BindingDoc, CameraDoc, CharacterDoc, CharacterId, LibraryPoseDoc, PlacementDoc, PlaybackDoc,
    ShotDoc, SkinningDoc, SmplDoc, StageDoc, ViewDoc,
};
use crate::rig::JointRotation;
use crate::rig::humanoid::HumanBone;
use crate::scene::keyframes::ClipPlayer;
use crate::scene::morphs::Morphs;
use crate::scene::node_clips::NodeClipPlayer;
use crate::scene::smpl::SmplCharacter;
use crate::scene::{Character, CharacterSkinning, CharacterView, JointPose, Placement, PoseDirty, SkinOnGpu as OnGpu};

/// Turn joints (by index) to these rotations, clamped to their limits.
#[derive(Clone, Debug, PartialEq)]
pub struct Pose {
    pub character: CharacterId,
    pub joints: Vec<(usize, JointRotation)>,
}

impl Pose {
    /// The joints of `after` that differ from `before`, at their rotations in `after`;
    /// none when no joint changed.
    pub fn change(character: CharacterId, before: &[JointRotation], after: &[JointRotation]) -> Option<Pose> {
        let joints: Vec<_> =
            after.iter().zip(before).enumerate().filter(|(_, (a, b))| a != b).map(|(j, (a, _))| (j, *a)).collect();
        (!joints.is_empty()).then_some(Pose { character, joints })
    }

    /// Every joint of a character at its rotation now.
    pub fn now(world: &World, id: CharacterId) -> Result<Pose, String> {
        let found = character_of(world, id)?;
        let joints = (0..found.joints.len())
            .map(|j| Ok((j, joint_state(world, &found, j)?.0)))
            .collect::<Result<_, String>>()?;
        Ok(Pose { character: id, joints })
    }
}

impl Command for Pose {
    fn character(&self) -> Option<CharacterId> {
        Some(self.character)
    }

    /// The joints it turns, at their rotations now (each once).
    fn undo(&self, world: &mut World) -> Result<Vec<Edit>, String> {
        let found = character_of(world, self.character)?;
        let mut undo: Vec<(usize, JointRotation)> = Vec::new();
        for &(j, rotation) in &self.joints {
            let (pose, limits) = joint_state(world, &found, j)?;
            if pose != rotation.clamped(&limits) && !undo.iter().any(|&(k, _)| k == j) {
                undo.push((j, pose));
            }
        }
        Ok(if undo.is_empty() { Vec::new() } else { vec![Pose { character: self.character, joints: undo }.into()] })
    }

    /// Not clamped here: `Solve` clamps every changed pose (once).
    fn write(self: Box<Self>, world: &mut World) -> Result<(), String> {
        let found = character_of(world, self.character)?;
        for (j, rotation) in self.joints {
            joint_state(world, &found, j)?;
            if let Some(mut pose) = world.get_mut::<JointPose>(found.joints[j]) {
                pose.set_if_neq(JointPose(rotation));
            }
        }
        Ok(())
    }
}

/// Declares a command that sets one component's value of a character.
macro_rules! component_setter {
    ($(#[$doc:meta])* $kind:ident { $field:ident: $value:ty } = $component:ident . $path:tt $(, poses: $poses:expr)?) => {
        $(#[$doc])*
        #[derive(Clone, Debug, PartialEq)]
        pub struct $kind {
            pub character: CharacterId,
            pub $field: $value,
        }

        impl Setter for $kind {
            $(
            /// Playback poses the joints from the clip; without a clip to return to, undo
            /// gives the joints back their rotations.
            fn also_undo(&self, world: &World) -> Result<Vec<Edit>, String> {
                Ok(if $poses { vec![Pose::now(world, self.character)?.into()] } else { Vec::new() })
            }
            )?

            fn character(&self) -> Option<CharacterId> {
                Some(self.character)
            }

            fn read(&self, world: &World) -> Result<Self, String> {
                let $field = component::<$component>(world, self.character)?.$path.clone();
                Ok($kind { character: self.character, $field })
            }

            fn set(self, world: &mut World) -> Result<(), String> {
                component_mut::<$component>(world, self.character)?.$path = self.$field;
                Ok(())
            }
        }
    };
}

component_setter!(
    /// Move, turn or scale a character.
    Place { placement: PlacementDoc } = Placement.0
);
component_setter!(
    /// Display mode, visibility, weight colours, heat map, tint.
    View { view: ViewDoc } = CharacterView.0
);
component_setter!(
    /// β, clips, time, playback and blend of an SMPL body.
    Smpl { state: SmplDoc } = SmplCharacter.state, poses: true
);
component_setter!(
    /// Clip, time, playback and blend of a source's own clips (glTF animations).
    Playback { state: PlaybackDoc } = NodeClipPlayer.state, poses: true
);
component_setter!(
    /// Linear blend or dual quaternion skinning.
    Skinning { method: SkinningDoc } = CharacterSkinning.0
);
component_setter!(
    /// Skinning by the GPU compute shader (`true`) or on the CPU.
    SkinOnGpu { on: bool } = OnGpu.0
);
component_setter!(
    /// Morph target weights.
    Morph { weights: Vec<f32> } = Morphs.weights
);

#[derive(Clone, Debug, PartialEq)]
pub struct Rename {
    pub character: CharacterId,
    pub name: String,
}

impl Setter for Rename {
    fn character(&self) -> Option<CharacterId> {
        Some(self.character)
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        Ok(Rename { character: self.character, name: component::<SceneCharacter>(world, self.character)?.name.clone() })
    }

    fn set(self, world: &mut World) -> Result<(), String> {
        let entity = entity_of(world, self.character)?;
        world.entity_mut(entity).insert(Name::new(self.name.clone()));
        component_mut::<SceneCharacter>(world, self.character)?.name = self.name;
        Ok(())
    }
}

/// Weights from the file (`None`) or computed from the bones.
#[derive(Clone, Debug, PartialEq)]
pub struct Rebind {
    pub character: CharacterId,
    pub binding: Option<BindingDoc>,
}

impl Setter for Rebind {
    fn character(&self) -> Option<CharacterId> {
        Some(self.character)
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        Ok(Rebind { character: self.character, binding: component::<SceneCharacter>(world, self.character)?.binding })
    }

    /// Swaps in the asset with the wanted weights (same skeleton, same mesh): re-skinned
    /// and recoloured this frame.
    fn set(self, world: &mut World) -> Result<(), String> {
        let entity = entity_of(world, self.character)?;
        let source = component::<SceneCharacter>(world, self.character)?.source.clone();
        let asset =
            world.resource_mut::<LoadedAssets>().load_bound(&source, self.binding).map_err(|e| e.to_string())?;
        let mut character = world.entity_mut(entity);
        if let Some(mut morphs) = character.get_mut::<Morphs>() {
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
            sc.binding = self.binding;
        }
        Ok(())
    }
}

/// A keyframed clip on a character, its time and playback (none: no clip).
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    pub character: CharacterId,
    pub anim: Option<AnimDoc>,
}

impl Setter for Clip {
    fn character(&self) -> Option<CharacterId> {
        Some(self.character)
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        let anim = world.get::<ClipPlayer>(entity_of(world, self.character)?).map(|p| p.state.clone());
        Ok(Clip { character: self.character, anim })
    }

    /// A new file is loaded and put on; none takes the clip off (the pose stays where the
    /// clip left it).
    fn set(self, world: &mut World) -> Result<(), String> {
        let (id, entity) = (self.character, entity_of(world, self.character)?);
        let Some(anim) = self.anim else {
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
        let (player, note) = clip_player(&mut world.resource_mut::<LoadedAssets>(), &found.asset, &name, &anim)
            .map_err(|e| e.to_string())?;
        if let Some(note) = note {
            world.resource_mut::<Messages>().push(note);
        }
        // A retargeting is worked out afresh for the new player.
        world.entity_mut(entity).insert(player).remove::<RetargetedFrom>();
        Ok(())
    }
}

/// Held by a joint of another character (none: let go), standing at `placement` (where
/// it stands when attached or let go, so that undo puts it back exactly).
#[derive(Clone, Debug, PartialEq)]
pub struct Attach {
    pub character: CharacterId,
    pub attached: Option<AttachDoc>,
    pub placement: PlacementDoc,
}

impl Setter for Attach {
    fn character(&self) -> Option<CharacterId> {
        Some(self.character)
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        let attached = world.get::<Attached>(entity_of(world, self.character)?).map(|a| a.0.clone());
        let placement = component::<Placement>(world, self.character)?.0;
        Ok(Attach { character: self.character, attached, placement })
    }

    fn set(self, world: &mut World) -> Result<(), String> {
        let entity = entity_of(world, self.character)?;
        component_mut::<Placement>(world, self.character)?.0 = self.placement;
        match self.attached {
            Some(attached) => world.entity_mut(entity).insert(Attached(attached)),
            None => world.entity_mut(entity).remove::<Attached>(),
        };
        Ok(())
    }
}

/// Standard bones assigned by hand (bone → pose key; an empty key takes the bone off),
/// over those found from the skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct Humanoid {
    pub character: CharacterId,
    pub bones: BTreeMap<HumanBone, String>,
}

impl Setter for Humanoid {
    fn character(&self) -> Option<CharacterId> {
        Some(self.character)
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        let bones =
            world.get::<HumanoidBones>(entity_of(world, self.character)?).map(|h| h.0.clone()).unwrap_or_default();
        Ok(Humanoid { character: self.character, bones })
    }

    fn set(self, world: &mut World) -> Result<(), String> {
        let entity = entity_of(world, self.character)?;
        match self.bones.is_empty() {
            true => world.entity_mut(entity).remove::<HumanoidBones>(),
            false => world.entity_mut(entity).insert(HumanoidBones(self.bones)),
        };
        Ok(())
    }
}

/// A character from its document (a fresh id is given when it has none).
#[derive(Clone, Debug, PartialEq)]
pub struct Add(pub Box<CharacterDoc>);

impl Command for Add {
    fn character(&self) -> Option<CharacterId> {
        self.0.id
    }

    fn undo(&self, world: &mut World) -> Result<Vec<Edit>, String> {
        let id = self.0.id.ok_or("a character to add has an id")?;
        if world.resource::<CharacterIndex>().get(id).is_some() {
            return Err(format!("character {id} is already in the scene"));
        }
        Ok(vec![Remove(id).into()])
    }

    /// Spawns the character (same entity layout as any scene character).
    fn write(self: Box<Self>, world: &mut World) -> Result<(), String> {
        let id = self.0.id.ok_or("a character to add has an id")?;
        let spawned = world.resource_scope(|world, mut library: Mut<LoadedAssets>| {
            world.resource_scope(|world, mut meshes: Mut<Assets<Mesh>>| {
                spawn_from_doc(&mut world.commands(), &mut meshes, &mut library, &self.0, id)
            })
        });
        world.flush();
        let (_, notes) = spawned.map_err(|e| e.to_string())?;
        let mut messages = world.resource_mut::<Messages>();
        notes.into_iter().for_each(|m| messages.push(m));
        Ok(())
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Remove(pub CharacterId);

impl Command for Remove {
    fn character(&self) -> Option<CharacterId> {
        Some(self.0)
    }

    /// Adding it back as its document says it is now.
    fn undo(&self, world: &mut World) -> Result<Vec<Edit>, String> {
        let entity = entity_of(world, self.0)?;
        let mut reader = SystemState::<SceneReader>::new(world);
        let doc = reader.get(world).map_err(|e| e.to_string())?.character_doc(entity).ok_or_else(|| missing(self.0))?;
        Ok(vec![Add(Box::new(doc)).into()])
    }

    fn write(self: Box<Self>, world: &mut World) -> Result<(), String> {
        let entity = entity_of(world, self.0)?;
        let found = character_of(world, self.0)?;
        crate::scene::despawn_character(&mut world.commands(), entity, &found);
        world.flush();
        Ok(())
    }
}

/// A pose kept in the scene's library under `name` (none: taken out).
#[derive(Clone, Debug, PartialEq)]
pub struct Library {
    pub name: String,
    pub pose: Option<LibraryPoseDoc>,
}

impl Setter for Library {
    fn character(&self) -> Option<CharacterId> {
        None
    }

    fn entry(&self) -> Option<&str> {
        Some(&self.name)
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        Ok(Library { name: self.name.clone(), pose: world.resource::<PoseLibrary>().0.get(&self.name).cloned() })
    }

    fn set(self, world: &mut World) -> Result<(), String> {
        let mut library = world.resource_mut::<PoseLibrary>();
        match self.pose {
            Some(pose) => library.0.insert(self.name, pose),
            None => library.0.remove(&self.name),
        };
        Ok(())
    }
}

/// A camera view kept under `name` (none: taken out).
#[derive(Clone, Debug, PartialEq)]
pub struct Bookmark {
    pub name: String,
    pub camera: Option<CameraDoc>,
}

impl Setter for Bookmark {
    fn character(&self) -> Option<CharacterId> {
        None
    }

    fn entry(&self) -> Option<&str> {
        Some(&self.name)
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        Ok(Bookmark { name: self.name.clone(), camera: world.resource::<Bookmarks>().0.get(&self.name).copied() })
    }

    fn set(self, world: &mut World) -> Result<(), String> {
        let mut bookmarks = world.resource_mut::<Bookmarks>();
        match self.camera {
            Some(camera) => bookmarks.0.insert(self.name, camera),
            None => bookmarks.0.remove(&self.name),
        };
        Ok(())
    }
}

/// Floor, lights, background, axes.
#[derive(Clone, Debug, PartialEq)]
pub struct Stage(pub StageDoc);

impl Setter for Stage {
    fn character(&self) -> Option<CharacterId> {
        None
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        Ok(Stage(world.resource::<StageSettings>().0.clone()))
    }

    fn set(self, world: &mut World) -> Result<(), String> {
        world.resource_mut::<StageSettings>().0 = self.0;
        Ok(())
    }
}

/// The picture `render` takes.
#[derive(Clone, Debug, PartialEq)]
pub struct Shot(pub ShotDoc);

impl Setter for Shot {
    fn character(&self) -> Option<CharacterId> {
        None
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        Ok(Shot(world.resource::<ShotSettings>().0))
    }

    fn set(self, world: &mut World) -> Result<(), String> {
        world.resource_mut::<ShotSettings>().0 = self.0;
        Ok(())
    }
}

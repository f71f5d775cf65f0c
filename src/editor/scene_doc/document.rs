//! The scene as a document: the scene character's identity and its id index, capturing
//! the live ECS into a `SceneDoc` (saving, duplicating, removing), spawning characters from
//! documents, and scene files.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use bevy::ecs::lifecycle::HookContext;
use bevy::ecs::query::QueryData;
use bevy::ecs::system::SystemParam;
use bevy::ecs::world::DeferredWorld;
use bevy::prelude::*;

use crate::document::AssetLibrary;
use crate::document::scenes::{pose_from_doc, read_scene, write_scene};
use crate::editor::state::StageSettings;
use crate::editor::state::camera::OrbitCamera;
use crate::formats::FormatError;
use crate::formats::scene::{BindingDoc, CharacterDoc, CharacterId, SceneDoc, SourceDoc, ViewDoc, pose_key};
use crate::rig::CharacterAsset;
use crate::scene::keyframes::ClipPlayer;
use crate::scene::smpl::SmplCharacter;
use crate::scene::{
    Character, CharacterSkinning, CharacterView, JointPose, Placement, SkinOnGpu, spawn_character_posed,
};

/// A character as the scene knows it: its stable id, where it comes from, its name and
/// whether its weights were computed from the bones. The rest of its document lives in
/// `Placement`, `CharacterView`, the joints' `JointPose` and `SmplCharacter`.
#[derive(Component, Clone, Debug)]
#[component(on_insert = index_character, on_discard = unindex_character)]
pub struct SceneCharacter {
    pub id: CharacterId,
    pub source: SourceDoc,
    pub name: String,
    pub binding: Option<BindingDoc>,
}

/// Held by a joint of another character (on the held character's entity; followed by
/// [`super::attach::follow_holders`]).
#[derive(Component, Clone, Debug, PartialEq, Deref)]
pub struct Attached(pub crate::formats::scene::AttachDoc);

/// Each scene character's entity by id (kept by `SceneCharacter`'s hooks).
#[derive(Resource, Default, Debug)]
pub struct CharacterIndex(HashMap<CharacterId, Entity>);

impl CharacterIndex {
    pub fn get(&self, id: CharacterId) -> Option<Entity> {
        self.0.get(&id).copied()
    }

    pub fn len(&self) -> usize {
        self.0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

fn index_character(mut world: DeferredWorld, context: HookContext) {
    let Some(id) = world.get::<SceneCharacter>(context.entity).map(|c| c.id) else { return };
    if let Some(mut index) = world.get_resource_mut::<CharacterIndex>() {
        index.0.insert(id, context.entity);
    }
}

fn unindex_character(mut world: DeferredWorld, context: HookContext) {
    let Some(id) = world.get::<SceneCharacter>(context.entity).map(|c| c.id) else { return };
    if let Some(mut index) = world.get_resource_mut::<CharacterIndex>()
        && index.0.get(&id) == Some(&context.entity)
    {
        index.0.remove(&id);
    }
}

/// The asset library as the editor's resource (the Bevy-free library inside).
#[derive(Resource, Default, Deref, DerefMut)]
pub struct Library(pub AssetLibrary);

/// A scene to open in place of the current one (startup, Open): every character, the
/// camera and the stage are replaced; selection, pins and history cleared.
#[derive(Resource, Default)]
pub struct PendingScene {
    pub doc: Option<SceneDoc>,
    /// Frame all characters afterwards (when the document has no camera).
    pub frame: bool,
}

/// The startup options changed the first scene from its file (`--pose`, `--clip`, …):
/// taken when it is opened, so it opens with unsaved changes.
#[derive(Resource, Default)]
pub struct ChangedAtStartup(pub bool);

/// Ids for new characters.
#[derive(Resource, Default)]
pub struct NextCharacterId(pub u64);

impl NextCharacterId {
    pub fn take(&mut self) -> CharacterId {
        self.0 += 1;
        CharacterId(self.0)
    }
}

/// Standard bones assigned by hand to a character's joints (bone → pose key), over those
/// found from its skeleton (the scene file's `humanoid`).
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct HumanoidBones(pub std::collections::BTreeMap<crate::rig::humanoid::HumanBone, String>);

/// A character's humanoid map: found from its skeleton, with the bones of its
/// [`HumanoidBones`] assigned over it. Derived data, worked out again only when the
/// character or its assigned bones change ([`update_humanoid_maps`]); the panels read it.
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct HumanoidMapOf(pub crate::rig::humanoid::HumanoidMap);

/// Works out the humanoid map of characters that are new, changed, or whose assigned bones
/// changed or were taken off (reads `Character`, `HumanoidBones`; writes `HumanoidMapOf`).
pub fn update_humanoid_maps(
    mut commands: Commands,
    changed: Query<
        (Entity, &Character, Option<&HumanoidBones>),
        (With<SceneCharacter>, Or<(Changed<Character>, Changed<HumanoidBones>)>),
    >,
    mut unassigned: RemovedComponents<HumanoidBones>,
    characters: Query<&Character, With<SceneCharacter>>,
) {
    let none = std::collections::BTreeMap::new();
    for (entity, character, bones) in &changed {
        let map = crate::document::retarget::humanoid_map(&character.asset, bones.map_or(&none, |b| &b.0));
        commands.entity(entity).insert(HumanoidMapOf(map));
    }
    for entity in unassigned.read() {
        if let Ok(character) = characters.get(entity)
            && !changed.contains(entity)
        {
            let map = crate::document::retarget::humanoid_map(&character.asset, &none);
            commands.entity(entity).insert(HumanoidMapOf(map));
        }
    }
}

/// What a character's retargeted clip was last worked out for (the setting, the bones
/// assigned by hand and the source's motion), and what the retargeting did (or why it
/// failed).
#[derive(Component, Clone, PartialEq, Debug)]
pub struct RetargetedFrom {
    pub settings: crate::formats::scene::RetargetDoc,
    pub bones: std::collections::BTreeMap<crate::rig::humanoid::HumanBone, String>,
    /// What the source character's motion was (its clip, blend and shape; not its time).
    pub source_motion: String,
    pub report: String,
}

/// Everything needed to capture the scene as a document (read only).
/// What the panels and capture read of a scene character, by name.
#[derive(QueryData)]
pub struct SceneCharacterData {
    pub entity: Entity,
    pub scene: &'static SceneCharacter,
    pub character: &'static Character,
    pub placement: &'static Placement,
    pub view: &'static CharacterView,
    pub smpl: Option<&'static SmplCharacter>,
    pub skinning: &'static CharacterSkinning,
    pub on_gpu: &'static SkinOnGpu,
    pub player: Option<&'static ClipPlayer>,
    pub morphs: Option<&'static crate::scene::morphs::Morphs>,
    pub node_clips: Option<&'static crate::scene::node_clips::NodeClipPlayer>,
    pub attached: Option<&'static Attached>,
    pub humanoid: Option<&'static HumanoidBones>,
    pub humanoid_map: Option<&'static HumanoidMapOf>,
    pub retargeted: Option<&'static RetargetedFrom>,
}

#[derive(SystemParam)]
pub struct SceneReader<'w, 's> {
    pub characters: Query<'w, 's, SceneCharacterData>,
    pub poses: Query<'w, 's, &'static JointPose>,
    pub cameras: Query<'w, 's, &'static OrbitCamera>,
    pub stage: Res<'w, StageSettings>,
    pub unloaded: Res<'w, crate::editor::state::UnloadedCharacters>,
    pub pose_library: Res<'w, crate::editor::state::PoseLibrary>,
    pub shot: Res<'w, crate::editor::state::ShotSettings>,
    pub bookmarks: Res<'w, crate::editor::state::camera::Bookmarks>,
}

impl SceneReader<'_, '_> {
    /// The current scene, characters in id order (built when saving or when a character is
    /// duplicated or removed, never every frame).
    pub fn capture(&self) -> SceneDoc {
        let mut characters: Vec<CharacterDoc> =
            self.characters.iter().filter_map(|c| self.character_doc(c.entity)).collect();
        characters.sort_by_key(|c| c.id);
        SceneDoc {
            // Characters that failed to load stay in the document as they were.
            characters: characters.into_iter().chain(self.unloaded.0.iter().cloned()).collect(),
            camera: self.cameras.iter().next().map(|o| o.0),
            stage: self.stage.0.clone(),
            poses: self.pose_library.0.clone(),
            bookmarks: self.bookmarks.0.clone(),
            shot: self.shot.0,
        }
    }

    /// The document of one live character: joints listed where they differ from the
    /// source's pose.
    pub fn character_doc(&self, entity: Entity) -> Option<CharacterDoc> {
        let c = self.characters.get(entity).ok()?;
        let (sc, character) = (c.scene, c.character);
        let skeleton = &character.asset.skeleton;
        let initial = skeleton.initial_pose();
        let pose = character
            .joints
            .iter()
            .enumerate()
            .filter_map(|(j, &e)| {
                let p = self.poses.get(e).ok()?.0;
                (p != initial[j]).then(|| (pose_key(skeleton, j), p))
            })
            .collect();
        Some(CharacterDoc {
            id: Some(sc.id),
            source: sc.source.clone(),
            name: sc.name.clone(),
            placement: c.placement.0,
            pose,
            view: c.view.0.clone(),
            smpl: c.smpl.map(|body| body.state.clone()),
            binding: sc.binding,
            skinning: c.skinning.0,
            gpu_skinning: c.on_gpu.0,
            anim: c.player.map(|p| p.state.clone()),
            morphs: c.morphs.map(|m| m.weights.clone()).unwrap_or_default(),
            playback: c.node_clips.map(|p| p.state.clone()),
            attached: c.attached.map(|a| a.0.clone()),
            humanoid: c.humanoid.map(|h| h.0.clone()).unwrap_or_default(),
        })
    }
}

/// Bevy's visibility for a character's view.
pub fn visibility_of(view: &ViewDoc) -> Visibility {
    if view.visible { Visibility::Inherited } else { Visibility::Hidden }
}

/// Spawns one character of a document with the given id.
pub fn spawn_from_doc(
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    library: &mut AssetLibrary,
    doc: &CharacterDoc,
    id: CharacterId,
) -> Result<(Entity, Vec<String>), FormatError> {
    let asset = library.load_bound(&doc.source, doc.binding)?;
    let smpl = match &doc.source {
        SourceDoc::File(dir) if crate::formats::smpl::is_smpl_dir(dir) => Some((dir, library.smpl(dir)?)),
        _ => None,
    };
    let (pose, mut messages) = pose_from_doc(&asset, doc);
    let player = doc.anim.as_ref().and_then(|anim| match clip_player(library, &asset, &doc.name, anim) {
        Ok((player, note)) => {
            messages.extend(note);
            Some(player)
        }
        Err(e) => {
            messages.push(format!("{}: the clip was not loaded: {e}", doc.name));
            None
        }
    });
    let node_clips = library.part_of_source(&doc.source).map(|part| part.clips).filter(|c| !c.is_empty());
    let morphs = (!asset.morphs.is_empty()).then(|| {
        let mut weights = doc.morphs.clone();
        weights.resize(asset.morphs.len(), 0.0);
        crate::scene::morphs::Morphs { base: asset.clone(), weights }
    });
    let entity = spawn_character_posed(commands, meshes, asset, Placement(doc.placement), &pose);
    if let Some(player) = player {
        commands.entity(entity).insert(player);
    }
    if let Some(morphs) = morphs {
        commands.entity(entity).insert(morphs);
    }
    if let Some(clips) = node_clips {
        let state = doc.playback.clone().unwrap_or_default();
        commands.entity(entity).insert(crate::scene::node_clips::NodeClipPlayer { clips, state });
    }
    commands.entity(entity).insert((
        SceneCharacter { id, source: doc.source.clone(), name: doc.name.clone(), binding: doc.binding },
        CharacterView(doc.view.clone()),
        CharacterSkinning(doc.skinning),
        SkinOnGpu(doc.gpu_skinning),
        visibility_of(&doc.view),
    ));
    if let Some(attached) = &doc.attached {
        commands.entity(entity).insert(Attached(attached.clone()));
    }
    if !doc.humanoid.is_empty() {
        commands.entity(entity).insert(HumanoidBones(doc.humanoid.clone()));
    }
    if let Some((dir, set)) = smpl {
        let state = doc.smpl.clone().unwrap_or_default();
        commands.entity(entity).insert(SmplCharacter::new(set.model, dir.clone(), set.clips, state));
    }
    Ok((entity, messages))
}

/// The player of a character's keyframed clip, and a note when the clip's channels do not
/// fit the skeleton (3 for the root, then 3 per joint).
pub fn clip_player(
    library: &mut AssetLibrary,
    asset: &CharacterAsset,
    name: &str,
    anim: &crate::formats::scene::AnimDoc,
) -> Result<(ClipPlayer, Option<String>), FormatError> {
    let clip = match (&anim.keys, &anim.retarget) {
        (Some(keys), _) => Arc::new(keys.clone()),
        // Worked out from the scene by `retarget::resolve_retargets`.
        (None, Some(_)) => Arc::new(crate::rig::anim::Clip::empty(asset.skeleton.len())),
        (None, None) => library.keyframe_clip(&anim.file)?,
    };
    let wanted = 3 + 3 * asset.skeleton.len();
    let note = if !clip.joint_names.is_empty() {
        let matched = asset.skeleton.joints().iter().filter(|j| clip_joint(&clip, anim, &j.name).is_some()).count();
        (matched < asset.skeleton.len()).then(|| {
            format!(
                "{name}: {} moves {matched} of its {} joints (by name; a name map in the scene file's `names` pairs the others)",
                anim.file.display(),
                asset.skeleton.len()
            )
        })
    } else {
        (clip.channels.len() != wanted).then(|| {
            format!(
                "{name}: {} has {} channels; its skeleton takes {wanted} (3 for the root, 3 per joint)",
                anim.file.display(),
                clip.channels.len()
            )
        })
    };
    let clip = if clip.joint_names.is_empty() { clip } else { Arc::new(clip.retargeted(&asset.skeleton, &anim.names)) };
    Ok((ClipPlayer { clip, state: anim.clone() }, note))
}

/// The clip's joint that moves a character's joint `name` (by the name map, or the same
/// name).
fn clip_joint(clip: &crate::rig::anim::Clip, anim: &crate::formats::scene::AnimDoc, name: &str) -> Option<usize> {
    let wanted = anim.names.get(name).map_or(name, String::as_str);
    clip.joint_names.iter().position(|n| n == wanted)
}

/// Saves the scene to `path`, saying so (or why not) in the messages; a save marks the
/// scene saved. Whether it was saved.
pub fn save_scene_to(
    path: &str,
    doc: &SceneDoc,
    messages: &mut crate::editor::state::Messages,
    saved: &mut crate::editor::state::SavedState,
) -> bool {
    match write_scene(Path::new(path), doc) {
        Ok(()) => {
            messages.push(format!("saved the scene to {path}"));
            saved.saved_now = true;
            true
        }
        Err(e) => {
            messages.push(format!("the scene was not saved: {e} (the changes are kept)"));
            false
        }
    }
}

/// Queues the scene file at `path` to replace the current scene, or says why it cannot.
pub fn open_scene_from(path: &str, pending: &mut PendingScene, messages: &mut crate::editor::state::Messages) {
    match read_scene(Path::new(path)) {
        Ok(doc) => *pending = PendingScene { frame: doc.camera.is_none(), doc: Some(doc) },
        Err(e) => messages.push(e.to_string()),
    }
}

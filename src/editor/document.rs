//! The scene as a document: the scene character's identity and its id index, capturing
//! the live ECS into a `SceneDoc` (saving, duplicating, removing), spawning characters from
//! documents, and scene files.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use bevy::ecs::lifecycle::HookContext;
use bevy::ecs::system::SystemParam;
use bevy::ecs::world::DeferredWorld;
use bevy::prelude::*;

use super::camera::OrbitCamera;
use super::stage::StageSettings;
use crate::formats::scene::{
    BindingDoc, CharacterDoc, CharacterId, PlacementDoc, SceneDoc, SourceDoc, ViewDoc, joint_of_pose_key, pose_key,
};
use crate::formats::{FormatError, load_character};
use crate::rig::smpl::{Clip, SmplModel};
use crate::rig::{CharacterAsset, JointRotation};
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

/// Loaded characters by source, shared by every scene character made from them.
#[derive(Resource, Default)]
pub struct AssetLibrary {
    cache: HashMap<SourceDoc, Arc<CharacterAsset>>,
    smpl: HashMap<PathBuf, SmplSet>,
    bound: HashMap<(SourceDoc, BindingDoc), Arc<CharacterAsset>>,
    keyframe_clips: HashMap<PathBuf, Arc<crate::rig::anim::Clip>>,
    gltf: HashMap<PathBuf, Vec<GltfPart>>,
}

/// One character of a glTF file, loaded: its asset, its clips and its base colour.
#[derive(Clone)]
pub struct GltfPart {
    pub asset: Arc<CharacterAsset>,
    pub clips: Arc<[crate::rig::node_clip::NodeClip]>,
    pub base_color: Option<[f32; 4]>,
    pub morph_weights: Vec<f32>,
}

/// A copy of `asset` whose weights come from its bones at rest (by `binding`); when heat
/// binding fails, smooth weights and a warning that says so.
pub fn rebind(asset: &CharacterAsset, binding: BindingDoc) -> CharacterAsset {
    use crate::rig::bind::{Binding, bind_to_skeleton};
    let mut out = asset.clone();
    let (skeleton, skin) = (&asset.skeleton, &asset.skin);
    out.skin.weights = match bind_to_skeleton(skeleton, &skin.bind_positions, &skin.triangles, binding) {
        Ok(weights) => weights,
        Err(e) => {
            out.warnings.push(format!("{}: {e}; smooth weights instead", asset.name));
            bind_to_skeleton(skeleton, &skin.bind_positions, &skin.triangles, Binding::Smooth)
                .expect("smooth binding cannot fail")
        }
    };
    out.warnings.push(format!("weights computed ({binding:?}) from the bones"));
    out
}

/// An SMPL model and the clips of its folder.
#[derive(Clone)]
pub struct SmplSet {
    pub model: Arc<SmplModel>,
    pub clips: Vec<(String, Arc<Clip>)>,
    /// What the loader fixed (normalised weight rows).
    pub warnings: Vec<String>,
}

impl AssetLibrary {
    /// The character of `source`, loaded once.
    pub fn load(&mut self, source: &SourceDoc) -> Result<Arc<CharacterAsset>, FormatError> {
        if let Some(asset) = self.cache.get(source) {
            return Ok(asset.clone());
        }
        let asset = Arc::new(match source {
            SourceDoc::Embedded(name) if name == "puppet" => crate::formats::puppet::embedded_puppet(),
            SourceDoc::Embedded(name) => {
                return Err(FormatError::other(
                    Path::new(name),
                    "expected a built-in character (`puppet`), found an unknown name",
                ));
            }
            // An SMPL folder is read once, for the body and for its clips.
            SourceDoc::File(dir) if crate::formats::smpl::is_smpl_dir(dir) => {
                let set = self.smpl(dir)?;
                let name = dir.file_stem().and_then(|s| s.to_str()).unwrap_or("smpl");
                let mut asset = set.model.asset(name, &[]).map_err(|e| FormatError::rig(dir, e))?;
                asset.warnings = set.warnings;
                asset
            }
            SourceDoc::File(path) if crate::formats::gltf_import::is_gltf(path) => {
                return Ok(self.gltf_part(path, 0)?.asset);
            }
            SourceDoc::Part(path, n) => return Ok(self.gltf_part(path, *n)?.asset),
            SourceDoc::File(path) => load_character(path)?,
        });
        self.cache.insert(source.clone(), asset.clone());
        Ok(asset)
    }

    /// Character `n` of the glTF file at `path` (the file read once).
    pub fn gltf_part(&mut self, path: &Path, n: usize) -> Result<GltfPart, FormatError> {
        let parts = self.gltf_parts(path)?;
        parts.get(n).cloned().ok_or_else(|| {
            FormatError::other(
                path,
                format!("expected character {} of the file, found {} characters", n.saturating_add(1), parts.len()),
            )
        })
    }

    /// Every character of the glTF file at `path` (the file read once).
    pub fn gltf_parts(&mut self, path: &Path) -> Result<&[GltfPart], FormatError> {
        if !self.gltf.contains_key(path) {
            let parts = crate::formats::gltf_import::load_gltf(path)?
                .into_iter()
                .map(|c| GltfPart {
                    asset: Arc::new(c.asset),
                    clips: c.clips.into(),
                    base_color: c.base_color,
                    morph_weights: c.morph_weights,
                })
                .collect();
            self.gltf.insert(path.to_path_buf(), parts);
        }
        Ok(&self.gltf[path])
    }

    /// The sources of a path: one per character of a glTF file (its first as `File`, the
    /// others as `Part`), or the path itself.
    pub fn sources_of(&mut self, path: &Path) -> Vec<SourceDoc> {
        let file = SourceDoc::File(path.to_path_buf());
        if !crate::formats::gltf_import::is_gltf(path) {
            return vec![file];
        }
        let count = self.gltf_parts(path).map_or(1, <[GltfPart]>::len);
        std::iter::once(file).chain((1..count).map(|n| SourceDoc::Part(path.to_path_buf(), n))).collect()
    }

    /// A new character's document for `source`: its name, the motion a BVH brings, the
    /// base colour a glTF material gives as its tint and the morph weights its mesh sets.
    pub fn new_character_doc(&mut self, source: SourceDoc, asset: &CharacterAsset) -> CharacterDoc {
        let mut doc = CharacterDoc { anim: own_motion(&source), ..CharacterDoc::new(source, asset.name.clone()) };
        if let Some(part) = self.gltf_source(&doc.source) {
            if let Some([r, g, b, _]) = part.base_color {
                doc.view.tint = [r, g, b];
            }
            if part.morph_weights.iter().any(|&w| w != 0.0) {
                doc.morphs = part.morph_weights;
            }
        }
        doc
    }

    /// The glTF character a source names, if it is one.
    pub fn gltf_source(&mut self, source: &SourceDoc) -> Option<GltfPart> {
        match source {
            SourceDoc::File(p) if crate::formats::gltf_import::is_gltf(p) => self.gltf_part(p, 0).ok(),
            SourceDoc::Part(p, n) => self.gltf_part(p, *n).ok(),
            _ => None,
        }
    }

    /// The keyframed clip (`.anim`) at `path`, read once.
    pub fn keyframe_clip(&mut self, path: &Path) -> Result<Arc<crate::rig::anim::Clip>, FormatError> {
        if let Some(clip) = self.keyframe_clips.get(path) {
            return Ok(clip.clone());
        }
        let clip = Arc::new(crate::formats::load_clip(path)?);
        self.keyframe_clips.insert(path.to_path_buf(), clip.clone());
        Ok(clip)
    }

    /// The character of `source` with weights computed from its bones (cached).
    pub fn load_bound(
        &mut self,
        source: &SourceDoc,
        binding: Option<BindingDoc>,
    ) -> Result<Arc<CharacterAsset>, FormatError> {
        let asset = self.load(source)?;
        let Some(binding) = binding else { return Ok(asset) };
        if let Some(bound) = self.bound.get(&(source.clone(), binding)) {
            return Ok(bound.clone());
        }
        let bound = Arc::new(rebind(&asset, binding));
        self.bound.insert((source.clone(), binding), bound.clone());
        Ok(bound)
    }

    /// The SMPL model and clips of a folder, loaded once.
    pub fn smpl(&mut self, dir: &Path) -> Result<SmplSet, FormatError> {
        if let Some(set) = self.smpl.get(dir) {
            return Ok(set.clone());
        }
        let (model, warnings) = crate::formats::smpl::load_smpl_dir(dir)?;
        let n = model.skeleton.len();
        let clips = crate::formats::smpl::clip_paths(dir)
            .into_iter()
            .map(|p| {
                let clip = crate::formats::smpl::parse_clip(crate::formats::error::open(&p)?, &p, n)?;
                Ok((p.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default(), Arc::new(clip)))
            })
            .collect::<Result<Vec<_>, FormatError>>()?;
        let set = SmplSet { model: Arc::new(model), clips, warnings };
        self.smpl.insert(dir.to_path_buf(), set.clone());
        Ok(set)
    }
}

/// A scene to open in place of the current one (startup, Open): every character, the
/// camera and the stage are replaced; selection, pins and history cleared.
#[derive(Resource, Default)]
pub struct PendingScene {
    pub doc: Option<SceneDoc>,
    /// Frame all characters afterwards (when the document has no camera).
    pub frame: bool,
}

/// Ids for new characters.
#[derive(Resource, Default)]
pub struct NextCharacterId(pub u64);

impl NextCharacterId {
    pub fn take(&mut self) -> CharacterId {
        self.0 += 1;
        CharacterId(self.0)
    }
}

/// Everything needed to capture the scene as a document (read only).
#[derive(SystemParam)]
pub struct SceneReader<'w, 's> {
    pub characters: Query<
        'w,
        's,
        (
            Entity,
            &'static SceneCharacter,
            &'static Character,
            &'static Placement,
            &'static CharacterView,
            Option<&'static SmplCharacter>,
            (&'static CharacterSkinning, &'static SkinOnGpu),
            Option<&'static ClipPlayer>,
            Option<&'static crate::scene::morphs::Morphs>,
            Option<&'static crate::scene::node_clips::NodeClipPlayer>,
        ),
    >,
    pub poses: Query<'w, 's, &'static JointPose>,
    pub cameras: Query<'w, 's, &'static OrbitCamera>,
    pub stage: Res<'w, StageSettings>,
    pub unloaded: Res<'w, super::state::UnloadedCharacters>,
    pub pose_library: Res<'w, super::pose_library::PoseLibrary>,
}

impl SceneReader<'_, '_> {
    /// The current scene, characters in id order (built when saving or when a character is
    /// duplicated or removed, never every frame).
    pub fn capture(&self) -> SceneDoc {
        let mut characters: Vec<CharacterDoc> =
            self.characters.iter().filter_map(|c| self.character_doc(c.0)).collect();
        characters.sort_by_key(|c| c.id);
        SceneDoc {
            // Characters that failed to load stay in the document as they were.
            characters: characters.into_iter().chain(self.unloaded.0.iter().cloned()).collect(),
            camera: self.cameras.iter().next().map(|o| o.0),
            stage: self.stage.0,
            poses: self.pose_library.0.clone(),
        }
    }

    /// The document of one live character: joints listed where they differ from the
    /// source's pose.
    pub fn character_doc(&self, entity: Entity) -> Option<CharacterDoc> {
        let (_, sc, character, placement, view, smpl, skinning, player, morphs, node_clips) =
            self.characters.get(entity).ok()?;
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
            placement: placement.0,
            pose,
            view: view.0.clone(),
            smpl: smpl.map(|body| body.state.clone()),
            binding: sc.binding,
            skinning: skinning.0.0,
            gpu_skinning: skinning.1.0,
            anim: player.map(|p| p.state.clone()),
            morphs: morphs.map(|m| m.weights.clone()).unwrap_or_default(),
            playback: node_clips.map(|p| p.state.clone()),
        })
    }
}

/// The pose a document gives a character: the source's pose with the listed joints
/// replaced. Keys that name no joint are returned as messages.
pub fn pose_from_doc(asset: &CharacterAsset, doc: &CharacterDoc) -> (Vec<JointRotation>, Vec<String>) {
    let mut pose = asset.skeleton.initial_pose();
    let mut unknown = Vec::new();
    for (key, rotation) in &doc.pose {
        match joint_of_pose_key(&asset.skeleton, key) {
            Some(j) => pose[j] = rotation.clamped(&asset.skeleton.joint(j).limits),
            None => {
                unknown.push(format!("{}: no joint `{key}` in {}; its pose was skipped", doc.name, doc.source.label()))
            }
        }
    }
    (pose, unknown)
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
    let node_clips = library.gltf_source(&doc.source).map(|part| part.clips).filter(|c| !c.is_empty());
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
    if let Some((dir, set)) = smpl {
        let state = doc.smpl.clone().unwrap_or_default();
        commands.entity(entity).insert(SmplCharacter::new(set.model, dir.clone(), set.clips, state));
    }
    Ok((entity, messages))
}

/// The motion a source brings with it: a BVH file plays its own clip.
pub fn own_motion(source: &SourceDoc) -> Option<crate::formats::scene::AnimDoc> {
    match source {
        SourceDoc::File(p) if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")) => {
            Some(crate::formats::scene::AnimDoc::of(p.clone()))
        }
        _ => None,
    }
}

/// The player of a character's keyframed clip, and a note when the clip's channels do not
/// fit the skeleton (3 for the root, then 3 per joint).
pub fn clip_player(
    library: &mut AssetLibrary,
    asset: &CharacterAsset,
    name: &str,
    anim: &crate::formats::scene::AnimDoc,
) -> Result<(ClipPlayer, Option<String>), FormatError> {
    let clip = match &anim.keys {
        Some(keys) => Arc::new(keys.clone()),
        None => library.keyframe_clip(&anim.file)?,
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

/// A document of characters placed side by side along x by their bind boxes, each
/// standing on y = 0 (re-placed by their boxes as they stand once skinned, see
/// [`super::arrange`]).
pub fn doc_side_by_side(library: &mut AssetLibrary, sources: Vec<SourceDoc>, messages: &mut Vec<String>) -> SceneDoc {
    let loaded: Vec<(SourceDoc, Arc<CharacterAsset>)> = sources
        .into_iter()
        .filter_map(|s| match library.load(&s) {
            Ok(a) => {
                messages.extend(a.warnings.iter().cloned());
                Some((s, a))
            }
            Err(e) => {
                messages.push(e.to_string());
                None
            }
        })
        .collect();
    // The characters of one glTF file stand as the file places them.
    use super::arrange::{gltf_file, one_file_groups, side_by_side, union};
    let groups = one_file_groups(&loaded.iter().map(|(s, _)| gltf_file(s)).collect::<Vec<_>>());
    let boxes: Vec<(Vec3, Vec3)> = groups.iter().map(|g| union(g.iter().map(|&i| loaded[i].1.bounds()))).collect();
    let mut translations = vec![Vec3::ZERO; loaded.len()];
    for (group, t) in groups.iter().zip(side_by_side(&boxes, &vec![1.0; boxes.len()])) {
        group.iter().for_each(|&i| translations[i] = t);
    }
    let characters = loaded
        .into_iter()
        .zip(translations)
        .map(|((source, asset), translation)| CharacterDoc {
            placement: PlacementDoc { translation, yaw: 0.0, scale: 1.0 },
            ..library.new_character_doc(source, &asset)
        })
        .collect();
    SceneDoc { characters, ..SceneDoc::default() }
}

/// The embedded default scene (`assets/default_scene.ron`).
pub fn default_scene_doc() -> SceneDoc {
    crate::formats::scene::parse_scene(
        std::io::Cursor::new(include_str!("../../assets/default_scene.ron")),
        Path::new("assets/default_scene.ron"),
    )
    .expect("the embedded default scene parses (rebuild it with `marionette gen-assets assets`)")
}

/// What the command line asked to open, as a document: a `.ron` scene (sources relative
/// to it), character paths side by side, or the default scene.
pub fn startup_doc(paths: &[PathBuf], library: &mut AssetLibrary, messages: &mut Vec<String>) -> Option<SceneDoc> {
    if paths.is_empty() {
        return Some(default_scene_doc());
    }
    if let Some(scene) = scene_path(paths) {
        return match read_scene(scene) {
            Ok(doc) => Some(doc),
            Err(e) => {
                messages.push(e.to_string());
                None
            }
        };
    }
    let sources = paths.iter().flat_map(|p| library.sources_of(p)).collect();
    Some(doc_side_by_side(library, sources, messages))
}

/// The scene file among startup paths: a single `.ron`.
pub fn scene_path(paths: &[PathBuf]) -> Option<&Path> {
    match paths {
        [one] if one.extension().is_some_and(|e| e == "ron") => Some(one),
        _ => None,
    }
}

/// Where Save writes until the user picks another file: the scene the editor was opened
/// on (against `cwd` when relative), else `scene.ron` in `cwd`. Edits to an opened scene
/// go back to it, not to a file elsewhere.
pub fn initial_save_path(paths: &[PathBuf], cwd: &Path) -> PathBuf {
    cwd.join(scene_path(paths).unwrap_or(Path::new("scene.ron")))
}

/// Reads a scene file and resolves its sources against its folder.
pub fn read_scene(path: &Path) -> Result<SceneDoc, FormatError> {
    let mut doc = crate::formats::scene::parse_scene(crate::formats::error::open(path)?, path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    for c in &mut doc.characters {
        c.source = c.source.resolved(dir);
        if let Some(anim) = c.anim.as_mut().filter(|a| !a.file.as_os_str().is_empty()) {
            anim.file = dir.join(&anim.file);
        }
    }
    Ok(doc)
}

/// Writes a scene file with sources relative to its folder.
pub fn write_scene(path: &Path, doc: &SceneDoc) -> Result<(), FormatError> {
    let mut doc = doc.clone();
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    for c in &mut doc.characters {
        c.source = c.source.relative_to(dir);
        if let Some(anim) = c.anim.as_mut().filter(|a| !a.file.as_os_str().is_empty()) {
            anim.file = crate::formats::scene::relative_path(&anim.file, dir);
        }
    }
    crate::formats::scene::save_scene(path, &doc)
}

/// Saves the scene to `path`, saying so (or why not) in the messages.
pub fn save_scene_to(path: &str, doc: &SceneDoc, messages: &mut super::state::Messages) {
    match write_scene(Path::new(path), doc) {
        Ok(()) => messages.push(format!("saved the scene to {path}")),
        Err(e) => messages.push(format!("the scene was not saved: {e}")),
    }
}

/// Queues the scene file at `path` to replace the current scene, or says why it cannot.
pub fn open_scene_from(path: &str, pending: &mut PendingScene, messages: &mut super::state::Messages) {
    match read_scene(Path::new(path)) {
        Ok(doc) => *pending = PendingScene { frame: doc.camera.is_none(), doc: Some(doc) },
        Err(e) => messages.push(e.to_string()),
    }
}

//! The scene as a document: capture the ECS state into a `SceneDoc`, and rebuild the ECS
//! from one (used by scene files, undo/redo and the startup scene).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;

use super::camera::OrbitCamera;
use super::stage::StageSettings;
use crate::formats::scene::{
    BindingDoc, CharacterDoc, PlacementDoc, SceneDoc, SourceDoc, ViewDoc, joint_of_pose_key, pose_key,
};
use crate::formats::{FormatError, load_character};
use crate::rig::smpl::{Clip, SmplModel};
use crate::rig::{CharacterAsset, JointRotation};
use crate::scene::smpl::SmplCharacter;
use crate::scene::{Character, DisplayMode, JointPose, Placement, SkinView, spawn_character_posed};

/// A character as the editor knows it: a stable id (kept across undo), its source, name,
/// visibility and whether the selected joint's weights are shown.
#[derive(Component, Clone, Debug)]
pub struct SceneCharacter {
    pub id: u64,
    pub source: SourceDoc,
    pub name: String,
    pub visible: bool,
    pub heat_of_selected: bool,
    pub binding: Option<BindingDoc>,
}

/// Loaded characters by source, shared by every scene character made from them.
#[derive(Resource, Default)]
pub struct AssetLibrary {
    cache: HashMap<SourceDoc, Arc<CharacterAsset>>,
    smpl: HashMap<PathBuf, SmplSet>,
    bound: HashMap<(SourceDoc, BindingDoc), Arc<CharacterAsset>>,
}

/// A copy of `asset` whose weights come from the distance to its bones at rest.
pub fn rebind(asset: &CharacterAsset, binding: BindingDoc) -> CharacterAsset {
    let mut out = asset.clone();
    out.skin.weights = crate::rig::bind::bind_to_skeleton(&asset.skeleton, &asset.skin.bind_positions, binding);
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
            SourceDoc::File(path) => load_character(path)?,
        });
        self.cache.insert(source.clone(), asset.clone());
        Ok(asset)
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

/// A scene to build in place of the current one (all characters are replaced).
#[derive(Resource, Default)]
pub struct PendingScene {
    pub doc: Option<SceneDoc>,
    /// Also set camera and stage from the document (not for undo).
    pub with_camera: bool,
    /// Frame all characters afterwards (when the document has no camera).
    pub frame: bool,
}

/// Ids for new characters.
#[derive(Resource, Default)]
pub struct NextCharacterId(pub u64);

impl NextCharacterId {
    pub fn take(&mut self) -> u64 {
        self.0 += 1;
        self.0
    }
}

/// Everything needed to capture the scene as a document.
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
            &'static SkinView,
            &'static DisplayMode,
            Option<&'static SmplCharacter>,
        ),
    >,
    pub poses: Query<'w, 's, &'static JointPose>,
    pub cameras: Query<'w, 's, &'static OrbitCamera>,
    pub stage: Res<'w, StageSettings>,
    pub unloaded: Res<'w, super::state::UnloadedCharacters>,
}

impl SceneReader<'_, '_> {
    /// The current scene, characters in id order.
    pub fn capture(&self) -> SceneDoc {
        let mut characters: Vec<(u64, CharacterDoc)> = self
            .characters
            .iter()
            .map(|(_, sc, character, placement, view, display, smpl)| {
                let mut doc = self.character_doc(sc, character, placement, view, display);
                doc.smpl = smpl.map(SmplCharacter::doc);
                (sc.id, doc)
            })
            .collect();
        characters.sort_by_key(|(id, _)| *id);
        SceneDoc {
            // Characters that failed to load stay in the document as they were.
            characters: characters.into_iter().map(|(_, d)| d).chain(self.unloaded.0.iter().cloned()).collect(),
            camera: self.cameras.iter().next().map(|o| o.0),
            stage: self.stage.0,
        }
    }

    fn character_doc(
        &self,
        sc: &SceneCharacter,
        character: &Character,
        placement: &Placement,
        view: &SkinView,
        display: &DisplayMode,
    ) -> CharacterDoc {
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
        CharacterDoc {
            id: Some(sc.id),
            source: sc.source.clone(),
            name: sc.name.clone(),
            placement: placement.0,
            pose,
            view: ViewDoc {
                display: display.0,
                visible: sc.visible,
                weight_colors: view.weight_colors,
                heat_of_selected: sc.heat_of_selected,
                tint: view.tint,
            },
            smpl: None,
            binding: sc.binding,
        }
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

fn placement_of(doc: &CharacterDoc) -> Placement {
    Placement(doc.placement)
}

fn display_of(doc: &CharacterDoc) -> DisplayMode {
    DisplayMode(doc.view.display)
}

fn visibility_of(doc: &CharacterDoc) -> Visibility {
    if doc.view.visible { Visibility::Inherited } else { Visibility::Hidden }
}

/// The live characters, as far as a document can set them in place.
#[derive(SystemParam)]
pub struct LiveCharacters<'w, 's> {
    pub characters: Query<
        'w,
        's,
        (
            Entity,
            &'static Character,
            &'static mut SceneCharacter,
            &'static mut Placement,
            &'static mut SkinView,
            &'static mut DisplayMode,
            &'static mut Visibility,
            Option<&'static mut SmplCharacter>,
        ),
    >,
    pub poses: Query<'w, 's, &'static mut JointPose>,
}

impl LiveCharacters<'_, '_> {
    /// Each live character's entity, id, source and binding.
    pub fn index(&self) -> Vec<(Entity, u64, SourceDoc, Option<BindingDoc>)> {
        self.characters.iter().map(|(e, _, sc, ..)| (e, sc.id, sc.source.clone(), sc.binding)).collect()
    }

    /// Sets a live character to its document in place (same entity, same mesh): pose,
    /// placement, name, view and SMPL state. Changes are written only where values differ,
    /// so only what changed is re-skinned. Returns messages about unknown pose keys.
    pub fn update_from_doc(&mut self, entity: Entity, doc: &CharacterDoc) -> Vec<String> {
        let Ok((_, character, mut sc, mut placement, mut view, mut display, mut visibility, smpl)) =
            self.characters.get_mut(entity)
        else {
            return Vec::new();
        };
        let (pose, messages) = pose_from_doc(&character.asset, doc);
        for (&joint, rotation) in character.joints.iter().zip(pose) {
            if let Ok(mut current) = self.poses.get_mut(joint) {
                current.set_if_neq(JointPose(rotation));
            }
        }
        placement.set_if_neq(placement_of(doc));
        display.set_if_neq(display_of(doc));
        visibility.set_if_neq(visibility_of(doc));
        let wanted =
            SkinView { tint: doc.view.tint, weight_colors: doc.view.weight_colors, heat_joint: view.heat_joint };
        view.set_if_neq(wanted);
        if sc.name != doc.name || sc.visible != doc.view.visible || sc.heat_of_selected != doc.view.heat_of_selected {
            sc.name = doc.name.clone();
            sc.visible = doc.view.visible;
            sc.heat_of_selected = doc.view.heat_of_selected;
        }
        if let (Some(mut body), Some(state)) = (smpl, doc.smpl.as_ref())
            && body.doc() != *state
        {
            body.apply_doc(state);
        }
        messages
    }
}

/// Spawns one character of a document with the given id.
pub fn spawn_from_doc(
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    library: &mut AssetLibrary,
    doc: &CharacterDoc,
    id: u64,
) -> Result<(Entity, Vec<String>), FormatError> {
    let asset = library.load_bound(&doc.source, doc.binding)?;
    let (pose, messages) = pose_from_doc(&asset, doc);
    let entity = spawn_character_posed(commands, meshes, asset, placement_of(doc), &pose);
    commands.entity(entity).insert((
        SceneCharacter {
            id,
            source: doc.source.clone(),
            name: doc.name.clone(),
            visible: doc.view.visible,
            heat_of_selected: doc.view.heat_of_selected,
            binding: doc.binding,
        },
        SkinView { tint: doc.view.tint, weight_colors: doc.view.weight_colors, heat_joint: None },
        display_of(doc),
        visibility_of(doc),
    ));
    if let SourceDoc::File(dir) = &doc.source
        && crate::formats::smpl::is_smpl_dir(dir)
    {
        let set = library.smpl(dir)?;
        commands.entity(entity).insert(SmplCharacter::new(set.model, dir.clone(), set.clips, doc.smpl.as_ref()));
    }
    Ok((entity, messages))
}

/// A document of characters placed side by side along x, each standing on y = 0.
pub fn doc_side_by_side(library: &mut AssetLibrary, sources: Vec<SourceDoc>, messages: &mut Vec<String>) -> SceneDoc {
    let gap = 0.15;
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
    let widths: Vec<f32> = loaded
        .iter()
        .map(|(_, a)| {
            let (lo, hi) = a.bounds();
            (hi.x - lo.x).max(0.1)
        })
        .collect();
    let total: f32 = widths.iter().sum::<f32>() + gap * loaded.len().saturating_sub(1) as f32;
    let mut x = -total / 2.0;
    let characters = loaded
        .into_iter()
        .zip(widths)
        .map(|((source, asset), w)| {
            let (lo, hi) = asset.bounds();
            let center = (lo + hi) / 2.0;
            let doc = CharacterDoc {
                id: None,
                name: asset.name.clone(),
                source,
                placement: PlacementDoc {
                    translation: Vec3::new(x + w / 2.0 - center.x, -lo.y, -center.z),
                    yaw: 0.0,
                    scale: 1.0,
                },
                pose: Default::default(),
                view: ViewDoc::default(),
                smpl: None,
                binding: None,
            };
            x += w + gap;
            doc
        })
        .collect();
    SceneDoc { characters, camera: None, stage: Default::default() }
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
    Some(doc_side_by_side(library, paths.iter().map(|p| SourceDoc::File(p.clone())).collect(), messages))
}

/// The scene file among startup paths: a single `.ron`.
pub fn scene_path(paths: &[PathBuf]) -> Option<&Path> {
    match paths {
        [one] if one.extension().is_some_and(|e| e == "ron") => Some(one),
        _ => None,
    }
}

/// Reads a scene file and resolves its sources against its folder.
pub fn read_scene(path: &Path) -> Result<SceneDoc, FormatError> {
    let mut doc = crate::formats::scene::parse_scene(crate::formats::error::open(path)?, path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    for c in &mut doc.characters {
        c.source = c.source.resolved(dir);
    }
    Ok(doc)
}

/// Writes a scene file with sources relative to its folder.
pub fn write_scene(path: &Path, doc: &SceneDoc) -> Result<(), FormatError> {
    let mut doc = doc.clone();
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    for c in &mut doc.characters {
        c.source = c.source.relative_to(dir);
    }
    crate::formats::scene::save_scene(path, &doc)
}

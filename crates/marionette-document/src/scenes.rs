//! Scene documents outside the ECS: reading and writing scene files (sources relative to
//! the file), the pose a document gives a character, characters side by side, the embedded
//! default scene and what the command line asks to open.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec3;

use super::library::AssetLibrary;
use marionette_formats::FormatError;
use marionette_formats::scene::{BackgroundDoc, CharacterDoc, PlacementDoc, SceneDoc, SourceDoc, joint_of_pose_key};
use marionette_rig::{CharacterAsset, JointRotation};

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

/// A document of characters placed side by side along x by their bind boxes, each
/// standing on y = 0 (re-placed by their boxes as they stand once skinned, see
/// `editor::arrange`).
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
    use super::layout::{gltf_file, one_file_groups, side_by_side, union};
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
            placement: PlacementDoc::new(translation, 0.0, 1.0),
            ..library.new_character_doc(source, &asset)
        })
        .collect();
    SceneDoc { characters, ..SceneDoc::default() }
}

/// A file's characters as a document, each where its file puts it: a character file's
/// one, or every character of a glTF or FBX file (their warnings are the library's).
pub fn file_doc(library: &mut AssetLibrary, path: &Path) -> Result<SceneDoc, FormatError> {
    let mut doc = SceneDoc::default();
    for source in library.sources_of(path) {
        let asset = library.load(&source)?;
        let c = library.new_character_doc(source, &asset);
        doc.characters.push(c);
    }
    Ok(doc)
}

/// The embedded default scene (`assets/default_scene.ron`).
pub fn default_scene_doc() -> SceneDoc {
    marionette_formats::scene::parse_scene(
        std::io::Cursor::new(include_str!("../../../assets/default_scene.ron")),
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

/// Reads a scene file and resolves its sources (and a background picture) against its
/// folder.
pub fn read_scene(path: &Path) -> Result<SceneDoc, FormatError> {
    let mut doc = marionette_formats::scene::parse_scene(marionette_formats::error::open(path)?, path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    if let BackgroundDoc::Image { path, .. } = &mut doc.stage.background
        && path.is_relative()
    {
        *path = dir.join(&*path);
    }
    for c in &mut doc.characters {
        c.source = c.source.resolved(dir);
        if let Some(anim) = c.anim.as_mut() {
            if !anim.file.as_os_str().is_empty() {
                anim.file = dir.join(&anim.file);
            }
            if let Some(retarget) = &mut anim.retarget {
                retarget.from = retarget.from.resolved(dir);
            }
        }
    }
    Ok(doc)
}

/// Writes a scene file with sources relative to its folder.
pub fn write_scene(path: &Path, doc: &SceneDoc) -> Result<(), FormatError> {
    let mut doc = doc.clone();
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if let BackgroundDoc::Image { path, .. } = &mut doc.stage.background {
        *path = marionette_formats::scene::relative_path(path, dir);
    }
    for c in &mut doc.characters {
        c.source = c.source.relative_to(dir);
        if let Some(anim) = c.anim.as_mut() {
            if !anim.file.as_os_str().is_empty() {
                anim.file = marionette_formats::scene::relative_path(&anim.file, dir);
            }
            if let Some(retarget) = &mut anim.retarget {
                retarget.from = retarget.from.relative_to(dir);
            }
        }
    }
    marionette_formats::scene::save_scene(path, &doc)
}

//! Exporting a scene: every character of a document as glTF, shaped (SMPL β, morph
//! weights), posed by its pose and its keyframed clip at its time, placed and tinted.

use crate::formats::FormatError;
use crate::formats::gltf::{GltfCharacter, GltfMesh, Motion, write_glb};
use crate::formats::scene::SceneDoc;

/// Frames per second at which clips are sampled for glTF.
pub const EXPORT_FPS: f32 = 30.0;

/// A clip sampled over its range at [`EXPORT_FPS`] (its last time included): the poses
/// and root translations a glTF animation holds. Joints without keys keep `rest`.
pub fn sampled(
    clip: &crate::rig::anim::Clip,
    skeleton: &crate::rig::Skeleton,
    rest: &[crate::rig::JointRotation],
) -> Motion {
    let (start, end) = clip.range;
    let frames = ((end - start).max(0.0) * EXPORT_FPS).ceil() as usize;
    let mut motion = Motion::default();
    for f in 0..=frames {
        let t = (start + f as f32 / EXPORT_FPS).min(end);
        let (root, pose) = clip.pose_at(skeleton, t, rest);
        motion.times.push(t - start);
        motion.poses.push(pose);
        motion.roots.push(root);
    }
    motion
}

/// A character's asset as the document shapes it: an SMPL body by its β, a mesh with morph
/// targets by their weights.
fn shaped(
    library: &mut super::document::AssetLibrary,
    c: &crate::formats::scene::CharacterDoc,
) -> Result<std::sync::Arc<crate::rig::CharacterAsset>, FormatError> {
    let mut asset = library.load_bound(&c.source, c.binding)?;
    if let (Some(smpl), crate::formats::scene::SourceDoc::File(dir)) = (&c.smpl, &c.source)
        && !smpl.betas.is_empty()
    {
        let set = library.smpl(dir)?;
        asset = std::sync::Arc::new(set.model.asset(&c.name, &smpl.betas).map_err(|e| FormatError::rig(dir, e))?);
    }
    if !c.morphs.is_empty() && !asset.morphs.is_empty() {
        let mut morphed = (*asset).clone();
        morphed.skin.bind_positions = asset.morphed_positions(&c.morphs);
        asset = std::sync::Arc::new(morphed);
    }
    Ok(asset)
}

/// Every character of a scene document as glTF: its shape, its pose, its keyframed clip at
/// its time, its placement and tint.
pub fn scene_glb(doc: &SceneDoc, mesh: GltfMesh, animated: bool) -> Result<Vec<u8>, FormatError> {
    let mut library = super::document::AssetLibrary::default();
    let mut loaded = Vec::new();
    for c in &doc.characters {
        let asset = shaped(&mut library, c)?;
        let (mut pose, notes) = super::document::pose_from_doc(&asset, c);
        notes.iter().for_each(|n| bevy::log::warn!("{n}"));
        let mut root = asset.skeleton.joint(0).rest_offset;
        let mut motion = None;
        if let Some(anim) = &c.anim {
            let clip = match &anim.keys {
                Some(keys) => keys.clone(),
                None => crate::formats::load_clip(&anim.file)?,
            };
            let clip = clip.retargeted(&asset.skeleton, &anim.names);
            if animated {
                motion = Some(sampled(&clip, &asset.skeleton, &pose));
            }
            (root, pose) = clip.pose_at(&asset.skeleton, anim.time, &pose);
        }
        loaded.push((c, asset, pose, root, motion));
    }
    let characters: Vec<GltfCharacter> = loaded
        .iter()
        .map(|(c, asset, pose, root, motion)| GltfCharacter {
            name: &c.name,
            asset,
            pose,
            root: *root,
            translation: c.placement.translation,
            yaw: c.placement.yaw,
            scale: c.placement.scale,
            tint: c.view.tint,
            motion: motion.clone(),
        })
        .collect();
    Ok(write_glb(&characters, mesh))
}

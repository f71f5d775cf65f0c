//! `marionette export`: characters or a scene, posed, as OBJ or glTF.

use std::io::Write;
use std::path::Path;

use anyhow::Result;
use glam::Mat4;

use super::args::{ClipArgs, ExportArgs};
use super::write_file;
use crate::document::posing::{PoseSpec, apply_ik_specs, apply_pose_specs, describe_ik, posed_positions_by};
use crate::formats::gltf::{GltfCharacter, GltfMesh, write_glb};
use crate::formats::scene::AnimDoc;
use crate::formats::{load_character, obj};

/// Runs `export`: a glTF file's characters, a scene as glTF, or a character as OBJ or glTF.
pub fn run(a: &ExportArgs) -> Result<()> {
    if a.clip.retarget.is_some() {
        return export_retargeted(a);
    }
    if crate::formats::has_parts(&a.path) {
        return export_gltf_file(&a.path, &a.out, &a.poses, a.skinning.into(), &a.clip, a.bake, a.animation);
    }
    if is_scene(&a.path) {
        let doc = crate::document::scenes::read_scene(&a.path)?;
        return export_scene(&doc, a);
    }
    export_character(a)
}

/// `export TARGET --retarget SOURCE`: the target's characters playing the source's motion
/// (at `--time`; with `--animation` the retargeted clip goes out), each retargeting
/// described.
fn export_retargeted(a: &ExportArgs) -> Result<()> {
    let mut library = crate::document::AssetLibrary::default();
    let mut doc = crate::formats::scene::SceneDoc::default();
    let anim = a.clip.anim_doc(false).expect("--retarget makes a clip");
    let settings = anim.retarget.clone().expect("--retarget sets it");
    for source in library.sources_of(&a.path) {
        let asset = library.load(&source)?;
        let mut c = library.new_character_doc(source, &asset);
        c.playback = None;
        let from = crate::document::retarget::motion_source_doc(&mut library, &doc, &settings.from)?;
        let done = crate::document::retarget::retarget(&mut library, &from, &c, &asset, &settings)?;
        eprintln!("{}", crate::document::retarget::describe(&done, &from.name, &c.name, &asset.skeleton));
        // Its clip as worked out here, so the export does not retarget it again.
        c.anim = Some(AnimDoc { keys: Some(done.clip), ..anim.clone() });
        doc.characters.push(c);
    }
    export_scene(&doc, a)
}

/// A scene document as `--out` asks: glTF (with `--bake`, `--animation`) or one OBJ mesh.
fn export_scene(doc: &crate::formats::scene::SceneDoc, a: &ExportArgs) -> Result<()> {
    if is_glb(&a.out) {
        let glb = crate::document::export::scene_glb(doc, mesh_kind(a.bake), a.animation)?;
        write_file(&a.out, |w| w.write_all(&glb))?;
    } else {
        let (positions, triangles) = crate::document::export::scene_mesh(doc)?;
        write_file(&a.out, |w| obj::write_obj(w, &positions, &triangles))?;
    }
    println!("wrote {} ({} characters)", a.out.display(), doc.characters.len());
    Ok(())
}

fn mesh_kind(bake: bool) -> GltfMesh {
    if bake { GltfMesh::Baked } else { GltfMesh::Skinned }
}

/// One character posed by `--anim`, `--pose` and `--ik`, as OBJ or glTF.
fn export_character(a: &ExportArgs) -> Result<()> {
    let (path, out, clip, animation, bake) = (&a.path, &a.out, &a.clip, a.animation, a.bake);
    let (poses, ik) = (&a.poses, &a.ik);
    let asset = load_character(path)?;
    for w in &asset.warnings {
        eprintln!("warning: {w}");
    }
    let mut pose = asset.skeleton.initial_pose();
    let mut origin = Mat4::IDENTITY;
    let mut clips = Vec::new();
    if let Some(file) = &clip.anim {
        let anim = crate::formats::load_clip(file)?.retargeted(&asset.skeleton, &Default::default());
        if animation {
            let name = crate::document::export::clip_name(file, &asset.name);
            let splines = crate::document::export::keyframes_as_splines(&anim, &asset.skeleton, &pose, &name);
            clips.push(splines.map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?);
        }
        let (root, clip_pose) = anim.pose_at(&asset.skeleton, clip.time.unwrap_or(0.0), &pose);
        pose = clip_pose;
        let root_offset = asset.skeleton.joint(0).rest_offset;
        origin = Mat4::from_translation(root - root_offset);
    }
    apply_pose_specs(&asset.skeleton, &mut pose, poses)?;
    for report in apply_ik_specs(&asset.skeleton, &mut pose, origin, ik)? {
        eprintln!("{}", describe_ik(&asset.skeleton, &report));
    }
    if is_glb(out) {
        let name = asset.name.clone();
        let root = origin.transform_point3(asset.skeleton.joint(0).rest_offset);
        let character = GltfCharacter { root, clips: &clips, ..GltfCharacter::new(&name, &asset, &pose) };
        let glb = write_glb(&[character], mesh_kind(bake)).map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
        write_file(out, |w| w.write_all(&glb))?;
        println!("wrote {} ({} joints, {} vertices)", out.display(), asset.skeleton.len(), asset.vertex_count());
        return Ok(());
    }
    let positions = posed_positions_by(&asset, &pose, origin, a.skinning.into());
    write_file(out, |w| obj::write_obj(w, &positions, &asset.skin.triangles))?;
    println!("wrote {} ({} vertices, {} triangles)", out.display(), positions.len(), asset.triangle_count());
    Ok(())
}

/// `export FILE.glb|FILE.gltf`: every character of the file, posed by `--clip` at `--time`
/// (or the file's node transforms) and `--pose`, as one OBJ of all their vertices in file
/// order, or as a glb scene.
fn export_gltf_file(
    path: &Path,
    out: &Path,
    poses: &[PoseSpec],
    method: crate::rig::dqs::SkinningMethod,
    clip: &ClipArgs,
    bake: bool,
    animation: bool,
) -> Result<()> {
    let time = clip.time.unwrap_or(0.0);
    if is_glb(out) {
        let mut library = crate::document::AssetLibrary::default();
        let mut doc = crate::formats::scene::SceneDoc::default();
        for source in library.sources_of(path) {
            let asset = library.load(&source)?;
            let mut c = library.new_character_doc(source.clone(), &asset);
            let part = library.part_of_source(&source);
            let found =
                clip.clip.as_deref().and_then(|spec| crate::document::posing::find_clip(&part?.clips, spec).cloned());
            c.playback =
                found.map(|k| crate::formats::scene::PlaybackDoc { clip: Some(k.name), time, ..Default::default() });
            doc.characters.push(c);
        }
        let mesh = mesh_kind(bake);
        let glb = crate::document::export::scene_glb(&doc, mesh, animation)?;
        write_file(out, |w| w.write_all(&glb))?;
        println!("wrote {} ({} characters)", out.display(), doc.characters.len());
        return Ok(());
    }
    let characters = crate::formats::load_parts(path)?;
    characters.iter().flat_map(|c| &c.asset.warnings).for_each(|w| eprintln!("warning: {w}"));
    let (positions, triangles) =
        crate::document::posing::posed_gltf(&characters, clip.clip.as_deref(), time, poses, method)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    write_file(out, |w| obj::write_obj(w, &positions, &triangles))?;
    println!(
        "wrote {} ({} characters, {} vertices, {} triangles)",
        out.display(),
        characters.len(),
        positions.len(),
        triangles.len()
    );
    Ok(())
}

fn is_glb(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb"))
}

fn is_scene(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ron"))
}

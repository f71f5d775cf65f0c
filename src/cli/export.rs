//! `marionette export`: characters or a scene, posed, as OBJ or glTF. Every input becomes a
//! scene document first (a scene file as it is; a character, glTF or FBX file as its
//! characters), then the posing options (`--retarget` among them)
//! change it as every command does ([`crate::document::options`]), then it goes out.

use std::io::Write;
use std::path::Path;

use anyhow::Result;

use super::args::ExportArgs;
use super::write_file;
use crate::document::AssetLibrary;
use crate::document::options::{PoseOptions, apply_options};
use crate::formats::gltf::GltfMesh;
use crate::formats::obj;
use crate::formats::scene::SceneDoc;

/// Runs `export`.
pub fn run(a: &ExportArgs) -> Result<()> {
    let options = pose_options(a);
    if a.animation && options.poses_joints() {
        anyhow::bail!("--pose and --ik pose a still figure; --animation exports the clips as they are: use one");
    }
    let mut library = AssetLibrary::default();
    let mut doc = match is_scene(&a.path) {
        true => crate::document::scenes::read_scene(&a.path)?,
        false => crate::document::scenes::file_doc(&mut library, &a.path)?,
    };
    let warnings = doc.characters.iter().filter_map(|c| library.load(&c.source).ok()).flat_map(|a| a.warnings.clone());
    warnings.for_each(|w| eprintln!("warning: {w}"));
    for note in apply_options(&mut doc, &options, &mut library).map_err(anyhow::Error::msg)? {
        eprintln!("{note}");
    }
    export_scene(&doc, a, &mut library)
}

/// The posing options `export` was given.
fn pose_options(a: &ExportArgs) -> PoseOptions {
    PoseOptions {
        specs: a.pose.specs(a.fps),
        skinning: a.skinning.map(Into::into),
        anim: a.clip.anim_doc(false),
        clip: a.clip.own_clip(),
        time: a.clip.time,
        still: !a.animation,
    }
}

/// A scene document as `--out` asks: glTF (with `--bake`, `--animation`) or one OBJ mesh.
fn export_scene(doc: &SceneDoc, a: &ExportArgs, library: &mut AssetLibrary) -> Result<()> {
    if is_glb(&a.out) {
        let mesh = if a.bake { GltfMesh::Baked } else { GltfMesh::Skinned };
        let glb = crate::document::export::scene_glb_from(library, doc, mesh, a.animation)?;
        write_file(&a.out, |w| w.write_all(&glb))?;
        println!("wrote {} ({} characters)", a.out.display(), doc.characters.len());
    } else {
        let (positions, triangles) = crate::document::export::scene_mesh_from(library, doc)?;
        write_file(&a.out, |w| obj::write_obj(w, &positions, &triangles))?;
        println!(
            "wrote {} ({} characters, {} vertices, {} triangles)",
            a.out.display(),
            doc.characters.len(),
            positions.len(),
            triangles.len()
        );
    }
    Ok(())
}

fn is_glb(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb"))
}

fn is_scene(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ron"))
}

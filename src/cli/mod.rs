//! Each command's body but the editor's (`edit`, `render`, `bench` run the app): `export`,
//! `info`, `bind`, `smpl` and `gen-assets` on the document layer, and the command line's
//! words ([`args`]). No Bevy; `main.rs` parses and dispatches.

pub mod args;
pub mod bind;
pub mod export;
pub mod smpl;
pub mod smpl_tasks;

use std::path::Path;

use anyhow::{Context, Result};

use crate::document::posing::describe;
use crate::formats::load_character;

/// `info`: what a character file loads as (every character of a glTF file, with its
/// animations).
pub fn info(path: &Path) -> Result<()> {
    if !crate::formats::gltf_import::is_gltf(path) {
        print!("{}", describe(&load_character(path)?));
        return Ok(());
    }
    for c in crate::formats::gltf_import::load_gltf(path)? {
        print!("{}", describe(&c.asset));
        for clip in &c.clips {
            println!("animation {} `{}`: {:.3} s", clip.index, clip.name, clip.duration());
        }
    }
    Ok(())
}

/// `gen-assets`: the project's own puppet and scenes, written into `dir`.
pub fn gen_assets(dir: &Path) -> Result<()> {
    crate::formats::puppet::write_6837(&crate::formats::puppet::puppet(), dir, "puppet")
        .with_context(|| format!("writing {}", dir.display()))?;
    let scene = dir.join("default_scene.ron");
    crate::formats::scene::save_scene(&scene, &crate::document::default_scene::generate())?;
    let crowd = dir.join("crowd_scene.ron");
    crate::formats::scene::save_scene(&crowd, &crate::document::crowd::shipped_crowd())?;
    println!("wrote {}/puppet.{{skel,obj,attach}}, {} and {}", dir.display(), scene.display(), crowd.display());
    Ok(())
}

/// Writes a whole file or nothing: into a temporary sibling, then renamed over `path`.
pub fn write_file(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> Result<()> {
    crate::formats::error::refuse_overwriting_input(path)?;
    crate::formats::write_atomically(path, write).with_context(|| format!("writing {}", path.display()))
}

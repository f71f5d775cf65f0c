//! Each command's body: `export`, `info`, `bind`, `smpl` and `gen-assets` on the document
//! layer; `edit`, `render` and `bench`, which run the app ([`app`]); `generate`'s plan and
//! run; and the command line's words ([`args`]). `main.rs` parses and dispatches.

pub mod app;
pub mod args;
pub mod bind;
pub mod export;
pub mod generate;
pub mod smpl;
pub mod smpl_tasks;

use std::path::Path;

use anyhow::{Context, Result};

use crate::document::posing::describe;
use crate::formats::load_character;

/// `info`: what a character file loads as: every part (character or prop) of a glTF file
/// with its materials and its clips (channels, keys, length, interpolation); a
/// BVH's motion; an SMPL folder's clips.
pub fn info(path: &Path) -> Result<()> {
    if !crate::formats::has_parts(path) {
        print!("{}", describe(&load_character(path)?));
        if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")) {
            let bvh = crate::formats::bvh::parse_bvh(crate::formats::error::open(path)?, path)?;
            let (start, end) = bvh.clip.range;
            let frames = ((end - start) / bvh.frame_time).round() as usize + 1;
            println!(
                "motion: {frames} frames every {:.4} s, {:.3} s, {} channels, LINEAR (sampled)",
                bvh.frame_time,
                end - start,
                bvh.clip.channels.len()
            );
        }
        if crate::formats::smpl::is_smpl_dir(path) {
            let mut library = crate::document::AssetLibrary::default();
            for (name, clip) in library.smpl(path)?.clips {
                let (frames, seconds) = (clip.frame_count(), crate::document::motion::smpl_span(&clip).end);
                println!("clip `{name}`: {frames} frames at {} per second, {seconds:.3} s", crate::rig::smpl::CLIP_FPS);
            }
        }
        return Ok(());
    }
    for c in crate::formats::load_parts(path)? {
        print!("{}", describe(&c.asset));
        for m in &c.asset.materials {
            println!("{}", crate::document::posing::describe_material(m));
        }
        for clip in &c.clips {
            println!("{}", crate::document::posing::describe_clip(clip));
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

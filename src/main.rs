//! The `marionette` command line: parses and dispatches. The commands' bodies are in
//! `marionette::cli` (on the document layer) and, for those that run the app (`edit`,
//! `render`, `bench`), in `marionette::editor`.

use std::process::ExitCode;

use anyhow::Result;
use clap::Parser;
use marionette::cli::args::{Cli, Command};

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("marionette: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        None => marionette::editor::run(Vec::new(), Default::default(), Default::default()),
        Some(Command::Edit { paths, clip, pose, recover }) => {
            let paths = if recover {
                use marionette::editor::ui::unsaved::{newest_recovery, recovery_dir};
                let newest = newest_recovery()
                    .ok_or_else(|| anyhow::anyhow!("{}: no recovery file", recovery_dir().display()))?;
                vec![newest]
            } else {
                paths
            };
            let edits = marionette::editor::StartupEdits {
                pose: pose.specs(),
                recovered: recover,
                anim: clip.anim_doc(true),
                time: clip.time,
                clip: clip.own_clip(),
                ..Default::default()
            };
            // The options as every command applies them: one naming what no character has
            // fails before the window opens; the files read here are the editor's.
            let mut library = marionette::document::AssetLibrary::default();
            marionette::editor::present::view::startup_scene(&paths, &edits, &mut library, &mut Vec::new())
                .map_err(anyhow::Error::msg)?;
            marionette::editor::run(paths, edits, library)
        }
        Some(Command::Info { path }) => marionette::cli::info(&path)?,
        Some(Command::Export(args)) => marionette::cli::export::run(&args)?,
        Some(Command::Render { paths, out, shot, pose, skinning, match_height, clip, frames }) => {
            let started = std::time::Instant::now();
            let edits = marionette::editor::StartupEdits {
                pose: pose.specs(),
                skinning: skinning.map(Into::into),
                match_height,
                anim: clip.anim_doc(false),
                time: clip.time,
                clip: clip.own_clip(),
                view: shot.view,
                ortho: shot.ortho,
                transparent: shot.transparent,
                recovered: false,
                still: false,
            };
            let (sequence, pictures) = (frames.sequence(), frames.pictures());
            let (notes, picture) = marionette::editor::present::render::render(
                paths,
                edits,
                out.clone(),
                shot.picture(),
                pictures,
                shot.data,
            )
            .map_err(anyhow::Error::msg)?;
            for n in notes {
                eprintln!("note: {n}");
            }
            let what = match sequence.and_then(|s| s.times().ok()) {
                Some(times) => format!("{} frames as {}", times.len(), out.display()),
                None => out.display().to_string(),
            };
            let (width, height) = (picture.width, picture.height);
            println!("wrote {what} ({width}x{height}) in {:.2} s", started.elapsed().as_secs_f64());
        }
        Some(Command::Bind(args)) => marionette::cli::bind::run(&args)?,
        Some(Command::Smpl(args)) => marionette::cli::smpl::run(&args)?,
        Some(Command::Bench { characters, frames, data, puppets, json, gpu, no_draw }) => {
            use marionette::editor::bench;
            let crowd = bench::crowd_of(data, puppets).map_err(anyhow::Error::msg)?;
            let (characters, frames) = (characters as usize, frames as usize);
            let setup = bench::Setup { characters, frames, crowd, gpu_skinning: gpu, drawn: !no_draw };
            let report = bench::run(&setup).map_err(anyhow::Error::msg)?;
            if json {
                println!("{}", serde_json::to_string(&report)?);
            } else {
                println!("{}", bench::table(&report));
            }
        }
        Some(Command::Generate(args)) => marionette::cli::generate::run(&args)?,
        Some(Command::GenAssets { dir }) => marionette::cli::gen_assets(&dir)?,
    }
    Ok(())
}

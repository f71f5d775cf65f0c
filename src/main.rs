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
        Some(Command::Generate(args)) => generate(&args)?,
        Some(Command::GenAssets { dir }) => marionette::cli::gen_assets(&dir)?,
    }
    Ok(())
}

/// `generate`: the plan's pictures rendered in one app, each recorded in the shard's
/// manifest as its files are written, a progress bar with pictures a second and the time left.
fn generate(args: &marionette::cli::args::GenerateArgs) -> Result<()> {
    use marionette::editor::present::render::{ScenePicture, render_scenes};
    let Some(mut plan) = marionette::cli::generate::plan(args)? else { return Ok(()) };
    let (todo, finished, shard) = (plan.pictures.len(), plan.finished, plan.shard);
    eprintln!(
        "generate: shard {}/{}: {} pictures, {finished} already there, {todo} to render into {}",
        shard.index,
        shard.count,
        finished + todo,
        plan.dir.display()
    );
    if todo == 0 {
        return Ok(());
    }
    let started = std::time::Instant::now();
    let numbers: Vec<usize> = plan.pictures.iter().map(|p| p.0).collect();
    let pictures: Vec<ScenePicture> = std::mem::take(&mut plan.pictures)
        .into_iter()
        .map(|(k, scene, backdrop)| ScenePicture {
            scene,
            out: plan.out(k),
            ids: marionette::document::generate::coco_ids(k),
            backdrop,
        })
        .collect();
    let first_scene = plan.scene_file(numbers[0]);
    let library = std::mem::take(&mut plan.library);
    let (picture, data) = (plan.picture(), plan.spec.data);
    let bar = indicatif::ProgressBar::new(todo as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} pictures, {per_sec}, {elapsed} (left {eta})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let recorder = bar.clone();
    let on_written = Box::new(move |index: usize| {
        plan.record(numbers[index])?;
        recorder.inc(1);
        Ok(())
    });
    let notes = render_scenes(first_scene, library, pictures, picture, data, on_written).map_err(anyhow::Error::msg)?;
    bar.finish();
    for n in notes {
        eprintln!("note: {n}");
    }
    println!("wrote {todo} pictures in {:.2} s", started.elapsed().as_secs_f64());
    Ok(())
}

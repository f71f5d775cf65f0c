//! The `marionette` command line: thin glue over the library.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use glam::Mat4;

use marionette::formats::{load_character, obj};
use marionette::posing::{PoseSpec, apply_pose_specs, describe, posed_positions};

#[derive(Parser)]
#[command(
    name = "marionette",
    version,
    about = "Build scenes of skinned characters: load, pose, see and export them."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Open the editor on characters (`Model1.skel` finds `Model1.obj` and `Model1.attach`).
    Edit {
        /// Character files; none opens the default scene.
        paths: Vec<PathBuf>,
    },
    /// Print what a character file loads as: joints, vertices, triangles, weight checks.
    Info { path: PathBuf },
    /// Write the posed, skinned mesh as OBJ: one `v` per source vertex in source order,
    /// then the source faces.
    Export {
        path: PathBuf,
        #[arg(long)]
        out: PathBuf,
        /// `JOINT=rx,ry,rz` in radians (x applied first); JOINT is a name or an index.
        /// Angles outside the joint's limits are clamped. Repeatable.
        #[arg(long = "pose", value_name = "JOINT=rx,ry,rz")]
        poses: Vec<PoseSpec>,
    },
    /// Render a scene (.ron) or characters offscreen to a PNG, without a window.
    Render {
        /// A scene file or character files; none renders the default scene.
        paths: Vec<PathBuf>,
        #[arg(long)]
        out: PathBuf,
        #[arg(long, default_value_t = 1280)]
        width: u32,
        #[arg(long, default_value_t = 720)]
        height: u32,
    },
    /// Rebuild the project's own characters into a folder (normally `assets`).
    GenAssets {
        #[arg(default_value = "assets")]
        dir: PathBuf,
    },
}

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
        None => marionette::editor::run(Vec::new()),
        Some(Command::Edit { paths }) => marionette::editor::run(paths),
        Some(Command::Info { path }) => print!("{}", describe(&load_character(&path)?)),
        Some(Command::Export { path, out, poses }) => {
            let asset = load_character(&path)?;
            for w in &asset.warnings {
                eprintln!("warning: {w}");
            }
            let mut pose = asset.skeleton.initial_pose();
            apply_pose_specs(&asset.skeleton, &mut pose, &poses)?;
            let positions = posed_positions(&asset, &pose, Mat4::IDENTITY);
            write_file(&out, |w| {
                obj::write_obj(w, &positions, &asset.skin.triangles)
            })?;
            println!(
                "wrote {} ({} vertices, {} triangles)",
                out.display(),
                positions.len(),
                asset.triangle_count()
            );
        }
        Some(Command::Render {
            paths,
            out,
            width,
            height,
        }) => {
            let started = std::time::Instant::now();
            let notes = marionette::editor::render::render(paths, out.clone(), width, height)
                .map_err(anyhow::Error::msg)?;
            for n in notes {
                eprintln!("note: {n}");
            }
            println!(
                "wrote {} ({width}x{height}) in {:.2} s",
                out.display(),
                started.elapsed().as_secs_f64()
            );
        }
        Some(Command::GenAssets { dir }) => {
            marionette::puppet::write_6837(&marionette::puppet::puppet(), &dir, "puppet")
                .with_context(|| format!("writing {}", dir.display()))?;
            let scene = dir.join("default_scene.ron");
            marionette::formats::scene::save_scene(
                &scene,
                &marionette::editor::default_scene::generate(),
            )?;
            println!(
                "wrote {}/puppet.{{skel,obj,attach}} and {}",
                dir.display(),
                scene.display()
            );
        }
    }
    Ok(())
}

/// Writes a whole file or nothing: into a temporary sibling, then renamed over `path`.
fn write_file(
    path: &std::path::Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> Result<()> {
    marionette::formats::write_atomically(path, write)
        .with_context(|| format!("writing {}", path.display()))
}

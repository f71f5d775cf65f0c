//! The `marionette` command line: parses and dispatches. The commands' bodies are in
//! `marionette::cli` (those that run the app, `edit`, `render` and `bench`, in `cli::app`).

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
    use marionette::cli;
    match cli.command {
        None => marionette::editor::run(Vec::new(), Default::default(), Default::default()),
        Some(Command::Edit(args)) => cli::app::edit(args)?,
        Some(Command::Info { path }) => cli::info(&path)?,
        Some(Command::Export(args)) => cli::export::run(&args)?,
        Some(Command::Render(args)) => cli::app::render(args)?,
        Some(Command::Bind(args)) => cli::bind::run(&args)?,
        Some(Command::Smpl(args)) => cli::smpl::run(&args)?,
        Some(Command::Bench(args)) => cli::app::bench(args)?,
        Some(Command::Generate(args)) => cli::generate::run(&args)?,
        Some(Command::GenAssets { dir }) => cli::gen_assets(&dir)?,
    }
    Ok(())
}

//! The commands that run the app: `edit` opens the editor, `render` draws offscreen,
//! `bench` measures a crowd; each reads its arguments and calls the editor's code.

use anyhow::Result;

use crate::cli::args::{BenchArgs, EditArgs, RenderArgs};

/// `edit`: the editor on the paths (or the newest recovery file), with the command line's
/// options applied first (one naming what no character has fails before the window opens).
pub fn edit(args: EditArgs) -> Result<()> {
    let EditArgs { paths, clip, pose, recover, fps } = args;
    let paths = if recover {
        use crate::editor::ui::unsaved::{newest_recovery, recovery_dir};
        let newest =
            newest_recovery().ok_or_else(|| anyhow::anyhow!("{}: no recovery file", recovery_dir().display()))?;
        vec![newest]
    } else {
        paths
    };
    let edits = crate::editor::StartupEdits {
        pose: pose.specs(fps),
        recovered: recover,
        anim: clip.anim_doc(true),
        time: clip.time,
        clip: clip.own_clip(),
        ..Default::default()
    };
    // The options as every command applies them; the files read here are the editor's.
    let mut library = crate::document::AssetLibrary::default();
    crate::editor::present::view::startup_scene(&paths, &edits, &mut library, &mut Vec::new())
        .map_err(anyhow::Error::msg)?;
    crate::editor::run(paths, edits, library);
    Ok(())
}

/// `render`: the picture, a frame sequence or a contact sheet, its notes on standard error
/// and what was written on standard output.
pub fn render(args: RenderArgs) -> Result<()> {
    let RenderArgs { paths, out, shot, pose, skinning, match_height, clip, frames } = args;
    let started = std::time::Instant::now();
    let edits = crate::editor::StartupEdits {
        pose: pose.specs(frames.fps),
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
    use crate::document::annotate::controlnet::ControlNet;
    use crate::editor::present::render::{Rendering, render_with};
    let controlnet = shot.controlnet.then_some(ControlNet { canny: shot.canny });
    let (picture, data) = (shot.picture(), shot.data);
    let rendering = Rendering { paths, edits, out: out.clone(), picture, pictures, data, controlnet };
    let (notes, picture) = render_with(rendering, None).map_err(anyhow::Error::msg)?;
    for n in notes {
        eprintln!("note: {n}");
    }
    let what = match sequence.and_then(|s| s.times().ok()) {
        Some(times) => format!("{} frames as {}", times.len(), out.display()),
        None => out.display().to_string(),
    };
    let (width, height) = (picture.width, picture.height);
    println!("wrote {what} ({width}x{height}) in {:.2} s", started.elapsed().as_secs_f64());
    Ok(())
}

/// `bench`: the crowd measured, as a table or one JSON object.
pub fn bench(args: BenchArgs) -> Result<()> {
    use crate::editor::bench;
    let BenchArgs { characters, frames, data, puppets, json, gpu, no_draw } = args;
    let crowd = bench::crowd_of(data, puppets).map_err(anyhow::Error::msg)?;
    let (characters, frames) = (characters as usize, frames as usize);
    let setup = bench::Setup { characters, frames, crowd, gpu_skinning: gpu, drawn: !no_draw };
    let report = bench::run(&setup).map_err(anyhow::Error::msg)?;
    if json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        println!("{}", bench::table(&report));
    }
    Ok(())
}

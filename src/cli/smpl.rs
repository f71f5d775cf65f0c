//! `marionette smpl`: the SMPL exercise's tasks and sequences, written as OBJ frames.

use std::path::Path;

use anyhow::Result;

/// Runs `smpl` with its flags.
pub fn run(a: &super::args::SmplArgs) -> Result<()> {
    smpl(&a.data, a.task, a.sequence.clone(), a.transition, a.slerp, &a.out, a.naive)
}

fn smpl(
    data: &Path,
    task: Option<u32>,
    sequence: Option<String>,
    transition: usize,
    slerp: bool,
    out: &Path,
    naive: bool,
) -> Result<()> {
    use super::smpl_tasks::{parse_sequence, sequence_frames, task_frames, write_frames, write_frames_naive};
    use crate::rig::smpl::BlendMode;
    let started = std::time::Instant::now();
    let (model, warnings) = crate::formats::smpl::load_smpl_dir(data)?;
    warnings.iter().for_each(|w| eprintln!("warning: {w}"));
    let frames = match (task, sequence) {
        (Some(task), _) => task_frames(&model, data, task)?,
        (None, Some(spec)) => {
            let segments = parse_sequence(&spec).map_err(anyhow::Error::msg)?;
            sequence_frames(
                &model,
                data,
                &segments,
                transition,
                if slerp { BlendMode::Slerp } else { BlendMode::Nlerp },
            )?
        }
        (None, None) => anyhow::bail!("give --task N or --sequence SPEC"),
    };
    let loaded = started.elapsed();
    let bar = indicatif::ProgressBar::new(frames.len() as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} frames {elapsed} (eta {eta})")
            .expect("valid template"),
    );
    let tick = || bar.inc(1);
    if naive {
        write_frames_naive(&model, &frames, out, &tick)?;
    } else {
        write_frames(&model, &frames, out, &tick)?;
    }
    bar.finish_and_clear();
    let total = started.elapsed();
    println!(
        "wrote {} frames to {} in {:.2} s (loading {:.2} s, frames {:.2} s){}",
        frames.len(),
        out.display(),
        total.as_secs_f64(),
        loaded.as_secs_f64(),
        (total - loaded).as_secs_f64(),
        if naive { " [naive]" } else { "" }
    );
    Ok(())
}

//! `generate`'s plan, before the app renders: the spec read and checked, the shard and
//! the pictures it still lacks, each picture's scene drawn and written beside where its
//! picture goes; `--example`, `--dry-run` and `--merge`; and each written picture's line in
//! the shard's manifest; then [`run`] hands the plan to the render, with a progress bar.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};

use crate::cli::args::{GenerateArgs, SetFormat};
use crate::document::AssetLibrary;
use crate::document::generate::{self, ManifestLine, Shard, Spec, picture_stem, scene_of};
use crate::document::scenes::{read_scene, write_scene};
use crate::document::webdataset::TarSet;
use crate::formats::scene::{SceneDoc, ShotDoc};

/// What the app renders for a shard.
pub struct Plan {
    pub dir: PathBuf,
    pub spec: Spec,
    pub shard: Shard,
    /// The pictures to render: their numbers and scenes (as their files read back), and
    /// the picture to put behind each.
    pub pictures: Vec<(usize, SceneDoc, Option<PathBuf>)>,
    /// The pictures the folder already holds whole, of this shard.
    pub finished: usize,
    /// The files every scene names, loaded.
    pub library: AssetLibrary,
    /// With `--format webdataset`: the run's tars.
    pub tars: Option<TarSet>,
}

impl Plan {
    pub fn picture(&self) -> ShotDoc {
        self.spec.shot()
    }

    /// The file of picture `k`.
    pub fn out(&self, k: usize) -> PathBuf {
        self.dir.join(format!("{}.png", picture_stem(k)))
    }

    /// The file of picture `k`'s scene.
    pub fn scene_file(&self, k: usize) -> PathBuf {
        scene_file(&self.dir, k)
    }

    /// Writes picture `k`'s line into the shard's manifest (its files and their digests).
    pub fn record(&self, k: usize) -> Result<ManifestLine, String> {
        let line = generate::manifest_line(&self.dir, k).map_err(|e| e.to_string())?;
        generate::append_manifest(&self.dir.join(self.shard.manifest_name()), &line).map_err(|e| e.to_string())?;
        Ok(line)
    }
}

fn scene_file(dir: &Path, k: usize) -> PathBuf {
    dir.join(format!("{}.scene.ron", picture_stem(k)))
}

/// What `generate` does besides rendering: prints the example, merges, or prints the
/// scenes of a dry run (then `None`); else the plan of what to render.
pub fn plan(args: &GenerateArgs) -> Result<Option<Plan>> {
    if args.example {
        print!("{}", generate::EXAMPLE);
        return Ok(None);
    }
    if let Some(dir) = &args.merge {
        let n = generate::merge(dir).map_err(anyhow::Error::msg)?;
        println!("wrote {} ({n} pictures)", dir.join("coco.json").display());
        return Ok(None);
    }
    let (Some(spec_path), Some(dir)) = (&args.spec, &args.out) else {
        return Err(anyhow!("generate: expected SPEC and --out DIR"));
    };
    let mut spec = generate::read_spec(spec_path)?;
    if let Some(seed) = args.seed {
        spec.seed = seed;
    }
    if let Some(count) = args.count {
        spec.count = count;
        spec.check().map_err(|e| anyhow!("--count: {}", e.expected))?;
    }
    let shard = Shard::from_environment(args.shard.as_deref(), args.shards, |k| std::env::var(k).ok())
        .map_err(anyhow::Error::msg)?;
    let mut library = AssetLibrary::default();
    if args.dry_run {
        for k in shard.pictures(spec.count) {
            let (scene, backdrop) = scene_of(&spec, &mut library, k as u64).map_err(anyhow::Error::msg)?;
            let text = crate::formats::scene::scene_to_string(&scene)?;
            let behind = backdrop.map_or(String::new(), |b| format!(" over {}", b.display()));
            println!("// picture {k}{behind}\n{text}");
        }
        return Ok(None);
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let tars = (args.format == SetFormat::Webdataset).then(|| TarSet {
        dir: dir.clone(),
        shard,
        size: args.shard_size as usize,
        count: spec.count,
    });
    let mut done = generate::finished_pictures(dir);
    if let Some(tars) = &tars {
        // A run stopped between a tar's last picture and the tar finishes it now.
        tars.pack_finished(&done).map_err(anyhow::Error::msg)?;
        done.extend(tars.packed());
    }
    let mut pictures = Vec::new();
    let mut finished = 0;
    for k in shard.pictures(spec.count) {
        if done.contains(&k) {
            finished += 1;
            continue;
        }
        let (scene, backdrop) = scene_of(&spec, &mut library, k as u64).map_err(anyhow::Error::msg)?;
        let file = scene_file(dir, k);
        write_scene(&file, &scene)?;
        // As the editor will read it: the picture is what its scene file shows.
        let scene = read_scene(&file)?;
        for c in &scene.characters {
            library.load(&c.source)?;
        }
        pictures.push((k, scene, backdrop));
    }
    Ok(Some(Plan { dir: dir.clone(), spec, shard, pictures, finished, library, tars }))
}

/// `generate`: the plan's pictures rendered in one app, each recorded in the shard's
/// manifest as its files are written (and with `--format webdataset` packed into its tar
/// once the tar's pictures are all there), a progress bar with pictures a second and the
/// time left.
pub fn run(args: &GenerateArgs) -> Result<()> {
    use crate::editor::present::data::Beside;
    use crate::editor::present::render::{ScenePicture, render_scenes};
    let Some(mut plan) = plan(args)? else { return Ok(()) };
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
    let mut numbers: Vec<usize> = plan.pictures.iter().map(|p| p.0).collect();
    let mut pictures: Vec<ScenePicture> = std::mem::take(&mut plan.pictures)
        .into_iter()
        .map(|(k, scene, backdrop)| ScenePicture { scene, out: plan.out(k), ids: generate::coco_ids(k), backdrop })
        .collect();
    let opening = crate::document::drawing::opening_picture(&pictures.iter().map(|p| &p.scene).collect::<Vec<_>>());
    pictures.swap(0, opening);
    numbers.swap(0, opening);
    let first_scene = plan.scene_file(numbers[0]);
    let library = std::mem::take(&mut plan.library);
    let picture = plan.picture();
    let beside = Beside::of_spec(&plan.spec);
    let bar = indicatif::ProgressBar::new(todo as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} pictures, {per_sec}, {elapsed} (left {eta})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let recorder = bar.clone();
    let mut finished = generate::finished_pictures(&plan.dir);
    let on_written = Box::new(move |index: usize| {
        plan.record(numbers[index])?;
        if let Some(tars) = &plan.tars {
            finished.insert(numbers[index]);
            tars.pack_tar_of(numbers[index], &finished).map_err(|e| e.to_string())?;
        }
        recorder.inc(1);
        Ok(())
    });
    let notes = render_scenes(
        first_scene,
        library,
        pictures,
        args.scenes_a_frame.map(usize::from),
        picture,
        beside,
        on_written,
    )
    .map_err(anyhow::Error::msg)?;
    bar.finish();
    for n in notes {
        eprintln!("note: {n}");
    }
    println!("wrote {todo} pictures in {:.2} s", started.elapsed().as_secs_f64());
    Ok(())
}

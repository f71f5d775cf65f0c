//! The `marionette` command line: thin glue over the library.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use std::io::Write;

use glam::Mat4;
use marionette::formats::gltf::{GltfCharacter, GltfMesh, write_glb};

use marionette::document::posing::{
    IkSpec, PoseSpec, apply_ik_specs, apply_pose_specs, describe, describe_ik, posed_positions_by,
};
use marionette::formats::{load_character, obj};

/// The largest picture side `render` accepts (the texture limit of common GPUs).
const MAX_PICTURE_SIDE: i64 = 8192;

#[derive(Parser)]
#[command(name = "marionette", version, about = "Build scenes of skinned characters: load, pose, see and export them.")]
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
        #[command(flatten)]
        clip: ClipArgs,
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
        /// `JOINT=x,y,z`: move JOINT to this world-space point by inverse kinematics
        /// (FABRIK), after --pose. Repeatable.
        #[arg(long = "ik", value_name = "JOINT=x,y,z")]
        ik: Vec<IkSpec>,
        /// Linear blend (`lbs`) or dual quaternion (`dq`) skinning.
        #[arg(long, value_enum, default_value_t = Skinning::Lbs)]
        skinning: Skinning,
        #[command(flatten)]
        clip: ClipArgs,
        /// With `--out X.glb`: the posed mesh without a skin, instead of a skinned mesh
        /// with its skeleton.
        #[arg(long)]
        bake: bool,
        /// With `--out X.glb`: keyframed clips (a scene's, or `--anim`) go out as glTF
        /// animations, sampled at 30 frames per second.
        #[arg(long)]
        animation: bool,
    },
    /// Bind a mesh without weights to a skeleton and write 6.837-style weights: by bone heat
    /// (weights diffused over the mesh from the bones each vertex sees), to the nearest
    /// bone, or smoothly to the nearest few.
    Bind {
        /// The mesh (.obj or .off).
        mesh: PathBuf,
        /// The skeleton (.skel of either course, or a Homer rig .json).
        skeleton: PathBuf,
        #[arg(long)]
        out: PathBuf,
        #[arg(long, value_enum, default_value_t = BindMethod::Heat)]
        method: BindMethod,
        /// The same as `--method smooth` (kept for older scripts).
        #[arg(long, conflicts_with = "method")]
        smooth: bool,
        /// Weights to compare with (a 6.837 `.attach` for the same mesh and skeleton):
        /// prints how often the heaviest joint agrees and the mean L1 distance of the rows.
        #[arg(long, value_name = "F.attach")]
        against: Option<PathBuf>,
    },
    /// Render a scene (.ron) or characters offscreen to a PNG, without a window.
    Render {
        /// A scene file or character files; none renders the default scene.
        paths: Vec<PathBuf>,
        #[arg(long)]
        out: PathBuf,
        #[arg(long, default_value_t = 1280, value_parser = clap::value_parser!(u32).range(1..=MAX_PICTURE_SIDE))]
        width: u32,
        #[arg(long, default_value_t = 720, value_parser = clap::value_parser!(u32).range(1..=MAX_PICTURE_SIDE))]
        height: u32,
        /// `JOINT=rx,ry,rz` applied to every character that has the joint. Repeatable.
        #[arg(long = "pose", value_name = "JOINT=rx,ry,rz")]
        poses: Vec<PoseSpec>,
        /// `JOINT=x,y,z` world-space IK target for every character that has the joint.
        #[arg(long = "ik", value_name = "JOINT=x,y,z")]
        ik: Vec<IkSpec>,
        /// Skin every character by linear blend (`lbs`) or dual quaternion (`dq`) skinning
        /// (default: as the scene file says).
        #[arg(long, value_enum)]
        skinning: Option<Skinning>,
        /// Scale every character to the first one's height (as they stand, feet on the
        /// floor); characters named on the command line then stand side by side.
        #[arg(long)]
        match_height: bool,
        #[command(flatten)]
        clip: ClipArgs,
    },
    /// The SMPL exercise: writes frame000.obj, frame001.obj, ... into --out.
    ///
    /// Tasks: 1 the shapes β0, β1, β2 (unskinned); 2 L_Elbow moved +0.2 in y, absolute
    /// (descendants stay); 3 the same, relative (descendants follow); 4 L_Shoulder rotated
    /// by (0, 0, -0.3827, 0.9239); 5 clip 7516 for β0, β1, β2 (480 frames).
    ///
    /// --sequence SPEC plays segments one after another: SPEC is CLIP[:FROM-TO][:BETA]
    /// joined by commas. CLIP is a clip file or the end of its name (7516); FROM-TO an
    /// inclusive frame range (40- runs to the end); BETA is 0, 1, 2 (the exercise's βs) or
    /// ten numbers joined by /. Consecutive segments overlap by --transition frames with
    /// α from 0 (first transition frame) to 1 (N-th); β blends linearly, rotations by
    /// normalised linear interpolation (or --slerp).
    /// Example: --sequence 7516:0-99:1,8806:20-:2 --transition 30
    #[command(verbatim_doc_comment)]
    Smpl {
        /// The folder with smpl_00.obj ... smpl_skin.txt and the clips.
        #[arg(long)]
        data: PathBuf,
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=5), conflicts_with = "sequence", required_unless_present = "sequence")]
        task: Option<u32>,
        #[arg(long, value_name = "SPEC")]
        sequence: Option<String>,
        #[arg(long, default_value_t = 20)]
        transition: usize,
        #[arg(long)]
        slerp: bool,
        #[arg(long)]
        out: PathBuf,
        /// Use the straightforward single-threaded writer (for timing against it).
        #[arg(long)]
        naive: bool,
    },
    /// A crowd of animated characters headless through the app and the render world:
    /// frame time (p50/p95) by phase, mesh data handed on, and the skinning kernel's speed.
    Bench {
        /// How many characters (SMPL bodies from the data folder, else puppets).
        #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=4096))]
        characters: u32,
        /// Frames measured (after warming up).
        #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u32).range(1..=100_000))]
        frames: u32,
        /// The course data folder (its `smpl`); defaults to MARIONETTE_DATA.
        #[arg(long)]
        data: Option<PathBuf>,
        /// Print one JSON object instead of the table.
        #[arg(long)]
        json: bool,
        /// Skin the crowd with the GPU skinning compute shader instead of on the CPU.
        #[arg(long)]
        gpu: bool,
    },
    /// Rebuild the project's own characters into a folder (normally `assets`).
    GenAssets {
        #[arg(default_value = "assets")]
        dir: PathBuf,
    },
}

/// `--skinning`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum Skinning {
    /// Linear blend skinning.
    Lbs,
    /// Dual quaternion skinning.
    Dq,
}

impl From<Skinning> for marionette::rig::dqs::SkinningMethod {
    fn from(s: Skinning) -> Self {
        match s {
            Skinning::Lbs => Self::Linear,
            Skinning::Dq => Self::DualQuaternion,
        }
    }
}

/// How `bind` computes weights.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum BindMethod {
    /// Bone heat (Baran and Popović 2007).
    Heat,
    /// Each vertex rigidly to its nearest bone.
    Nearest,
    /// The nearest few bones, falling off with distance.
    Smooth,
}

impl From<BindMethod> for marionette::rig::bind::Binding {
    fn from(m: BindMethod) -> Self {
        match m {
            BindMethod::Heat => Self::Heat,
            BindMethod::Nearest => Self::Nearest,
            BindMethod::Smooth => Self::Smooth,
        }
    }
}

/// `--anim FILE --time T`: pose characters from a keyframed clip.
#[derive(clap::Args, Debug, Clone)]
struct ClipArgs {
    /// A CSE169 `.anim` clip (channels 0-2 move the root, then x, y, z rotation per joint
    /// in the skeleton's order) or a `.bvh` (its joints by name), on every character whose
    /// skeleton it fits.
    #[arg(long, value_name = "FILE.anim|FILE.bvh")]
    anim: Option<PathBuf>,
    /// The time in seconds at which clips are sampled: `--anim`'s, `--clip`'s, and a
    /// scene's own keyframes, SMPL and glTF clips (extrapolated outside their keys as each
    /// clip says).
    #[arg(long, value_parser = finite_seconds)]
    time: Option<f32>,
    /// A glTF file's animation, by name or by index among the file's animations, on every
    /// character of the file it moves (without it the file's node transforms are the pose).
    #[arg(long, value_name = "NAME|INDEX")]
    clip: Option<String>,
}

impl ClipArgs {
    fn anim_doc(&self, playing: bool) -> Option<marionette::formats::scene::AnimDoc> {
        let file = self.anim.clone()?;
        Some(marionette::formats::scene::AnimDoc {
            time: self.time.unwrap_or(0.0),
            playing,
            ..marionette::formats::scene::AnimDoc::of(file)
        })
    }
}

fn is_gltf(path: &std::path::Path) -> bool {
    marionette::formats::gltf_import::is_gltf(path)
}

/// `export FILE.glb|FILE.gltf`: every character of the file, posed by `--clip` at `--time`
/// (or the file's node transforms) and `--pose`, as one OBJ of all their vertices in file
/// order, or as a glb scene.
fn export_gltf_file(
    path: &std::path::Path,
    out: &std::path::Path,
    poses: &[PoseSpec],
    method: marionette::rig::dqs::SkinningMethod,
    clip: &ClipArgs,
    bake: bool,
    animation: bool,
) -> Result<()> {
    let time = clip.time.unwrap_or(0.0);
    if is_glb(out) {
        let mut library = marionette::document::AssetLibrary::default();
        let mut doc = marionette::formats::scene::SceneDoc::default();
        for source in library.sources_of(path) {
            let asset = library.load(&source)?;
            let mut c = library.new_character_doc(source.clone(), &asset);
            let part = library.gltf_source(&source);
            let found = clip
                .clip
                .as_deref()
                .and_then(|spec| marionette::document::posing::find_clip(&part?.clips, spec).cloned());
            c.playback = found.map(|k| marionette::formats::scene::PlaybackDoc {
                clip: Some(k.name),
                time,
                ..Default::default()
            });
            doc.characters.push(c);
        }
        let mesh = if bake { GltfMesh::Baked } else { GltfMesh::Skinned };
        let glb = marionette::document::export::scene_glb(&doc, mesh, animation)?;
        write_file(out, |w| w.write_all(&glb))?;
        println!("wrote {} ({} characters)", out.display(), doc.characters.len());
        return Ok(());
    }
    let characters = marionette::formats::gltf_import::load_gltf(path)?;
    characters.iter().flat_map(|c| &c.asset.warnings).for_each(|w| eprintln!("warning: {w}"));
    let (positions, triangles) =
        marionette::document::posing::posed_gltf(&characters, clip.clip.as_deref(), time, poses, method)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    write_file(out, |w| obj::write_obj(w, &positions, &triangles))?;
    println!(
        "wrote {} ({} characters, {} vertices, {} triangles)",
        out.display(),
        characters.len(),
        positions.len(),
        triangles.len()
    );
    Ok(())
}

fn is_glb(path: &std::path::Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb"))
}

fn is_scene(path: &std::path::Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ron"))
}

/// A finite number of seconds.
fn finite_seconds(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(t) if t.is_finite() => Ok(t),
        _ => Err(format!("expected a finite number of seconds, found `{text}`")),
    }
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
        None => marionette::editor::run(Vec::new(), Default::default()),
        Some(Command::Edit { paths, clip }) => {
            let edits = marionette::editor::StartupEdits {
                anim: clip.anim_doc(true),
                time: clip.time,
                clip: clip.clip.clone(),
                ..Default::default()
            };
            marionette::editor::run(paths, edits)
        }
        Some(Command::Info { path }) if is_gltf(&path) => {
            for c in marionette::formats::gltf_import::load_gltf(&path)? {
                print!("{}", describe(&c.asset));
                for clip in &c.clips {
                    println!("animation {} `{}`: {:.3} s", clip.index, clip.name, clip.duration());
                }
            }
        }
        Some(Command::Info { path }) => print!("{}", describe(&load_character(&path)?)),
        Some(Command::Export { path, out, poses, skinning, clip, bake, animation, .. }) if is_gltf(&path) => {
            export_gltf_file(&path, &out, &poses, skinning.into(), &clip, bake, animation)?
        }
        Some(Command::Export { path, out, bake, animation, .. }) if is_glb(&out) && is_scene(&path) => {
            let doc = marionette::document::scenes::read_scene(&path)?;
            let mesh = if bake { GltfMesh::Baked } else { GltfMesh::Skinned };
            let glb = marionette::document::export::scene_glb(&doc, mesh, animation)?;
            write_file(&out, |w| w.write_all(&glb))?;
            println!("wrote {} ({} characters)", out.display(), doc.characters.len());
        }
        Some(Command::Export { path, out, poses, ik, skinning, clip, bake, animation }) => {
            let asset = load_character(&path)?;
            for w in &asset.warnings {
                eprintln!("warning: {w}");
            }
            let mut pose = asset.skeleton.initial_pose();
            let mut origin = Mat4::IDENTITY;
            let mut motion = None;
            if let Some(file) = &clip.anim {
                let anim = marionette::formats::load_clip(file)?.retargeted(&asset.skeleton, &Default::default());
                if animation {
                    let sampled = marionette::document::export::sampled(&anim, &asset.skeleton, &pose);
                    motion = Some(sampled.map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?);
                }
                let (root, clip_pose) = anim.pose_at(&asset.skeleton, clip.time.unwrap_or(0.0), &pose);
                pose = clip_pose;
                let root_offset = asset.skeleton.joint(0).rest_offset;
                origin = marionette::scene::keyframes::RootTranslation(Some(root)).origin(root_offset);
            }
            apply_pose_specs(&asset.skeleton, &mut pose, &poses)?;
            for report in apply_ik_specs(&asset.skeleton, &mut pose, origin, &ik)? {
                eprintln!("{}", describe_ik(&asset.skeleton, &report));
            }
            if is_glb(&out) {
                let name = asset.name.clone();
                let root = origin.transform_point3(asset.skeleton.joint(0).rest_offset);
                let character = GltfCharacter { root, motion, ..GltfCharacter::new(&name, &asset, &pose) };
                let glb = write_glb(&[character], if bake { GltfMesh::Baked } else { GltfMesh::Skinned })
                    .map_err(|e| anyhow::anyhow!("{}: {e}", out.display()))?;
                write_file(&out, |w| w.write_all(&glb))?;
                println!(
                    "wrote {} ({} joints, {} vertices)",
                    out.display(),
                    asset.skeleton.len(),
                    asset.vertex_count()
                );
                return Ok(());
            }
            let positions = posed_positions_by(&asset, &pose, origin, skinning.into());
            write_file(&out, |w| obj::write_obj(w, &positions, &asset.skin.triangles))?;
            println!("wrote {} ({} vertices, {} triangles)", out.display(), positions.len(), asset.triangle_count());
        }
        Some(Command::Render { paths, out, width, height, poses, ik, skinning, match_height, clip }) => {
            let started = std::time::Instant::now();
            let edits = marionette::editor::StartupEdits {
                poses,
                ik,
                skinning: skinning.map(Into::into),
                match_height,
                anim: clip.anim_doc(false),
                time: clip.time,
                clip: clip.clip.clone(),
            };
            let notes = marionette::editor::render::render(paths, edits, out.clone(), width, height)
                .map_err(anyhow::Error::msg)?;
            for n in notes {
                eprintln!("note: {n}");
            }
            println!("wrote {} ({width}x{height}) in {:.2} s", out.display(), started.elapsed().as_secs_f64());
        }
        Some(Command::Bind { mesh, skeleton, out, method, smooth, against }) => {
            let method = if smooth { BindMethod::Smooth } else { method };
            bind(&mesh, &skeleton, &out, method.into(), against.as_deref())?
        }
        Some(Command::Smpl { data, task, sequence, transition, slerp, out, naive }) => {
            smpl(&data, task, sequence, transition, slerp, &out, naive)?
        }
        Some(Command::Bench { characters, frames, data, json, gpu }) => {
            use marionette::editor::bench;
            let data = bench::data_folder(data);
            let report =
                bench::run(characters as usize, frames as usize, data.as_deref(), gpu).map_err(anyhow::Error::msg)?;
            if json {
                println!("{}", serde_json::to_string(&report)?);
            } else {
                println!("{}", bench::table(&report));
            }
        }
        Some(Command::GenAssets { dir }) => {
            marionette::formats::puppet::write_6837(&marionette::formats::puppet::puppet(), &dir, "puppet")
                .with_context(|| format!("writing {}", dir.display()))?;
            let scene = dir.join("default_scene.ron");
            marionette::formats::scene::save_scene(&scene, &marionette::document::default_scene::generate())?;
            let crowd = dir.join("crowd_scene.ron");
            marionette::formats::scene::save_scene(&crowd, &marionette::document::crowd::shipped_crowd())?;
            println!("wrote {}/puppet.{{skel,obj,attach}}, {} and {}", dir.display(), scene.display(), crowd.display());
        }
    }
    Ok(())
}

fn bind(
    mesh_path: &std::path::Path,
    skeleton_path: &std::path::Path,
    out: &std::path::Path,
    binding: marionette::rig::bind::Binding,
    against: Option<&std::path::Path>,
) -> Result<()> {
    use marionette::formats::{error::open, mit6837, off};
    use marionette::rig::bind::bind_to_skeleton;
    let mesh = match mesh_path.extension().and_then(|e| e.to_str()) {
        Some("off") => off::parse_off(open(mesh_path)?, mesh_path)?,
        _ => obj::parse_obj(open(mesh_path)?, mesh_path)?,
    };
    let skeleton = marionette::formats::character::load_skeleton(skeleton_path)?;
    let started = std::time::Instant::now();
    let weights = bind_to_skeleton(&skeleton, &mesh.positions, &mesh.triangles, binding)
        .map_err(|e| anyhow::anyhow!("{}: {e}", mesh_path.display()))?;
    let seconds = started.elapsed().as_secs_f64();
    write_file(out, |w| mit6837::write_attach(w, &weights, skeleton.len()))?;
    println!(
        "wrote {} ({} vertices, {} joints, {binding:?} binding in {seconds:.3} s)",
        out.display(),
        mesh.positions.len(),
        skeleton.len()
    );
    if let Some(reference) = against {
        let (theirs, _) = mit6837::parse_attach(open(reference)?, reference, skeleton.len(), mesh.positions.len())?;
        let (agree, l1) = marionette::rig::skinning::agreement(&weights, &theirs);
        println!(
            "against {}: heaviest joint agrees on {:.1} % of the vertices; mean L1 {l1:.3}",
            reference.display(),
            100.0 * agree
        );
    }
    Ok(())
}

fn smpl(
    data: &std::path::Path,
    task: Option<u32>,
    sequence: Option<String>,
    transition: usize,
    slerp: bool,
    out: &std::path::Path,
    naive: bool,
) -> Result<()> {
    use marionette::cli::smpl_tasks::{parse_sequence, sequence_frames, task_frames, write_frames, write_frames_naive};
    use marionette::rig::smpl::BlendMode;
    let started = std::time::Instant::now();
    let (model, warnings) = marionette::formats::smpl::load_smpl_dir(data)?;
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

/// Writes a whole file or nothing: into a temporary sibling, then renamed over `path`.
fn write_file(
    path: &std::path::Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> Result<()> {
    marionette::formats::error::refuse_overwriting_input(path)?;
    marionette::formats::write_atomically(path, write).with_context(|| format!("writing {}", path.display()))
}

//! One way through the commands: for every kind of input (a character file, a scene, a
//! glTF file of two characters, an FBX file, a BVH) and every posing option, `render` (whose
//! posing is the ECS's, on the scene `startup_scene` makes) and `export` pose the same, or
//! both fail with the same words on an option that names what no character has.

use std::path::{Path, PathBuf};

use bevy::prelude::*;
use glam::Vec3;
use marionette::editor::StartupEdits;
use marionette::editor::scene_doc::document::{PendingScene, SceneCharacter};
use marionette::scene::{Placement, SkinScratch};

/// A command line's posing options as `render` and `export` both take them.
struct Options(&'static [&'static str]);

impl Options {
    /// `render`'s startup options for these words (parsed as `edit` parses them).
    fn startup(&self, paths: &[PathBuf]) -> StartupEdits {
        use marionette::cli::args::{Cli, Command, RenderArgs};
        let mut args: Vec<String> = vec!["marionette".into(), "render".into()];
        args.extend(paths.iter().map(|p| p.display().to_string()));
        args.extend(["--out".into(), "unused.png".into()]);
        args.extend(self.0.iter().map(|s| s.to_string()));
        let cli = <Cli as clap::Parser>::try_parse_from(&args).unwrap();
        let Some(Command::Render(RenderArgs { pose, skinning, clip, .. })) = cli.command else { unreachable!() };
        StartupEdits {
            pose: pose.specs(None),
            skinning: skinning.map(Into::into),
            anim: clip.anim_doc(false),
            time: clip.time,
            clip: clip.own_clip(),
            still: true,
            ..StartupEdits::default()
        }
    }
}

/// `render`'s figures: the scene it opens, posed by the ECS, every vertex in the world in
/// document order; or why it refuses.
fn rendered(path: &Path, options: &Options) -> Result<Vec<Vec3>, String> {
    let paths = vec![path.to_path_buf()];
    let edits = options.startup(&paths);
    let mut library = marionette::document::AssetLibrary::default();
    let doc = marionette::editor::present::view::startup_scene(&paths, &edits, &mut library, &mut Vec::new())?
        .expect("a scene");
    let mut app = crate::edits::scene_app();
    *app.world_mut().resource_mut::<PendingScene>() = PendingScene { doc: Some(doc), frame: false };
    for _ in 0..4 {
        app.update();
    }
    let world = app.world_mut();
    let mut characters: Vec<(u64, Vec<Vec3>)> = world
        .query::<(&SceneCharacter, &Placement, &SkinScratch)>()
        .iter(world)
        .map(|(c, placement, skin)| {
            let m = placement.0.to_mat4();
            (c.id.0, skin.positions.iter().map(|p| m.transform_point3(*p)).collect())
        })
        .collect();
    characters.sort_by_key(|c| c.0);
    Ok(characters.into_iter().flat_map(|c| c.1).collect())
}

/// `export`'s figures (an OBJ of every character), or why it refuses.
fn exported(path: &Path, options: &Options, out: &Path) -> Result<Vec<Vec3>, String> {
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_marionette"))
        .arg("export")
        .arg(path)
        .arg("--out")
        .arg(out)
        .args(options.0)
        .output()
        .unwrap();
    if !output.status.success() {
        let said = String::from_utf8_lossy(&output.stderr);
        return Err(said.trim().trim_start_matches("marionette: ").to_string());
    }
    let obj = marionette::formats::obj::parse_obj(marionette::formats::error::open(out).unwrap(), out).unwrap();
    Ok(obj.positions)
}

/// The shape of a set of points, wherever it stands: each less their mean.
fn centred(points: &[Vec3]) -> Vec<Vec3> {
    let mean = points.iter().copied().sum::<Vec3>() / points.len().max(1) as f32;
    points.iter().map(|p| *p - mean).collect()
}

#[test]
fn render_and_export_pose_every_input_alike_under_every_option() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = crate::common::scratch("commands-table");
    let puppet = root.join("assets/puppet.skel");
    let scene = dir.join("scene.ron");
    let doc = crate::editor::doc_with(marionette::formats::scene::SourceDoc::File(puppet.clone()), &[]);
    marionette::document::scenes::write_scene(&scene, &doc).unwrap();
    let data = root.join("tests/data");
    let inputs =
        [puppet.clone(), scene, data.join("blender_pair.glb"), data.join("one_key.fbx"), data.join("steps.bvh")];
    let bvh = data.join("steps.bvh");
    let bvh = bvh.to_str().unwrap();
    // A humanoid walk (CMU names, centimetres) whose motion retargets onto the puppet.
    let walk = data.join("rigs/cmu_walk.bvh");
    let walk = walk.to_str().unwrap();
    let options: Vec<Vec<String>> = vec![
        vec![],
        vec!["--pose".into(), "1=0.3,-0.2,0.4".into()],
        vec!["--ik".into(), "2=0.3,1.0,0.2".into()],
        vec!["--skinning".into(), "dq".into(), "--pose".into(), "2=0.2,0.5,0.1".into()],
        vec!["--clip".into(), "0".into(), "--time".into(), "0.4".into()],
        vec!["--clip".into(), "0".into(), "--time".into(), "0.6".into(), "--pose".into(), "1=0,0.4,0".into()],
        vec!["--anim".into(), bvh.into(), "--time".into(), "0.3".into()],
        vec!["--retarget".into(), bvh.into(), "--time".into(), "0.3".into()],
        vec!["--retarget".into(), walk.into(), "--time".into(), "0.5".into()],
        vec![
            "--retarget".into(),
            walk.into(),
            "--time".into(),
            "0.5".into(),
            "--ik".into(),
            "l_wrist=0.3,1.0,0.3".into(),
        ],
        vec!["--pose".into(), "no_such_joint=0,0,0".into()],
        vec!["--clip".into(), "no_such_clip".into()],
    ];
    let mut table = Vec::new();
    for input in &inputs {
        for (k, words) in options.iter().enumerate() {
            let words: &'static [&'static str] =
                Box::leak(words.iter().map(|w| &*Box::leak(w.clone().into_boxed_str())).collect::<Vec<_>>().into());
            let options = Options(words);
            let out = dir.join(format!("out{k}.obj"));
            let name = format!("{} {}", input.file_name().unwrap().to_string_lossy(), words.join(" "));
            match (rendered(input, &options), exported(input, &options, &out)) {
                (Ok(a), Ok(b)) => {
                    assert_eq!(a.len(), b.len(), "{name}: vertex counts");
                    let (a, b) = (centred(&a), centred(&b));
                    let size = a.iter().map(|p| p.length()).fold(0.0, f32::max);
                    let worst = a.iter().zip(&b).map(|(p, q)| p.distance(*q)).fold(0.0, f32::max) / size;
                    assert!(worst < 1e-4, "{name}: render and export differ by {worst:e} of the size");
                    table.push(format!("{name}: same within {worst:.1e}"));
                }
                (Err(a), Err(b)) => {
                    assert_eq!(a, b, "{name}: they refuse in different words");
                    table.push(format!("{name}: both refuse: {a}"));
                }
                (a, b) => panic!("{name}: render {:?} but export {:?}", a.map(|_| "posed"), b.map(|_| "posed")),
            }
        }
    }
    println!("{}", table.join("\n"));
    // The missing joint and clip are refused for every input; the walk retargets onto the
    // puppet, in its file and in the scene, with and without IK after it.
    assert_eq!(table.iter().filter(|l| l.contains("both refuse") && l.contains("no_such")).count(), 2 * inputs.len());
    let carried = |l: &&String| l.contains("cmu_walk") && l.contains("same within");
    assert!(table.iter().filter(carried).count() >= 4, "{table:#?}");
}

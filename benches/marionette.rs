//! Benchmarks: the skinning kernels (LBS and dual quaternions, on an SMPL body and on the
//! benchmarked asset); one frame of the ECS systems for 1 and 16 characters
//! (one joint changed per character per frame, so every character re-skins); one of 16
//! moved or posed (with the bytes of mesh data handed on); an editing frame through the
//! editor's commands (three SMPL bodies playing, a puppet dragged by IK), with and without
//! the old per-frame document capture; FABRIK on 3-, 6- and 20-joint chains; the
//! rotation-space IK solve of the CSE169 dragon's tail; fitting one picture's keypoints.
//!
//! Run: `cargo bench --profile dev --bench marionette` (with `MARIONETTE_DATA` set, the
//! 6.837 Model1 is used; otherwise the project's puppet).

mod ozz_jobs;

use std::sync::{Arc, OnceLock};

use bevy::prelude::*;
use divan::Bencher;
use marionette::rig::fk::forward_kinematics;
use marionette::rig::simd::Simd;
use marionette::rig::skinning::{flat_shade, skin_positions};
use marionette::rig::{CharacterAsset, JointRotation};
use marionette::scene::*;

fn main() {
    // `MARIONETTE_OZZ_DUMP=FILE`: only write the SMPL body's jobs for the ozz harness.
    if let Some(path) = std::env::var_os("MARIONETTE_OZZ_DUMP") {
        let body = smpl_body();
        let palette = posed_palette(&body);
        let skin = &body.skin;
        let mut want = vec![Vec3::ZERO; skin.bind_positions.len()];
        skin_positions(&skin.bind_positions, &skin.weights, &palette, &mut want);
        let jobs = ozz_jobs::jobs(&skin.bind_positions, &skin.weights);
        ozz_jobs::dump(&jobs, &palette, &want, std::path::Path::new(&path)).expect("the jobs are written");
        return;
    }
    divan::main();
}

fn asset() -> Arc<CharacterAsset> {
    static ASSET: OnceLock<Arc<CharacterAsset>> = OnceLock::new();
    ASSET
        .get_or_init(|| {
            let asset = std::env::var_os("MARIONETTE_DATA")
                .map(|d| std::path::PathBuf::from(d).join("mit6837/Model1.skel"))
                .and_then(|p| marionette::formats::load_character(&p).ok())
                .unwrap_or_else(marionette::formats::puppet::embedded_puppet);
            eprintln!(
                "benchmarking `{}`: {} vertices, {} triangles",
                asset.name,
                asset.vertex_count(),
                asset.triangle_count()
            );
            Arc::new(asset)
        })
        .clone()
}

fn posed_palette(asset: &CharacterAsset) -> Vec<Mat4> {
    let n = asset.skeleton.len();
    let pose: Vec<JointRotation> =
        (0..n).map(|i| JointRotation::euler_xyz(0.1 * i as f32, 0.05, -0.02 * i as f32)).collect();
    marionette::rig::fk::posed_palette(&asset.skeleton, &asset.bind_world_to_joint, &pose, Mat4::IDENTITY)
}

/// The SMPL body (6,890 vertices, up to 4 influences) with a shape, when `MARIONETTE_DATA`
/// is set; otherwise the benchmarked asset.
fn smpl_body() -> Arc<CharacterAsset> {
    static BODY: OnceLock<Arc<CharacterAsset>> = OnceLock::new();
    BODY.get_or_init(|| {
        std::env::var_os("MARIONETTE_DATA")
            .map(|d| std::path::PathBuf::from(d).join("smpl"))
            .and_then(|dir| marionette::formats::smpl::load_smpl_dir(&dir).ok())
            .and_then(|(model, _)| model.asset("smpl", &[1.0, -0.5]).ok())
            .map_or_else(asset, Arc::new)
    })
    .clone()
}

type Kernel = fn(&[Vec3], &marionette::rig::SkinWeights, &[Mat4], &mut [Vec3]);

/// The skinning kernels on the SMPL body, positions only, in vertices per second:
/// `oracle` (the plain loop), `fast` (the best level this CPU runs: AVX2 + FMA in blocks of
/// eight vertices, built with AVX-512 VL where the CPU has it), `avx2` (the same without
/// AVX-512), `portable` (glam `Vec4`, vertex by vertex).
#[divan::bench(args = ["oracle", "fast", "avx2", "portable"])]
fn kernel_skin_positions(bencher: Bencher, kernel: &str) {
    use marionette::rig::lbs::skin_using;
    let body = smpl_body();
    let palette = posed_palette(&body);
    let mut out = vec![Vec3::ZERO; body.vertex_count()];
    let Some(simd) = level(kernel) else { return };
    let (bind, weights) = (&body.skin.bind_positions, &body.skin.weights);
    bencher.counter(divan::counter::ItemsCount::new(body.vertex_count())).bench_local(|| match simd {
        None => skin_positions(bind, weights, &palette, divan::black_box(&mut out)),
        Some(simd) => _ = skin_using(simd, bind, weights, &palette, divan::black_box(&mut out)),
    });
}

/// The kernel level a benchmark's argument names (`oracle`: none, the plain loop); none at
/// all (the benchmark is skipped) where this CPU does not run it.
fn level(kernel: &str) -> Option<Option<Simd>> {
    let simd = match kernel {
        "oracle" => return Some(None),
        "fast" => Simd::best(),
        "avx2" => Simd::Avx2,
        _ => Simd::Portable,
    };
    simd.is_available().then_some(Some(simd))
}

/// Unit vectors for the normals of `body` (from its centre out), for timing and tests of the
/// kernels that skin normals: their values do not change the work.
fn outward_normals(body: &CharacterAsset) -> Vec<Vec3> {
    let centre = body.skin.bind_positions.iter().sum::<Vec3>() / body.vertex_count().max(1) as f32;
    body.skin.bind_positions.iter().map(|p| (*p - centre).normalize_or(Vec3::Y)).collect()
}

/// The skinning kernels on the SMPL body, positions and normals (one blend of each vertex's
/// matrices for both), in vertices per second, the levels as in `kernel_skin_positions`.
/// Against it, what skinning the normals costs.
#[divan::bench(args = ["oracle", "fast", "avx2", "portable"])]
fn kernel_skin_positions_and_normals(bencher: Bencher, kernel: &str) {
    use marionette::rig::lbs::{Normals, skin_with_normals_using};
    let body = smpl_body();
    let palette = posed_palette(&body);
    let bind_normals = outward_normals(&body);
    let (mut out, mut normals) = (vec![Vec3::ZERO; body.vertex_count()], vec![Vec3::ZERO; body.vertex_count()]);
    let (bind, weights) = (&body.skin.bind_positions, &body.skin.weights);
    let Some(simd) = level(kernel) else { return };
    bencher.counter(divan::counter::ItemsCount::new(body.vertex_count())).bench_local(|| {
        let n = Normals { bind: &bind_normals, out: divan::black_box(&mut normals) };
        match simd {
            None => marionette::rig::skinning::skin_positions_and_normals(bind, weights, &palette, &mut out, n),
            Some(simd) => _ = skin_with_normals_using(simd, bind, weights, &palette, divan::black_box(&mut out), n),
        }
    });
}

/// Dual quaternion skinning on the SMPL body, positions only, against which the LBS kernel
/// above and ozz's LBS (the ozz harness) are the yardsticks (the issue asks for at least
/// ozz's LBS speed): `kernel` alone (the best level this CPU runs), as the LBS kernel is
/// timed with its palette made; `avx2`, the same without AVX-512; and `with_palette`, the
/// best with the palette's conversion to dual quaternions (24 joints).
#[divan::bench(args = ["kernel", "avx2", "with_palette"])]
fn kernel_skin_dual_quaternion(bencher: Bencher, part: &str) {
    use marionette::rig::dqs::{dual_quaternion_palette, skin_dq_using};
    let body = smpl_body();
    let palette = posed_palette(&body);
    let mut dq = Vec::new();
    dual_quaternion_palette(&palette, &mut dq);
    let mut out = vec![Vec3::ZERO; body.vertex_count()];
    let with_palette = part == "with_palette";
    let Some(Some(simd)) = level(if part == "avx2" { "avx2" } else { "fast" }) else { return };
    bencher.counter(divan::counter::ItemsCount::new(body.vertex_count())).bench_local(|| {
        if with_palette {
            dual_quaternion_palette(&palette, &mut dq);
        }
        skin_dq_using(simd, &body.skin.bind_positions, &body.skin.weights, &dq, divan::black_box(&mut out));
    });
}

/// Both kernels on the benchmarked asset (Model1 with the data: 13,336 vertices, up to 13
/// influences, so rows of every length and few runs of eight alike), in vertices per
/// second.
#[divan::bench(args = ["lbs", "dq"])]
fn kernels_on_the_asset(bencher: Bencher, kernel: &str) {
    use marionette::rig::dqs::{dual_quaternion_palette, skin_dq};
    let asset = asset();
    let palette = posed_palette(&asset);
    let mut dq = Vec::new();
    dual_quaternion_palette(&palette, &mut dq);
    let mut out = vec![Vec3::ZERO; asset.vertex_count()];
    let (bind, weights) = (&asset.skin.bind_positions, &asset.skin.weights);
    bencher.counter(divan::counter::ItemsCount::new(asset.vertex_count())).bench_local(|| match kernel {
        "lbs" => marionette::rig::lbs::skin(bind, weights, &palette, divan::black_box(&mut out)),
        _ => skin_dq(bind, weights, &dq, divan::black_box(&mut out)),
    });
}

/// LBS plus flat normals into unshared render buffers (what one SMPL body costs), per
/// vertex of the body.
#[divan::bench(args = ["oracle", "fast"])]
fn kernel_skin_and_flat_shade(bencher: Bencher, kernel: &str) {
    let body = smpl_body();
    let palette = posed_palette(&body);
    let mut skinned = vec![Vec3::ZERO; body.vertex_count()];
    let n = body.triangle_count() * 3;
    let (mut p, mut nrm) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
    let run: Kernel = if kernel == "oracle" { skin_positions } else { marionette::rig::lbs::skin };
    bencher.counter(divan::counter::ItemsCount::new(body.vertex_count())).bench_local(|| {
        run(&body.skin.bind_positions, &body.skin.weights, &palette, &mut skinned);
        flat_shade(&skinned, &body.skin.triangles, &mut p, divan::black_box(&mut nrm));
    });
}

/// Flat normals alone on the SMPL body, per triangle.
#[divan::bench]
fn kernel_flat_shade(bencher: Bencher) {
    let body = smpl_body();
    let palette = posed_palette(&body);
    let mut skinned = vec![Vec3::ZERO; body.vertex_count()];
    marionette::rig::lbs::skin(&body.skin.bind_positions, &body.skin.weights, &palette, &mut skinned);
    let n = body.triangle_count() * 3;
    let (mut p, mut nrm) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
    bencher
        .counter(divan::counter::ItemsCount::new(body.triangle_count()))
        .bench_local(|| flat_shade(&skinned, &body.skin.triangles, &mut p, divan::black_box(&mut nrm)));
}

/// One `App::update` where every character has one joint changed: mark, FK, skin.
/// An app with the ECS core and `n` characters of `asset` in a row.
fn crowd_app(asset: &Arc<CharacterAsset>, n: usize) -> (App, Vec<Entity>) {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, AssetPlugin::default(), bevy::mesh::MeshPlugin, RigCorePlugin, SkinningPlugin));
    let ids = spawn_row(&mut app, asset, n);
    (app, ids)
}

/// Spawns `n` characters of `asset` one unit apart along x.
fn spawn_row(app: &mut App, asset: &Arc<CharacterAsset>, n: usize) -> Vec<Entity> {
    let world = app.world_mut();
    let mut meshes = world.remove_resource::<Assets<Mesh>>().unwrap();
    let mut queue = bevy::ecs::world::CommandQueue::default();
    let ids: Vec<Entity> = {
        let mut commands = Commands::new(&mut queue, world);
        (0..n)
            .map(|i| spawn_character(&mut commands, &mut meshes, asset.clone(), Placement::at(Vec3::X * i as f32)))
            .collect()
    };
    queue.apply(world);
    world.insert_resource(meshes);
    ids
}

#[divan::bench(args = [1, 16])]
fn ecs_frame(bencher: Bencher, characters: usize) {
    let asset = asset();
    let (mut app, crowd) = crowd_app(&asset, characters);
    let joints: Vec<Entity> = crowd
        .iter()
        .map(|&c| app.world().get::<Character>(c).unwrap().joints[6.min(asset.skeleton.len() - 1)])
        .collect();
    app.update();
    let mut angle = 0.0f32;
    bencher.bench_local(|| {
        angle += 0.01;
        for &j in &joints {
            app.world_mut().get_mut::<JointPose>(j).unwrap().0 = JointRotation::euler_xyz(angle, 0.0, 0.0);
        }
        app.update();
    });
}

/// 16 characters, one of which is moved (placement) or posed (a joint) each frame: the
/// frame's cost, and (printed once) the bytes of vertex data handed to the GPU per frame.
#[divan::bench(args = ["moved", "posed"])]
fn ecs_frame_one_of_16_edited(bencher: Bencher, edit: &str) {
    let asset = asset();
    let (mut app, crowd) = crowd_app(&asset, 16);
    let first = crowd[0];
    let joint = app.world().get::<Character>(first).unwrap().joints[6.min(asset.skeleton.len() - 1)];
    app.update();
    app.update();
    let mut step = 0.0f32;
    let mut edit_once = |app: &mut App| {
        step += 0.01;
        if edit == "moved" {
            app.world_mut().get_mut::<Placement>(first).unwrap().translation.z = step;
        } else {
            app.world_mut().get_mut::<JointPose>(joint).unwrap().0 = JointRotation::euler_xyz(step, 0.0, 0.0);
        }
        app.update();
    };
    // Bytes handed to the GPU per frame (the packed vertices of re-skinned characters).
    let mut bytes = 0;
    for _ in 0..4 {
        edit_once(&mut app);
        bytes += app.world().resource::<marionette::scene::upload::HandedOn>().0;
    }
    eprintln!("ecs_frame_one_of_16_edited({edit}): {} bytes of mesh data per frame", bytes / 4);
    bencher.bench_local(|| edit_once(&mut app));
}

/// The document capture the editor ran every frame before edits became commands.
fn capture_scene_document(reader: marionette::editor::scene_doc::document::SceneReader) {
    divan::black_box(reader.capture());
}

/// An editing frame through the editor's own path: a scene of the puppet and three SMPL
/// bodies each playing its own clip with its own β (from `MARIONETTE_DATA`; without it only
/// the puppet), opened from a document; each frame the puppet's hand is dragged by IK (the
/// solve, then an pose edit applied in `Animate`), the chain runs and packs the vertices
/// handed to the GPU. `before`: the same frame plus the scene document the editor captured
/// every frame before edits became commands.
#[divan::bench(args = ["after", "before"])]
fn editing_frame_3_smpl_playing_1_puppet_dragged(bencher: Bencher, variant: &str) {
    use marionette::editor::edits::commands::EditQueue;
    use marionette::editor::edits::kinds;
    use marionette::editor::scene_doc::document::{CharacterIndex, PendingScene};
    use marionette::formats::scene::{CharacterDoc, CharacterId, SceneDoc, SmplDoc, SourceDoc};
    use marionette::rig::ik::{IkGoal, solve_ik};
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, AssetPlugin::default(), bevy::mesh::MeshPlugin, RigCorePlugin, SkinningPlugin))
        .add_plugins(marionette::editor::ScenePlugin);
    if variant == "before" {
        app.add_systems(Update, capture_scene_document);
    }
    let character = |id: u64, source: SourceDoc, x: f32, smpl: Option<SmplDoc>| CharacterDoc {
        id: Some(CharacterId(id)),
        placement: marionette::formats::scene::PlacementDoc { translation: Vec3::X * x, ..Default::default() },
        smpl,
        ..CharacterDoc::new(source, format!("c{id}"))
    };
    let mut characters = vec![character(1, SourceDoc::Embedded("puppet".into()), 0.0, None)];
    if let Some(dir) = std::env::var_os("MARIONETTE_DATA").map(|d| std::path::PathBuf::from(d).join("smpl")) {
        let clips = marionette::formats::smpl::clip_paths(&dir);
        for i in 0..3 {
            let state = SmplDoc {
                betas: vec![0.5 * i as f32; 10],
                clip: Some(clips[i % clips.len()].file_name().unwrap().to_string_lossy().into_owned()),
                playing: true,
                time: 10.0 * i as f32,
                ..SmplDoc::default()
            };
            characters.push(character(2 + i as u64, SourceDoc::File(dir.clone()), 1.0 + i as f32, Some(state)));
        }
    }
    let doc = SceneDoc { characters, ..SceneDoc::default() };
    *app.world_mut().resource_mut::<PendingScene>() = PendingScene { doc: Some(doc), frame: false };
    app.update();
    app.update();
    let puppet = app.world().resource::<CharacterIndex>().get(CharacterId(1)).expect("the puppet opened");
    let puppet = app.world().get::<Character>(puppet).unwrap().clone();
    let hand = puppet.asset.skeleton.find("l_hand").expect("the puppet has a left hand");
    let mut step = 0.0f32;
    let mut drag_once = |app: &mut App| {
        step += 0.02;
        // What the drag does each frame: solve on the live pose, push the changed joints.
        let world = app.world_mut();
        let before: Vec<JointRotation> =
            puppet.joints.iter().map(|&e| world.get::<JointPose>(e).map_or(JointRotation::IDENTITY, |p| p.0)).collect();
        let mut pose = before.clone();
        let target = Vec3::new(0.3 + 0.1 * step.sin(), 1.2, 0.2 * step.cos());
        solve_ik(&puppet.asset.skeleton, &mut pose, Mat4::IDENTITY, &[IkGoal { end: hand, target }], 1e-4, 8);
        let joints = pose.into_iter().enumerate().filter(|&(j, p)| p != before[j]).collect();
        world.resource_mut::<EditQueue>().push(kinds::Pose { character: CharacterId(1), joints });
        app.update();
    };
    let mut bytes = 0;
    for _ in 0..8 {
        drag_once(&mut app);
        bytes += app.world().resource::<marionette::scene::upload::HandedOn>().0;
    }
    eprintln!(
        "editing frame ({variant}): {} characters, {} bytes of vertex data handed to the GPU per frame",
        app.world().resource::<CharacterIndex>().len(),
        bytes / 8
    );
    bencher.bench_local(|| drag_once(&mut app));
}

/// A zig-zag chain of `n` joints (unit bones), and a reachable target off its line.
fn chain(n: usize) -> (Vec<Vec3>, Vec3) {
    let points: Vec<Vec3> = (0..n).map(|i| Vec3::new(i as f32, if i % 2 == 0 { 0.0 } else { 0.3 }, 0.0)).collect();
    let reach = (n - 1) as f32 * 0.7;
    (points, Vec3::new(reach * 0.5, reach * 0.6, reach * 0.3))
}

/// FABRIK alone on position chains of 3, 6 and 20 joints, tolerance 1e-4.
#[divan::bench(args = [3, 6, 20])]
fn ik_fabrik(bencher: Bencher, joints: usize) {
    let (points, target) = chain(joints);
    let r = marionette::rig::ik::fabrik(&points, target, 1e-4, 200);
    eprintln!(
        "fabrik {joints} joints: reached {} in {} iterations (distance {:.2e})",
        r.reached, r.iterations, r.distance
    );
    bencher.bench_local(|| marionette::rig::ik::fabrik(divan::black_box(&points), target, 1e-4, 200));
}

/// The full rotation-space solve (FABRIK ↔ FK, limits) of the CSE169 dragon's tail
/// (tail_12 up to the root: 13 joints) when `MARIONETTE_DATA` is set.
#[divan::bench]
fn ik_solve_dragon_tail(bencher: Bencher) {
    let Some(path) =
        std::env::var_os("MARIONETTE_DATA").map(|d| std::path::PathBuf::from(d).join("cse169/project1/dragon.skel"))
    else {
        return;
    };
    let asset = marionette::formats::load_character(&path).unwrap();
    let s = &asset.skeleton;
    let end = s.find("tail_12").unwrap();
    let mut world = vec![Mat4::IDENTITY; s.len()];
    forward_kinematics(s, &s.initial_pose(), Mat4::IDENTITY, &mut world);
    let target = world[end].w_axis.truncate() + Vec3::new(4.0, 3.0, 2.0);
    let goal = [marionette::rig::ik::IkGoal { end, target }];
    let mut pose = s.initial_pose();
    let r = marionette::rig::ik::solve_ik(s, &mut pose, Mat4::IDENTITY, &goal, 1e-3, 24);
    eprintln!(
        "dragon tail ({} joints): reached {} after {} rounds, {} FABRIK iterations, distance {:.4}, limited {}",
        marionette::rig::ik::chain_to_sub_base(s, end).len(),
        r[0].reached,
        r[0].rounds,
        r[0].iterations,
        r[0].distance,
        r[0].limited
    );
    bencher.bench_local(|| {
        let mut pose = s.initial_pose();
        marionette::rig::ik::solve_ik(s, &mut pose, Mat4::IDENTITY, &goal, 1e-3, 24)
    });
}

/// The passes of one SMPL body's share of the crowd's skin phase and upload, each alone,
/// in vertices per second: the kernel, the bounds of its output, packing the other
/// attributes (a colour change), and copying the positions as the render world writes them
/// into the mesh's slot.
#[divan::bench(args = ["kernel", "bounds", "pack", "copy"])]
fn skin_phase_parts(bencher: Bencher, part: &str) {
    use marionette::scene::upload::SkinAttributes;
    let body = smpl_body();
    let palette = posed_palette(&body);
    let skin = &body.skin;
    let mut positions = vec![Vec3::ZERO; skin.bind_positions.len()];
    marionette::rig::lbs::skin(&skin.bind_positions, &skin.weights, &palette, &mut positions);
    let colors = vec![[0.8, 0.7, 0.6, 1.0]; positions.len()];
    let mut attributes = SkinAttributes::default();
    let mut out = positions.clone();
    let mut slot = vec![0u8; std::mem::size_of_val(positions.as_slice())];
    bencher.counter(divan::counter::ItemsCount::new(positions.len())).bench_local(|| match part {
        "kernel" => marionette::rig::lbs::skin(&skin.bind_positions, &skin.weights, &palette, &mut out),
        "bounds" => drop(divan::black_box(marionette::rig::skinning::bounds(&positions))),
        "pack" => attributes.pack(&skin.texcoords, &colors),
        _ => slot.copy_from_slice(bytemuck::cast_slice(divan::black_box(&positions))),
    });
}

/// Where a skin needs normals (a glTF normal map bends them), on one SMPL body: the
/// positions alone, the positions with the bind normals skinned by the same blend
/// (`lbs::skin_with_normals`), and the positions with smooth normals derived from them (each
/// vertex's triangles' area-weighted normals summed, then normalised), in vertices per
/// second; and the same two ways of the dual quaternion kernel.
#[divan::bench(args = ["positions", "skinned normals", "derived normals", "DQ positions", "DQ skinned normals"])]
fn skin_normals_skinned_or_derived(bencher: Bencher, way: &str) {
    use marionette::rig::dqs::{dual_quaternion_palette, skin_dq, skin_dq_with_normals};
    use marionette::rig::lbs::{Normals, skin, skin_with_normals};
    let body = smpl_body();
    let palette = posed_palette(&body);
    let mut dq = Vec::new();
    dual_quaternion_palette(&palette, &mut dq);
    let skin_ = &body.skin;
    let n = skin_.bind_positions.len();
    let mut bind_normals = vec![Vec3::ZERO; n];
    derive_normals(&skin_.bind_positions, &skin_.triangles, &mut bind_normals);
    let (mut out, mut normals) = (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]);
    bencher.counter(divan::counter::ItemsCount::new(n)).bench_local(|| match way {
        "positions" => skin(&skin_.bind_positions, &skin_.weights, &palette, &mut out),
        "skinned normals" => {
            let normals = Normals { bind: &bind_normals, out: &mut normals };
            skin_with_normals(&skin_.bind_positions, &skin_.weights, &palette, &mut out, normals);
        }
        "DQ positions" => skin_dq(&skin_.bind_positions, &skin_.weights, &dq, &mut out),
        "DQ skinned normals" => {
            let normals = Normals { bind: &bind_normals, out: &mut normals };
            skin_dq_with_normals(&skin_.bind_positions, &skin_.weights, &dq, &mut out, normals);
        }
        _ => {
            skin(&skin_.bind_positions, &skin_.weights, &palette, &mut out);
            derive_normals(&out, &skin_.triangles, &mut normals);
        }
    });
}

/// Smooth normals from positions: each triangle's cross product (twice its area along its
/// normal) added to its corners, then each sum normalised.
fn derive_normals(positions: &[Vec3], triangles: &[[u32; 3]], out: &mut [Vec3]) {
    out.fill(Vec3::ZERO);
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        t.iter().for_each(|&i| out[i as usize] += n);
    }
    out.iter_mut().for_each(|n| *n = n.normalize_or_zero());
}

/// A crowd for the kernel alone: each body, its posed palette and room for its output.
struct Crowd {
    assets: Vec<Arc<CharacterAsset>>,
    palettes: Vec<Vec<Mat4>>,
    outs: Vec<Vec<Vec3>>,
}

/// SMPL bodies of their own β (their own bind positions and output, shared weights), or
/// puppets without `MARIONETTE_DATA`.
fn crowd_of_bodies(bodies: usize) -> Crowd {
    let model = std::env::var_os("MARIONETTE_DATA")
        .map(|d| std::path::PathBuf::from(d).join("smpl"))
        .and_then(|dir| marionette::formats::smpl::load_smpl_dir(&dir).ok());
    let assets: Vec<Arc<CharacterAsset>> = (0..bodies)
        .map(|i| match &model {
            Some((model, _)) => Arc::new(model.asset("smpl", &[0.01 * i as f32, -0.5]).expect("a body")),
            None => asset(),
        })
        .collect();
    let palettes = assets.iter().map(|a| posed_palette(a)).collect();
    let outs = assets.iter().map(|a| vec![Vec3::ZERO; a.vertex_count()]).collect();
    Crowd { assets, palettes, outs }
}

/// The LBS kernel over `bodies` SMPL bodies of their own β in turn on one core, in vertices
/// per second: against one body skinned again and again (the kernel's speed, all in cache),
/// what a crowd's memory costs the kernel alone.
#[divan::bench(args = [1, 64, 256])]
fn kernel_skin_crowd_one_core(bencher: Bencher, bodies: usize) {
    let Crowd { assets, palettes, mut outs } = crowd_of_bodies(bodies);
    let vertices = assets.iter().map(|a| a.vertex_count()).sum::<usize>();
    bencher.counter(divan::counter::ItemsCount::new(vertices)).bench_local(|| {
        for ((asset, palette), out) in assets.iter().zip(&palettes).zip(&mut outs) {
            let skin = &asset.skin;
            marionette::rig::lbs::skin(&skin.bind_positions, &skin.weights, palette, divan::black_box(out));
        }
    });
}

/// The same crowd on every core, split as the skin phase splits it (Bevy's compute task
/// pool, a few bodies a task): the kernel's speed over a crowd on this machine, memory and
/// scheduling included, without the rest of the frame. `warm`: each run right after the
/// last (the crowd's memory in the caches that hold it); `cold`: each run after 320 MB of
/// other memory was written, more than every cache here (as drawing on llvmpipe between
/// frames leaves them).
#[divan::bench(args = ["16 warm", "16 cold", "64 warm", "64 cold", "256 warm", "256 cold"], sample_size = 1, sample_count = 60)]
fn kernel_skin_crowd_all_cores(bencher: Bencher, case: &str) {
    each_body_on_all_cores(bencher, case, |asset, palette, out| {
        let skin = &asset.skin;
        marionette::rig::lbs::skin(&skin.bind_positions, &skin.weights, palette, out);
    });
}

/// The floor under [`kernel_skin_crowd_all_cores`]: each body's bind positions copied into
/// its output, split the same way. The same bytes read and written, no arithmetic: how long
/// this machine's memory alone takes to move them.
#[divan::bench(args = ["16 cold", "64 cold", "256 cold"], sample_size = 1, sample_count = 60)]
fn crowd_memory_floor_all_cores(bencher: Bencher, case: &str) {
    each_body_on_all_cores(bencher, case, |asset, _, out| out.copy_from_slice(&asset.skin.bind_positions));
}

/// Runs `body` on each body of the crowd that `case` names ("64 cold": 64 bodies, caches
/// emptied before each run) on Bevy's compute task pool, a few bodies a task.
fn each_body_on_all_cores(bencher: Bencher, case: &str, body: fn(&CharacterAsset, &[Mat4], &mut [Vec3])) {
    let (bodies, cold) = case.split_once(' ').map(|(n, c)| (n.parse::<usize>().unwrap(), c == "cold")).unwrap();
    let pool = bevy::tasks::ComputeTaskPool::get_or_init(bevy::tasks::TaskPool::new);
    let Crowd { assets, palettes, mut outs } = crowd_of_bodies(bodies);
    let vertices = assets.iter().map(|a| a.vertex_count()).sum::<usize>();
    let per_task = bodies.div_ceil(pool.thread_num().max(1) * 8);
    let mut other = if cold { vec![0u8; 320 << 20] } else { Vec::new() };
    let mut pass = 0u8;
    let evict = || {
        pass = pass.wrapping_add(1);
        other.iter_mut().step_by(64).for_each(|b| *b = pass);
    };
    bencher.counter(divan::counter::ItemsCount::new(vertices)).with_inputs(evict).bench_local_values(|()| {
        pool.scope(|scope| {
            for ((assets, palettes), outs) in
                assets.chunks(per_task).zip(palettes.chunks(per_task)).zip(outs.chunks_mut(per_task))
            {
                scope.spawn(async move {
                    for ((asset, palette), out) in assets.iter().zip(palettes).zip(outs) {
                        body(asset, palette, out);
                    }
                });
            }
        });
    });
}

/// Fitting one picture's keypoints (`--fit`): a rig family's Blender-made fixture in
/// `sit-chair`, seen from ahead and to the left at 640×480, its COCO file as `render
/// --data` writes it; the whole fit, every mode of the prior tried. The issue asks ≤ 1 s.
#[divan::bench(args = ["mixamo.glb", "rigify.glb", "vroid.glb"], sample_count = 5, sample_size = 1)]
fn fit_one_picture(bencher: Bencher, rig: &str) {
    use marionette::document::annotate::{self, Figure, Pinhole, Surface, raster::FLOOR};
    use marionette::document::options::{PoseOptions, PoseSpecs, apply_options};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs").join(rig);
    let mut library = marionette::document::AssetLibrary::default();
    let source = marionette::formats::scene::SourceDoc::File(path);
    let asset = library.load(&source).unwrap();
    let doc = library.new_character_doc(source, &asset);
    let mut scene = marionette::formats::scene::SceneDoc { characters: vec![doc], ..Default::default() };
    let specs = PoseSpecs { preset: Some("sit-chair".parse().unwrap()), ..PoseSpecs::default() };
    apply_options(&mut scene, &PoseOptions { specs, ..PoseOptions::default() }, &mut library).unwrap();
    let c = &scene.characters[0];
    let asset = library.shaped(c).unwrap();
    let map = marionette::document::retarget::humanoid_map(&asset, &c.humanoid);
    let (pose, _) = marionette::document::scenes::pose_from_doc(&asset, c);
    let placement = c.placement.to_mat4();
    let camera = marionette::formats::stage::CameraDoc {
        focus: Vec3::new(0.0, 0.7, 0.0),
        yaw: 0.5,
        pitch: -0.2,
        distance: 3.5,
        ..Default::default()
    };
    let pinhole = Pinhole::of(&camera, 640, 480).unwrap();
    let mut world = vec![Mat4::IDENTITY; asset.skeleton.len()];
    forward_kinematics(&asset.skeleton, &pose, placement, &mut world);
    let joints: Vec<Vec3> = world.iter().map(|m| m.w_axis.truncate()).collect();
    let positions = marionette::document::posing::posed_positions(&asset, &pose, placement);
    let figure = Figure::new("figure", 1, &asset, Some(&map), positions, &joints, false);
    let floor =
        [Vec3::new(-9.0, 0.0, -9.0), Vec3::new(9.0, 0.0, -9.0), Vec3::new(9.0, 0.0, 9.0), Vec3::new(-9.0, 0.0, 9.0)];
    let floor = Surface { instance: FLOOR, positions: &floor, triangles: &[[0, 2, 1], [0, 3, 2]], parts: &[] };
    let passes = annotate::rasterize(&pinhole, &[figure.surface(), floor]);
    let figures = [figure];
    let coco = annotate::coco::file(
        vec![annotate::coco::image_json(1, "picture.png", &pinhole)],
        annotate::coco::annotations(&pinhole, &passes, &figures, 1, 1),
    );
    let file = std::path::Path::new("picture.json");
    let keypoints = marionette::formats::keypoints::parse_keypoints(&coco.to_string(), file).unwrap();
    let spec = marionette::document::fit::FitSpec { file: file.into(), ..Default::default() };
    bencher.bench_local(|| marionette::document::fit::fit(&asset, &map, placement, false, &keypoints, &spec).unwrap());
}

//! Skinning benchmarks: the pure kernel, and one frame of the ECS systems for 1 and 16
//! characters (one joint changed per character per frame, so every character re-skins).
//!
//! Run: `cargo bench --profile dev --bench skinning` (with `MARIONETTE_DATA` set, the
//! 6.837 Model1 is used; otherwise the project's puppet).

use std::sync::{Arc, OnceLock};

use bevy::prelude::*;
use divan::Bencher;
use marionette::rig::fk::{forward_kinematics, skinning_palette};
use marionette::rig::skinning::{flat_shade, skin_positions};
use marionette::rig::{CharacterAsset, JointRotation};
use marionette::scene::*;

fn main() {
    divan::main();
}

fn asset() -> Arc<CharacterAsset> {
    static ASSET: OnceLock<Arc<CharacterAsset>> = OnceLock::new();
    ASSET
        .get_or_init(|| {
            let asset = std::env::var_os("MARIONETTE_DATA")
                .map(|d| std::path::PathBuf::from(d).join("mit6837/Model1.skel"))
                .and_then(|p| marionette::formats::load_character(&p).ok())
                .unwrap_or_else(marionette::puppet::embedded_puppet);
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
    let mut current = vec![Mat4::IDENTITY; n];
    forward_kinematics(&asset.skeleton, &pose, Mat4::IDENTITY, &mut current);
    let mut palette = vec![Mat4::IDENTITY; n];
    skinning_palette(&current, &asset.bind_world_to_joint, &mut palette);
    palette
}

/// LBS of every vertex (positions only).
#[divan::bench]
fn kernel_skin_positions(bencher: Bencher) {
    let asset = asset();
    let palette = posed_palette(&asset);
    let mut out = vec![Vec3::ZERO; asset.vertex_count()];
    bencher.bench_local(|| {
        skin_positions(&asset.skin.bind_positions, &asset.skin.weights, &palette, divan::black_box(&mut out))
    });
}

/// LBS plus flat normals into unshared render buffers (what one character costs).
#[divan::bench]
fn kernel_skin_and_flat_shade(bencher: Bencher) {
    let asset = asset();
    let palette = posed_palette(&asset);
    let mut skinned = vec![Vec3::ZERO; asset.vertex_count()];
    let n = asset.triangle_count() * 3;
    let (mut p, mut nrm) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
    bencher.bench_local(|| {
        skin_positions(&asset.skin.bind_positions, &asset.skin.weights, &palette, &mut skinned);
        flat_shade(&skinned, &asset.skin.triangles, &mut p, divan::black_box(&mut nrm));
    });
}

/// One `App::update` where every character has one joint changed: mark, FK, skin.
#[divan::bench(args = [1, 16])]
fn ecs_frame(bencher: Bencher, characters: usize) {
    let asset = asset();
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, AssetPlugin::default(), bevy::mesh::MeshPlugin, RigCorePlugin, SkinningPlugin));
    let joints: Vec<Entity> = {
        let world = app.world_mut();
        let mut meshes = world.remove_resource::<Assets<Mesh>>().unwrap();
        let mut queue = bevy::ecs::world::CommandQueue::default();
        let ids: Vec<Entity> = {
            let mut commands = Commands::new(&mut queue, world);
            (0..characters)
                .map(|i| spawn_character(&mut commands, &mut meshes, asset.clone(), Placement::at(Vec3::X * i as f32)))
                .collect()
        };
        queue.apply(world);
        world.insert_resource(meshes);
        ids.iter().map(|&c| world.get::<Character>(c).unwrap().joints[6.min(asset.skeleton.len() - 1)]).collect()
    };
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

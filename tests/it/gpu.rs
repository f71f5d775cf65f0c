//! GPU skinning against the CPU kernels, through the app and the render world: the compute
//! shader's output is read back from the meshes' slots of the vertex buffer (on llvmpipe
//! here: wgpu compute runs there).

use std::sync::Arc;

use bevy::prelude::*;
use bevy::render::RenderApp;
use bevy::render::pipelined_rendering::PipelinedRenderingPlugin;
use marionette::rig::dqs::SkinningMethod;
use marionette::rig::{CharacterAsset, JointRotation};
use marionette::scene::gpu_skinning::{GpuSkinJob, read_back_mesh_positions, read_back_mesh_positions_and_normals};
use marionette::scene::*;

/// Our plugins with Bevy's renderer and no window (no pipelining: a frame's GPU work is
/// submitted within its `update`).
fn render_app() -> App {
    let mut app = App::new();
    app.add_plugins(marionette::editor::windowless_plugins().disable::<PipelinedRenderingPlugin>())
        .add_plugins((RigCorePlugin, SkinningPlugin));
    app.finish();
    app.cleanup();
    app
}

fn pose_of(asset: &CharacterAsset) -> Vec<JointRotation> {
    (0..asset.skeleton.len()).map(|i| JointRotation::euler_xyz(0.3 + 0.05 * i as f32, -0.2, 0.25)).collect()
}

/// The puppet and, with the data, Model1 (up to 13 influences a vertex) and an SMPL body,
/// each posed, skinned on the GPU by linear blend and by dual quaternions: every vertex
/// within 1e-4 (relative to the model's size) of the CPU oracles. Then one goes back to the
/// CPU and uploads from there.
#[test]
fn gpu_skinning_matches_the_cpu_oracles() {
    let mut assets = vec![Arc::new(marionette::formats::puppet::embedded_puppet())];
    if let Some(data) = crate::common::optional_data_dir() {
        assets.push(Arc::new(marionette::formats::load_character(&data.join("mit6837/Model1.skel")).unwrap()));
        let (model, _) = marionette::formats::smpl::load_smpl_dir(&data.join("smpl")).unwrap();
        assets.push(Arc::new(model.asset("smpl", &[0.8, -0.4]).unwrap()));
    }
    let mut app = render_app();
    let mut characters = Vec::new();
    for asset in &assets {
        for method in [SkinningMethod::Linear, SkinningMethod::DualQuaternion] {
            let entity = spawn_posed(&mut app, asset.clone(), &pose_of(asset));
            app.world_mut().entity_mut(entity).insert((SkinOnGpu(true), CharacterSkinning(method)));
            let expected = oracle(asset, &pose_of(asset), method);
            characters.push((entity, asset.clone(), method, expected));
        }
    }
    let mut worst = Vec::new();
    for _ in 0..600 {
        app.update();
        worst = characters.iter().map(|c| largest_error(&app, c.0, &c.1, &c.3)).collect();
        if worst.iter().all(|w| w.is_some_and(|w| w <= 1e-4)) {
            break;
        }
    }
    for ((_, asset, method, _), worst) in characters.iter().zip(&worst) {
        let worst = worst.unwrap_or_else(|| panic!("{} ({method:?}) was never skinned on the GPU", asset.name));
        eprintln!("GPU skinning, {} ({method:?}): largest relative difference {worst:e}", asset.name);
        assert!(worst <= 1e-4, "{} ({method:?}): largest relative difference {worst:e}", asset.name);
    }
    // Back to the CPU: the job is withdrawn and the CPU's vertices are uploaded.
    let (entity, ..) = characters[0].clone();
    app.world_mut().entity_mut(entity).insert(SkinOnGpu(false));
    app.update();
    assert!(app.world().get::<GpuSkinJob>(entity).unwrap().0.is_none());
    let upload = app.world().get::<marionette::scene::upload::SkinUpload>(entity).unwrap();
    assert_eq!(upload.vertex_count, assets[0].vertex_count());
}

/// A skin with normals (a normal-mapped glTF skin's) hands its skinned normals on after
/// each position: the puppet given normals, posed, read back from its slot within 1e-5 of
/// the plain loop's positions and normals, also when it asks for the GPU (whose compute
/// shader writes positions only: such a skin stays on the CPU); skinned by dual
/// quaternions, its positions and normals are the portable DQ path's.
#[test]
fn a_skin_with_normals_lands_positions_and_normals_in_its_slot() {
    let mut puppet = marionette::formats::puppet::embedded_puppet();
    let skin = &mut puppet.skin;
    skin.normals =
        (0..skin.bind_positions.len()).map(|v| Vec3::new(v as f32, 1.0, -0.5 * v as f32).normalize()).collect();
    let asset = Arc::new(puppet);
    let pose = pose_of(&asset);
    let palette =
        marionette::rig::fk::posed_palette(&asset.skeleton, &asset.bind_world_to_joint, &pose, Mat4::IDENTITY);
    let (mut positions, mut normals) = (vec![Vec3::ZERO; asset.vertex_count()], vec![Vec3::ZERO; asset.vertex_count()]);
    let out = marionette::rig::skinning::Normals { bind: &asset.skin.normals, out: &mut normals };
    let skin = &asset.skin;
    marionette::rig::skinning::skin_positions_and_normals(
        &skin.bind_positions,
        &skin.weights,
        &palette,
        &mut positions,
        out,
    );
    let mut app = render_app();
    let on_cpu = spawn_posed(&mut app, asset.clone(), &pose);
    let asks_gpu = spawn_posed(&mut app, asset.clone(), &pose);
    app.world_mut().entity_mut(asks_gpu).insert(SkinOnGpu(true));
    let dq = spawn_posed(&mut app, asset.clone(), &pose);
    app.world_mut().entity_mut(dq).insert(CharacterSkinning(SkinningMethod::DualQuaternion));
    let read_back = |app: &App, entity: Entity| {
        let mesh = app.world().get::<Character>(entity)?.skins[0].mesh.id();
        read_back_mesh_positions_and_normals(app.sub_app(RenderApp).world(), mesh)
    };
    let landed = |app: &App, entity: Entity| {
        read_back(app, entity).is_some_and(|(p, n)| {
            p.len() == positions.len() && relative_error(&p, &positions) <= 1e-5 && relative_error(&n, &normals) <= 1e-5
        })
    };
    let ready = (0..600).any(|_| {
        app.update();
        landed(&app, on_cpu) && landed(&app, asks_gpu)
    });
    assert!(ready, "positions and normals reached both slots");
    assert!(app.world().get::<GpuSkinJob>(asks_gpu).unwrap().0.is_none(), "a skin with normals stays on the CPU");
    let (dq_positions, dq_normals) = read_back(&app, dq).expect("the DQ-skinned skin's slot");
    let (expected_positions, expected_normals) = dq_oracle_with_normals(&asset, &palette);
    assert!(relative_error(&dq_positions, &expected_positions) <= 1e-5);
    assert!(relative_error(&dq_normals, &expected_normals) <= 1e-5, "DQ's normals");
    assert!(relative_error(&dq_normals, &normals) > 1e-3, "DQ's normals, not LBS's");
}

/// The portable DQ path's positions and normals.
fn dq_oracle_with_normals(asset: &CharacterAsset, palette: &[Mat4]) -> (Vec<Vec3>, Vec<Vec3>) {
    let mut dq = Vec::new();
    marionette::rig::dqs::dual_quaternion_palette(palette, &mut dq);
    let (mut positions, mut normals) = (vec![Vec3::ZERO; asset.vertex_count()], vec![Vec3::ZERO; asset.vertex_count()]);
    let out = marionette::rig::skinning::Normals { bind: &asset.skin.normals, out: &mut normals };
    let simd = marionette::rig::simd::Simd::Portable;
    marionette::rig::dqs::skin_dq_with_normals_using(
        simd,
        &asset.skin.bind_positions,
        &asset.skin.weights,
        &dq,
        &mut positions,
        out,
    );
    (positions, normals)
}

/// The CPU oracles the fast kernels are checked against: the plain LBS loop, and the
/// portable DQ path.
fn oracle(asset: &CharacterAsset, pose: &[JointRotation], method: SkinningMethod) -> Vec<Vec3> {
    let palette = marionette::rig::fk::posed_palette(&asset.skeleton, &asset.bind_world_to_joint, pose, Mat4::IDENTITY);
    let skin = &asset.skin;
    let mut out = vec![Vec3::ZERO; asset.vertex_count()];
    if method.is_linear() {
        marionette::rig::skinning::skin_positions(&skin.bind_positions, &skin.weights, &palette, &mut out);
    } else {
        let mut dq = Vec::new();
        marionette::rig::dqs::dual_quaternion_palette(&palette, &mut dq);
        marionette::rig::dqs::skin_dq_using(
            marionette::rig::simd::Simd::Portable,
            &skin.bind_positions,
            &skin.weights,
            &dq,
            &mut out,
        );
    }
    out
}

fn spawn_posed(app: &mut App, asset: Arc<CharacterAsset>, pose: &[JointRotation]) -> Entity {
    let world = app.world_mut();
    let mut meshes = world.remove_resource::<Assets<Mesh>>().unwrap();
    let mut queue = bevy::ecs::world::CommandQueue::default();
    let entity = spawn_character_posed(&mut Commands::new(&mut queue, world), &mut meshes, asset, default(), pose);
    queue.apply(world);
    world.insert_resource(meshes);
    entity
}

/// The largest distance between the GPU's positions and `expected`, relative to the
/// model's size (`None` until the GPU has skinned it).
fn largest_error(app: &App, entity: Entity, asset: &CharacterAsset, expected: &[Vec3]) -> Option<f32> {
    app.world().get::<GpuSkinJob>(entity)?.0.as_ref()?;
    let mesh = app.world().get::<Character>(entity)?.skins[0].mesh.id();
    let positions = read_back_mesh_positions(app.sub_app(RenderApp).world(), mesh)?;
    assert_eq!(positions.len(), expected.len(), "{}: the mesh's slot holds its vertices", asset.name);
    Some(relative_error(&positions, expected))
}

/// The largest distance between `positions` and `expected`, relative to the model's size.
fn relative_error(positions: &[Vec3], expected: &[Vec3]) -> f32 {
    let size = expected.iter().fold(1.0f32, |m, p| m.max(p.abs().max_element()));
    positions.iter().zip(expected).map(|(p, want)| p.distance(*want) / size).fold(0.0, f32::max)
}

/// A GPU-skinned character's bounds, the hull of its joints' influence boxes moved by the
/// palette, hold every vertex linear blend skinning puts anywhere: the puppet and, with
/// the data, Model1, in twenty poses each.
#[test]
fn influence_hull_bounds_hold_every_skinned_vertex() {
    use marionette::rig::skinning::{bounds, influence_boxes, influence_hull_bounds, skin_positions};
    let mut assets = vec![marionette::formats::puppet::embedded_puppet()];
    if let Some(data) = crate::common::optional_data_dir() {
        assets.push(marionette::formats::load_character(&data.join("mit6837/Model1.skel")).unwrap());
    }
    for asset in &assets {
        let skin = &asset.skin;
        let boxes = influence_boxes(&skin.bind_positions, &skin.weights, asset.skeleton.len());
        for s in 0..20 {
            let a = 0.3 * s as f32;
            let pose: Vec<JointRotation> = (0..asset.skeleton.len())
                .map(|j| {
                    JointRotation::euler_xyz((a + j as f32).sin(), (0.7 * a).cos() * 0.8, 0.5 * (a * j as f32).sin())
                })
                .collect();
            let palette =
                marionette::rig::fk::posed_palette(&asset.skeleton, &asset.bind_world_to_joint, &pose, Mat4::IDENTITY);
            let mut skinned = vec![Vec3::ZERO; asset.vertex_count()];
            skin_positions(&skin.bind_positions, &skin.weights, &palette, &mut skinned);
            let (lo, hi) = influence_hull_bounds(&boxes, &palette);
            let (tight_lo, tight_hi) = bounds(&skinned);
            let slack = 1e-5 * (tight_hi - tight_lo).length();
            assert!(lo.cmple(tight_lo + slack).all() && hi.cmpge(tight_hi - slack).all(), "{} pose {s}", asset.name);
            // And not far from it: within the size of the model again on each side.
            assert!((hi - lo).length() <= 3.0 * (tight_hi - tight_lo).length(), "{} pose {s}", asset.name);
        }
    }
}

/// Characters skinned on the CPU land in their own meshes' slots of the vertex buffer,
/// whole: several puppets and, with the data, SMPL bodies (slots that follow one another,
/// written through one staging allocation), each posed differently, read back within 1e-5
/// (relative to the model's size) of the plain-loop oracle; then one is posed again alone
/// and only its slot changes.
#[test]
fn cpu_skinned_vertices_land_in_each_meshs_slot() {
    let puppet = Arc::new(marionette::formats::puppet::embedded_puppet());
    let mut assets = vec![puppet.clone(), puppet.clone(), puppet];
    if let Some(data) = crate::common::optional_data_dir() {
        let (model, _) = marionette::formats::smpl::load_smpl_dir(&data.join("smpl")).unwrap();
        assets.push(Arc::new(model.asset("smpl", &[0.8, -0.4]).unwrap()));
        assets.push(Arc::new(model.asset("smpl", &[-1.0, 0.5]).unwrap()));
    }
    let pose = |asset: &CharacterAsset, k: usize| -> Vec<JointRotation> {
        (0..asset.skeleton.len())
            .map(|i| JointRotation::euler_xyz(0.1 * k as f32 + 0.05 * i as f32, -0.2, 0.1))
            .collect()
    };
    let mut app = render_app();
    let entities: Vec<Entity> =
        assets.iter().enumerate().map(|(k, asset)| spawn_posed(&mut app, asset.clone(), &pose(asset, k))).collect();
    let landed = |app: &App, k: usize, pose: &[JointRotation]| -> Option<f32> {
        let mesh = app.world().get::<Character>(entities[k])?.skins[0].mesh.id();
        let positions = read_back_mesh_positions(app.sub_app(RenderApp).world(), mesh)?;
        let expected = oracle(&assets[k], pose, SkinningMethod::Linear);
        assert_eq!(positions.len(), expected.len(), "character {k}: the slot holds its vertices");
        Some(relative_error(&positions, &expected))
    };
    let all_landed = |app: &App, poses: &[Vec<JointRotation>]| {
        (0..assets.len()).all(|k| landed(app, k, &poses[k]).is_some_and(|w| w <= 1e-5))
    };
    let mut poses: Vec<Vec<JointRotation>> = assets.iter().enumerate().map(|(k, a)| pose(a, k)).collect();
    let ready = (0..600).any(|_| {
        app.update();
        all_landed(&app, &poses)
    });
    assert!(ready, "every character's vertices reached its slot");
    // One posed again alone: its slot follows, the others' stay.
    poses[1] = pose(&assets[1], 7);
    for (j, rotation) in poses[1].iter().enumerate() {
        let joint = app.world().get::<Character>(entities[1]).unwrap().joints[j];
        app.world_mut().get_mut::<JointPose>(joint).unwrap().0 = *rotation;
    }
    app.update();
    assert!(all_landed(&app, &poses), "the re-posed character's slot follows it, the others' stay");
}

/// The skins' attributes on the GPU: laid out whole when skins come (the default scene's
/// puppets), then a recolour writes only the recoloured character's surface in place.
/// Shown by spoiling another puppet's bytes in the main world's copy before the recolour:
/// had the whole buffer been sent again, the GPU would hold the spoiled bytes.
#[test]
fn a_recolour_writes_only_its_characters_attributes_on_the_gpu() {
    use marionette::editor::present::skin_material::SkinAttributeStore;
    use marionette::scene::upload::SkinAttributes;
    let mut app = App::new();
    app.add_plugins(marionette::editor::windowless_plugins().disable::<PipelinedRenderingPlugin>()).add_plugins((
        RigCorePlugin,
        SkinningPlugin,
        marionette::editor::present::view::ViewPlugin,
    ));
    app.finish();
    app.cleanup();
    // A surface's bytes in the buffer: from its mesh's first vertex, as many as its
    // attributes.
    let range_of = |app: &App, character: Entity| {
        let skin = app.world().get::<Character>(character)?.skins.first()?;
        let at = app.world().resource::<SkinAttributeStore>().first(skin.entity)? as usize * 12;
        Some(at..at + skin.vertices.len() * 12)
    };
    let packed = |app: &App, character: Entity| {
        let skin = &app.world().get::<Character>(character).unwrap().skins[0];
        let words = &app.world().get::<SkinAttributes>(character).unwrap().0;
        bytemuck::cast_slice(&words[skin.vertices.start as usize..skin.vertices.end as usize]).to_vec()
    };
    let on_gpu = |app: &App| {
        let id = app.world().resource::<SkinAttributeStore>().buffer.id();
        read_back_shader_buffer(app.sub_app(RenderApp).world(), id)
    };
    let landed = |app: &App, character: Entity| {
        let (bytes, range) = (on_gpu(app), range_of(app, character));
        bytes.zip(range).is_some_and(|(bytes, range)| bytes.get(range) == Some(&packed(app, character)[..]))
    };
    let characters = |app: &mut App| {
        let world = app.world_mut();
        world.query_filtered::<Entity, With<Character>>().iter(world).collect::<Vec<_>>()
    };
    let mut scene = Vec::new();
    let all_landed = (0..300).any(|_| {
        app.update();
        scene = characters(&mut app);
        scene.len() >= 2 && scene.iter().all(|&c| landed(&app, c))
    });
    assert!(all_landed, "the default scene's attributes on the GPU");
    let (first, second) = (scene[0], scene[1]);
    let (before, second_range) = (packed(&app, first), range_of(&app, second).unwrap());
    let id = app.world().resource::<SkinAttributeStore>().buffer.id();
    let mut buffers = app.world_mut().resource_mut::<Assets<bevy::render::storage::ShaderBuffer>>();
    buffers.get_mut_untracked(id).unwrap().data.as_mut().unwrap()[second_range.clone()].fill(0xAB);
    app.world_mut().get_mut::<CharacterView>(first).unwrap().0.weight_colors = true;
    for _ in 0..3 {
        app.update();
    }
    assert_ne!(packed(&app, first), before, "weight colours repacked the attributes");
    assert!(landed(&app, first), "the recoloured puppet's attributes reached the GPU");
    let gpu = on_gpu(&app).unwrap();
    assert!(gpu[second_range].iter().any(|&b| b != 0xAB), "the other puppet's were not sent again");
    assert!(landed(&app, second), "the other puppet's are as they were");
}

/// A `ShaderBuffer`'s bytes on the GPU (none until it is there).
fn read_back_shader_buffer(render_world: &World, id: AssetId<bevy::render::storage::ShaderBuffer>) -> Option<Vec<u8>> {
    use bevy::render::{render_asset::RenderAssets, storage::GpuShaderBuffer};
    let gpu = render_world.get_resource::<RenderAssets<GpuShaderBuffer>>()?.get(id)?;
    marionette::scene::gpu_skinning::read_back_buffer(render_world, &gpu.buffer, 0, gpu.buffer.size())
}

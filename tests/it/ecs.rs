//! ECS systems against the pure kernels (oracle tests), in an App with only our plugins.

use std::sync::Arc;

use bevy::asset::AssetEvent;
use bevy::ecs::message::Messages;
use bevy::prelude::*;
use marionette::document::posing::posed_positions;
use marionette::formats::puppet::embedded_puppet;
use marionette::rig::{CharacterAsset, JointRotation};
use marionette::scene::*;

use crate::common::data_dir;

pub fn app() -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, AssetPlugin::default(), bevy::mesh::MeshPlugin, RigCorePlugin, SkinningPlugin));
    app
}

pub fn spawn(app: &mut App, asset: Arc<CharacterAsset>, placement: Placement) -> Entity {
    let world = app.world_mut();
    let mut meshes = world.remove_resource::<Assets<Mesh>>().unwrap();
    let mut commands_queue = bevy::ecs::world::CommandQueue::default();
    let entity = {
        let mut commands = Commands::new(&mut commands_queue, world);
        spawn_character(&mut commands, &mut meshes, asset, placement)
    };
    commands_queue.apply(world);
    world.insert_resource(meshes);
    entity
}

/// The positions and colours a character hands to the GPU (its skinned positions and the
/// colours decoded from its packed attributes).
fn uploaded_vertices(app: &App, character: Entity) -> (Vec<[f32; 3]>, Vec<[f32; 4]>) {
    let attributes = app.world().get::<marionette::scene::upload::SkinAttributes>(character).unwrap();
    let positions = &app.world().get::<marionette::scene::SkinScratch>(character).unwrap().positions;
    let colors = (0..attributes.0.len()).map(|k| attributes.color(k).unwrap());
    positions.iter().map(|p| p.to_array()).zip(colors).unzip()
}

fn mesh_positions(app: &App, character: Entity) -> Vec<[f32; 3]> {
    uploaded_vertices(app, character).0
}

/// The kernel's expected render positions: the skinned vertices (the mesh shares them
/// between triangles).
fn oracle(asset: &CharacterAsset, pose: &[JointRotation], placement: &Placement) -> Vec<[f32; 3]> {
    posed_positions(asset, pose, placement.to_mat4()).iter().map(|p| p.to_array()).collect()
}

fn assert_positions_close(a: &[[f32; 3]], b: &[[f32; 3]], tol: f32) {
    assert_eq!(a.len(), b.len());
    let worst = a.iter().zip(b).map(|(x, y)| Vec3::from(*x).distance(Vec3::from(*y))).fold(0.0f32, f32::max);
    assert!(worst <= tol, "largest difference {worst}");
}

pub fn set_joint(app: &mut App, character: Entity, joint: usize, rotation: JointRotation) {
    let entity = app.world().get::<Character>(character).unwrap().joints[joint];
    app.world_mut().get_mut::<JointPose>(entity).unwrap().0 = rotation;
}

#[test]
fn spawning_builds_the_joint_hierarchy_as_entities() {
    let asset = Arc::new(embedded_puppet());
    let mut app = app();
    let character = spawn(&mut app, asset.clone(), Placement::default());
    app.update();
    let c = app.world().get::<Character>(character).unwrap().clone();
    assert_eq!(c.joints.len(), asset.skeleton.len());
    for (i, &e) in c.joints.iter().enumerate() {
        let joint = app.world().get::<Joint>(e).unwrap();
        assert_eq!(joint.index, i);
        assert_eq!(joint.character, character);
        let parent = app.world().get::<ChildOf>(e).unwrap().parent();
        let expected = asset.skeleton.parent(i).map_or(character, |p| c.joints[p]);
        assert_eq!(parent, expected);
    }
    // The ECS bind pass agrees with the pure one.
    for (i, &e) in c.joints.iter().enumerate() {
        let bind = app.world().get::<BindWorldToJoint>(e).unwrap().0;
        crate::common::assert_mat_close(bind, asset.bind_world_to_joint[i], 1e-5);
    }
}

/// The skin is written in model space; the character's `Transform` (its placement) takes
/// it to the world, where it matches the kernel skinned at that placement.
#[test]
fn posing_a_joint_reskins_the_mesh_like_the_kernel() {
    let asset = Arc::new(embedded_puppet());
    let placement = Placement::new(Vec3::new(1.0, 0.0, -2.0), 0.4, 1.5);
    let mut app = app();
    let character = spawn(&mut app, asset.clone(), placement);
    app.update();
    let model = Placement::default();
    assert_positions_close(
        &mesh_positions(&app, character),
        &oracle(&asset, &asset.skeleton.initial_pose(), &model),
        1e-5,
    );
    let elbow = asset.skeleton.find("l_elbow").unwrap();
    let rotation = JointRotation::euler_xyz(0.2, -0.9, 0.4);
    set_joint(&mut app, character, elbow, rotation);
    app.update();
    let mut pose = asset.skeleton.initial_pose();
    pose[elbow] = rotation;
    assert_positions_close(&mesh_positions(&app, character), &oracle(&asset, &pose, &model), 1e-5);
    let transform = *app.world().get::<Transform>(character).unwrap();
    let placed: Vec<[f32; 3]> =
        mesh_positions(&app, character).iter().map(|p| transform.transform_point(Vec3::from(*p)).to_array()).collect();
    assert_positions_close(&placed, &oracle(&asset, &pose, &placement), 1e-4);
}

/// The skin is drawn from its own vertices and triangles: the positions and colours handed
/// to the GPU are what the kernels give, the mesh's indices are the triangles, and it
/// carries no normals (the skin material lights each triangle with its own, from the
/// position's derivatives).
#[test]
fn mesh_triangles_and_weight_colours_match_the_kernels() {
    use marionette::rig::skinning::{joint_colors, weight_colors};
    let asset = Arc::new(embedded_puppet());
    let mut app = app();
    let character = spawn(&mut app, asset.clone(), Placement::default());
    app.world_mut().get_mut::<CharacterView>(character).unwrap().weight_colors = true;
    let knee = asset.skeleton.find("l_knee").unwrap();
    let rotation = JointRotation::euler_xyz(-1.1, 0.0, 0.2);
    set_joint(&mut app, character, knee, rotation);
    app.update();
    let mut pose = asset.skeleton.initial_pose();
    pose[knee] = rotation;
    let skinned: Vec<[f32; 3]> = posed_positions(&asset, &pose, Mat4::IDENTITY).iter().map(|p| p.to_array()).collect();
    let mut per_vertex = vec![[0.0; 3]; asset.vertex_count()];
    weight_colors(&asset.skin.weights, &joint_colors(asset.skeleton.len()), &mut per_vertex);
    let handle = app.world().get::<Character>(character).unwrap().skins[0].mesh.clone();
    let mesh = app.world().resource::<Assets<Mesh>>().get(&handle).unwrap();
    let (positions, colors) = uploaded_vertices(&app, character);
    assert_positions_close(&positions, &skinned, 1e-5);
    assert!(mesh.attribute(Mesh::ATTRIBUTE_NORMAL).is_none(), "no normals are written");
    let Some(bevy::mesh::Indices::U32(indices)) = mesh.indices() else { panic!("indices are u32") };
    assert_eq!(indices.as_slice(), asset.skin.triangles.as_flattened());
    // Colours go out in 8 bits a channel: each within half a step of the kernel's.
    for (color, [r, g, b]) in colors.iter().zip(per_vertex) {
        let off = color.iter().zip([r, g, b, 1.0]).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(off <= 0.5 / 255.0 + 1e-6, "{color:?} against {:?}", [r, g, b, 1.0]);
    }
}

/// The characters whose packed vertices changed in the last update, recorded by a system.
#[derive(Resource, Default)]
struct Uploaded(Vec<Entity>);

fn record_uploads(
    changed: Query<Entity, Changed<marionette::scene::upload::SkinUpload>>,
    mut uploaded: ResMut<Uploaded>,
) {
    uploaded.0 = changed.iter().collect();
}

/// Bytes handed to the GPU follow what changed: none for a move (the placement is the
/// character's `Transform`), the posed character's only for a pose; the mesh assets are
/// never modified (no whole-mesh extraction).
#[test]
fn moving_a_character_uploads_nothing_and_posing_one_uploads_only_its_own() {
    let asset = Arc::new(embedded_puppet());
    let mut app = app();
    app.init_resource::<Uploaded>().add_systems(Last, record_uploads);
    let a = spawn(&mut app, asset.clone(), Placement::default());
    let other = spawn(&mut app, asset.clone(), Placement::at(Vec3::X));
    app.update();
    let mut first = app.world().resource::<Uploaded>().0.clone();
    first.sort();
    let mut both = vec![a, other];
    both.sort();
    assert_eq!(first, both, "both are uploaded once");
    app.update();
    app.world_mut().resource_mut::<Messages<AssetEvent<Mesh>>>().clear();
    app.world_mut().get_mut::<Placement>(a).unwrap().translation = Vec3::new(3.0, 0.0, 1.0);
    app.update();
    assert_eq!(app.world().resource::<Uploaded>().0, Vec::<Entity>::new(), "moving re-skins nothing");
    assert_eq!(app.world().get::<Transform>(a).unwrap().translation, Vec3::new(3.0, 0.0, 1.0));
    set_joint(&mut app, a, 3, JointRotation::euler_xyz(0.5, 0.0, 0.0));
    app.update();
    assert_eq!(app.world().resource::<Uploaded>().0, vec![a], "posing a re-skins a only");
    app.update();
    let modified = app
        .world_mut()
        .resource_mut::<Messages<AssetEvent<Mesh>>>()
        .drain()
        .filter(|e| matches!(e, AssetEvent::Modified { .. }))
        .count();
    assert_eq!(modified, 0, "no mesh asset is modified");
}

/// The skin mesh's vertex buffer is its positions alone, byte for byte what the render world
/// copies into the mesh's slot (12 bytes a vertex); texture coordinates and colours are
/// packed apart, three words a vertex, as the skin's vertex shader reads them (u and v as
/// float bits, the colour as `unpack4x8unorm` takes it: red in the low byte).
#[test]
fn skin_vertex_buffer_holds_positions_and_attributes_are_packed_apart() {
    use marionette::scene::upload::{SKIN_VERTEX_BYTES, SkinAttributes};
    let triangles = [[0u32, 1, 2], [2, 1, 3]];
    let positions = [Vec3::new(0.0, 1.0, 2.0), Vec3::X, Vec3::new(-1.5, 0.25, 8.0), Vec3::splat(3.0)];
    let mut mesh = marionette::scene::spawn::empty_skin_mesh(&triangles, positions.len(), false);
    mesh.insert_attribute(Mesh::ATTRIBUTE_POSITION, positions.map(|p| p.to_array()).to_vec());
    assert_eq!(bytemuck::cast_slice::<Vec3, u8>(&positions), mesh.create_packed_vertex_buffer_data());
    assert_eq!(mesh.get_vertex_size() as usize, SKIN_VERTEX_BYTES);
    let colors = [[0.2, 0.6, 1.0, 1.0], [1.0, 0.0, 0.5, 1.0], [0.0; 4], [-0.5, 0.2, 0.6, 1.5]];
    // Each channel clamped and to the nearest of 255 steps (0.2 → 51, 0.6 → 153, 0.5 →
    // 127.5 → 128), worked out here.
    let words = [0xffff_9933u32, 0xff80_00ff, 0, 0xff99_3300];
    let mut attributes = SkinAttributes::default();
    attributes.pack(&[], &colors);
    assert_eq!(attributes.0, words.map(|w| [0, 0, w]));
    let uv = [Vec2::new(0.0, 0.5), Vec2::new(1.0, 0.25), Vec2::ZERO, Vec2::new(-2.0, 7.5)];
    attributes.pack(&uv, &colors);
    let expected: Vec<[u32; 3]> = uv.iter().zip(words).map(|(t, w)| [t.x.to_bits(), t.y.to_bits(), w]).collect();
    assert_eq!(attributes.0, expected);
    assert_eq!(attributes.color(1), Some([1.0, 0.0, 128.0 / 255.0, 1.0]));
}

/// The one buffer of every skin's attributes: surfaces laid out one after another in the
/// order given (each from its first vertex, its mesh's tag), each written from its own
/// character's vertices, nothing while they are not packed; more vertices than its room
/// grow it, to spare; fewer keep it.
#[test]
fn skins_share_one_attribute_buffer_each_surface_at_its_place() {
    use marionette::editor::present::skin_material::SkinAttributeStore;
    use marionette::scene::upload::SkinAttributes;
    let mut world = World::new();
    let (a, b) = (world.spawn_empty().id(), world.spawn_empty().id());
    let attributes = |n: usize, red: f32| {
        let mut packed = SkinAttributes::default();
        let colors: Vec<[f32; 4]> = (0..n).map(|k| [red, k as f32 / 8.0, 0.0, 1.0]).collect();
        let uv: Vec<Vec2> = (0..n).map(|k| Vec2::new(k as f32, red)).collect();
        packed.pack(&uv, &colors);
        packed
    };
    let (first, second) = (attributes(5, 1.0), attributes(4, 0.0));
    let mut store = SkinAttributeStore::default();
    assert!(store.lay_out(&[(a, 3), (b, 4)]), "no room yet: it grows");
    assert_eq!((store.first(a), store.first(b)), (Some(0), Some(3)));
    let mut buffer = store.empty_buffer();
    let room = buffer.data.as_ref().unwrap().len();
    assert!(room >= 7 * 12, "room for both: {room} bytes");
    store.write(&mut buffer, a, &SkinAttributes::default(), &(2..5));
    assert!(buffer.data.as_ref().unwrap().iter().all(|&byte| byte == 0), "not packed yet: nothing written");
    store.write(&mut buffer, a, &first, &(2..5));
    store.write(&mut buffer, b, &second, &(0..4));
    let bytes = |words: &[[u32; 3]]| bytemuck::cast_slice::<[u32; 3], u8>(words).to_vec();
    let data = buffer.data.as_ref().unwrap();
    assert_eq!(data[..36], bytes(&first.0[2..5]), "a's surface: its character's vertices 2 to 4");
    assert_eq!(data[36..84], bytes(&second.0), "b's surface after it");
    assert!(data[84..].iter().all(|&byte| byte == 0));
    assert!(!store.lay_out(&[(b, 4)]), "fewer vertices: the same room");
    assert_eq!(store.first(b), Some(0));
}

#[test]
fn only_changed_characters_are_reskinned_and_skins_are_shared() {
    let asset = Arc::new(embedded_puppet());
    let mut app = app();
    let a = spawn(&mut app, asset.clone(), Placement::default());
    let b = spawn(&mut app, asset.clone(), Placement::at(Vec3::X));
    app.update();
    assert!(Arc::ptr_eq(
        &app.world().get::<Character>(a).unwrap().asset,
        &app.world().get::<Character>(b).unwrap().asset
    ));
    let before_b = mesh_positions(&app, b);
    set_joint(&mut app, a, 3, JointRotation::euler_xyz(0.5, 0.0, 0.0));
    app.update();
    assert_eq!(app.world().get::<PoseDirty>(a).unwrap(), &PoseDirty::default());
    assert_eq!(mesh_positions(&app, b), before_b);
    assert_ne!(mesh_positions(&app, a), oracle(&asset, &asset.skeleton.initial_pose(), &Placement::default()));
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn poses_set_outside_the_limits_are_clamped() {
    let data = data_dir();
    let asset = Arc::new(marionette::formats::load_character(&data.join("cse169/project1/test.skel")).unwrap());
    let knee = asset.skeleton.find("knee_r").unwrap();
    let mut app = app();
    let character = spawn(&mut app, asset, Placement::default());
    app.update();
    set_joint(&mut app, character, knee, JointRotation::euler_xyz(-5.0, 1.0, 1.0));
    app.update();
    let entity = app.world().get::<Character>(character).unwrap().joints[knee];
    assert_eq!(app.world().get::<JointPose>(entity).unwrap().0, JointRotation::euler_xyz(-2.0, 0.0, 0.0));
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn model1_in_the_ecs_matches_the_kernel() {
    ecs_matches_the_kernel("mit6837/Model1.skel");
}

/// Homer's 24,421-vertex mesh is larger than one skinning chunk: it is skinned in parts on
/// several threads, and the result is the kernel's.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn a_mesh_skinned_in_chunks_matches_the_kernel() {
    let vertices = ecs_matches_the_kernel("homer/homerskel.json");
    assert!(vertices > marionette::scene::systems::SKIN_CHUNK_VERTICES, "{vertices} vertices: more than one chunk");
}

/// Poses joint 6 of the character in the ECS and compares its skin with the kernel's;
/// returns its vertex count.
fn ecs_matches_the_kernel(file: &str) -> usize {
    let asset = Arc::new(marionette::formats::load_character(&data_dir().join(file)).unwrap());
    let mut app = app();
    let character = spawn(&mut app, asset.clone(), Placement::default());
    app.update();
    let rotation = JointRotation::euler_xyz(-0.6, 0.3, 0.9);
    set_joint(&mut app, character, 6, rotation);
    app.update();
    let mut pose = asset.skeleton.initial_pose();
    pose[6] = rotation;
    assert_positions_close(&mesh_positions(&app, character), &oracle(&asset, &pose, &Placement::default()), 1e-5);
    asset.vertex_count()
}

/// SMPL in the ECS (shape change, clip pose) against the pure SMPL poser.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn smpl_body_in_the_ecs_matches_the_poser() {
    use marionette::cli::smpl_tasks::{FrameSpec, SmplPoser, exercise_beta};
    use marionette::formats::scene::SmplDoc;
    use marionette::scene::PlaybackPlugin;
    use marionette::scene::smpl::SmplCharacter;
    let data = data_dir();
    let dir = data.join("smpl");
    let (model, _) = marionette::formats::smpl::load_smpl_dir(&dir).unwrap();
    let model = Arc::new(model);
    let clip_path = dir.join("smpl_quaternions_mosh_cmu_7516.txt");
    let clip = Arc::new(
        marionette::formats::smpl::parse_clip(
            std::io::BufReader::new(std::fs::File::open(&clip_path).unwrap()),
            &clip_path,
            24,
        )
        .unwrap(),
    );
    let asset = Arc::new(model.asset("smpl", &[]).unwrap());
    let mut app = app();
    app.add_plugins(PlaybackPlugin);
    let character = spawn(&mut app, asset.clone(), Placement::default());
    let doc = SmplDoc {
        betas: exercise_beta(2).to_vec(),
        clip: Some("c".into()),
        time: 42.0 / 30.0,
        upright: false,
        ..SmplDoc::default()
    };
    app.world_mut().entity_mut(character).insert(SmplCharacter::new(
        model.clone(),
        dir.clone(),
        vec![("c".into(), clip.clone())],
        doc,
    ));
    app.update();
    app.update();
    let frame =
        FrameSpec { betas: exercise_beta(2), rotations: clip.frame(42).to_vec(), translation: None, skinned: true };
    let mut expected = Vec::new();
    SmplPoser::new(&model).frame(&frame, &mut expected);
    let expected: Vec<[f32; 3]> = expected.iter().map(|p| p.to_array()).collect();
    assert_positions_close(&mesh_positions(&app, character), &expected, 1e-5);
}

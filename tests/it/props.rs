//! Props: an OBJ without a skeleton is a prop; a prop held by a joint follows it, keeping
//! its offset from attach time; detach keeps it where it stands; every prop edit undoes to
//! the exact world; scene files keep the holding.

use bevy::prelude::*;
use marionette::editor::edits::commands::Edit;
use marionette::editor::edits::history::HistoryRequest;
use marionette::editor::edits::kinds;
use marionette::editor::scene_doc::attach::Attached;
use marionette::editor::scene_doc::document::PendingScene;
use marionette::formats::scene::{AttachDoc, CharacterDoc, CharacterId, PlacementDoc, SceneDoc, SourceDoc};
use marionette::rig::JointRotation;
use marionette::scene::{Character, CurrentJointToWorld, Placement};

use crate::common::scratch;
use crate::edits::{Captured, edit, entity, joint, request, scene_app, state};

/// A small tetrahedron as an OBJ file (no skeleton beside it).
fn tetrahedron(dir: &std::path::Path) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join("blade.obj");
    std::fs::write(&path, "v 0 0 0\nv 0.05 0 0\nv 0 0.6 0\nv 0 0 0.05\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n").unwrap();
    path
}

/// A puppet (id 1) and the prop (id 2) standing tilted beside it.
fn puppet_and_prop(obj: &std::path::Path) -> SceneDoc {
    let puppet = CharacterDoc {
        id: Some(CharacterId(1)),
        placement: PlacementDoc::new(Vec3::new(0.3, 0.0, -0.2), 0.4, 1.1),
        ..CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "puppet")
    };
    let mut placement = PlacementDoc::new(Vec3::new(0.7, 1.0, 0.1), 0.2, 0.9);
    placement.tilt = Quat::from_rotation_x(0.6);
    let prop =
        CharacterDoc { id: Some(CharacterId(2)), placement, ..CharacterDoc::new(SourceDoc::File(obj.into()), "blade") };
    SceneDoc { characters: vec![puppet, prop], ..SceneDoc::default() }
}

fn open(app: &mut App, doc: SceneDoc) {
    *app.world_mut().resource_mut::<PendingScene>() = PendingScene { doc: Some(doc), frame: false };
    app.update();
    app.update();
}

/// The world transform of the puppet's joint `name`, as the ECS holds it.
fn joint_world(app: &App, name: &str) -> Mat4 {
    let puppet = entity(app, 1);
    let character = app.world().get::<Character>(puppet).unwrap();
    let j = joint(app, 1, name);
    let current = app.world().get::<CurrentJointToWorld>(character.joints[j]).unwrap();
    current.world(app.world().get::<Placement>(puppet).unwrap())
}

fn placement(app: &App, id: u64) -> PlacementDoc {
    app.world().get::<Placement>(entity(app, id)).unwrap().0
}

fn hold_in_right_hand(app: &App) -> Edit {
    let here = placement(app, 2);
    let attached = AttachDoc::holding(CharacterId(1), "r_hand".into(), joint_world(app, "r_hand"), &here);
    Edit::from(kinds::Attach { character: CharacterId(2), attached: Some(attached), placement: here })
}

#[test]
fn an_obj_without_a_skeleton_loads_as_a_prop_of_one_joint() {
    let obj = tetrahedron(&scratch("props-obj"));
    let asset = marionette::formats::load_character(&obj).unwrap();
    assert_eq!(asset.skeleton.len(), 1);
    assert_eq!(asset.vertex_count(), 4);
    assert_eq!(asset.skin_kind, marionette::rig::character::SkinKind::Rigid);
    let empty = scratch("props-obj-empty").join("none.obj");
    std::fs::create_dir_all(empty.parent().unwrap()).unwrap();
    std::fs::write(&empty, "# nothing\n").unwrap();
    let e = marionette::formats::load_character(&empty).unwrap_err().to_string();
    assert!(e.contains("none.obj") && e.contains("found none"), "{e}");
}

#[test]
fn a_held_prop_follows_its_joint_in_the_ecs_and_in_the_exported_mesh() {
    let obj = tetrahedron(&scratch("props-follow"));
    let mut app = scene_app();
    open(&mut app, puppet_and_prop(&obj));
    let attach = hold_in_right_hand(&app);
    let Some(kinds::Attach { attached: Some(held), .. }) = attach.get::<kinds::Attach>() else { unreachable!() };
    let offset = held.offset;
    edit(&mut app, attach.clone());
    let (wrist, elbow) = (joint(&app, 1, "r_wrist"), joint(&app, 1, "r_elbow"));
    let bend =
        vec![(elbow, JointRotation::euler_xyz(0.2, -0.9, 0.4)), (wrist, JointRotation::euler_xyz(0.5, 0.3, -0.7))];
    edit(&mut app, Edit::from(kinds::Pose { character: CharacterId(1), joints: bend }));
    app.update();

    // The ECS: the prop stands at the hand's transform times its attach-time offset.
    let expected = joint_world(&app, "r_hand") * offset;
    let got = placement(&app, 2).to_mat4();
    crate::common::assert_mat_close(got, expected, 1e-5);
    assert!(got.w_axis.distance(placement_at_start(&obj).to_mat4().w_axis) > 0.05, "the prop moved with the hand");

    // The exported mesh (document layer, posing the saved scene itself): every prop vertex
    // is the hand's current transform applied to the offset and the prop's own vertex.
    let doc = app.world().resource::<Captured>().0.clone();
    assert_eq!(doc.characters[1].attached.as_ref().map(|a| a.joint.as_str()), Some("r_hand"));
    let (positions, triangles) = marionette::document::export::scene_mesh(&doc).unwrap();
    let puppet_vertices = app.world().get::<Character>(entity(&app, 1)).unwrap().asset.vertex_count();
    let prop = marionette::formats::load_character(&obj).unwrap();
    assert_eq!(positions.len(), puppet_vertices + 4);
    assert_eq!(triangles.len(), app.world().get::<Character>(entity(&app, 1)).unwrap().asset.triangle_count() + 4);
    for (v, got) in prop.skin.bind_positions.iter().zip(&positions[puppet_vertices..]) {
        let want = expected.transform_point3(*v);
        assert!(got.distance(want) < 1e-5, "{got} vs {want}");
    }
}

fn placement_at_start(obj: &std::path::Path) -> PlacementDoc {
    puppet_and_prop(obj).characters[1].placement
}

#[test]
fn detach_keeps_the_prop_where_it_stands_and_every_prop_edit_undoes_exactly() {
    let obj = tetrahedron(&scratch("props-undo"));
    let mut app = scene_app();
    open(&mut app, puppet_and_prop(&obj));
    let start = state(&mut app);
    let elbow = joint(&app, 1, "r_elbow");
    let attach = hold_in_right_hand(&app);
    edit(&mut app, attach);
    edit(
        &mut app,
        Edit::from(kinds::Pose {
            character: CharacterId(1),
            joints: vec![(elbow, JointRotation::euler_xyz(0.0, -1.1, 0.3))],
        }),
    );
    app.update();
    let held_at = placement(&app, 2);
    edit(&mut app, Edit::from(kinds::Attach { character: CharacterId(2), attached: None, placement: held_at }));
    edit(
        &mut app,
        Edit::from(kinds::Pose {
            character: CharacterId(1),
            joints: vec![(elbow, JointRotation::euler_xyz(0.0, 0.5, 0.0))],
        }),
    );
    app.update();
    assert_eq!(placement(&app, 2), held_at, "let go, it stays where it was when detached");
    assert!(app.world().get::<Attached>(entity(&app, 2)).is_none());
    edit(&mut app, Edit::from(kinds::Rename { character: CharacterId(2), name: "sword".into() }));
    edit(
        &mut app,
        Edit::from(kinds::Place { character: CharacterId(2), placement: PlacementDoc::new(Vec3::X, 1.0, 2.0) }),
    );
    let end = state(&mut app);

    for _ in 0..6 {
        request(&mut app, HistoryRequest::Undo);
    }
    app.update();
    assert_eq!(state(&mut app), start, "undo all: the exact start");
    for _ in 0..6 {
        request(&mut app, HistoryRequest::Redo);
    }
    app.update();
    assert_eq!(state(&mut app), end, "redo all: the exact end");
}

#[test]
fn a_held_prop_round_trips_through_a_scene_file() {
    let dir = scratch("props-save");
    let obj = tetrahedron(&dir);
    let mut app = scene_app();
    open(&mut app, puppet_and_prop(&obj));
    let hold = hold_in_right_hand(&app);
    edit(&mut app, hold);
    let wrist = joint(&app, 1, "r_wrist");
    edit(
        &mut app,
        Edit::from(kinds::Pose {
            character: CharacterId(1),
            joints: vec![(wrist, JointRotation::euler_xyz(0.9, 0.0, 0.0))],
        }),
    );
    app.update();
    let saved = app.world().resource::<Captured>().0.clone();
    let path = dir.join("held.ron");
    marionette::document::scenes::write_scene(&path, &saved).unwrap();
    let read = marionette::document::scenes::read_scene(&path).unwrap();
    assert_eq!(read.characters[1].attached, saved.characters[1].attached);
    assert_eq!(read.characters[1].placement, saved.characters[1].placement);

    let mut again = scene_app();
    open(&mut again, read);
    again.update();
    crate::common::assert_mat_close(placement(&again, 2).to_mat4(), placement(&app, 2).to_mat4(), 1e-6);
    assert!(again.world().get::<Attached>(entity(&again, 2)).is_some(), "still held");
}

#[test]
fn a_ray_finds_the_nearest_triangle_of_a_moving_mesh() {
    use marionette::rig::triangle_tree::first_hit;
    // Two squares facing the ray, at z = -1 and z = -3; the ray from the origin along -z.
    let square =
        |z: f32| [Vec3::new(-1.0, -1.0, z), Vec3::new(1.0, -1.0, z), Vec3::new(1.0, 1.0, z), Vec3::new(-1.0, 1.0, z)];
    let positions: Vec<Vec3> = square(-3.0).into_iter().chain(square(-1.0)).collect();
    let triangles = [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7], [4, 5, 99]];
    let t = first_hit(&positions, &triangles, Vec3::ZERO, Vec3::new(0.1, 0.2, -2.0)).unwrap();
    assert!((t - 0.5).abs() < 1e-6, "the nearer square, half way along the direction: {t}");
    assert_eq!(first_hit(&positions, &triangles, Vec3::ZERO, Vec3::Z), None, "behind the ray");
    assert_eq!(first_hit(&positions, &triangles, Vec3::new(5.0, 0.0, 0.0), -Vec3::Z), None, "beside the squares");
}

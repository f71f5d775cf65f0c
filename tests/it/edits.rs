//! Edits as commands on the live ECS: undo and redo replay inverses in place, a gesture is
//! one step, a click none; opening a scene replaces the world; ids are stable.

use bevy::prelude::*;
use marionette::editor::edits::commands::{Edit, EditQueue, GestureHold};
use marionette::editor::edits::history::{History, HistoryRequest};
use marionette::editor::edits::kinds;
use marionette::editor::scene_doc::document::{CharacterIndex, PendingScene, SceneCharacter, SceneReader};
use marionette::editor::state::Pins;
use marionette::editor::{Messages, ScenePlugin, Selection};
use marionette::formats::scene::{
    BindingDoc, CharacterDoc, CharacterId, DisplayDoc, SceneDoc, SourceDoc, StageDoc, ViewDoc,
};
use marionette::rig::JointRotation;
use marionette::scene::{Character, JointPose, Placement};

use crate::editor::doc_with;

#[derive(Resource, Default)]
pub struct Captured(pub SceneDoc);

/// The ECS core and the live scene (no window, no rendering); after each update the scene
/// is captured into `Captured`.
pub fn scene_app() -> App {
    let mut app = crate::ecs::app();
    app.add_plugins(ScenePlugin).init_resource::<Captured>().add_systems(Last, capture_scene);
    app
}

pub fn capture_scene(reader: SceneReader, mut out: ResMut<Captured>) {
    out.0 = reader.capture();
}

/// Opens a scene of puppets with these ids.
pub fn open_puppets(app: &mut App, ids: &[Option<u64>]) {
    let one = doc_with(SourceDoc::Embedded("puppet".into()), &[]).characters[0].clone();
    let characters = ids.iter().map(|&id| CharacterDoc { id: id.map(CharacterId), ..one.clone() }).collect();
    let doc = SceneDoc { characters, ..SceneDoc::default() };
    *app.world_mut().resource_mut::<PendingScene>() = PendingScene { doc: Some(doc), frame: false };
    app.update();
    app.update();
}

pub fn edit(app: &mut App, edit: Edit) {
    app.world_mut().resource_mut::<EditQueue>().push(edit);
    app.update();
}

pub fn request(app: &mut App, request: HistoryRequest) {
    app.world_mut().resource_mut::<History>().request = Some(request);
    app.update();
}

pub fn entity(app: &App, id: u64) -> Entity {
    app.world().resource::<CharacterIndex>().get(CharacterId(id)).expect("the character is in the scene")
}

pub fn joint(app: &App, id: u64, name: &str) -> usize {
    app.world().get::<Character>(entity(app, id)).unwrap().asset.skeleton.find(name).unwrap()
}

/// Everything an edit can change: the scene document (poses, placements, views, names,
/// weights, stage, ids) and the number of entities.
pub fn state(app: &mut App) -> (SceneDoc, usize) {
    let doc = app.world().resource::<Captured>().0.clone();
    let count = app.world_mut().query::<Entity>().iter(app.world()).count();
    (doc, count)
}

#[test]
fn commands_then_undo_all_return_the_ecs_to_its_start_and_redo_to_its_end() {
    let mut app = scene_app();
    open_puppets(&mut app, &[Some(1), Some(2)]);
    let (first, first_mesh) =
        (entity(&app, 1), app.world().get::<Character>(entity(&app, 1)).unwrap().skins[0].mesh.id());
    let elbow = joint(&app, 1, "l_elbow");
    let selection = Selection { character: Some(CharacterId(1)), joints: vec![elbow] };
    *app.world_mut().resource_mut::<Selection>() = selection.clone();
    let start = state(&mut app);

    let mut added = doc_with(SourceDoc::Embedded("puppet".into()), &[]).characters[0].clone();
    added.id = Some(CharacterId(10));
    added.placement.translation.x = 3.0;
    let edits = vec![
        Edit::from(kinds::Pose {
            character: CharacterId(1),
            joints: vec![(elbow, JointRotation::euler_xyz(0.0, 0.7, 0.0))],
        }),
        Edit::from(kinds::Place {
            character: CharacterId(2),
            placement: Placement::new(Vec3::new(1.0, 0.0, 2.0), 0.5, 1.5).0,
        }),
        Edit::from(kinds::View {
            character: CharacterId(1),
            view: ViewDoc { display: DisplayDoc::Both, tint: [0.1, 0.2, 0.3], ..ViewDoc::default() },
        }),
        Edit::from(kinds::Rename { character: CharacterId(2), name: "Bea".into() }),
        Edit::from(kinds::Stage(StageDoc { axes: true, floor: false, ..StageDoc::default() })),
        Edit::from(kinds::Rebind { character: CharacterId(1), binding: Some(BindingDoc::Nearest) }),
        Edit::from(kinds::Skinning {
            character: CharacterId(2),
            method: marionette::formats::scene::SkinningDoc::DualQuaternion,
        }),
        Edit::from(kinds::SkinOnGpu { character: CharacterId(1), on: true }),
        Edit::from(kinds::Add(Box::new(added))),
        Edit::from(kinds::Pose {
            character: CharacterId(10),
            joints: vec![(elbow, JointRotation::euler_xyz(0.3, 0.0, 0.0))],
        }),
        Edit::from(kinds::Remove(CharacterId(2))),
    ];
    let n = edits.len();
    for e in edits {
        edit(&mut app, e);
    }
    app.update();
    let end = state(&mut app);
    assert_ne!(end, start);
    assert_eq!(app.world().resource::<History>().undo_steps(), n, "one step per edit");
    assert_eq!(end.0.characters.iter().map(|c| c.id.unwrap().0).collect::<Vec<_>>(), vec![1, 10]);

    for _ in 0..n {
        request(&mut app, HistoryRequest::Undo);
    }
    assert_eq!(state(&mut app), start, "undo all returns to the exact start");
    assert_eq!(entity(&app, 1), first, "the character that stayed keeps its entity");
    assert_eq!(app.world().get::<Character>(first).unwrap().skins[0].mesh.id(), first_mesh, "and its mesh");
    assert_eq!(*app.world().resource::<Selection>(), selection, "the selection survives");
    assert!(!app.world().resource::<History>().can_undo());

    for _ in 0..n {
        request(&mut app, HistoryRequest::Redo);
    }
    assert_eq!(state(&mut app), end, "redo all returns to the end");
    assert!(app.world().resource::<Messages>().0.iter().all(|m| !m.contains("not in the scene")));
}

/// A slider dragged over many frames is one undo step back to where it started; a click
/// that changes nothing (or a drag that comes back) is none and keeps the redo steps.
#[test]
fn a_gesture_is_one_undo_step_and_a_click_is_none() {
    let mut app = scene_app();
    open_puppets(&mut app, &[Some(1)]);
    let elbow = joint(&app, 1, "l_elbow");
    let pose_of = |app: &App| {
        app.world().get::<JointPose>(app.world().get::<Character>(entity(app, 1)).unwrap().joints[elbow]).unwrap().0
    };
    let before = pose_of(&app);
    let turn = |a: f32| {
        Edit::from(kinds::Pose {
            character: CharacterId(1),
            joints: vec![(elbow, JointRotation::euler_xyz(0.0, a, 0.0))],
        })
    };

    app.world_mut().resource_mut::<GestureHold>().panels = true;
    for k in 1..=5 {
        edit(&mut app, turn(0.1 * k as f32));
    }
    assert_eq!(app.world().resource::<History>().undo_steps(), 0, "the gesture is still under way");
    app.world_mut().resource_mut::<GestureHold>().panels = false;
    app.update();
    app.update();
    assert_eq!(app.world().resource::<History>().undo_steps(), 1, "a drag is one step");
    request(&mut app, HistoryRequest::Undo);
    assert_eq!(pose_of(&app), before, "undo returns to where the drag started");
    assert_eq!(app.world().resource::<History>().redo_steps(), 1);

    // A click on the slider: the same value again.
    app.world_mut().resource_mut::<GestureHold>().panels = true;
    edit(&mut app, Edit::from(kinds::Pose { character: CharacterId(1), joints: vec![(elbow, before)] }));
    app.world_mut().resource_mut::<GestureHold>().panels = false;
    app.update();
    // A drag that comes back to where it began.
    app.world_mut().resource_mut::<GestureHold>().panels = true;
    edit(&mut app, turn(0.4));
    edit(&mut app, Edit::from(kinds::Pose { character: CharacterId(1), joints: vec![(elbow, before)] }));
    app.world_mut().resource_mut::<GestureHold>().panels = false;
    app.update();
    app.update();
    let history = app.world().resource::<History>();
    assert_eq!((history.undo_steps(), history.redo_steps()), (0, 1), "no step; the redo step survives");
}

/// Selecting changes nothing the history holds; an edit naming a character that is not
/// there is a message, not a panic and not a step.
#[test]
fn selecting_is_no_edit_and_edits_of_missing_characters_are_reported() {
    let mut app = scene_app();
    open_puppets(&mut app, &[Some(1)]);
    *app.world_mut().resource_mut::<Selection>() = Selection { character: Some(CharacterId(1)), joints: vec![3] };
    app.update();
    assert!(!app.world().resource::<History>().can_undo(), "selecting is no undo step");
    edit(&mut app, Edit::from(kinds::Rename { character: CharacterId(99), name: "x".into() }));
    assert!(!app.world().resource::<History>().can_undo());
    let messages = &app.world().resource::<Messages>().0;
    assert!(messages.iter().any(|m| m.contains("character #99 is not in the scene")), "{messages:?}");
}

/// Open replaces the world: the old selection, pins and history refer to nothing in it
/// and are cleared; a character that fails to load is reported and kept, as it was, in
/// what Save writes.
#[test]
fn opening_a_scene_clears_selection_pins_and_history_and_keeps_unloadable_characters() {
    let mut app = scene_app();
    open_puppets(&mut app, &[Some(7)]);
    // What the previous scene left behind.
    *app.world_mut().resource_mut::<Selection>() = Selection { character: Some(CharacterId(7)), joints: vec![4] };
    app.world_mut().resource_mut::<Pins>().0.insert(CharacterId(7), vec![4]);
    edit(&mut app, Edit::from(kinds::Rename { character: CharacterId(7), name: "renamed".into() }));
    app.update();
    assert!(app.world().resource::<History>().can_undo());

    let mut doc = doc_with(SourceDoc::Embedded("puppet".into()), &[]);
    let mut missing = doc.characters[0].clone();
    missing.source = SourceDoc::File("/nonexistent/gone.skel".into());
    missing.name = "gone".into();
    doc.characters.push(missing.clone());
    *app.world_mut().resource_mut::<PendingScene>() = PendingScene { doc: Some(doc), frame: false };
    app.update();
    app.update();

    let world = app.world_mut();
    assert_eq!(*world.resource::<Selection>(), Selection::default());
    assert!(world.resource::<Pins>().0.is_empty());
    assert!(!world.resource::<History>().can_undo());
    assert_eq!(world.query::<&SceneCharacter>().iter(world).count(), 1);
    let messages = &world.resource::<Messages>().0;
    assert!(messages.iter().any(|m| m.contains("gone.skel") && m.contains("kept in the scene file")), "{messages:?}");
    let saved = &world.resource::<Captured>().0;
    assert_eq!(saved.characters.len(), 2);
    assert_eq!(saved.characters[1], missing, "the unloadable character is saved as it was");
}

/// Ids are saved in the document and kept when it is opened; documents without ids (old
/// files) or with a repeated one get fresh ids that never repeat.
#[test]
fn character_ids_are_kept_from_files_and_old_files_get_fresh_ones() {
    let mut app = scene_app();
    let ids = |app: &mut App| {
        let world = app.world_mut();
        let mut ids: Vec<u64> = world.query::<&SceneCharacter>().iter(world).map(|c| c.id.0).collect();
        ids.sort();
        ids
    };
    open_puppets(&mut app, &[Some(5), Some(9)]);
    assert_eq!(ids(&mut app), vec![5, 9]);
    let saved: Vec<_> = app.world().resource::<Captured>().0.characters.iter().map(|c| c.id).collect();
    assert_eq!(saved, vec![Some(CharacterId(5)), Some(CharacterId(9))], "ids are saved");
    open_puppets(&mut app, &[None, Some(9), Some(9)]);
    assert_eq!(ids(&mut app), vec![9, 10, 11]);
    assert_eq!(app.world().resource::<CharacterIndex>().len(), 3, "the index follows despawns and spawns");
}

/// An SMPL body's shape and clip are edits like any other: undo reshapes it back (same
/// entity) and redo again.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the SMPL folder)")]
fn smpl_shape_and_clip_edits_undo_and_redo() {
    use marionette::formats::scene::SmplDoc;
    use marionette::scene::smpl::SmplCharacter;
    let dir = crate::common::data_dir().join("smpl");
    let mut app = scene_app();
    let body = CharacterDoc {
        id: Some(CharacterId(1)),
        smpl: Some(SmplDoc::default()),
        ..CharacterDoc::new(SourceDoc::File(dir.clone()), "body")
    };
    *app.world_mut().resource_mut::<PendingScene>() =
        PendingScene { doc: Some(SceneDoc { characters: vec![body], ..SceneDoc::default() }), frame: false };
    app.update();
    app.update();
    let e = entity(&app, 1);
    let shape = |app: &App| app.world().get::<Character>(e).unwrap().asset.skin.bind_positions.clone();
    let start = (state(&mut app), shape(&app));
    let clip = marionette::formats::smpl::clip_paths(&dir)[0].file_name().unwrap().to_string_lossy().into_owned();
    let wanted = SmplDoc { betas: vec![2.0, -1.0], clip: Some(clip), time: 12.0 / 30.0, ..SmplDoc::default() };
    edit(&mut app, Edit::from(kinds::Smpl { character: CharacterId(1), state: wanted.clone() }));
    assert_eq!(app.world().get::<SmplCharacter>(e).unwrap().state, wanted);
    let end = (state(&mut app), shape(&app));
    assert_ne!(end.1, start.1, "β reshaped the body");
    assert_ne!(end.0, start.0, "the clip posed it");
    request(&mut app, HistoryRequest::Undo);
    assert_eq!((state(&mut app), shape(&app)), start);
    assert_eq!(entity(&app, 1), e);
    request(&mut app, HistoryRequest::Redo);
    assert_eq!((state(&mut app), shape(&app)), end);
}

/// A gizmo drag pushes one pose edit a frame; the drag is one undo step, and a drag that
/// is cancelled (its start pushed back) leaves the pose exactly as it was and no step.
#[test]
fn a_gizmo_drag_is_one_undo_step_and_a_cancelled_one_none() {
    use marionette::editor::interact::rotate_gizmo::{Grip, Turn};
    let mut app = scene_app();
    open_puppets(&mut app, &[Some(1)]);
    let elbow = joint(&app, 1, "l_elbow");
    let pose_of = |app: &App| {
        app.world().get::<JointPose>(app.world().get::<Character>(entity(app, 1)).unwrap().joints[elbow]).unwrap().0
    };
    let start = pose_of(&app);
    let limits = app.world().get::<Character>(entity(&app, 1)).unwrap().asset.skeleton.joint(elbow).limits;
    let drag = |app: &mut App, angles: &[f32]| {
        let grip = Grip::Ring { axis: 2, normal: Vec3::Z, across: Vec3::X, last: 0.0, turned: 0.0 };
        let mut turn = Turn { character: CharacterId(1), joint: elbow, start: pose_of(app), limits, grip };
        app.world_mut().resource_mut::<GestureHold>().typing = true;
        for &a in angles {
            turn.ring_to(a);
            edit(app, Edit::from(kinds::Pose { character: CharacterId(1), joints: vec![(elbow, turn.rotation())] }));
        }
        turn
    };
    let release = |app: &mut App| {
        app.world_mut().resource_mut::<GestureHold>().typing = false;
        app.update();
        app.update();
    };

    let turn = drag(&mut app, &[0.1, 0.2, 0.3]);
    edit(&mut app, Edit::from(kinds::Pose { character: CharacterId(1), joints: vec![(elbow, turn.start)] }));
    release(&mut app);
    assert_eq!(pose_of(&app), start, "cancel restores the pose exactly");
    assert_eq!(app.world().resource::<History>().undo_steps(), 0, "a cancelled drag is no step");

    let turn = drag(&mut app, &[0.1, 0.2, 0.3]);
    release(&mut app);
    assert_eq!(pose_of(&app), turn.rotation());
    assert_ne!(pose_of(&app), start);
    assert_eq!(app.world().resource::<History>().undo_steps(), 1, "a drag is one step");
    request(&mut app, HistoryRequest::Undo);
    assert_eq!(pose_of(&app), start, "undo returns to where the drag began");
}

/// Keying is an edit: the first key puts a clip of the character's own keys on it, undo
/// takes it off again, redo puts it back.
#[test]
fn keying_a_pose_is_undone_and_redone_like_any_edit() {
    use marionette::scene::keyframes::{ClipPlayer, keyed};
    let mut app = scene_app();
    open_puppets(&mut app, &[Some(1)]);
    let elbow = joint(&app, 1, "l_elbow");
    edit(
        &mut app,
        Edit::from(kinds::Pose {
            character: CharacterId(1),
            joints: vec![(elbow, JointRotation::euler_xyz(0.0, -0.5, 0.0))],
        }),
    );
    let character = app.world().get::<Character>(entity(&app, 1)).unwrap().clone();
    let pose: Vec<_> = character.joints.iter().map(|&e| app.world().get::<JointPose>(e).unwrap().0).collect();
    let anim = keyed(None, pose.len(), &[elbow], &pose);
    edit(&mut app, Edit::from(kinds::Clip { character: CharacterId(1), anim: Some(anim.clone()) }));
    app.update();
    let player = |app: &App| app.world().get::<ClipPlayer>(entity(app, 1)).map(|p| p.state.clone());
    assert_eq!(player(&app), Some(anim.clone()));
    let clip = anim.keys.as_ref().unwrap();
    assert_eq!(clip.channels[3 + 3 * elbow + 1].keys()[0].value, -0.5);
    assert!(clip.channels[3].keys().is_empty(), "only the selected joint is keyed");
    request(&mut app, HistoryRequest::Undo);
    assert_eq!(player(&app), None, "undo takes the keys off");
    request(&mut app, HistoryRequest::Redo);
    assert_eq!(player(&app), Some(anim));
}

/// Morph weights are an edit, undone like any; a rebind keeps them applied (the morphs
/// blend from the rebound asset).
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn morph_weights_are_undone_and_survive_a_rebind() {
    let head = crate::common::data_dir().join("cse169/extras/head.skel");
    let mut app = scene_app();
    let doc = CharacterDoc { id: Some(CharacterId(1)), ..CharacterDoc::new(SourceDoc::File(head), "head") };
    *app.world_mut().resource_mut::<PendingScene>() =
        PendingScene { doc: Some(SceneDoc { characters: vec![doc], ..SceneDoc::default() }), frame: false };
    app.update();
    app.update();
    let bind = |app: &App| app.world().get::<Character>(entity(app, 1)).unwrap().asset.skin.bind_positions.clone();
    let base = bind(&app);
    edit(&mut app, Edit::from(kinds::Morph { character: CharacterId(1), weights: vec![1.0, 0.0] }));
    app.update();
    let morphed = bind(&app);
    assert_ne!(morphed, base, "the morph moves vertices");
    edit(&mut app, Edit::from(kinds::Rebind { character: CharacterId(1), binding: Some(BindingDoc::Nearest) }));
    app.update();
    assert_eq!(bind(&app), morphed, "still morphed after the rebind");
    request(&mut app, HistoryRequest::Undo);
    request(&mut app, HistoryRequest::Undo);
    app.update();
    assert_eq!(bind(&app), base, "undoing both puts the skin back");
}

/// Files dropped on the window: a BVH comes in as a character playing its motion, a scene
/// file opens in place of the scene.
#[test]
fn dropped_files_add_characters_and_open_scenes() {
    use marionette::editor::ui::{InspectorState, open_dropped_files};
    use marionette::scene::keyframes::ClipPlayer;
    let mut app = scene_app();
    app.add_message::<bevy::window::FileDragAndDrop>()
        .init_resource::<InspectorState>()
        .add_systems(Update, open_dropped_files);
    let drop = |app: &mut App, path: std::path::PathBuf| {
        app.world_mut()
            .write_message(bevy::window::FileDragAndDrop::DroppedFile { window: Entity::PLACEHOLDER, path_buf: path });
        app.update();
        app.update();
    };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    drop(&mut app, root.join("tests/data/steps.bvh"));
    let names: Vec<String> =
        app.world_mut().query::<&SceneCharacter>().iter(app.world()).map(|c| c.name.clone()).collect();
    assert_eq!(names, ["steps"]);
    assert_eq!(app.world_mut().query::<&ClipPlayer>().iter(app.world()).count(), 1, "playing its own motion");
    drop(&mut app, root.join("assets/default_scene.ron"));
    let mut names: Vec<String> =
        app.world_mut().query::<&SceneCharacter>().iter(app.world()).map(|c| c.name.clone()).collect();
    names.sort();
    assert_eq!(names, ["Ada", "Bo", "Cy"], "the scene replaced the world");
}

/// A glTF file of two characters (made by Blender) dropped on the window: both load, each
/// with its own clip; playing one through an edit poses the ECS joints exactly as the rig
/// samples the clip (rotations, keyed scale); undo gives the file's pose back; the scene
/// file keeps the second character as `Part` and its playback, and reopens it posed the
/// same.
#[test]
fn a_glb_of_two_characters_plays_its_clips_in_the_ecs_as_the_rig_samples_them() {
    use marionette::editor::ui::{InspectorState, open_dropped_files};
    use marionette::formats::scene::PlaybackDoc;
    use marionette::rig::node_clip::NodePose;
    use marionette::scene::CurrentJointToWorld;
    use marionette::scene::node_clips::NodeClipPlayer;
    let mut app = scene_app();
    app.add_message::<bevy::window::FileDragAndDrop>()
        .init_resource::<InspectorState>()
        .add_systems(Update, open_dropped_files);
    let glb = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender_pair.glb");
    app.world_mut().write_message(bevy::window::FileDragAndDrop::DroppedFile {
        window: Entity::PLACEHOLDER,
        path_buf: glb.clone(),
    });
    app.update();
    app.update();
    let mut found: Vec<(String, SourceDoc, CharacterId)> = app
        .world_mut()
        .query::<&SceneCharacter>()
        .iter(app.world())
        .map(|c| (c.name.clone(), c.source.clone(), c.id))
        .collect();
    found.sort();
    assert_eq!(found.len(), 2);
    assert_eq!((found[0].0.as_str(), &found[0].1), ("walker", &SourceDoc::File(glb.clone())));
    assert_eq!((found[1].0.as_str(), &found[1].1), ("waver", &SourceDoc::Part(glb.clone(), 1)));
    let waver = found[1].2;
    let e = entity(&app, waver.0);
    // Added together, they keep the layout the file gives them: one placement for both.
    let placement = |id: CharacterId| app.world().get::<Placement>(entity(&app, id.0)).unwrap().0;
    assert_eq!(placement(found[0].2), placement(waver));
    assert_eq!(app.world_mut().query::<&NodeClipPlayer>().iter(app.world()).count(), 2);
    let matrices = |app: &App| -> Vec<Mat4> {
        let c = app.world().get::<Character>(e).unwrap();
        c.joints.iter().map(|&j| app.world().get::<CurrentJointToWorld>(j).unwrap().0).collect()
    };
    let character = app.world().get::<Character>(e).unwrap().clone();
    let skeleton = &character.asset.skeleton;
    let file_pose = NodePose::of(skeleton).joint_to_world(skeleton, Mat4::IDENTITY);
    let start = matrices(&app);
    start.iter().zip(&file_pose).for_each(|(a, b)| crate::common::assert_mat_close(*a, *b, 1e-6));

    let clip = app.world().get::<NodeClipPlayer>(e).unwrap().clips[0].clone();
    let playing = PlaybackDoc { clip: Some(clip.name.clone()), time: 0.5, ..PlaybackDoc::default() };
    edit(&mut app, Edit::from(kinds::Playback { character: waver, state: playing.clone() }));
    let expected = clip.sample(skeleton, 0.5).joint_to_world(skeleton, Mat4::IDENTITY);
    let posed = matrices(&app);
    posed.iter().zip(&expected).for_each(|(a, b)| crate::common::assert_mat_close(*a, *b, 1e-6));
    assert!(posed[1].x_axis.length() > 1.05, "the keyed scale of `lower` is played: {}", posed[1].x_axis.length());

    let doc = app.world().resource::<Captured>().0.clone();
    let saved = doc.characters.iter().find(|c| c.id == Some(waver)).unwrap();
    assert_eq!(saved.playback.as_ref(), Some(&playing));
    let file = crate::common::scratch("glb-scene").join("pair.ron");
    marionette::document::scenes::write_scene(&file, &doc).unwrap();

    request(&mut app, HistoryRequest::Undo);
    matrices(&app).iter().zip(&file_pose).for_each(|(a, b)| crate::common::assert_mat_close(*a, *b, 1e-6));

    let mut reopened = scene_app();
    let doc = marionette::document::scenes::read_scene(&file).unwrap();
    let part = doc.characters.iter().find_map(|c| match &c.source {
        SourceDoc::Part(p, 1) => Some(p.canonicalize().unwrap()),
        _ => None,
    });
    assert_eq!(part, Some(glb.canonicalize().unwrap()));
    *reopened.world_mut().resource_mut::<PendingScene>() = PendingScene { doc: Some(doc), frame: false };
    reopened.update();
    reopened.update();
    let e = entity(&reopened, waver.0);
    let c = reopened.world().get::<Character>(e).unwrap();
    let again: Vec<Mat4> =
        c.joints.iter().map(|&j| reopened.world().get::<CurrentJointToWorld>(j).unwrap().0).collect();
    again.iter().zip(&expected).for_each(|(a, b)| crate::common::assert_mat_close(*a, *b, 1e-6));
}

/// The humanoid map is derived data: worked out when a character comes in and when its
/// assigned bones change (undo included), and left alone by frames that change neither.
#[test]
fn the_humanoid_map_is_kept_and_follows_assigned_bones() {
    use marionette::editor::scene_doc::document::HumanoidMapOf;
    use marionette::rig::humanoid::{HumanBone, of_asset};
    let mut app = scene_app();
    open_puppets(&mut app, &[Some(1)]);
    let e = entity(&app, 1);
    let asset = app.world().get::<Character>(e).unwrap().asset.clone();
    let found = of_asset(&asset).expect("the puppet is a humanoid").map;
    let map = |app: &App| app.world().get::<HumanoidMapOf>(e).expect("the map is worked out").0.clone();
    assert_eq!(map(&app), found);
    let changed = |app: &mut App| {
        let mut q = app.world_mut().query::<Ref<HumanoidMapOf>>();
        q.get(app.world(), e).unwrap().last_changed()
    };
    let before = changed(&mut app);
    app.update();
    app.update();
    assert_eq!(changed(&mut app), before, "frames without a change leave the map alone");

    let hand = found[&HumanBone::LeftHand];
    let elsewhere = (0..asset.skeleton.len()).find(|&j| j != hand).unwrap();
    let key = marionette::formats::scene::pose_key(&asset.skeleton, elsewhere);
    let bones = [(HumanBone::LeftHand, key)].into_iter().collect();
    edit(&mut app, Edit::from(kinds::Humanoid { character: CharacterId(1), bones }));
    app.update();
    assert_eq!(map(&app)[&HumanBone::LeftHand], elsewhere, "an assigned bone is in the map");
    request(&mut app, HistoryRequest::Undo);
    app.update();
    assert_eq!(map(&app), found, "undone, the map is the found one again");
}

/// With symmetry on, turning the left arm turns the right one mirrored (each twin turned
/// from rest in the model as its joint is, reflected across the body), and one undo takes
/// both back; with it off, only the left turns.
#[test]
fn an_edit_with_symmetry_turns_the_twin_in_the_same_undo_step() {
    let mut app = scene_app();
    open_puppets(&mut app, &[Some(1)]);
    let (left, right) = (joint(&app, 1, "l_shoulder"), joint(&app, 1, "r_shoulder"));
    let (elbow, r_elbow) = (joint(&app, 1, "l_elbow"), joint(&app, 1, "r_elbow"));
    let pose_of = |app: &App| {
        let c = app.world().get::<Character>(entity(app, 1)).unwrap();
        c.joints.iter().map(|&e| app.world().get::<JointPose>(e).unwrap().0).collect::<Vec<_>>()
    };
    let skeleton = app.world().get::<Character>(entity(&app, 1)).unwrap().asset.skeleton.clone();
    let rest = pose_of(&app);
    let turns = |pose: &[JointRotation]| {
        let model = |pose: &[JointRotation]| {
            let mut world = vec![glam::Mat4::IDENTITY; skeleton.len()];
            marionette::rig::fk::forward_kinematics(&skeleton, pose, glam::Mat4::IDENTITY, &mut world);
            world.iter().map(|&m| marionette::rig::ik::rotation_of(m)).collect::<Vec<_>>()
        };
        let (now, at_rest) = (model(pose), model(&skeleton.initial_pose()));
        now.iter().zip(&at_rest).map(|(n, r)| *n * r.inverse()).collect::<Vec<_>>()
    };
    let arm = Edit::from(kinds::Pose {
        character: CharacterId(1),
        joints: vec![
            (left, JointRotation::euler_xyz(0.3, -0.4, -0.7)),
            (elbow, JointRotation::euler_xyz(0.0, 0.9, 0.1)),
        ],
    });
    app.world_mut().resource_mut::<marionette::editor::state::Symmetry>().0 = true;
    edit(&mut app, arm.clone());
    app.update();
    let posed = pose_of(&app);
    assert_ne!(posed[right], rest[right], "the twin turned");
    let t = turns(&posed);
    for (j, k) in [(left, right), (elbow, r_elbow)] {
        let want = marionette::rig::mirror::reflected(t[j], glam::Vec3::X);
        assert!(1.0 - t[k].dot(want).abs() < 1e-5, "joint {k}: {:?} against {want:?}", t[k]);
    }
    assert_eq!(app.world().resource::<History>().undo_steps(), 1);
    request(&mut app, HistoryRequest::Undo);
    assert_eq!(pose_of(&app), rest, "one undo takes both sides back");

    app.world_mut().resource_mut::<marionette::editor::state::Symmetry>().0 = false;
    edit(&mut app, arm);
    let posed = pose_of(&app);
    assert_ne!(posed[left], rest[left]);
    assert_eq!(posed[right], rest[right], "without symmetry the twin stays");
}

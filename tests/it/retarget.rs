//! Retargeting clips between humanoids of different origins, checked from the joints'
//! world positions (this file's own forward kinematics walk, not the retargeter's): bone
//! directions against the source's, feet above the floor, and feet the source keeps still
//! kept still; the hips' height over the floor as a share of the standing height against
//! the source's is printed (the feet stand on the floor, so the hips go where the target's
//! own legs put them: a crouch on a figure of other proportions is not the same share).

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};
use marionette::document::AssetLibrary;
use marionette::document::retarget::{file_motion_doc, humanoid_map, retarget};
use marionette::formats::scene::{CharacterDoc, MotionSourceDoc, RetargetDoc, SourceDoc};
use marionette::rig::humanoid::{HumanBone, HumanoidMap};
use marionette::rig::retarget::{Frame, Retargeted};
use marionette::rig::{CharacterAsset, JointRotation, Skeleton};

/// Each joint's world position: the root at `root`, then parent · T(offset) · R · S(its
/// rest scale), walked here by hand.
fn positions(skeleton: &Skeleton, root: Vec3, pose: &[JointRotation]) -> Vec<Vec3> {
    let mut world: Vec<Mat4> = Vec::with_capacity(skeleton.len());
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let offset = if j == 0 { root } else { joint.rest_offset };
        let local =
            Mat4::from_translation(offset) * Mat4::from_quat(pose[j].to_quat()) * Mat4::from_scale(joint.rest_scale);
        let parent = skeleton.parent(j).map_or(Mat4::IDENTITY, |p| world[p]);
        world.push(parent * local);
    }
    world.iter().map(|m| m.w_axis.truncate()).collect()
}

/// The bones whose directions are compared: (bone, the bone it points at).
const AIMED: [(HumanBone, HumanBone); 14] = {
    use HumanBone::*;
    [
        (Hips, Spine),
        (Chest, Neck),
        (LeftUpperArm, LeftLowerArm),
        (LeftLowerArm, LeftHand),
        (RightUpperArm, RightLowerArm),
        (RightLowerArm, RightHand),
        (LeftUpperLeg, LeftLowerLeg),
        (LeftLowerLeg, LeftFoot),
        (RightUpperLeg, RightLowerLeg),
        (RightLowerLeg, RightFoot),
        (Hips, Chest),
        (Chest, Head),
        (LeftShoulder, LeftUpperArm),
        (RightShoulder, RightUpperArm),
    ]
};

/// The figures of one retargeting.
#[derive(Debug, Default)]
struct Figures {
    /// The worst angle (degrees) between a target bone and its source bone, and which.
    worst_direction: (f32, String),
    /// The range of target hips height over the floor as a share of its standing height,
    /// over the source's.
    hips_ratio: (f32, f32),
    /// The lowest foot joint over the floor, in target leg lengths.
    lowest_foot: f32,
    /// The worst slide of a target foot while its source foot stays still (≥ 5 frames), in
    /// target leg lengths; and how many such stretches there were.
    worst_slide: f32,
    still_stretches: usize,
    /// Bone-frames not compared because the report says they were clamped or moved, and
    /// the worst angle among them.
    excused: usize,
    worst_excused: f32,
}

pub(crate) struct Side {
    pub(crate) asset: std::sync::Arc<CharacterAsset>,
    pub(crate) map: HumanoidMap,
    pub(crate) floor: f32,
    pub(crate) leg: f32,
    /// The hips' height over the lowest point standing in the initial pose.
    pub(crate) standing: f32,
    /// The hips' height over the floor with the legs hanging straight down: the hips over
    /// the thighs, the thigh and shin lengths, and the ankle over the floor at rest.
    pub(crate) straight: f32,
}

pub(crate) fn side(library: &mut AssetLibrary, doc: &CharacterDoc, floor: f32) -> Side {
    side_standing(library, doc, floor, None)
}

/// As [`side`], standing as in `stands` (a motion capture whose rest lies down: its first
/// frame) in place of its initial pose.
pub(crate) fn side_standing(
    library: &mut AssetLibrary,
    doc: &CharacterDoc,
    floor: f32,
    stands: Option<&Frame>,
) -> Side {
    let asset = library.shaped(doc).unwrap();
    let map = humanoid_map(&asset, &doc.humanoid);
    let skeleton = &asset.skeleton;
    let at = match stands {
        Some(frame) => frame.world(skeleton).1,
        None => positions(skeleton, skeleton.joint(0).rest_offset, &skeleton.initial_pose()),
    };
    use HumanBone::*;
    let leg = |u, l, f| at[map[&u]].distance(at[map[&l]]) + at[map[&l]].distance(at[map[&f]]);
    let leg = (leg(LeftUpperLeg, LeftLowerLeg, LeftFoot) + leg(RightUpperLeg, RightLowerLeg, RightFoot)) / 2.0;
    let rest_floor = match stands {
        Some(_) => at.iter().map(|p| p.y).fold(f32::INFINITY, f32::min),
        None => marionette::document::retarget::floor_of(&asset),
    };
    let standing = at[map[&Hips]].y - rest_floor;
    let straight = |u, l, f| {
        at[map[&Hips]].y - at[map[&u]].y
            + at[map[&u]].distance(at[map[&l]])
            + at[map[&l]].distance(at[map[&f]])
            + at[map[&f]].y
            - rest_floor
    };
    let straight =
        (straight(LeftUpperLeg, LeftLowerLeg, LeftFoot) + straight(RightUpperLeg, RightLowerLeg, RightFoot)) / 2.0;
    Side { asset, map, floor, leg, standing, straight }
}

/// Whether `j` lies below `ancestor`.
fn below(skeleton: &Skeleton, j: usize, ancestor: usize) -> bool {
    let mut up = skeleton.parent(j);
    while let Some(p) = up {
        if p == ancestor {
            return true;
        }
        up = skeleton.parent(p);
    }
    false
}

/// The legs of each side, for skipping where the report says a leg was moved.
const LEGS: [[HumanBone; 2]; 2] =
    [[HumanBone::LeftUpperLeg, HumanBone::LeftLowerLeg], [HumanBone::RightUpperLeg, HumanBone::RightLowerLeg]];

fn measure(s: &Side, source: &[Frame], t: &Side, report: &Retargeted) -> Figures {
    let target = &report.frames;
    let mut figures =
        Figures { hips_ratio: (f32::INFINITY, f32::NEG_INFINITY), lowest_foot: f32::INFINITY, ..Default::default() };
    let (s_at, t_at): (Vec<Vec<Vec3>>, Vec<Vec<Vec3>>) = source
        .iter()
        .zip(target)
        .map(|(a, b)| (positions(&s.asset.skeleton, a.root, &a.pose), positions(&t.asset.skeleton, b.root, &b.pose)))
        .unzip();
    for (f, (sa, ta)) in s_at.iter().zip(&t_at).enumerate() {
        for (bone, next) in AIMED {
            let (Some(&sj), Some(&sn), Some(&tj), Some(&tn)) =
                (s.map.get(&bone), s.map.get(&next), t.map.get(&bone), t.map.get(&next))
            else {
                continue;
            };
            // The bone's mapped child: the spine, else the chest; the neck, else the head.
            let first_choice = |b: HumanBone| {
                [(HumanBone::Hips, HumanBone::Spine), (HumanBone::Chest, HumanBone::Neck)]
                    .iter()
                    .find(|(k, _)| *k == b)
                    .map(|(_, c)| *c)
            };
            if first_choice(bone).is_some_and(|c| c != next && s.map.contains_key(&c) && t.map.contains_key(&c)) {
                continue;
            }
            if !below(&t.asset.skeleton, tn, tj) || !below(&s.asset.skeleton, sn, sj) {
                continue;
            }
            // Where the report says the target's limits clamped the bone, or its leg was
            // moved to plant the foot or keep it above the floor.
            let angle = (sa[sn] - sa[sj]).angle_between(ta[tn] - ta[tj]).to_degrees();
            let moved = (0..2).any(|k| report.legs_moved[k][f] && LEGS[k].contains(&bone));
            if moved || report.clamped.contains(&(f, tj)) {
                figures.excused += 1;
                figures.worst_excused = figures.worst_excused.max(angle);
                continue;
            }
            if angle > figures.worst_direction.0 {
                figures.worst_direction = (angle, format!("{bone:?}"));
            }
        }
        // Hips hung below the chest (6.837's models): they lie from the chest as the source's.
        let (hips, chest) = (HumanBone::Hips, HumanBone::Chest);
        if let (Some(&tc), Some(&sc)) = (t.map.get(&chest), s.map.get(&chest))
            && below(&t.asset.skeleton, t.map[&hips], tc)
        {
            let (sh, th) = (s.map[&hips], t.map[&hips]);
            let angle = (sa[sh] - sa[sc]).angle_between(ta[th] - ta[tc]).to_degrees();
            if angle > figures.worst_direction.0 {
                figures.worst_direction = (angle, "Hips from the Chest".into());
            }
        }
        let h = HumanBone::Hips;
        let hips = ((ta[t.map[&h]].y - t.floor) / t.standing) / ((sa[s.map[&h]].y - s.floor) / s.standing);
        figures.hips_ratio = (figures.hips_ratio.0.min(hips), figures.hips_ratio.1.max(hips));
        for foot in [HumanBone::LeftFoot, HumanBone::RightFoot, HumanBone::LeftToes, HumanBone::RightToes] {
            if let Some(&j) = t.map.get(&foot) {
                figures.lowest_foot = figures.lowest_foot.min((ta[j].y - t.floor) / t.leg);
            }
        }
    }
    // Stretches of at least 5 frames over which the source's foot stays within 0.5 % of
    // its leg length of where it was at their start (and near the floor).
    for foot in [HumanBone::LeftFoot, HumanBone::RightFoot] {
        let (sj, tj) = (s.map[&foot], t.map[&foot]);
        let mut start = 0;
        while start < s_at.len() {
            let mut end = start;
            while end + 1 < s_at.len() && s_at[end + 1][sj].distance(s_at[start][sj]) < 0.005 * s.leg {
                end += 1;
            }
            if end - start + 1 >= 5 {
                figures.still_stretches += 1;
                let slide = (start..=end).map(|f| t_at[f][tj].distance(t_at[start][tj])).fold(0.0, f32::max);
                figures.worst_slide = figures.worst_slide.max(slide / t.leg);
            }
            start = end + 1;
        }
    }
    figures
}

fn doc_of(library: &mut AssetLibrary, path: &Path) -> CharacterDoc {
    let source = SourceDoc::File(path.to_path_buf());
    let asset = library.load(&source).unwrap();
    library.new_character_doc(source, &asset)
}

/// Every source with a clip of its own onto every target, the figures printed and held to
/// the bounds.
#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn clips_carry_across_humanoids_of_every_origin() {
    let data = crate::common::data_dir();
    let mut library = AssetLibrary::default();
    let sources: Vec<(PathBuf, Option<&str>)> = vec![
        (data.join("smpl"), Some("7516")),
        (data.join("smpl"), Some("8806")),
        (data.join("khronos/CesiumMan.glb"), None),
        (data.join("khronos/RiggedFigure.glb"), None),
    ];
    let mut targets: Vec<CharacterDoc> = ["Model1", "Model2", "Model3", "Model4"]
        .iter()
        .map(|m| doc_of(&mut library, &data.join(format!("mit6837/{m}.skel"))))
        .collect();
    targets.push(CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "puppet"));
    for f in ["smpl", "khronos/CesiumMan.glb", "khronos/RiggedFigure.glb", "homer/homer.json"] {
        targets.push(doc_of(&mut library, &data.join(f)));
    }
    let mut stretches = 0;
    for (path, clip) in &sources {
        let source = file_motion_doc(&mut library, path, *clip).unwrap();
        for target in &targets {
            let asset = library.shaped(target).unwrap();
            for plant in [false, true] {
                let settings = RetargetDoc {
                    plant_feet: plant,
                    ..RetargetDoc::of(MotionSourceDoc::File { path: path.clone(), clip: clip.map(str::to_owned) })
                };
                let done = retarget(&mut library, &source, target, &asset, &settings).unwrap();
                let (s, t) = (side(&mut library, &source, done.floors.0), side(&mut library, target, done.floors.1));
                let figures = measure(&s, &done.source_frames, &t, &done.report);
                eprintln!(
                    "{plant} {} {} → {}: worst direction {:.2}° ({}), hips height over standing / the source's {:.4}–{:.4}, lowest foot {:+.4} legs, {} still stretches, worst slide {:.4} legs, {} clamped, {} bone-frames excused (worst {:.1}°)",
                    path.file_name().unwrap().to_string_lossy(),
                    clip.unwrap_or(""),
                    target.name,
                    figures.worst_direction.0,
                    figures.worst_direction.1,
                    figures.hips_ratio.0,
                    figures.hips_ratio.1,
                    figures.lowest_foot,
                    figures.still_stretches,
                    figures.worst_slide,
                    done.report.clamped.len(),
                    figures.excused,
                    figures.worst_excused,
                );
                assert!(figures.worst_direction.0 < 2.0, "{}: {:?}", target.name, figures.worst_direction);
                assert!(
                    figures.lowest_foot > -1e-3,
                    "{}: a foot {} legs below the floor",
                    target.name,
                    figures.lowest_foot
                );
                assert!(figures.worst_slide < 0.01, "{}: a still foot slid {} legs", target.name, figures.worst_slide);
                stretches += figures.still_stretches;
            }
        }
    }
    assert!(stretches > 0, "some source keeps a foot still");
}

/// Quaternions equal within `tolerance`, either sign.
fn same_rotation(a: glam::Quat, b: glam::Quat, tolerance: f32) -> bool {
    (a - b).length().min((a + b).length()) < tolerance
}

/// A clip retargeted onto its own character is that clip: every joint's rotation and the
/// root within 1e-5, for the SMPL body (its clip stood upright, hanging from a fixed root
/// below the body's floor) and CesiumMan (whose walk dips 0.026 below its rest's floor).
#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn a_clip_retargeted_onto_its_own_character_is_itself() {
    let data = crate::common::data_dir();
    let mut library = AssetLibrary::default();
    for (path, clip) in [(data.join("smpl"), Some("7516")), (data.join("khronos/CesiumMan.glb"), None)] {
        let source = file_motion_doc(&mut library, &path, clip).unwrap();
        let asset = library.shaped(&source).unwrap();
        let settings = RetargetDoc::of(MotionSourceDoc::File { path: path.clone(), clip: clip.map(str::to_owned) });
        let done = retarget(&mut library, &source, &source, &asset, &settings).unwrap();
        assert!(done.report.clamped.is_empty());
        eprintln!("{path:?}: floors {:?}", done.floors);
        // Onto itself, the character stands on its clip's floor: nothing is lifted.
        assert_eq!(done.floors.0, done.floors.1, "{path:?}");
        assert_eq!(done.report.frames.len(), done.source_frames.len());
        for (f, (got, want)) in done.report.frames.iter().zip(&done.source_frames).enumerate() {
            assert!(got.root.distance(want.root) < 1e-5, "{path:?} frame {f}: root {} against {}", got.root, want.root);
            for (j, (a, b)) in got.pose.iter().zip(&want.pose).enumerate() {
                assert!(
                    same_rotation(a.to_quat(), b.to_quat(), 1e-5),
                    "{path:?} frame {f} joint {j}: {a:?} against {b:?}"
                );
            }
            // The baked clip plays the same at the frame's time.
            let t = f as f32 / marionette::document::retarget::FPS;
            let (root, played) = done.clip.pose_at(&asset.skeleton, t, &asset.skeleton.initial_pose());
            assert!(root.distance(want.root) < 1e-5, "{path:?} frame {f}: the clip's root");
            for (j, (a, b)) in played.iter().zip(&want.pose).enumerate() {
                let (a, b) = (a.to_quat(), b.to_quat());
                assert!(same_rotation(a, b, 1e-5), "{path:?} frame {f} joint {j}: the clip's {a:?} against {b:?}");
            }
        }
    }
}

/// A retargeting is worked out once per command: checking the options and posing after
/// get the same one, wherever the source's clip is paused and whatever motion the target
/// had; other settings work out another.
#[test]
fn a_retargeting_is_worked_out_once_per_command() {
    let doc = editor::two_puppets();
    let mut library = AssetLibrary::default();
    let (source, target) = (&doc.characters[0], &doc.characters[1]);
    let asset = library.shaped(target).unwrap();
    let settings = target.anim.as_ref().unwrap().retarget.clone().unwrap();
    let first = retarget(&mut library, source, target, &asset, &settings).unwrap();
    let mut paused_later = source.clone();
    paused_later.anim.iter_mut().for_each(|a| (a.time, a.playing) = (0.7, true));
    let before_its_clip = CharacterDoc { anim: None, ..target.clone() };
    let again = retarget(&mut library, &paused_later, &before_its_clip, &asset, &settings).unwrap();
    assert!(std::sync::Arc::ptr_eq(&first, &again));
    let unplanted = RetargetDoc { plant_feet: !settings.plant_feet, ..settings.clone() };
    let other = retarget(&mut library, source, target, &asset, &unplanted).unwrap();
    assert!(!std::sync::Arc::ptr_eq(&first, &other));
}

mod editor {
    //! The editor's retargeted clip against the document layer's (the oracle), and its
    //! edits: bake, stop, the humanoid map; all undoable; scene files keep them.

    use bevy::prelude::*;
    use marionette::document::AssetLibrary;
    use marionette::editor::edits::commands::Edit;
    use marionette::editor::edits::history::HistoryRequest;
    use marionette::editor::scene_doc::document::PendingScene;
    use marionette::formats::scene::{
        AnimDoc, CharacterDoc, CharacterId, MotionSourceDoc, PlacementDoc, RetargetDoc, SceneDoc, SourceDoc,
    };
    use marionette::rig::JointRotation;
    use marionette::rig::anim::Clip;
    use marionette::rig::humanoid::HumanBone;
    use marionette::scene::keyframes::ClipPlayer;

    use crate::common::scratch;
    use crate::edits::{edit, entity, request, scene_app, state};

    /// Two puppets: the first (id 1, small) waves its left arm and bends its knee over a
    /// second, keyed; the second (id 2, tall) plays its motion.
    pub(super) fn two_puppets() -> SceneDoc {
        let skeleton = marionette::formats::puppet::embedded_puppet().skeleton;
        let keyed: Vec<usize> =
            ["l_shoulder", "l_elbow", "l_knee", "pelvis"].iter().map(|n| skeleton.find(n).unwrap()).collect();
        let mut pose = skeleton.initial_pose();
        let mut clip = Clip::empty(skeleton.len()).with_pose_keyed(&keyed, &pose, 0.0);
        for (k, &j) in keyed.iter().enumerate() {
            pose[j] = JointRotation::euler_xyz(0.3 * k as f32, 0.1, -0.8 + 0.2 * k as f32);
        }
        clip = clip.with_pose_keyed(&keyed, &pose, 1.0);
        let source = CharacterDoc {
            id: Some(CharacterId(1)),
            placement: PlacementDoc::new(Vec3::new(-0.6, 0.0, 0.0), 0.0, 0.8),
            anim: Some(AnimDoc { keys: Some(clip), playing: false, ..AnimDoc::default() }),
            ..CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "small")
        };
        let settings = RetargetDoc::of(MotionSourceDoc::Character(CharacterId(1)));
        let target = CharacterDoc {
            id: Some(CharacterId(2)),
            placement: PlacementDoc::new(Vec3::new(0.6, 0.0, 0.0), 0.5, 1.3),
            anim: Some(AnimDoc { retarget: Some(settings), time: 0.4, playing: false, ..AnimDoc::default() }),
            ..CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "tall")
        };
        SceneDoc { characters: vec![source, target], ..SceneDoc::default() }
    }

    fn open(app: &mut App, doc: SceneDoc) {
        *app.world_mut().resource_mut::<PendingScene>() = PendingScene { doc: Some(doc), frame: false };
        for _ in 0..3 {
            app.update();
        }
    }

    fn player(app: &App, id: u64) -> ClipPlayer {
        app.world().get::<ClipPlayer>(entity(app, id)).unwrap().clone()
    }

    /// The clip the editor plays is the document layer's retargeting, key for key; baking
    /// keeps it and makes it the character's own; undo and redo go back and forth exactly;
    /// a bone assigned by hand is kept, undone, and saved.
    #[test]
    fn the_editor_plays_the_documents_retargeting_and_bakes_it() {
        let doc = two_puppets();
        let mut app = scene_app();
        open(&mut app, doc.clone());
        let mut library = AssetLibrary::default();
        let target = &doc.characters[1];
        let asset = library.load(&target.source).unwrap();
        let anim = target.anim.as_ref().unwrap();
        let oracle = marionette::document::retarget::anim_clip(&mut library, &doc, target, &asset, anim).unwrap();
        let playing = player(&app, 2);
        let said = app
            .world()
            .get::<marionette::editor::scene_doc::retarget::RetargetedFrom>(entity(&app, 2))
            .map(|r| r.report.clone());
        assert!(*playing.clip == oracle, "the editor's clip is not the document's: {said:?}");
        assert!(oracle.channels.iter().any(|c| c.keys().len() > 1), "the motion is keyed");
        let (retargeted, count) = state(&mut app);

        let baked = AnimDoc { keys: Some(oracle.clone()), retarget: None, ..playing.state.clone() };
        edit(
            &mut app,
            Edit::from(marionette::editor::edits::kinds::Clip { character: CharacterId(2), anim: Some(baked.clone()) }),
        );
        let now = player(&app, 2);
        assert!(
            *now.clip == oracle,
            "{:?} {:?} {:?}",
            now.state.retarget,
            now.state.keys.is_some(),
            now.clip.channels.iter().map(|c| c.keys().len()).sum::<usize>()
        );
        assert_eq!(player(&app, 2).state, baked);
        request(&mut app, HistoryRequest::Undo);
        app.update();
        assert_eq!(state(&mut app), (retargeted.clone(), count));
        assert!(*player(&app, 2).clip == oracle);

        let bones = [(HumanBone::LeftHand, "l_hand".to_string())].into_iter().collect();
        edit(&mut app, Edit::from(marionette::editor::edits::kinds::Humanoid { character: CharacterId(2), bones }));
        app.update();
        let (mapped, _) = state(&mut app);
        assert_eq!(mapped.characters[1].humanoid[&HumanBone::LeftHand], "l_hand");
        let path = scratch("retarget-editor").join("scene.ron");
        marionette::document::scenes::write_scene(&path, &mapped).unwrap();
        let read = marionette::document::scenes::read_scene(&path).unwrap();
        assert_eq!(read.characters[1].humanoid, mapped.characters[1].humanoid);
        assert_eq!(read.characters[1].anim.as_ref().unwrap().retarget, anim.retarget);
        request(&mut app, HistoryRequest::Undo);
        app.update();
        assert_eq!(state(&mut app), (retargeted.clone(), count));

        // The source's motion changes (its keys scaled in time): the clip follows.
        let mut source_anim = retargeted.characters[0].anim.clone().unwrap();
        let mut keys = source_anim.keys.take().unwrap();
        keys = keys.with_pose_keyed(&[1, 2], &[JointRotation::euler_xyz(0.5, 0.0, 0.0); 3], 2.0);
        source_anim.keys = Some(keys);
        edit(
            &mut app,
            Edit::from(marionette::editor::edits::kinds::Clip { character: CharacterId(1), anim: Some(source_anim) }),
        );
        app.update();
        let (changed, _) = state(&mut app);
        let oracle = marionette::document::retarget::anim_clip(&mut library, &changed, target, &asset, anim).unwrap();
        assert!(oracle.range.1 > 1.5, "the source's clip is longer now");
        assert!(*player(&app, 2).clip == oracle, "the editor's clip follows the source's motion");
    }
}

/// Blender's bones in `tests/data/blender_ta.txt`: for each pose label, each bone's head
/// and tail.
fn blender_bones() -> std::collections::BTreeMap<String, std::collections::BTreeMap<String, (Vec3, Vec3)>> {
    let text = std::fs::read_to_string(crate::common::path("tests/data/blender_ta.txt")).unwrap();
    let mut out: std::collections::BTreeMap<String, std::collections::BTreeMap<String, (Vec3, Vec3)>> =
        Default::default();
    let mut label = String::new();
    for line in text.lines() {
        if let Some(l) = line.strip_prefix("pose ") {
            label = l.to_string();
            continue;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        let n: Vec<f32> = words[2..].iter().map(|w| w.parse().unwrap()).collect();
        let (head, tail) = (Vec3::new(n[0], n[1], n[2]), Vec3::new(n[3], n[4], n[5]));
        out.entry(label.clone()).or_default().insert(words[1].to_string(), (head, tail));
    }
    out
}

/// A T-pose humanoid's clip on an A-pose one, both made with Blender: carried rest to
/// rest, the source's rest frame gives the target its own A-pose (every bone along its
/// rest bone as Blender has it, 0.1°); with bones following directions, the target's arms
/// point where Blender says the source's point, at rest (straight out) and with them
/// raised (2°), the motion read from the glTF file and from Blender's BVH of it.
#[test]
fn a_t_pose_clip_drives_an_a_pose_character() {
    let mut library = AssetLibrary::default();
    let blender = blender_bones();
    let source_path = crate::common::path("tests/data/blender_tpose.glb").to_path_buf();
    let source = file_motion_doc(&mut library, &source_path, None).unwrap();
    let target = doc_of(&mut library, crate::common::path("tests/data/blender_apose.glb"));
    let asset = library.shaped(&target).unwrap();
    let skeleton = &asset.skeleton;
    let from = MotionSourceDoc::File { path: source_path.clone(), clip: None };
    let angle = |a: Vec3, b: Vec3| a.normalize().dot(b.normalize()).clamp(-1.0, 1.0).acos().to_degrees();
    let direction = |frame: &Frame, joint: usize, child: usize| {
        let at = positions(skeleton, frame.root, &frame.pose);
        at[child] - at[joint]
    };
    let child_of = |j: usize| skeleton.joints().iter().position(|c| c.parent == Some(j));

    let rest = RetargetDoc { rest: marionette::rig::retarget::RestAlignment::OwnRest, ..RetargetDoc::of(from) };
    let done = retarget(&mut library, &source, &target, &asset, &rest).unwrap();
    let mut compared = 0;
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let (Some(child), Some((head, tail))) = (child_of(j), blender["apose rest"].get(&joint.name)) else { continue };
        let off = angle(direction(&done.report.frames[0], j, child), *tail - *head);
        assert!(off < 0.1, "{}: {off}° off its rest", joint.name);
        compared += 1;
    }
    assert!(compared >= 14, "{compared} bones compared");

    // The same motion from the glTF file and from Blender's BVH of it.
    for file in ["tests/data/blender_tpose.glb", "tests/data/blender_tpose.bvh"] {
        let path = crate::common::path(file).to_path_buf();
        let source = file_motion_doc(&mut library, &path, None).unwrap();
        let follow = RetargetDoc::of(MotionSourceDoc::File { path, clip: None });
        let done = retarget(&mut library, &source, &target, &asset, &follow).unwrap();
        for (frame, label) in [(0, "tpose 0"), (15, "tpose 12")] {
            for name in ["upper_arm.L", "upper_arm.R", "forearm.L", "thigh.L", "shin.R", "spine"] {
                let j = skeleton.find(name).unwrap();
                let (head, tail) = blender[label][name];
                let off = angle(direction(&done.report.frames[frame], j, child_of(j).unwrap()), tail - head);
                assert!(off < 2.0, "{file} {label}: {name} {off}° off the source's");
            }
        }
        let raised = direction(
            &done.report.frames[15],
            skeleton.find("upper_arm.L").unwrap(),
            skeleton.find("forearm.L").unwrap(),
        );
        assert!(raised.normalize().y > 0.9, "{file}: the arm is raised: {raised}");
    }
}

/// A pose kept on the puppet, put on the SMPL body (whose joints have other names) through
/// their humanoid maps: each posed arm bone points as the puppet's (2°); mirrored, the
/// body's right arm points as the puppet's left, reflected in x.
#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn a_pose_carries_to_a_rig_with_other_names_as_it_was_or_mirrored() {
    use marionette::document::retarget::pose_onto;
    use marionette::editor::edits::pose_library::pose_by_name;
    let data = crate::common::data_dir();
    let puppet = marionette::formats::puppet::embedded_puppet();
    let body = marionette::formats::load_character(&data.join("smpl")).unwrap();
    let (p_map, b_map) = (humanoid_map(&puppet, &Default::default()), humanoid_map(&body, &Default::default()));
    let mut pose = puppet.skeleton.initial_pose();
    let named = |n: &str| puppet.skeleton.find(n).unwrap();
    pose[named("l_shoulder")] = JointRotation::euler_xyz(0.4, 0.2, -1.1);
    pose[named("l_elbow")] = JointRotation::euler_xyz(0.0, -0.9, 0.0);
    let joints = [named("l_shoulder"), named("l_elbow")];
    let copied = pose_by_name(&puppet.skeleton, &pose, &joints);
    let p_at = positions(&puppet.skeleton, puppet.skeleton.joint(0).rest_offset, &pose);
    let direction = |at: &[Vec3], map: &HumanoidMap, a: HumanBone, b: HumanBone| at[map[&b]] - at[map[&a]];
    use HumanBone::*;
    for mirrored in [false, true] {
        let joints = pose_onto(
            (&body.skeleton, &b_map),
            &body.skeleton.initial_pose(),
            &copied,
            Some((&puppet.skeleton, &p_map)),
            mirrored,
        );
        assert_eq!(joints.len(), 2, "the two posed bones, mapped");
        let mut b_pose = body.skeleton.initial_pose();
        joints.iter().for_each(|&(j, r)| b_pose[j] = r);
        let b_at = positions(&body.skeleton, body.skeleton.joint(0).rest_offset, &b_pose);
        let reflect = |v: Vec3| if mirrored { Vec3::new(-v.x, v.y, v.z) } else { v };
        let (upper, lower, hand) =
            if mirrored { (RightUpperArm, RightLowerArm, RightHand) } else { (LeftUpperArm, LeftLowerArm, LeftHand) };
        for ((a, b), (sa, sb)) in
            [((upper, lower), (LeftUpperArm, LeftLowerArm)), ((lower, hand), (LeftLowerArm, LeftHand))]
        {
            let want = reflect(direction(&p_at, &p_map, sa, sb));
            let got = direction(&b_at, &b_map, a, b);
            let off = want.angle_between(got).to_degrees();
            assert!(off < 2.0, "mirrored {mirrored}: {a:?} {off}° off");
        }
    }
}

/// A target whose elbow is limited: the bent source elbow is clamped into the limits and
/// the report names the elbow in the frames it clamped; the other bones still point as the
/// source's.
#[test]
fn the_targets_limits_clamp_and_the_report_says_where() {
    use marionette::rig::retarget::{Humanoid, RestAlignment, Retargeter};
    use marionette::rig::{DofLimits, RawJoint};
    let source = marionette::formats::puppet::embedded_puppet().skeleton;
    let raw: Vec<RawJoint> = source
        .joints()
        .iter()
        .map(|j| {
            let mut raw = RawJoint::new(j.name.clone(), j.parent, j.rest_offset);
            if j.name == "l_elbow" {
                raw.limits = DofLimits { min: Vec3::splat(-0.2), max: Vec3::splat(0.2) };
            }
            raw
        })
        .collect();
    let target = Skeleton::build(raw).unwrap();
    let map = marionette::rig::humanoid::detect(&source).unwrap();
    let side = |skeleton| Humanoid { skeleton, map: &map, floor: 0.0, rest_floor: 0.0, soles: &[], stands: None };
    let retargeter = Retargeter::new(side(&source), side(&target), RestAlignment::Directions).unwrap();
    let elbow = source.find("l_elbow").unwrap();
    let frames: Vec<Frame> = (0..4)
        .map(|f| {
            let mut pose = source.initial_pose();
            pose[elbow] = JointRotation::euler_xyz(0.0, 0.0, 0.1 + 0.4 * f as f32);
            Frame::posed(source.joint(0).rest_offset, pose)
        })
        .collect();
    let done = retargeter.motion(&frames, 30.0, false);
    // 0.1 fits within ±0.2; 0.5, 0.9, 1.3 do not.
    assert_eq!(done.clamped, vec![(1, elbow), (2, elbow), (3, elbow)]);
    for frame in &done.frames {
        let held = frame.pose[elbow].to_euler(marionette::rig::EulerOrder::Xyz);
        assert!(held.z <= 0.2 + 1e-5 && held.z >= -0.2 - 1e-5, "clamped: {held}");
    }
}

/// A scene file keeps a retargeting's file (and a motion file its clip names) relative to
/// its folder, as it keeps sources, and reading it finds them again from there.
#[test]
fn a_scene_file_keeps_the_motion_file_relative_to_its_folder() {
    use marionette::document::scenes::{read_scene, write_scene};
    use marionette::formats::scene::{AnimDoc, SceneDoc};
    let dir = crate::common::scratch("retarget-relative");
    let motion = dir.join("clips").join("walk.glb");
    let skel = dir.join("clips").join("rig.skel");
    let anim = dir.join("clips").join("walk.anim");
    let mut doc = SceneDoc::default();
    for (path, clip) in [(motion.clone(), Some("Walk".to_string())), (skel.clone(), Some(anim.display().to_string()))] {
        let retarget = Some(RetargetDoc::of(MotionSourceDoc::File { path, clip }));
        let c = CharacterDoc {
            anim: Some(AnimDoc { retarget, ..AnimDoc::default() }),
            ..CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "a")
        };
        doc.characters.push(c);
    }
    let scene = dir.join("scene.ron");
    write_scene(&scene, &doc).unwrap();
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(
        text.contains("\"clips/walk.glb\"") && text.contains("\"clips/walk.anim\"") && text.contains("\"Walk\""),
        "{text}"
    );
    assert!(!text.contains(&dir.display().to_string()), "no absolute path: {text}");
    let read = read_scene(&scene).unwrap();
    let from = |i: usize| read.characters[i].anim.as_ref().unwrap().retarget.as_ref().unwrap().from.clone();
    assert_eq!(from(0), MotionSourceDoc::File { path: motion, clip: Some("Walk".into()) });
    assert_eq!(from(1), MotionSourceDoc::File { path: skel, clip: Some(anim.display().to_string()) });
}

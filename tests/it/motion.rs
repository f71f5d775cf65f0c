//! One pose at a time t: the ECS, `render --data` and `export` pose a scene that mixes every
//! kind of motion as the motion service does; the command line's solving edits hold on the
//! pose that is written, whatever their order.

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::{Mat4, Quat, Vec3};

use marionette::document::AssetLibrary;
use marionette::document::motion::{Clock, Playing, pose_at};
use marionette::formats::scene::{
    AnimDoc, CameraDoc, CharacterDoc, MotionSourceDoc, PlacementDoc, PlaybackDoc, RetargetDoc, SceneDoc, SmplDoc,
    SourceDoc,
};

use crate::common::{data_dir, scratch};

fn rig(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs").join(file)
}

/// A scene of every kind of motion, each character `x` metres along: an SMPL body playing
/// its clip and also given a CMU walk retargeted onto it (the walk plays over the clip), a
/// glTF character playing its own clip, the CSE169 wasp playing its keyframes, a BVH
/// skeleton playing itself and a Mixamo character playing the BVH retargeted.
fn every_motion() -> SceneDoc {
    let data = data_dir();
    let walk = rig("cmu_walk.bvh");
    let at = |x: f32| PlacementDoc::new(Vec3::new(x, 0.0, 0.0), 0.0, 1.0);
    let retargeted = || AnimDoc {
        retarget: Some(RetargetDoc::of(MotionSourceDoc::File { path: walk.clone(), clip: None })),
        ..AnimDoc::default()
    };
    let smpl = SmplDoc {
        clip: Some("smpl_quaternions_mosh_cmu_7516.txt".into()),
        upright: true,
        playing: true,
        ..SmplDoc::default()
    };
    let body = CharacterDoc {
        smpl: Some(smpl),
        anim: Some(retargeted()),
        placement: at(-2.0),
        ..CharacterDoc::new(SourceDoc::File(data.join("smpl")), "body")
    };
    let cesium = CharacterDoc {
        playback: Some(PlaybackDoc { clip: Some("0".into()), playing: true, ..PlaybackDoc::default() }),
        placement: at(-1.0),
        ..CharacterDoc::new(SourceDoc::File(data.join("khronos/CesiumMan.glb")), "cesium")
    };
    let wasp = CharacterDoc {
        anim: Some(AnimDoc::of(data.join("cse169/project3/wasp_walk.anim"))),
        placement: at(0.0),
        ..CharacterDoc::new(SourceDoc::File(data.join("cse169/project3/wasp.skel")), "wasp")
    };
    // The BVH file is in centimetres: a hundredth of its size stands as tall as the others.
    let bvh = CharacterDoc {
        anim: Some(AnimDoc::of(&walk)),
        placement: PlacementDoc::new(Vec3::new(1.0, 0.0, 0.0), 0.0, 0.01),
        ..CharacterDoc::new(SourceDoc::File(walk.clone()), "bvh")
    };
    let mixamo = CharacterDoc {
        anim: Some(retargeted()),
        placement: at(2.0),
        ..CharacterDoc::new(SourceDoc::File(rig("mixamo.glb")), "mixamo")
    };
    let camera =
        CameraDoc { focus: Vec3::new(0.0, 0.9, 0.0), yaw: 0.0, pitch: -0.1, distance: 7.0, fov: 40.0, ortho: None };
    let characters = vec![body, cesium, wasp, bvh, mixamo];
    let mut doc = SceneDoc { characters, camera: Some(camera), ..SceneDoc::default() };
    // CesiumMan's clip by its name in the file.
    let mut library = AssetLibrary::default();
    let part = library.part_of_source(&doc.characters[1].source).expect("CesiumMan has a clip");
    doc.characters[1].playback.as_mut().unwrap().clip = Some(part.clips[0].name.clone());
    doc
}

const TIMES: [f32; 3] = [0.25, 0.75, 1.25];

/// Every character of `doc` in the ECS, each joint's matrix against the motion service's
/// (the same scene, paused at each of three times), within 1e-5 m.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn the_ecs_poses_every_kind_of_motion_as_the_motion_service_does() {
    use marionette::editor::ScenePlugin;
    use marionette::editor::scene_doc::document::{PendingScene, SceneCharacter};
    use marionette::scene::{Character, CurrentJointToWorld};

    for t in TIMES {
        let mut doc = every_motion();
        marionette::document::options::pause_clips_at(&mut doc, t);
        let mut app = crate::ecs::app();
        app.add_plugins(ScenePlugin);
        *app.world_mut().resource_mut::<PendingScene>() = PendingScene { doc: Some(doc.clone()), frame: false };
        (0..4).for_each(|_| app.update());
        let mut library = AssetLibrary::default();
        let mut checked = 0;
        let mut query = app.world_mut().query::<(&SceneCharacter, &Character)>();
        let characters: Vec<_> = query.iter(app.world()).map(|(s, c)| (s.name.clone(), c.clone())).collect();
        for (name, character) in characters {
            let c = doc.characters.iter().find(|c| c.name == name).unwrap();
            let asset = library.shaped(c).unwrap();
            let (motion, _) = marionette::document::export::character_motion(&mut library, &doc, c, &asset).unwrap();
            let want = motion.pose_now(&asset.skeleton).joint_to_world(&asset.skeleton, Mat4::IDENTITY);
            for (j, &e) in character.joints.iter().enumerate() {
                let got = app.world().get::<CurrentJointToWorld>(e).unwrap().0;
                let off = got.w_axis.truncate().distance(want[j].w_axis.truncate());
                assert!(off < 1e-5, "{name} at {t} s: joint {j} {off} m off the motion service");
                assert!(got.abs_diff_eq(want[j], 1e-4), "{name} at {t} s: joint {j}");
            }
            checked += 1;
        }
        assert_eq!(checked, 5, "every character is in the ECS");
    }
}

/// The joints `render --data` writes for a sequence at three times equal those of `export
/// --time T --out x.glb` of the same scene (read from the file's nodes), within 1e-5 m.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn the_picture_and_the_export_show_one_pose() {
    let dir = scratch("one-pose");
    let scene = dir.join("scene.ron");
    let doc = every_motion();
    marionette::document::scenes::write_scene(&scene, &doc).unwrap();
    let out = dir.join("f_%02d.png");
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["render", scene.to_str().unwrap(), "--out", out.to_str().unwrap(), "--data"])
        .args(["--from", "0.25", "--to", "1.25", "--fps", "2", "--width", "320", "--height", "120"])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let coco: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("f_all.json")).unwrap()).unwrap();
    let images = coco["images"].as_array().unwrap();
    assert_eq!(images.len(), TIMES.len());
    let mut library = AssetLibrary::default();
    let mut worst = 0.0f32;
    let (mut compared, mut seen) = (0, std::collections::BTreeSet::new());
    for (k, t) in TIMES.iter().enumerate() {
        let glb = dir.join(format!("x{k}.glb"));
        let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
            .args(["export", scene.to_str().unwrap(), "--time", &t.to_string(), "--out", glb.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        let exported = joints_of_glb(&glb);
        let image_id = &images[k]["id"];
        let annotations = coco["annotations"].as_array().unwrap().iter().filter(|a| &a["image_id"] == image_id);
        for ann in annotations {
            let name = ann["character"].as_str().unwrap();
            seen.insert(name.to_owned());
            let c = doc.characters.iter().find(|c| c.name == name).unwrap();
            let asset = library.shaped(c).unwrap();
            let map = marionette::document::retarget::humanoid_map(&asset, &c.humanoid);
            for (bone, p) in ann["joints_3d"].as_object().unwrap() {
                let bone: marionette::rig::humanoid::HumanBone = ron::from_str(bone).unwrap();
                let p: Vec<f32> = serde_json::from_value(p.clone()).unwrap();
                let joint = &asset.skeleton.joint(*map.get(&bone).unwrap()).name;
                let q = exported[name][joint];
                let off = Vec3::new(p[0], p[1], p[2]).distance(q);
                worst = worst.max(off);
                assert!(off < 1e-5, "{name} at {t} s: {bone:?} ({joint}) drawn {p:?}, exported {q}: {off} m apart");
                compared += 1;
            }
        }
    }
    assert!(seen.len() >= 3, "joints of only {seen:?} compared");
    eprintln!("{compared} joints of {seen:?} compared over {} times; worst {worst:e} m", TIMES.len());
}

/// Every skin's joints in a GLB, by skin (character) and node name, in the world, from the
/// file's node tree (an independent reading: no code of ours).
fn joints_of_glb(path: &Path) -> std::collections::HashMap<String, std::collections::HashMap<String, Vec3>> {
    let gltf = gltf::Gltf::from_slice(&std::fs::read(path).unwrap()).unwrap();
    let mut world = vec![Mat4::IDENTITY; gltf.nodes().count()];
    fn walk(node: gltf::Node, parent: Mat4, world: &mut [Mat4]) {
        let m = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        world[node.index()] = m;
        node.children().for_each(|c| walk(c, m, world));
    }
    for scene in gltf.scenes() {
        scene.nodes().for_each(|n| walk(n, Mat4::IDENTITY, &mut world));
    }
    gltf.skins()
        .map(|skin| {
            let joints = skin.joints().map(|j| (j.name().unwrap_or("").to_owned(), world[j.index()].w_axis.truncate()));
            (skin.name().unwrap_or("").to_owned(), joints.collect())
        })
        .collect()
}

/// The motion service's precedence: SMPL, then keyframes over it, then the source's
/// clips over both, on a chain of three joints.
#[test]
fn later_motions_win_the_joints_they_move() {
    use marionette::rig::{JointRotation, RawJoint, Skeleton};
    let skeleton = Skeleton::build(vec![
        RawJoint::new("a", None, Vec3::ZERO),
        RawJoint::new("b", Some(0), Vec3::Y),
        RawJoint::new("c", Some(1), Vec3::Y),
    ])
    .unwrap();
    let still = vec![JointRotation::euler_xyz(0.1, 0.0, 0.0); 3];
    let nothing = pose_at(&skeleton, &still, &[], &Playing::default());
    assert_eq!(nothing.rotations, still, "nothing plays: the still pose");
    assert_eq!(nothing.root, None);
    // Keys for joint b only: a and c keep the still pose.
    let mut clip = marionette::rig::anim::Clip::empty(3);
    let turn = JointRotation::euler_xyz(0.0, 0.5, 0.0);
    let mut posed = still.clone();
    posed[1] = turn;
    clip = clip.with_pose_keyed(&[1], &posed, 0.0);
    let clock = Clock { time: 0.0, playing: false, speed: 1.0, looping: true };
    let now = pose_at(&skeleton, &still, &[], &Playing { keyframes: Some((&clip, clock)), ..Playing::default() });
    assert_eq!(now.rotations[0], still[0]);
    assert!(now.rotations[1].to_quat().angle_between(Quat::from_rotation_y(0.5)) < 1e-6);
    assert_eq!(now.rotations[2], still[2]);
}

/// Two-bone and look-at on one character, given in either order: the written pose has
/// the hand on its target within 1e-4 of the arm and the face within 0.1° of its target,
/// and the printed report says so of that pose.
#[test]
fn solving_edits_hold_together_on_the_written_pose() {
    let xbot = rig("mixamo.glb");
    let mut library = AssetLibrary::default();
    let doc = marionette::document::scenes::file_doc(&mut library, &xbot).unwrap();
    let c = &doc.characters[0];
    let asset = library.shaped(c).unwrap();
    let skeleton = &asset.skeleton;
    let map = marionette::document::retarget::humanoid_map(&asset, &c.humanoid);
    use marionette::rig::humanoid::HumanBone;
    let bone = |b: HumanBone| *map.get(&b).unwrap();
    let (hand, head) = (bone(HumanBone::LeftHand), bone(HumanBone::Head));
    let mut rest = vec![Mat4::IDENTITY; skeleton.len()];
    let placement = c.placement.to_mat4();
    marionette::rig::forward_kinematics(skeleton, &skeleton.initial_pose(), placement, &mut rest);
    let at = |j: usize| rest[j].w_axis.truncate();
    let shoulder = at(skeleton.parent(skeleton.parent(hand).unwrap()).unwrap());
    let arm =
        shoulder.distance(at(skeleton.parent(hand).unwrap())) + at(skeleton.parent(hand).unwrap()).distance(at(hand));
    // A target in reach in front of the shoulder, the pole below; a look far to one side.
    let target = shoulder + Vec3::new(0.1, -0.3, 0.35) * arm;
    let pole = shoulder + Vec3::new(0.0, -1.0, -0.5) * arm;
    let look = at(head) + Vec3::new(2.0, 0.3, 1.5);
    let (hand_name, head_name) = (&skeleton.joint(hand).name, &skeleton.joint(head).name);
    let two_bone = format!("{hand_name}={},{},{}@{},{},{}", target.x, target.y, target.z, pole.x, pole.y, pole.z);
    let look_at = format!("{head_name}={},{},{}", look.x, look.y, look.z);
    let dir = scratch("solving-edits");
    for (k, order) in [["--two-bone", "--look-at"], ["--look-at", "--two-bone"]].iter().enumerate() {
        let value = |flag: &str| if flag == "--two-bone" { two_bone.clone() } else { look_at.clone() };
        let out = dir.join(format!("posed{k}.glb"));
        let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
            .args(["export", xbot.to_str().unwrap(), "--out", out.to_str().unwrap()])
            .args([order[0].to_string(), value(order[0]), order[1].to_string(), value(order[1])])
            .output()
            .unwrap();
        let said = String::from_utf8_lossy(&output.stderr).into_owned() + &String::from_utf8_lossy(&output.stdout);
        assert!(output.status.success(), "{said}");
        let joints = joints_of_glb(&out);
        let skin = joints.values().next().unwrap();
        let off = skin[hand_name].distance(target);
        assert!(off <= 1e-4 * arm, "{order:?}: the hand {off} m from its target (arm {arm} m)\n{said}");
        let reported = said.lines().find(|l| l.contains("two-bone")).expect("a two-bone report");
        assert!(reported.contains("reached"), "{reported}");
        // The face: where the character faces at rest (square to its hips' line), in the
        // head's frame, turned with the head.
        let facing =
            marionette::rig::look_at::facing(at(bone(HumanBone::RightUpperLeg)), at(bone(HumanBone::LeftUpperLeg)));
        let rest_head = marionette::rig::ik::rotation_of(rest[head]);
        let face = gltf_world_rotation(&out, head_name) * (rest_head.inverse() * facing);
        let degrees = face.angle_between(look - skin[head_name]).to_degrees();
        assert!(degrees <= 0.1, "{order:?}: the face {degrees}° off its target\n{said}");
        let reported = said.lines().find(|l| l.contains("look-at")).expect("a look-at report");
        assert!(reported.contains("° off"), "{reported}");
    }
}

/// The world rotation of the node named `name` in a GLB.
fn gltf_world_rotation(path: &Path, name: &str) -> Quat {
    let gltf = gltf::Gltf::from_slice(&std::fs::read(path).unwrap()).unwrap();
    let mut parents = vec![None; gltf.nodes().count()];
    for n in gltf.nodes() {
        n.children().for_each(|c| parents[c.index()] = Some(n.index()));
    }
    let nodes: Vec<_> = gltf.nodes().collect();
    let mut at = nodes.iter().find(|n| n.name() == Some(name)).unwrap().index();
    let mut m = Mat4::IDENTITY;
    loop {
        m = Mat4::from_cols_array_2d(&nodes[at].transform().matrix()) * m;
        match parents[at] {
            Some(p) => at = p,
            None => break,
        }
    }
    marionette::rig::ik::rotation_of(m)
}

/// Every combination of `--preset`, `--pose`, `--hand`, `--ik`, `--two-bone` and
/// `--look-at` on one Mixamo character: every distance and angle reported is the written
/// pose's, and every goal reported reached holds on it (the hands within 1e-4 of the arm,
/// the face within 0.1°).
#[test]
fn every_combination_of_posing_options_reports_the_written_pose() {
    use marionette::document::options::{PoseOptions, PoseSpecs, apply_options};
    use marionette::rig::humanoid::HumanBone;
    let xbot = rig("mixamo.glb");
    let mut library = AssetLibrary::default();
    let base = marionette::document::scenes::file_doc(&mut library, &xbot).unwrap();
    let asset = library.shaped(&base.characters[0]).unwrap();
    let skeleton = &asset.skeleton;
    let map = marionette::document::retarget::humanoid_map(&asset, &base.characters[0].humanoid);
    let bone = |b: HumanBone| *map.get(&b).unwrap();
    let name = |b: HumanBone| skeleton.joint(bone(b)).name.clone();
    let mut rest = vec![Mat4::IDENTITY; skeleton.len()];
    marionette::rig::forward_kinematics(skeleton, &skeleton.initial_pose(), Mat4::IDENTITY, &mut rest);
    let at = |j: usize| rest[j].w_axis.truncate();
    let (left, right, head) = (bone(HumanBone::LeftHand), bone(HumanBone::RightHand), bone(HumanBone::Head));
    let arm = at(left).distance(at(skeleton.parent(left).unwrap()))
        + at(skeleton.parent(left).unwrap()).distance(at(skeleton.parent(skeleton.parent(left).unwrap()).unwrap()));
    let (reach, ik_goal, look) = (
        at(left) + Vec3::new(0.2, -0.4, 0.4) * arm,
        at(right) + Vec3::new(-0.1, -0.5, 0.3) * arm,
        at(head) + Vec3::new(-1.5, 0.5, 2.0),
    );
    let facing =
        marionette::rig::look_at::facing(at(bone(HumanBone::RightUpperLeg)), at(bone(HumanBone::LeftUpperLeg)));
    let face = marionette::rig::ik::rotation_of(rest[head]).inverse() * facing;
    let xyz = |v: Vec3| format!("{},{},{}", v.x, v.y, v.z);
    let number = |line: &str, before: &str, after: &str| -> f32 {
        let tail = &line[line.find(before).unwrap() + before.len()..];
        tail[..tail.find(after).unwrap_or(tail.len())].trim().parse().unwrap()
    };
    let mut checked = 0;
    for mask in 0..64u32 {
        let on = |k: u32| mask & (1 << k) != 0;
        let specs = PoseSpecs {
            preset: on(0).then(|| "wave".parse().unwrap()),
            poses: if on(1) { vec![format!("{}=0.2,0.3,0", name(HumanBone::Chest)).parse().unwrap()] } else { vec![] },
            hands: if on(2) { vec!["left=fist".parse().unwrap()] } else { vec![] },
            ik: if on(3) {
                vec![format!("{}={}", name(HumanBone::RightHand), xyz(ik_goal)).parse().unwrap()]
            } else {
                vec![]
            },
            two_bone: if on(4) {
                vec![format!("{}={}", name(HumanBone::LeftHand), xyz(reach)).parse().unwrap()]
            } else {
                vec![]
            },
            look_at: if on(5) {
                vec![format!("{}={}", name(HumanBone::Head), xyz(look)).parse().unwrap()]
            } else {
                vec![]
            },
            ..PoseSpecs::default()
        };
        let mut doc = base.clone();
        let options = PoseOptions { specs, still: true, ..PoseOptions::default() };
        let notes = apply_options(&mut doc, &options, &mut library).unwrap();
        let c = &doc.characters[0];
        let (motion, _) = marionette::document::export::character_motion(&mut library, &doc, c, &asset).unwrap();
        let world = motion.pose_now(skeleton).joint_to_world(skeleton, c.placement.to_mat4());
        let place = |j: usize| world[j].w_axis.truncate();
        for line in &notes {
            let (measured, tolerance, holds) = if line.contains("two-bone") {
                let d = place(left).distance(reach);
                (d, 1e-5, d <= 1e-4 * arm)
            } else if line.contains(": ik ") {
                let d = place(right).distance(ik_goal);
                (d, 1e-5, d <= 1e-4 * arm)
            } else if line.contains("look-at") {
                let now = marionette::rig::ik::rotation_of(world[head]) * face;
                let degrees = now.angle_between(look - place(head)).to_degrees();
                let said = number(line, "the face", "°");
                assert!((said - degrees).abs() <= 2e-3, "mask {mask}: {line}: measured {degrees}°");
                assert!(said > 0.1 || degrees <= 0.1 + 2e-3, "mask {mask}: {line}: measured {degrees}°");
                checked += 1;
                continue;
            } else {
                continue;
            };
            let said = number(line, "distance", ",");
            assert!((said - measured).abs() <= tolerance, "mask {mask}: {line}: measured {measured}");
            if line.contains(": reached") {
                assert!(holds, "mask {mask}: {line}: measured {measured} (arm {arm})");
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 3 * 32, "each goal reported in every combination that asks for it");
}

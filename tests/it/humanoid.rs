//! The humanoid map found from structure: the SMPL body, the puppet, the four 6.837 models
//! (numbered joints, hips hung from the chest), CesiumMan and RiggedFigure each get every
//! limb bone, the hips and the chest, with left on the character's left.

use marionette::rig::Skeleton;
use marionette::rig::humanoid::{HumanBone, HumanoidMap, detect};

fn named(skeleton: &Skeleton, map: &HumanoidMap) -> Vec<(HumanBone, String)> {
    map.iter().map(|(b, &j)| (*b, skeleton.joint(j).name.clone())).collect()
}

fn expect(skeleton: &Skeleton, pairs: &[(HumanBone, &str)]) {
    let map = detect(skeleton).expect("a humanoid");
    for (bone, joint) in pairs {
        let found = map.get(bone).map(|&j| skeleton.joint(j).name.as_str());
        assert_eq!(found, Some(*joint), "{bone:?} in {:?}", named(skeleton, &map));
    }
}

use HumanBone::*;

#[test]
fn the_puppet_maps_by_its_structure_and_names() {
    let puppet = marionette::formats::puppet::embedded_puppet();
    expect(
        &puppet.skeleton,
        &[
            (Hips, "pelvis"),
            (Spine, "spine"),
            (Chest, "chest"),
            (Neck, "neck"),
            (Head, "head"),
            (LeftUpperArm, "l_shoulder"),
            (LeftLowerArm, "l_elbow"),
            (LeftHand, "l_wrist"),
            (RightUpperArm, "r_shoulder"),
            (RightHand, "r_wrist"),
            (LeftUpperLeg, "l_hip"),
            (LeftLowerLeg, "l_knee"),
            (LeftFoot, "l_ankle"),
            (LeftToes, "l_toe"),
            (RightUpperLeg, "r_hip"),
            (RightToes, "r_toe"),
        ],
    );
}

#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn the_smpl_body_maps_collars_to_shoulders_and_its_feet_to_toes() {
    let data = crate::common::data_dir();
    let asset = marionette::formats::load_character(&data.join("smpl")).unwrap();
    expect(
        &asset.skeleton,
        &[
            (Hips, "Pelvis"),
            (Spine, "Spine1"),
            (Chest, "Spine3"),
            (Neck, "Neck"),
            (Head, "Head"),
            (LeftShoulder, "L_Collar"),
            (LeftUpperArm, "L_Shoulder"),
            (LeftLowerArm, "L_Elbow"),
            (LeftHand, "L_Wrist"),
            (RightShoulder, "R_Collar"),
            (RightHand, "R_Wrist"),
            (LeftUpperLeg, "L_Hip"),
            (LeftLowerLeg, "L_Knee"),
            (LeftFoot, "L_Ankle"),
            (LeftToes, "L_Foot"),
            (RightFoot, "R_Ankle"),
        ],
    );
}

#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn the_6837_models_map_by_structure_alone() {
    let data = crate::common::data_dir();
    for k in 1..=4 {
        let skeleton =
            marionette::formats::character::load_skeleton(&data.join(format!("mit6837/Model{k}.skel"))).unwrap();
        // Numbered joints: the hips (joint2) hang from the chest (joint0), the legs from
        // joint4 and joint8, the arms from the chest (each arm's first joint on the chest
        // itself, its bone the clavicle); the left side is +x.
        expect(
            &skeleton,
            &[
                (Hips, "joint2"),
                (Chest, "joint0"),
                (RightUpperLeg, "joint5"),
                (RightLowerLeg, "joint6"),
                (RightFoot, "joint7"),
                (LeftUpperLeg, "joint9"),
                (LeftLowerLeg, "joint10"),
                (LeftFoot, "joint11"),
                (RightShoulder, "joint12"),
                (RightUpperArm, "joint13"),
                (RightLowerArm, "joint14"),
                (LeftShoulder, "joint15"),
                (LeftUpperArm, "joint16"),
                (LeftLowerArm, "joint17"),
            ],
        );
        // Each arm is three joints from the chest's own place: clavicle, upper arm, and the
        // elbow, whose lower arm ends in no joint: no hand.
        let map = detect(&skeleton).unwrap();
        assert!(
            !map.contains_key(&LeftHand) && !map.contains_key(&RightHand),
            "Model{k}: {:?}",
            named(&skeleton, &map)
        );
    }
}

#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn the_khronos_figures_map_every_limb_with_left_as_named() {
    let data = crate::common::data_dir();
    for file in ["khronos/CesiumMan.glb", "khronos/RiggedFigure.glb"] {
        let skeleton = marionette::formats::character::load_skeleton(&data.join(file)).unwrap();
        let map = detect(&skeleton).expect(file);
        for bone in [Hips, Spine, Chest, Neck, Head, LeftUpperArm, LeftLowerArm, LeftHand, RightUpperArm]
            .into_iter()
            .chain([RightLowerArm, RightHand, LeftUpperLeg, LeftLowerLeg, LeftFoot, RightUpperLeg, RightLowerLeg])
            .chain([RightFoot])
        {
            assert!(map.contains_key(&bone), "{file}: no {bone:?} in {:?}", named(&skeleton, &map));
        }
        for bone in [LeftUpperArm, LeftHand, LeftUpperLeg, LeftFoot] {
            let name = &skeleton.joint(map[&bone]).name;
            assert!(name.contains("_L"), "{file}: {bone:?} is {name}");
        }
    }
}

/// A pose carried from a character onto itself is that pose (within 1e-5 in every joint's
/// world rotation); carried from the puppet onto the SMPL body, every mapped bone turns
/// in the world exactly as the puppet's did from its initial pose.
#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn a_retargeted_pose_turns_each_bone_as_its_source_turned() {
    use glam::Quat;
    use marionette::rig::JointRotation;
    use marionette::rig::retarget::{RestAlignment, retarget_pose};
    let puppet = marionette::formats::puppet::embedded_puppet().skeleton;
    let map = detect(&puppet).unwrap();
    let mut pose = puppet.initial_pose();
    for (k, rotation) in pose.iter_mut().enumerate() {
        *rotation = JointRotation::euler_xyz(0.1 * k as f32, -0.05 * k as f32, 0.3);
    }
    let world = |skeleton: &Skeleton, pose: &[JointRotation]| {
        let mut out = vec![Quat::IDENTITY; skeleton.len()];
        for j in 0..skeleton.len() {
            let parent = skeleton.parent(j).map_or(Quat::IDENTITY, |p| out[p]);
            out[j] = parent * pose[j].to_quat();
        }
        out
    };
    for rest in [RestAlignment::Directions, RestAlignment::OwnRest] {
        let same = retarget_pose((&puppet, &map), &pose, (&puppet, &map), rest).unwrap();
        let (want, got) = (world(&puppet, &pose), world(&puppet, &same));
        for &j in map.values() {
            assert!(want[j].angle_between(got[j]) < 1e-5, "{rest:?}: {}", puppet.joint(j).name);
        }
    }
    let data = crate::common::data_dir();
    let body = marionette::formats::load_character(&data.join("smpl")).unwrap().skeleton;
    let body_map = detect(&body).unwrap();
    let carried = retarget_pose((&puppet, &map), &pose, (&body, &body_map), RestAlignment::OwnRest).unwrap();
    let (p_rest, p_now) = (world(&puppet, &puppet.initial_pose()), world(&puppet, &pose));
    let (b_rest, b_now) = (world(&body, &body.initial_pose()), world(&body, &carried));
    for (bone, &bj) in &body_map {
        let Some(&pj) = map.get(bone) else { continue };
        let (turned_source, turned_target) = (p_now[pj] * p_rest[pj].inverse(), b_now[bj] * b_rest[bj].inverse());
        assert!(turned_source.angle_between(turned_target) < 1e-4, "{bone:?}");
    }
}

/// Homer's rig (the chest its root, the abdomen hung below it): every limb from the joint
/// at the shoulder or hip, the chest never an arm bone.
#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn homer_maps_his_arms_from_the_shoulders() {
    let data = crate::common::data_dir();
    let homer = marionette::formats::load_character(&data.join("homer/homer.json")).unwrap();
    expect(
        &homer.skeleton,
        &[
            (Hips, "LowerAbdomen"),
            (Chest, "Root"),
            (Head, "Head"),
            (LeftUpperArm, "Shoulder.L"),
            (LeftLowerArm, "Elbow.L"),
            (LeftHand, "Wrist.L"),
            (RightUpperArm, "Shoulder.R"),
            (RightHand, "Wrist.R"),
            (LeftUpperLeg, "Hip.L"),
            (LeftFoot, "Ankle.L"),
            (RightLowerLeg, "Knee.R"),
        ],
    );
}

/// A character written mid-stride and turned (the puppet walking the SMPL clip, exported to
/// glTF, whose file pose is the stride) maps as the puppet does: sides are told across its
/// hips, not along x.
#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn a_character_in_mid_stride_maps_as_at_rest() {
    use marionette::formats::scene::{AnimDoc, CharacterDoc, MotionSourceDoc, RetargetDoc, SceneDoc, SourceDoc};
    let data = crate::common::data_dir();
    let from = MotionSourceDoc::File { path: data.join("smpl"), clip: Some("7516".into()) };
    let anim = AnimDoc { retarget: Some(RetargetDoc::of(from)), time: 1.0, playing: false, ..AnimDoc::default() };
    let walker = CharacterDoc { anim: Some(anim), ..CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "walker") };
    let doc = SceneDoc { characters: vec![walker], ..SceneDoc::default() };
    let glb =
        marionette::document::export::scene_glb(&doc, marionette::formats::gltf::GltfMesh::Skinned, false).unwrap();
    let path = crate::common::scratch("humanoid-stride").join("walker.glb");
    std::fs::write(&path, glb).unwrap();
    let walker = marionette::formats::load_character(&path).unwrap();
    let puppet = marionette::formats::puppet::embedded_puppet();
    assert_eq!(
        named(&walker.skeleton, &detect(&walker.skeleton).unwrap()),
        named(&puppet.skeleton, &detect(&puppet.skeleton).unwrap())
    );
}

/// A BVH hierarchy in CMU's shape (a pelvis-side joint at the hips' centre, `OFFSET 0 0 0`,
/// whose bone runs to the hip socket, then the thigh), with these names for the hip joint,
/// the thigh, the shin, the foot and the toes of each side (`{s}` is `L`/`R`, `{side}`
/// `Left`/`Right`, `{l}` `l`/`r`).
fn cmu_shaped(names: [&str; 5]) -> Skeleton {
    let text = cmu_text(names);
    let file = marionette::formats::bvh::parse_bvh(std::io::Cursor::new(text), std::path::Path::new("cmu.bvh"));
    file.expect("the fixture reads").skeleton
}

/// The text of [`cmu_shaped`]'s BVH.
fn cmu_text(names: [&str; 5]) -> String {
    let leg = |s: &str, side: &str, l: &str, x: f32| {
        let name = |n: &str| n.replace("{s}", s).replace("{side}", side).replace("{l}", l);
        format!(
            "JOINT {}\n{{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
             JOINT {}\n{{\nOFFSET {x} -1.9 0.8\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
             JOINT {}\n{{\nOFFSET {x2} -7.5 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
             JOINT {}\n{{\nOFFSET 0 -7.2 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
             JOINT {}\n{{\nOFFSET 0 -0.4 2.2\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
             End Site\n{{\nOFFSET 0 0 0.8\n}}\n}}\n}}\n}}\n}}\n}}\n",
            name(names[0]),
            name(names[1]),
            name(names[2]),
            name(names[3]),
            name(names[4]),
            x2 = x * 0.5,
        )
    };
    let arm = |side: &str, x: f32| {
        format!(
            "JOINT {side}Shoulder\n{{\nOFFSET {} 1.5 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
             JOINT {side}Arm\n{{\nOFFSET {} 0 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
             JOINT {side}ForeArm\n{{\nOFFSET {} 0 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
             JOINT {side}Hand\n{{\nOFFSET {} 0 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
             End Site\n{{\nOFFSET {} 0 0\n}}\n}}\n}}\n}}\n}}\n",
            x * 1.5,
            x * 3.0,
            x * 5.0,
            x * 4.5,
            x * 1.5
        )
    };
    format!(
        "HIERARCHY\nROOT Hips\n{{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n\
         {}{}\
         JOINT LowerBack\n{{\nOFFSET 0 2.0 -0.1\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
         JOINT Spine\n{{\nOFFSET 0 2.0 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
         JOINT Spine1\n{{\nOFFSET 0 2.0 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
         {}{}\
         JOINT Neck\n{{\nOFFSET 0 2.0 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
         JOINT Head\n{{\nOFFSET 0 1.5 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n\
         End Site\n{{\nOFFSET 0 1.8 0\n}}\n}}\n}}\n}}\n}}\n}}\n}}\n\
         MOTION\nFrames: 1\nFrame Time: 0.0083333\n{}\n",
        leg("L", "Left", "l", 1.6),
        leg("R", "Right", "r", -1.6),
        arm("Left", 1.0),
        arm("Right", -1.0),
        vec!["0"; 6 + 3 * 23].join(" ")
    )
}

/// CMU's legs: the joint at the hips' centre whose bone runs to the hip socket
/// (`LHipJoint`, `lhipjoint`) is never the upper leg; the thigh below it is, whatever it is
/// called (`LeftHip`, `LeftUpLeg`, `lfemur`).
#[test]
fn cmu_legs_map_the_thigh_not_the_pelvis_side_joint() {
    for (names, thigh, shin) in [
        (["{s}HipJoint", "{side}Hip", "{side}Knee", "{side}Ankle", "{side}Toe"], "Hip", "Knee"),
        (["{s}HipJoint", "{side}UpLeg", "{side}Leg", "{side}Foot", "{side}ToeBase"], "UpLeg", "Leg"),
        (["{l}hipjoint", "{l}femur", "{l}tibia", "{l}foot", "{l}toes"], "femur", "tibia"),
    ] {
        let skeleton = cmu_shaped(names);
        let (left_thigh, right_thigh) = if thigh == "femur" {
            ("lfemur".to_string(), "rfemur".to_string())
        } else {
            (format!("Left{thigh}"), format!("Right{thigh}"))
        };
        let (left_shin, right_shin) = if shin == "tibia" {
            ("ltibia".to_string(), "rtibia".to_string())
        } else {
            (format!("Left{shin}"), format!("Right{shin}"))
        };
        expect(
            &skeleton,
            &[
                (Hips, "Hips"),
                (LeftUpperLeg, &left_thigh),
                (LeftLowerLeg, &left_shin),
                (RightUpperLeg, &right_thigh),
                (RightLowerLeg, &right_shin),
                (LeftUpperArm, "LeftArm"),
                (LeftHand, "LeftHand"),
            ],
        );
    }
}

/// A BVH in 6.837's shape: numbered joints, the chest the root, the hips hung below it by a
/// joint on the chest itself, each arm a joint on the chest (its bone the clavicle), one at
/// the shoulder and one at the elbow whose lower arm ends in no joint (zero End Sites).
fn model1_text() -> String {
    let chain = |joints: &[(usize, [f32; 3])], end: [f32; 3]| {
        let mut text = String::new();
        for (j, o) in joints {
            text += &format!(
                "JOINT joint{j}\n{{\nOFFSET {} {} {}\nCHANNELS 3 Zrotation Xrotation Yrotation\n",
                o[0], o[1], o[2]
            );
        }
        text += &format!("End Site\n{{\nOFFSET {} {} {}\n}}\n", end[0], end[1], end[2]);
        text + &"}\n".repeat(joints.len())
    };
    let leg = |first: usize, x: f32| {
        chain(
            &[
                (first, [0.0, -0.07, 0.0]),
                (first + 1, [x, 0.0, 0.0]),
                (first + 2, [0.0, -0.21, 0.02]),
                (first + 3, [0.0, -0.24, -0.02]),
            ],
            [0.0; 3],
        )
    };
    let arm = |first: usize, x: f32| {
        chain(
            &[(first, [0.0; 3]), (first + 1, [x * 0.1, -0.01, -0.04]), (first + 2, [x * 0.09, -0.1, -0.06])],
            [0.0; 3],
        )
    };
    format!(
        "HIERARCHY\nROOT joint0\n{{\nOFFSET 0 0.75 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\
         JOINT joint1\n{{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
         JOINT joint2\n{{\nOFFSET 0 -0.14 -0.04\nCHANNELS 3 Zrotation Xrotation Yrotation\n{}{}}}\n}}\n\
         {}{}{}}}\nMOTION\nFrames: 1\nFrame Time: 0.1\n{}\n",
        leg(4, -0.05),
        leg(8, 0.05),
        chain(&[(3, [0.0; 3])], [0.0, 0.2, 0.0]),
        arm(12, -1.0),
        arm(15, 1.0),
        vec!["0"; 6 + 3 * 17].join(" ")
    )
}

/// `info` prints the map of a three-joint arm (6.837's: clavicle, upper arm, lower arm, no
/// hand) and of CMU's legs (the thigh below `LHipJoint`), each bone by its joint's name.
#[test]
fn info_prints_the_map_of_three_joint_arms_and_cmu_legs() {
    let dir = crate::common::scratch("info-maps");
    let cmu = cmu_text(["{s}HipJoint", "{side}UpLeg", "{side}Leg", "{side}Foot", "{side}ToeBase"]);
    for (file, text, want, absent) in [
        (
            "model1.bvh",
            model1_text(),
            &[
                "Hips = joint2",
                "Chest = joint0",
                "LeftShoulder = joint15",
                "LeftUpperArm = joint16",
                "LeftLowerArm = joint17",
            ][..],
            &["LeftHand ="][..],
        ),
        (
            "cmu.bvh",
            cmu,
            &["LeftUpperLeg = LeftUpLeg", "LeftLowerLeg = LeftLeg", "RightUpperLeg = RightUpLeg"][..],
            &["= LHipJoint"][..],
        ),
    ] {
        let path = dir.join(file);
        std::fs::write(&path, text).unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_marionette"))
            .args(["info", path.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let info = String::from_utf8_lossy(&out.stdout);
        for line in want {
            assert!(info.lines().any(|l| l.trim_start().starts_with(line)), "{file}: no `{line}` in\n{info}");
        }
        for part in absent {
            assert!(!info.contains(part), "{file}: `{part}` in\n{info}");
        }
    }
}

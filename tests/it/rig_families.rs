//! The humanoid map on the rig families people bring (Blender-made fixtures, see
//! `scripts/make_rig_fixtures.py`): every standard bone, fingers included, named right on
//! each; no bone on a cape, hair, a sword, a twist or roll joint, an IK goal or a control.

use std::path::PathBuf;

use marionette::rig::humanoid::names::{Role, Side, read, without_common_prefix, words};
use marionette::rig::humanoid::{Found, HumanBone, of_asset};

fn rig(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs").join(file)
}

/// A family's names: the body's bones (hips, spine, chest, neck, head), each side's arm
/// (clavicle, upper, lower, hand) and leg (upper, lower, foot, toes) by side letter, and a
/// finger's phalanx (finger 0-4, phalanx 0-2, side letter); None where the rig has none.
struct Family {
    file: &'static str,
    body: [&'static str; 5],
    arm: fn(char) -> [String; 4],
    leg: fn(char) -> [String; 4],
    finger: Option<fn(usize, usize, char) -> String>,
    /// Bones the names do not give, found by the skeleton's shape.
    by_shape: &'static [HumanBone],
    /// Bones beyond the body's and the fingers' table (a rig's one-joint fingers).
    extra: &'static [(HumanBone, &'static str)],
}

fn side_word(s: char) -> &'static str {
    if s == 'L' { "Left" } else { "Right" }
}

fn lower(s: char) -> char {
    s.to_ascii_lowercase()
}

const FINGER_WORDS: [&str; 5] = ["Thumb", "Index", "Middle", "Ring", "Pinky"];

fn families() -> Vec<Family> {
    vec![
        Family {
            file: "mixamo.glb",
            body: ["mixamorig:Hips", "mixamorig:Spine", "mixamorig:Spine2", "mixamorig:Neck", "mixamorig:Head"],
            arm: |s| ["Shoulder", "Arm", "ForeArm", "Hand"].map(|b| format!("mixamorig:{}{b}", side_word(s))),
            leg: |s| ["UpLeg", "Leg", "Foot", "ToeBase"].map(|b| format!("mixamorig:{}{b}", side_word(s))),
            finger: Some(|f, p, s| format!("mixamorig:{}Hand{}{}", side_word(s), FINGER_WORDS[f], p + 1)),
            by_shape: &[],
            extra: &[],
        },
        Family {
            file: "unreal.glb",
            body: ["pelvis", "spine_01", "spine_03", "neck_01", "head"],
            arm: |s| ["clavicle", "upperarm", "lowerarm", "hand"].map(|b| format!("{b}_{}", lower(s))),
            leg: |s| ["thigh", "calf", "foot", "ball"].map(|b| format!("{b}_{}", lower(s))),
            finger: Some(|f, p, s| format!("{}_0{}_{}", FINGER_WORDS[f].to_lowercase(), p + 1, lower(s))),
            by_shape: &[],
            extra: &[],
        },
        Family {
            file: "humanik.glb",
            body: ["Hips", "Spine", "Spine2", "Neck", "Head"],
            arm: |s| ["Shoulder", "Arm", "ForeArm", "Hand"].map(|b| format!("{}{b}", side_word(s))),
            leg: |s| ["UpLeg", "Leg", "Foot", "ToeBase"].map(|b| format!("{}{b}", side_word(s))),
            finger: Some(|f, p, s| format!("{}Hand{}{}", side_word(s), FINGER_WORDS[f], p + 1)),
            by_shape: &[],
            extra: &[],
        },
        Family {
            file: "bandai.glb",
            body: ["Hips", "Spine", "Chest", "Neck", "Head"],
            arm: |s| ["Shoulder", "UpperArm", "LowerArm", "Hand"].map(|b| format!("{b}_{s}")),
            leg: |s| ["UpperLeg", "LowerLeg", "Foot", "Toes"].map(|b| format!("{b}_{s}")),
            finger: None,
            by_shape: &[],
            extra: &[],
        },
        Family {
            file: "maya_controls.glb",
            body: ["Character1_Hips", "Character1_Spine", "Character1_Spine2", "Character1_Neck", "Character1_Head"],
            arm: |s| ["Shoulder", "Arm", "ForeArm", "Hand"].map(|b| format!("Character1_{}{b}", side_word(s))),
            leg: |s| ["UpLeg", "Leg", "Foot", "ToeBase"].map(|b| format!("Character1_{}{b}", side_word(s))),
            finger: None,
            by_shape: &[],
            extra: &[],
        },
        Family {
            file: "daz.glb",
            body: ["hip", "abdomenLower", "chestUpper", "neckLower", "head"],
            arm: |s| ["Collar", "ShldrBend", "ForearmBend", "Hand"].map(|b| format!("{}{b}", lower(s))),
            leg: |s| ["ThighBend", "Shin", "Foot", "Toe"].map(|b| format!("{}{b}", lower(s))),
            finger: Some(|f, p, s| format!("{}{}{}", lower(s), ["Thumb", "Index", "Mid", "Ring", "Pinky"][f], p + 1)),
            by_shape: &[],
            extra: &[],
        },
        Family {
            file: "vroid.glb",
            body: ["J_Bip_C_Hips", "J_Bip_C_Spine", "J_Bip_C_UpperChest", "J_Bip_C_Neck", "J_Bip_C_Head"],
            arm: |s| ["Shoulder", "UpperArm", "LowerArm", "Hand"].map(|b| format!("J_Bip_{s}_{b}")),
            leg: |s| ["UpperLeg", "LowerLeg", "Foot", "ToeBase"].map(|b| format!("J_Bip_{s}_{b}")),
            finger: Some(|f, p, s| format!("J_Bip_{s}_{}{}", ["Thumb", "Index", "Middle", "Ring", "Little"][f], p + 1)),
            by_shape: &[],
            extra: &[],
        },
        Family {
            file: "biped.glb",
            body: ["Bip01 Pelvis", "Bip01 Spine", "Bip01 Spine2", "Bip01 Neck", "Bip01 Head"],
            arm: |s| ["Clavicle", "UpperArm", "Forearm", "Hand"].map(|b| format!("Bip01 {s} {b}")),
            leg: |s| ["Thigh", "Calf", "Foot", "Toe0"].map(|b| format!("Bip01 {s} {b}")),
            finger: Some(|f, p, s| {
                format!("Bip01 {s} Finger{f}{}", if p == 0 { String::new() } else { p.to_string() })
            }),
            by_shape: &[],
            extra: &[],
        },
        Family {
            file: "rigify.glb",
            body: ["DEF-spine", "DEF-spine.001", "DEF-spine.003", "DEF-spine.004", "DEF-spine.006"],
            arm: |s| ["shoulder", "upper_arm", "forearm", "hand"].map(|b| format!("DEF-{b}.{s}")),
            leg: |s| ["thigh", "shin", "foot", "toe"].map(|b| format!("DEF-{b}.{s}")),
            finger: Some(|f, p, s| {
                let name = ["thumb", "f_index", "f_middle", "f_ring", "f_pinky"][f];
                format!("DEF-{name}.0{}.{s}", p + 1)
            }),
            // Rigify names its neck and head `spine.004` and `spine.006`.
            by_shape: &[HumanBone::Neck, HumanBone::Head],
            extra: &[],
        },
        Family {
            file: "cmu_walk.bvh",
            body: ["Hips", "LowerBack", "Spine1", "Neck", "Head"],
            arm: |s| ["Shoulder", "Arm", "ForeArm", "Hand"].map(|b| format!("{}{b}", side_word(s))),
            leg: |s| ["UpLeg", "Leg", "Foot", "ToeBase"].map(|b| format!("{}{b}", side_word(s))),
            finger: None,
            by_shape: &[],
            // CMU's one thumb joint and one index joint.
            extra: &[
                (HumanBone::LeftThumbProximal, "LThumb"),
                (HumanBone::RightThumbProximal, "RThumb"),
                (HumanBone::LeftIndexProximal, "LeftHandIndex1"),
                (HumanBone::RightIndexProximal, "RightHandIndex1"),
            ],
        },
        Family {
            file: "bandai_walk.bvh",
            body: ["Hips", "Spine", "Chest", "Neck", "Head"],
            arm: |s| ["Shoulder", "UpperArm", "LowerArm", "Hand"].map(|b| format!("{b}_{s}")),
            leg: |s| ["UpperLeg", "LowerLeg", "Foot", "Toes"].map(|b| format!("{b}_{s}")),
            finger: None,
            by_shape: &[],
            extra: &[],
        },
    ]
}

/// Every family's expected map, bone by bone.
fn expected(family: &Family) -> Vec<(HumanBone, String)> {
    use HumanBone::*;
    let mut out: Vec<(HumanBone, String)> =
        [Hips, Spine, Chest, Neck, Head].into_iter().zip(family.body.map(String::from)).collect();
    out.extend(family.extra.iter().map(|&(b, n)| (b, n.to_string())));
    for (s, arm, leg) in [
        ('L', [LeftShoulder, LeftUpperArm, LeftLowerArm, LeftHand], [LeftUpperLeg, LeftLowerLeg, LeftFoot, LeftToes]),
        (
            'R',
            [RightShoulder, RightUpperArm, RightLowerArm, RightHand],
            [RightUpperLeg, RightLowerLeg, RightFoot, RightToes],
        ),
    ] {
        out.extend(arm.into_iter().zip((family.arm)(s)));
        out.extend(leg.into_iter().zip((family.leg)(s)));
        if let Some(finger) = family.finger {
            for f in 0..5 {
                for p in 0..3 {
                    out.push((HumanBone::finger(s == 'L', f, p), finger(f, p, s)));
                }
            }
        }
    }
    out
}

#[test]
fn every_family_maps_every_bone_by_name() {
    let mut failures = Vec::new();
    for family in families() {
        let asset = marionette::formats::load_character(&rig(family.file)).expect(family.file);
        let skeleton = &asset.skeleton;
        let Some(found) = of_asset(&asset) else {
            failures.push(format!("{}: no humanoid", family.file));
            continue;
        };
        let expected = expected(&family);
        for (bone, name) in &expected {
            let got = found.map.get(bone).map(|&j| skeleton.joint(j).name.as_str());
            if got != Some(name.as_str()) {
                failures.push(format!("{}: {bone:?} is {got:?}, expected {name}", family.file));
            }
            let how = if family.by_shape.contains(bone) { Found::Structure } else { Found::Name };
            if got.is_some() && found.found[bone] != how {
                failures.push(format!("{}: {bone:?} found by {:?}, not {how:?}", family.file, found.found[bone]));
            }
        }
        // Nothing beyond the table (no finger on a rig without fingers).
        for (bone, &j) in &found.map {
            if !expected.iter().any(|(b, _)| b == bone) {
                failures.push(format!(
                    "{}: {bone:?} mapped to {} beyond the table",
                    family.file,
                    skeleton.joint(j).name
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn no_bone_lands_on_a_cape_hair_a_sword_a_twist_or_a_control() {
    let off_body = ["cape", "hair", "sword", "twist", "roll", "ik", "ctrl", "pole", "mch", "org", "fk", "end"];
    for family in families() {
        let asset = marionette::formats::load_character(&rig(family.file)).unwrap();
        let found = of_asset(&asset).unwrap();
        for (bone, &j) in &found.map {
            let name = &asset.skeleton.joint(j).name;
            assert!(!words(name).iter().any(|w| off_body.contains(&w.as_str())), "{}: {bone:?} on {name}", family.file);
        }
    }
}

#[test]
fn names_of_each_family_read_as_their_bones() {
    use Role::*;
    use Side::*;
    let cases: &[(&str, Option<Side>, Option<Role>)] = &[
        ("mixamorig:LeftUpLeg", Some(Left), Some(UpperLeg)),
        ("mixamorig:RightForeArm", Some(Right), Some(LowerArm)),
        ("mixamorig:LeftHandIndex2", Some(Left), Some(Finger(1))),
        ("LHipJoint", Some(Left), Some(SidedHip)),
        ("LThumb", Some(Left), Some(Finger(0))),
        ("UpperArm_L", Some(Left), Some(UpperArm)),
        ("thigh_r", Some(Right), Some(UpperLeg)),
        ("calf_l", Some(Left), Some(LowerLeg)),
        ("ball_l", Some(Left), Some(Toes)),
        ("DEF-upper_arm.L", Some(Left), Some(UpperArm)),
        ("DEF-f_pinky.02.R", Some(Right), Some(Finger(4))),
        ("J_Bip_L_LowerArm", Some(Left), Some(LowerArm)),
        ("lShldrBend", Some(Left), Some(UpperArm)),
        ("L_Collar", Some(Left), Some(Clavicle)),
        ("left_middle2", Some(Left), Some(Finger(2))),
        ("Bip01 R Finger12", Some(Right), Some(Finger(1))),
        ("lfemur", Some(Left), Some(UpperLeg)),
        ("Hips", None, Some(Hips)),
        ("pelvis", None, Some(Hips)),
        ("LeftForeArm", Some(Left), Some(LowerArm)),
        ("mixamorig:LeftToe_End", Some(Left), None),
        ("HeadTop_End", None, None),
        ("LeftFootCtrl", Some(Left), None),
        ("Knight_Cape", None, None),
        ("upperarm_twist_01_l", Some(Left), None),
        ("ORG-hand.L", Some(Left), None),
        ("hand_fk.L", Some(Left), None),
    ];
    for &(name, side, role) in cases {
        let says = read(name);
        assert_eq!((says.side, says.role), (side, role), "{name}: {:?}", words(name));
    }
}

#[test]
fn a_prefix_every_name_shares_is_taken_off() {
    assert_eq!(
        without_common_prefix(&["Character1_Reference", "Character1_Hips", "Character1_LeftUpLeg"]),
        ["Reference", "Hips", "LeftUpLeg"]
    );
    assert_eq!(without_common_prefix(&["Bip01", "Bip01 Pelvis"]), ["Bip01", "Bip01 Pelvis"]);
    assert_eq!(without_common_prefix(&["Hips", "Head"]), ["Hips", "Head"]);
}

/// Fingers whose names say nothing are found by the hand's shape: with every joint below
/// each hand renamed `bone_N` (but those named as controls, mechanism or ends, which keep
/// saying so; a `DEF-` kept), each family with fingers maps every phalanx to the joint its
/// names gave it.
#[test]
fn fingers_named_for_nothing_are_found_by_the_hands_shape() {
    use marionette::rig::humanoid::detect_reported;
    use marionette::rig::skeleton::{RawJoint, Skeleton};
    let mut failures = Vec::new();
    for family in families().into_iter().filter(|f| f.finger.is_some()) {
        let asset = marionette::formats::load_character(&rig(family.file)).unwrap();
        let skeleton = &asset.skeleton;
        let named = detect_reported(skeleton).unwrap();
        let hands = [named.map[&HumanBone::LeftHand], named.map[&HumanBone::RightHand]];
        let raw: Vec<RawJoint> = skeleton
            .joints()
            .iter()
            .enumerate()
            .map(|(j, d)| {
                let below_hand = hands.iter().any(|&h| j != h && skeleton.is_below(j, h)) && !read(&d.name).excluded;
                let kind = d.name.split_once('-').filter(|(k, _)| *k == "DEF").map(|(k, _)| k);
                RawJoint {
                    name: match (below_hand, kind) {
                        (false, _) => d.name.clone(),
                        (true, Some(kind)) => format!("{kind}-bone_{j}"),
                        (true, None) => format!("bone_{j}"),
                    },
                    parent: d.parent,
                    rest_offset: d.rest_offset,
                    limits: d.limits,
                    bone_box: d.bone_box,
                    initial_rotation: d.initial_rotation,
                    rest_scale: d.rest_scale,
                }
            })
            .collect();
        let renamed = Skeleton::build(raw).unwrap();
        let Some(shaped) = detect_reported(&renamed) else {
            failures.push(format!("{}: no humanoid once renamed", family.file));
            continue;
        };
        for bone in HumanBone::ALL.iter().filter(|b| b.is_finger()) {
            let (want, got) = (named.map.get(bone), shaped.map.get(bone));
            if want != got {
                let name = |j: Option<&usize>| j.map(|&j| skeleton.joint(j).name.clone());
                failures.push(format!("{}: {bone:?} is {:?}, by name {:?}", family.file, name(got), name(want)));
            } else if got.is_some() && shaped.found[bone] != Found::Structure {
                failures.push(format!("{}: {bone:?} not found by structure", family.file));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Hand presets on every family with fingers, both hands, checked per phalanx by the angle
/// between each phalanx and the bone that leads into it (FK here): `fist` bends every phalanx
/// of the four fingers at least 60° and the thumb's at least 30°, toward the palm (down at
/// rest); `open` leaves each within 10° of straight; `point` the index straight, the others
/// as in `fist`.
#[test]
fn hand_presets_bend_every_phalanx_as_defined() {
    use marionette::rig::fk::forward_kinematics;
    use marionette::rig::hands::{apply_hand, preset};
    use marionette::rig::humanoid::detect_reported;
    let mut failures = Vec::new();
    for family in families().into_iter().filter(|f| f.finger.is_some()) {
        let asset = marionette::formats::load_character(&rig(family.file)).unwrap();
        let skeleton = &asset.skeleton;
        let map = detect_reported(skeleton).unwrap().map;
        for name in ["fist", "open", "point"] {
            for left in [true, false] {
                let (curl, spread) = preset(name).unwrap();
                let mut pose = skeleton.initial_pose();
                apply_hand(skeleton, &map, &mut pose, left, curl, spread).unwrap();
                let mut world = vec![glam::Mat4::IDENTITY; skeleton.len()];
                forward_kinematics(skeleton, &pose, glam::Mat4::IDENTITY, &mut world);
                let at = |j: usize| world[j].w_axis.truncate();
                for f in 0..5 {
                    for p in 0..3 {
                        let Some(&j) = map.get(&HumanBone::finger(left, f, p)) else { continue };
                        let (Some(&child), Some(parent)) = (skeleton.children(j).first(), skeleton.parent(j)) else {
                            continue;
                        };
                        let bend = (at(child) - at(j)).angle_between(at(j) - at(parent)).to_degrees();
                        let straight = name == "open" || (name == "point" && f == 1);
                        let least = if f == 0 { 30.0 } else { 60.0 };
                        let mut ok = if straight { bend <= 10.0 } else { bend >= least };
                        if name == "fist" && f > 0 && p == 2 {
                            // The fingertip went down, toward the palm.
                            let mut rest = vec![glam::Mat4::IDENTITY; skeleton.len()];
                            forward_kinematics(skeleton, &skeleton.initial_pose(), glam::Mat4::IDENTITY, &mut rest);
                            ok &= at(child).y < rest[child].w_axis.y;
                        }
                        if !ok {
                            failures
                                .push(format!("{} {name} left={left} finger {f} phalanx {p}: {bend:.1}°", family.file));
                        }
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

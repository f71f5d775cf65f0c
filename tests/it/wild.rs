//! Motion and avatars from the wild: the Blender-made BVH clips (centimetres, a T-pose first
//! frame; CMU-style, and Bandai-Namco-style with a still `joint_Root` above a walking `Hips`
//! and position channels on every joint) retargeted onto characters of every origin, and
//! VRM avatars (1.0 and 0.x) made from a Blender rig with the extension's humanoid bones and
//! expressions.
//!
//! Retargeting is checked from the posed skins and joints (this file's own measures): every
//! mapped bone with a mapped child within 2° of the source's direction (but a leg moved to
//! keep its foot above the floor), the target's lowest point within 2 % of its leg of its
//! floor in the frames where the source stands on its own, never below it, and the hips'
//! height over the floor within 5 % of the source's times the ratio of their heights standing
//! on straight legs (the hips over the thighs, thigh, shin and the ankle over the floor).
//! The feet on the floor come first: the hips go where the target's own legs, aimed as the
//! source's, put them, which differs from that ratio as the rigs' feet and pelvises differ
//! in proportion. That ratio, the share of the standing height, and the hips against the
//! source's times the thigh-and-shin ratio are printed.

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};
use marionette::document::AssetLibrary;
use marionette::document::posing::posed_positions;
use marionette::document::retarget::{file_motion_doc, humanoid_map, retarget};
use marionette::formats::scene::{CharacterDoc, MotionSourceDoc, RetargetDoc, SourceDoc};
use marionette::rig::humanoid::{Found, HumanBone};
use marionette::rig::retarget::{Frame, Retargeted, world_frames};

use crate::common::scratch;
use crate::retarget::{Side, side};

fn fixture(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs").join(file)
}

/// The VRoid-named Blender rig with a `VRMC_vrm` (1.0) or `VRM` (0.x) extension naming its
/// humanoid bones (by its joints' names) and two expressions (its shape keys `Joy`, `Blink`).
pub fn vrm_avatar(version: u8) -> PathBuf {
    let glb = std::fs::read(fixture("vroid.glb")).unwrap();
    let out = scratch(&format!("vrm{version}")).join("avatar.vrm");
    let bytes = crate::common::glb_with_json(&glb, |json| {
        let nodes: Vec<String> =
            json["nodes"].as_array().unwrap().iter().map(|n| n["name"].as_str().unwrap_or("").to_string()).collect();
        let node = |name: &str| nodes.iter().position(|n| n == name).unwrap();
        let body = json["nodes"].as_array().unwrap().iter().position(|n| n.get("mesh").is_some()).unwrap();
        let mut bones: Vec<(String, usize)> = Vec::new();
        for (vrm, ours) in [("hips", "Hips"), ("spine", "Spine"), ("chest", "Chest"), ("upperChest", "UpperChest")]
            .into_iter()
            .chain([("neck", "Neck"), ("head", "Head")])
        {
            bones.push((vrm.into(), node(&format!("J_Bip_C_{ours}"))));
        }
        for (side, s) in [("left", 'L'), ("right", 'R')] {
            for (vrm, ours) in [("Shoulder", "Shoulder"), ("UpperArm", "UpperArm"), ("LowerArm", "LowerArm")]
                .into_iter()
                .chain([("Hand", "Hand"), ("UpperLeg", "UpperLeg"), ("LowerLeg", "LowerLeg"), ("Foot", "Foot")])
                .chain([("Toes", "ToeBase")])
            {
                bones.push((format!("{side}{vrm}"), node(&format!("J_Bip_{s}_{ours}"))));
            }
            for finger in ["Thumb", "Index", "Middle", "Ring", "Little"] {
                let phalanges: [&str; 3] = match (version, finger) {
                    (1, "Thumb") => ["Metacarpal", "Proximal", "Distal"],
                    _ => ["Proximal", "Intermediate", "Distal"],
                };
                for (k, p) in phalanges.iter().enumerate() {
                    bones.push((format!("{side}{finger}{p}"), node(&format!("J_Bip_{s}_{finger}{}", k + 1))));
                }
            }
        }
        json["extensionsUsed"] = serde_json::json!([if version == 1 { "VRMC_vrm" } else { "VRM" }]);
        json["extensions"] = if version == 1 {
            let human: serde_json::Map<String, serde_json::Value> =
                bones.iter().map(|(b, n)| (b.clone(), serde_json::json!({ "node": n }))).collect();
            serde_json::json!({ "VRMC_vrm": {
                "specVersion": "1.0",
                "meta": { "name": "avatar", "authors": ["marionette tests"], "licenseUrl": "https://vrm.dev/licenses/1.0/" },
                "humanoid": { "humanBones": human },
                "expressions": { "preset": {
                    "happy": { "morphTargetBinds": [{ "node": body, "index": 0, "weight": 1.0 }] },
                    "blink": { "morphTargetBinds": [{ "node": body, "index": 1, "weight": 1.0 }] }
                } }
            } })
        } else {
            let human: Vec<serde_json::Value> =
                bones.iter().map(|(b, n)| serde_json::json!({ "bone": b, "node": n })).collect();
            serde_json::json!({ "VRM": {
                "specVersion": "0.0",
                "humanoid": { "humanBones": human },
                "blendShapeMaster": { "blendShapeGroups": [
                    { "name": "Joy", "presetName": "joy", "binds": [{ "mesh": 0, "index": 0, "weight": 100 }] },
                    { "name": "Blink", "presetName": "blink", "binds": [{ "mesh": 0, "index": 1, "weight": 50 }] }
                ] }
            } })
        };
    });
    std::fs::write(&out, bytes).unwrap();
    out
}

#[test]
fn vrm_avatars_load_with_the_files_humanoid_bones_and_expressions() {
    for version in [1, 0] {
        let path = vrm_avatar(version);
        let asset = marionette::formats::load_character(&path).unwrap();
        let found = marionette::rig::humanoid::of_asset(&asset).unwrap();
        // Every bone the extension names, fingers included, found from the file.
        assert_eq!(asset.humanoid.len(), 21 + 30, "VRM {version}");
        for (bone, &j) in &asset.humanoid {
            assert_eq!(found.map[bone], j);
            assert_eq!(found.found[bone], Found::File, "VRM {version}: {bone:?}");
        }
        let name = |b: HumanBone| asset.skeleton.joint(found.map[&b]).name.as_str();
        assert_eq!(name(HumanBone::Chest), "J_Bip_C_UpperChest");
        assert_eq!(name(HumanBone::LeftThumbProximal), "J_Bip_L_Thumb1");
        assert_eq!(name(HumanBone::RightLittleDistal), "J_Bip_R_Little3");
        // The expressions, as morph weights.
        let morphs = asset.morphs.len();
        assert_eq!(morphs, 2);
        let weights = |name: &str| {
            let e = asset.expressions.iter().find(|e| e.name == name).unwrap_or_else(|| panic!("no {name}"));
            e.morph_weights(morphs)
        };
        assert_eq!(asset.expressions.len(), 2);
        assert_eq!(weights(if version == 1 { "happy" } else { "joy" }), [1.0, 0.0]);
        assert_eq!(weights("blink"), [0.0, if version == 1 { 1.0 } else { 0.5 }]);
        let info = marionette::document::posing::describe(&asset);
        assert!(info.contains("expressions: "), "{info}");
        assert!(info.contains(&format!("humanoid: {} of 51 bones", found.map.len())), "{info}");
    }
}

/// The lowest point of a side's skin in a frame.
fn lowest(side: &Side, frame: &Frame) -> f32 {
    let origin = Mat4::from_translation(frame.root - side.asset.skeleton.joint(0).rest_offset);
    posed_positions(&side.asset, &frame.pose, origin).iter().map(|p| p.y).fold(f32::INFINITY, f32::min)
}

/// The figures of one retargeting: the worst bone angle (degrees, and which), the range of
/// the hips' height over the floor as a share of its standing height against the source's,
/// of the hips' height against the source's times the leg ratio, and the target's lowest
/// point over its floor (in its legs) in the frames the source stands on its floor, and in
/// all.
#[derive(Debug)]
struct Figures {
    worst: (f32, String),
    hips: (f32, f32),
    hips_by_leg: (f32, f32),
    by_straight: (f32, f32),
    standing: (f32, f32),
    lowest: f32,
}

fn measure(s: &Side, source: &[Frame], t: &Side, report: &Retargeted) -> Figures {
    let target = &report.frames;
    use HumanBone::*;
    let aimed = [
        (Spine, Chest),
        (LeftUpperArm, LeftLowerArm),
        (LeftLowerArm, LeftHand),
        (RightUpperArm, RightLowerArm),
        (RightLowerArm, RightHand),
        (LeftUpperLeg, LeftLowerLeg),
        (LeftLowerLeg, LeftFoot),
        (RightUpperLeg, RightLowerLeg),
        (RightLowerLeg, RightFoot),
        (Chest, Neck),
        (Neck, Head),
    ];
    let ratio = t.leg / s.leg;
    let range = (f32::MAX, f32::MIN);
    let mut f = Figures {
        worst: (0.0, String::new()),
        hips: range,
        hips_by_leg: range,
        by_straight: range,
        standing: range,
        lowest: f32::MAX,
    };
    for (k, (sf, tf)) in source.iter().zip(target).enumerate() {
        let (_, sa) = world_frames(&s.asset.skeleton, sf.root, &sf.pose);
        let (_, ta) = world_frames(&t.asset.skeleton, tf.root, &tf.pose);
        for (bone, next) in aimed {
            let (Some(&a), Some(&b), Some(&c), Some(&d)) =
                (s.map.get(&bone), s.map.get(&next), t.map.get(&bone), t.map.get(&next))
            else {
                continue;
            };
            let angle = (sa[b] - sa[a]).angle_between(ta[d] - ta[c]).to_degrees();
            // A leg the report says was moved to keep its foot above the floor is excused.
            let legs = [[LeftUpperLeg, LeftLowerLeg], [RightUpperLeg, RightLowerLeg]];
            if (0..2).any(|side| report.legs_moved[side][k] && legs[side].contains(&bone)) {
                continue;
            }
            if angle > f.worst.0 {
                f.worst = (angle, format!("{bone:?}"));
            }
        }
        let (t_hips, s_hips) = (ta[t.map[&Hips]].y - t.floor, sa[s.map[&Hips]].y - s.floor);
        let hips = (t_hips / t.standing) / (s_hips / s.standing);
        f.hips = (f.hips.0.min(hips), f.hips.1.max(hips));
        let by_leg = t_hips / (s_hips * ratio);
        let by_straight = t_hips / (s_hips * t.straight / s.straight);
        f.by_straight = (f.by_straight.0.min(by_straight), f.by_straight.1.max(by_straight));
        f.hips_by_leg = (f.hips_by_leg.0.min(by_leg), f.hips_by_leg.1.max(by_leg));
        let target_low = (lowest(t, tf) - t.floor) / t.leg;
        f.lowest = f.lowest.min(target_low);
        if (lowest(s, sf) - s.floor) / s.leg < 1e-3 {
            f.standing = (f.standing.0.min(target_low), f.standing.1.max(target_low));
        }
    }
    f
}

fn doc_of(library: &mut AssetLibrary, path: &Path) -> CharacterDoc {
    let source = SourceDoc::File(path.to_path_buf());
    let asset = library.load(&source).unwrap();
    library.new_character_doc(source, &asset)
}

/// Every BVH fixture onto every target: the figures printed, held to the bounds.
fn carry_onto(targets: Vec<CharacterDoc>, library: &mut AssetLibrary) {
    let mut failures = Vec::new();
    for bvh in ["cmu_walk.bvh", "bandai_walk.bvh"] {
        let path = fixture(bvh);
        let source = file_motion_doc(library, &path, None).unwrap();
        for target in &targets {
            let asset = library.shaped(target).unwrap();
            let settings = RetargetDoc {
                plant_feet: false,
                ..RetargetDoc::of(MotionSourceDoc::File { path: path.clone(), clip: None })
            };
            let done = retarget(library, &source, target, &asset, &settings).unwrap();
            let (s, t) = (side(library, &source, done.floors.0), side(library, target, done.floors.1));
            let f = measure(&s, &done.source_frames, &t, &done.report);
            eprintln!(
                "{bvh} → {}: worst bone {:.2}° ({}), hips over standing against the source's {:.4}–{:.4} (over the source's × leg ratio {:.4}–{:.4}, × straight {:.4}–{:.4}), lowest point where the source stands {:+.4}–{:+.4} legs, lowest {:+.4}",
                target.name,
                f.worst.0,
                f.worst.1,
                f.hips.0,
                f.hips.1,
                f.hips_by_leg.0,
                f.hips_by_leg.1,
                f.by_straight.0,
                f.by_straight.1,
                f.standing.0,
                f.standing.1,
                f.lowest
            );
            let ok = f.worst.0 < 2.0
                && f.by_straight.0 > 0.95
                && f.by_straight.1 < 1.05
                && f.standing.0 <= f.standing.1
                && f.standing.1 < 0.02
                && f.lowest > -1e-3;
            if !ok {
                failures.push(format!("{bvh} → {}: {f:?}", target.name));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn bvh_from_the_wild_stands_the_puppet_and_a_vrm_avatar_on_the_floor() {
    let mut library = AssetLibrary::default();
    let targets =
        vec![CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "puppet"), doc_of(&mut library, &vrm_avatar(1))];
    carry_onto(targets, &mut library);
}

#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn bvh_from_the_wild_stands_course_and_khronos_characters_on_the_floor() {
    let data = crate::common::data_dir();
    let mut library = AssetLibrary::default();
    let targets = ["mit6837/Model1.skel", "khronos/CesiumMan.glb", "smpl"]
        .iter()
        .map(|f| doc_of(&mut library, &data.join(f)))
        .collect();
    carry_onto(targets, &mut library);
}

/// The Bandai-Namco-style clip's walk is carried by `Hips`' position channels under a still
/// `joint_Root`: the figure walks the metre the clip walks (within 1 %), its hips at their
/// height.
#[test]
fn position_channels_below_the_root_move_the_figure() {
    let path = fixture("bandai_walk.bvh");
    let bvh = marionette::formats::bvh::parse_bvh(std::io::BufReader::new(std::fs::File::open(&path).unwrap()), &path)
        .unwrap();
    let hips = bvh.skeleton.find("Hips").unwrap();
    let at = |t: f32| {
        let (root, pose) = bvh.clip.pose_at(&bvh.skeleton, t, &bvh.skeleton.initial_pose());
        world_frames(&bvh.skeleton, root, &pose).1[hips]
    };
    let (start, end) = (at(bvh.clip.range.0 + bvh.frame_time), at(bvh.clip.range.1));
    let walked = Vec3::new(end.x - start.x, 0.0, end.z - start.z).length();
    // 100 cm over frames 2–41 of the clip (39 of its 39 steps).
    assert!((walked - 100.0).abs() < 1.0, "walked {walked} cm");
    assert!((start.y - 100.0).abs() < 0.01 && (end.y - 100.0).abs() < 0.01, "hips at {start} and {end}");
    assert!(bvh.warnings.is_empty(), "{:?}", bvh.warnings);
}

/// Finger motion carries over where both rigs have fingers: a Mixamo-named hand's fingers
/// curled (every phalanx of every finger turned 40° about the hand's across axis) put on
/// the VRM avatar through the two maps, each target phalanx pointing where the source's
/// points (within 2°).
#[test]
fn finger_motion_carries_between_rigs_of_other_names() {
    use marionette::rig::JointRotation;
    use marionette::rig::retarget::{RestAlignment, retarget_pose};
    let source = marionette::formats::load_character(&fixture("mixamo.glb")).unwrap();
    let target = marionette::formats::load_character(&vrm_avatar(1)).unwrap();
    let (s_map, t_map) = (humanoid_map(&source, &Default::default()), humanoid_map(&target, &Default::default()));
    let mut pose = source.skeleton.initial_pose();
    for finger in 0..5 {
        for phalanx in 0..3 {
            let j = s_map[&HumanBone::finger(true, finger, phalanx)];
            let curl = glam::Quat::from_rotation_z(-0.7);
            pose[j] = JointRotation::Quat(pose[j].to_quat() * curl);
        }
    }
    let carried =
        retarget_pose((&source.skeleton, &s_map), &pose, (&target.skeleton, &t_map), RestAlignment::Directions)
            .unwrap();
    let (_, sa) = world_frames(&source.skeleton, source.skeleton.joint(0).rest_offset, &pose);
    let (_, ta) = world_frames(&target.skeleton, target.skeleton.joint(0).rest_offset, &carried);
    let mut worst = 0.0f32;
    for finger in 0..5 {
        for phalanx in 0..2 {
            let (a, b) = (HumanBone::finger(true, finger, phalanx), HumanBone::finger(true, finger, phalanx + 1));
            let s_dir = sa[s_map[&b]] - sa[s_map[&a]];
            let t_dir = ta[t_map[&b]] - ta[t_map[&a]];
            worst = worst.max(s_dir.angle_between(t_dir).to_degrees());
        }
    }
    // The curl moved the fingers: compare with the rest.
    let (_, rest) =
        world_frames(&source.skeleton, source.skeleton.joint(0).rest_offset, &source.skeleton.initial_pose());
    let moved = sa[s_map[&HumanBone::LeftIndexDistal]].distance(rest[s_map[&HumanBone::LeftIndexDistal]]);
    assert!(moved > 0.01, "the curl moved the index's tip {moved} m");
    assert!(worst < 2.0, "a phalanx {worst}° off the source's");
}

/// A material marked unlit (`KHR_materials_unlit`, as VRM exporters mark an unlit MToon
/// material's glTF fallback) reads as unlit, and goes out as unlit again.
#[test]
fn unlit_materials_read_and_write_as_unlit() {
    let glb = std::fs::read(fixture("vroid.glb")).unwrap();
    let bytes = crate::common::glb_with_json(&glb, |json| {
        if json["materials"].as_array().is_none_or(|m| m.is_empty()) {
            json["materials"] = serde_json::json!([{ "name": "toon" }]);
            for mesh in json["meshes"].as_array_mut().unwrap() {
                for p in mesh["primitives"].as_array_mut().unwrap() {
                    p["material"] = serde_json::json!(0);
                }
            }
        }
        json["materials"][0]["extensions"] = serde_json::json!({ "KHR_materials_unlit": {} });
        json["extensionsUsed"] = serde_json::json!(["KHR_materials_unlit"]);
    });
    let dir = scratch("unlit");
    let path = dir.join("unlit.glb");
    std::fs::write(&path, bytes).unwrap();
    let asset = marionette::formats::load_character(&path).unwrap();
    assert!(
        asset.materials.iter().all(|m| m.unlit),
        "{:?}",
        asset.materials.iter().map(|m| m.unlit).collect::<Vec<_>>()
    );
    let out = dir.join("out.glb");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["export", path.to_str().unwrap(), "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let back = marionette::formats::load_character(&out).unwrap();
    assert!(!back.materials.is_empty() && back.materials.iter().all(|m| m.unlit));
}

/// Broken VRM extensions are refused with their place: a bone's node past the file's
/// nodes, an expression's morph index that is no index, a weight past 1, humanoid bones
/// that are not an object.
#[test]
fn broken_vrm_extensions_are_refused_with_their_place() {
    let avatar = std::fs::read(vrm_avatar(1)).unwrap();
    let dir = scratch("vrm-broken");
    let vrm = "/extensions/VRMC_vrm";
    let cases: [(&str, &str, serde_json::Value, &str); 4] = [
        ("node", "/humanoid/humanBones/hips/node", serde_json::json!(1_000_000_000_000u64), "node index below"),
        ("index", "/expressions/preset/happy/morphTargetBinds/0/index", serde_json::json!(-3), "expected an index"),
        ("weight", "/expressions/preset/happy/morphTargetBinds/0/weight", serde_json::json!(7.5), "weight from 0 to 1"),
        ("bones", "/humanoid/humanBones", serde_json::json!("hips"), "expected an object"),
    ];
    for (name, pointer, value, says) in cases {
        let bytes = crate::common::glb_with_json(&avatar, |json| {
            *json.pointer_mut(&format!("{vrm}{pointer}")).unwrap() = value.clone();
        });
        let path = dir.join(format!("{name}.vrm"));
        std::fs::write(&path, bytes).unwrap();
        let e = marionette::formats::load_character(&path).unwrap_err().to_string();
        assert!(e.contains(&format!("{name}.vrm")) && e.contains("at $.extensions") && e.contains(says), "{e}");
    }
}

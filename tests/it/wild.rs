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
use crate::retarget::{Side, side, side_standing};

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
    /// The most a target knee bends past its source's (degrees), and the frames a target
    /// knee bends the other way from a source's bent one.
    knee_past: f32,
    knees_backwards: usize,
    /// Frames a target elbow bends the other way from a source's bent one.
    elbows_backwards: usize,
    /// Leg-frames the report says were moved to plant a foot.
    legs_moved: usize,
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
        knee_past: f32::MIN,
        knees_backwards: 0,
        elbows_backwards: 0,
        legs_moved: report.legs_moved.iter().map(|side| side.iter().filter(|&&m| m).count()).sum(),
    };
    for (k, (sf, tf)) in source.iter().zip(target).enumerate() {
        let (_, sa) = sf.world(&s.asset.skeleton);
        let (_, ta) = tf.world(&t.asset.skeleton);
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
        // Each knee bent no further than the source's and the same way: about the hips'
        // across axis (right to left thigh), the turn from thigh to shin.
        for (upper, lower, foot) in [(LeftUpperLeg, LeftLowerLeg, LeftFoot), (RightUpperLeg, RightLowerLeg, RightFoot)]
        {
            let bend = |map: &marionette::rig::humanoid::HumanoidMap, at: &[Vec3]| {
                let (thigh, shin) = (at[map[&lower]] - at[map[&upper]], at[map[&foot]] - at[map[&lower]]);
                let across = at[map[&LeftUpperLeg]] - at[map[&RightUpperLeg]];
                (thigh.angle_between(shin).to_degrees(), thigh.cross(shin).dot(across).signum())
            };
            let ((s_angle, s_way), (t_angle, t_way)) = (bend(&s.map, &sa), bend(&t.map, &ta));
            f.knee_past = f.knee_past.max(t_angle - s_angle);
            if s_angle > 5.0 && t_angle > 5.0 && s_way != t_way {
                f.knees_backwards += 1;
            }
        }
        // Each elbow bent the same way as the source's (the turn from upper to lower arm).
        for (upper, lower, hand) in [(LeftUpperArm, LeftLowerArm, LeftHand), (RightUpperArm, RightLowerArm, RightHand)]
        {
            let bend = |map: &marionette::rig::humanoid::HumanoidMap, at: &[Vec3]| -> Option<(f32, Vec3)> {
                let (u, l, h) = (at[*map.get(&upper)?], at[*map.get(&lower)?], at[*map.get(&hand)?]);
                Some(((l - u).angle_between(h - l).to_degrees(), (l - u).cross(h - l)))
            };
            if let (Some((s_angle, s_axis)), Some((t_angle, t_axis))) = (bend(&s.map, &sa), bend(&t.map, &ta))
                && s_angle > 5.0
                && t_angle > 5.0
                && s_axis.dot(t_axis) < 0.0
            {
                f.elbows_backwards += 1;
            }
        }
        // Hips hung below the chest (6.837's models) lie from the chest as the source's.
        if t.asset.skeleton.is_below(t.map[&Hips], t.map[&Chest]) {
            let (a, b, c, d) = (s.map[&Chest], s.map[&Hips], t.map[&Chest], t.map[&Hips]);
            let angle = (sa[b] - sa[a]).angle_between(ta[d] - ta[c]).to_degrees();
            if angle > f.worst.0 {
                f.worst = (angle, "Hips from the Chest".into());
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

/// Every BVH fixture (CMU- and Bandai-shaped, and the CMU walk as MotionBuilder and Mixamo
/// files are shaped) onto every target: the figures printed, held to the bounds.
fn carry_onto(targets: Vec<CharacterDoc>, library: &mut AssetLibrary) {
    let mut failures = Vec::new();
    let mut walks = vec![fixture("cmu_walk.bvh"), fixture("bandai_walk.bvh")];
    walks.extend(family_walks());
    walks.push(fixture("bandai_lying_walk.bvh"));
    for path in walks {
        let bvh = path.file_name().unwrap().to_string_lossy().into_owned();
        let source = file_motion_doc(library, &path, None).unwrap();
        for (target, plant_feet) in targets.iter().flat_map(|t| [(t, false), (t, true)]) {
            let asset = library.shaped(target).unwrap();
            let settings =
                RetargetDoc { plant_feet, ..RetargetDoc::of(MotionSourceDoc::File { path: path.clone(), clip: None }) };
            let done = retarget(library, &source, target, &asset, &settings).unwrap();
            // A source lying down at rest stands as in its first frame.
            let source_asset = library.shaped(&source).unwrap();
            let upright = marionette::document::retarget::stands_upright(
                &source_asset.skeleton,
                &humanoid_map(&source_asset, &source.humanoid),
            );
            let stands = done.source_frames.first().filter(|_| !upright);
            let s = side_standing(library, &source, done.floors.0, stands);
            let t = side(library, target, done.floors.1);
            let f = measure(&s, &done.source_frames, &t, &done.report);
            eprintln!(
                "{bvh} → {} (planting {plant_feet}): worst bone {:.2}° ({}), hips over standing against the source's {:.4}–{:.4} (over the source's × leg ratio {:.4}–{:.4}, × straight {:.4}–{:.4}), lowest point where the source stands {:+.4}–{:+.4} legs, lowest {:+.4}, knees at most {:.2}° past the source's, {} knees and {} elbows bent backwards, {} leg-frames moved to plant",
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
                f.lowest,
                f.knee_past,
                f.knees_backwards,
                f.elbows_backwards,
                f.legs_moved
            );
            let ok = f.worst.0 < 2.0
                && f.by_straight.0 > 0.95
                && f.by_straight.1 < 1.05
                && f.standing.0 <= f.standing.1
                && f.standing.1 < 0.02
                && f.lowest > -1e-3
                // Planting bends no knee further than the source's (2°: the directions' bound).
                && f.knee_past < 2.0
                && f.knees_backwards == 0
                && f.elbows_backwards == 0;
            if !ok {
                failures.push(format!("{bvh} → {} (planting {plant_feet}): {f:?}", target.name));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The Blender-made Mixamo rig as Mixamo's own glTF files have it: the armature node scaled
/// 0.01, the joints' offsets in centimetres and their frames in centimetres too (each
/// inverse bind matrix scaled by 100), so every joint and vertex stays where it was.
pub fn mixamo_in_centimetres() -> PathBuf {
    let glb = std::fs::read(fixture("mixamo.glb")).unwrap();
    let out = scratch("mixamo-cm").join("mixamo_cm.glb");
    let mut ibm = None;
    let mut bytes = crate::common::glb_with_json(&glb, |json| {
        let accessor = &json["accessors"][json["skins"][0]["inverseBindMatrices"].as_u64().unwrap() as usize];
        let view = &json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
        let at = |v: &serde_json::Value, k: &str| v[k].as_u64().unwrap_or(0) as usize;
        ibm = Some((at(view, "byteOffset") + at(accessor, "byteOffset"), at(accessor, "count")));
        let nodes = json["nodes"].as_array_mut().unwrap();
        for node in nodes.iter_mut() {
            let name = node["name"].as_str().unwrap_or("").to_string();
            if name == "Armature" {
                node["scale"] = serde_json::json!([0.01, 0.01, 0.01]);
            } else if name.starts_with("mixamorig:")
                && let Some(t) = node.get_mut("translation")
            {
                let cm: Vec<f64> = t.as_array().unwrap().iter().map(|v| v.as_f64().unwrap() * 100.0).collect();
                *t = serde_json::json!(cm);
            }
        }
    });
    // S(100) · M for each inverse bind matrix M (column-major floats): its rows x, y, z.
    let (offset, count) = ibm.unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let bin = 20 + json_len + 8 + offset;
    for m in 0..count {
        for column in 0..4 {
            for row in 0..3 {
                let at = bin + 4 * (16 * m + 4 * column + row);
                let v = f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) * 100.0;
                bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
            }
        }
    }
    std::fs::write(&out, bytes).unwrap();
    out
}

#[test]
fn bvh_from_the_wild_stands_the_puppet_and_a_vrm_avatar_on_the_floor() {
    let mut library = AssetLibrary::default();
    let mut targets =
        vec![CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "puppet"), doc_of(&mut library, &vrm_avatar(1))];
    for path in [fixture("mixamo.glb"), mixamo_in_centimetres(), fixture("unreal.glb"), fixture("vroid.glb")] {
        targets.push(doc_of(&mut library, &path));
    }
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
        Frame { root, pose, offsets: bvh.clip.offsets_at(&bvh.skeleton, t) }.world(&bvh.skeleton).1[hips]
    };
    let (start, end) = (at(bvh.clip.range.0 + bvh.frame_time), at(bvh.clip.range.1));
    let walked = Vec3::new(end.x - start.x, 0.0, end.z - start.z).length();
    // 100 cm over frames 2–41 of the clip (39 of its 39 steps).
    assert!((walked - 100.0).abs() < 1.0, "walked {walked} cm");
    assert!((start.y - 100.0).abs() < 0.01 && (end.y - 100.0).abs() < 0.01, "hips at {start} and {end}");
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

/// A BVH joint as written: name, parent, OFFSET, whether it has position channels, and its
/// rotation channels' axes outermost first.
type BvhJoint = (&'static str, Option<usize>, [f64; 3], bool, &'static str);

/// A Bandai-Namco-shaped BVH: a still `joint_Root` (placed and turned, the same in every
/// frame) above a `Hips` whose position channels walk it away from its OFFSET, every joint
/// with its rotation channels in the file's own order. `info` prints the file's OFFSETs, and
/// `export --animation` writes every joint where the file defines it in every frame (its
/// position channels in place of its OFFSET, then its rotations outermost first), within
/// 1e-5 of the skeleton's size; `joint_Root` stays where it is.
#[test]
fn a_still_root_above_moving_hips_exports_as_the_file_defines_it() {
    use glam::{DMat4, DVec3};
    // (name, parent, OFFSET, position channels, rotation order): Hips' OFFSET is not where
    // its channels put it.
    let joints: [BvhJoint; 5] = [
        ("joint_Root", None, [0.0, 0.0, 0.0], true, "ZYX"),
        ("Hips", Some(0), [0.0, 0.0, 0.0], true, "ZYX"),
        ("Spine", Some(1), [0.0, 20.0, 0.0], false, "ZXY"),
        ("LeftUpLeg", Some(1), [10.0, -5.0, 0.0], false, "ZXY"),
        ("LeftLeg", Some(3), [0.0, -45.0, 0.0], false, "ZXY"),
    ];
    let frames = 12;
    let dt = 1.0 / 30.0;
    // Each frame's channel values per joint: (position, rotations in the joint's order).
    let values = |f: usize, j: usize| -> ([f64; 3], [f64; 3]) {
        let t = f as f64;
        match j {
            0 => ([5.0, 0.0, -3.0], [0.0, 30.0, 0.0]),
            1 => ([2.0 + 3.0 * t, 92.0 + (0.5 * t).sin(), 1.5 * t], [4.0 * t, -10.0 + t, 3.0]),
            k => ([0.0; 3], [7.0 * (t + k as f64).sin(), 20.0 - 2.0 * t, 5.0 * k as f64 - t]),
        }
    };
    let mut text = String::from("HIERARCHY\n");
    let mut close = Vec::new();
    for (j, (name, parent, offset, positions, order)) in joints.iter().enumerate() {
        while close.last().is_some_and(|&open| Some(open) != *parent) {
            close.pop();
            text.push_str("}\n");
        }
        let kind = if parent.is_none() { "ROOT" } else { "JOINT" };
        let axes: Vec<String> = order.chars().map(|a| format!("{a}rotation")).collect();
        let channels = if *positions {
            format!("6 Xposition Yposition Zposition {}", axes.join(" "))
        } else {
            format!("3 {}", axes.join(" "))
        };
        text.push_str(&format!(
            "{kind} {name}\n{{\nOFFSET {} {} {}\nCHANNELS {channels}\n",
            offset[0], offset[1], offset[2]
        ));
        if matches!(*name, "Spine" | "LeftLeg") {
            text.push_str("End Site\n{\nOFFSET 0 10 0\n}\n");
        }
        close.push(j);
    }
    close.iter().for_each(|_| text.push_str("}\n"));
    text.push_str(&format!("MOTION\nFrames: {frames}\nFrame Time: {dt}\n"));
    for f in 0..frames {
        let mut row = Vec::new();
        for (j, joint) in joints.iter().enumerate() {
            let (p, r) = values(f, j);
            if joint.3 {
                row.extend(p);
            }
            row.extend(r);
        }
        text.push_str(&row.iter().map(|v| format!("{v:.6}")).collect::<Vec<_>>().join(" "));
        text.push('\n');
    }
    let dir = scratch("bandai-still-root");
    let (bvh, glb) = (dir.join("still_root.bvh"), dir.join("still_root.glb"));
    std::fs::write(&bvh, &text).unwrap();
    let run = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_marionette")).args(args).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let info = run(&["info", bvh.to_str().unwrap()]);
    assert!(
        info.contains("Hips")
            && info.lines().any(|l| l.contains(" Hips ") && l.contains("offset (0.0000, 0.0000, 0.0000)")),
        "{info}"
    );
    run(&["export", bvh.to_str().unwrap(), "--animation", "--out", glb.to_str().unwrap()]);
    // The file's definition, walked here in double precision.
    let defined = |f: usize| -> Vec<DVec3> {
        let mut world: Vec<DMat4> = Vec::new();
        for (j, (_, parent, offset, positions, order)) in joints.iter().enumerate() {
            let (p, r) = values(f, j);
            let at = DVec3::from_array(if *positions { p } else { *offset });
            let turn = order.chars().zip(r).fold(DMat4::IDENTITY, |m, (axis, deg)| {
                let angle = f64::to_radians(deg);
                m * match axis {
                    'X' => DMat4::from_rotation_x(angle),
                    'Y' => DMat4::from_rotation_y(angle),
                    _ => DMat4::from_rotation_z(angle),
                }
            });
            let up = parent.map_or(DMat4::IDENTITY, |p| world[p]);
            world.push(up * DMat4::from_translation(at) * turn);
        }
        world.iter().map(|m| m.w_axis.truncate()).collect()
    };
    let spec = crate::gltf_spec::SpecFile::read(&glb);
    let node = |name: &str| spec.nodes().iter().position(|n| n["name"] == name).unwrap_or_else(|| panic!("{name}"));
    let size = 92.0 + 45.0;
    let mut worst = 0.0f64;
    for f in 0..frames {
        let globals = spec.node_globals(Some((0, f as f64 * dt)));
        for (j, joint) in joints.iter().enumerate() {
            let got = globals[node(joint.0)].w_axis.truncate();
            worst = worst.max(got.distance(defined(f)[j]) / size);
        }
    }
    eprintln!("worst joint off the file's definition: {worst:.2e} of the skeleton's size");
    assert!(worst < 1e-5, "{worst}");
}

/// A BVH joint read for rewriting: its name, OFFSET, channel names, its motion columns, its
/// children and its End Site.
struct BvhNode {
    name: String,
    offset: [f64; 3],
    channels: Vec<String>,
    columns: std::ops::Range<usize>,
    children: Vec<BvhNode>,
    end: Option<[f64; 3]>,
}

/// `text`'s skeleton and frames (each a row of numbers).
fn read_bvh_tree(text: &str) -> (BvhNode, String, Vec<Vec<f64>>) {
    let (hierarchy, motion) = text.split_once("MOTION").unwrap();
    let mut words = hierarchy.split_whitespace().peekable();
    let mut column = 0;
    fn node(words: &mut std::iter::Peekable<std::str::SplitWhitespace<'_>>, column: &mut usize) -> BvhNode {
        let name = words.next().unwrap().to_string();
        assert_eq!(words.next(), Some("{"));
        assert_eq!(words.next(), Some("OFFSET"));
        let mut v = || words.next().unwrap().parse::<f64>().unwrap();
        let offset = [v(), v(), v()];
        assert_eq!(words.next(), Some("CHANNELS"));
        let n: usize = words.next().unwrap().parse().unwrap();
        let channels: Vec<String> = (0..n).map(|_| words.next().unwrap().to_string()).collect();
        let columns = *column..*column + n;
        *column += n;
        let (mut children, mut end) = (Vec::new(), None);
        loop {
            match words.next().unwrap() {
                "JOINT" => children.push(node(words, column)),
                "End" => {
                    let _site = words.next();
                    let _open = words.next();
                    let _offset = words.next();
                    let mut v = || words.next().unwrap().parse::<f64>().unwrap();
                    end = Some([v(), v(), v()]);
                    let _close = words.next();
                }
                "}" => break,
                other => panic!("{other}"),
            }
        }
        BvhNode { name, offset, channels, columns, children, end }
    }
    assert_eq!(words.next(), Some("HIERARCHY"));
    assert_eq!(words.next(), Some("ROOT"));
    let root = node(&mut words, &mut column);
    let mut lines = motion.lines().filter(|l| !l.trim().is_empty());
    let header = format!("{}\n{}\n", lines.next().unwrap().trim(), lines.next().unwrap().trim());
    let frames = lines.map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect()).collect();
    (root, header, frames)
}

/// `cmu_walk.bvh` in another family's shape: the joints `drop` names taken out (their
/// children hung from their parents, moved by their offsets; their channels gone) and every
/// other renamed by `rename` (a name it does not know kept).
fn bvh_in_family(drop: &[&str], rename: &dyn Fn(&str) -> Option<String>) -> String {
    let (root, header, frames) = read_bvh_tree(&std::fs::read_to_string(fixture("cmu_walk.bvh")).unwrap());
    fn kept(node: BvhNode, drop: &[&str], moved: [f64; 3]) -> Vec<BvhNode> {
        let offset = [node.offset[0] + moved[0], node.offset[1] + moved[1], node.offset[2] + moved[2]];
        if drop.contains(&node.name.as_str()) {
            return node.children.into_iter().flat_map(|c| kept(c, drop, offset)).collect();
        }
        let children = node.children.into_iter().flat_map(|c| kept(c, drop, [0.0; 3])).collect();
        vec![BvhNode { offset, children, ..node }]
    }
    let root = kept(root, drop, [0.0; 3]).pop().unwrap();
    let mut text = String::from("HIERARCHY\n");
    let mut columns = Vec::new();
    fn write(
        node: &BvhNode,
        root: bool,
        rename: &dyn Fn(&str) -> Option<String>,
        text: &mut String,
        columns: &mut Vec<usize>,
    ) {
        let name = rename(&node.name).unwrap_or_else(|| node.name.clone());
        let [x, y, z] = node.offset;
        *text += &format!(
            "{} {name}\n{{\nOFFSET {x} {y} {z}\nCHANNELS {} {}\n",
            if root { "ROOT" } else { "JOINT" },
            node.channels.len(),
            node.channels.join(" ")
        );
        columns.extend(node.columns.clone());
        for child in &node.children {
            write(child, false, rename, text, columns);
        }
        if let Some([x, y, z]) = node.end.filter(|_| node.children.is_empty()) {
            *text += &format!("End Site\n{{\nOFFSET {x} {y} {z}\n}}\n");
        }
        *text += "}\n";
    }
    write(&root, true, rename, &mut text, &mut columns);
    text += &format!("MOTION\n{header}");
    for row in frames {
        text += &columns.iter().map(|&c| format!("{}", row[c])).collect::<Vec<_>>().join(" ");
        text.push('\n');
    }
    text
}

/// The CMU walk written as MotionBuilder (HumanIK) and Mixamo files are shaped: no
/// pelvis-side hip joints, one neck, no thumbs or finger bases; MotionBuilder's names, and
/// Mixamo's (`mixamorig:` and its three spine joints).
fn family_walks() -> Vec<PathBuf> {
    let drop = ["LHipJoint", "RHipJoint", "Neck1", "LThumb", "RThumb", "LeftFingerBase", "RightFingerBase"];
    let dir = scratch("bvh-families");
    let mixamo = |name: &str| {
        let renamed = match name {
            "LowerBack" => "Spine",
            "Spine" => "Spine1",
            "Spine1" => "Spine2",
            other => other,
        };
        Some(format!("mixamorig:{renamed}"))
    };
    let mut out = Vec::new();
    for (file, rename) in
        [("motionbuilder_walk.bvh", &(|_: &str| None) as &dyn Fn(&str) -> Option<String>), ("mixamo_walk.bvh", &mixamo)]
    {
        let path = dir.join(file);
        std::fs::write(&path, bvh_in_family(&drop, rename)).unwrap();
        out.push(path);
    }
    out
}

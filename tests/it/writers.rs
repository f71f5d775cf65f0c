//! A property of every writer: what is written from a valid model — any finite pose,
//! placement, scale, tint or clip, however extreme — never holds a number that is not
//! finite. Either the file is written with finite numbers only, or the writer refuses and
//! writes nothing. Cases come from a seeded generator (each run replays them).

use std::path::Path;

use arbitrary::Unstructured;
use glam::{EulerRot, Quat, Vec3};
use marionette::formats::gltf::{GltfCharacter, GltfMesh, Motion, write_glb};
use marionette::formats::scene::{CharacterDoc, PlacementDoc, SceneDoc, SourceDoc, parse_scene};
use marionette::formats::{gltf_import, load_character, obj};
use marionette::rig::dqs::SkinningMethod;
use marionette::rig::{CharacterAsset, EulerOrder, JointRotation};
use serde_json::Value;

use crate::fuzz::random_bytes;

const CASES: u64 = 300;

/// Finite numbers from ordinary to extreme.
const FINITE: &[f32] = &[0.0, -0.0, 0.3, -1.7, 2.5, 100.0, -1e4, 1e15, -1e30, 3.4e38, -3.4e38, 1e-30, 1e-45];

fn finite(u: &mut Unstructured) -> arbitrary::Result<f32> {
    Ok(if u.arbitrary()? { *u.choose(FINITE)? } else { u.int_in_range(-4000..=4000i32)? as f32 / 1000.0 })
}

fn vec3(u: &mut Unstructured) -> arbitrary::Result<Vec3> {
    Ok(Vec3::new(finite(u)?, finite(u)?, finite(u)?))
}

/// A pose of `joints` joints: Euler angles or (non-zero) quaternions of any finite size.
fn pose(joints: usize, u: &mut Unstructured) -> arbitrary::Result<Vec<JointRotation>> {
    (0..joints)
        .map(|_| {
            Ok(if u.arbitrary()? {
                JointRotation::Euler(vec3(u)?, EulerOrder::Xyz)
            } else {
                let q = Quat::from_xyzw(finite(u)?, finite(u)?, finite(u)?, finite(u)?);
                let q = if q.length_squared() > 1e-12 && q.length_squared().is_finite() { q } else { Quat::IDENTITY };
                JointRotation::Quat(q)
            })
        })
        .collect()
}

fn models() -> Vec<CharacterAsset> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut models = vec![load_character(&root.join("assets/puppet.skel")).unwrap()];
    models
        .extend(gltf_import::load_gltf(&root.join("tests/data/blender_arm.glb")).unwrap().into_iter().map(|c| c.asset));
    models
}

/// Every number in an OBJ's `v` lines is finite.
fn obj_is_finite(text: &str) -> bool {
    text.lines()
        .filter(|l| l.starts_with("v "))
        .flat_map(|l| l[2..].split(' '))
        .all(|t| t.parse::<f32>().is_ok_and(f32::is_finite))
}

/// Every JSON number is one (no null stands for a NaN) and every float of every FLOAT
/// accessor is finite.
fn glb_is_finite(glb: &[u8]) -> bool {
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let json: Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let bin = &glb[28 + json_len..];
    fn no_null_in_arrays(v: &Value) -> bool {
        match v {
            Value::Array(items) => items.iter().all(|i| !i.is_null() && no_null_in_arrays(i)),
            Value::Object(fields) => fields.values().all(no_null_in_arrays),
            _ => true,
        }
    }
    let floats_finite = json["accessors"].as_array().unwrap().iter().filter(|a| a["componentType"] == 5126).all(|a| {
        let view = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
        let (at, len) =
            (view["byteOffset"].as_u64().unwrap_or(0) as usize, view["byteLength"].as_u64().unwrap() as usize);
        bin[at..at + len].chunks_exact(4).all(|f| f32::from_le_bytes(f.try_into().unwrap()).is_finite())
    });
    no_null_in_arrays(&json) && floats_finite
}

#[test]
fn no_obj_gltf_or_scene_written_from_a_valid_model_holds_a_non_finite_number() {
    let models = models();
    let (mut written, mut refused) = ([0; 3], [0; 3]);
    for case in 0..CASES {
        let noise = random_bytes(0x5eed ^ case, 512);
        let mut u = Unstructured::new(&noise);
        let asset = &models[case as usize % models.len()];
        let pose = pose(asset.skeleton.len(), &mut u).unwrap();
        let (translation, yaw) = (vec3(&mut u).unwrap(), finite(&mut u).unwrap());
        let scale = finite(&mut u).unwrap().abs().max(1e-30);
        let method = if u.arbitrary().unwrap() { SkinningMethod::Linear } else { SkinningMethod::DualQuaternion };

        // OBJ: the posed, placed mesh.
        let placement = glam::Mat4::from_scale_rotation_translation(
            Vec3::splat(scale),
            Quat::from_euler(EulerRot::YXZ, yaw, 0.0, 0.0),
            translation,
        );
        let positions = marionette::document::posing::posed_positions_by(asset, &pose, placement, method);
        let mut text = Vec::new();
        match obj::write_obj(&mut text, &positions, &asset.skin.triangles) {
            Ok(()) => {
                assert!(
                    obj_is_finite(&String::from_utf8(text).unwrap()),
                    "case {case}: an OBJ with a non-finite number"
                );
                written[0] += 1;
            }
            Err(_) => refused[0] += 1,
        }

        // glTF: skinned, with a motion of two poses.
        let second = self::pose(asset.skeleton.len(), &mut u).unwrap();
        let motion = Motion {
            times: vec![0.0, finite(&mut u).unwrap().abs().max(1e-3)],
            poses: vec![pose.clone(), second],
            roots: vec![vec3(&mut u).unwrap(), vec3(&mut u).unwrap()],
            rests: Vec::new(),
        };
        let character = GltfCharacter {
            placement: marionette::formats::scene::PlacementDoc::new(translation, yaw, scale),
            tint: [finite(&mut u).unwrap(), 0.5, 0.5],
            motion: Some(motion),
            ..GltfCharacter::new("c", asset, &pose)
        };
        let mesh = if u.arbitrary().unwrap() { GltfMesh::Skinned } else { GltfMesh::Baked };
        match write_glb(&[character], mesh) {
            Ok(glb) => {
                assert!(glb_is_finite(&glb), "case {case}: a glTF with a non-finite number");
                written[1] += 1;
            }
            Err(_) => refused[1] += 1,
        }

        // Scene: what is written reads back (reading refuses any non-finite number).
        let mut c = CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "p");
        c.placement = PlacementDoc::new(translation, yaw, scale);
        c.morphs = vec![finite(&mut u).unwrap()];
        c.pose.insert("l_elbow".into(), pose[0]);
        let doc = SceneDoc { characters: vec![c], ..SceneDoc::default() };
        let dir = crate::common::scratch(&format!("writers-{case}"));
        match marionette::formats::scene::save_scene(&dir.join("s.ron"), &doc) {
            Ok(()) => {
                let text = std::fs::read_to_string(dir.join("s.ron")).unwrap();
                assert_eq!(parse_scene(text.as_bytes(), Path::new("s.ron")).unwrap(), doc, "case {case}");
                written[2] += 1;
            }
            Err(_) => {
                assert!(!dir.join("s.ron").exists());
                refused[2] += 1;
            }
        }
        let _ = std::fs::remove_dir_all(dir);
    }
    eprintln!("writers: {CASES} cases; written (OBJ, glTF, scene) {written:?}, refused {refused:?}");
    // The generator reaches both outcomes for the mesh writers.
    assert!(written.iter().all(|&w| w > 0) && refused[0] > 0, "written {written:?}, refused {refused:?}");
}

//! glTF export: the file read back here on its own (GLB chunks, JSON, the binary buffer)
//! and skinned as the glTF spec says gives our skinned vertices; names, hierarchy and
//! weights come back as they went out.

use glam::{Mat4, Quat, Vec3};
use marionette::formats::gltf::{GltfCharacter, GltfMesh, write_glb};
use marionette::rig::JointRotation;

/// The JSON and the binary chunk of a GLB.
fn chunks(glb: &[u8]) -> (serde_json::Value, Vec<u8>) {
    let u32_at = |at: usize| u32::from_le_bytes(glb[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&glb[0..4], b"glTF");
    assert_eq!(u32_at(8), glb.len());
    let json_len = u32_at(12);
    assert_eq!(&glb[16..20], b"JSON");
    let json = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let bin_at = 20 + json_len;
    assert_eq!(&glb[bin_at + 4..bin_at + 8], b"BIN\0");
    (json, glb[bin_at + 8..bin_at + 8 + u32_at(bin_at)].to_vec())
}

/// An accessor's floats (or u16/u32 as floats).
fn read(json: &serde_json::Value, bin: &[u8], accessor: usize) -> Vec<f32> {
    let a = &json["accessors"][accessor];
    let view = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let start = view["byteOffset"].as_u64().unwrap() as usize;
    let bytes = &bin[start..start + view["byteLength"].as_u64().unwrap() as usize];
    match a["componentType"].as_u64().unwrap() {
        5126 => bytes.chunks(4).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect(),
        5123 => bytes.chunks(2).map(|b| f32::from(u16::from_le_bytes(b.try_into().unwrap()))).collect(),
        5125 => bytes.chunks(4).map(|b| u32::from_le_bytes(b.try_into().unwrap()) as f32).collect(),
        other => panic!("component type {other}"),
    }
}

fn local(node: &serde_json::Value) -> Mat4 {
    let v = |k: &str, n: usize, d: f32| -> Vec<f32> {
        node[k].as_array().map_or(vec![d; n], |a| a.iter().map(|x| x.as_f64().unwrap() as f32).collect())
    };
    let (t, r, s) =
        (v("translation", 3, 0.0), node["rotation"].as_array().map(|_| v("rotation", 4, 0.0)), v("scale", 3, 1.0));
    let r = r.map_or(Quat::IDENTITY, |r| Quat::from_xyzw(r[0], r[1], r[2], r[3]));
    Mat4::from_scale_rotation_translation(Vec3::new(s[0], s[1], s[2]), r, Vec3::new(t[0], t[1], t[2]))
}

/// Every node's global matrix, from the scene's roots down.
fn globals(json: &serde_json::Value) -> Vec<Mat4> {
    let nodes = json["nodes"].as_array().unwrap();
    let mut out = vec![Mat4::IDENTITY; nodes.len()];
    let mut todo: Vec<(usize, Mat4)> = json["scenes"][0]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| (n.as_u64().unwrap() as usize, Mat4::IDENTITY))
        .collect();
    while let Some((n, parent)) = todo.pop() {
        out[n] = parent * local(&nodes[n]);
        for c in nodes[n]["children"].as_array().into_iter().flatten() {
            todo.push((c.as_u64().unwrap() as usize, out[n]));
        }
    }
    out
}

/// The largest distance between corresponding points.
fn largest_distance(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter().zip(b).map(|(p, q)| p.distance(*q)).fold(0.0f32, f32::max)
}

/// A line of numbers, `x y z ...`.
fn numbers(line: &str) -> Vec<f32> {
    line.split_whitespace().map(|x| x.parse().unwrap()).collect()
}

#[test]
fn an_exported_character_skins_back_to_our_vertices_with_its_names_and_weights() {
    let puppet = marionette::formats::puppet::embedded_puppet();
    let skeleton = &puppet.skeleton;
    let mut pose = skeleton.initial_pose();
    pose[skeleton.find("l_elbow").unwrap()] = JointRotation::euler_xyz(0.2, -1.1, 0.3);
    pose[0] = JointRotation::Quat(Quat::from_rotation_y(0.7));
    let root = skeleton.joint(0).rest_offset + Vec3::new(0.1, 0.05, -0.2);
    let character = GltfCharacter {
        root,
        placement: marionette::formats::scene::PlacementDoc::new(Vec3::new(1.0, 0.0, -2.0), 0.6, 1.5),
        tint: [0.2, 0.4, 0.6],
        ..GltfCharacter::new("p", &puppet, &pose)
    };
    let (json, bin) = chunks(&write_glb(&[character], GltfMesh::Skinned).unwrap());

    // Our skinned vertices, placed.
    let placement =
        Mat4::from_scale_rotation_translation(Vec3::splat(1.5), Quat::from_rotation_y(0.6), Vec3::new(1.0, 0.0, -2.0));
    let origin = Mat4::from_translation(root - skeleton.joint(0).rest_offset);
    let ours: Vec<Vec3> = marionette::document::posing::posed_positions(&puppet, &pose, origin)
        .into_iter()
        .map(|p| placement.transform_point3(p))
        .collect();

    // The file's, as the spec skins: Σ w · (global(joint) · inverseBind) · position.
    let skin = &json["skins"][0];
    let joints: Vec<usize> = skin["joints"].as_array().unwrap().iter().map(|j| j.as_u64().unwrap() as usize).collect();
    let names: Vec<&str> = joints.iter().map(|&n| json["nodes"][n]["name"].as_str().unwrap()).collect();
    assert_eq!(names, skeleton.joints().iter().map(|j| j.name.as_str()).collect::<Vec<_>>(), "names in joint order");
    for (j, &n) in joints.iter().enumerate() {
        let children: Vec<usize> = json["nodes"][n]["children"].as_array().map_or(Vec::new(), |c| {
            c.iter().map(|k| joints.iter().position(|&x| x == k.as_u64().unwrap() as usize).unwrap()).collect()
        });
        assert_eq!(children, skeleton.children(j), "the hierarchy of joint {j}");
    }
    let ibm = read(&json, &bin, skin["inverseBindMatrices"].as_u64().unwrap() as usize);
    let g = globals(&json);
    let joint_matrices: Vec<Mat4> =
        joints.iter().enumerate().map(|(j, &n)| g[n] * Mat4::from_cols_slice(&ibm[16 * j..16 * j + 16])).collect();
    let primitive = &json["meshes"][0]["primitives"][0];
    let attribute = |name: &str| read(&json, &bin, primitive["attributes"][name].as_u64().unwrap() as usize);
    let (positions, joint_ids, weights) = (attribute("POSITION"), attribute("JOINTS_0"), attribute("WEIGHTS_0"));
    assert_eq!(positions.len(), 3 * ours.len());
    for (v, want) in ours.iter().enumerate() {
        let p = Vec3::from_slice(&positions[3 * v..3 * v + 3]);
        let mut got = Vec3::ZERO;
        for k in 0..4 {
            let w = weights[4 * v + k];
            got += w * joint_matrices[joint_ids[4 * v + k] as usize].transform_point3(p);
            if w > 0.0 {
                let joint = joint_ids[4 * v + k] as usize;
                assert!((puppet.skin.weights.weight(v, joint) - w).abs() < 1e-7, "the weights go out as they are");
            }
        }
        assert!((got - *want).length() < 1e-5, "vertex {v}: {got} vs {want}");
    }
    assert_eq!(json["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"][1].as_f64().unwrap() as f32, 0.4);
}

/// More than four influences (Model1 has up to 13) go out in further sets of four.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn more_than_four_influences_go_into_further_sets() {
    let model = marionette::formats::load_character(&crate::common::data_dir().join("mit6837/Model1.skel")).unwrap();
    let pose = model.skeleton.initial_pose();
    let character = GltfCharacter::new("m", &model, &pose);
    let (json, bin) = chunks(&write_glb(&[character], GltfMesh::Skinned).unwrap());
    let attributes = &json["meshes"][0]["primitives"][0]["attributes"];
    let sets = model.skin.weights.max_influences().div_ceil(4);
    assert!(sets > 1);
    for s in 0..sets {
        assert!(attributes.get(format!("WEIGHTS_{s}")).is_some(), "set {s}");
    }
    let total: f32 = (0..sets)
        .map(|s| {
            read(&json, &bin, attributes[format!("WEIGHTS_{s}")].as_u64().unwrap() as usize)[0..4].iter().sum::<f32>()
        })
        .sum();
    assert!((total - 1.0).abs() < 1e-5, "vertex 0's weights over all sets sum to 1: {total}");
}

/// A scene's SMPL body goes out in its shape (β), not the mean one.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn a_scene_exports_its_smpl_body_in_its_shape() {
    use marionette::formats::scene::{CharacterDoc, SceneDoc, SmplDoc, SourceDoc};
    let dir = crate::common::data_dir().join("smpl");
    let betas = vec![2.0, -1.0];
    let body = CharacterDoc {
        smpl: Some(SmplDoc { betas: betas.clone(), ..SmplDoc::default() }),
        ..CharacterDoc::new(SourceDoc::File(dir.clone()), "b")
    };
    let doc = SceneDoc { characters: vec![body], ..SceneDoc::default() };
    let (json, bin) = chunks(&marionette::document::export::scene_glb(&doc, GltfMesh::Skinned, false).unwrap());
    let positions =
        read(&json, &bin, json["meshes"][0]["primitives"][0]["attributes"]["POSITION"].as_u64().unwrap() as usize);
    let (model, _) = marionette::formats::smpl::load_smpl_dir(&dir).unwrap();
    let shaped = model.asset("b", &betas).unwrap();
    let mean = model.asset("b", &[]).unwrap();
    let at = |v: usize| Vec3::from_slice(&positions[3 * v..3 * v + 3]);
    assert!((0..shaped.vertex_count()).all(|v| (at(v) - shaped.skin.bind_positions[v]).length() < 1e-6));
    assert!(
        (0..mean.vertex_count()).any(|v| (at(v) - mean.skin.bind_positions[v]).length() > 1e-3),
        "not the mean shape"
    );
}

/// An SMPL body playing a clip goes out with `--animation` as a glTF animation of every
/// frame (30 per second): at frame f each joint's rotation is the clip's frame f.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn an_smpl_body_playing_a_clip_goes_out_as_an_animation_of_its_frames() {
    use marionette::formats::scene::{CharacterDoc, SceneDoc, SmplDoc, SourceDoc};
    let dir = crate::common::data_dir().join("smpl");
    let clip_path = marionette::formats::smpl::clip_paths(&dir)[0].clone();
    let name = clip_path.file_name().unwrap().to_string_lossy().into_owned();
    let body = CharacterDoc {
        smpl: Some(SmplDoc { clip: Some(name), upright: false, ..SmplDoc::default() }),
        ..CharacterDoc::new(SourceDoc::File(dir.clone()), "b")
    };
    let doc = SceneDoc { characters: vec![body], ..SceneDoc::default() };
    let (json, bin) = chunks(&marionette::document::export::scene_glb(&doc, GltfMesh::Skinned, true).unwrap());
    let (model, _) = marionette::formats::smpl::load_smpl_dir(&dir).unwrap();
    let clip = marionette::formats::smpl::parse_clip(
        std::io::BufReader::new(std::fs::File::open(&clip_path).unwrap()),
        &clip_path,
        model.skeleton.len(),
    )
    .unwrap();
    let animation = &json["animations"][0];
    let joint_nodes: Vec<u64> =
        json["skins"][0]["joints"].as_array().unwrap().iter().map(|j| j.as_u64().unwrap()).collect();
    let mut checked = 0;
    for channel in animation["channels"].as_array().unwrap() {
        if channel["target"]["path"] != "rotation" {
            continue;
        }
        let j = joint_nodes.iter().position(|&n| n == channel["target"]["node"].as_u64().unwrap()).unwrap();
        let sampler = &animation["samplers"][channel["sampler"].as_u64().unwrap() as usize];
        let times = read(&json, &bin, sampler["input"].as_u64().unwrap() as usize);
        let values = read(&json, &bin, sampler["output"].as_u64().unwrap() as usize);
        assert_eq!(times.len(), clip.frame_count());
        for f in [0, 1, clip.frame_count() / 2, clip.frame_count() - 1] {
            assert!((times[f] - f as f32 / 30.0).abs() < 1e-6);
            let q = Quat::from_slice(&values[4 * f..4 * f + 4]);
            assert!(q.dot(clip.frame(f)[j]).abs() > 1.0 - 1e-6, "joint {j} frame {f}");
        }
        checked += 1;
    }
    assert_eq!(checked, model.skeleton.len());
}

/// A keyframed clip goes out as CUBICSPLINE tracks, key for key: every seam of the clip's
/// channels in its range (keys, and keys of their cycles) is a key time of its tracks, and
/// the file read as the glTF spec says (`gltf_spec`, double precision) deforms as our
/// posing of the clip does at times between the keys, within `tolerance` of its size.
/// Returns the worst difference (of the size) and the number of keys.
fn keyframes_go_out_as_splines(
    asset: &marionette::rig::CharacterAsset,
    clip: &marionette::rig::anim::Clip,
    tolerance: f64,
) -> (f64, usize) {
    use marionette::rig::anim::Clip;
    let skeleton = &asset.skeleton;
    let rest = skeleton.initial_pose();
    let splines = marionette::document::export::keyframes_as_splines(clip, skeleton, &rest, "walk").unwrap();
    let clips = [splines];
    let (start, end) = clip.range;
    let (root, pose) = clip.pose_at(skeleton, start, &rest);
    let character = GltfCharacter { root, clips: &clips, ..GltfCharacter::new("c", asset, &pose) };
    let glb = write_glb(&[character], GltfMesh::Skinned).unwrap();
    let path = crate::common::scratch(&format!("keyframe-splines-{}", asset.name)).join("c.glb");
    std::fs::write(&path, &glb).unwrap();
    let (json, bin) = chunks(&glb);
    let animation = &json["animations"][0];
    assert_eq!(animation["name"], "walk");
    let mut key_times = Vec::new();
    for sampler in animation["samplers"].as_array().unwrap() {
        assert_eq!(sampler["interpolation"], "CUBICSPLINE");
        key_times.extend(read(&json, &bin, sampler["input"].as_u64().unwrap() as usize));
    }
    let channels = Clip::joint_channel(skeleton.len(), 0);
    for (c, channel) in clip.channels.iter().enumerate().take(channels).filter(|(_, c)| !c.keys().is_empty()) {
        for seam in channel.seams(clip.range, 100_000).unwrap() {
            assert!(key_times.contains(&(seam - start)), "channel {c}: no key at {seam}");
        }
    }
    let spec = super::gltf_spec::SpecFile::read(&path);
    let (lo, hi) = marionette::rig::skinning::bounds(&asset.skin.bind_positions);
    let size = f64::from((hi - lo).length());
    let mut worst = 0.0f64;
    let steps = 397;
    for step in 0..=steps {
        let t = start + (end - start) * step as f32 / steps as f32;
        let (root, pose) = clip.pose_at(skeleton, t, &rest);
        let origin = Mat4::from_translation(root - skeleton.joint(0).rest_offset);
        let ours = marionette::document::posing::posed_positions(asset, &pose, origin);
        let theirs = spec.posed(Some((0, f64::from(t - start))));
        assert_eq!(ours.len(), theirs.len());
        for (a, b) in ours.iter().zip(&theirs) {
            worst = worst.max((a.as_dvec3() - *b).length() / size);
        }
    }
    assert!(worst < tolerance, "worst {worst:e} of the size");
    (worst, key_times.len())
}

/// The puppet under a clip of every kind of key: a stepped, bouncing root, a cycling
/// shoulder, a knee driven past its limits (clamped, kinks and all).
#[test]
fn a_keyframed_clip_with_steps_cycles_and_limits_goes_out_as_splines() {
    use marionette::rig::anim::{Channel, Clip, Extrapolation, Key, Tangent};
    let mut puppet = marionette::formats::puppet::embedded_puppet();
    let knee = puppet.skeleton.find("l_knee").unwrap();
    let limit = 1.1;
    let raw = puppet.skeleton.joints().iter().enumerate().map(|(j, def)| {
        let mut raw = marionette::rig::RawJoint::new(&def.name, def.parent, def.rest_offset);
        if j == knee {
            raw.limits = marionette::rig::DofLimits { min: glam::Vec3::splat(-0.2), max: glam::Vec3::splat(limit) };
        }
        raw
    });
    puppet.skeleton = marionette::rig::Skeleton::build(raw.collect()).unwrap();
    let skeleton = &puppet.skeleton;
    let key = |time, value, tangent: Tangent| Key { time, value, tangent_in: tangent, tangent_out: tangent };
    let channel = |keys, before, after| Channel::new(keys, before, after);
    let mut clip = Clip::empty(skeleton.len());
    clip.range = (0.25, 3.0);
    let offset = skeleton.joint(0).rest_offset;
    clip.channels[1] = channel(
        vec![
            key(0.0, offset.y, Tangent::Step),
            key(0.5, offset.y + 0.2, Tangent::Smooth),
            key(1.0, offset.y + 0.1, Tangent::Flat),
        ],
        Extrapolation::Constant,
        Extrapolation::Bounce,
    );
    let shoulder = skeleton.find("r_shoulder").unwrap();
    clip.channels[Clip::joint_channel(shoulder, 2)] = channel(
        vec![key(0.0, 0.0, Tangent::Smooth), key(0.4, -1.2, Tangent::Smooth), key(0.8, -0.3, Tangent::Smooth)],
        Extrapolation::Cycle,
        Extrapolation::CycleOffset,
    );
    clip.channels[Clip::joint_channel(shoulder, 0)] = channel(
        vec![key(0.3, 0.5, Tangent::Linear), key(1.9, -0.4, Tangent::Linear)],
        Extrapolation::Linear,
        Extrapolation::Constant,
    );
    clip.channels[Clip::joint_channel(knee, 0)] = channel(
        vec![key(0.0, limit - 1.0, Tangent::Smooth), key(1.5, limit + 1.0, Tangent::Smooth)],
        Extrapolation::Constant,
        Extrapolation::Bounce,
    );
    let (worst, keys) = keyframes_go_out_as_splines(&puppet, &clip, 1e-4);
    eprintln!("puppet: worst {worst:.2e} of its size, {keys} keys");
}

/// The wasp's walk (smooth keys, cycles with offset) goes out key for key.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn the_wasp_walk_goes_out_as_splines_key_for_key() {
    let data = crate::common::data_dir().join("cse169/project3");
    let wasp = marionette::formats::load_character(&data.join("wasp.skel")).unwrap();
    let clip = marionette::formats::load_clip(&data.join("wasp_walk.anim")).unwrap();
    let (worst, keys) = keyframes_go_out_as_splines(&wasp, &clip, 1e-4);
    eprintln!("wasp walk: worst {worst:.2e} of its size, {keys} keys");
}

/// Marionette → glb → Marionette: the same skinned vertices, joint names, hierarchy and
/// weights.
#[test]
fn a_round_trip_through_glb_keeps_vertices_names_hierarchy_and_weights() {
    let puppet = marionette::formats::puppet::embedded_puppet();
    let skeleton = &puppet.skeleton;
    let mut pose = skeleton.initial_pose();
    pose[skeleton.find("r_shoulder").unwrap()] = JointRotation::euler_xyz(0.4, 0.2, -1.0);
    pose[skeleton.find("l_knee").unwrap()] = JointRotation::euler_xyz(0.9, 0.0, 0.0);
    let character = GltfCharacter::new("p", &puppet, &pose);
    let path = crate::common::scratch("gltf-round-trip").join("p.glb");
    std::fs::write(&path, write_glb(&[character], GltfMesh::Skinned).unwrap()).unwrap();
    let back = marionette::formats::load_character(&path).unwrap();
    let names =
        |s: &marionette::rig::Skeleton| s.joints().iter().map(|j| (j.name.clone(), j.parent)).collect::<Vec<_>>();
    assert_eq!(names(&back.skeleton), names(skeleton), "names and hierarchy");
    let ours = marionette::document::posing::posed_positions(&puppet, &pose, Mat4::IDENTITY);
    let theirs = marionette::document::posing::posed_positions(&back, &back.skeleton.initial_pose(), Mat4::IDENTITY);
    let worst = largest_distance(&ours, &theirs);
    assert!(worst <= 1e-5, "skinned vertices differ by {worst}");
    for v in 0..puppet.vertex_count() {
        for j in 0..skeleton.len() {
            assert!((puppet.skin.weights.weight(v, j) - back.skin.weights.weight(v, j)).abs() < 1e-6, "weight {v} {j}");
        }
    }
}

/// A rigged arm made and exported by Blender 5 (`scripts/make_gltf_fixture.py`: bones with
/// rest rotations, automatic weights, a pose): loaded here, it deforms as Blender deforms
/// it (`tests/data/blender_arm.txt`, vertex by vertex).
#[test]
fn a_blender_made_glb_deforms_as_blender_deforms_it() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let arm = marionette::formats::load_character(&data.join("blender_arm.glb")).unwrap();
    assert_eq!(arm.skeleton.joints().iter().map(|j| j.name.as_str()).collect::<Vec<_>>(), ["upper", "lower"]);
    let ours = marionette::document::posing::posed_positions(&arm, &arm.skeleton.initial_pose(), Mat4::IDENTITY);
    let text = std::fs::read_to_string(data.join("blender_arm.txt")).unwrap();
    let blender: Vec<Vec3> = text.lines().map(|l| Vec3::from_slice(&numbers(l))).collect();
    assert_eq!(ours.len(), blender.len());
    let worst = largest_distance(&ours, &blender);
    assert!(worst <= 1e-5, "{worst}");
}

/// `tests/data/blender_pair.txt`: per mesh, its morph deltas (lines after `morph NAME`)
/// and its vertices as Blender deforms them (lines after `time T`); and the spec's own
/// CUBICSPLINE values (`spline NODE PATH`, then `t x y z [w]` lines).
#[derive(Default)]
struct BlenderPair {
    meshes: Vec<(String, BlenderMesh)>,
    splines: Vec<(String, String, Vec<Vec<f32>>)>,
}

#[derive(Default)]
struct BlenderMesh {
    morphs: Vec<(String, Vec<Vec3>)>,
    frames: Vec<(f32, Vec<Vec3>)>,
}

fn blender_pair(path: &std::path::Path) -> BlenderPair {
    let mut pair = BlenderPair::default();
    let text = std::fs::read_to_string(path).unwrap();
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let (word, rest) = line.split_once(' ').unwrap();
        match word {
            "spline" => {
                let (node, property) = rest.split_once(' ').unwrap();
                pair.splines.push((node.to_string(), property.to_string(), Vec::new()));
            }
            "mesh" => pair.meshes.push((rest.to_string(), BlenderMesh::default())),
            "morph" => pair.meshes.last_mut().unwrap().1.morphs.push((rest.to_string(), Vec::new())),
            "time" => pair.meshes.last_mut().unwrap().1.frames.push((rest.parse().unwrap(), Vec::new())),
            _ => {
                let v = numbers(line);
                let Some((_, mesh)) = pair.meshes.last_mut() else {
                    pair.splines.last_mut().unwrap().2.push(v);
                    continue;
                };
                let target = match mesh.frames.last_mut() {
                    Some(frame) => &mut frame.1,
                    None => &mut mesh.morphs.last_mut().unwrap().1,
                };
                target.push(Vec3::from_slice(&v));
            }
        }
    }
    pair
}

/// Two characters made, rigged, animated and exported by Blender 5
/// (`scripts/make_gltf_pair_fixture.py`): the file loads as two characters; their clips
/// (STEP rotation and LINEAR scale of a skeleton under a moved, turned and scaled node;
/// CUBICSPLINE root translation and rotation) deform them as Blender deforms them when it
/// reads the file back (at six times; at the key times for CUBICSPLINE, whose tangents
/// Blender's importer drops; with the morph weight the file sets), CUBICSPLINE follows the
/// spec's formula between keys, and the morph target is Blender's shape key.
#[test]
fn two_blender_characters_play_their_clips_as_blender_plays_them() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let characters = marionette::formats::gltf_import::load_gltf(&data.join("blender_pair.glb")).unwrap();
    let blender = blender_pair(&data.join("blender_pair.txt"));
    let names: Vec<&str> = characters.iter().map(|c| c.asset.name.as_str()).collect();
    assert_eq!(names, ["walker", "waver"]);
    let walker = &characters[0];
    assert_eq!(walker.morph_weights, [0.25], "the shape key's value in the file");
    assert_eq!(blender.splines.len(), 2);
    for (node, property, samples) in &blender.splines {
        let j = walker.asset.skeleton.find(node).unwrap();
        let tracks = &walker.clips[0].tracks[j];
        for v in samples {
            let ours: Vec<f32> = match property.as_str() {
                "translation" => tracks.translation.as_ref().unwrap().sample(v[0]).to_array().to_vec(),
                _ => tracks.rotation.as_ref().unwrap().sample(v[0]).to_array().to_vec(),
            };
            let off = ours.iter().zip(&v[1..]).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
            assert!(off <= 1e-6, "{node} {property} at {}: {ours:?} vs {:?}", v[0], &v[1..]);
        }
    }
    let mut worst = 0.0f32;
    for (character, (mesh, expected)) in characters.iter().zip(&blender.meshes) {
        assert_eq!(&character.asset.name, mesh);
        let asset = &character.asset;
        assert_eq!(character.clips.len(), 1, "{mesh}: its own action only");
        for (t, vertices) in &expected.frames {
            let pose = character.clips[0].sample(&asset.skeleton, *t);
            let world = pose.joint_to_world(&asset.skeleton, Mat4::IDENTITY);
            let palette: Vec<Mat4> = world.iter().zip(&asset.bind_world_to_joint).map(|(w, b)| *w * *b).collect();
            let mut ours = vec![Vec3::ZERO; asset.vertex_count()];
            // The morph weights the file sets are part of its pose.
            let shaped = asset.morphed_positions(&character.morph_weights);
            marionette::rig::lbs::skin(&shaped, &asset.skin.weights, &palette, &mut ours);
            assert_eq!(ours.len(), vertices.len());
            let off = largest_distance(&ours, vertices);
            assert!(off <= 1e-4, "{mesh} at {t} s: {off}");
            worst = worst.max(off);
        }
        assert_eq!(asset.morphs.len(), expected.morphs.len(), "{mesh}");
        for (morph, (name, deltas)) in asset.morphs.iter().zip(&expected.morphs) {
            assert_eq!(&morph.name, name);
            let mut dense = vec![Vec3::ZERO; asset.vertex_count()];
            morph.deltas.iter().for_each(|&(v, d)| dense[v as usize] = d);
            let off = largest_distance(&dense, deltas);
            assert!(off <= 1e-5 && morph.deltas.len() > 10, "{name}: {off}");
        }
    }
    eprintln!("blender pair: worst vertex {worst:e}");
}

#[test]
fn bad_gltf_files_say_what_and_where() {
    let dir = crate::common::scratch("gltf-bad");
    let not = dir.join("not.glb");
    std::fs::write(&not, b"glTF nonsense").unwrap();
    let e = marionette::formats::load_character(&not).unwrap_err().to_string();
    assert!(e.contains("not.glb") && e.contains("glTF"), "{e}");
}

/// A file without a skin (our baked export) loads as a prop: its mesh rides on its node,
/// vertex for vertex where the file puts it.
#[test]
fn a_file_without_a_skin_loads_as_a_prop() {
    let dir = crate::common::scratch("gltf-prop");
    let puppet = marionette::formats::puppet::embedded_puppet();
    let pose = puppet.skeleton.initial_pose();
    let character = GltfCharacter::new("p", &puppet, &pose);
    let baked = dir.join("baked.glb");
    std::fs::write(&baked, write_glb(&[character], GltfMesh::Baked).unwrap()).unwrap();
    let prop = marionette::formats::load_character(&baked).unwrap();
    assert_eq!(prop.skin_kind, marionette::rig::character::SkinKind::Rigid);
    let expected = marionette::document::posing::posed_positions(&puppet, &pose, Mat4::IDENTITY);
    let ours = marionette::document::posing::posed_positions(&prop, &prop.skeleton.initial_pose(), Mat4::IDENTITY);
    assert_eq!(ours.len(), expected.len());
    assert!(largest_distance(&ours, &expected) <= 1e-5);
}

/// `export FILE.glb --clip 0 --time 1 --out x.obj` writes both characters of the Blender
/// pair, in file order: the walker as Blender plays its clip at 1 s, the waver (which the
/// clip does not move) in the file's pose. An animation the file lacks is an error naming
/// the file and what it has, and nothing is written.
#[test]
fn exporting_a_glb_to_obj_writes_every_character_as_blender_poses_it() {
    use std::process::Command;
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let blender = blender_pair(&data.join("blender_pair.txt"));
    let at = |mesh: usize, t: f32| &blender.meshes[mesh].1.frames.iter().find(|f| f.0 == t).unwrap().1;
    let expected: Vec<Vec3> = at(0, 1.0).iter().chain(at(1, 0.0)).copied().collect();
    let dir = crate::common::scratch("gltf-obj");
    let obj = dir.join("pair.obj");
    let glb = data.join("blender_pair.glb");
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_marionette")).arg("export").arg(&glb).args(args).output().unwrap()
    };
    let out = run(&["--clip", "0", "--time", "1", "--out", obj.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let ours =
        marionette::formats::obj::parse_obj(marionette::formats::error::open(&obj).unwrap(), &obj).unwrap().positions;
    assert_eq!(ours.len(), expected.len());
    let worst = largest_distance(&ours, &expected);
    assert!(worst <= 1e-5, "{worst}");

    let missing = dir.join("missing.obj");
    let out = run(&["--clip", "dance", "--out", missing.to_str().unwrap()]);
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && !missing.exists());
    assert!(
        message.contains("blender_pair.glb") && message.contains("`dance`") && message.contains("waver_rig_action"),
        "{message}"
    );
}

/// The Blender pair's walker wears Blender's 8 x 8 red and blue checker: the PNG inside
/// the .glb is decoded to its pixels, every vertex has texture coordinates, and the
/// material's base colour is white under the texture.
#[test]
fn a_base_colour_texture_comes_with_its_coordinates() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let characters = marionette::formats::gltf_import::load_gltf(&data.join("blender_pair.glb")).unwrap();
    let walker = &characters[0];
    let Some(marionette::rig::SkinTexture::Picture { picture, .. }) = walker.asset.base_color_texture() else {
        panic!("no texture: {:?}", walker.asset.warnings)
    };
    assert_eq!((picture.width, picture.height), (8, 8));
    let pixel = |x: usize, y: usize| &picture.pixels[4 * (y * 8 + x)..4 * (y * 8 + x) + 4];
    let (red, blue) = ([255, 0, 0, 255], [0, 0, 255, 255]);
    for (x, y) in [(0, 0), (1, 0), (0, 1), (7, 7)] {
        assert!(pixel(x, y) == red || pixel(x, y) == blue, "({x}, {y}): {:?}", pixel(x, y));
        assert_ne!(pixel(x, y), pixel((x + 1) % 8, y), "a checker");
    }
    assert_eq!(walker.asset.skin.texcoords.len(), walker.asset.vertex_count());
    assert!(walker.asset.skin.texcoords.iter().all(|t| (0.0..=1.0).contains(&t.x) && (0.0..=1.0).contains(&t.y)));
    assert_eq!(walker.asset.materials[0].base_color, [1.0; 4]);
    let waver = &characters[1];
    assert!(waver.asset.base_color_texture().is_none() && waver.asset.skin.texcoords.is_empty());
}

/// Keyframes on a glTF character whose import folded nodes above its root (CesiumMan's
/// z-up frame) go out in that frame: the animated export played at t, read as the spec
/// says, deforms as the still export of the scene at t does, its root keyed too.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn keyframes_on_a_folded_root_go_out_in_its_frame() {
    use marionette::formats::scene::{AnimDoc, CharacterDoc, SceneDoc, SourceDoc};
    use marionette::rig::anim::{Channel, Clip, Extrapolation, Key, Tangent};
    let path = crate::common::data_dir().join("khronos/CesiumMan.glb");
    let part = &marionette::formats::load_parts(&path).unwrap()[0];
    assert_ne!(part.clips[0].root_parent, Mat4::IDENTITY, "CesiumMan's root sits under folded nodes");
    let skeleton = &part.asset.skeleton;
    let smooth = |time, value| Key { time, value, tangent_in: Tangent::Smooth, tangent_out: Tangent::Smooth };
    let channel = |keys| Channel::new(keys, Extrapolation::Constant, Extrapolation::Constant);
    let mut clip = Clip::empty(skeleton.len());
    clip.range = (0.0, 2.0);
    let rest = skeleton.joint(0).rest_offset;
    clip.channels[1] = channel(vec![smooth(0.0, rest.y), smooth(1.0, rest.y + 0.3), smooth(2.0, rest.y)]);
    clip.channels[Clip::joint_channel(0, 2)] = channel(vec![smooth(0.0, 0.0), smooth(2.0, 1.2)]);
    clip.channels[Clip::joint_channel(3, 0)] = channel(vec![smooth(0.0, 0.0), smooth(1.0, 0.9), smooth(2.0, -0.4)]);
    let doc_at = |time: f32| {
        let anim = AnimDoc { keys: Some(clip.clone()), time, ..AnimDoc::default() };
        let man = CharacterDoc { anim: Some(anim), ..CharacterDoc::new(SourceDoc::File(path.clone()), "man") };
        SceneDoc { characters: vec![man], ..SceneDoc::default() }
    };
    let dir = crate::common::scratch("folded-keyframes");
    let write = |name: &str, doc: &SceneDoc, animated: bool| {
        let file = dir.join(name);
        std::fs::write(&file, marionette::document::export::scene_glb(doc, GltfMesh::Skinned, animated).unwrap())
            .unwrap();
        super::gltf_spec::SpecFile::read(&file)
    };
    let animated = write("animated.glb", &doc_at(0.0), true);
    let keyframes = animated.animations().iter().position(|a| a["name"] == "man").unwrap();
    let mut worst = 0.0f64;
    for t in [0.0, 0.37, 1.0, 1.61, 2.0] {
        let still = write("still.glb", &doc_at(t), false).posed(None);
        let played = animated.posed(Some((keyframes, f64::from(t))));
        let (lo, hi) = still.iter().fold((glam::DVec3::MAX, glam::DVec3::MIN), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
        for (a, b) in still.iter().zip(&played) {
            worst = worst.max((*a - *b).length() / (hi - lo).length());
        }
    }
    assert!(worst < 1e-4, "worst {worst:e} of the size");
}

/// A normal-mapped glTF skin keeps its file's normals, one per vertex: the Blender pair's
/// walker given a normal map has its NORMAL as the `gltf` crate reads it from the file;
/// the waver beside it (no normal map) and both in the file as it is (none) keep none.
#[test]
fn a_normal_mapped_skin_keeps_its_files_normals() {
    let pair = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender_pair.glb");
    let glb = std::fs::read(&pair).unwrap();
    let bumpy = crate::common::glb_with_json(&glb, |json| {
        json["materials"][0]["normalTexture"] = serde_json::json!({ "index": 0 });
    });
    let path = crate::common::scratch("normal-mapped").join("bumpy.glb");
    std::fs::write(&path, &bumpy).unwrap();
    let characters = marionette::formats::gltf_import::load_gltf(&path).unwrap();
    let file = gltf::Gltf::from_slice(&bumpy).unwrap();
    let blob = file.blob.as_deref().unwrap();
    let walker = file.meshes().find(|m| m.name() == Some("walker")).unwrap();
    let primitive = walker.primitives().next().unwrap();
    let normals: Vec<Vec3> = primitive.reader(|_| Some(blob)).read_normals().unwrap().map(Vec3::from).collect();
    assert_eq!(characters[0].asset.name, "walker");
    assert_eq!(characters[0].asset.skin.normals.len(), characters[0].asset.vertex_count());
    assert_eq!(characters[0].asset.skin.normals, normals);
    assert!(characters[1].asset.skin.normals.is_empty(), "the waver has no normal map");
    let plain = marionette::formats::gltf_import::load_gltf(&pair).unwrap();
    assert!(plain.iter().all(|c| c.asset.skin.normals.is_empty()), "no normal map, no normals");
}

/// An SMPL body playing a clip with a second one blended in and stood upright goes out as
/// the editor plays it: the exported animation at frame f, and the still export paused at
/// a time between frames, hold the rotations the ECS's player gives every joint there.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn an_smpl_body_with_a_blend_clip_upright_goes_out_as_the_editor_plays_it() {
    use marionette::editor::scene_doc::document::PendingScene;
    use marionette::formats::scene::{CharacterDoc, SceneDoc, SmplDoc, SourceDoc};
    use marionette::scene::{Character, JointPose};
    let dir = crate::common::data_dir().join("smpl");
    let clips = marionette::formats::smpl::clip_paths(&dir);
    let name = |k: usize| clips[k].file_name().unwrap().to_string_lossy().into_owned();
    let doc_at = |time: f32| {
        let smpl = SmplDoc {
            clip: Some(name(0)),
            blend_clip: Some(name(1)),
            blend: 0.4,
            upright: true,
            time,
            playing: false,
            ..SmplDoc::default()
        };
        let body = CharacterDoc { smpl: Some(smpl), ..CharacterDoc::new(SourceDoc::File(dir.clone()), "b") };
        SceneDoc { characters: vec![body], ..SceneDoc::default() }
    };
    // The editor's playback, paused at `frames` (the clip's frames, 30 a second).
    let played = |frames: f32| -> Vec<Quat> {
        let time = frames / 30.0;
        let mut app = crate::edits::scene_app();
        *app.world_mut().resource_mut::<PendingScene>() = PendingScene { doc: Some(doc_at(time)), frame: false };
        app.update();
        app.update();
        let world = app.world_mut();
        let character = world.query::<&Character>().single(world).unwrap().clone();
        character.joints.iter().map(|&e| world.get::<JointPose>(e).unwrap().0.to_quat()).collect()
    };
    let same = |a: Quat, b: Quat| a.dot(b).abs() > 1.0 - 1e-5;

    let (json, bin) = chunks(&marionette::document::export::scene_glb(&doc_at(0.0), GltfMesh::Skinned, true).unwrap());
    let animation = &json["animations"][0];
    let joint_nodes: Vec<u64> =
        json["skins"][0]["joints"].as_array().unwrap().iter().map(|j| j.as_u64().unwrap()).collect();
    let frames = [0usize, 7, 40];
    let expected: Vec<Vec<Quat>> = frames.iter().map(|&f| played(f as f32)).collect();
    // The blend and the upright turn change the pose (the check would pass on raw frames).
    let (model, _) = marionette::formats::smpl::load_smpl_dir(&dir).unwrap();
    let raw = marionette::formats::smpl::parse_clip(
        std::io::BufReader::new(std::fs::File::open(&clips[0]).unwrap()),
        &clips[0],
        model.skeleton.len(),
    )
    .unwrap();
    assert!(!same(expected[1][0], raw.frame(7)[0]), "the root is stood upright");
    assert!((1..raw.frame(7).len()).any(|j| !same(expected[1][j], raw.frame(7)[j])), "the second clip is mixed in");
    let mut checked = 0;
    for channel in animation["channels"].as_array().unwrap() {
        if channel["target"]["path"] != "rotation" {
            continue;
        }
        let j = joint_nodes.iter().position(|&n| n == channel["target"]["node"].as_u64().unwrap()).unwrap();
        let values = read(
            &json,
            &bin,
            animation["samplers"][channel["sampler"].as_u64().unwrap() as usize]["output"].as_u64().unwrap() as usize,
        );
        for (k, &f) in frames.iter().enumerate() {
            let q = Quat::from_slice(&values[4 * f..4 * f + 4]);
            assert!(same(q, expected[k][j]), "joint {j} frame {f}: exported {q} played {}", expected[k][j]);
        }
        checked += 1;
    }
    assert_eq!(checked, joint_nodes.len());

    // A still export paused between frames stands as the paused editor does.
    let between = 12.6;
    let (json, bin) =
        chunks(&marionette::document::export::scene_glb(&doc_at(between / 30.0), GltfMesh::Skinned, false).unwrap());
    let _ = bin;
    let expected = played(between);
    for (j, &node) in joint_nodes.iter().enumerate() {
        let r = &json["nodes"][node as usize]["rotation"];
        let q = if r.is_null() {
            Quat::IDENTITY
        } else {
            Quat::from_array(std::array::from_fn(|i| r[i].as_f64().unwrap() as f32))
        };
        assert!(same(q, expected[j]), "still joint {j}: exported {q} played {}", expected[j]);
    }
}

//! The Khronos glTF sample models (`$MARIONETTE_DATA/khronos`), each posed at rest and at
//! two times of each of its animations, against the spec read on its own
//! ([`gltf_spec`](super::gltf_spec), double precision): every vertex within 5e-6 of the
//! model's size.

use glam::{DVec3, Vec3};

use super::gltf_spec::SpecFile;

/// The largest distance between our vertices and the reference's, and the model's size
/// (the diagonal of its bounds at rest).
pub fn worst_against_spec(path: &std::path::Path) -> (f64, f64, usize) {
    let spec = SpecFile::read(path);
    let rest = spec.posed(None);
    let (lo, hi) = rest.iter().fold((DVec3::MAX, DVec3::MIN), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let size = (hi - lo).length();
    // (animation and time for the reference, clip for us): at rest, then each clip twice.
    type Case = (Option<(usize, f64)>, Option<String>);
    let mut cases: Vec<Case> = vec![(None, None)];
    for a in 0..spec.animations().len() {
        for u in [0.3, 0.7] {
            cases.push((Some((a, u * spec.duration(a))), Some(a.to_string())));
        }
    }
    let mut worst = 0.0f64;
    for (animation, clip) in &cases {
        let expected = spec.posed(*animation);
        let time = animation.map_or(0.0, |(_, t)| t as f32);
        let posed = crate::common::posed_at(path, clip.as_deref(), time);
        assert_eq!(posed.len(), expected.len(), "{}", path.display());
        let off =
            posed.iter().zip(&expected).map(|(p, q): (&Vec3, &DVec3)| (p.as_dvec3() - *q).length()).fold(0.0, f64::max);
        worst = worst.max(off);
    }
    (worst, size, cases.len())
}

#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn every_khronos_model_poses_as_the_spec_says() {
    let data = crate::common::data_dir();
    let mut files: Vec<_> = std::fs::read_dir(data.join("khronos"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "glb"))
        .collect();
    files.sort();
    assert!(files.len() >= 8, "{files:?}");
    let mut failed = Vec::new();
    for path in &files {
        let (worst, size, poses) = worst_against_spec(path);
        let name = path.file_name().unwrap().to_string_lossy();
        eprintln!("{name:<24} {poses:2} poses  worst {worst:.3e}  size {size:.3}  ratio {:.2e}", worst / size);
        if worst > 5e-6 * size {
            failed.push(format!("{name}: {worst:e} of {size}"));
        }
    }
    assert!(failed.is_empty(), "{failed:?}");
}

/// `tests/data/blender_nested.txt`: per mesh, per time, Blender's vertices.
fn blender_frames(path: &std::path::Path) -> Vec<(String, f32, Vec<Vec3>)> {
    let mut out: Vec<(String, f32, Vec<Vec3>)> = Vec::new();
    let mut mesh = String::new();
    for line in std::fs::read_to_string(path).unwrap().lines() {
        match line.split_once(' ') {
            Some(("mesh", name)) => mesh = name.to_string(),
            Some(("time", t)) => out.push((mesh.clone(), t.parse().unwrap(), Vec::new())),
            _ => {
                let v: Vec<f32> = line.split_whitespace().map(|x| x.parse().unwrap()).collect();
                out.last_mut().unwrap().2.push(Vec3::from_slice(&v));
            }
        }
    }
    out
}

/// The farthest any point of `a` is from the nearest point of `b`.
fn farthest_from(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter().map(|p| b.iter().map(|q| p.distance(*q)).fold(f32::MAX, f32::min)).fold(0.0, f32::max)
}

/// A skeleton inside a skeleton, made by Blender 5 (`scripts/make_nested_fixture.py`): the
/// hand's armature hangs under the body's animated `arm` bone, a hat (no skin) rides on
/// `spine`, and the body has two materials. The file is one part whose skeleton holds both
/// skins' joints; at rest and while the clip plays, it poses as the spec says, and as
/// Blender deforms the file when it reads it back (compared as point sets: Blender splits
/// vertices by material in its own order).
#[test]
fn a_skeleton_under_another_skins_joint_moves_with_it() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let path = data.join("blender_nested.glb");
    let parts = marionette::formats::gltf_import::load_gltf(&path).unwrap();
    assert_eq!(parts.len(), 1);
    let skeleton = &parts[0].asset.skeleton;
    let hand_root = skeleton.find("hand_rig").unwrap();
    let arm = skeleton.find("arm").unwrap();
    assert_eq!(skeleton.joint(hand_root).parent, Some(arm), "the hand's armature hangs under the arm");
    let hat = skeleton.find("hat").unwrap();
    assert_eq!(skeleton.joint(hat).parent, skeleton.find("spine"));

    let (worst, size, poses) = worst_against_spec(&path);
    assert!(worst <= 5e-6 * size, "{worst} of {size} over {poses} poses");

    let blender = blender_frames(&data.join("blender_nested.txt"));
    let mut worst_blender = 0.0f32;
    for t in [0.0f32, 0.3, 0.5, 0.75, 1.0] {
        let ours = crate::common::posed_at(&path, Some("0"), t);
        let theirs: Vec<Vec3> =
            blender.iter().filter(|(_, time, _)| *time == t).flat_map(|(_, _, v)| v.iter().copied()).collect();
        let off = farthest_from(&ours, &theirs).max(farthest_from(&theirs, &ours));
        assert!(off <= 1e-4 * size as f32, "at {t} s: {off}");
        worst_blender = worst_blender.max(off);
    }
    eprintln!("nested: spec {worst:.2e}, Blender {worst_blender:.2e}, size {size:.3}");
}

/// `export F.glb|F.fbx --animation --out x.glb` and reading `x.glb` back gives the file's parts
/// again: the same joints (names, parents, rest), vertices, triangles, weights, morph
/// targets, surfaces, materials with their images (embedded as PNG), texture coordinates
/// and colours, and every clip under its own name, key for key (times, values,
/// interpolation), so it poses the same at any time.
#[test]
fn an_exported_glb_reads_back_key_for_key() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let mut files = ["blender_nested.glb", "blender_pair.glb", "blender_nested.fbx", "blender_pair.fbx"]
        .map(|f| data.join(f))
        .to_vec();
    if let Some(dir) = crate::common::optional_data_dir() {
        files.extend(
            ["Fox", "CesiumMan", "BrainStem", "AnimatedMorphCube"].map(|m| dir.join(format!("khronos/{m}.glb"))),
        );
    }
    let dir = crate::common::scratch("gltf-round-trip");
    for path in &files {
        let out = dir.join(path.file_name().unwrap()).with_extension("glb");
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_marionette"))
            .args(["export", path.to_str().unwrap(), "--animation", "--out", out.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        let before = marionette::formats::load_parts(path).unwrap();
        let after = marionette::formats::gltf_import::load_gltf(&out).unwrap();
        let name = path.display();
        assert_eq!(before.len(), after.len(), "{name}");
        for (a, b) in before.iter().zip(&after) {
            assert_eq!(a.asset.skin_kind, b.asset.skin_kind, "{name}: a prop stays a prop");
            let (sa, sb) = (&a.asset.skeleton, &b.asset.skeleton);
            assert_eq!(sa.len(), sb.len(), "{name}");
            for (ja, jb) in sa.joints().iter().zip(sb.joints()) {
                assert_eq!((&ja.name, ja.parent), (&jb.name, jb.parent), "{name}");
                assert!(ja.rest_offset.abs_diff_eq(jb.rest_offset, 1e-5), "{name} {}", ja.name);
                assert!(ja.rest_scale.abs_diff_eq(jb.rest_scale, 1e-5), "{name} {}", ja.name);
            }
            // A prop's vertices go out in their node's frame and come back through it:
            // equal within rounding; a skinned mesh's go out as they are.
            let prop = a.asset.skin_kind == marionette::rig::character::SkinKind::Rigid;
            let tolerance = if prop { 1e-6 * (1.0 + a.asset.bounds().1.abs().max_element()) } else { 0.0 };
            let near = |x: &[Vec3], y: &[Vec3]| {
                x.len() == y.len() && x.iter().zip(y).all(|(p, q)| p.distance(*q) <= tolerance)
            };
            assert!(near(&a.asset.skin.bind_positions, &b.asset.skin.bind_positions), "{name}: vertices");
            assert!(a.asset.skin.triangles == b.asset.skin.triangles, "{name}: triangles");
            let (wa, wb) = (&a.asset.skin.weights, &b.asset.skin.weights);
            for v in 0..wa.vertex_count() {
                let row = |w: &marionette::rig::SkinWeights| -> Vec<(u16, f32)> {
                    w.of_vertex(v).iter().map(|i| (i.joint, i.weight)).collect()
                };
                // Rows are normalised on reading, so a row read twice may move by an ulp.
                let (ra, rb) = (row(wa), row(wb));
                let same =
                    ra.len() == rb.len() && ra.iter().zip(&rb).all(|(x, y)| x.0 == y.0 && (x.1 - y.1).abs() <= 1e-6);
                assert!(same, "{name}: vertex {v}'s weights {ra:?} and {rb:?}");
            }
            assert_eq!(a.asset.morphs.len(), b.asset.morphs.len(), "{name}: morphs");
            for (ma, mb) in a.asset.morphs.iter().zip(&b.asset.morphs) {
                let (ia, da): (Vec<u32>, Vec<Vec3>) = ma.deltas.iter().copied().unzip();
                let (ib, db): (Vec<u32>, Vec<Vec3>) = mb.deltas.iter().copied().unzip();
                assert!(ma.name == mb.name && ia == ib && near(&da, &db), "{name}: morph {}", ma.name);
            }
            assert!(a.asset.surfaces() == b.asset.surfaces(), "{name}: surfaces");
            assert_eq!(a.asset.skin.texcoords, b.asset.skin.texcoords, "{name}: texture coordinates");
            assert_eq!(a.asset.skin.colors, b.asset.skin.colors, "{name}: colours");
            assert_eq!(a.asset.materials.len(), b.asset.materials.len(), "{name}: materials");
            for (ma, mb) in a.asset.materials.iter().zip(&b.asset.materials) {
                // The same but for where the images came from (their keys name the file).
                let pixels = |m: &marionette::rig::material::Material| -> Vec<Vec<u8>> {
                    m.textures()
                        .map(|(_, t)| match &t.image {
                            marionette::rig::SkinTexture::Picture { picture, .. } => picture.pixels.clone(),
                            marionette::rig::SkinTexture::File(_) => Vec::new(),
                        })
                        .collect()
                };
                assert_eq!(pixels(ma), pixels(mb), "{name}: {}'s images", ma.name);
                let bare = |m: &marionette::rig::material::Material| {
                    let strip = |t: &Option<marionette::rig::material::TextureRef>| {
                        t.as_ref().map(|t| (t.sampler, t.transform))
                    };
                    (
                        m.name.clone(),
                        m.base_color,
                        m.metallic,
                        m.roughness,
                        m.emissive,
                        m.alpha,
                        m.double_sided,
                        [
                            strip(&m.base_color_texture),
                            strip(&m.metallic_roughness_texture),
                            strip(&m.normal_texture),
                            strip(&m.emissive_texture),
                        ],
                    )
                };
                assert_eq!(bare(ma), bare(mb), "{name}: material {}", ma.name);
            }
            assert_eq!(a.morph_weights, b.morph_weights, "{name}");
            assert_eq!(a.clips.len(), b.clips.len(), "{name}");
            for (ca, cb) in a.clips.iter().zip(&b.clips) {
                assert_eq!(ca.name, cb.name, "{name}");
                assert!(ca.tracks == cb.tracks, "{name} {}: tracks", ca.name);
                assert!(ca.weights == cb.weights, "{name} {}: weight tracks", ca.name);
                assert!(ca.root_parent.abs_diff_eq(cb.root_parent, 1e-6), "{name} {}", ca.name);
            }
        }
        let clips: Vec<Option<String>> =
            std::iter::once(None).chain(before.iter().flat_map(|c| &c.clips).map(|k| Some(k.name.clone()))).collect();
        for clip in &clips {
            for t in [0.0, 0.37, 1.1] {
                let pa = crate::common::posed_at(path, clip.as_deref(), t);
                let pb = crate::common::posed_at(&out, clip.as_deref(), t);
                let off = pa.iter().zip(&pb).map(|(p, q)| p.distance(*q)).fold(0.0f32, f32::max);
                assert!(off <= 1e-5, "{name} {clip:?} at {t}: {off}");
            }
        }
    }
}

/// `KHR_texture_transform`'s own example: offset (0, 1), rotation π/2, scale ½ maps the
/// unit square onto the image's lower left quadrant (v runs down), turned; Bevy's affine
/// transform of the same numbers (as the editor builds it) agrees.
#[test]
fn a_texture_transform_reads_as_the_extensions_example() {
    use marionette::rig::material::TextureTransform;
    let t = TextureTransform {
        offset: glam::Vec2::new(0.0, 1.0),
        rotation: std::f32::consts::FRAC_PI_2,
        scale: glam::Vec2::splat(0.5),
    };
    let corners = [(0.0, 0.0, 0.0, 1.0), (1.0, 0.0, 0.0, 0.5), (1.0, 1.0, 0.5, 0.5), (0.0, 1.0, 0.5, 1.0)];
    let bevy = bevy::math::Affine2::from_scale_angle_translation(t.scale, -t.rotation, t.offset);
    for (u, v, x, y) in corners {
        let uv = glam::Vec2::new(u, v);
        assert!(t.apply(uv).abs_diff_eq(glam::Vec2::new(x, y), 1e-6), "{uv} -> {}", t.apply(uv));
        assert!(bevy.transform_point2(uv).abs_diff_eq(t.apply(uv), 1e-6), "{uv}");
    }
}

/// The Blender fixture's body has two materials (red below, blue above): it loads as two
/// surfaces that split its vertices and triangles, each with its material's name and
/// colour; the hand and the hat, which have none, are one surface of the tint.
#[test]
fn each_primitive_keeps_its_material() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let part = marionette::formats::gltf_import::load_gltf(&data.join("blender_nested.glb")).unwrap().swap_remove(0);
    let asset = &part.asset;
    let names: Vec<&str> = asset.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["red", "blue"]);
    assert!((asset.materials[0].base_color[0] - 0.8).abs() < 1e-6 && asset.materials[0].double_sided);
    let surfaces = asset.surfaces();
    let used: Vec<Option<usize>> = surfaces.iter().map(|s| s.material).collect();
    assert_eq!(used, [None, Some(0), Some(1)], "in node order: the hand and the hat (one run), the body's red, blue");
    let mut next = (0, 0);
    for s in surfaces.iter() {
        assert_eq!((s.vertices.start, s.triangles.start), next, "surfaces tile the mesh");
        next = (s.vertices.end, s.triangles.end);
        let tris = &asset.skin.triangles[s.triangles.start as usize..s.triangles.end as usize];
        assert!(tris.iter().flatten().all(|i| s.vertices.contains(i)), "a surface's triangles use its vertices");
    }
    assert_eq!(next, (asset.vertex_count() as u32, asset.triangle_count() as u32));
}

/// A `.gltf` whose buffer is a `data:` URI (base64) and one whose `.bin` name needs
/// percent-decoding load as the `.glb` they were made from.
#[test]
fn data_uris_and_percent_encoded_names_load() {
    use base64::Engine;
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let glb = std::fs::read(data.join("blender_arm.glb")).unwrap();
    let u32_at = |at: usize| u32::from_le_bytes(glb[at..at + 4].try_into().unwrap()) as usize;
    let json_len = u32_at(12);
    let mut json: serde_json::Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let bin = &glb[28 + json_len..28 + json_len + u32_at(20 + json_len)];
    let dir = crate::common::scratch("gltf-uris");
    let encoded = base64::engine::general_purpose::STANDARD.encode(bin);
    json["buffers"][0]["uri"] = serde_json::json!(format!("data:application/octet-stream;base64,{encoded}"));
    std::fs::write(dir.join("embedded.gltf"), serde_json::to_vec(&json).unwrap()).unwrap();
    json["buffers"][0]["uri"] = serde_json::json!("arm%20data.bin");
    std::fs::write(dir.join("arm data.bin"), bin).unwrap();
    std::fs::write(dir.join("named.gltf"), serde_json::to_vec(&json).unwrap()).unwrap();
    let expected = marionette::formats::load_character(&data.join("blender_arm.glb")).unwrap();
    for file in ["embedded.gltf", "named.gltf"] {
        let loaded = marionette::formats::load_character(&dir.join(file)).unwrap_or_else(|e| panic!("{e}"));
        assert!(loaded.skin == expected.skin && loaded.skeleton == expected.skeleton, "{file}");
    }
    json["buffers"][0]["uri"] = serde_json::json!("data:application/octet-stream;base64,@@@@");
    std::fs::write(dir.join("bad.gltf"), serde_json::to_vec(&json).unwrap()).unwrap();
    let e = marionette::formats::load_character(&dir.join("bad.gltf")).unwrap_err().to_string();
    assert!(e.contains("bad.gltf") && e.contains("buffers[0].uri") && e.contains("base64"), "{e}");
}

/// A file of several scenes loads the scene it shows (`scene`, else its first): the Blender
/// pair with a second scene holding only the waver loads both when the first scene shows,
/// and only the waver when the second does.
#[test]
fn only_the_scene_a_file_shows_loads() {
    let pair =
        std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender_pair.glb")).unwrap();
    let dir = crate::common::scratch("scenes");
    let joints = |scene: u64| {
        let glb = crate::common::glb_with_json(&pair, |json| {
            json["scenes"].as_array_mut().unwrap().push(serde_json::json!({ "name": "waver alone", "nodes": [8] }));
            // Against the spec, a child (the waver's mesh) listed too: its root decides.
            json["scenes"]
                .as_array_mut()
                .unwrap()
                .push(serde_json::json!({ "name": "and a child", "nodes": [4, 8, 7] }));
            json["scene"] = serde_json::json!(scene);
        });
        let path = dir.join(format!("scene{scene}.glb"));
        std::fs::write(&path, glb).unwrap();
        let parts = marionette::formats::load_parts(&path).unwrap();
        parts
            .iter()
            .map(|p| p.asset.skeleton.joints().iter().map(|j| j.name.clone()).collect())
            .collect::<Vec<Vec<_>>>()
    };
    let both = joints(0);
    assert_eq!(both.len(), 2);
    assert_eq!(joints(1), [both[1].clone()], "the waver's part alone");
    assert!(both[1].iter().any(|j| j == "upper"));
    assert_eq!(joints(2), both, "a child listed in the scene takes its root's place");
}

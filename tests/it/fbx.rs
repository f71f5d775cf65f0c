//! FBX import: fixtures Blender 5 made from the project's own Blender glTF fixtures
//! (`scripts/make_fbx_fixtures.py`), each beside its glTF twin written from the same
//! Blender scene. Loaded with Marionette, the FBX and its twin pose alike (as point sets:
//! the two formats split vertices differently) at rest and at frames of their clip,
//! within 1e-4 of the model's size; bad FBX files say so, naming the file.

use glam::Vec3;

/// The farthest any point of `a` is from the nearest point of `b`, where that is within
/// `reach` (infinity when a point has none that near): `b` is hashed into cells of `reach`.
fn farthest_from(a: &[Vec3], b: &[Vec3], reach: f32) -> f32 {
    let cell = |p: Vec3| (p / reach).floor().as_ivec3();
    let mut cells: std::collections::HashMap<glam::IVec3, Vec<Vec3>> = std::collections::HashMap::new();
    b.iter().for_each(|&q| cells.entry(cell(q)).or_default().push(q));
    let nearest = |p: Vec3| {
        let c = cell(p);
        let around =
            (-1..=1).flat_map(|x| (-1..=1).flat_map(move |y| (-1..=1).map(move |z| c + glam::IVec3::new(x, y, z))));
        around.filter_map(|k| cells.get(&k)).flatten().map(|q| p.distance(*q)).fold(f32::INFINITY, f32::min)
    };
    a.iter().map(|&p| nearest(p)).fold(0.0, f32::max)
}

/// The largest distance between `NAME.fbx` and `NAME_twin.glb` in `dir` posed alike (at
/// rest and at five times of their first clip), and the model's size.
pub fn fbx_against_twin(dir: &std::path::Path, name: &str) -> (f32, f32) {
    let (fbx_path, twin_path) = (dir.join(format!("{name}.fbx")), dir.join(format!("{name}_twin.glb")));
    let fbx = marionette::formats::load_parts(&fbx_path).unwrap();
    let twin = marionette::formats::load_parts(&twin_path).unwrap();
    let rest = crate::common::posed_at(&twin_path, None, 0.0);
    let (lo, hi) = marionette::rig::skinning::bounds(&rest);
    let size = (hi - lo).length();
    let animated = !twin.iter().all(|p| p.clips.is_empty());
    assert_eq!(animated, fbx.iter().any(|p| !p.clips.is_empty()), "{name}: both have a clip or neither");
    let times: &[f32] = if animated { &[0.0, 0.25, 0.5, 10.0 / 24.0, 1.0] } else { &[0.0] };
    let clip = animated.then_some("0");
    let mut worst = 0.0f32;
    for &t in times {
        let a = crate::common::posed_at(&fbx_path, clip, t);
        let b = crate::common::posed_at(&twin_path, clip, t);
        let reach = 1e-3 * size;
        worst = worst.max(farthest_from(&a, &b, reach).max(farthest_from(&b, &a, reach)));
    }
    (worst, size)
}

#[test]
fn fbx_fixtures_pose_as_their_gltf_twins() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    for name in ["blender_arm", "blender_pair", "blender_nested"] {
        let fbx = marionette::formats::load_parts(&data.join(format!("{name}.fbx"))).unwrap();
        let twin = marionette::formats::load_parts(&data.join(format!("{name}_twin.glb"))).unwrap();
        let morphs = |parts: &[marionette::formats::part::Part]| -> Vec<(String, f32)> {
            let mut m: Vec<(String, f32)> = parts
                .iter()
                .flat_map(|p| p.asset.morphs.iter().map(|m| m.name.clone()).zip(p.morph_weights.iter().copied()))
                .collect();
            m.sort_by(|a, b| a.0.cmp(&b.0));
            m
        };
        let (mf, mt) = (morphs(&fbx), morphs(&twin));
        assert_eq!(mf.len(), mt.len(), "{name}: morphs {mf:?} and {mt:?}");
        for ((a, wa), (b, wb)) in mf.iter().zip(&mt) {
            assert!(a == b && (wa - wb).abs() < 1e-5, "{name}: morph {a} {wa} and {b} {wb}");
        }
        let (worst, size) = fbx_against_twin(&data, name);
        assert!(worst <= 1e-4 * size, "{name}: {worst} of {size}");
        eprintln!("{name}: fbx vs glTF twin worst {worst:.2e} of size {size:.3} ({:.1e})", worst / size);
    }
    // The walker's checker texture comes embedded in the FBX.
    let pair = marionette::formats::load_parts(&data.join("blender_pair.fbx")).unwrap();
    let Some(marionette::rig::SkinTexture::Picture { picture, .. }) = pair[0].asset.base_color_texture() else {
        panic!("no texture")
    };
    assert_eq!((picture.width, picture.height), (8, 8));
}

/// With `MARIONETTE_FBX_TWINS=DIR` (a folder `scripts/make_fbx_fixtures.py DIR FILES..`
/// filled, e.g. from the Khronos samples, which stay out of the project): every
/// `NAME.fbx` there against its `NAME_twin.glb`, printed as a table.
#[test]
#[ignore = "needs MARIONETTE_FBX_TWINS=DIR; run with --ignored"]
fn fbx_twins_in_a_folder_of_your_own() {
    let dir = std::env::var_os("MARIONETTE_FBX_TWINS").map(std::path::PathBuf::from).expect("MARIONETTE_FBX_TWINS=DIR");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.unwrap().file_name().to_str()?.strip_suffix(".fbx").map(str::to_string))
        .collect();
    names.sort();
    for name in names {
        let (worst, size) = fbx_against_twin(&dir, &name);
        eprintln!("| {name} | {worst:.2e} | {size:.3} | {:.1e} |", worst / size);
    }
}

#[test]
fn bad_fbx_files_say_what_and_name_the_file() {
    let dir = crate::common::scratch("fbx-bad");
    let cases: [(&str, &[u8]); 3] = [
        ("empty.fbx", b""),
        ("text.fbx", b"this is not an FBX file at all"),
        ("truncated.fbx", b"Kaydara FBX Binary  \x00\x1a\x00\xe8\x1c\x00\x00"),
    ];
    for (file, bytes) in cases {
        let path = dir.join(file);
        std::fs::write(&path, bytes).unwrap();
        let e = marionette::formats::load_parts(&path).unwrap_err().to_string();
        assert!(e.contains(file), "{e}");
    }
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender_nested.fbx");
    let whole = std::fs::read(data).unwrap();
    // Cut anywhere, it fails with a message or loads what is there; it never panics.
    for cut in (0..whole.len()).step_by(997) {
        let path = dir.join("cut.fbx");
        std::fs::write(&path, &whole[..cut]).unwrap();
        if let Err(e) = marionette::formats::load_parts(&path) {
            assert!(e.to_string().contains("cut.fbx"), "{e}");
        }
    }
}

/// `bytes` with every occurrence of `pattern` followed by `at` bytes overwritten by `with`.
fn patched(bytes: &[u8], pattern: &[u8], at: usize, with: &[u8]) -> (Vec<u8>, usize) {
    let mut out = bytes.to_vec();
    let mut count = 0;
    let mut from = 0;
    while let Some(k) = out[from..].windows(pattern.len()).position(|w| w == pattern) {
        let start = from + k + pattern.len() + at;
        if start + with.len() > out.len() {
            break;
        }
        out[start..start + with.len()].copy_from_slice(with);
        count += 1;
        from = start + with.len();
    }
    (out, count)
}

/// Hostile FBX regressions, made from a Blender fixture: a node translation that is not a
/// number, and a cluster whose bind matrix is all zeros (singular), are refused with a
/// message naming the file and what was wrong, never a panic or a skin of NaNs.
#[test]
fn hostile_fbx_transforms_and_binds_are_refused_at_the_boundary() {
    let dir = crate::common::scratch("fbx-hostile");
    let whole =
        std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender_arm.fbx")).unwrap();
    // `P: "Lcl Translation", "Lcl Translation", "", "A", D x, D y, D z`: x made NaN.
    let property = b"Lcl TranslationS\x0f\x00\x00\x00Lcl TranslationS\x00\x00\x00\x00S\x01\x00\x00\x00AD";
    let (nan, count) = patched(&whole, property, 0, &f64::NAN.to_le_bytes());
    assert!(count >= 2, "the fixture's translations were found");
    // Every 4×4 matrix a cluster's bind is made of (the cluster's `Transform` and
    // `TransformLink`, the bind pose's `Matrix`: `d[16]`, count, encoding 0, byte length,
    // then the doubles) all zero.
    let matrix = b"\x10\x00\x00\x00\x00\x00\x00\x00\x80\x00\x00\x00";
    let mut singular = whole.clone();
    for name in [&b"Transformd"[..], b"TransformLinkd", b"Matrixd"] {
        let (out, count) = patched(&singular, &[name, matrix].concat(), 0, &[0; 128]);
        assert!(count >= 1, "the fixture's {} were found", String::from_utf8_lossy(name));
        singular = out;
    }
    for (file, bytes, says) in [("nan.fbx", nan, "translation"), ("singular.fbx", singular, "bind")] {
        let path = dir.join(file);
        std::fs::write(&path, bytes).unwrap();
        match marionette::formats::load_parts(&path) {
            Err(e) => {
                let e = e.to_string();
                assert!(e.contains(file) && e.contains(says), "{e}");
            }
            Ok(parts) => panic!("{file} loaded ({} parts)", parts.len()),
        }
    }
}

/// A Blender FBX whose hair mesh has two vertices no bone weighs loads (with a warning
/// naming the mesh) and those vertices follow the mesh's node: at rest where Blender put
/// them, and left there while the arm turns (the node is the armature, which stays).
#[test]
fn vertices_without_weights_follow_their_mesh_node() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/unweighted.fbx");
    let parts = marionette::formats::load_parts(&path).unwrap();
    let asset = &parts[0].asset;
    assert!(
        asset.warnings.iter().any(|w| w.contains("`Hair`") && w.contains("2 vertices have no skin weight")),
        "{:?}",
        asset.warnings
    );
    // Blender's z up is y up here: the strand's free end at (0.2..0.3, 1.5, 0).
    let free: Vec<usize> = asset
        .skin
        .bind_positions
        .iter()
        .enumerate()
        .filter(|(_, p)| (p.y - 1.5).abs() < 1e-5 && p.z.abs() < 1e-5 && (0.19..0.31).contains(&p.x))
        .map(|(v, _)| v)
        .collect();
    assert_eq!(free.len(), 2, "the two unweighted vertices, once each");
    // The arm bent at `lower`: the strand's weighted end goes with it, the free end stays.
    let lower = asset.skeleton.find("lower").unwrap();
    let mut pose = asset.skeleton.initial_pose();
    pose[lower] = marionette::rig::JointRotation::Quat(glam::Quat::from_rotation_x(0.7) * pose[lower].to_quat());
    let rest =
        marionette::document::posing::posed_positions(asset, &asset.skeleton.initial_pose(), glam::Mat4::IDENTITY);
    let posed = marionette::document::posing::posed_positions(asset, &pose, glam::Mat4::IDENTITY);
    let moved = (0..rest.len()).filter(|&v| posed[v].distance(rest[v]) > 1e-3).count();
    assert!(moved > 0, "bending moves the weighted vertices");
    for v in free {
        assert!(rest[v].distance(asset.skin.bind_positions[v]) < 1e-5, "at rest where the file puts it");
        assert!(posed[v].distance(rest[v]) < 1e-5, "left where the mesh's node puts it");
    }
}

/// A curve whose keys are all one value (Blender writes a constant curve so; ufbx calls it
/// constant) still sets its joint: `lower` stays turned 30° about x through the clip, its
/// box's far end over half a bone (sin 30°, and the box's width) off the arm's plane, where
/// the node's own rotation would leave it at 0.1.
#[test]
fn constant_fbx_curves_set_their_joint() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/one_key.fbx");
    let rest = crate::common::posed_at(&path, None, 0.0);
    let height = rest.iter().map(|p| p.y).fold(f32::MIN, f32::max);
    for t in [0.0, 0.5, 0.9] {
        let posed = crate::common::posed_at(&path, Some("0"), t);
        let off_plane = posed.iter().map(|p| p.z.abs()).fold(0.0, f32::max) / (height / 2.0);
        assert!((0.5..0.7).contains(&off_plane), "t = {t}: {off_plane}");
    }
}

/// One clip numbering for every format: an FBX file's clips are numbered from 0 as a glTF
/// file's animations are, `--clip 0` finds the first in either, and a `--clip` that names
/// no clip of a file fails, listing the file's clips.
#[test]
fn clips_are_numbered_alike_and_a_missing_clip_fails_naming_the_clips() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let (fbx, glb) = (data.join("one_key.fbx"), data.join("blender_pair.glb"));
    // `--clip SPEC` on the characters of these files, as every command applies it.
    let clip = |paths: &[&std::path::PathBuf], spec: &str| {
        use marionette::document::options::{PoseOptions, apply_options};
        let mut library = marionette::document::AssetLibrary::default();
        let sources = paths.iter().flat_map(|p| library.sources_of(p)).collect();
        let mut doc = marionette::document::scenes::doc_side_by_side(&mut library, sources, &mut Vec::new());
        let options = PoseOptions { clip: Some(spec.to_string()), ..PoseOptions::default() };
        apply_options(&mut doc, &options, &mut library).map(|_| doc)
    };
    for path in [&fbx, &glb] {
        let parts = marionette::formats::load_parts(path).unwrap();
        assert_eq!(parts[0].clips[0].index, 0, "{path:?}");
        let doc = clip(&[path], "0").unwrap();
        assert_eq!(doc.characters[0].playback.as_ref().unwrap().clip.as_ref(), Some(&parts[0].clips[0].name));
    }
    let e = clip(&[&fbx, &glb], "7").unwrap_err().to_string();
    assert!(e.contains("one_key.fbx: no clip `7` (its clips: 0 `Scene`)"), "{e}");
    // A file of several whose clips it names one of, and one whose it names none of.
    let e = clip(&[&fbx, &glb], "Scene").unwrap_err().to_string();
    assert!(
        e.contains("blender_pair.glb: no clip `Scene` (its clips: 0 `walker_rig_action`, 1 `waver_rig_action`)"),
        "{e}"
    );
}

/// An FBX whose connections make a cycle of nodes (A under B under A, which the format's
/// connections allow to be written), or a node under itself, is refused naming the file,
/// never a hang or a stack overflow.
#[test]
fn fbx_node_cycles_are_refused() {
    let dir = crate::common::scratch("fbx-cycles");
    let file = |connections: &str| {
        format!(
            "; FBX 7.4.0 project file\nFBXHeaderExtension:  {{\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 7400\n}}\n\
             Objects:  {{\n\tGeometry: 100, \"Geometry::tri\", \"Mesh\" {{\n\t\tVertices: *9 {{\n\t\t\ta: 0,0,0,1,0,0,0,1,0\n\t\t}}\n\
             \t\tPolygonVertexIndex: *3 {{\n\t\t\ta: 0,1,-3\n\t\t}}\n\t}}\n\tModel: 200, \"Model::A\", \"Mesh\" {{\n\t}}\n\
             \tModel: 300, \"Model::B\", \"Null\" {{\n\t}}\n}}\nConnections:  {{\n{connections}}}\n"
        )
    };
    let cases = [
        ("cycle.fbx", "\tC: \"OO\",100,200\n\tC: \"OO\",200,300\n\tC: \"OO\",300,200\n\tC: \"OO\",300,0\n"),
        ("self.fbx", "\tC: \"OO\",100,200\n\tC: \"OO\",200,200\n\tC: \"OO\",300,0\n"),
    ];
    // The same file without the cycle loads: the cases fail for their cycles alone.
    let plain = dir.join("plain.fbx");
    std::fs::write(&plain, file("\tC: \"OO\",100,200\n\tC: \"OO\",200,300\n\tC: \"OO\",300,0\n")).unwrap();
    marionette::formats::load_parts(&plain).expect("the file without a cycle");
    for (name, connections) in cases {
        let path = dir.join(name);
        std::fs::write(&path, file(connections)).unwrap();
        match marionette::formats::load_parts(&path) {
            Err(e) => assert!(e.to_string().contains(name), "{e}"),
            Ok(parts) => assert!(!parts.is_empty(), "{name}: loaded with its cycle broken"),
        }
    }
}

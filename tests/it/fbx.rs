//! FBX import: fixtures Blender 5 made from the project's own Blender glTF fixtures
//! (`scripts/make_fbx_fixtures.py`), each beside its glTF twin written from the same
//! Blender scene. Loaded with Marionette, the FBX and its twin pose alike (as point sets:
//! the two formats split vertices differently) at rest and at frames of their clip,
//! within 1e-4 of the model's size; bad FBX files say so, naming the file.

use glam::Vec3;
use marionette::document::posing::posed_gltf;
use marionette::rig::dqs::SkinningMethod;

/// The farthest any point of `a` is from the nearest point of `b`.
fn farthest_from(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter().map(|p| b.iter().map(|q| p.distance(*q)).fold(f32::MAX, f32::min)).fold(0.0, f32::max)
}

#[test]
fn fbx_fixtures_pose_as_their_gltf_twins() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    for name in ["blender_arm", "blender_pair", "blender_nested"] {
        let fbx = marionette::formats::load_parts(&data.join(format!("{name}.fbx"))).unwrap();
        let twin = marionette::formats::load_parts(&data.join(format!("{name}_twin.glb"))).unwrap();
        let morphs = |parts: &[marionette::formats::gltf_import::ImportedCharacter]| -> Vec<(String, f32)> {
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
        let (rest, _) = posed_gltf(&twin, None, 0.0, &[], SkinningMethod::Linear).unwrap();
        let (lo, hi) = marionette::rig::skinning::bounds(&rest);
        let size = (hi - lo).length();
        let animated = !twin.iter().all(|p| p.clips.is_empty());
        assert_eq!(animated, fbx.iter().any(|p| !p.clips.is_empty()), "{name}: both have a clip or neither");
        let times: &[f32] = if animated { &[0.0, 0.25, 0.5, 10.0 / 24.0, 1.0] } else { &[0.0] };
        let clip = animated.then_some("0");
        let mut worst = 0.0f32;
        for &t in times {
            let (a, _) = posed_gltf(&fbx, clip, t, &[], SkinningMethod::Linear).unwrap();
            let (b, _) = posed_gltf(&twin, clip, t, &[], SkinningMethod::Linear).unwrap();
            let off = farthest_from(&a, &b).max(farthest_from(&b, &a));
            assert!(off <= 1e-4 * size, "{name} at {t} s: {off} of {size}");
            worst = worst.max(off);
        }
        eprintln!("{name}: fbx vs glTF twin worst {worst:.2e} of size {size:.3} ({:.1e})", worst / size);
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

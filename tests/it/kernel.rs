//! The fast skinning kernel (`rig::lbs`, AVX2 and portable paths) against the plain loop it
//! replaces (`skinning::skin_positions`, the oracle): within 1e-5 on every data set and on
//! synthetic rows of 1 to 13 influences, positions alone and with normals; the box each
//! grows as it writes is the box of what it wrote.

use glam::{Mat4, Quat, Vec3};
use marionette::rig::lbs::{skin_chunk_using, skin_using};
use marionette::rig::simd::Simd;
use marionette::rig::skinning::{Bounds, bounds, skin_positions};
use marionette::rig::{CharacterAsset, JointRotation, SkinWeights};

/// A pose that turns every joint (and so every palette matrix) differently.
fn posed_palette(asset: &CharacterAsset) -> Vec<Mat4> {
    let n = asset.skeleton.len();
    let pose: Vec<JointRotation> =
        (0..n).map(|i| JointRotation::euler_xyz(0.1 * i as f32, 0.05 - 0.01 * i as f32, -0.02 * i as f32)).collect();
    let placement = Mat4::from_translation(Vec3::new(0.3, -0.2, 0.1));
    marionette::rig::fk::posed_palette(&asset.skeleton, &asset.bind_world_to_joint, &pose, placement)
}

/// Each level of the kernel this CPU runs (AVX-512 VL, AVX2, portable) agrees with the
/// oracle within `1e-5` (relative to the mesh's size).
fn assert_kernel_matches_oracle(name: &str, bind: &[Vec3], weights: &SkinWeights, palette: &[Mat4]) {
    let n = bind.len();
    let mut expected = vec![Vec3::ZERO; n];
    skin_positions(bind, weights, palette, &mut expected);
    let scale = expected.iter().fold(1.0f32, |m, p| m.max(p.abs().max_element()));
    for path in Simd::available() {
        let mut out = vec![Vec3::splat(f32::NAN); n];
        let grown = skin_using(path, bind, weights, palette, &mut out);
        let worst = expected.iter().zip(&out).map(|(a, b)| (*a - *b).abs().max_element()).fold(0.0f32, f32::max);
        assert!(worst <= 1e-5 * scale, "{name} ({path:?}): worst difference {worst:e} (mesh scale {scale})");
        // The box grown as the vertices are written is the box of what was written.
        assert_eq!(grown.pair(), bounds(&out), "{name} ({path:?}): bounds");
    }
    assert_normals_match_oracle(name, bind, weights, palette);
}

/// The kernel that skins normals with the positions (each level) against the plain loop:
/// positions, normals and box. Outputs start as NaN, so a vertex left unwritten fails.
fn assert_normals_match_oracle(name: &str, bind: &[Vec3], weights: &SkinWeights, palette: &[Mat4]) {
    use marionette::rig::lbs::{Normals, skin_with_normals_using};
    let n = bind.len();
    let centre = bind.iter().sum::<Vec3>() / n.max(1) as f32;
    let bind_normals: Vec<Vec3> = bind.iter().map(|p| (*p - centre).normalize_or(Vec3::Y)).collect();
    let (mut expected, mut expected_normals) = (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]);
    let normals = Normals { bind: &bind_normals, out: &mut expected_normals };
    marionette::rig::skinning::skin_positions_and_normals(bind, weights, palette, &mut expected, normals);
    let scale = expected.iter().fold(1.0f32, |m, p| m.max(p.abs().max_element()));
    for path in Simd::available() {
        let (mut out, mut out_normals) = (vec![Vec3::splat(f32::NAN); n], vec![Vec3::splat(f32::NAN); n]);
        let normals = Normals { bind: &bind_normals, out: &mut out_normals };
        let grown = skin_with_normals_using(path, bind, weights, palette, &mut out, normals);
        let worst =
            |a: &[Vec3], b: &[Vec3]| a.iter().zip(b).map(|(a, b)| (*a - *b).abs().max_element()).fold(0.0f32, f32::max);
        let (positions, normals) = (worst(&expected, &out), worst(&expected_normals, &out_normals));
        assert!(positions <= 1e-5 * scale, "{name} ({path:?}, with normals): positions {positions:e}");
        // Normals are unit vectors turned by blends of palette matrices (scaled in the
        // synthetic set by up to 1.5): 1e-5 of their size.
        assert!(normals <= 1e-5 * 2.0, "{name} ({path:?}): normals {normals:e}");
        assert_eq!(grown.pair(), bounds(&out), "{name} ({path:?}, with normals): bounds");
    }
}

#[test]
fn the_kernel_matches_the_oracle_on_rows_of_1_to_13_influences() {
    // splitmix64: reproducible without a dependency.
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    };
    let joints = 30;
    let palette: Vec<Mat4> = (0..joints)
        .map(|_| {
            let q = Quat::from_euler(glam::EulerRot::XYZ, next() * 6.0, next() * 6.0, next() * 6.0);
            Mat4::from_scale_rotation_translation(Vec3::splat(0.5 + next()), q, Vec3::new(next(), next(), next()) * 4.0)
        })
        .collect();
    let n = 2000;
    let bind: Vec<Vec3> = (0..n).map(|_| Vec3::new(next(), next(), next()) * 2.0 - 1.0).collect();
    let rows: Vec<Vec<(usize, f32)>> =
        (0..n).map(|v| (0..1 + v % 13).map(|k| ((v * 7 + k * 11) % joints, 0.1 + next())).collect()).collect();
    let (weights, _) = SkinWeights::from_rows(rows, joints).unwrap();
    assert!(weights.groups().fixed.iter().all(|g| !g.vertices.is_empty()) && !weights.groups().wide.is_empty());
    assert_kernel_matches_oracle("synthetic", &bind, &weights, &palette);
    // In chunks of 300 (how a large mesh is split across threads; blocks cut at their
    // edges at each level's width): the same output exactly, at every level.
    for simd in Simd::available() {
        let mut whole = vec![Vec3::ZERO; n];
        skin_using(simd, &bind, &weights, &palette, &mut whole);
        let mut chunked = vec![Vec3::splat(f32::NAN); n];
        let boxes = chunked
            .chunks_mut(300)
            .enumerate()
            .map(|(k, chunk)| skin_chunk_using(simd, &bind, &weights, &palette, k * 300, chunk));
        let grown = boxes.fold(Bounds::EMPTY, Bounds::union);
        assert_eq!(chunked, whole, "{simd:?}");
        assert_eq!(grown.pair(), bounds(&whole), "{simd:?}");
    }
}

#[test]
fn the_kernel_matches_the_oracle_on_the_puppet() {
    let asset = marionette::formats::puppet::embedded_puppet();
    assert_kernel_matches_oracle("puppet", &asset.skin.bind_positions, &asset.skin.weights, &posed_palette(&asset));
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn the_kernel_matches_the_oracle_on_every_data_set() {
    let data = crate::common::data_dir();
    let mut files: Vec<std::path::PathBuf> = (1..=4).map(|m| data.join(format!("mit6837/Model{m}.skel"))).collect();
    files.extend(
        ["project1/wasp.skel", "project1/dragon.skel", "project2/tube.skel"].map(|f| data.join("cse169").join(f)),
    );
    files.extend([data.join("homer/homer.json"), data.join("smpl")]);
    for path in files {
        let asset = if path.is_dir() {
            let (model, _) = marionette::formats::smpl::load_smpl_dir(&path).unwrap();
            model.asset("smpl", &[1.0, -0.5, 0.3]).unwrap()
        } else {
            marionette::formats::load_character(&path).unwrap()
        };
        let name = path.display().to_string();
        assert_kernel_matches_oracle(&name, &asset.skin.bind_positions, &asset.skin.weights, &posed_palette(&asset));
    }
}

/// The kernel tests above run every level this CPU runs; a level it lacks is reported here
/// as ignored (build.rs reads the building CPU), never passed unseen.
#[test]
#[cfg_attr(not(cpu_avx512), ignore = "this CPU lacks AVX-512 (F and VL): that kernel level is not tested here")]
fn the_avx512_kernels_are_among_those_tested() {
    assert!(Simd::available().any(|s| s == Simd::Avx512Vl), "built on a CPU with AVX-512, run on one without");
}

#[test]
#[cfg_attr(not(cpu_avx2), ignore = "this CPU lacks AVX2 and FMA: that kernel level is not tested here")]
fn the_avx2_kernels_are_among_those_tested() {
    assert!(Simd::available().any(|s| s == Simd::Avx2), "built on a CPU with AVX2, run on one without");
}

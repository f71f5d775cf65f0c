//! Dual quaternion skinning: identity at the bind pose, LBS where a vertex has one
//! influence, volume kept where LBS collapses a twist, and the same in the ECS.

use std::sync::Arc;

use glam::{Mat4, Quat, Vec3};
use marionette::rig::dqs::{
    DualQuat, SkinningMethod, dual_quaternion_palette, skin_dq, skin_dq_using, skin_dq_with_normals,
    skin_dq_with_normals_using,
};
use marionette::rig::lbs::skin;
use marionette::rig::skinning::Normals;
use marionette::rig::{JointRotation, SkinWeights};

fn dq(palette: &[Mat4]) -> Vec<DualQuat> {
    let mut out = Vec::new();
    dual_quaternion_palette(palette, &mut out);
    out
}

#[test]
fn at_the_bind_pose_dual_quaternions_return_the_input() {
    let asset = marionette::formats::puppet::embedded_puppet();
    let identity = vec![Mat4::IDENTITY; asset.skeleton.len()];
    let mut out = vec![Vec3::ZERO; asset.vertex_count()];
    skin_dq(&asset.skin.bind_positions, &asset.skin.weights, &dq(&identity), &mut out);
    for (a, b) in out.iter().zip(&asset.skin.bind_positions) {
        assert!(a.distance(*b) < 1e-6, "{a} vs {b}");
    }
}

#[test]
fn a_vertex_with_one_influence_moves_as_in_linear_blend_skinning() {
    let asset = marionette::formats::puppet::embedded_puppet();
    let n = asset.skeleton.len();
    let palette: Vec<Mat4> = (0..n)
        .map(|j| {
            let q = Quat::from_euler(glam::EulerRot::XYZ, 0.3 * j as f32, -0.2, 0.1 * j as f32);
            Mat4::from_rotation_translation(q, Vec3::new(0.1 * j as f32, 0.5, -0.3))
        })
        .collect();
    let rigid = SkinWeights::rigid(&(0..asset.vertex_count()).map(|v| (v % n) as u16).collect::<Vec<_>>());
    let (mut lbs, mut dqs) = (vec![Vec3::ZERO; asset.vertex_count()], vec![Vec3::ZERO; asset.vertex_count()]);
    skin(&asset.skin.bind_positions, &rigid, &palette, &mut lbs);
    skin_dq(&asset.skin.bind_positions, &rigid, &dq(&palette), &mut dqs);
    for (a, b) in lbs.iter().zip(&dqs) {
        assert!(a.distance(*b) < 1e-5, "{a} vs {b}");
    }
}

/// Unit normals of their own for `count` vertices, pointing every way.
fn unit_normals(count: usize) -> Vec<Vec3> {
    (0..count)
        .map(|v| Vec3::new((v as f32 * 0.37).sin(), 1.0 - (v % 7) as f32 * 0.3, (v as f32 * 1.3).cos()).normalize())
        .collect()
}

/// A vertex with one influence has its normal turned by that joint's rotation (the
/// matrix's 3×3 part, as linear blend skinning turns it), at every level of the kernel.
#[test]
fn a_vertex_with_one_influence_has_its_normal_turned_by_its_joint() {
    let asset = marionette::formats::puppet::embedded_puppet();
    let n = asset.skeleton.len();
    let palette: Vec<Mat4> = (0..n)
        .map(|j| {
            let q = Quat::from_euler(glam::EulerRot::YXZ, 0.4 * j as f32, 0.25, -0.15 * j as f32);
            Mat4::from_rotation_translation(q, Vec3::new(-0.2, 0.1 * j as f32, 0.4))
        })
        .collect();
    let count = asset.vertex_count();
    let joint_of = |v: usize| (v * 5 % n) as u16;
    let rigid = SkinWeights::rigid(&(0..count).map(joint_of).collect::<Vec<_>>());
    let bind_normals = unit_normals(count);
    for simd in marionette::rig::simd::Simd::available() {
        let (mut positions, mut normals) = (vec![Vec3::NAN; count], vec![Vec3::NAN; count]);
        let out = Normals { bind: &bind_normals, out: &mut normals };
        skin_dq_with_normals_using(simd, &asset.skin.bind_positions, &rigid, &dq(&palette), &mut positions, out);
        for (v, (got, bind)) in normals.iter().zip(&bind_normals).enumerate() {
            let expected = palette[joint_of(v) as usize].transform_vector3(*bind);
            assert!(got.distance(expected) < 1e-5, "{simd:?}, vertex {v}: {got} vs {expected}");
        }
    }
}

/// Blending several joints, the normal is turned by a rotation: unit normals stay unit
/// (linear blend skinning shortens them where its joints disagree).
#[test]
fn dual_quaternion_normals_keep_their_length() {
    let asset = marionette::formats::puppet::embedded_puppet();
    let pose: Vec<JointRotation> =
        (0..asset.skeleton.len()).map(|i| JointRotation::euler_xyz(0.5 * i as f32, -0.7, 0.3 * i as f32)).collect();
    let palette =
        marionette::rig::fk::posed_palette(&asset.skeleton, &asset.bind_world_to_joint, &pose, Mat4::IDENTITY);
    let count = asset.vertex_count();
    let bind_normals = unit_normals(count);
    let (mut positions, mut normals) = (vec![Vec3::ZERO; count], vec![Vec3::ZERO; count]);
    let out = Normals { bind: &bind_normals, out: &mut normals };
    skin_dq_with_normals(&asset.skin.bind_positions, &asset.skin.weights, &dq(&palette), &mut positions, out);
    let worst = normals.iter().map(|n| (n.length() - 1.0).abs()).fold(0.0f32, f32::max);
    assert!(worst < 1e-5, "length off by {worst}");
    let mut alone = vec![Vec3::ZERO; count];
    skin_dq(&asset.skin.bind_positions, &asset.skin.weights, &dq(&palette), &mut alone);
    assert_eq!(alone, positions, "the positions are those of the kernel without normals");
}

/// The area of a closed polygon of points in the plane x = const (shoelace over y, z).
fn area_yz(ring: &[Vec3]) -> f32 {
    let n = ring.len();
    (0..n).map(|i| ring[i].y * ring[(i + 1) % n].z - ring[(i + 1) % n].y * ring[i].z).sum::<f32>().abs() / 2.0
}

/// A cylinder along x over two bones (the joint at x = 1, weights blending over
/// 0.5..1.5) and the cross-section at the joint after the second bone twists by `angle`,
/// as a fraction of the rest area: (LBS, DQ).
fn twisted_cross_section(angle: f32) -> (f32, f32) {
    let (slices, around, radius) = (21usize, 32usize, 0.2f32);
    let mut bind = Vec::new();
    let mut rows = Vec::new();
    for s in 0..slices {
        let x = 2.0 * s as f32 / (slices - 1) as f32;
        let w1 = ((x - 0.5).clamp(0.0, 1.0) * std::f32::consts::PI / 2.0).sin().powi(2);
        for k in 0..around {
            let a = std::f32::consts::TAU * k as f32 / around as f32;
            bind.push(Vec3::new(x, radius * a.cos(), radius * a.sin()));
            rows.push(vec![(0, 1.0 - w1), (1, w1)]);
        }
    }
    let (weights, _) = SkinWeights::from_rows(rows, 2).unwrap();
    let twist = Mat4::from_translation(Vec3::X) * Mat4::from_rotation_x(angle) * Mat4::from_translation(-Vec3::X);
    let palette = [Mat4::IDENTITY, twist];
    let (mut lbs, mut dqs) = (vec![Vec3::ZERO; bind.len()], vec![Vec3::ZERO; bind.len()]);
    skin(&bind, &weights, &palette, &mut lbs);
    skin_dq(&bind, &weights, &dq(&palette), &mut dqs);
    let middle = (slices / 2) * around..(slices / 2 + 1) * around;
    let rest = area_yz(&bind[middle.clone()]);
    (area_yz(&lbs[middle.clone()]) / rest, area_yz(&dqs[middle]) / rest)
}

#[test]
fn a_twisted_joint_keeps_its_cross_section_with_dual_quaternions() {
    let (lbs, dq) = twisted_cross_section(std::f32::consts::FRAC_PI_2);
    eprintln!(
        "90° twist, cross-section at the joint: LBS {:.1} %, DQ {:.1} % of the rest area",
        lbs * 100.0,
        dq * 100.0
    );
    assert!((dq - 1.0).abs() < 0.05, "DQ keeps the area within 5 %: {dq}");
    assert!(lbs < 0.6, "LBS loses area: {lbs}");
    let (lbs, dq) = twisted_cross_section(2.8);
    eprintln!("160° twist: LBS {:.1} %, DQ {:.1} %", lbs * 100.0, dq * 100.0);
    assert!(lbs < 0.1 && (dq - 1.0).abs() < 0.05);
}

/// A character switched to dual quaternion skinning in the ECS skins like the kernel.
#[test]
fn dual_quaternion_skinning_in_the_ecs_matches_the_kernel() {
    use marionette::scene::{CharacterSkinning, Placement};
    let asset = Arc::new(marionette::formats::puppet::embedded_puppet());
    let mut app = crate::ecs::app();
    let character = crate::ecs::spawn(&mut app, asset.clone(), Placement::default());
    app.world_mut().get_mut::<CharacterSkinning>(character).unwrap().0 = SkinningMethod::DualQuaternion;
    let elbow = asset.skeleton.find("l_elbow").unwrap();
    let rotation = JointRotation::euler_xyz(0.0, 1.2, 0.4);
    crate::ecs::set_joint(&mut app, character, elbow, rotation);
    app.update();
    let mut pose = asset.skeleton.initial_pose();
    pose[elbow] = rotation;
    let expected =
        marionette::document::posing::posed_positions_by(&asset, &pose, Mat4::IDENTITY, SkinningMethod::DualQuaternion);
    let got = &app.world().get::<marionette::scene::SkinScratch>(character).unwrap().positions;
    let worst = got.iter().zip(&expected).map(|(a, b)| a.distance(*b)).fold(0.0f32, f32::max);
    assert!(worst < 1e-5, "largest difference {worst}");
    let linear = marionette::document::posing::posed_positions(&asset, &pose, Mat4::IDENTITY);
    assert!(linear.iter().zip(&expected).any(|(a, b)| a.distance(*b) > 1e-3), "DQ differs from LBS at the elbow");
}

/// The SIMD path (where the CPU has AVX2 and FMA) against the portable one on the puppet
/// and, with the data, every character of the courses and SMPL, posed.
#[test]
fn the_dual_quaternion_kernel_paths_agree() {
    let mut assets = vec![marionette::formats::puppet::embedded_puppet()];
    if let Some(data) = crate::common::optional_data_dir() {
        let files = ["mit6837/Model1.skel", "mit6837/Model2.skel", "mit6837/Model3.skel", "mit6837/Model4.skel"]
            .into_iter()
            .chain(["cse169/project1/wasp.skel", "cse169/project1/dragon.skel", "cse169/project2/tube.skel"])
            .chain(["homer/homer.json"]);
        for f in files {
            assets.push(marionette::formats::load_character(&data.join(f)).unwrap());
        }
        let (model, _) = marionette::formats::smpl::load_smpl_dir(&data.join("smpl")).unwrap();
        assets.push(model.asset("smpl", &[0.5]).unwrap());
    }
    for asset in assets {
        let n = asset.skeleton.len();
        let pose: Vec<JointRotation> =
            (0..n).map(|i| JointRotation::euler_xyz(0.2 * i as f32, -0.1, 0.15 * i as f32)).collect();
        let palette =
            marionette::rig::fk::posed_palette(&asset.skeleton, &asset.bind_world_to_joint, &pose, Mat4::IDENTITY);
        assert_simd_levels_match_portable(&asset.name, &asset.skin.bind_positions, &asset.skin.weights, &dq(&palette));
    }
}

/// Each SIMD level of the kernel this CPU runs (AVX2, and AVX-512 VL where it has it)
/// against the portable path, within 1e-5 of the mesh's size: positions alone, and
/// positions with unit normals (those within 1e-5). Outputs start as NaN, so a vertex
/// left unwritten fails.
fn assert_simd_levels_match_portable(name: &str, bind: &[Vec3], weights: &SkinWeights, dq: &[DualQuat]) {
    use marionette::rig::simd::Simd;
    let worst =
        |a: &[Vec3], b: &[Vec3]| a.iter().zip(b).map(|(x, y)| (*x - *y).abs().max_element()).fold(0.0f32, f32::max);
    let bind_normals = unit_normals(bind.len());
    let with_normals = |simd| {
        let (mut positions, mut normals) = (vec![Vec3::NAN; bind.len()], vec![Vec3::NAN; bind.len()]);
        let out = Normals { bind: &bind_normals, out: &mut normals };
        skin_dq_with_normals_using(simd, bind, weights, dq, &mut positions, out);
        (positions, normals)
    };
    let mut expected = vec![Vec3::NAN; bind.len()];
    skin_dq_using(Simd::Portable, bind, weights, dq, &mut expected);
    let (expected_with, expected_normals) = with_normals(Simd::Portable);
    assert_eq!(expected_with, expected, "{name}: the portable positions, with normals or without");
    let scale = expected.iter().fold(1.0f32, |m, p| m.max(p.abs().max_element()));
    for simd in Simd::available().filter(|&s| s != Simd::Portable) {
        let mut out = vec![Vec3::NAN; bind.len()];
        skin_dq_using(simd, bind, weights, dq, &mut out);
        let off = worst(&out, &expected);
        assert!(off <= 1e-5 * scale, "{name} ({simd:?}): worst {off:e} (scale {scale})");
        let (positions, normals) = with_normals(simd);
        assert_eq!(positions, out, "{name} ({simd:?}): positions with normals or without");
        let off = worst(&normals, &expected_normals);
        assert!(off <= 1e-5, "{name} ({simd:?}): normals off by {off:e}");
    }
}

/// The SIMD path against the portable one on rows of 1 to 13 influences over 40 joints:
/// blocks whose lanes share a pivot, blocks whose pivots all have a row of the table of
/// hemispheres, blocks with a pivot beyond it (more than 32 pivots), and a partial last
/// block. Outputs start as NaN, so a vertex left unwritten fails.
#[test]
fn the_dual_quaternion_kernel_matches_the_portable_path_on_rows_of_1_to_13_influences() {
    use marionette::rig::influences::BlockPivots;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let joints = 40;
    let palette: Vec<Mat4> = (0..joints)
        .map(|_| {
            let q = Quat::from_euler(glam::EulerRot::XYZ, next() * 6.0, next() * 6.0, next() * 6.0);
            Mat4::from_rotation_translation(q, Vec3::new(next(), next(), next()) * 4.0)
        })
        .collect();
    let n = 2003;
    let bind: Vec<Vec3> = (0..n).map(|_| Vec3::new(next(), next(), next()) * 2.0 - 1.0).collect();
    let rows: Vec<Vec<(usize, f32)>> = (0..n)
        .map(|v| match v {
            // The first 64: one pivot a block (joint 3 the heaviest of two).
            0..64 => vec![(3, 0.7), (v % 5 + 4, 0.3)],
            // Then pivots among the first 20 joints, then any of the 40.
            _ => {
                (0..1 + v % 13).map(|k| ((v * 7 + k * 11) % if v < 1000 { 20 } else { joints }, 0.1 + next())).collect()
            }
        })
        .collect();
    let (weights, _) = SkinWeights::from_rows(rows, joints).unwrap();
    let kinds = &weights.groups().blocks.block_pivots;
    assert!(kinds.iter().any(|k| matches!(k, BlockPivots::Shared(_))), "a block of one pivot");
    assert!(kinds.contains(&BlockPivots::Rows) && kinds.contains(&BlockPivots::Lanes), "{kinds:?}");
    assert_simd_levels_match_portable("rows of 1 to 13", &bind, &weights, &dq(&palette));
}

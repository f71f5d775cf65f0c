//! Bone heat binding: on a closed tube over a chain of joints the weights are a partition
//! of unity that hands over from one joint to the next along the tube; on meshes that are
//! open or in pieces every row is whole; on the 6.837 models they agree with the models'
//! own weights (Pinocchio's bone heat).

use glam::Vec3;
use marionette::rig::bind::{Binding, bind_to_skeleton};
use marionette::rig::{RawJoint, Skeleton, SkinWeights};

/// A closed tube along y from 0 to 3 (rings of 16, capped), over a chain of joints at y =
/// 0, 1, 2 (the last a leaf: its bone must reach into the tube's top by itself).
fn capped_tube() -> (Vec<Vec3>, Vec<[u32; 3]>, Skeleton) {
    let (rings, around) = (31u32, 16u32);
    let mut vertices = Vec::new();
    for r in 0..rings {
        let y = 3.0 * r as f32 / (rings - 1) as f32;
        for k in 0..around {
            let a = std::f32::consts::TAU * k as f32 / around as f32;
            vertices.push(Vec3::new(0.25 * a.cos(), y, 0.25 * a.sin()));
        }
    }
    let mut triangles = Vec::new();
    for r in 0..rings - 1 {
        for k in 0..around {
            let (a, b) = (r * around + k, r * around + (k + 1) % around);
            let (c, d) = (a + around, b + around);
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
    }
    // The caps: a centre vertex each, outward faces.
    let (bottom, top) = (vertices.len() as u32, vertices.len() as u32 + 1);
    vertices.push(Vec3::ZERO);
    vertices.push(Vec3::new(0.0, 3.0, 0.0));
    let last = (rings - 1) * around;
    for k in 0..around {
        triangles.push([bottom, k, (k + 1) % around]);
        triangles.push([top, last + (k + 1) % around, last + k]);
    }
    let skeleton = Skeleton::build(vec![
        RawJoint::new("hip", None, Vec3::ZERO),
        RawJoint::new("knee", Some(0), Vec3::Y),
        RawJoint::new("ankle", Some(1), Vec3::Y),
    ])
    .unwrap();
    (vertices, triangles, skeleton)
}

fn assert_whole_rows(weights: &SkinWeights, vertices: usize) {
    assert_eq!(weights.vertex_count(), vertices);
    for v in 0..vertices {
        let row = weights.of_vertex(v);
        assert!(!row.is_empty(), "vertex {v} has no weight");
        assert!(row.iter().all(|i| i.weight.is_finite() && i.weight > 0.0 && i.weight <= 1.0 + 1e-6), "{row:?}");
        let sum: f32 = row.iter().map(|i| i.weight).sum();
        assert!((sum - 1.0).abs() < 1e-5, "vertex {v}: {sum}");
    }
}

/// Each joint owns the tube where its bone runs (weight > 0.95 in the middle of its bone),
/// the leaf's bone reaches into the top, and the weight of each joint falls off smoothly
/// past its bone (monotone along the tube, never jumping by more than a third per ring).
#[test]
fn heat_hands_over_along_a_tube_from_joint_to_joint() {
    let (vertices, triangles, skeleton) = capped_tube();
    let weights = bind_to_skeleton(&skeleton, &vertices, &triangles, Binding::Heat).unwrap();
    assert_whole_rows(&weights, vertices.len());
    let ring_weight = |y_ring: u32, joint: usize| weights.weight((y_ring * 16) as usize, joint);
    for (ring, joint) in [(5, 0), (15, 1), (27, 2)] {
        assert!(ring_weight(ring, joint) > 0.95, "ring {ring}: joint {joint} {}", ring_weight(ring, joint));
    }
    for r in 10..20 {
        let (w, next) = (ring_weight(r, 0), ring_weight(r + 1, 0));
        assert!(next <= w + 1e-4, "the hip's weight falls along the tube: ring {r} {w} -> {next}");
        assert!(w - next < 0.34, "smoothly: ring {r} {w} -> {next}");
    }
    // Every ring is nearly the same all around (the tube is symmetric about its axis; its
    // triangles, split one way, are not quite).
    for r in 0..31 {
        let w: Vec<f32> = (0..16).map(|k| weights.weight((r * 16 + k) as usize, 1)).collect();
        assert!(w.iter().all(|x| (x - w[0]).abs() < 0.05), "ring {r}: {w:?}");
    }
}

/// A mesh in pieces, open, with a vertex in no triangle and a piece that sees no bone
/// (outside the skeleton's reach, inside out): every row is whole, nothing is NaN.
#[test]
fn heat_gives_every_vertex_a_whole_row_on_open_meshes_in_pieces() {
    let (mut vertices, mut triangles, skeleton) = capped_tube();
    // Open it: drop the caps.
    triangles.truncate(triangles.len() - 32);
    // A lone vertex and an inside-out triangle far away.
    let first = vertices.len() as u32;
    vertices.extend([
        Vec3::new(5.0, 1.0, 0.0),
        Vec3::new(6.0, 0.0, 0.0),
        Vec3::new(6.0, 1.0, 0.0),
        Vec3::new(6.0, 0.0, 1.0),
    ]);
    triangles.push([first + 1, first + 3, first + 2]);
    let weights = bind_to_skeleton(&skeleton, &vertices, &triangles, Binding::Heat).unwrap();
    assert_whole_rows(&weights, vertices.len());
    // The puppet: boxes and tubes in many pieces.
    let puppet = marionette::formats::puppet::embedded_puppet();
    let weights =
        bind_to_skeleton(&puppet.skeleton, &puppet.skin.bind_positions, &puppet.skin.triangles, Binding::Heat).unwrap();
    assert_whole_rows(&weights, puppet.vertex_count());
}

/// SMPL and Homer (open and multi-piece meshes from the course data) bind with whole rows.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn heat_binds_the_course_characters_with_whole_rows() {
    let data = crate::common::data_dir();
    for path in [data.join("smpl"), data.join("homer/homer.json")] {
        let asset = marionette::formats::load_character(&path).unwrap();
        let weights =
            bind_to_skeleton(&asset.skeleton, &asset.skin.bind_positions, &asset.skin.triangles, Binding::Heat)
                .unwrap();
        assert_whole_rows(&weights, asset.vertex_count());
    }
}

/// The 6.837 models' weights are Pinocchio's bone heat: ours agree with them (the
/// heaviest joint, and the mean L1 distance of the rows) at least as well as the issue's
/// target, 98 % and 0.05 (this binder: 99.6, 99.7, 98.5, 98.8 % and 0.008, 0.009, 0.021,
/// 0.033). Blender 5's automatic weights reach 95.8, 96.8, 93.7, 97.3 %.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn heat_agrees_with_the_6837_models_own_weights() {
    let dir = crate::common::data_dir().join("mit6837");
    for (m, floor, ceiling) in [(1, 0.99, 0.015), (2, 0.99, 0.015), (3, 0.98, 0.03), (4, 0.98, 0.04)] {
        let model = marionette::formats::load_character(&dir.join(format!("Model{m}.skel"))).unwrap();
        let skin = &model.skin;
        let started = std::time::Instant::now();
        let ours = bind_to_skeleton(&model.skeleton, &skin.bind_positions, &skin.triangles, Binding::Heat).unwrap();
        let seconds = started.elapsed().as_secs_f64();
        let (agree, l1) = marionette::rig::skinning::agreement(&ours, &skin.weights);
        eprintln!(
            "Model{m}: heaviest joint agrees on {:.1} %, mean L1 {l1:.3}, bound in {seconds:.3} s",
            100.0 * agree
        );
        assert!(agree >= floor && l1 <= ceiling, "Model{m}: {agree} {l1}");
    }
}

/// A joint whose children start at one point (the 6.837 back, whose two thighs both start
/// at the hips) has one bone there: a repeated bone would count twice in a vertex's heat.
#[test]
fn heat_counts_a_bone_that_two_children_share_once() {
    let skeleton = Skeleton::build(vec![
        RawJoint::new("back", None, Vec3::ZERO),
        RawJoint::new("left hip", Some(0), -Vec3::Y),
        RawJoint::new("right hip", Some(0), -Vec3::Y),
        RawJoint::new("left knee", Some(1), Vec3::new(-0.3, -1.0, 0.0)),
        RawJoint::new("right knee", Some(2), Vec3::new(0.3, -1.0, 0.0)),
    ])
    .unwrap();
    let joints = [Vec3::ZERO, -Vec3::Y, -Vec3::Y, Vec3::new(-0.3, -2.0, 0.0), Vec3::new(0.3, -2.0, 0.0)];
    let bones = marionette::rig::heat::heat_bones(&skeleton, &joints, &joints);
    let back: Vec<_> = bones.iter().filter(|b| b.joint == 0).collect();
    assert_eq!(back.len(), 1, "{bones:?}");
    assert_eq!((back[0].start, back[0].end), (Vec3::ZERO, -Vec3::Y));
    assert_eq!(bones.iter().filter(|b| b.joint == 1 || b.joint == 2).count(), 2);
}

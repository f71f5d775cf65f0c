//! The rig core: matrix stack, Euler order and clamping, FK, skinning kernels.

use std::f32::consts::{FRAC_PI_2, PI};

use crate::fk::{bind_world_to_joint, forward_kinematics, skinning_palette};
use crate::skinning::{flat_shade, joint_colors, skin_positions, weight_colors};
use crate::{DofLimits, EulerOrder, JointRotation, MatrixStack, RawJoint, RigError, Skeleton, SkinWeights};
use glam::{Mat3, Mat4, Quat, Vec3};

#[test]
fn empty_matrix_stack_top_is_identity() {
    let stack = MatrixStack::new();
    assert_eq!(stack.top(), Mat4::IDENTITY);
    assert_eq!(stack.depth(), 0);
}

#[test]
fn push_multiplies_onto_the_top_and_pop_restores() {
    let mut stack = MatrixStack::new();
    let a = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0));
    let b = Mat4::from_rotation_z(0.5);
    stack.push(a);
    assert_eq!(stack.top(), a);
    stack.push(b);
    // top · new, not new · top: the translation is applied after the rotation.
    assert_mat_close(stack.top(), a * b, 1e-6);
    assert_ne!(stack.top(), b * a);
    assert_eq!(stack.pop(), Some(a * b));
    assert_eq!(stack.top(), a);
    stack.pop();
    assert_eq!(stack.top(), Mat4::IDENTITY);
    assert_eq!(stack.pop(), None, "popping an empty stack is a no-op");
}

#[test]
fn euler_xyz_applies_x_first_then_y_then_z() {
    let (x, y, z) = (0.3, -0.7, 1.1);
    let r = JointRotation::euler_xyz(x, y, z).to_mat3();
    let expected = Mat3::from_rotation_z(z) * Mat3::from_rotation_y(y) * Mat3::from_rotation_x(x);
    assert!(r.abs_diff_eq(expected, 1e-6));
    // Hand-checked: x by 90° then z by 90° sends +y to +z (x) and then keeps it on +z (z).
    let r = JointRotation::euler_xyz(FRAC_PI_2, 0.0, FRAC_PI_2).to_mat3();
    assert_vec_close(r * Vec3::Y, Vec3::Z, 1e-6);
    // and sends +x to +y (z rotates x into y; the x rotation leaves x alone).
    assert_vec_close(r * Vec3::X, Vec3::Y, 1e-6);
}

#[test]
fn every_euler_order_round_trips_through_quaternions() {
    let angles = Vec3::new(0.4, -0.3, 0.9);
    for order in [EulerOrder::Xyz, EulerOrder::Xzy, EulerOrder::Yxz, EulerOrder::Yzx, EulerOrder::Zxy, EulerOrder::Zyx]
    {
        let rot = JointRotation::Euler(angles, order);
        let back = JointRotation::Quat(rot.to_quat()).to_euler(order);
        assert_vec_close(back, angles, 1e-5);
        let [a, b, c] = order.axes();
        let axis = |i: usize, t: f32| match i {
            0 => Mat3::from_rotation_x(t),
            1 => Mat3::from_rotation_y(t),
            _ => Mat3::from_rotation_z(t),
        };
        let expected = axis(c, angles[c]) * axis(b, angles[b]) * axis(a, angles[a]);
        assert!(rot.to_mat3().abs_diff_eq(expected, 1e-6), "{order:?}");
    }
}

#[test]
fn clamping_respects_limits_and_locked_axes() {
    let limits = DofLimits { min: Vec3::new(-2.0, 0.0, -0.5), max: Vec3::new(0.0, 0.0, 0.5) };
    let clamped = JointRotation::euler_xyz(-3.0, 1.0, 0.2).clamped(&limits);
    assert_eq!(clamped, JointRotation::euler_xyz(-2.0, 0.0, 0.2));
    assert!(limits.is_locked(1));
    assert!(!limits.is_locked(0));
    assert_eq!(
        JointRotation::euler_xyz(9.0, 9.0, 9.0).clamped(&DofLimits::UNLIMITED),
        JointRotation::euler_xyz(9.0, 9.0, 9.0)
    );
    assert_eq!(DofLimits::UNLIMITED.display_range(0), (-PI, PI));
}

fn chain() -> Skeleton {
    Skeleton::build(vec![
        RawJoint::new("root", None, Vec3::new(1.0, 0.0, 0.0)),
        RawJoint::new("a", Some(0), Vec3::new(0.0, 2.0, 0.0)),
        RawJoint::new("b", Some(1), Vec3::new(0.0, 0.0, 3.0)),
        RawJoint::new("c", Some(0), Vec3::new(-1.0, 0.0, 0.0)),
    ])
    .unwrap()
}

#[test]
fn fk_matches_hand_computed_matrices() {
    let s = chain();
    let mut pose = s.rest_pose();
    pose[0] = JointRotation::euler_xyz(0.0, 0.0, FRAC_PI_2); // root: +90° about z
    pose[1] = JointRotation::euler_xyz(FRAC_PI_2, 0.0, 0.0); // a: +90° about x
    let mut m = vec![Mat4::IDENTITY; 4];
    forward_kinematics(&s, &pose, Mat4::IDENTITY, &mut m);
    // root at (1,0,0); a = root + Rz90·(0,2,0) = (1,0,0) + (-2,0,0) = (-1,0,0).
    assert_vec_close(m[0].w_axis.truncate(), Vec3::new(1.0, 0.0, 0.0), 1e-6);
    assert_vec_close(m[1].w_axis.truncate(), Vec3::new(-1.0, 0.0, 0.0), 1e-6);
    // b = a + Rz90·Rx90·(0,0,3): Rx90 takes z to -y, Rz90 takes -y to +x: (-1,0,0)+(3,0,0).
    assert_vec_close(m[2].w_axis.truncate(), Vec3::new(2.0, 0.0, 0.0), 1e-5);
    // c = root + Rz90·(-1,0,0) = (1,0,0) + (0,-1,0).
    assert_vec_close(m[3].w_axis.truncate(), Vec3::new(1.0, -1.0, 0.0), 1e-6);
    let expected_b = Mat4::from_translation(Vec3::X)
        * Mat4::from_rotation_z(FRAC_PI_2)
        * Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0))
        * Mat4::from_rotation_x(FRAC_PI_2)
        * Mat4::from_translation(Vec3::new(0.0, 0.0, 3.0));
    assert_mat_close(m[2], expected_b, 1e-5);
}

#[test]
fn fk_starts_from_the_placement() {
    let s = chain();
    let placement = Mat4::from_translation(Vec3::new(0.0, 10.0, 0.0)) * Mat4::from_rotation_y(0.3);
    let mut placed = vec![Mat4::IDENTITY; 4];
    let mut plain = vec![Mat4::IDENTITY; 4];
    forward_kinematics(&s, &s.rest_pose(), placement, &mut placed);
    forward_kinematics(&s, &s.rest_pose(), Mat4::IDENTITY, &mut plain);
    for j in 0..4 {
        assert_mat_close(placed[j], placement * plain[j], 1e-5);
    }
}

#[test]
fn skeleton_validation_rejects_bad_trees() {
    let e = Skeleton::build(vec![RawJoint::new("a", None, Vec3::ZERO), RawJoint::new("b", Some(7), Vec3::ZERO)])
        .unwrap_err();
    assert_eq!(e, RigError::ParentOutOfRange { joint: 1, parent: 7, count: 2 });
    let e =
        Skeleton::build(vec![RawJoint::new("a", None, Vec3::ZERO), RawJoint::new("b", None, Vec3::ZERO)]).unwrap_err();
    assert!(matches!(e, RigError::SeveralRoots { .. }));
    let e = Skeleton::build(vec![
        RawJoint::new("r", None, Vec3::ZERO),
        RawJoint::new("a", Some(2), Vec3::ZERO),
        RawJoint::new("b", Some(1), Vec3::ZERO),
    ])
    .unwrap_err();
    assert!(matches!(e, RigError::Cycle { .. }), "{e:?}");
    assert_eq!(Skeleton::build(vec![]).unwrap_err(), RigError::EmptySkeleton);
    // A forward reference without a cycle can be reordered, but `build` keeps file order.
    let raw = vec![RawJoint::new("child", Some(1), Vec3::ZERO), RawJoint::new("root", None, Vec3::ZERO)];
    assert!(matches!(Skeleton::build(raw.clone()).unwrap_err(), RigError::NotParentFirst { .. }));
    // Parents first but not depth-first: `build` keeps the file order.
    let kept = Skeleton::build(vec![
        RawJoint::new("r", None, Vec3::ZERO),
        RawJoint::new("a", Some(0), Vec3::ZERO),
        RawJoint::new("b", Some(0), Vec3::ZERO),
        RawJoint::new("a1", Some(1), Vec3::ZERO),
    ])
    .unwrap();
    assert_eq!(kept.joint(3).name, "a1");
    assert_eq!(kept.parent(3), Some(1));
    let (s, new_index) = Skeleton::build_reordered(raw).unwrap();
    assert_eq!(s.joint(0).name, "root");
    assert_eq!(new_index, vec![1, 0]);
}

fn two_bone_weights() -> SkinWeights {
    SkinWeights::from_rows(vec![vec![(0, 1.0)], vec![(0, 0.5), (1, 0.5)], vec![(1, 1.0)]], 2).unwrap().0
}

#[test]
fn skinning_blends_the_palette_by_weight() {
    let bind = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0)];
    let palette = [Mat4::IDENTITY, Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0))];
    let mut out = [Vec3::ZERO; 3];
    skin_positions(&bind, &two_bone_weights(), &palette, &mut out);
    assert_eq!(out, [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(2.0, 2.0, 0.0)]);
}

#[test]
fn weights_are_normalised_and_reported() {
    let (w, normalised) = SkinWeights::from_rows(vec![vec![(0, 0.5), (1, 0.3)], vec![(1, 1.0)]], 2).unwrap();
    assert_eq!(normalised.len(), 1);
    assert_eq!(normalised[0].vertex, 0);
    assert!((w.weight(0, 0) - 0.625).abs() < 1e-6);
    assert!((w.weight(0, 1) - 0.375).abs() < 1e-6);
    assert!(matches!(SkinWeights::from_rows(vec![vec![(0, 0.0)]], 1), Err(RigError::NoInfluence { vertex: 0 })));
    assert!(matches!(SkinWeights::from_rows(vec![vec![(3, 1.0)]], 2), Err(RigError::InfluenceJointOutOfRange { .. })));
    assert!(matches!(SkinWeights::from_rows(vec![vec![(0, -1.0), (1, 2.0)]], 2), Err(RigError::BadWeight { .. })));
}

#[test]
fn skinning_at_the_bind_pose_returns_the_input() {
    let s = chain();
    let bind = bind_world_to_joint(&s, None);
    let mut current = vec![Mat4::IDENTITY; 4];
    forward_kinematics(&s, &s.rest_pose(), Mat4::IDENTITY, &mut current);
    let mut palette = vec![Mat4::IDENTITY; 4];
    skinning_palette(&current, &bind, &mut palette);
    let verts: Vec<Vec3> = (0..20).map(|i| Vec3::new(i as f32 * 0.1, (i * 7 % 5) as f32, (i % 3) as f32)).collect();
    let weights = SkinWeights::from_rows((0..20).map(|i| vec![(i % 4, 0.25), ((i + 1) % 4, 0.75)]), 4).unwrap().0;
    let mut out = vec![Vec3::ZERO; 20];
    skin_positions(&verts, &weights, &palette, &mut out);
    for (a, b) in verts.iter().zip(&out) {
        assert_vec_close(*a, *b, 1e-5);
    }
}

#[test]
fn flat_shading_unshares_vertices_with_one_unit_normal_per_triangle() {
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 1.0)];
    let triangles = [[0, 1, 2], [1, 3, 2]];
    let mut out_p = [[0.0; 3]; 6];
    let mut out_n = [[0.0; 3]; 6];
    flat_shade(&positions, &triangles, &mut out_p, &mut out_n);
    assert_eq!(out_p[3], [1.0, 0.0, 0.0]);
    assert_eq!(out_p[4], [1.0, 1.0, 1.0]);
    for n in &out_n[..3] {
        assert_eq!(*n, [0.0, 0.0, 1.0]);
    }
    let n = Vec3::from(out_n[3]);
    assert!((n.length() - 1.0).abs() < 1e-6);
    assert_eq!(out_n[3], out_n[4]);
    assert_eq!(out_n[4], out_n[5]);
    // Perpendicular to the triangle's edges.
    assert!(n.dot(Vec3::new(0.0, 1.0, 1.0)).abs() < 1e-6 && n.dot(Vec3::new(-1.0, 1.0, 0.0)).abs() < 1e-6);
}

#[test]
fn weight_colours_are_distinct_per_joint_and_blended() {
    let colors = joint_colors(18);
    for i in 0..18 {
        for j in 0..i {
            let d = Vec3::from(colors[i]).distance(Vec3::from(colors[j]));
            assert!(d > 0.05, "joints {i} and {j} have nearly the same colour");
        }
    }
    let mut out = [[0.0; 3]; 3];
    weight_colors(&two_bone_weights(), &colors[..2], &mut out);
    assert_eq!(out[0], colors[0]);
    let mid = (Vec3::from(colors[0]) + Vec3::from(colors[1])) / 2.0;
    assert_vec_close(Vec3::from(out[1]), mid, 1e-6);
}

#[test]
fn quaternion_poses_drive_fk_like_euler_poses() {
    let s = chain();
    let euler: Vec<JointRotation> = (0..4).map(|i| JointRotation::euler_xyz(0.1 * i as f32, -0.2, 0.3)).collect();
    let quats: Vec<JointRotation> = euler.iter().map(|r| JointRotation::Quat(r.to_quat())).collect();
    let (mut a, mut b) = (vec![Mat4::IDENTITY; 4], vec![Mat4::IDENTITY; 4]);
    forward_kinematics(&s, &euler, Mat4::IDENTITY, &mut a);
    forward_kinematics(&s, &quats, Mat4::IDENTITY, &mut b);
    for j in 0..4 {
        assert_mat_close(a[j], b[j], 1e-5);
    }
    let q = Quat::from_rotation_y(0.5);
    assert_eq!(JointRotation::Quat(q).with_rotation_of(Quat::IDENTITY), JointRotation::Quat(Quat::IDENTITY));
}

fn assert_mat_close(a: Mat4, b: Mat4, tol: f32) {
    let (a, b) = (a.to_cols_array(), b.to_cols_array());
    for k in 0..16 {
        assert!((a[k] - b[k]).abs() <= tol, "matrices differ at {k}: {a:?} vs {b:?}");
    }
}

fn assert_vec_close(a: Vec3, b: Vec3, tol: f32) {
    assert!(a.distance(b) <= tol, "{a} vs {b} (distance {})", a.distance(b));
}

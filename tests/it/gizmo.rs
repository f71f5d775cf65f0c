//! The rotation gizmo's math without a window: each DOF's axis, a ring drag from one angle
//! to another, limits, the trackball, typing, and where a ray meets a ring.

use std::f32::consts::{FRAC_PI_2, PI};

use bevy::math::{Dir3, Ray3d};
use glam::{Quat, Vec3};
use marionette::editor::interact::rotate_gizmo::{Grip, Turn, angle_on_ring};
use marionette::formats::scene::CharacterId;
use marionette::rig::turn::{dof_angles, dof_axes, turn_dof, turn_freely, wrap_angle};
use marionette::rig::{DofLimits, EulerOrder, JointRotation};

const ORDERS: [EulerOrder; 6] =
    [EulerOrder::Xyz, EulerOrder::Xzy, EulerOrder::Yxz, EulerOrder::Yzx, EulerOrder::Zxy, EulerOrder::Zyx];

fn close(a: glam::Mat3, b: glam::Mat3) -> bool {
    (a - b).to_cols_array().iter().all(|d| d.abs() < 1e-5)
}

fn ring(start: JointRotation, limits: DofLimits, axis: usize, at: f32) -> Turn {
    let grip = Grip::Ring { axis, normal: Vec3::Z, across: Vec3::X, last: at, turned: 0.0 };
    Turn { character: CharacterId(1), joint: 3, start, limits, grip }
}

#[test]
fn turning_about_a_dofs_axis_is_adding_to_that_angle_in_every_order() {
    let angles = Vec3::new(0.4, -0.7, 1.1);
    for order in ORDERS {
        let rotation = JointRotation::Euler(angles, order);
        let axes = dof_axes(&rotation);
        for (axis, &direction) in axes.iter().enumerate() {
            assert!((direction.length() - 1.0).abs() < 1e-6);
            let delta = 0.3;
            let mut moved = angles;
            moved[axis] += delta;
            let by_axis = glam::Mat3::from_quat(Quat::from_axis_angle(direction, delta)) * rotation.to_mat3();
            assert!(close(by_axis, JointRotation::Euler(moved, order).to_mat3()), "{order:?} axis {axis}");
        }
    }
}

#[test]
fn a_ring_drag_from_a_to_b_changes_that_dof_by_b_minus_a_wrapped_and_leaves_the_others() {
    let start = JointRotation::euler_xyz(0.1, 0.2, 0.3);
    for (a, b) in [(0.5f32, 1.25f32), (3.0, -3.0), (-3.0, 3.0), (1.0, 1.0 - 0.4)] {
        for axis in 0..3 {
            let mut turn = ring(start, DofLimits::UNLIMITED, axis, a);
            turn.ring_to(b);
            let (after, _) = dof_angles(&turn.rotation());
            let (before, _) = dof_angles(&start);
            let expected = wrap_angle(b - a);
            assert!(expected.abs() < PI);
            assert!((wrap_angle(after[axis] - before[axis]) - expected).abs() < 1e-6, "{a} → {b} on {axis}");
            for other in (0..3).filter(|&o| o != axis) {
                assert_eq!(after[other], before[other], "the other DOFs stay exactly");
            }
        }
    }
    // Across the seam (3.0 → −3.0) the short way: +0.283, not −6.
    let mut turn = ring(start, DofLimits::UNLIMITED, 2, 3.0);
    turn.ring_to(-3.0);
    assert!((dof_angles(&turn.rotation()).0.z - (0.3 + 2.0 * PI - 6.0)).abs() < 1e-5);
}

#[test]
fn a_ring_drag_adds_up_over_frames_and_several_turns() {
    let start = JointRotation::euler_xyz(0.0, 0.0, 0.0);
    let mut turn = ring(start, DofLimits::UNLIMITED, 0, 0.0);
    // A full turn and a quarter in small steps comes back a quarter turn on.
    for k in 1..=50 {
        turn.ring_to(wrap_angle(k as f32 * (2.5 * PI) / 50.0));
    }
    let Grip::Ring { turned, .. } = turn.grip else { unreachable!() };
    assert!((turned - 2.5 * PI).abs() < 1e-4, "{turned}");
    assert!((dof_angles(&turn.rotation()).0.x - FRAC_PI_2).abs() < 1e-4);
}

#[test]
fn a_ring_drag_stops_at_the_limits() {
    let limits = DofLimits { min: Vec3::new(-0.5, -1.0, 0.0), max: Vec3::new(0.5, 1.0, 0.0) };
    let start = JointRotation::euler_xyz(0.2, 0.0, 0.0);
    let mut turn = ring(start, limits, 0, 0.0);
    turn.ring_to(1.0);
    assert_eq!(dof_angles(&turn.rotation()).0, Vec3::new(0.5, 0.0, 0.0), "stops at the maximum");
    turn.ring_to(-0.9);
    assert_eq!(dof_angles(&turn.rotation()).0, Vec3::new(-0.5, 0.0, 0.0), "and at the minimum");
    turn.ring_to(0.0);
    assert!((dof_angles(&turn.rotation()).0.x - 0.2).abs() < 1e-6, "and comes back");
    // A quaternion joint with limits keeps to them too.
    let q = JointRotation::Quat(Quat::from_rotation_y(0.8));
    let (angles, _) = dof_angles(&turn_dof(&q, &limits, 1, 0.6));
    assert!((angles.y - 1.0).abs() < 1e-5, "{angles}");
}

#[test]
fn cancelling_and_a_zero_turn_restore_the_start_exactly() {
    for start in [JointRotation::euler_xyz(0.1, -0.2, 0.7), JointRotation::Quat(Quat::from_rotation_z(0.4))] {
        let mut turn = ring(start, DofLimits::UNLIMITED, 1, 0.3);
        turn.ring_to(1.2);
        assert_ne!(turn.rotation(), start);
        turn.ring_to(0.3);
        assert!(close(turn.rotation().to_mat3(), start.to_mat3()), "back where it began");
        let typed = Turn { grip: Grip::Typed { axis: Some(0), text: String::new() }, ..turn.clone() };
        assert_eq!(typed.rotation(), start, "nothing typed is no turn");
        let trackball = Turn { grip: Grip::Trackball { turned: Quat::IDENTITY }, ..turn };
        assert!(close(trackball.rotation().to_mat3(), start.to_mat3()));
    }
}

#[test]
fn a_quaternion_joint_turns_about_the_same_axes_as_its_sliders() {
    let q = Quat::from_euler(glam::EulerRot::ZYX, 0.3, -0.4, 0.5);
    let rotation = JointRotation::Quat(q);
    let (angles, _) = dof_angles(&rotation);
    for axis in 0..3 {
        let mut moved = angles;
        moved[axis] += 0.25;
        let by_slider = JointRotation::Euler(moved, EulerOrder::Xyz).to_mat3();
        let by_ring = turn_dof(&rotation, &DofLimits::UNLIMITED, axis, 0.25).to_mat3();
        assert!(close(by_ring, by_slider), "axis {axis}");
    }
}

#[test]
fn typing_r_x_30_turns_by_30_degrees() {
    let start = JointRotation::euler_xyz(0.1, 0.0, 0.0);
    let turn = Turn {
        character: CharacterId(1),
        joint: 0,
        start,
        limits: DofLimits::UNLIMITED,
        grip: Grip::Typed { axis: Some(0), text: "-30".into() },
    };
    assert!((dof_angles(&turn.rotation()).0.x - (0.1 - 30f32.to_radians())).abs() < 1e-6);
    let bad = Turn { grip: Grip::Typed { axis: Some(0), text: "-".into() }, ..turn };
    assert_eq!(bad.rotation(), start, "a number not yet typed is no turn");
}

#[test]
fn the_trackball_turns_freely_and_keeps_an_euler_joint_s_order() {
    let start = JointRotation::Euler(Vec3::new(0.2, 0.1, -0.3), EulerOrder::Zyx);
    let roll = Quat::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.7);
    let turned = turn_freely(&start, &DofLimits::UNLIMITED, roll);
    assert!(matches!(turned, JointRotation::Euler(_, EulerOrder::Zyx)));
    assert!(close(turned.to_mat3(), glam::Mat3::from_quat(roll) * start.to_mat3()));
    let limits = DofLimits { min: Vec3::splat(-0.1), max: Vec3::splat(0.1) };
    let (clamped, _) = dof_angles(&turn_freely(&start, &limits, roll));
    assert!(clamped.abs().max_element() <= 0.1 + 1e-6, "held within the limits: {clamped}");
}

#[test]
fn a_ray_meets_a_ring_at_the_angle_of_the_point_it_hits() {
    let (center, normal, across) = (Vec3::new(1.0, 2.0, 3.0), Vec3::Y, Vec3::X);
    for angle in [0.0f32, 0.7, 2.0, -2.5] {
        // Right-handed about +y from +x: the point at angle a is (cos a, 0, −sin a).
        let target = center + Vec3::new(angle.cos(), 0.0, -angle.sin()) * 0.5;
        let origin = target + Vec3::new(0.3, 4.0, 0.2);
        let ray = Ray3d::new(origin, Dir3::new(target - origin).unwrap());
        let got = angle_on_ring(center, normal, across, ray).unwrap();
        assert!((wrap_angle(got - angle)).abs() < 1e-5, "{angle} → {got}");
    }
    let along = Ray3d::new(center + Vec3::Y, Dir3::X);
    assert_eq!(angle_on_ring(center, normal, across, along), None, "a ray along the plane meets it nowhere");
}

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

mod moving {
    //! The move gizmo's math: a drag along an arrow or on the ground square moves by what
    //! the cursor's rays say, the ring turns about the vertical, Ctrl snaps to the grid and
    //! Shift to the floor, typed moves are exact; a drag's edits are one undo step.

    use bevy::math::{Dir3, Ray3d};
    use glam::Vec3;
    use marionette::editor::interact::move_gizmo::{GRID_STEP, Move, MoveGrip, Snap, along_axis, on_ground};
    use marionette::formats::scene::{CharacterId, PlacementDoc};

    /// A ray from a camera-ish eye through `target`.
    fn ray_to(target: Vec3) -> Ray3d {
        let eye = Vec3::new(1.2, 2.5, 4.0);
        Ray3d::new(eye, Dir3::new(target - eye).unwrap())
    }

    fn start() -> PlacementDoc {
        PlacementDoc::new(Vec3::new(0.43, 0.0, -1.27), 0.3, 1.2)
    }

    #[test]
    fn an_arrow_drag_moves_along_its_axis_by_the_cursor_s_travel() {
        let s = start();
        for axis in 0..3 {
            let along = Vec3::AXES[axis];
            let from = along_axis(s.translation, along, ray_to(s.translation + along * 0.2)).unwrap();
            assert!((from - 0.2).abs() < 1e-5);
            let mut drag = Move::new(CharacterId(1), s, MoveGrip::Axis { axis, from });
            for k in 1..=3 {
                drag.follow(ray_to(s.translation + along * (0.2 + 0.35 * k as f32)));
            }
            // A ray that runs along the axis moves nothing further.
            drag.follow(Ray3d::new(s.translation + along * 9.0, Dir3::new(-along).unwrap()));
            let moved = drag.placement(Snap::default()).translation - s.translation;
            assert!((moved - along * 1.05).length() < 1e-4, "axis {axis}: {moved}");
        }
    }

    #[test]
    fn a_square_drag_moves_in_the_ground_plane() {
        let s = start();
        let from = on_ground(0.0, ray_to(Vec3::new(0.5, 0.0, -1.2))).unwrap();
        let mut drag = Move::new(CharacterId(1), s, MoveGrip::Plane { height: 0.0, from });
        drag.follow(ray_to(Vec3::new(1.7, 0.0, -0.4)));
        let p = drag.placement(Snap::default());
        assert!((p.translation - (s.translation + Vec3::new(1.2, 0.0, 0.8))).length() < 1e-4, "{}", p.translation);
        assert_eq!((p.yaw, p.scale), (s.yaw, s.scale));
    }

    #[test]
    fn ctrl_snaps_to_the_grid_and_shift_stands_it_on_the_floor() {
        let s = start();
        let from = on_ground(0.0, ray_to(Vec3::new(0.5, 0.0, -1.2))).unwrap();
        let mut drag = Move::new(CharacterId(1), s, MoveGrip::Plane { height: 0.0, from });
        drag.follow(ray_to(Vec3::new(1.737, 0.0, -0.449)));
        let p = drag.placement(Snap { grid: true, floor: None });
        for v in [p.translation.x, p.translation.z] {
            assert!(((v / GRID_STEP).round() * GRID_STEP - v).abs() < 1e-5, "{v} is on the grid");
        }
        assert!((p.translation.x - 1.7).abs() < 1e-5 && (p.translation.z - (-0.5)).abs() < 1e-5, "{}", p.translation);
        // The lowest point 0.08 below the model's origin, scaled 1.2, on a floor at 0.25.
        let p = drag.placement(Snap { grid: false, floor: Some((0.25, -0.08)) });
        assert!((p.translation.y - (0.25 + 0.08 * 1.2)).abs() < 1e-6);
    }

    #[test]
    fn the_ring_turns_about_the_vertical_and_snaps_to_15_degrees() {
        let s = start();
        let at = |angle: f32| ray_to(s.translation + Vec3::new(angle.sin(), 0.0, angle.cos()) * 0.8);
        let mut drag = Move::new(CharacterId(1), s, MoveGrip::Turn { last: 0.1 });
        for k in 1..=10 {
            drag.follow(at(0.1 + 0.07 * k as f32));
        }
        let p = drag.placement(Snap::default());
        assert!((p.yaw - (s.yaw + 0.7)).abs() < 1e-4, "{}", p.yaw);
        assert_eq!(p.translation, s.translation);
        let snapped = drag.placement(Snap { grid: true, floor: None }).yaw.to_degrees();
        assert!((snapped / 15.0 - (snapped / 15.0).round()).abs() < 1e-3, "{snapped}");
    }

    #[test]
    fn typed_moves_and_turns_are_exact() {
        let s = start();
        let typed = |turn, axis, text: &str| {
            Move::new(CharacterId(1), s, MoveGrip::Typed { turn, axis, text: text.into() }).placement(Snap::default())
        };
        assert_eq!(typed(false, Some(0), "1.5").translation, s.translation + Vec3::new(1.5, 0.0, 0.0));
        assert_eq!(typed(false, Some(1), "-0.25").translation, s.translation + Vec3::new(0.0, -0.25, 0.0));
        assert!((typed(true, None, "90").yaw - (s.yaw + std::f32::consts::FRAC_PI_2)).abs() < 1e-6);
        assert_eq!(typed(false, Some(2), "").translation, s.translation, "nothing typed yet");
    }

    #[test]
    fn a_drag_s_placements_are_one_undo_step_that_restores_the_start_exactly() {
        use bevy::prelude::*;
        use marionette::editor::edits::commands::Edit;
        use marionette::editor::edits::history::{History, HistoryRequest};
        use marionette::scene::Placement;
        let mut app = crate::edits::scene_app();
        let doc = crate::editor::doc_with(marionette::formats::scene::SourceDoc::Embedded("puppet".into()), &[]);
        let mut doc = doc;
        doc.characters[0].id = Some(CharacterId(1));
        *app.world_mut().resource_mut::<marionette::editor::scene_doc::document::PendingScene>() =
            marionette::editor::scene_doc::document::PendingScene { doc: Some(doc), frame: false };
        app.update();
        app.update();
        let entity = crate::edits::entity(&app, 1);
        let s = app.world().get::<Placement>(entity).unwrap().0;
        let mut buttons = ButtonInput::<MouseButton>::default();
        buttons.press(MouseButton::Left);
        app.world_mut().insert_resource(buttons);
        // What follow_move pushes each frame of a drag along x by the cursor.
        let from = along_axis(s.translation, Vec3::X, ray_to(s.translation)).unwrap();
        let mut drag = Move::new(CharacterId(1), s, MoveGrip::Axis { axis: 0, from });
        for k in 1..=6 {
            drag.follow(ray_to(s.translation + Vec3::X * 0.1 * k as f32));
            let placement = drag.placement(Snap::default());
            crate::edits::edit(
                &mut app,
                Edit::from(marionette::editor::edits::kinds::Place { character: CharacterId(1), placement }),
            );
        }
        let moved = app.world().get::<Placement>(entity).unwrap().translation - s.translation;
        assert!((moved - Vec3::new(0.6, 0.0, 0.0)).length() < 1e-4, "{moved}");
        app.world_mut().resource_mut::<ButtonInput<MouseButton>>().release(MouseButton::Left);
        app.update();
        app.update();
        assert_eq!(app.world().resource::<History>().undo_steps(), 1, "the drag is one step");
        crate::edits::request(&mut app, HistoryRequest::Undo);
        assert_eq!(app.world().get::<Placement>(entity).unwrap().0, s, "undo: exactly where it stood");
    }
}

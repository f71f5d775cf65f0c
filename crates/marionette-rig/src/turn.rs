//! Turning one joint by hand: the axes its three angles turn about, and a turn about one
//! of them (or a free turn) within the joint's limits. What the rotation gizmo does, without
//! a window.
//!
//! A joint's rotation `R = R₃(a₃) · R₂(a₂) · R₁(a₁)` (first applied on the right) is
//! expressed in its parent's frame. Changing the last applied angle `a₃` by δ turns the
//! joint by δ about the parent's axis `e₃`; changing `a₂` turns it about `R₃ e₂`, and `a₁`
//! about `R₃ R₂ e₁`: `R₃ R₂(a₂+δ) R₁ = (R₃ R₂(δ) R₃⁻¹) R`. So each angle has one axis in
//! the parent's frame, and turning about that axis by δ is adding δ to that angle.

use glam::{Quat, Vec3};

use super::pose::{DofLimits, EulerOrder, JointRotation};

/// The Euler angles of `rotation` and their order: its own for Euler joints, x-y-z for
/// quaternion joints (the order their sliders show).
pub fn dof_angles(rotation: &JointRotation) -> (Vec3, EulerOrder) {
    match *rotation {
        JointRotation::Euler(a, order) => (a, order),
        JointRotation::Quat(_) => (rotation.to_euler(EulerOrder::Xyz), EulerOrder::Xyz),
    }
}

/// The axes (unit, in the parent's frame) that the x, y and z angles of `rotation` turn
/// the joint about: adding δ to angle k is turning the joint by δ about `axes[k]`.
pub fn dof_axes(rotation: &JointRotation) -> [Vec3; 3] {
    let (angles, order) = dof_angles(rotation);
    let [first, second, third] = order.axes();
    let unit = |axis: usize| Vec3::AXES[axis];
    let about = |axis: usize, angle: f32| Quat::from_axis_angle(unit(axis), angle);
    let mut axes = [Vec3::ZERO; 3];
    axes[third] = unit(third);
    axes[second] = about(third, angles[third]) * unit(second);
    axes[first] = about(third, angles[third]) * about(second, angles[second]) * unit(first);
    axes
}

/// `a` wrapped into (−π, π].
pub fn wrap_angle(a: f32) -> f32 {
    let tau = std::f32::consts::TAU;
    let w = a - tau * (a / tau).round();
    if w <= -std::f32::consts::PI { w + tau } else { w }
}

/// Whether axis `axis` may turn all the way round.
fn is_free(limits: &DofLimits, axis: usize) -> bool {
    limits.min[axis] <= -std::f32::consts::PI && limits.max[axis] >= std::f32::consts::PI
}

/// `rotation` with angle `axis` changed by `delta` (radians) and held within its limits;
/// the other two angles stay as they are. A free angle is kept within (−π, π].
pub fn turn_dof(rotation: &JointRotation, limits: &DofLimits, axis: usize, delta: f32) -> JointRotation {
    match *rotation {
        JointRotation::Euler(mut a, order) => {
            a[axis] = if is_free(limits, axis) {
                wrap_angle(a[axis] + delta)
            } else {
                (a[axis] + delta).max(limits.min[axis]).min(limits.max[axis])
            };
            JointRotation::Euler(a, order)
        }
        JointRotation::Quat(q) => {
            // The same turn, applied to the quaternion about the angle's axis: no trip
            // through Euler angles, which lose the other two near gimbal lock.
            let turned = JointRotation::Quat((Quat::from_axis_angle(dof_axes(rotation)[axis], delta) * q).normalize());
            turned.clamped(limits)
        }
    }
}

/// `rotation` turned freely by `turn` (a rotation in the parent's frame), held within the
/// limits; an Euler joint keeps its order.
pub fn turn_freely(rotation: &JointRotation, limits: &DofLimits, turn: Quat) -> JointRotation {
    let q = (turn * rotation.to_quat()).normalize();
    let turned = match *rotation {
        JointRotation::Euler(_, order) => JointRotation::Euler(JointRotation::Quat(q).to_euler(order), order),
        JointRotation::Quat(_) => JointRotation::Quat(q),
    };
    turned.clamped(limits)
}

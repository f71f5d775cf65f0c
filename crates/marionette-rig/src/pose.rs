//! Joint rotations (Euler angles with an explicit order, or quaternions) and DOF limits.

use glam::{EulerRot, Mat3, Mat4, Quat, Vec3};

/// The order in which a joint's three Euler angles are applied.
///
/// `Xyz` (the CSE169 and 6.837 convention) rotates about x first, then y, then z:
/// for column vectors `R = Rz(z) · Ry(y) · Rx(x)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum EulerOrder {
    #[default]
    Xyz,
    Xzy,
    Yxz,
    Yzx,
    Zxy,
    Zyx,
}

impl EulerOrder {
    /// Axes in application order (first applied first).
    pub fn axes(self) -> [usize; 3] {
        match self {
            EulerOrder::Xyz => [0, 1, 2],
            EulerOrder::Xzy => [0, 2, 1],
            EulerOrder::Yxz => [1, 0, 2],
            EulerOrder::Yzx => [1, 2, 0],
            EulerOrder::Zxy => [2, 0, 1],
            EulerOrder::Zyx => [2, 1, 0],
        }
    }

    /// glam's name for the same rotation (glam lists the axes outermost first).
    fn glam(self) -> EulerRot {
        match self {
            EulerOrder::Xyz => EulerRot::ZYX,
            EulerOrder::Xzy => EulerRot::YZX,
            EulerOrder::Yxz => EulerRot::ZXY,
            EulerOrder::Yzx => EulerRot::XZY,
            EulerOrder::Zxy => EulerRot::YXZ,
            EulerOrder::Zyx => EulerRot::XYZ,
        }
    }
}

/// Rotation matrix about one axis (0 = x, 1 = y, 2 = z).
fn axis_rotation(axis: usize, angle: f32) -> Mat3 {
    match axis {
        0 => Mat3::from_rotation_x(angle),
        1 => Mat3::from_rotation_y(angle),
        _ => Mat3::from_rotation_z(angle),
    }
}

/// Per-axis rotation limits in radians; `min == max` locks an axis.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DofLimits {
    pub min: Vec3,
    pub max: Vec3,
}

impl DofLimits {
    pub const UNLIMITED: Self = Self { min: Vec3::splat(f32::NEG_INFINITY), max: Vec3::splat(f32::INFINITY) };

    pub fn is_unlimited(&self) -> bool {
        self.min.cmple(Vec3::splat(-1e30)).all() && self.max.cmpge(Vec3::splat(1e30)).all()
    }

    /// Whether axis `axis` cannot move.
    pub fn is_locked(&self, axis: usize) -> bool {
        self.min[axis] >= self.max[axis]
    }

    /// Clamps Euler angles (radians) axis by axis.
    pub fn clamp(&self, angles: Vec3) -> Vec3 {
        // max() then min() so that a locked axis (min == max) lands exactly on it.
        angles.max(self.min).min(self.max)
    }

    /// The range to show for an axis: the limits, or ±π where unlimited.
    pub fn display_range(&self, axis: usize) -> (f32, f32) {
        let pi = std::f32::consts::PI;
        (self.min[axis].max(-pi), self.max[axis].min(pi))
    }
}

impl Default for DofLimits {
    fn default() -> Self {
        Self::UNLIMITED
    }
}

/// A joint's rotation relative to its parent: one type for both kinds of source data.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum JointRotation {
    /// Angles in radians about x, y and z, applied in `order`.
    Euler(Vec3, EulerOrder),
    /// A unit quaternion (SMPL, motion capture).
    Quat(Quat),
}

impl Default for JointRotation {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl JointRotation {
    pub const IDENTITY: Self = Self::Euler(Vec3::ZERO, EulerOrder::Xyz);

    /// Euler angles in the default order (x first, then y, then z).
    pub fn euler_xyz(x: f32, y: f32, z: f32) -> Self {
        Self::Euler(Vec3::new(x, y, z), EulerOrder::Xyz)
    }

    /// The rotation as a 3×3 matrix (column vectors).
    pub fn to_mat3(&self) -> Mat3 {
        match *self {
            JointRotation::Euler(a, order) => {
                let [first, second, third] = order.axes();
                axis_rotation(third, a[third]) * axis_rotation(second, a[second]) * axis_rotation(first, a[first])
            }
            JointRotation::Quat(q) => Mat3::from_quat(q.normalize()),
        }
    }

    pub fn to_quat(&self) -> Quat {
        match *self {
            JointRotation::Euler(..) => Quat::from_mat3(&self.to_mat3()).normalize(),
            JointRotation::Quat(q) => q.normalize(),
        }
    }

    /// Euler angles of this rotation in `order` (exact for Euler poses of that order).
    pub fn to_euler(&self, order: EulerOrder) -> Vec3 {
        match *self {
            JointRotation::Euler(a, o) if o == order => a,
            _ => {
                let (c, b, a) = self.to_quat().to_euler(order.glam());
                // glam returns the outermost angle first; put them back on their axes.
                let [first, second, third] = order.axes();
                let mut out = Vec3::ZERO;
                out[third] = c;
                out[second] = b;
                out[first] = a;
                out
            }
        }
    }

    /// The same rotation expressed like `self` (Euler stays Euler in its order).
    pub fn with_rotation_of(&self, q: Quat) -> Self {
        match *self {
            JointRotation::Euler(_, order) => JointRotation::Euler(JointRotation::Quat(q).to_euler(order), order),
            JointRotation::Quat(_) => JointRotation::Quat(q.normalize()),
        }
    }

    /// Clamped to the limits. Euler angles clamp per axis; a quaternion is clamped through
    /// its XYZ Euler angles, and only when the joint has limits.
    pub fn clamped(&self, limits: &DofLimits) -> Self {
        if limits.is_unlimited() {
            return *self;
        }
        match *self {
            JointRotation::Euler(a, order) => JointRotation::Euler(limits.clamp(a), order),
            JointRotation::Quat(_) => {
                let a = limits.clamp(self.to_euler(EulerOrder::Xyz));
                JointRotation::Quat(JointRotation::Euler(a, EulerOrder::Xyz).to_quat())
            }
        }
    }

    /// The joint's local transform: translate by its rest offset, then rotate
    /// (`T(offset) · R`, column vectors).
    pub fn local_transform(&self, rest_offset: Vec3) -> Mat4 {
        Mat4::from_mat3(self.to_mat3()).with_translation(rest_offset)
    }
}

trait WithTranslation {
    fn with_translation(self, t: Vec3) -> Self;
}

impl WithTranslation for Mat4 {
    fn with_translation(mut self, t: Vec3) -> Self {
        self.w_axis = t.extend(1.0);
        self
    }
}

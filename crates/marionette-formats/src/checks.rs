//! Checks of the numbers files hold, one place for each: the predicates every reader uses
//! (a matrix that can be inverted, a quaternion that can be normalised), and the documents'
//! checks whose errors name the field (`characters[0].placement.scale`).

use glam::{Mat4, Quat};

/// A matrix that can be inverted: finite, its determinant not (near) zero, its inverse
/// finite.
pub fn is_invertible(m: &Mat4) -> bool {
    m.is_finite() && m.determinant().abs() >= 1e-12 && m.inverse().is_finite()
}

/// A quaternion that normalises to a rotation: finite and not (near) zero (a zero or
/// overflowing quaternion normalises to NaN).
pub fn is_normalisable(q: Quat) -> bool {
    q.is_finite() && q.length_squared().is_finite() && q.length_squared() >= 1e-12
}

/// Every value finite.
pub fn finite(at: &str, values: &[f32]) -> Result<(), String> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(format!("{at}: expected a finite number, found {v}")),
        None => Ok(()),
    }
}

/// A positive finite number.
pub fn positive(at: &str, value: f32) -> Result<(), String> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(format!("{at}: expected a positive finite number, found {value}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn a_matrix_is_invertible_when_finite_and_not_singular() {
        assert!(is_invertible(&Mat4::IDENTITY));
        assert!(is_invertible(&Mat4::from_scale(Vec3::new(0.01, 2.0, -3.0))));
        assert!(!is_invertible(&Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0))));
        // Determinant 1e-15: singular to single precision.
        assert!(!is_invertible(&Mat4::from_scale(Vec3::splat(1e-5))));
        assert!(!is_invertible(&Mat4::from_translation(Vec3::new(f32::NAN, 0.0, 0.0))));
    }

    #[test]
    fn a_quaternion_is_normalisable_when_finite_and_not_zero() {
        assert!(is_normalisable(Quat::IDENTITY));
        assert!(is_normalisable(Quat::from_xyzw(0.0, 0.0, 0.0, 1e-3)));
        assert!(!is_normalisable(Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)));
        assert!(!is_normalisable(Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0)));
        // Its squared length overflows: it would normalise to NaN.
        assert!(!is_normalisable(Quat::from_xyzw(1e30, 0.0, 0.0, 1e30)));
    }
}

//! Dual quaternion skinning (Kavan, Collins, Žára, O'Sullivan 2008). Each joint's rigid
//! palette transform becomes a unit dual quaternion. A vertex blends its influences'
//! dual quaternions linearly, after flipping each into the hemisphere of its heaviest
//! influence, normalises the blend and applies it. Unlike linear blend skinning, a twisted
//! or bent joint keeps its volume ("candy wrapper"). Rigid palettes only: a scale in a
//! palette matrix is dropped (see [`has_scale`]).

use glam::{Mat4, Quat, Vec3, Vec4};

use super::skinning::SkinWeights;

/// How a character's vertices follow its joints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize)]
pub enum SkinningMethod {
    /// Linear blend skinning: the weighted sum of the palette matrices.
    #[default]
    Linear,
    /// Dual quaternion skinning: the normalised weighted sum of unit dual quaternions.
    DualQuaternion,
}

impl SkinningMethod {
    pub fn is_linear(&self) -> bool {
        *self == SkinningMethod::Linear
    }
}

/// A rigid transform as a unit dual quaternion `real + ε dual`: rotation `real`,
/// translation `t` with `dual = ½ (t, 0) · real`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DualQuat {
    pub real: Vec4,
    pub dual: Vec4,
}

impl DualQuat {
    /// The rigid part of `m` (rotation and translation; a scale is dropped).
    pub fn from_rigid(m: &Mat4) -> Self {
        let (_, rotation, t) = m.to_scale_rotation_translation();
        let real = rotation.normalize();
        let dual = Quat::from_xyzw(t.x, t.y, t.z, 0.0) * real * 0.5;
        Self { real: Vec4::from(real), dual: Vec4::from(dual) }
    }

    /// Applies a (normalised) dual quaternion to a point: rotate, then translate by
    /// `2 · dual · conj(real)`.
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        let real = Quat::from_vec4(self.real);
        let t = Quat::from_vec4(self.dual) * real.conjugate() * 2.0;
        real * p + Vec3::new(t.x, t.y, t.z)
    }
}

/// Whether `m` scales (by more than 1e-3): dual quaternion skinning ignores it.
pub fn has_scale(m: &Mat4) -> bool {
    let (scale, ..) = m.to_scale_rotation_translation();
    (scale - Vec3::ONE).abs().max_element() > 1e-3
}

/// Each palette matrix as a dual quaternion (into a caller's buffer: no allocation once
/// it has grown).
pub fn dual_quaternion_palette(palette: &[Mat4], out: &mut Vec<DualQuat>) {
    out.clear();
    out.extend(palette.iter().map(DualQuat::from_rigid));
}

/// Skins bind-pose vertices with dual quaternions.
///
/// # Panics
/// When the lengths of `bind_positions`, `weights` and `out` differ, or an influence names
/// a joint beyond the palette.
pub fn skin_dq(bind_positions: &[Vec3], weights: &SkinWeights, palette: &[DualQuat], out: &mut [Vec3]) {
    assert_eq!(bind_positions.len(), weights.vertex_count(), "one weight row per vertex");
    assert_eq!(out.len(), bind_positions.len(), "one output per vertex");
    for (v, (p, o)) in bind_positions.iter().zip(out.iter_mut()).enumerate() {
        let row = weights.of_vertex(v);
        let Some(heaviest) = row.iter().max_by(|a, b| a.weight.total_cmp(&b.weight)) else { continue };
        let pivot = palette[heaviest.joint as usize].real;
        let (mut real, mut dual) = (Vec4::ZERO, Vec4::ZERO);
        for inf in row {
            let q = &palette[inf.joint as usize];
            // Into the heaviest influence's hemisphere: q and -q are the same rotation.
            let w = if q.real.dot(pivot) < 0.0 { -inf.weight } else { inf.weight };
            real += q.real * w;
            dual += q.dual * w;
        }
        let n = real.length();
        *o = DualQuat { real: real / n, dual: dual / n }.transform_point(*p);
    }
}

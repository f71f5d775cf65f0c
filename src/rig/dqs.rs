//! Dual quaternion skinning (Kavan, Collins, Žára, O'Sullivan 2008). Each joint's rigid
//! palette transform becomes a unit dual quaternion. A vertex blends its influences'
//! dual quaternions linearly, after flipping each into the hemisphere of its heaviest
//! influence, normalises the blend and applies it. Unlike linear blend skinning, a twisted
//! or bent joint keeps its volume ("candy wrapper"). Rigid palettes only: a scale in a
//! palette matrix is dropped (see [`has_scale`]).

use glam::{Mat4, Quat, Vec3, Vec4};

use super::lbs::FixedGroup;
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

/// Skins bind-pose vertices with dual quaternions (rows taken from the influence groups
/// the LBS kernel uses: fixed-size rows for up to four influences, the general rows beyond).
///
/// # Panics
/// When the lengths of `bind_positions`, `weights` and `out` differ, or an influence names
/// a joint beyond the palette.
pub fn skin_dq(bind_positions: &[Vec3], weights: &SkinWeights, palette: &[DualQuat], out: &mut [Vec3]) {
    assert_eq!(bind_positions.len(), weights.vertex_count(), "one weight row per vertex");
    assert_eq!(out.len(), bind_positions.len(), "one output per vertex");
    let groups = weights.groups();
    fixed_rows::<1>(bind_positions, &groups.fixed[0], palette, out);
    fixed_rows::<2>(bind_positions, &groups.fixed[1], palette, out);
    fixed_rows::<3>(bind_positions, &groups.fixed[2], palette, out);
    fixed_rows::<4>(bind_positions, &groups.fixed[3], palette, out);
    for &v in &groups.wide {
        let row = weights.of_vertex(v as usize);
        let joints: Vec<u16> = row.iter().map(|i| i.joint).collect();
        let w: Vec<f32> = row.iter().map(|i| i.weight).collect();
        out[v as usize] = blend_and_apply(&joints, &w, palette, bind_positions[v as usize]);
    }
}

fn fixed_rows<const K: usize>(bind: &[Vec3], group: &FixedGroup, palette: &[DualQuat], out: &mut [Vec3]) {
    let rows = group.joints.chunks_exact(K).zip(group.weights.chunks_exact(K));
    for (&v, (joints, weights)) in group.vertices.iter().zip(rows) {
        out[v as usize] = blend_and_apply(joints, weights, palette, bind[v as usize]);
    }
}

/// Blends one vertex's dual quaternions in its heaviest influence's hemisphere (q and -q
/// are the same rotation), normalises and applies the blend to `p`.
#[inline(always)]
fn blend_and_apply(joints: &[u16], weights: &[f32], palette: &[DualQuat], p: Vec3) -> Vec3 {
    let mut heaviest = 0;
    for k in 1..weights.len() {
        if weights[k] > weights[heaviest] {
            heaviest = k;
        }
    }
    let pivot = palette[joints[heaviest] as usize].real;
    let (mut real, mut dual) = (Vec4::ZERO, Vec4::ZERO);
    for (&j, &w) in joints.iter().zip(weights) {
        let q = &palette[j as usize];
        let w = if q.real.dot(pivot) < 0.0 { -w } else { w };
        real += q.real * w;
        dual += q.dual * w;
    }
    let inv = real.length_recip();
    let (real, dual) = (real * inv, dual * inv);
    // Rotation by the unit quaternion, then the translation 2 (w_r d - w_d r + r × d).
    let (r, d) = (real.truncate(), dual.truncate());
    let t = 2.0 * (real.w * d - dual.w * r + r.cross(d));
    Quat::from_vec4(real) * p + t
}

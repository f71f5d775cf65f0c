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
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        let groups = weights.groups();
        // SAFETY: the CPU has AVX2 and FMA (checked above).
        unsafe {
            avx2::fixed_rows::<1>(bind_positions, &groups.fixed[0], palette, out);
            avx2::fixed_rows::<2>(bind_positions, &groups.fixed[1], palette, out);
            avx2::fixed_rows::<3>(bind_positions, &groups.fixed[2], palette, out);
            avx2::fixed_rows::<4>(bind_positions, &groups.fixed[3], palette, out);
        }
        skin_wide(bind_positions, weights, palette, out);
        return;
    }
    skin_dq_portable(bind_positions, weights, palette, out);
}

/// [`skin_dq`] without the AVX2 path (what other CPUs run; the SIMD path's oracle).
///
/// # Panics
/// As [`skin_dq`].
pub fn skin_dq_portable(bind_positions: &[Vec3], weights: &SkinWeights, palette: &[DualQuat], out: &mut [Vec3]) {
    assert_eq!(bind_positions.len(), weights.vertex_count(), "one weight row per vertex");
    assert_eq!(out.len(), bind_positions.len(), "one output per vertex");
    let groups = weights.groups();
    fixed_rows::<1>(bind_positions, &groups.fixed[0], palette, out);
    fixed_rows::<2>(bind_positions, &groups.fixed[1], palette, out);
    fixed_rows::<3>(bind_positions, &groups.fixed[2], palette, out);
    fixed_rows::<4>(bind_positions, &groups.fixed[3], palette, out);
    skin_wide(bind_positions, weights, palette, out);
}

/// Vertices with more than four influences.
fn skin_wide(bind_positions: &[Vec3], weights: &SkinWeights, palette: &[DualQuat], out: &mut [Vec3]) {
    for &v in &weights.groups().wide {
        let row = weights.of_vertex(v as usize).iter().map(|i| (i.joint, i.weight));
        out[v as usize] = blend_and_apply(row, palette, bind_positions[v as usize]);
    }
}

fn fixed_rows<const K: usize>(bind: &[Vec3], group: &FixedGroup, palette: &[DualQuat], out: &mut [Vec3]) {
    let rows = group.joints.chunks_exact(K).zip(group.weights.chunks_exact(K));
    for (&v, (joints, weights)) in group.vertices.iter().zip(rows) {
        let row = joints.iter().copied().zip(weights.iter().copied());
        out[v as usize] = blend_and_apply(row, palette, bind[v as usize]);
    }
}

/// Blends one vertex's dual quaternions in its heaviest influence's hemisphere (q and -q
/// are the same rotation), normalises and applies the blend to `p`.
#[inline(always)]
fn blend_and_apply(row: impl Iterator<Item = (u16, f32)> + Clone, palette: &[DualQuat], p: Vec3) -> Vec3 {
    // The first of the heaviest influences (as the SIMD path picks it).
    let heaviest = row.clone().fold(None, |best, (j, w)| match best {
        Some((_, bw)) if bw >= w => best,
        _ => Some((j, w)),
    });
    let Some((heaviest, _)) = heaviest else { return p };
    let pivot = palette[heaviest as usize].real;
    let (mut real, mut dual) = (Vec4::ZERO, Vec4::ZERO);
    for (j, w) in row {
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

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use glam::{Vec3, Vec4};

    use super::DualQuat;
    use crate::rig::lbs::FixedGroup;

    /// `a × b` of the xyz lanes (w: 0).
    /// `a · b` in every lane, by shuffles and adds (`dpps` is microcoded and slow on
    /// some CPUs, AMD's Zen among them).
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn dot(a: __m128, b: __m128) -> __m128 {
        let m = _mm_mul_ps(a, b);
        let pairs = _mm_add_ps(m, _mm_shuffle_ps::<0b10_11_00_01>(m, m));
        _mm_add_ps(pairs, _mm_shuffle_ps::<0b01_00_11_10>(pairs, pairs))
    }

    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn cross(a: __m128, b: __m128) -> __m128 {
        let a_yzx = _mm_shuffle_ps::<0b11_00_10_01>(a, a);
        let b_yzx = _mm_shuffle_ps::<0b11_00_10_01>(b, b);
        let c = _mm_fmsub_ps(a, b_yzx, _mm_mul_ps(a_yzx, b));
        _mm_shuffle_ps::<0b11_00_10_01>(c, c)
    }

    /// One fixed group, each vertex's blend and its application in 128-bit registers:
    /// hemisphere test by a broadcast dot product, the sign flipped into the weight,
    /// one reciprocal square root, rotation `v + 2w (r × v) + 2 r × (r × v)` and
    /// translation `2 (w_r d - w_d r + r × d)`.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA. (Indices are checked.)
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn fixed_rows<const K: usize>(
        bind: &[Vec3],
        group: &FixedGroup,
        palette: &[DualQuat],
        out: &mut [Vec3],
    ) {
        let rows = group.joints.chunks_exact(K).zip(group.weights.chunks_exact(K));
        let sign = _mm_set1_ps(-0.0);
        for (&v, (joints, weights)) in group.vertices.iter().zip(rows) {
            let (joints, weights): (&[u16; K], &[f32; K]) = (joints.try_into().unwrap(), weights.try_into().unwrap());
            // Rows are stored heaviest first (`InfluenceGroups::build`): no search, no branch.
            let pivot: __m128 = palette[joints[0] as usize].real.into();
            let (mut real, mut dual) = (_mm_setzero_ps(), _mm_setzero_ps());
            for k in 0..K {
                let q = &palette[joints[k] as usize];
                let (qr, qd): (__m128, __m128) = (q.real.into(), q.dual.into());
                // The weight takes the sign of dot(q.real, pivot): q and -q are one rotation.
                let dot = dot(qr, pivot);
                let w = _mm_xor_ps(_mm_set1_ps(weights[k]), _mm_and_ps(dot, sign));
                real = _mm_fmadd_ps(w, qr, real);
                dual = _mm_fmadd_ps(w, qd, dual);
            }
            // 1/|real| by the reciprocal square root estimate and one Newton step (about
            // 23 bits, the same as the division it replaces; a shorter chain of latency).
            let n2 = dot(real, real);
            let y = _mm_rsqrt_ps(n2);
            let inv =
                _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(0.5), y), _mm_fnmadd_ps(_mm_mul_ps(n2, y), y, _mm_set1_ps(3.0)));
            let (real, dual) = (_mm_mul_ps(real, inv), _mm_mul_ps(dual, inv));
            let wr = _mm_shuffle_ps::<0xFF>(real, real);
            let wd = _mm_shuffle_ps::<0xFF>(dual, dual);
            let b = bind[v as usize];
            let p = _mm_setr_ps(b.x, b.y, b.z, 0.0);
            let two = _mm_set1_ps(2.0);
            // t = r × p + w p; p' = p + 2 r × t; translation 2 (w_r d - w_d r + r × d).
            let t = _mm_fmadd_ps(wr, p, cross(real, p));
            let rotated = _mm_fmadd_ps(two, cross(real, t), p);
            let translation =
                _mm_mul_ps(two, _mm_add_ps(_mm_fmsub_ps(wr, dual, _mm_mul_ps(wd, real)), cross(real, dual)));
            out[v as usize] = Vec4::from(_mm_add_ps(rotated, translation)).truncate();
        }
    }
}

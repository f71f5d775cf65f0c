//! The fast linear-blend-skinning kernel. Vertices are grouped by influence count when the
//! weights are built (1, 2, 3 or 4 influences in fixed-size rows; more in a general
//! group); each vertex blends its palette matrices once (`M = Σ wᵢ Pᵢ`) and transforms its
//! bind position by `M`. On x86-64 with AVX2 and FMA (detected at run time) the blend is
//! fused multiply-adds on 256-bit registers (two columns of a matrix in each); elsewhere
//! glam's `Vec4` does it.
//! [`skin_positions`](super::skinning::skin_positions) stays as the plain oracle.

use glam::{Mat4, Vec3, Vec3A, Vec4};

use super::influences::FixedGroup;
use super::skinning::{Bounds, SkinWeights};

/// Skins bind-pose vertices: `out[v] = (Σ wᵢ · palette[jᵢ]) · bind[v]` (the same result as
/// the oracle up to rounding). No allocation.
///
/// # Panics
/// When the lengths of `bind_positions`, `weights` and `out` differ, or an influence names
/// a joint beyond the palette.
pub fn skin(bind_positions: &[Vec3], weights: &SkinWeights, palette: &[Mat4], out: &mut [Vec3]) {
    skin_bounded(bind_positions, weights, palette, out);
}

/// [`skin`], returning the box of the skinned vertices (exactly
/// [`bounds`](super::skinning::bounds) of `out`), grown as they are written.
///
/// # Panics
/// As [`skin`].
pub fn skin_bounded(bind_positions: &[Vec3], weights: &SkinWeights, palette: &[Mat4], out: &mut [Vec3]) -> Bounds {
    assert_eq!(out.len(), bind_positions.len(), "one output per vertex");
    skin_chunk(bind_positions, weights, palette, 0, out)
}

/// Skins the vertices `first..first + out.len()` into `out` (a large mesh is skinned in
/// chunks on several threads, each writing its own part of the output) and returns their
/// box.
///
/// # Panics
/// When `bind_positions` and `weights` differ in length, the chunk runs past the mesh, or
/// an influence names a joint beyond the palette.
pub fn skin_chunk(
    bind_positions: &[Vec3],
    weights: &SkinWeights,
    palette: &[Mat4],
    first: usize,
    out: &mut [Vec3],
) -> Bounds {
    assert_eq!(bind_positions.len(), weights.vertex_count(), "one weight row per vertex");
    assert!(first + out.len() <= bind_positions.len(), "the chunk lies inside the mesh");
    let groups = weights.groups();
    assert!(groups.joint_bound <= palette.len(), "an influence names a joint beyond the palette");
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU has AVX2 and FMA (checked above).
        return unsafe {
            avx2::skin_fixed::<1>(bind_positions, &groups.fixed[0], palette, first, out)
                .union(avx2::skin_fixed::<2>(bind_positions, &groups.fixed[1], palette, first, out))
                .union(avx2::skin_fixed::<3>(bind_positions, &groups.fixed[2], palette, first, out))
                .union(avx2::skin_fixed::<4>(bind_positions, &groups.fixed[3], palette, first, out))
                .union(avx2::skin_wide(bind_positions, weights, palette, first, out))
        };
    }
    skin_portable_chunk(bind_positions, weights, palette, first, out)
}

/// [`skin_bounded`] without the AVX2 path: glam's `Vec4` on any target (what other CPUs
/// run).
///
/// # Panics
/// As [`skin`].
pub fn skin_portable(bind_positions: &[Vec3], weights: &SkinWeights, palette: &[Mat4], out: &mut [Vec3]) -> Bounds {
    assert_eq!(bind_positions.len(), weights.vertex_count(), "one weight row per vertex");
    assert_eq!(out.len(), bind_positions.len(), "one output per vertex");
    skin_portable_chunk(bind_positions, weights, palette, 0, out)
}

fn skin_portable_chunk(
    bind: &[Vec3],
    weights: &SkinWeights,
    palette: &[Mat4],
    first: usize,
    out: &mut [Vec3],
) -> Bounds {
    let groups = weights.groups();
    skin_fixed_portable::<1>(bind, &groups.fixed[0], palette, first, out)
        .union(skin_fixed_portable::<2>(bind, &groups.fixed[1], palette, first, out))
        .union(skin_fixed_portable::<3>(bind, &groups.fixed[2], palette, first, out))
        .union(skin_fixed_portable::<4>(bind, &groups.fixed[3], palette, first, out))
        .union(skin_wide(bind, weights, &groups.wide, palette, first, out))
}

/// The rows of `group` whose vertices lie in `first..first + len` (vertices ascend).
fn rows_in<const K: usize>(group: &FixedGroup, first: usize, len: usize) -> (&[u32], &[u16], &[f32]) {
    let lo = group.vertices.partition_point(|&v| (v as usize) < first);
    let hi = group.vertices.partition_point(|&v| (v as usize) < first + len);
    (&group.vertices[lo..hi], &group.joints[lo * K..hi * K], &group.weights[lo * K..hi * K])
}

/// The vertices of `wide` that lie in `first..first + len` (vertices ascend).
fn wide_in(wide: &[u32], first: usize, len: usize) -> &[u32] {
    let lo = wide.partition_point(|&v| (v as usize) < first);
    let hi = wide.partition_point(|&v| (v as usize) < first + len);
    &wide[lo..hi]
}

/// The portable path of one fixed group: blend `K` matrices with glam's `Vec4`.
fn skin_fixed_portable<const K: usize>(
    bind: &[Vec3],
    group: &FixedGroup,
    palette: &[Mat4],
    first: usize,
    out: &mut [Vec3],
) -> Bounds {
    let (vertices, joints, weights) = rows_in::<K>(group, first, out.len());
    let mut bounds = Bounds::EMPTY;
    for (&v, (joints, weights)) in vertices.iter().zip(joints.chunks_exact(K).zip(weights.chunks_exact(K))) {
        let mut m = [Vec4::ZERO; 4];
        for (&j, &w) in joints.iter().zip(weights) {
            let p = &palette[j as usize];
            m[0] += p.x_axis * w;
            m[1] += p.y_axis * w;
            m[2] += p.z_axis * w;
            m[3] += p.w_axis * w;
        }
        let b = bind[v as usize];
        let p = Vec3A::from_vec4(m[0] * b.x + m[1] * b.y + m[2] * b.z + m[3]);
        bounds = bounds.with(p);
        out[v as usize - first] = p.into();
    }
    bounds
}

/// Vertices with more than four influences, blended the same way from the compressed rows.
fn skin_wide(
    bind: &[Vec3],
    weights: &SkinWeights,
    wide: &[u32],
    palette: &[Mat4],
    first: usize,
    out: &mut [Vec3],
) -> Bounds {
    let mut bounds = Bounds::EMPTY;
    for &v in wide_in(wide, first, out.len()) {
        let mut m = Mat4::ZERO;
        for inf in weights.of_vertex(v as usize) {
            let p = &palette[inf.joint as usize];
            m.x_axis += p.x_axis * inf.weight;
            m.y_axis += p.y_axis * inf.weight;
            m.z_axis += p.z_axis * inf.weight;
            m.w_axis += p.w_axis * inf.weight;
        }
        let p = m.transform_point3(bind[v as usize]);
        bounds = bounds.with(p.into());
        out[v as usize - first] = p;
    }
    bounds
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use glam::{Mat4, Vec3, Vec3A, Vec4};

    use super::FixedGroup;
    use crate::rig::skinning::{Bounds, Influence, SkinWeights};

    /// One fixed group with FMA on 256-bit registers: a palette matrix is two of them
    /// (columns 0 and 1, columns 2 and 3), so a blend of `K` matrices is `2K` multiply-adds,
    /// and the blended matrix transforms the bind position with one more multiply-add and
    /// one add of the register's halves.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA. (Indices are checked: a joint beyond the palette or a
    /// vertex beyond the buffers panics.)
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn skin_fixed<const K: usize>(
        bind: &[Vec3],
        group: &FixedGroup,
        palette: &[Mat4],
        first: usize,
        out: &mut [Vec3],
    ) -> Bounds {
        let (vertices, joints, weights) = super::rows_in::<K>(group, first, out.len());
        let rows = joints.chunks_exact(K).zip(weights.chunks_exact(K));
        let mut bounds = Bounds::EMPTY;
        for (&v, (joints, weights)) in vertices.iter().zip(rows) {
            let (joints, weights): (&[u16; K], &[f32; K]) = (joints.try_into().unwrap(), weights.try_into().unwrap());
            // Two accumulators per half (even and odd influences) halve the chain of
            // dependent multiply-adds.
            let mut c = [[_mm256_setzero_ps(); 2]; 2];
            for k in 0..K {
                let (c01, c23) = columns(&palette[joints[k] as usize]);
                let w = _mm256_set1_ps(weights[k]);
                let acc = &mut c[k % 2];
                acc[0] = _mm256_fmadd_ps(w, c01, acc[0]);
                acc[1] = _mm256_fmadd_ps(w, c23, acc[1]);
            }
            let (c01, c23) = (_mm256_add_ps(c[0][0], c[1][0]), _mm256_add_ps(c[0][1], c[1][1]));
            let p = transform(c01, c23, bind[v as usize]);
            bounds = bounds.with(p);
            out[v as usize - first] = p.into();
        }
        bounds
    }

    /// The vertices with more than four influences, blended as in [`skin_fixed`] from their
    /// compressed rows.
    ///
    /// # Safety
    /// As [`skin_fixed`].
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn skin_wide(
        bind: &[Vec3],
        weights: &SkinWeights,
        palette: &[Mat4],
        first: usize,
        out: &mut [Vec3],
    ) -> Bounds {
        let mut bounds = Bounds::EMPTY;
        for &v in super::wide_in(&weights.groups().wide, first, out.len()) {
            let row = weights.of_vertex(v as usize);
            let term = |i: &Influence| {
                let (c01, c23) = columns(&palette[i.joint as usize]);
                (_mm256_set1_ps(i.weight), c01, c23)
            };
            // Even and odd influences in their own sums, as in `skin_fixed`.
            let (mut even, mut odd) = ([_mm256_setzero_ps(); 2], [_mm256_setzero_ps(); 2]);
            let pairs = row.chunks_exact(2);
            if let [last] = pairs.remainder() {
                let (w, c01, c23) = term(last);
                even = [_mm256_mul_ps(w, c01), _mm256_mul_ps(w, c23)];
            }
            for pair in pairs {
                let ((w0, a01, a23), (w1, b01, b23)) = (term(&pair[0]), term(&pair[1]));
                even = [_mm256_fmadd_ps(w0, a01, even[0]), _mm256_fmadd_ps(w0, a23, even[1])];
                odd = [_mm256_fmadd_ps(w1, b01, odd[0]), _mm256_fmadd_ps(w1, b23, odd[1])];
            }
            let (c01, c23) = (_mm256_add_ps(even[0], odd[0]), _mm256_add_ps(even[1], odd[1]));
            let p = transform(c01, c23, bind[v as usize]);
            bounds = bounds.with(p);
            out[v as usize - first] = p.into();
        }
        bounds
    }

    /// A palette matrix as two registers: columns 0 and 1, columns 2 and 3.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn columns(m: &Mat4) -> (__m256, __m256) {
        (_mm256_set_m128(m.y_axis.into(), m.x_axis.into()), _mm256_set_m128(m.w_axis.into(), m.z_axis.into()))
    }

    /// A blended matrix (as [`columns`] gives it) applied to a bind position: one
    /// multiply-add and one add of the register's halves.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn transform(c01: __m256, c23: __m256, b: Vec3) -> Vec3A {
        let xy = _mm256_set_m128(_mm_set1_ps(b.y), _mm_set1_ps(b.x));
        let z1 = _mm256_set_m128(_mm_set1_ps(1.0), _mm_set1_ps(b.z));
        let p = _mm256_fmadd_ps(c01, xy, _mm256_mul_ps(c23, z1));
        let p = _mm_add_ps(_mm256_castps256_ps128(p), _mm256_extractf128_ps::<1>(p));
        Vec3A::from_vec4(Vec4::from(p))
    }
}

//! The fast linear-blend-skinning kernel. On x86-64 with AVX2 and FMA (detected at run
//! time), the vertices are skinned in blocks of eight consecutive ones ([`LaneBlocks`],
//! built with the weights), one vertex a lane of a 256-bit register: each
//! of a block's joints transforms all eight bind positions at once, weighted lane by lane
//! (`pᵥ = Σⱼ wᵥⱼ (Pⱼ bᵥ)`), so a joint's matrix is read once for eight vertices. Elsewhere
//! each vertex blends its own matrices with glam's `Vec4`, grouped by influence count.
//! With AVX-512 F, the blocks are sixteen vertices wide
//! ([`WideLaneBlocks`](super::influences::WideLaneBlocks)) on 512-bit registers: a joint's
//! multiply-adds serve twice the vertices, and the pair of blocks of eight they replace
//! share most joints (SMPL: 37 % fewer multiply-adds). [`Simd`] names the levels; the
//! `_using` entry points run any level the CPU has.
//! [`skin_positions`](super::skinning::skin_positions) stays as the plain oracle.

use glam::{Mat4, Vec3, Vec3A, Vec4};

use super::influences::{FixedGroup, LaneBlocks};
use super::simd::Simd;
pub use super::skinning::Normals;
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
    skin_using(Simd::best(), bind_positions, weights, palette, out)
}

/// Skins the vertices `first..first + out.len()` into `out` (a large mesh is skinned in
/// chunks on several threads, each writing its own part of the output) and returns their
/// box. (Chunks that start and end on multiples of eight are the fastest.)
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
    skin_chunk_using(Simd::best(), bind_positions, weights, palette, first, out)
}

/// [`skin_bounded`] at a given level of the kernel (the tests run each the CPU has).
///
/// # Panics
/// As [`skin`], or when the CPU does not run `simd`.
pub fn skin_using(
    simd: Simd,
    bind_positions: &[Vec3],
    weights: &SkinWeights,
    palette: &[Mat4],
    out: &mut [Vec3],
) -> Bounds {
    assert_lengths(bind_positions, weights, out, None);
    skin_chunk_using(simd, bind_positions, weights, palette, 0, out)
}

/// [`skin_chunk`] at a given level of the kernel.
///
/// # Panics
/// As [`skin_chunk`], or when the CPU does not run `simd`.
pub fn skin_chunk_using(
    simd: Simd,
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
    assert!(simd.is_available(), "this CPU does not run {simd:?}");
    #[cfg(target_arch = "x86_64")]
    match simd {
        // SAFETY: the CPU runs `simd` (checked above).
        Simd::Avx512Vl => {
            return unsafe { avx512::skin_blocks(bind_positions, &groups.wide_blocks, palette, first, out) };
        }
        // SAFETY: as above.
        Simd::Avx2 => return unsafe { avx2::skin_blocks(bind_positions, &groups.blocks, palette, first, out) },
        Simd::Portable => {}
    }
    skin_portable_chunk(bind_positions, weights, palette, first, out, None)
}

/// [`skin_bounded`] with the normals: both from one blend of each vertex's matrices.
///
/// # Panics
/// As [`skin`], or when the normals' lengths differ from the positions'.
pub fn skin_with_normals(
    bind_positions: &[Vec3],
    weights: &SkinWeights,
    palette: &[Mat4],
    out: &mut [Vec3],
    normals: Normals,
) -> Bounds {
    skin_with_normals_using(Simd::best(), bind_positions, weights, palette, out, normals)
}

/// [`skin_with_normals`] at a given level of the kernel.
///
/// # Panics
/// As [`skin_with_normals`], or when the CPU does not run `simd`.
pub fn skin_with_normals_using(
    simd: Simd,
    bind_positions: &[Vec3],
    weights: &SkinWeights,
    palette: &[Mat4],
    out: &mut [Vec3],
    normals: Normals,
) -> Bounds {
    assert_lengths(bind_positions, weights, out, Some(&normals));
    let groups = weights.groups();
    assert!(groups.joint_bound <= palette.len(), "an influence names a joint beyond the palette");
    assert!(simd.is_available(), "this CPU does not run {simd:?}");
    #[cfg(target_arch = "x86_64")]
    match simd {
        // SAFETY: the CPU runs `simd` (checked above).
        Simd::Avx512Vl => {
            return unsafe {
                avx512::skin_blocks_with_normals(bind_positions, &groups.wide_blocks, palette, out, normals)
            };
        }
        // SAFETY: as above.
        Simd::Avx2 => {
            return unsafe { avx2::skin_blocks_with_normals(bind_positions, &groups.blocks, palette, out, normals) };
        }
        Simd::Portable => {}
    }
    skin_portable_chunk(bind_positions, weights, palette, 0, out, Some(normals))
}

/// What the whole-mesh entry points assert: one weight row, one output and (when given)
/// one normal in and one out per bind position.
fn assert_lengths(bind_positions: &[Vec3], weights: &SkinWeights, out: &[Vec3], normals: Option<&Normals>) {
    assert_eq!(bind_positions.len(), weights.vertex_count(), "one weight row per vertex");
    assert_eq!(out.len(), bind_positions.len(), "one output per vertex");
    if let Some(normals) = normals {
        assert!(normals.bind.len() == out.len() && normals.out.len() == out.len(), "one normal per vertex");
    }
}

/// The portable path: each vertex blends its matrices (`M = Σ wᵢ Pᵢ`) with glam's `Vec4`
/// and transforms its bind position by `M`. (Eight lanes in plain arrays spill 128-bit
/// registers: 71 µs a SMPL body against this path's 38.)
fn skin_portable_chunk(
    bind: &[Vec3],
    weights: &SkinWeights,
    palette: &[Mat4],
    first: usize,
    out: &mut [Vec3],
    mut normals: Option<Normals>,
) -> Bounds {
    let groups = weights.groups();
    let n = &mut normals;
    skin_fixed_portable::<1>(bind, &groups.fixed[0], palette, first, out, n)
        .union(skin_fixed_portable::<2>(bind, &groups.fixed[1], palette, first, out, n))
        .union(skin_fixed_portable::<3>(bind, &groups.fixed[2], palette, first, out, n))
        .union(skin_fixed_portable::<4>(bind, &groups.fixed[3], palette, first, out, n))
        .union(skin_wide(bind, weights, &groups.wide, palette, first, out, n))
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
    normals: &mut Option<Normals>,
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
        if let Some(normals) = normals {
            let n = normals.bind[v as usize];
            normals.out[v as usize - first] = (m[0] * n.x + m[1] * n.y + m[2] * n.z).truncate();
        }
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
    normals: &mut Option<Normals>,
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
        if let Some(normals) = normals {
            normals.out[v as usize - first] = m.transform_vector3(normals.bind[v as usize]);
        }
    }
    bounds
}

/// A palette matrix's twelve elements as a block reads them: element `e` is column `e / 3`,
/// row `e % 3` (the fourth row of an affine matrix is not needed).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn elements(m: &Mat4) -> [f32; 12] {
    let c = m.to_cols_array();
    std::array::from_fn(|e| c[e / 3 * 4 + e % 3])
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use glam::{Mat4, Vec3, Vec3A};

    use super::{LaneBlocks, Normals, elements};
    use crate::rig::avx2::{
        deinterleave, deinterleave_some, floats, interleave, lane_points, prefetch_ahead, register,
    };
    use crate::rig::influences::LANES;
    use crate::rig::skinning::Bounds;

    /// Each block on 256-bit registers, one vertex a lane: each of the block's joints
    /// transforms all eight bind positions (its matrix's elements broadcast once) and adds
    /// them in with each lane's weight; twelve multiply-adds a joint for eight vertices.
    /// Blocks that lie wholly in the chunk read and write their eight positions in order;
    /// the chunk's first and last blocks (when it does not start or end on a multiple of
    /// eight) and the mesh's last go lane by lane.
    ///
    /// (Indices are checked: a joint beyond the palette or a vertex beyond the buffers
    /// panics.)
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn skin_blocks(
        bind: &[Vec3],
        blocks: &LaneBlocks,
        palette: &[Mat4],
        first: usize,
        out: &mut [Vec3],
    ) -> Bounds {
        // SAFETY: the CPU has AVX2 and FMA (this function's contract).
        unsafe {
            let end = first + out.len();
            let (mut lo, mut hi) = ([_mm256_set1_ps(f32::INFINITY); 3], [_mm256_set1_ps(f32::NEG_INFINITY); 3]);
            let mut edges = Bounds::EMPTY;
            for b in first / LANES..end.div_ceil(LANES) {
                let lanes = b * LANES..(b + 1) * LANES;
                let whole = first <= lanes.start && lanes.end <= end;
                prefetch_ahead(bind, lanes.start, out, lanes.start.saturating_sub(first), LANES);
                let [x, y, z] = if whole {
                    deinterleave(&bind[lanes.clone()])
                } else {
                    deinterleave_some(&bind[lanes.start..lanes.end.min(bind.len())])
                };
                let mut p = [_mm256_setzero_ps(); 3];
                let joints = blocks.joint_starts[b] as usize..blocks.joint_starts[b + 1] as usize;
                for (&j, w) in blocks.joints[joints.clone()].iter().zip(&blocks.weights[joints]) {
                    let w = register(w.0);
                    let m = elements(&palette[j as usize]).map(|c| _mm256_set1_ps(c));
                    for (r, p) in p.iter_mut().enumerate() {
                        let row = _mm256_fmadd_ps(
                            m[r],
                            x,
                            _mm256_fmadd_ps(m[3 + r], y, _mm256_fmadd_ps(m[6 + r], z, m[9 + r])),
                        );
                        *p = _mm256_fmadd_ps(w, row, *p);
                    }
                }
                if whole {
                    for k in 0..3 {
                        (lo[k], hi[k]) = (_mm256_min_ps(lo[k], p[k]), _mm256_max_ps(hi[k], p[k]));
                    }
                    interleave(p, &mut out[lanes.start - first..lanes.end - first]);
                } else {
                    let lane = p.map(floats);
                    for (i, v) in lanes.enumerate().filter(|(_, v)| (first..end).contains(v)) {
                        let q = Vec3A::new(lane[0][i], lane[1][i], lane[2][i]);
                        out[v - first] = q.into();
                        edges = edges.with(q);
                    }
                }
            }
            lanes_bounds(lo, hi).union(edges)
        }
    }

    /// The box between eight lanes of lower and eight of upper corners.
    #[inline]
    fn lanes_bounds(lo: [__m256; 3], hi: [__m256; 3]) -> Bounds {
        let reduce = |r: __m256, f: fn(f32, f32) -> f32| floats(r).into_iter().reduce(f).unwrap_or(0.0);
        Bounds::between(
            Vec3A::new(reduce(lo[0], f32::min), reduce(lo[1], f32::min), reduce(lo[2], f32::min)),
            Vec3A::new(reduce(hi[0], f32::max), reduce(hi[1], f32::max), reduce(hi[2], f32::max)),
        )
    }

    /// [`skin_blocks`] of a whole mesh with its normals: each lane's matrix is blended
    /// first (`Σⱼ wⱼ Pⱼ`, twelve multiply-adds a joint for eight vertices), then turns the
    /// eight positions and the eight normals once. (Transforming by each joint, as
    /// `skin_blocks` does for positions alone, needs more registers than there are with the
    /// normals: 46 µs a SMPL body against this order's 22.)
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn skin_blocks_with_normals(
        bind: &[Vec3],
        blocks: &LaneBlocks,
        palette: &[Mat4],
        out: &mut [Vec3],
        normals: Normals,
    ) -> Bounds {
        // SAFETY: the CPU has AVX2 and FMA (this function's contract).
        unsafe {
            let n = bind.len();
            let (mut lo, mut hi) = ([_mm256_set1_ps(f32::INFINITY); 3], [_mm256_set1_ps(f32::NEG_INFINITY); 3]);
            let mut last = Bounds::EMPTY;
            for b in 0..n.div_ceil(LANES) {
                let lanes = b * LANES..(b + 1) * LANES;
                let mut m = [_mm256_setzero_ps(); 12];
                let joints = blocks.joint_starts[b] as usize..blocks.joint_starts[b + 1] as usize;
                for (&j, w) in blocks.joints[joints.clone()].iter().zip(&blocks.weights[joints]) {
                    let w = register(w.0);
                    for (m, e) in m.iter_mut().zip(elements(&palette[j as usize])) {
                        *m = _mm256_fmadd_ps(w, _mm256_set1_ps(e), *m);
                    }
                }
                let [x, y, z] = lane_points(bind, lanes.clone());
                let p: [__m256; 3] = std::array::from_fn(|r| {
                    _mm256_fmadd_ps(m[r], x, _mm256_fmadd_ps(m[3 + r], y, _mm256_fmadd_ps(m[6 + r], z, m[9 + r])))
                });
                let [x, y, z] = lane_points(normals.bind, lanes.clone());
                let normal: [__m256; 3] = std::array::from_fn(|r| {
                    _mm256_fmadd_ps(m[r], x, _mm256_fmadd_ps(m[3 + r], y, _mm256_mul_ps(m[6 + r], z)))
                });
                if lanes.end <= n {
                    for k in 0..3 {
                        (lo[k], hi[k]) = (_mm256_min_ps(lo[k], p[k]), _mm256_max_ps(hi[k], p[k]));
                    }
                    interleave(p, &mut out[lanes.clone()]);
                    interleave(normal, &mut normals.out[lanes]);
                } else {
                    let (p, normal) = (p.map(floats), normal.map(floats));
                    for (i, v) in lanes.take_while(|&v| v < n).enumerate() {
                        let q = Vec3A::new(p[0][i], p[1][i], p[2][i]);
                        (out[v], normals.out[v]) = (q.into(), Vec3::new(normal[0][i], normal[1][i], normal[2][i]));
                        last = last.with(q);
                    }
                }
            }
            lanes_bounds(lo, hi).union(last)
        }
    }
}

/// The AVX-512 kernels: [`avx2`]'s, sixteen vertices a block on 512-bit registers.
#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    use glam::{Mat4, Vec3, Vec3A};

    use super::{Normals, elements};
    use crate::rig::avx2::prefetch_ahead;
    use crate::rig::avx512::{deinterleave, deinterleave_some, floats, interleave, lane_points, register};
    use crate::rig::influences::{WIDE_LANES, WideLaneBlocks};
    use crate::rig::skinning::Bounds;

    /// [`super::avx2::skin_blocks`] sixteen vertices a block: each of the block's joints
    /// transforms the sixteen bind positions (its matrix's elements broadcast inside the
    /// multiply-adds) and adds them in with each lane's weight. Blocks wholly in the chunk
    /// read and write their positions in order; the chunk's edges and the mesh's last block
    /// go lane by lane.
    ///
    /// # Safety
    /// The CPU must have AVX-512 F, AVX2 and FMA.
    #[target_feature(enable = "avx512f,avx2,fma")]
    pub unsafe fn skin_blocks(
        bind: &[Vec3],
        blocks: &WideLaneBlocks,
        palette: &[Mat4],
        first: usize,
        out: &mut [Vec3],
    ) -> Bounds {
        let end = first + out.len();
        let (mut lo, mut hi) = ([_mm512_set1_ps(f32::INFINITY); 3], [_mm512_set1_ps(f32::NEG_INFINITY); 3]);
        let mut edges = Bounds::EMPTY;
        for b in first / WIDE_LANES..end.div_ceil(WIDE_LANES) {
            let lanes = b * WIDE_LANES..(b + 1) * WIDE_LANES;
            let whole = first <= lanes.start && lanes.end <= end;
            prefetch_ahead(bind, lanes.start, out, lanes.start.saturating_sub(first), WIDE_LANES);
            let [x, y, z] = if whole {
                // SAFETY: the CPU has AVX-512 F (this function's contract).
                unsafe { deinterleave(&bind[lanes.clone()]) }
            } else {
                deinterleave_some(&bind[lanes.start..lanes.end.min(bind.len())])
            };
            let mut p = [_mm512_setzero_ps(); 3];
            let joints = blocks.joint_starts[b] as usize..blocks.joint_starts[b + 1] as usize;
            for (&j, w) in blocks.joints[joints.clone()].iter().zip(&blocks.weights[joints]) {
                let w = register(w.0);
                let m = elements(&palette[j as usize]).map(|c| _mm512_set1_ps(c));
                for (r, p) in p.iter_mut().enumerate() {
                    let row =
                        _mm512_fmadd_ps(m[r], x, _mm512_fmadd_ps(m[3 + r], y, _mm512_fmadd_ps(m[6 + r], z, m[9 + r])));
                    *p = _mm512_fmadd_ps(w, row, *p);
                }
            }
            if whole {
                for k in 0..3 {
                    (lo[k], hi[k]) = (_mm512_min_ps(lo[k], p[k]), _mm512_max_ps(hi[k], p[k]));
                }
                // SAFETY: as above.
                unsafe { interleave(p, &mut out[lanes.start - first..lanes.end - first]) };
            } else {
                let lane = p.map(floats);
                for (i, v) in lanes.enumerate().filter(|(_, v)| (first..end).contains(v)) {
                    let q = Vec3A::new(lane[0][i], lane[1][i], lane[2][i]);
                    out[v - first] = q.into();
                    edges = edges.with(q);
                }
            }
        }
        lanes_bounds(lo, hi).union(edges)
    }

    /// [`super::avx2::skin_blocks_with_normals`] sixteen vertices a block.
    ///
    /// # Safety
    /// The CPU must have AVX-512 F, AVX2 and FMA.
    #[target_feature(enable = "avx512f,avx2,fma")]
    pub unsafe fn skin_blocks_with_normals(
        bind: &[Vec3],
        blocks: &WideLaneBlocks,
        palette: &[Mat4],
        out: &mut [Vec3],
        normals: Normals,
    ) -> Bounds {
        let n = bind.len();
        let (mut lo, mut hi) = ([_mm512_set1_ps(f32::INFINITY); 3], [_mm512_set1_ps(f32::NEG_INFINITY); 3]);
        let mut last = Bounds::EMPTY;
        for b in 0..n.div_ceil(WIDE_LANES) {
            let lanes = b * WIDE_LANES..(b + 1) * WIDE_LANES;
            let mut m = [_mm512_setzero_ps(); 12];
            let joints = blocks.joint_starts[b] as usize..blocks.joint_starts[b + 1] as usize;
            for (&j, w) in blocks.joints[joints.clone()].iter().zip(&blocks.weights[joints]) {
                let w = register(w.0);
                for (m, e) in m.iter_mut().zip(elements(&palette[j as usize])) {
                    *m = _mm512_fmadd_ps(w, _mm512_set1_ps(e), *m);
                }
            }
            // SAFETY: the CPU has AVX-512 F (this function's contract).
            let [x, y, z] = unsafe { lane_points(bind, lanes.clone()) };
            let p: [__m512; 3] = std::array::from_fn(|r| {
                _mm512_fmadd_ps(m[r], x, _mm512_fmadd_ps(m[3 + r], y, _mm512_fmadd_ps(m[6 + r], z, m[9 + r])))
            });
            // SAFETY: as above.
            let [x, y, z] = unsafe { lane_points(normals.bind, lanes.clone()) };
            let normal: [__m512; 3] = std::array::from_fn(|r| {
                _mm512_fmadd_ps(m[r], x, _mm512_fmadd_ps(m[3 + r], y, _mm512_mul_ps(m[6 + r], z)))
            });
            if lanes.end <= n {
                for k in 0..3 {
                    (lo[k], hi[k]) = (_mm512_min_ps(lo[k], p[k]), _mm512_max_ps(hi[k], p[k]));
                }
                // SAFETY: as above.
                unsafe {
                    interleave(p, &mut out[lanes.clone()]);
                    interleave(normal, &mut normals.out[lanes]);
                }
            } else {
                let (p, normal) = (p.map(floats), normal.map(floats));
                for (i, v) in lanes.take_while(|&v| v < n).enumerate() {
                    let q = Vec3A::new(p[0][i], p[1][i], p[2][i]);
                    (out[v], normals.out[v]) = (q.into(), Vec3::new(normal[0][i], normal[1][i], normal[2][i]));
                    last = last.with(q);
                }
            }
        }
        lanes_bounds(lo, hi).union(last)
    }

    /// The box between sixteen lanes of lower and sixteen of upper corners.
    #[inline(always)]
    fn lanes_bounds(lo: [__m512; 3], hi: [__m512; 3]) -> Bounds {
        let reduce = |r: __m512, f: fn(f32, f32) -> f32| floats(r).into_iter().reduce(f).unwrap_or(0.0);
        Bounds::between(
            Vec3A::new(reduce(lo[0], f32::min), reduce(lo[1], f32::min), reduce(lo[2], f32::min)),
            Vec3A::new(reduce(hi[0], f32::max), reduce(hi[1], f32::max), reduce(hi[2], f32::max)),
        )
    }
}

//! The fast linear-blend-skinning kernel. On x86-64 with AVX2 and FMA (detected at run
//! time), the vertices are skinned in blocks of eight consecutive ones
//! ([`LaneBlocks`](super::influences::LaneBlocks), built with the weights), one vertex a
//! lane of a 256-bit register: each of a block's joints transforms all eight bind
//! positions at once, weighted lane by lane (`pᵥ = Σⱼ wᵥⱼ (Pⱼ bᵥ)`), so a joint's matrix is
//! read once for eight vertices. Elsewhere each vertex blends its own matrices with glam's
//! `Vec4`, grouped by influence count. With AVX-512 F, the blocks are sixteen vertices wide
//! ([`WideLaneBlocks`](super::influences::WideLaneBlocks)) on 512-bit registers: a joint's
//! multiply-adds serve twice the vertices, and the pair of blocks of eight they replace
//! share most joints (SMPL: 37 % fewer multiply-adds). [`Simd`] names the levels; the
//! `_using` entry points run any level the CPU has.
//! [`skin_positions`](super::skinning::skin_positions) stays as the plain oracle.

use glam::{Mat4, Vec3, Vec3A, Vec4};

use super::influences::FixedGroup;
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
            return unsafe { blocks::skin_blocks_avx512(bind_positions, &groups.wide_blocks, palette, first, out) };
        }
        // SAFETY: as above.
        Simd::Avx2 => {
            return unsafe { blocks::skin_blocks_avx2(bind_positions, &groups.blocks.joints, palette, first, out) };
        }
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
                blocks::skin_blocks_with_normals_avx512(bind_positions, &groups.wide_blocks, palette, out, normals)
            };
        }
        // SAFETY: as above.
        Simd::Avx2 => {
            return unsafe {
                blocks::skin_blocks_with_normals_avx2(bind_positions, &groups.blocks.joints, palette, out, normals)
            };
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
/// and transforms its bind position by `M`, one vertex at a time (lanes in plain arrays
/// spill 128-bit registers).
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

/// The SIMD kernels: one generic body each over [`Lanes`], built for AVX2 + FMA (eight
/// vertices a block) and for AVX-512 F (sixteen).
#[cfg(target_arch = "x86_64")]
mod blocks {
    use std::arch::x86_64::*;

    use glam::{Mat4, Vec3, Vec3A};

    use super::Normals;
    use crate::avx2::prefetch_ahead;
    use crate::influences::{JointBlocks, LaneWeights, WideLaneBlocks};
    use crate::lanes::Lanes;
    use crate::skinning::Bounds;

    /// Linear blend skinning of the vertices `first..first + out.len()` on 256-bit
    /// registers, eight vertices a block ([`skin_blocks`]).
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn skin_blocks_avx2(
        bind: &[Vec3],
        blocks: &JointBlocks<LaneWeights>,
        palette: &[Mat4],
        first: usize,
        out: &mut [Vec3],
    ) -> Bounds {
        // SAFETY: the CPU has AVX2 and FMA (this function's contract).
        unsafe { skin_blocks::<__m256>(bind, blocks, palette, first, out) }
    }

    /// The same on 512-bit registers, sixteen vertices a block.
    ///
    /// # Safety
    /// The CPU must have AVX-512 F, AVX2 and FMA.
    #[target_feature(enable = "avx512f,avx2,fma")]
    pub unsafe fn skin_blocks_avx512(
        bind: &[Vec3],
        blocks: &WideLaneBlocks,
        palette: &[Mat4],
        first: usize,
        out: &mut [Vec3],
    ) -> Bounds {
        // SAFETY: the CPU has AVX-512 F (this function's contract).
        unsafe { skin_blocks::<__m512>(bind, blocks, palette, first, out) }
    }

    /// A whole mesh with its normals on 256-bit registers ([`skin_blocks_with_normals`]).
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn skin_blocks_with_normals_avx2(
        bind: &[Vec3],
        blocks: &JointBlocks<LaneWeights>,
        palette: &[Mat4],
        out: &mut [Vec3],
        normals: Normals,
    ) -> Bounds {
        // SAFETY: the CPU has AVX2 and FMA (this function's contract).
        unsafe { skin_blocks_with_normals::<__m256>(bind, blocks, palette, out, normals) }
    }

    /// The same on 512-bit registers.
    ///
    /// # Safety
    /// The CPU must have AVX-512 F, AVX2 and FMA.
    #[target_feature(enable = "avx512f,avx2,fma")]
    pub unsafe fn skin_blocks_with_normals_avx512(
        bind: &[Vec3],
        blocks: &WideLaneBlocks,
        palette: &[Mat4],
        out: &mut [Vec3],
        normals: Normals,
    ) -> Bounds {
        // SAFETY: the CPU has AVX-512 F (this function's contract).
        unsafe { skin_blocks_with_normals::<__m512>(bind, blocks, palette, out, normals) }
    }

    /// A palette matrix's twelve elements as a block reads them: element `e` is column
    /// `e / 3`, row `e % 3` (the fourth row of an affine matrix is not needed). (With
    /// AVX-512, each broadcast of one folds into the multiply-add that reads it.)
    #[inline(always)]
    fn elements(m: &Mat4) -> [f32; 12] {
        let c = m.to_cols_array();
        std::array::from_fn(|e| c[e / 3 * 4 + e % 3])
    }

    /// Each block on `L`'s registers, one vertex a lane: each of the block's joints
    /// transforms all its bind positions (its matrix's elements broadcast once) and adds them
    /// in with each lane's weight; twelve multiply-adds a joint for the block. Blocks that
    /// lie wholly in the chunk read and write their positions in order; the chunk's first
    /// and last blocks (when it does not start or end on a block's edge) and the mesh's last
    /// go lane by lane.
    ///
    /// (Indices are checked: a joint beyond the palette or a vertex beyond the buffers
    /// panics.)
    ///
    /// # Safety
    /// The CPU must have `L`'s features.
    #[inline(always)]
    unsafe fn skin_blocks<L: Lanes>(
        bind: &[Vec3],
        blocks: &JointBlocks<L::Weights>,
        palette: &[Mat4],
        first: usize,
        out: &mut [Vec3],
    ) -> Bounds {
        // SAFETY: the CPU has `L`'s features (this function's contract).
        unsafe {
            let end = first + out.len();
            let (mut lo, mut hi) = ([L::splat(f32::INFINITY); 3], [L::splat(f32::NEG_INFINITY); 3]);
            let mut edges = Bounds::EMPTY;
            for b in first / L::LANES..end.div_ceil(L::LANES) {
                let lanes = b * L::LANES..(b + 1) * L::LANES;
                let whole = first <= lanes.start && lanes.end <= end;
                prefetch_ahead(bind, lanes.start, out, lanes.start.saturating_sub(first), L::LANES);
                let [x, y, z] = if whole {
                    L::points(&bind[lanes.clone()])
                } else {
                    L::some_points(&bind[lanes.start..lanes.end.min(bind.len())])
                };
                let mut p = [L::splat(0.0); 3];
                let (joints, weights) = blocks.block(b);
                for (&j, w) in joints.iter().zip(weights) {
                    let w = L::weights(w);
                    let m = elements(&palette[j as usize]).map(|e| L::splat(e));
                    for (r, p) in p.iter_mut().enumerate() {
                        let row = L::fmadd(m[r], x, L::fmadd(m[3 + r], y, L::fmadd(m[6 + r], z, m[9 + r])));
                        *p = L::fmadd(w, row, *p);
                    }
                }
                if whole {
                    for k in 0..3 {
                        (lo[k], hi[k]) = (L::min(lo[k], p[k]), L::max(hi[k], p[k]));
                    }
                    L::write_points(p, &mut out[lanes.start - first..lanes.end - first]);
                } else {
                    for (i, v) in lanes.enumerate().filter(|(_, v)| (first..end).contains(v)) {
                        let q = Vec3A::new(p[0].lane(i), p[1].lane(i), p[2].lane(i));
                        out[v - first] = q.into();
                        edges = edges.with(q);
                    }
                }
            }
            lanes_bounds(lo, hi).union(edges)
        }
    }

    /// [`skin_blocks`] of a whole mesh with its normals: each lane's matrix is blended
    /// first (`Σⱼ wⱼ Pⱼ`, twelve multiply-adds a joint for the block), then turns the block's
    /// positions and normals once. (Transforming by each joint, as `skin_blocks` does for
    /// positions alone, needs more registers than AVX2 has with the normals: 46 µs a SMPL
    /// body against this order's 22.)
    ///
    /// # Safety
    /// The CPU must have `L`'s features.
    #[inline(always)]
    unsafe fn skin_blocks_with_normals<L: Lanes>(
        bind: &[Vec3],
        blocks: &JointBlocks<L::Weights>,
        palette: &[Mat4],
        out: &mut [Vec3],
        normals: Normals,
    ) -> Bounds {
        // SAFETY: the CPU has `L`'s features (this function's contract).
        unsafe {
            let n = bind.len();
            let (mut lo, mut hi) = ([L::splat(f32::INFINITY); 3], [L::splat(f32::NEG_INFINITY); 3]);
            let mut last = Bounds::EMPTY;
            for b in 0..n.div_ceil(L::LANES) {
                let lanes = b * L::LANES..(b + 1) * L::LANES;
                let mut m = [L::splat(0.0); 12];
                let (joints, weights) = blocks.block(b);
                for (&j, w) in joints.iter().zip(weights) {
                    let w = L::weights(w);
                    // Each element broadcast where it is used: twelve held at once spill
                    // AVX2's sixteen registers beside the twelve sums (22 -> 27 µs a SMPL body).
                    for (m, e) in m.iter_mut().zip(elements(&palette[j as usize])) {
                        *m = L::fmadd(w, L::splat(e), *m);
                    }
                }
                let [x, y, z] = lane_points::<L>(bind, lanes.clone());
                let p: [L; 3] =
                    std::array::from_fn(|r| L::fmadd(m[r], x, L::fmadd(m[3 + r], y, L::fmadd(m[6 + r], z, m[9 + r]))));
                let [x, y, z] = lane_points::<L>(normals.bind, lanes.clone());
                let normal: [L; 3] =
                    std::array::from_fn(|r| L::fmadd(m[r], x, L::fmadd(m[3 + r], y, L::mul(m[6 + r], z))));
                if lanes.end <= n {
                    for k in 0..3 {
                        (lo[k], hi[k]) = (L::min(lo[k], p[k]), L::max(hi[k], p[k]));
                    }
                    L::write_points(p, &mut out[lanes.clone()]);
                    L::write_points(normal, &mut normals.out[lanes]);
                } else {
                    for (i, v) in lanes.take_while(|&v| v < n).enumerate() {
                        let q = Vec3A::new(p[0].lane(i), p[1].lane(i), p[2].lane(i));
                        out[v] = q.into();
                        normals.out[v] = Vec3::new(normal[0].lane(i), normal[1].lane(i), normal[2].lane(i));
                        last = last.with(q);
                    }
                }
            }
            lanes_bounds(lo, hi).union(last)
        }
    }

    /// The points of a block's `lanes` as x, y and z registers: all of them where they are
    /// all there, else those up to the end (zero past them).
    ///
    /// # Safety
    /// The CPU must have `L`'s features.
    #[inline(always)]
    unsafe fn lane_points<L: Lanes>(points: &[Vec3], lanes: std::ops::Range<usize>) -> [L; 3] {
        match points.get(lanes.clone()) {
            // SAFETY: this function's contract.
            Some(whole) => unsafe { L::points(whole) },
            None => L::some_points(&points[lanes.start..points.len()]),
        }
    }

    /// The box between a register of lower and one of upper corners.
    #[inline(always)]
    fn lanes_bounds<L: Lanes>(lo: [L; 3], hi: [L; 3]) -> Bounds {
        let reduce = |r: L, f: fn(f32, f32) -> f32| (0..L::LANES).map(|i| r.lane(i)).reduce(f).unwrap_or(0.0);
        Bounds::between(
            Vec3A::new(reduce(lo[0], f32::min), reduce(lo[1], f32::min), reduce(lo[2], f32::min)),
            Vec3A::new(reduce(hi[0], f32::max), reduce(hi[1], f32::max), reduce(hi[2], f32::max)),
        )
    }
}

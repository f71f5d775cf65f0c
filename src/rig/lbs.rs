//! The fast linear-blend-skinning kernel. When the weights are built, the vertices are put
//! in blocks of eight that share few joints ([`LaneBlocks`]); a block blends each of its
//! joints' matrices into all eight vertices' matrices at once (`Mᵥ = Σ wᵥⱼ Pⱼ`, one vertex
//! a lane) and transforms each lane's bind position by its own. On x86-64 with AVX2 and FMA
//! (detected at run time) the lanes are 256-bit registers; elsewhere plain arrays.
//! [`skin_positions`](super::skinning::skin_positions) stays as the plain oracle.

use glam::{Mat4, Vec3, Vec3A};

pub use super::influences::TILE_VERTICES;
use super::influences::{LANES, LaneBlocks};
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
/// box. Chunks that start and end on multiples of [`TILE_VERTICES`] read only their own
/// blocks; others also skin (and do not write) their tiles' other vertices.
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
        return unsafe { avx2::skin_blocks(bind_positions, &groups.blocks, palette, first, out) };
    }
    skin_blocks_portable(bind_positions, &groups.blocks, palette, first, out)
}

/// [`skin_bounded`] without the AVX2 path: the same blocks in plain arrays, on any target
/// (what other CPUs run).
///
/// # Panics
/// As [`skin`].
pub fn skin_portable(bind_positions: &[Vec3], weights: &SkinWeights, palette: &[Mat4], out: &mut [Vec3]) -> Bounds {
    assert_eq!(bind_positions.len(), weights.vertex_count(), "one weight row per vertex");
    assert_eq!(out.len(), bind_positions.len(), "one output per vertex");
    skin_blocks_portable(bind_positions, &weights.groups().blocks, palette, 0, out)
}

/// Element `e` of the blended matrix in a block: column `e / 3`, row `e % 3` (the fourth
/// row of an affine matrix is not needed).
const ELEMENTS: usize = 12;

/// A palette matrix's twelve elements, as [`ELEMENTS`] orders them.
#[inline]
fn elements(m: &Mat4) -> [f32; ELEMENTS] {
    let c = m.to_cols_array();
    std::array::from_fn(|e| c[e / 3 * 4 + e % 3])
}

/// Writes lane `vertex`'s skinned position `p` when the vertex lies in the chunk
/// `first..first + out.len()`, growing `bounds`.
#[inline]
fn store_lane(out: &mut [Vec3], first: usize, vertex: u32, p: Vec3A, bounds: &mut Bounds) {
    let at = (vertex as usize).wrapping_sub(first);
    if at < out.len() {
        out[at] = p.into();
        *bounds = bounds.with(p);
    }
}

/// The portable path: each block's matrices blended into all eight lanes in plain arrays.
fn skin_blocks_portable(
    bind: &[Vec3],
    blocks: &LaneBlocks,
    palette: &[Mat4],
    first: usize,
    out: &mut [Vec3],
) -> Bounds {
    let mut bounds = Bounds::EMPTY;
    for b in blocks.covering(first, out.len()) {
        let joints = blocks.joint_starts[b] as usize..blocks.joint_starts[b + 1] as usize;
        let mut m = [[0.0f32; LANES]; ELEMENTS];
        for (&j, w) in blocks.joints[joints.clone()].iter().zip(&blocks.weights[joints]) {
            for (m, c) in m.iter_mut().zip(elements(&palette[j as usize])) {
                for (m, w) in m.iter_mut().zip(w.0) {
                    *m += w * c;
                }
            }
        }
        for (i, &v) in blocks.vertices[b].iter().enumerate() {
            let b = bind[v as usize];
            let row = |r: usize| m[r][i] * b.x + m[3 + r][i] * b.y + m[6 + r][i] * b.z + m[9 + r][i];
            store_lane(out, first, v, Vec3A::new(row(0), row(1), row(2)), &mut bounds);
        }
    }
    bounds
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use glam::{Mat4, Vec3, Vec3A, Vec4};

    use super::{LANES, LaneBlocks, elements, store_lane};
    use crate::rig::skinning::Bounds;

    /// Each block on 256-bit registers, one vertex a lane: each of the block's joints
    /// transforms all eight bind positions (its matrix's elements broadcast once) and adds
    /// them in with each lane's weight; twelve multiply-adds a joint for eight vertices.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA. (Indices are checked: a joint beyond the palette or a
    /// vertex beyond the buffers panics.)
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn skin_blocks(
        bind: &[Vec3],
        blocks: &LaneBlocks,
        palette: &[Mat4],
        first: usize,
        out: &mut [Vec3],
    ) -> Bounds {
        let mut bounds = Bounds::EMPTY;
        for b in blocks.covering(first, out.len()) {
            let lanes = &blocks.vertices[b];
            let [x, y, z] = gather(bind, lanes);
            let mut p = [_mm256_setzero_ps(); 3];
            let joints = blocks.joint_starts[b] as usize..blocks.joint_starts[b + 1] as usize;
            for (&j, w) in blocks.joints[joints.clone()].iter().zip(&blocks.weights[joints]) {
                // SAFETY: `LaneWeights` is eight `f32`s, as `__m256` is.
                let w: __m256 = unsafe { std::mem::transmute(w.0) };
                let m = elements(&palette[j as usize]).map(|c| _mm256_set1_ps(c));
                for (r, p) in p.iter_mut().enumerate() {
                    let row =
                        _mm256_fmadd_ps(m[r], x, _mm256_fmadd_ps(m[3 + r], y, _mm256_fmadd_ps(m[6 + r], z, m[9 + r])));
                    *p = _mm256_fmadd_ps(w, row, *p);
                }
            }
            for (p, &v) in scatter(p).into_iter().zip(lanes) {
                store_lane(out, first, v, p, &mut bounds);
            }
        }
        bounds
    }

    /// The lanes' bind positions as three registers: the x, y and z of each lane.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn gather(bind: &[Vec3], lanes: &[u32; LANES]) -> [__m256; 3] {
        let pair = |i: usize| _mm256_set_m128(load(bind, lanes[i + 4]), load(bind, lanes[i]));
        // Lanes i and i + 4 side by side, then a 4 × 4 transpose in each half.
        let (r0, r1, r2, r3) = (pair(0), pair(1), pair(2), pair(3));
        let (xy01, xy23) = (_mm256_unpacklo_ps(r0, r1), _mm256_unpacklo_ps(r2, r3));
        let (zw01, zw23) = (_mm256_unpackhi_ps(r0, r1), _mm256_unpackhi_ps(r2, r3));
        [
            _mm256_shuffle_ps::<0x44>(xy01, xy23),
            _mm256_shuffle_ps::<0xEE>(xy01, xy23),
            _mm256_shuffle_ps::<0x44>(zw01, zw23),
        ]
    }

    /// Vertex `v`'s bind position in the first three floats of a register, read in one load
    /// of four floats (the fourth is the next vertex's x) except for the last vertex.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn load(bind: &[Vec3], v: u32) -> __m128 {
        /// Sixteen bytes read from wherever they lie.
        #[repr(C, packed)]
        struct Unaligned(__m128);
        let v = v as usize;
        match bind.get(v..v + 2) {
            // SAFETY: two `Vec3`s are 24 readable bytes; `Unaligned` reads 16 of them at any
            // alignment.
            Some(two) => unsafe { two.as_ptr().cast::<Unaligned>().read().0 },
            None => {
                let b = bind[v];
                _mm_setr_ps(b.x, b.y, b.z, 0.0)
            }
        }
    }

    /// The inverse of [`gather`]: the x, y and z registers as each lane's point.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn scatter([x, y, z]: [__m256; 3]) -> [Vec3A; LANES] {
        let zero = _mm256_setzero_ps();
        let (xy01, xy23) = (_mm256_unpacklo_ps(x, y), _mm256_unpackhi_ps(x, y));
        let (z01, z23) = (_mm256_unpacklo_ps(z, zero), _mm256_unpackhi_ps(z, zero));
        let pairs = [
            _mm256_shuffle_ps::<0x44>(xy01, z01),
            _mm256_shuffle_ps::<0xEE>(xy01, z01),
            _mm256_shuffle_ps::<0x44>(xy23, z23),
            _mm256_shuffle_ps::<0xEE>(xy23, z23),
        ];
        let point = |q: __m128| Vec3A::from_vec4(Vec4::from(q));
        std::array::from_fn(|i| {
            let pair = pairs[i % 4];
            point(if i < 4 { _mm256_castps256_ps128(pair) } else { _mm256_extractf128_ps::<1>(pair) })
        })
    }
}

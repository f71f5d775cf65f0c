//! Dual quaternion skinning (Kavan, Collins, Žára, O'Sullivan 2008). Each joint's rigid
//! palette transform becomes a unit dual quaternion. A vertex blends its influences'
//! dual quaternions linearly, after flipping each into the hemisphere of its heaviest
//! influence, normalises the blend and applies it. Unlike linear blend skinning, a twisted
//! or bent joint keeps its volume ("candy wrapper"). Rigid palettes only: a scale in a
//! palette matrix is dropped (see [`has_scale`]).

use glam::{Mat4, Quat, Vec3, Vec4};

use super::influences::FixedGroup;
use super::simd::Simd;
use super::skinning::{Normals, SkinWeights};

pub use super::skinning::SkinningMethod;

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
/// Skins `bind_positions` by the model-space `palette` as `method` does: linear blend, or
/// dual quaternions (a palette without scale).
pub fn skin_by(
    method: super::skinning::SkinningMethod,
    bind_positions: &[Vec3],
    weights: &SkinWeights,
    palette: &[Mat4],
    out: &mut [Vec3],
) {
    if method.is_linear() {
        crate::lbs::skin(bind_positions, weights, palette, out);
    } else {
        let mut dq = Vec::new();
        dual_quaternion_palette(palette, &mut dq);
        skin_dq(bind_positions, weights, &dq, out);
    }
}

/// it has grown).
pub fn dual_quaternion_palette(palette: &[Mat4], out: &mut Vec<DualQuat>) {
    out.clear();
    out.extend(palette.iter().map(DualQuat::from_rigid));
}

/// Skins bind-pose vertices with dual quaternions, at the best level of the kernel the CPU
/// runs ([`Simd::best`]). On x86-64 with AVX2 and FMA, in the
/// linear blend kernel's blocks of eight consecutive vertices, one a lane: each of a
/// block's joints adds its dual quaternion into all eight blends at once, its weight's sign
/// flipped lane by lane into the hemisphere of that vertex's pivot; then the eight blends
/// are normalised and applied side by side. Elsewhere, vertex by vertex.
///
/// # Panics
/// When the lengths of `bind_positions`, `weights` and `out` differ, or an influence names
/// a joint beyond the palette.
pub fn skin_dq(bind_positions: &[Vec3], weights: &SkinWeights, palette: &[DualQuat], out: &mut [Vec3]) {
    skin_dq_using(Simd::best(), bind_positions, weights, palette, out);
}

/// [`skin_dq`] with normals: each vertex's normal turned by the rotation of the same
/// normalised blend that moves its position (a unit normal stays unit).
///
/// # Panics
/// As [`skin_dq`], or when there is not one bind normal and one output normal per vertex.
pub fn skin_dq_with_normals(
    bind_positions: &[Vec3],
    weights: &SkinWeights,
    palette: &[DualQuat],
    out: &mut [Vec3],
    normals: Normals,
) {
    skin_dq_with_normals_using(Simd::best(), bind_positions, weights, palette, out, normals);
}

/// [`skin_dq`] at a given level of the kernel (`Simd::Portable`: vertex by vertex, what
/// other CPUs run and the SIMD levels' oracle).
///
/// # Panics
/// As [`skin_dq`], or when the CPU does not run `simd`.
pub fn skin_dq_using(
    simd: Simd,
    bind_positions: &[Vec3],
    weights: &SkinWeights,
    palette: &[DualQuat],
    out: &mut [Vec3],
) {
    skin_dq_at(simd, bind_positions, weights, palette, out, None);
}

/// [`skin_dq_with_normals`] at a given level of the kernel.
///
/// # Panics
/// As [`skin_dq_with_normals`], or when the CPU does not run `simd`.
pub fn skin_dq_with_normals_using(
    simd: Simd,
    bind_positions: &[Vec3],
    weights: &SkinWeights,
    palette: &[DualQuat],
    out: &mut [Vec3],
    normals: Normals,
) {
    assert!(normals.bind.len() == out.len() && normals.out.len() == out.len(), "one normal per vertex");
    skin_dq_at(simd, bind_positions, weights, palette, out, Some(normals));
}

/// The kernel at level `simd`, with normals or without.
fn skin_dq_at(
    simd: Simd,
    bind_positions: &[Vec3],
    weights: &SkinWeights,
    palette: &[DualQuat],
    out: &mut [Vec3],
    mut normals: Option<Normals>,
) {
    assert_eq!(bind_positions.len(), weights.vertex_count(), "one weight row per vertex");
    assert_eq!(out.len(), bind_positions.len(), "one output per vertex");
    let groups = weights.groups();
    assert!(groups.joint_bound <= palette.len(), "an influence names a joint beyond the palette");
    assert!(simd.is_available(), "this CPU does not run {simd:?}");
    #[cfg(target_arch = "x86_64")]
    if simd != Simd::Portable {
        HEMISPHERES.with_borrow_mut(|hemispheres| {
            hemisphere_bits(palette, &groups.blocks.pivot_rows, hemispheres);
            // SAFETY: the CPU runs `simd` (checked above).
            unsafe { avx2::skin_blocks(simd, bind_positions, &groups.blocks, palette, hemispheres, out, normals) };
        });
        return;
    }
    skin_dq_portable(bind_positions, weights, palette, out, &mut normals);
}

#[cfg(target_arch = "x86_64")]
std::thread_local! {
    /// Each thread's [`hemisphere_bits`] (grown once, then reused: the kernel does not
    /// allocate per call once it has grown).
    static HEMISPHERES: std::cell::RefCell<Vec<u32>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// For each joint, one bit for each of `pivot_rows` (bit r: row r): set where the joint's
/// rotation lies in the other hemisphere from that pivot's, so that its weight's sign is
/// flipped. Made once per palette (a dot product for each joint and row), so that a block
/// blends without a dot product of its own.
fn hemisphere_bits(palette: &[DualQuat], pivot_rows: &[u16], bits: &mut Vec<u32>) {
    bits.clear();
    bits.extend(palette.iter().map(|q| {
        let pivots = pivot_rows.iter().map(|&p| palette.get(p as usize).map_or(Vec4::W, |p| p.real));
        pivots.enumerate().map(|(r, pivot)| u32::from(q.real.dot(pivot) < 0.0) << r).sum::<u32>()
    }));
}

/// The portable path: vertex by vertex, grouped by influence count.
fn skin_dq_portable(
    bind_positions: &[Vec3],
    weights: &SkinWeights,
    palette: &[DualQuat],
    out: &mut [Vec3],
    normals: &mut Option<Normals>,
) {
    let groups = weights.groups();
    fixed_rows::<1>(bind_positions, &groups.fixed[0], palette, out, normals);
    fixed_rows::<2>(bind_positions, &groups.fixed[1], palette, out, normals);
    fixed_rows::<3>(bind_positions, &groups.fixed[2], palette, out, normals);
    fixed_rows::<4>(bind_positions, &groups.fixed[3], palette, out, normals);
    for &v in &groups.wide {
        let row = weights.of_vertex(v as usize).iter().map(|i| (i.joint, i.weight));
        apply_to_vertex(blend(row, palette), v as usize, bind_positions, out, normals);
    }
}

fn fixed_rows<const K: usize>(
    bind: &[Vec3],
    group: &FixedGroup,
    palette: &[DualQuat],
    out: &mut [Vec3],
    normals: &mut Option<Normals>,
) {
    let rows = group.joints.chunks_exact(K).zip(group.weights.chunks_exact(K));
    for (&v, (joints, weights)) in group.vertices.iter().zip(rows) {
        let row = joints.iter().copied().zip(weights.iter().copied());
        apply_to_vertex(blend(row, palette), v as usize, bind, out, normals);
    }
}

/// Moves vertex `v` (and turns its normal, where there are normals) by a blend's rotation
/// and translation.
#[inline(always)]
fn apply_to_vertex(
    (rotation, t): (Quat, Vec3),
    v: usize,
    bind: &[Vec3],
    out: &mut [Vec3],
    normals: &mut Option<Normals>,
) {
    out[v] = rotation * bind[v] + t;
    if let Some(normals) = normals {
        normals.out[v] = rotation * normals.bind[v];
    }
}

/// Blends one vertex's dual quaternions in its heaviest influence's hemisphere (q and -q
/// are the same rotation) and normalises the blend: its rotation and translation (none
/// for a row without influences).
#[inline(always)]
fn blend(row: impl Iterator<Item = (u16, f32)> + Clone, palette: &[DualQuat]) -> (Quat, Vec3) {
    // The first of the heaviest influences (as the SIMD path picks it).
    let heaviest = row.clone().fold(None, |best, (j, w)| match best {
        Some((_, bw)) if bw >= w => best,
        _ => Some((j, w)),
    });
    let Some((heaviest, _)) = heaviest else { return (Quat::IDENTITY, Vec3::ZERO) };
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
    (Quat::from_vec4(real), t)
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use glam::{Vec3, Vec4};

    use super::DualQuat;
    use crate::avx2::{deinterleave, deinterleave_some, floats, for_both_levels, interleave, register};
    use crate::influences::{BlockPivots, LANES, LaneBlocks};
    use crate::skinning::Normals;

    for_both_levels! {
    /// Each block on 256-bit registers, one vertex a lane: each of the block's joints
    /// broadcasts its dual quaternion and adds it into the eight blends with each lane's
    /// weight (eight multiply-adds for eight vertices), the weight's sign flipped where the
    /// joint lies in the other hemisphere from the lane's pivot. That sign is a bit of
    /// `hemispheres` (from [`hemisphere_bits`](super::hemisphere_bits)): one for the whole
    /// block where its lanes share their pivot, shifted out lane by lane where they do not;
    /// for pivots beyond the table, from the dot product with each lane's pivot. Whole
    /// blocks read and write their positions (and normals, turned by the blend's rotation)
    /// in order; the mesh's last block, when partial, lane by lane.
    ///
    /// (Indices are checked: a joint beyond the palette panics.)
    pub unsafe fn skin_blocks = skin_blocks_body(
        bind: &[Vec3],
        blocks: &LaneBlocks,
        palette: &[DualQuat],
        hemispheres: &[u32],
        out: &mut [Vec3],
        normals: Option<Normals>,
    )
    }

    /// [`skin_blocks`]' body.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[inline(always)]
    unsafe fn skin_blocks_body(
        bind: &[Vec3],
        blocks: &LaneBlocks,
        palette: &[DualQuat],
        hemispheres: &[u32],
        out: &mut [Vec3],
        mut normals: Option<Normals>,
    ) {
        // SAFETY: the CPU has AVX2 and FMA (this function's contract).
        unsafe {
            let n = bind.len();
            let (zero, sign) = (_mm256_setzero_ps(), _mm256_set1_ps(-0.0));
            let add = |blend: &mut [__m256; 8], w: __m256, q: &DualQuat| {
                let (real, dual) = (q.real.to_array(), q.dual.to_array());
                for c in 0..4 {
                    blend[c] = _mm256_fmadd_ps(w, _mm256_set1_ps(real[c]), blend[c]);
                    blend[4 + c] = _mm256_fmadd_ps(w, _mm256_set1_ps(dual[c]), blend[4 + c]);
                }
            };
            for b in 0..n.div_ceil(LANES) {
                let lanes = b * LANES..((b + 1) * LANES).min(n);
                let mut blend = [zero; 8];
                let (joints, weights) = blocks.joints.block(b);
                let influences = joints.iter().zip(weights);
                match blocks.block_pivots[b] {
                    BlockPivots::Shared(row) => {
                        for (&j, w) in influences {
                            let flip = f32::from_bits((hemispheres[j as usize] >> row & 1) << 31);
                            add(&mut blend, _mm256_xor_ps(register(w.0), _mm256_set1_ps(flip)), &palette[j as usize]);
                        }
                    }
                    BlockPivots::Rows => {
                        // Lane i's bit moved to the sign: a left shift by 31 less its row.
                        let rows: [u8; LANES] = blocks.lane_rows[lanes.clone()].try_into().expect("eight lanes");
                        let rows = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(i64::from_le_bytes(rows)));
                        let shifts = _mm256_sub_epi32(_mm256_set1_epi32(31), rows);
                        for (&j, w) in influences {
                            let bits = _mm256_sllv_epi32(_mm256_set1_epi32(hemispheres[j as usize] as i32), shifts);
                            let flip = _mm256_and_ps(_mm256_castsi256_ps(bits), sign);
                            add(&mut blend, _mm256_xor_ps(register(w.0), flip), &palette[j as usize]);
                        }
                    }
                    BlockPivots::Lanes => {
                        let unit = Vec4::W;
                        let pivots = lanes_of(std::array::from_fn(|i| {
                            let pivot = blocks.pivots.get(lanes.start + i).map(|&j| j as usize);
                            pivot.and_then(|j| palette.get(j)).map_or(&unit, |q| &q.real)
                        }));
                        for (&j, w) in influences {
                            let q = &palette[j as usize];
                            // q and -q are one rotation: the weight takes the sign of dot(q.real, pivot).
                            let real = q.real.to_array().map(|c| _mm256_set1_ps(c));
                            let behind = _mm256_cmp_ps::<_CMP_LT_OQ>(dot8(&real, &pivots), zero);
                            add(&mut blend, _mm256_xor_ps(register(w.0), _mm256_and_ps(behind, sign)), q);
                        }
                    }
                }
                // The bind positions read after the blend: with their three registers held through
                // it, an accumulator spilled to memory (a tenth of the kernel's time).
                let moved = normalise_and_apply(blend, read_lanes(bind, lanes.clone()));
                write_lanes(moved, out, lanes.clone());
                if let Some(Normals { bind, out }) = &mut normals {
                    write_lanes(normalise_and_turn(blend, read_lanes(bind, lanes.clone())), out, lanes);
                }
            }
        }
    }

    /// The points of `lanes` as x, y and z registers (a partial block's missing lanes zero).
    #[inline(always)]
    unsafe fn read_lanes(points: &[Vec3], lanes: std::ops::Range<usize>) -> [__m256; 3] {
        // SAFETY: the CPU has AVX2 (the caller's contract).
        if lanes.len() == LANES { unsafe { deinterleave(&points[lanes]) } } else { deinterleave_some(&points[lanes]) }
    }

    /// x, y and z registers written as the points of `lanes` (a partial block's lane by lane).
    #[inline(always)]
    unsafe fn write_lanes(lanes_xyz: [__m256; 3], points: &mut [Vec3], lanes: std::ops::Range<usize>) {
        if lanes.len() == LANES {
            // SAFETY: the CPU has AVX2 (the caller's contract).
            unsafe { interleave(lanes_xyz, &mut points[lanes]) };
        } else {
            let lane = lanes_xyz.map(floats);
            for (i, v) in lanes.enumerate() {
                points[v] = Vec3::new(lane[0][i], lane[1][i], lane[2][i]);
            }
        }
    }

    /// Normalises eight blends (the real part's x, y, z, w, then the dual part's; lane i
    /// vertex i) and applies them to eight points (x, y and z registers). (A blend is never
    /// zero: every row has an influence, and each is flipped towards the row's pivot.)
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn normalise_and_apply([rx, ry, rz, wr, dx, dy, dz, wd]: [__m256; 8], p: [__m256; 3]) -> [__m256; 3] {
        let (r, d) = ([rx, ry, rz], [dx, dy, dz]);
        // The blend (r, w_r) + ε (d, w_d) is not normalised: with n² = |r|² + w_r², the unit
        // one moves p to p + (2 / n²) (r × t + w_r d - w_d r + r × d), where t = r × p + w_r p;
        // r × t + r × d is r × u, with u = t + d.
        let scale = _mm256_div_ps(_mm256_set1_ps(2.0), dot8(&[rx, ry, rz, wr], &[rx, ry, rz, wr]));
        let rxp = cross8(r, p);
        let mut u = [_mm256_setzero_ps(); 3];
        for c in 0..3 {
            u[c] = _mm256_add_ps(_mm256_fmadd_ps(wr, p[c], rxp[c]), d[c]);
        }
        let rxu = cross8(r, u);
        let mut moved = [_mm256_setzero_ps(); 3];
        for c in 0..3 {
            let rest = _mm256_fmsub_ps(wr, d[c], _mm256_mul_ps(wd, r[c]));
            moved[c] = _mm256_fmadd_ps(scale, _mm256_add_ps(rxu[c], rest), p[c]);
        }
        moved
    }

    /// The rotation of eight blends (normalised, as in [`normalise_and_apply`]) turning
    /// eight vectors: `n + (2 / n²) r × (r × n + w_r n)`.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn normalise_and_turn([rx, ry, rz, wr, ..]: [__m256; 8], n: [__m256; 3]) -> [__m256; 3] {
        let r = [rx, ry, rz];
        let scale = _mm256_div_ps(_mm256_set1_ps(2.0), dot8(&[rx, ry, rz, wr], &[rx, ry, rz, wr]));
        let rxn = cross8(r, n);
        let u: [__m256; 3] = std::array::from_fn(|c| _mm256_fmadd_ps(wr, n[c], rxn[c]));
        let rxu = cross8(r, u);
        std::array::from_fn(|c| _mm256_fmadd_ps(scale, rxu[c], n[c]))
    }

    /// Four quaternions, one per lane of each 128-bit half (`a`, `b`, `c`, `d` hold
    /// quaternions 0..3 of the low half and 4..7 of the high one), as x, y, z, w registers.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn transpose(a: __m256, b: __m256, c: __m256, d: __m256) -> [__m256; 4] {
        let (ab_lo, ab_hi) = (_mm256_unpacklo_ps(a, b), _mm256_unpackhi_ps(a, b));
        let (cd_lo, cd_hi) = (_mm256_unpacklo_ps(c, d), _mm256_unpackhi_ps(c, d));
        [
            _mm256_shuffle_ps::<0x44>(ab_lo, cd_lo),
            _mm256_shuffle_ps::<0xEE>(ab_lo, cd_lo),
            _mm256_shuffle_ps::<0x44>(ab_hi, cd_hi),
            _mm256_shuffle_ps::<0xEE>(ab_hi, cd_hi),
        ]
    }

    /// Eight quaternions as four registers of eight lanes: x, y, z, w; lane i holds
    /// quaternion i.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn lanes_of(q: [&Vec4; 8]) -> [__m256; 4] {
        transpose(
            _mm256_set_m128((*q[4]).into(), (*q[0]).into()),
            _mm256_set_m128((*q[5]).into(), (*q[1]).into()),
            _mm256_set_m128((*q[6]).into(), (*q[2]).into()),
            _mm256_set_m128((*q[7]).into(), (*q[3]).into()),
        )
    }

    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn cross8([ax, ay, az]: [__m256; 3], [bx, by, bz]: [__m256; 3]) -> [__m256; 3] {
        [
            _mm256_fmsub_ps(ay, bz, _mm256_mul_ps(az, by)),
            _mm256_fmsub_ps(az, bx, _mm256_mul_ps(ax, bz)),
            _mm256_fmsub_ps(ax, by, _mm256_mul_ps(ay, bx)),
        ]
    }

    /// `a · b` of four-lane-register quaternions.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn dot8(a: &[__m256; 4], b: &[__m256; 4]) -> __m256 {
        _mm256_fmadd_ps(a[3], b[3], _mm256_fmadd_ps(a[2], b[2], _mm256_fmadd_ps(a[1], b[1], _mm256_mul_ps(a[0], b[0]))))
    }
}

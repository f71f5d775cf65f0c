//! Dual quaternion skinning (Kavan, Collins, Žára, O'Sullivan 2008). Each joint's rigid
//! palette transform becomes a unit dual quaternion. A vertex blends its influences'
//! dual quaternions linearly, after flipping each into the hemisphere of its heaviest
//! influence, normalises the blend and applies it. Unlike linear blend skinning, a twisted
//! or bent joint keeps its volume ("candy wrapper"). Rigid palettes only: a scale in a
//! palette matrix is dropped (see [`has_scale`]).

use glam::{Mat4, Quat, Vec3, Vec4};

use super::influences::FixedGroup;
use super::skinning::SkinWeights;

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
    assert!(groups.joint_bound <= palette.len(), "an influence names a joint beyond the palette");
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        HEMISPHERES.with_borrow_mut(|by_pivot| {
            palette_by_pivot(palette, by_pivot);
            let dq = avx2::Palette { quaternions: palette, by_pivot, stride: row_stride(palette.len()) };
            // SAFETY: the CPU has AVX2 and FMA (checked above).
            unsafe {
                avx2::fixed_rows::<1>(bind_positions, &groups.fixed[0], &dq, out);
                avx2::fixed_rows::<2>(bind_positions, &groups.fixed[1], &dq, out);
                avx2::fixed_rows::<3>(bind_positions, &groups.fixed[2], &dq, out);
                avx2::fixed_rows::<4>(bind_positions, &groups.fixed[3], &dq, out);
                avx2::wide_rows(bind_positions, weights, &dq, out);
            }
        });
        return;
    }
    skin_dq_portable(bind_positions, weights, palette, out);
}

#[cfg(target_arch = "x86_64")]
std::thread_local! {
    /// Each thread's [`palette_by_pivot`] (grown once, then reused: the kernel does not
    /// allocate per call once it has grown).
    static HEMISPHERES: std::cell::RefCell<Vec<DualQuat>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// For every joint `pivot`, the palette flipped into its hemisphere: at
/// `pivot · stride + j` (the stride being [`row_stride`]), `j`'s dual quaternion, negated
/// when its real part's dot product with `pivot`'s is negative. Made once per palette
/// (24 KB for SMPL's 24 joints), so a vertex's blend needs no dot product and no sign per
/// influence.
fn palette_by_pivot(palette: &[DualQuat], by_pivot: &mut Vec<DualQuat>) {
    let (n, stride) = (palette.len(), row_stride(palette.len()));
    by_pivot.resize(n * stride, DualQuat { real: Vec4::ZERO, dual: Vec4::ZERO });
    for (pivot, row) in palette.iter().zip(by_pivot.chunks_exact_mut(stride)) {
        for (q, flipped) in palette.iter().zip(row) {
            // −1 where q lies in the other hemisphere; no branch (the signs follow the pose).
            let sign = 1.0 - 2.0 * f32::from(u8::from(q.real.dot(pivot.real) < 0.0));
            *flipped = DualQuat { real: q.real * sign, dual: q.dual * sign };
        }
    }
}

/// The rows of [`palette_by_pivot`] are a power of two long, at least the palette's: a
/// joint index masked by `stride − 1` then lies in its row without a bounds check.
fn row_stride(joints: usize) -> usize {
    joints.next_power_of_two()
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
    skin_wide(bind_positions, weights, &groups.wide, palette, out);
}

/// Vertices with more than four influences (`vertices`: some of the skin's wide group).
fn skin_wide(bind_positions: &[Vec3], weights: &SkinWeights, vertices: &[u32], palette: &[DualQuat], out: &mut [Vec3]) {
    for &v in vertices {
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
    use crate::rig::avx2::{deinterleave, interleave};
    use crate::rig::influences::FixedGroup;
    use crate::rig::skinning::{Influence, SkinWeights};

    /// `a · b` in every lane, by shuffles and adds (`dpps` is microcoded and slow on
    /// some CPUs, AMD's Zen among them).
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn dot(a: __m128, b: __m128) -> __m128 {
        let m = _mm_mul_ps(a, b);
        let pairs = _mm_add_ps(m, _mm_shuffle_ps::<0b10_11_00_01>(m, m));
        _mm_add_ps(pairs, _mm_shuffle_ps::<0b01_00_11_10>(pairs, pairs))
    }

    /// `a × b` of the xyz lanes (w: 0).
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn cross(a: __m128, b: __m128) -> __m128 {
        let a_yzx = _mm_shuffle_ps::<0b11_00_10_01>(a, a);
        let b_yzx = _mm_shuffle_ps::<0b11_00_10_01>(b, b);
        let c = _mm_fmsub_ps(a, b_yzx, _mm_mul_ps(a_yzx, b));
        _mm_shuffle_ps::<0b11_00_10_01>(c, c)
    }

    /// The dual quaternions and their [`palette_by_pivot`](super::palette_by_pivot).
    pub struct Palette<'a> {
        pub quaternions: &'a [DualQuat],
        pub by_pivot: &'a [DualQuat],
        /// The length of a row of `by_pivot` ([`row_stride`](super::row_stride)).
        pub stride: usize,
    }

    impl Palette<'_> {
        /// The palette flipped into `pivot`'s hemisphere, and the mask that keeps a joint
        /// index inside it (the row's length less one). The joints lie in the palette
        /// (`skin_dq` checked), so the mask changes none; it spares a bounds check.
        #[inline]
        fn flipped(&self, pivot: usize) -> (&[DualQuat], usize) {
            let mask = self.stride - 1;
            (&self.by_pivot[pivot * self.stride..][..=mask], mask)
        }
    }

    /// One fixed group: batches of eight vertices, each vertex's dual quaternions blended
    /// whole (real and dual parts in one 256-bit register, taken from the palette flipped
    /// into the hemisphere of the row's heaviest influence), the eight blends transposed so
    /// that the normalisation and the application run with one vertex per lane; then the
    /// rows left over one at a time.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA. (Indices are checked.)
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn fixed_rows<const K: usize>(bind: &[Vec3], group: &FixedGroup, palette: &Palette, out: &mut [Vec3]) {
        let n = palette.quaternions.len();
        assert_eq!(palette.by_pivot.len(), n * palette.stride, "a flipped palette for every joint");
        assert!(palette.stride.is_power_of_two() && palette.stride >= n, "rows a power of two long");
        let batches = group.vertices.len() / 8 * 8;
        let rows =
            group.joints[..batches * K].chunks_exact(8 * K).zip(group.weights[..batches * K].chunks_exact(8 * K));
        for (vertices, (joints, weights)) in group.vertices[..batches].chunks_exact(8).zip(rows) {
            let vertices: &[u32; 8] = vertices.try_into().unwrap();
            let mut blends = [_mm256_setzero_ps(); 8];
            for (i, b) in blends.iter_mut().enumerate() {
                *b = blend::<K>(&joints[i * K..][..K], &weights[i * K..][..K], palette);
            }
            // Eight consecutive vertices (every batch of an SMPL body) are read and written as
            // 24 floats; others one by one.
            let run = (vertices[7] - vertices[0] == 7).then_some(vertices[0] as usize..vertices[0] as usize + 8);
            let p = match &run {
                Some(run) => deinterleave(&bind[run.clone()]),
                None => gather(bind, vertices),
            };
            let moved = normalise_and_apply(transpose_eight(blends), p);
            match run {
                Some(run) => interleave(moved, &mut out[run]),
                None => scatter(moved, vertices, out),
            }
        }
        let rest = (&group.vertices[batches..], &group.joints[batches * K..], &group.weights[batches * K..]);
        // SAFETY: as this function's.
        unsafe { rows_one_by_one::<K>(bind, rest, palette.quaternions, out) };
    }

    /// The vertices with more than four influences: in batches of eight as [`fixed_rows`]
    /// does (each row's pivot found first), then the rest one at a time.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA. (Indices are checked.)
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn wide_rows(bind: &[Vec3], weights: &SkinWeights, palette: &Palette, out: &mut [Vec3]) {
        let groups = weights.groups();
        let batches = groups.wide.len() / 8 * 8;
        let rows = groups.wide[..batches].chunks_exact(8).zip(groups.wide_pivots.chunks_exact(8));
        for (vertices, pivots) in rows {
            let vertices: &[u32; 8] = vertices.try_into().unwrap();
            let mut blends = [_mm256_setzero_ps(); 8];
            for ((b, &v), &pivot) in blends.iter_mut().zip(vertices).zip(pivots) {
                *b = blend_any(weights.of_vertex(v as usize), pivot, palette);
            }
            let moved = normalise_and_apply(transpose_eight(blends), gather(bind, vertices));
            scatter(moved, vertices, out);
        }
        super::skin_wide(bind, weights, &groups.wide[batches..], palette.quaternions, out);
    }

    /// [`blend`] of a row of any length and order, `pivot` its heaviest influence's joint.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn blend_any(row: &[Influence], pivot: u16, palette: &Palette) -> __m256 {
        let (flipped, mask) = palette.flipped(pivot as usize);
        let term = |i: &Influence| {
            let q = &flipped[i.joint as usize & mask];
            (_mm256_set1_ps(i.weight), _mm256_set_m128(q.dual.into(), q.real.into()))
        };
        // Two sums (even and odd influences) halve the chain of dependent multiply-adds.
        let (mut even, mut odd) = (_mm256_setzero_ps(), _mm256_setzero_ps());
        let pairs = row.chunks_exact(2);
        if let [last] = pairs.remainder() {
            let (w, q) = term(last);
            even = _mm256_mul_ps(w, q);
        }
        for pair in pairs {
            let ((w0, q0), (w1, q1)) = (term(&pair[0]), term(&pair[1]));
            even = _mm256_fmadd_ps(w0, q0, even);
            odd = _mm256_fmadd_ps(w1, q1, odd);
        }
        _mm256_add_ps(even, odd)
    }

    /// One row's blend `Σ wₖ qₖ` (real parts in the low half, dual in the high), each
    /// `qₖ` in the hemisphere of the row's heaviest influence (its first).
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn blend<const K: usize>(joints: &[u16], weights: &[f32], palette: &Palette) -> __m256 {
        let (flipped, mask) = palette.flipped(joints[0] as usize);
        let mut sum = _mm256_setzero_ps();
        for k in 0..K {
            let q = &flipped[joints[k] as usize & mask];
            sum = _mm256_fmadd_ps(_mm256_set1_ps(weights[k]), _mm256_set_m128(q.dual.into(), q.real.into()), sum);
        }
        sum
    }

    /// Normalises eight blends (as [`transpose_eight`] gives them) and applies them to eight
    /// points (x, y and z registers), one vertex per lane.
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

    /// The bind positions of eight vertices anywhere as x, y and z registers.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn gather(bind: &[Vec3], vertices: &[u32; 8]) -> [__m256; 3] {
        let points: [Vec4; 8] = std::array::from_fn(|i| bind[vertices[i] as usize].extend(0.0));
        let [x, y, z, _] = lanes(std::array::from_fn(|i| &points[i]));
        [x, y, z]
    }

    /// Writes x, y and z registers to eight vertices anywhere.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn scatter(moved: [__m256; 3], vertices: &[u32; 8], out: &mut [Vec3]) {
        let mut lanes = [[0.0f32; 8]; 3];
        for c in 0..3 {
            // SAFETY: `lanes[c]` is eight f32s.
            unsafe { _mm256_storeu_ps(lanes[c].as_mut_ptr(), moved[c]) };
        }
        for (i, &v) in vertices.iter().enumerate() {
            out[v as usize] = Vec3::new(lanes[0][i], lanes[1][i], lanes[2][i]);
        }
    }

    /// Eight blended dual quaternions (one per register) as eight registers of eight lanes:
    /// the real part's x, y, z, w, then the dual part's; lane i holds vertex i.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn transpose_eight(q: [__m256; 8]) -> [__m256; 8] {
        let low = transpose(q[0], q[1], q[2], q[3]);
        let high = transpose(q[4], q[5], q[6], q[7]);
        [
            _mm256_permute2f128_ps::<0x20>(low[0], high[0]),
            _mm256_permute2f128_ps::<0x20>(low[1], high[1]),
            _mm256_permute2f128_ps::<0x20>(low[2], high[2]),
            _mm256_permute2f128_ps::<0x20>(low[3], high[3]),
            _mm256_permute2f128_ps::<0x31>(low[0], high[0]),
            _mm256_permute2f128_ps::<0x31>(low[1], high[1]),
            _mm256_permute2f128_ps::<0x31>(low[2], high[2]),
            _mm256_permute2f128_ps::<0x31>(low[3], high[3]),
        ]
    }

    /// Four quaternions, one per lane of each 128-bit half (`a`, `b`, `c`, `d` hold
    /// vertices 0..3 of the low half and 4..7 of the high one), as x, y, z, w registers.
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

    /// Eight quaternions (`real` or `dual` parts) as four registers of eight lanes: x, y,
    /// z, w; lane i holds quaternion i.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn lanes(q: [&Vec4; 8]) -> [__m256; 4] {
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

    /// Rows one vertex at a time (those left over from the batches of eight), in 128-bit
    /// registers: the hemisphere test by a broadcast dot product, the sign flipped into
    /// the weight, one reciprocal square root, then the rotation and translation together.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA. (Indices are checked.)
    #[target_feature(enable = "avx2,fma")]
    unsafe fn rows_one_by_one<const K: usize>(
        bind: &[Vec3],
        (vertices, joints, weights): (&[u32], &[u16], &[f32]),
        palette: &[DualQuat],
        out: &mut [Vec3],
    ) {
        let rows = joints.chunks_exact(K).zip(weights.chunks_exact(K));
        let sign = _mm_set1_ps(-0.0);
        for (&v, (joints, weights)) in vertices.iter().zip(rows) {
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
            // p' = p + 2 (r × u + w_r d - w_d r), with u = r × p + w_r p + d (the rotation
            // p + 2 r × (r × p + w_r p) and the translation 2 (w_r d - w_d r + r × d)).
            let u = _mm_add_ps(_mm_fmadd_ps(wr, p, cross(real, p)), dual);
            let rest = _mm_fmsub_ps(wr, dual, _mm_mul_ps(wd, real));
            let moved = _mm_fmadd_ps(_mm_set1_ps(2.0), _mm_add_ps(cross(real, u), rest), p);
            out[v as usize] = Vec4::from(moved).truncate();
        }
    }
}

//! 256-bit helpers the AVX2 kernels share (x86-64 only; callers check for AVX2 and FMA).
//!
//! The point shuffles are `unsafe` functions always inlined rather than `target_feature`
//! ones (which may not be `inline(always)`): with three kernels calling them, LLVM stopped
//! inlining `interleave`, and the call cost the LBS kernel a tenth of its time.
//! [`for_both_levels`] builds a kernel for AVX2 and again with AVX-512 VL (the DQ kernel;
//! the linear blend kernels have sixteen-lane AVX-512 versions of their own).

use std::arch::x86_64::*;

use glam::Vec3;

/// Eight points (24 floats) as six 128-bit registers, at any alignment: read and written
/// by value, without the precondition checks that the unaligned load and store intrinsics
/// make (through `copy_nonoverlapping`) when debug assertions are on.
#[repr(C, packed)]
#[derive(Clone, Copy)]
struct EightPoints([__m128; 6]);

const _: () = assert!(std::mem::size_of::<[Vec3; 8]>() == std::mem::size_of::<EightPoints>());

/// Eight points as x, y and z registers (lane i: point i).
///
/// # Safety
/// The CPU must have AVX2 (the callers are AVX2 kernels).
#[inline(always)]
pub unsafe fn deinterleave(points: &[Vec3]) -> [__m256; 3] {
    assert_eq!(points.len(), 8, "eight points");
    // SAFETY: `Vec3` is three f32s (`repr(C)`), so the eight are 24 in a row, read as
    // `EightPoints` (alignment 1); the CPU has AVX2 (this function's contract).
    unsafe {
        let [m0, m1, m2, m3, m4, m5] = (*(points.as_ptr() as *const EightPoints)).0;
        let (m03, m14, m25) = (_mm256_set_m128(m3, m0), _mm256_set_m128(m4, m1), _mm256_set_m128(m5, m2));
        let xy = _mm256_shuffle_ps::<0b10_01_11_10>(m14, m25);
        let yz = _mm256_shuffle_ps::<0b01_00_10_01>(m03, m14);
        [
            _mm256_shuffle_ps::<0b10_00_11_00>(m03, xy),
            _mm256_shuffle_ps::<0b11_01_10_00>(yz, xy),
            _mm256_shuffle_ps::<0b11_00_11_01>(yz, m25),
        ]
    }
}

/// Up to eight points as x, y and z registers (lane i: point i), zero in the lanes past
/// them.
#[inline(always)]
pub fn deinterleave_some(points: &[Vec3]) -> [__m256; 3] {
    let p: [Vec3; 8] = std::array::from_fn(|i| points.get(i).copied().unwrap_or_default());
    [p.map(|p| p.x), p.map(|p| p.y), p.map(|p| p.z)].map(register)
}

/// The inverse of [`deinterleave`]: x, y and z registers written as eight points.
///
/// # Safety
/// As [`deinterleave`].
#[inline(always)]
pub unsafe fn interleave([x, y, z]: [__m256; 3], points: &mut [Vec3]) {
    assert_eq!(points.len(), 8, "eight points");
    // SAFETY: as in `deinterleave`.
    unsafe {
        let xy = _mm256_shuffle_ps::<0b10_00_10_00>(x, y);
        let yz = _mm256_shuffle_ps::<0b11_01_11_01>(y, z);
        let zx = _mm256_shuffle_ps::<0b11_01_10_00>(z, x);
        let m03 = _mm256_shuffle_ps::<0b10_00_10_00>(xy, zx);
        let m14 = _mm256_shuffle_ps::<0b11_01_10_00>(yz, xy);
        let m25 = _mm256_shuffle_ps::<0b11_01_11_01>(zx, yz);
        let (lo, hi) = (_mm256_castps256_ps128, _mm256_extractf128_ps::<1>);
        *(points.as_mut_ptr() as *mut EightPoints) =
            EightPoints([lo(m03), lo(m14), lo(m25), hi(m03), hi(m14), hi(m25)]);
    }
}

/// How far ahead of the block it skins a kernel asks for bind positions and output (in
/// vertices). In a crowd each body's positions are cold (drawing on llvmpipe evicts the
/// caches between frames) and the hardware prefetcher starts late on each body's short run:
/// asking 128 vertices ahead took 8 % off the crowd's cold kernel at 64 bodies on both
/// cores and 13 % at 256 (medians of three interleaved runs: 0.75 -> 0.69 ms, 2.82 ->
/// 2.46 ms).
pub const PREFETCH_AHEAD: usize = 128;

/// Asks for the cache lines of the `lanes` vertices [`PREFETCH_AHEAD`] past bind position
/// `bind_at` and output `out_at` (the output's to be written). Only hints: an address past
/// either buffer is never read.
#[inline(always)]
pub fn prefetch_ahead(bind: &[Vec3], bind_at: usize, out: &[Vec3], out_at: usize, lanes: usize) {
    let bind = bind.as_ptr().wrapping_add(bind_at + PREFETCH_AHEAD) as *const i8;
    let out = out.as_ptr().wrapping_add(out_at + PREFETCH_AHEAD) as *const i8;
    for line in (0..lanes * std::mem::size_of::<Vec3>()).step_by(64) {
        // SAFETY: prefetches are hints that never fault (SSE, part of x86-64).
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(bind.wrapping_add(line));
            _mm_prefetch::<_MM_HINT_ET0>(out.wrapping_add(line));
        }
    }
}

/// Eight floats as a register (lane i: float i).
#[inline]
pub fn register(lanes: [f32; 8]) -> __m256 {
    // SAFETY: eight `f32`s are an `__m256`, any bits a valid one.
    unsafe { std::mem::transmute(lanes) }
}

/// A register's eight floats.
#[inline]
pub fn floats(r: __m256) -> [f32; 8] {
    // SAFETY: as in `register`.
    unsafe { std::mem::transmute(r) }
}

/// Defines `$name(simd, args…)`: the always-inlined kernel `$body` compiled for AVX2 + FMA
/// and again with AVX-512 F and VL, the build run chosen by `simd`.
///
/// The kernels are written with AVX2 intrinsics; built with AVX-512 VL as well, LLVM folds
/// each broadcast of a palette element into the multiply-add that reads it and has 32
/// registers, which saved a tenth to a fifth of each kernel's time.
macro_rules! for_both_levels {
    ($(#[$attr:meta])* $vis:vis unsafe fn $name:ident = $body:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)?) => {
        $(#[$attr])*
        ///
        /// # Safety
        /// The CPU must run `simd` (`Simd::is_available`), which is `Avx2` or `Avx512Vl`.
        $vis unsafe fn $name(simd: crate::simd::Simd, $($arg: $ty),*) $(-> $ret)? {
            #[target_feature(enable = "avx2,fma")]
            unsafe fn avx2($($arg: $ty),*) $(-> $ret)? {
                // SAFETY: the CPU has AVX2 and FMA (this function's features).
                unsafe { $body($($arg),*) }
            }
            #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
            unsafe fn avx512($($arg: $ty),*) $(-> $ret)? {
                // SAFETY: as above; the CPU also has AVX-512 F and VL.
                unsafe { $body($($arg),*) }
            }
            debug_assert!(simd != crate::simd::Simd::Portable, "a SIMD level");
            if simd == crate::simd::Simd::Avx512Vl {
                // SAFETY: the CPU runs `simd` (this function's contract).
                unsafe { avx512($($arg),*) }
            } else {
                // SAFETY: as above.
                unsafe { avx2($($arg),*) }
            }
        }
    };
}
pub(crate) use for_both_levels;

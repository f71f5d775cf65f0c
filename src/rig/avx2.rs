//! 256-bit helpers the AVX2 kernels share (x86-64 only; callers check for AVX2 and FMA).
//!
//! The point shuffles are `unsafe` functions always inlined rather than `target_feature`
//! ones (which may not be `inline(always)`): with three kernels calling them, LLVM stopped
//! inlining `interleave`, and the call cost the LBS kernel a tenth of its time.

use std::arch::x86_64::*;

use glam::{Vec3, Vec4};

// `deinterleave` and `interleave` read eight `Vec3`s as 24 f32s.
const _: () = assert!(std::mem::size_of::<[Vec3; 8]>() == std::mem::size_of::<[f32; 24]>());

/// Eight points as x, y and z registers (lane i: point i).
///
/// # Safety
/// The CPU must have AVX2 (the callers are AVX2 kernels).
#[inline(always)]
pub unsafe fn deinterleave(points: &[Vec3]) -> [__m256; 3] {
    assert_eq!(points.len(), 8, "eight points");
    // SAFETY: `Vec3` is three f32s (`repr(C)`), so the eight are 24 in a row; the CPU has
    // AVX2 (this function's contract).
    unsafe {
        let f: &[f32; 24] = &*(points.as_ptr() as *const [f32; 24]);
        let m03 = _mm256_set_m128(Vec4::from_slice(&f[12..]).into(), Vec4::from_slice(&f[..4]).into());
        let m14 = _mm256_set_m128(Vec4::from_slice(&f[16..]).into(), Vec4::from_slice(&f[4..]).into());
        let m25 = _mm256_set_m128(Vec4::from_slice(&f[20..]).into(), Vec4::from_slice(&f[8..]).into());
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
        let f: &mut [f32; 24] = &mut *(points.as_mut_ptr() as *mut [f32; 24]);
        Vec4::from(_mm256_castps256_ps128(m03)).write_to_slice(&mut f[..4]);
        Vec4::from(_mm256_castps256_ps128(m14)).write_to_slice(&mut f[4..]);
        Vec4::from(_mm256_castps256_ps128(m25)).write_to_slice(&mut f[8..]);
        Vec4::from(_mm256_extractf128_ps::<1>(m03)).write_to_slice(&mut f[12..]);
        Vec4::from(_mm256_extractf128_ps::<1>(m14)).write_to_slice(&mut f[16..]);
        Vec4::from(_mm256_extractf128_ps::<1>(m25)).write_to_slice(&mut f[20..]);
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

//! The registers the linear blend kernels are written over, one vertex a lane: `__m256`
//! (eight lanes, AVX2 and FMA) and `__m512` (sixteen, AVX-512 F), each with the weights of
//! its blocks ([`JointBlocks`](super::influences::JointBlocks)). One generic body of each
//! kernel serves both widths (x86-64 only).

use std::arch::x86_64::*;

use glam::Vec3;

use super::influences::{LaneWeights, WideLaneWeights};

/// A register of [`Self::LANES`] floats as the kernels use it.
///
/// # Safety
/// Implementors' methods use intrinsics of their width: they may be called only where the
/// CPU has its features (inside the kernels built for them), which is why most are
/// `unsafe`; they are always inlined into those kernels.
pub unsafe trait Lanes: Copy {
    /// Vertices a register holds.
    const LANES: usize;
    /// One joint's weights on a block's vertices.
    type Weights;

    /// `x` in every lane.
    unsafe fn splat(x: f32) -> Self;
    /// `a · b + c`, lane by lane, rounded once.
    unsafe fn fmadd(a: Self, b: Self, c: Self) -> Self;
    /// `a · b`, lane by lane.
    unsafe fn mul(a: Self, b: Self) -> Self;
    /// The smaller of `a` and `b`, lane by lane.
    unsafe fn min(a: Self, b: Self) -> Self;
    /// The larger of `a` and `b`, lane by lane.
    unsafe fn max(a: Self, b: Self) -> Self;
    /// The weights as a register.
    fn weights(w: &Self::Weights) -> Self;
    /// Lane `i`'s float.
    fn lane(self, i: usize) -> f32;
    /// [`Self::LANES`] points as x, y and z registers (lane i: point i).
    unsafe fn points(points: &[Vec3]) -> [Self; 3];
    /// Up to [`Self::LANES`] points so, zero in the lanes past them.
    fn some_points(points: &[Vec3]) -> [Self; 3];
    /// x, y and z registers written as [`Self::LANES`] points.
    unsafe fn write_points(p: [Self; 3], out: &mut [Vec3]);
}

// SAFETY: each method uses AVX2 / FMA intrinsics only (see the trait).
unsafe impl Lanes for __m256 {
    const LANES: usize = 8;
    type Weights = LaneWeights;

    #[inline(always)]
    unsafe fn splat(x: f32) -> Self {
        unsafe { _mm256_set1_ps(x) }
    }
    #[inline(always)]
    unsafe fn fmadd(a: Self, b: Self, c: Self) -> Self {
        unsafe { _mm256_fmadd_ps(a, b, c) }
    }
    #[inline(always)]
    unsafe fn mul(a: Self, b: Self) -> Self {
        unsafe { _mm256_mul_ps(a, b) }
    }
    #[inline(always)]
    unsafe fn min(a: Self, b: Self) -> Self {
        unsafe { _mm256_min_ps(a, b) }
    }
    #[inline(always)]
    unsafe fn max(a: Self, b: Self) -> Self {
        unsafe { _mm256_max_ps(a, b) }
    }
    #[inline(always)]
    fn weights(w: &LaneWeights) -> Self {
        super::avx2::register(w.0)
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f32 {
        super::avx2::floats(self)[i]
    }
    #[inline(always)]
    unsafe fn points(points: &[Vec3]) -> [Self; 3] {
        unsafe { super::avx2::deinterleave(points) }
    }
    #[inline(always)]
    fn some_points(points: &[Vec3]) -> [Self; 3] {
        super::avx2::deinterleave_some(points)
    }
    #[inline(always)]
    unsafe fn write_points(p: [Self; 3], out: &mut [Vec3]) {
        unsafe { super::avx2::interleave(p, out) }
    }
}

// SAFETY: each method uses AVX-512 F intrinsics only (see the trait).
unsafe impl Lanes for __m512 {
    const LANES: usize = 16;
    type Weights = WideLaneWeights;

    #[inline(always)]
    unsafe fn splat(x: f32) -> Self {
        unsafe { _mm512_set1_ps(x) }
    }
    #[inline(always)]
    unsafe fn fmadd(a: Self, b: Self, c: Self) -> Self {
        unsafe { _mm512_fmadd_ps(a, b, c) }
    }
    #[inline(always)]
    unsafe fn mul(a: Self, b: Self) -> Self {
        unsafe { _mm512_mul_ps(a, b) }
    }
    #[inline(always)]
    unsafe fn min(a: Self, b: Self) -> Self {
        unsafe { _mm512_min_ps(a, b) }
    }
    #[inline(always)]
    unsafe fn max(a: Self, b: Self) -> Self {
        unsafe { _mm512_max_ps(a, b) }
    }
    #[inline(always)]
    fn weights(w: &WideLaneWeights) -> Self {
        super::avx512::register(w.0)
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f32 {
        super::avx512::floats(self)[i]
    }
    #[inline(always)]
    unsafe fn points(points: &[Vec3]) -> [Self; 3] {
        unsafe { super::avx512::deinterleave(points) }
    }
    #[inline(always)]
    fn some_points(points: &[Vec3]) -> [Self; 3] {
        super::avx512::deinterleave_some(points)
    }
    #[inline(always)]
    unsafe fn write_points(p: [Self; 3], out: &mut [Vec3]) {
        unsafe { super::avx512::interleave(p, out) }
    }
}

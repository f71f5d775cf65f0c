//! 512-bit helpers for the AVX-512 kernels (x86-64 only; callers check for AVX-512 F):
//! sixteen points between their interleaved form and x, y and z registers, one point a
//! lane. As in [`super::avx2`], the shuffles are always-inlined `unsafe` functions rather
//! than `target_feature` ones, so that they inline into every kernel.

use std::arch::x86_64::*;

use glam::Vec3;

/// How many points a register holds (one a lane).
const LANES: usize = 16;

/// Sixteen points (48 floats) as three 512-bit registers, at any alignment (read and written
/// by value, as `avx2`'s `EightPoints`).
#[repr(C, packed)]
#[derive(Clone, Copy)]
struct SixteenPoints([__m512; 3]);

const _: () = assert!(std::mem::size_of::<[Vec3; LANES]>() == std::mem::size_of::<SixteenPoints>());

/// The two `vpermt2ps` index vectors that gather coordinate `k` of sixteen interleaved points
/// from registers holding floats 0–15, 16–31 and 32–47: the first takes floats below 32 from
/// the first two registers, the second keeps them and takes the rest from the third.
const fn gather_indices(k: usize) -> [[i32; LANES]; 2] {
    let mut idx = [[0; LANES]; 2];
    let mut lane = 0;
    while lane < LANES {
        let float = 3 * lane + k;
        if float < 32 {
            (idx[0][lane], idx[1][lane]) = (float as i32, lane as i32);
        } else {
            idx[1][lane] = (16 + float - 32) as i32;
        }
        lane += 1;
    }
    idx
}

/// The two `vpermt2ps` index vectors that write floats `16r..16r + 16` of sixteen interleaved
/// points from their x, y and z registers: the first takes x and y, the second keeps them
/// and takes z.
const fn scatter_indices(r: usize) -> [[i32; LANES]; 2] {
    let mut idx = [[0; LANES]; 2];
    let mut lane = 0;
    while lane < LANES {
        let (point, k) = ((16 * r + lane) / 3, (16 * r + lane) % 3);
        (idx[0][lane], idx[1][lane]) = match k {
            0 => (point as i32, lane as i32),
            1 => (16 + point as i32, lane as i32),
            _ => (0, 16 + point as i32),
        };
        lane += 1;
    }
    idx
}

const GATHER: [[[i32; LANES]; 2]; 3] = [gather_indices(0), gather_indices(1), gather_indices(2)];
const SCATTER: [[[i32; LANES]; 2]; 3] = [scatter_indices(0), scatter_indices(1), scatter_indices(2)];

/// Sixteen 32-bit lanes as an index register.
#[inline(always)]
fn indices(lanes: [i32; LANES]) -> __m512i {
    // SAFETY: sixteen `i32`s are an `__m512i`, any bits a valid one.
    unsafe { std::mem::transmute(lanes) }
}

/// Sixteen points as x, y and z registers (lane i: point i).
///
/// # Safety
/// The CPU must have AVX-512 F (the callers are AVX-512 kernels).
#[inline(always)]
pub unsafe fn deinterleave(points: &[Vec3]) -> [__m512; 3] {
    assert_eq!(points.len(), LANES, "sixteen points");
    // SAFETY: `Vec3` is three f32s (`repr(C)`), so the sixteen are 48 in a row, read as
    // `SixteenPoints` (alignment 1); the CPU has AVX-512 F (this function's contract).
    unsafe {
        let [a, b, c] = (*(points.as_ptr() as *const SixteenPoints)).0;
        GATHER.map(|[first, second]| {
            _mm512_permutex2var_ps(_mm512_permutex2var_ps(a, indices(first), b), indices(second), c)
        })
    }
}

/// The inverse of [`deinterleave`]: x, y and z registers written as sixteen points.
///
/// # Safety
/// As [`deinterleave`].
#[inline(always)]
pub unsafe fn interleave([x, y, z]: [__m512; 3], points: &mut [Vec3]) {
    assert_eq!(points.len(), LANES, "sixteen points");
    // SAFETY: as in `deinterleave`.
    unsafe {
        let floats = SCATTER.map(|[first, second]| {
            _mm512_permutex2var_ps(_mm512_permutex2var_ps(x, indices(first), y), indices(second), z)
        });
        *(points.as_mut_ptr() as *mut SixteenPoints) = SixteenPoints(floats);
    }
}

/// Up to sixteen points as x, y and z registers, zero in the lanes past them.
#[inline(always)]
pub fn deinterleave_some(points: &[Vec3]) -> [__m512; 3] {
    let p: [Vec3; LANES] = std::array::from_fn(|i| points.get(i).copied().unwrap_or_default());
    [p.map(|p| p.x), p.map(|p| p.y), p.map(|p| p.z)].map(register)
}

/// Sixteen floats as a register (lane i: float i).
#[inline(always)]
pub fn register(lanes: [f32; LANES]) -> __m512 {
    // SAFETY: sixteen `f32`s are an `__m512`, any bits a valid one.
    unsafe { std::mem::transmute(lanes) }
}

/// A register's sixteen floats.
#[inline(always)]
pub fn floats(r: __m512) -> [f32; LANES] {
    // SAFETY: as in `register`.
    unsafe { std::mem::transmute(r) }
}

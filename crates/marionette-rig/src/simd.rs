//! The instruction sets the fast skinning kernels are compiled for, chosen at run time:
//! [`Simd::best`] is what the CPU has, and every level it has can be asked for by name (the
//! tests check each against the plain loop).

/// A level of the skinning kernels, best first.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Simd {
    /// AVX-512: the linear blend kernels sixteen vertices a block on 512-bit registers;
    /// the dual quaternion kernel is the AVX2 one built with AVX-512 F and VL as well (each
    /// palette element broadcast inside the multiply-add that reads it, 32 registers).
    Avx512Vl,
    /// Eight lanes of 256 bits, AVX2 and FMA.
    Avx2,
    /// Vertex by vertex with glam's `Vec4`, on any target.
    Portable,
}

impl Simd {
    /// All the levels, best first.
    pub const ALL: [Simd; 3] = [Simd::Avx512Vl, Simd::Avx2, Simd::Portable];

    /// Whether this CPU runs the level.
    pub fn is_available(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            match self {
                Simd::Avx512Vl => has!("avx2") && has!("fma") && has!("avx512f") && has!("avx512vl"),
                Simd::Avx2 => has!("avx2") && has!("fma"),
                Simd::Portable => true,
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            self == Simd::Portable
        }
    }

    /// The best level this CPU runs.
    pub fn best() -> Self {
        Self::ALL.into_iter().find(|s| s.is_available()).unwrap_or(Simd::Portable)
    }

    /// The levels this CPU runs, best first.
    pub fn available() -> impl Iterator<Item = Simd> {
        Self::ALL.into_iter().filter(|s| s.is_available())
    }
}

//! Which instruction sets the running CPU has. Detection lives here, under everything
//! that chooses a code path by it (the draw loop's copies, the glyph fit), so `simd`
//! depends on nothing else in the crate.

/// Which instructions the draw loop is compiled for. All give identical bits: only
/// instruction selection differs (fused multiply-adds are written as such and are
/// correctly rounded on every one), nothing is reordered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// The build's target (baseline x86-64: 8-lane types run as two SSE halves).
    Baseline,
    /// x86-64 with AVX2 and FMA (and the POPCNT and BMI1 that every AVX2 CPU has, for
    /// the per-group fragment counts and lane loops), chosen at run time when the CPU
    /// has them.
    Avx2,
    /// The loop on 16-lane `zmm` registers with AVX-512 (F, VL, BW, DQ): a group is two
    /// rows of 8 pixels, so the dense meshes' small triangles take half the groups, and
    /// each group has 32 vector registers for its per-triangle constants and mask
    /// registers for its compares, blends and masked stores. The renderer builds it
    /// only for the copies where it pays (see `crate::render`).
    Avx512,
}

impl Isa {
    /// Every instruction set, from the most widely available.
    pub const ALL: [Isa; 3] = [Isa::Baseline, Isa::Avx2, Isa::Avx512];

    /// The best the running CPU supports.
    #[must_use]
    pub fn detect() -> Self {
        Self::ALL
            .into_iter()
            .rev()
            .find(|isa| isa.is_supported())
            .unwrap_or(Isa::Baseline)
    }

    /// The instruction sets the running CPU supports (always including the baseline).
    pub fn supported() -> impl Iterator<Item = Isa> {
        Self::ALL.into_iter().filter(|isa| isa.is_supported())
    }

    /// Whether the running CPU has what this instruction set is compiled for.
    #[must_use]
    pub fn is_supported(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            let avx2 = || has!("avx2") && has!("fma") && has!("popcnt") && has!("bmi1");
            match self {
                Isa::Baseline => true,
                Isa::Avx2 => avx2(),
                Isa::Avx512 => {
                    avx2()
                        && has!("avx512f")
                        && has!("avx512vl")
                        && has!("avx512bw")
                        && has!("avx512dq")
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            self == Isa::Baseline
        }
    }

    /// The name used on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Isa::Baseline => "baseline",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }
}

/// Asks the CPU to bring every cache line of `value` towards this core, without
/// waiting for it: a hint that changes no result. A threaded walk reads each set-up
/// record (several lines, written by another core) only once, so it asks for the next
/// record while it walks the current one.
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let start = std::ptr::from_ref(value).cast::<i8>();
        // From the line holding the first byte: a value that does not start a line
        // reaches one line further than its size.
        let lead = start.addr() % 64;
        let line = start.wrapping_sub(lead);
        for offset in (0..lead + size_of::<T>()).step_by(64) {
            // SAFETY: SSE is part of x86-64, and a prefetch never faults (each address
            // lies in a line that holds part of `value` anyway).
            unsafe { _mm_prefetch::<_MM_HINT_T0>(line.wrapping_add(offset)) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

//! The instruction sets the draw loop is compiled for, and the copies of the loop
//! built for each.
//!
//! Each copy is a free function in its own module on purpose: the compiler splits a
//! crate into code-generation units by module (a method goes with its type's module),
//! so with an explicit unit count (see `Cargo.toml`) the baseline, AVX2 and AVX-512
//! copies of every shader's draw loop, most of the crate's machine code, are
//! optimised in parallel instead of in one unit.

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
    /// rows of 8 pixels, so the dense meshes' small triangles take half the groups
    /// (the 65k sphere at 1080p: 297k instead of 579k), and each group has 32 vector
    /// registers for its per-triangle constants and mask registers for its compares,
    /// blends and masked stores. Built only for shaders with lane code of their own
    /// ([`crate::render::Shader::LANE_CODE`]) and the default state
    /// (depth `Less` with writes, perspective-correct) with the `wide` traversal, the
    /// path that matters for speed: other draws run the AVX2 copy, which keeps the
    /// build (and the tests' build) from compiling the whole loop a third time.
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

/// The baseline copy: the build's own target, for CPUs without AVX2.
pub(super) mod baseline {
    use crate::render::{ColorTarget, DrawOptions, Renderer, Shader, VertexCache};

    /// The draw loop on [`wide`]'s portable lanes.
    pub(in crate::render) fn draw<S: Shader, C: ColorTarget>(
        r: &mut Renderer,
        shader: &S,
        cache: &VertexCache<S::Varying>,
        indices: &[u32],
        opts: &DrawOptions,
        color: &mut C,
    ) {
        r.draw_triangles::<_, _, wide::i32x8, false>(shader, cache, indices, opts, color);
    }
}

/// The AVX2 copy.
#[cfg(target_arch = "x86_64")]
pub(super) mod avx2 {
    use crate::render::{ColorTarget, DrawOptions, Renderer, Shader, VertexCache};

    /// The draw loop compiled with AVX2 and FMA enabled and on [`crate::simd`]'s AVX2
    /// lanes, so 8-lane values are one 256-bit register instead of two 128-bit halves
    /// and `mul_add` is one instruction. Only the instruction selection differs: no
    /// operation is fused or reordered beyond what the code says, so the output is
    /// bit-identical to the baseline path (the tests compare both).
    ///
    /// # Safety
    /// The CPU must have AVX2, FMA, POPCNT and BMI1 ([`super::Isa::Avx2`]).
    #[target_feature(enable = "avx2,fma,popcnt,bmi1")]
    pub(in crate::render) unsafe fn draw<S: Shader, C: ColorTarget>(
        r: &mut Renderer,
        shader: &S,
        cache: &VertexCache<S::Varying>,
        indices: &[u32],
        opts: &DrawOptions,
        color: &mut C,
    ) {
        r.draw_triangles::<_, _, crate::simd::avx2::I32x8, false>(
            shader, cache, indices, opts, color,
        );
    }
}

/// The AVX-512 copy, for the default state with the `wide` traversal only.
#[cfg(target_arch = "x86_64")]
pub(super) mod avx512 {
    use crate::render::{ColorTarget, DrawOptions, Renderer, Shader, VertexCache};

    /// [`super::avx2::draw`]'s loop on 16 AVX-512 lanes in two-row groups (see
    /// [`super::Isa::Avx512`]): the same operations per lane, so the same bits.
    ///
    /// # Safety
    /// The CPU must have what [`super::Isa::Avx512`] names.
    #[target_feature(enable = "avx2,fma,popcnt,bmi1,avx512f,avx512vl,avx512bw,avx512dq")]
    pub(in crate::render) unsafe fn draw<S: Shader, C: ColorTarget>(
        r: &mut Renderer,
        shader: &S,
        cache: &VertexCache<S::Varying>,
        indices: &[u32],
        opts: &DrawOptions,
        color: &mut C,
    ) {
        r.draw_triangles::<_, _, crate::simd::avx512::I32x16, true>(
            shader, cache, indices, opts, color,
        );
    }
}

//! The copies of the draw loop: instruction sets ([`Isa`]) × variants
//! ([`DrawVariant`]), and [`DrawCopy::choose`], the one function that picks a copy
//! for a draw (the table of what is compiled is in [`crate::render`]'s module doc).
//!
//! Each instruction set's copy is a free function in its own module on purpose: the
//! compiler splits a crate into code-generation units by module (a method goes with
//! its type's module), so with an explicit unit count (see `Cargo.toml`) the
//! baseline, AVX2 and AVX-512 copies of every shader's draw loop, most of the crate's
//! machine code, are optimised in parallel instead of in one unit.

use super::options::DrawOptions;
use super::shader::Shader;
use super::target::ColorTarget;
use super::tiles;
use super::{Renderer, VertexCache};
use crate::raster::Traversal;
use crate::raster::depth::DepthState;
use crate::raster::interp::Interpolation;
pub use crate::simd::Isa;

/// What a copy of the draw loop fixes at compile time. Implemented by three
/// zero-sized types, [`Generic`], [`Standard`] and [`Fast`]; the draw loop is generic
/// over one of them, so an option that is a constant costs no check per group.
pub trait DrawVariant {
    /// Depth test `Less` with writes and perspective-correct interpolation are
    /// constants, whatever [`DrawOptions`] says.
    const STANDARD_STATE: bool;
    /// The traversal is `wide`, whatever [`DrawOptions::traversal`] says.
    const WIDE_ONLY: bool;

    /// Whether a draw with `opts` may run on this variant (it draws them as they say).
    #[inline(always)]
    #[must_use]
    fn admits(opts: &DrawOptions) -> bool {
        let standard =
            opts.depth == DepthState::default() && opts.interpolation == Interpolation::Perspective;
        (!Self::STANDARD_STATE || standard)
            && (!Self::WIDE_ONLY || opts.traversal == Traversal::Wide)
    }

    /// The depth state and interpolation a draw with `opts` runs with on this variant:
    /// constants when [`DrawVariant::STANDARD_STATE`].
    #[inline(always)]
    #[must_use]
    fn state(opts: &DrawOptions) -> (DepthState, Interpolation) {
        if Self::STANDARD_STATE {
            (DepthState::default(), Interpolation::Perspective)
        } else {
            (opts.depth, opts.interpolation)
        }
    }
}

/// Reads every option at run time: any depth state, interpolation and traversal.
#[derive(Clone, Copy, Debug)]
pub struct Generic;

/// The viewer's and the benchmark's state (depth `Less` with writes,
/// perspective-correct interpolation) as constants, any traversal.
#[derive(Clone, Copy, Debug)]
pub struct Standard;

/// [`Standard`] with the `wide` traversal: the one path the AVX-512 copy is built for.
#[derive(Clone, Copy, Debug)]
pub struct Fast;

impl DrawVariant for Generic {
    const STANDARD_STATE: bool = false;
    const WIDE_ONLY: bool = false;
}

impl DrawVariant for Standard {
    const STANDARD_STATE: bool = true;
    const WIDE_ONLY: bool = false;
}

impl DrawVariant for Fast {
    const STANDARD_STATE: bool = true;
    const WIDE_ONLY: bool = true;
}

/// Which [`DrawVariant`] a draw runs, as a value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// [`Generic`].
    Generic,
    /// [`Standard`].
    Standard,
    /// [`Fast`].
    Fast,
}

/// The compiled copy of the draw loop a draw runs on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawCopy {
    pub isa: Isa,
    pub variant: Variant,
}

impl DrawCopy {
    /// The copy for a draw of shader `S` with `opts` into a target `width` pixels wide,
    /// preferring instruction set `isa`: the most specialised variant that admits the
    /// options, on `isa` if the CPU has it and that copy is compiled, else the next
    /// instruction set down. The only place that decides; see the table in
    /// [`crate::render`].
    #[must_use]
    pub fn choose<S: Shader>(isa: Isa, opts: &DrawOptions, width: u32) -> Self {
        let variant = if Fast::admits(opts) {
            Variant::Fast
        } else if Standard::admits(opts) {
            Variant::Standard
        } else {
            Variant::Generic
        };
        // Two-row groups have no per-pixel fallback for groups past the target's edge,
        // so AVX-512 needs a target at least a group wide.
        let avx512 = S::LANE_CODE && variant == Variant::Fast && width >= 8;
        let isa = match isa {
            Isa::Avx512 if avx512 && Isa::Avx512.is_supported() => Isa::Avx512,
            Isa::Avx2 | Isa::Avx512 if Isa::Avx2.is_supported() => Isa::Avx2,
            _ => Isa::Baseline,
        };
        let variant = match variant {
            // On x86_64 the baseline copy serves only CPUs without AVX2, and is built
            // for `Generic` alone, which keeps the build short.
            _ if isa == Isa::Baseline && cfg!(target_arch = "x86_64") => Variant::Generic,
            Variant::Fast if isa != Isa::Avx512 => Variant::Standard,
            v => v,
        };
        Self { isa, variant }
    }
}

/// Runs `copy` (from [`DrawCopy::choose`]): the one match from the table's cells to
/// the compiled functions.
#[inline(always)]
pub(super) fn run<S: Shader, C: ColorTarget>(
    copy: DrawCopy,
    r: &mut Renderer,
    shader: &S,
    cache: &VertexCache<S::Varying>,
    indices: &[u32],
    opts: &DrawOptions,
    color: &mut C,
) {
    // `S::THREADED` first, as its own condition: a constant `false` keeps the threaded
    // copies from being compiled for the shader.
    if S::THREADED && r.spread() != super::Spread::One {
        run_tiled(copy, r, shader, cache, indices, opts, color);
        return;
    }
    #[cfg(target_arch = "x86_64")]
    {
        // `S::LANE_CODE` first, as its own condition: a constant `false` there keeps
        // the compiler from building the AVX-512 copy for this shader at all.
        if S::LANE_CODE && copy.isa == Isa::Avx512 {
            // SAFETY: `choose` picks an instruction set only when the CPU has it.
            unsafe { avx512::draw(r, shader, cache, indices, opts, color) };
            return;
        }
        if copy.isa != Isa::Baseline {
            // SAFETY: as above; AVX-512 implies AVX2.
            unsafe {
                match copy.variant {
                    Variant::Generic => {
                        avx2::draw::<Generic, _, _>(r, shader, cache, indices, opts, color)
                    }
                    Variant::Standard | Variant::Fast => {
                        avx2::draw::<Standard, _, _>(r, shader, cache, indices, opts, color);
                    }
                }
            }
            return;
        }
    }
    #[cfg(target_arch = "x86_64")]
    baseline::draw::<Generic, _, _>(r, shader, cache, indices, opts, color);
    #[cfg(not(target_arch = "x86_64"))]
    match copy.variant {
        Variant::Generic => baseline::draw::<Generic, _, _>(r, shader, cache, indices, opts, color),
        Variant::Standard | Variant::Fast => {
            baseline::draw::<Standard, _, _>(r, shader, cache, indices, opts, color);
        }
    }
}

/// [`run`] on the renderer's threads (see [`tiles`]): the same copy of the draw
/// loop, walking bands of rows.
#[inline(always)]
fn run_tiled<S: Shader, C: ColorTarget>(
    copy: DrawCopy,
    r: &mut Renderer,
    shader: &S,
    cache: &VertexCache<S::Varying>,
    indices: &[u32],
    opts: &DrawOptions,
    color: &mut C,
) {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY (all three): `choose` picks an instruction set only when the CPU has it.
        if S::LANE_CODE && copy.isa == Isa::Avx512 {
            unsafe { tiles::draw::<avx512::Tiled, _, _>(r, shader, cache, indices, opts, color) };
            return;
        }
        if copy.isa != Isa::Baseline {
            unsafe {
                match copy.variant {
                    Variant::Generic => tiles::draw::<avx2::Tiled<Generic>, _, _>(
                        r, shader, cache, indices, opts, color,
                    ),
                    Variant::Standard | Variant::Fast => {
                        tiles::draw::<avx2::Tiled<Standard>, _, _>(
                            r, shader, cache, indices, opts, color,
                        )
                    }
                }
            }
            return;
        }
    }
    // SAFETY: the baseline copy runs on every CPU.
    #[cfg(target_arch = "x86_64")]
    unsafe {
        tiles::draw::<baseline::Tiled<Generic>, _, _>(r, shader, cache, indices, opts, color);
    }
    // SAFETY: as above.
    #[cfg(not(target_arch = "x86_64"))]
    unsafe {
        match copy.variant {
            Variant::Generic => {
                tiles::draw::<baseline::Tiled<Generic>, _, _>(
                    r, shader, cache, indices, opts, color,
                );
            }
            Variant::Standard | Variant::Fast => {
                tiles::draw::<baseline::Tiled<Standard>, _, _>(
                    r, shader, cache, indices, opts, color,
                );
            }
        }
    }
}

/// The baseline copy: the build's own target, for CPUs without AVX2.
pub(super) mod baseline {
    use std::marker::PhantomData;
    use std::ops::Range;

    use super::DrawVariant;
    use glam::Vec3;

    use crate::raster::depth::DepthRows;
    use crate::render::options::DrawStats;
    use crate::render::target::SplitOff;
    use crate::render::tiles::strips::{self, Handover, Part, StripPlan};
    use crate::render::tiles::{self, Chunk, Job, TileCopy};
    use crate::render::{ColorTarget, DrawOptions, Renderer, Shader, VertexCache};

    /// The threaded draw's steps of variant `V` on [`wide`]'s portable lanes.
    pub(in crate::render) struct Tiled<V>(PhantomData<V>);

    impl<V: DrawVariant> TileCopy for Tiled<V> {
        unsafe fn setup<S: Shader>(
            job: &Job<'_, S>,
            range: Range<u32>,
            chunk: &mut Chunk<S::Varying>,
        ) {
            tiles::setup_chunk(job, range, chunk);
        }
        unsafe fn walk<S: Shader, C: ColorTarget>(
            job: &Job<'_, S>,
            chunks: &[Chunk<S::Varying>],
            band: usize,
            color: &mut C,
            depth: &mut DepthRows<'_>,
            clear: Option<Vec3>,
        ) -> DrawStats {
            tiles::walk_band::<V, S, C, wide::i32x8>(job, chunks, band, color, depth, clear)
        }
        unsafe fn strip<'d, S: Shader, C: ColorTarget + SplitOff>(
            job: &Job<'_, S>,
            plan: &StripPlan<'_>,
            part: &mut Part<'d, C>,
            handover: &Handover<'d, C>,
            clear: Option<Vec3>,
        ) -> DrawStats {
            strips::draw_strip::<V, S, C, wide::i32x8>(job, plan, part, handover, clear)
        }
    }

    /// The draw loop of variant `V` on [`wide`]'s portable lanes.
    pub(in crate::render) fn draw<V: DrawVariant, S: Shader, C: ColorTarget>(
        r: &mut Renderer,
        shader: &S,
        cache: &VertexCache<S::Varying>,
        indices: &[u32],
        opts: &DrawOptions,
        color: &mut C,
    ) {
        r.draw_triangles::<V, _, _, wide::i32x8>(shader, cache, indices, opts, color);
    }
}

/// The AVX2 copy.
#[cfg(target_arch = "x86_64")]
pub(super) mod avx2 {
    use std::marker::PhantomData;
    use std::ops::Range;

    use super::DrawVariant;
    use glam::Vec3;

    use crate::raster::depth::DepthRows;
    use crate::render::options::DrawStats;
    use crate::render::target::SplitOff;
    use crate::render::tiles::strips::{self, Handover, Part, StripPlan};
    use crate::render::tiles::{self, Chunk, Job, TileCopy};
    use crate::render::{ColorTarget, DrawOptions, Renderer, Shader, VertexCache};

    /// The threaded draw's steps of variant `V`, compiled as [`draw`] is.
    pub(in crate::render) struct Tiled<V>(PhantomData<V>);

    impl<V: DrawVariant> TileCopy for Tiled<V> {
        unsafe fn setup<S: Shader>(
            job: &Job<'_, S>,
            range: Range<u32>,
            chunk: &mut Chunk<S::Varying>,
        ) {
            // SAFETY: the caller's guarantee.
            unsafe { setup(job, range, chunk) };
        }
        unsafe fn walk<S: Shader, C: ColorTarget>(
            job: &Job<'_, S>,
            chunks: &[Chunk<S::Varying>],
            band: usize,
            color: &mut C,
            depth: &mut DepthRows<'_>,
            clear: Option<Vec3>,
        ) -> DrawStats {
            // SAFETY: the caller's guarantee.
            unsafe { walk::<V, S, C>(job, chunks, band, color, depth, clear) }
        }
        unsafe fn strip<'d, S: Shader, C: ColorTarget + SplitOff>(
            job: &Job<'_, S>,
            plan: &StripPlan<'_>,
            part: &mut Part<'d, C>,
            handover: &Handover<'d, C>,
            clear: Option<Vec3>,
        ) -> DrawStats {
            // SAFETY: the caller's guarantee.
            unsafe { self::strip::<V, S, C>(job, plan, part, handover, clear) }
        }
    }

    /// [`tiles::setup_chunk`] compiled with AVX2.
    ///
    /// # Safety
    /// As for [`draw`].
    #[target_feature(enable = "avx2,fma,popcnt,bmi1")]
    unsafe fn setup<S: Shader>(job: &Job<'_, S>, range: Range<u32>, chunk: &mut Chunk<S::Varying>) {
        tiles::setup_chunk(job, range, chunk);
    }

    /// [`tiles::walk_band`] on the AVX2 lanes.
    ///
    /// # Safety
    /// As for [`draw`].
    #[target_feature(enable = "avx2,fma,popcnt,bmi1")]
    unsafe fn walk<V: DrawVariant, S: Shader, C: ColorTarget>(
        job: &Job<'_, S>,
        chunks: &[Chunk<S::Varying>],
        band: usize,
        color: &mut C,
        depth: &mut DepthRows<'_>,
        clear: Option<Vec3>,
    ) -> DrawStats {
        tiles::walk_band::<V, S, C, crate::simd::avx2::I32x8>(
            job, chunks, band, color, depth, clear,
        )
    }

    /// [`strips::draw_strip`] on the AVX2 lanes.
    ///
    /// # Safety
    /// As for [`draw`].
    #[target_feature(enable = "avx2,fma,popcnt,bmi1")]
    unsafe fn strip<'d, V: DrawVariant, S: Shader, C: ColorTarget + SplitOff>(
        job: &Job<'_, S>,
        plan: &StripPlan<'_>,
        part: &mut Part<'d, C>,
        handover: &Handover<'d, C>,
        clear: Option<Vec3>,
    ) -> DrawStats {
        strips::draw_strip::<V, S, C, crate::simd::avx2::I32x8>(job, plan, part, handover, clear)
    }

    /// The draw loop of variant `V` compiled with AVX2 and FMA enabled and on
    /// [`crate::simd`]'s AVX2 lanes, so 8-lane values are one 256-bit register instead
    /// of two 128-bit halves and `mul_add` is one instruction. Only the instruction
    /// selection differs: no operation is fused or reordered beyond what the code
    /// says, so the output is bit-identical to the baseline path (the tests compare
    /// both).
    ///
    /// # Safety
    /// The CPU must have AVX2, FMA, POPCNT and BMI1 ([`super::Isa::Avx2`]).
    #[target_feature(enable = "avx2,fma,popcnt,bmi1")]
    pub(in crate::render) unsafe fn draw<V: DrawVariant, S: Shader, C: ColorTarget>(
        r: &mut Renderer,
        shader: &S,
        cache: &VertexCache<S::Varying>,
        indices: &[u32],
        opts: &DrawOptions,
        color: &mut C,
    ) {
        r.draw_triangles::<V, _, _, crate::simd::avx2::I32x8>(shader, cache, indices, opts, color);
    }
}

/// The AVX-512 copy, of the [`super::Fast`] variant only.
#[cfg(target_arch = "x86_64")]
pub(super) mod avx512 {
    use std::ops::Range;

    use super::Fast;
    use glam::Vec3;

    use crate::raster::depth::DepthRows;
    use crate::render::options::DrawStats;
    use crate::render::target::SplitOff;
    use crate::render::tiles::strips::{self, Handover, Part, StripPlan};
    use crate::render::tiles::{self, Chunk, Job, TileCopy};
    use crate::render::{ColorTarget, DrawOptions, Renderer, Shader, VertexCache};

    /// The threaded draw's steps, compiled as [`draw`] is.
    pub(in crate::render) struct Tiled;

    impl TileCopy for Tiled {
        unsafe fn setup<S: Shader>(
            job: &Job<'_, S>,
            range: Range<u32>,
            chunk: &mut Chunk<S::Varying>,
        ) {
            // SAFETY: the caller's guarantee.
            unsafe { setup(job, range, chunk) };
        }
        unsafe fn walk<S: Shader, C: ColorTarget>(
            job: &Job<'_, S>,
            chunks: &[Chunk<S::Varying>],
            band: usize,
            color: &mut C,
            depth: &mut DepthRows<'_>,
            clear: Option<Vec3>,
        ) -> DrawStats {
            // SAFETY: the caller's guarantee.
            unsafe { walk::<S, C>(job, chunks, band, color, depth, clear) }
        }
        unsafe fn strip<'d, S: Shader, C: ColorTarget + SplitOff>(
            job: &Job<'_, S>,
            plan: &StripPlan<'_>,
            part: &mut Part<'d, C>,
            handover: &Handover<'d, C>,
            clear: Option<Vec3>,
        ) -> DrawStats {
            // SAFETY: the caller's guarantee.
            unsafe { self::strip::<S, C>(job, plan, part, handover, clear) }
        }
    }

    /// [`tiles::setup_chunk`] compiled with AVX-512.
    ///
    /// # Safety
    /// As for [`draw`].
    #[target_feature(enable = "avx2,fma,popcnt,bmi1,avx512f,avx512vl,avx512bw,avx512dq")]
    unsafe fn setup<S: Shader>(job: &Job<'_, S>, range: Range<u32>, chunk: &mut Chunk<S::Varying>) {
        tiles::setup_chunk(job, range, chunk);
    }

    /// [`tiles::walk_band`] on 16 AVX-512 lanes in two-row groups.
    ///
    /// # Safety
    /// As for [`draw`].
    #[target_feature(enable = "avx2,fma,popcnt,bmi1,avx512f,avx512vl,avx512bw,avx512dq")]
    unsafe fn walk<S: Shader, C: ColorTarget>(
        job: &Job<'_, S>,
        chunks: &[Chunk<S::Varying>],
        band: usize,
        color: &mut C,
        depth: &mut DepthRows<'_>,
        clear: Option<Vec3>,
    ) -> DrawStats {
        tiles::walk_band::<Fast, S, C, crate::simd::avx512::I32x16>(
            job, chunks, band, color, depth, clear,
        )
    }

    /// [`strips::draw_strip`] on 16 AVX-512 lanes in two-row groups.
    ///
    /// # Safety
    /// As for [`draw`].
    #[target_feature(enable = "avx2,fma,popcnt,bmi1,avx512f,avx512vl,avx512bw,avx512dq")]
    unsafe fn strip<'d, S: Shader, C: ColorTarget + SplitOff>(
        job: &Job<'_, S>,
        plan: &StripPlan<'_>,
        part: &mut Part<'d, C>,
        handover: &Handover<'d, C>,
        clear: Option<Vec3>,
    ) -> DrawStats {
        strips::draw_strip::<Fast, S, C, crate::simd::avx512::I32x16>(
            job, plan, part, handover, clear,
        )
    }

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
        r.draw_triangles::<Fast, _, _, crate::simd::avx512::I32x16>(
            shader, cache, indices, opts, color,
        );
    }
}

//! `f32` and `i32` lane vectors behind two traits, so the hot loops (the `wide`
//! traversal, the fragment stage, the shaders' `fragment_lanes`, the colour stores) are
//! written once and compiled three times:
//!
//! - on [`wide`]'s `f32x8`/`i32x8`, for the build's target (on baseline x86-64 each
//!   is two SSE halves);
//! - on AVX2 registers (the crate-private `avx2` module), instantiated only inside
//!   [`crate::render::Renderer`]'s AVX2 draw loop, which runs after the CPU was checked;
//! - on 16-lane AVX-512 registers (`avx512`), only inside the AVX-512 draw loop.
//!
//! Lanes come in rows of 8 pixels: the 8-lane backends hold one row of a group, the
//! 16-lane one two rows (lane `k` is pixel `k % 8` of row `k / 8`). Small triangles
//! cover a few pixels of many rows, so two rows per group halve the groups of the
//! dense meshes, where a 16-pixel row would leave most lanes empty.
//!
//! `wide` picks its implementation when the crate is compiled, so a function compiled
//! with AVX2 enabled at run time still gets its SSE halves; these traits let that
//! function use 256-bit (or 512-bit) registers instead.
//!
//! All backends perform the same IEEE operations lane by lane, with no reassociation,
//! so they give identical bits (the tests compare whole frames). Fused multiply-add is
//! one of those operations ([`F32s::mul_add`], one rounding): one instruction on the
//! AVX2 path (which requires FMA, as every AVX2 CPU has it), the correctly rounded
//! `f32::mul_add` lane by lane on the baseline. (The one exception is which NaN payload
//! a fused multiply-add of NaNs keeps, which x86 ties to the operand order the compiler
//! picks; no output depends on it: NaN fails every depth test and clamps to 0 in
//! colour.) Masks are lanes of all ones or all zeros.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Sub};

use wide::{f32x8, i32x8};

/// `[body(0), body(1), body(2)]` with `e` bound to each index, expanded in place.
///
/// Per-edge and per-channel lane code uses this rather than a closure: a closure is a
/// function of its own, compiled without the AVX2 draw loop's target features, so the
/// intrinsics in its body would stay out-of-line calls.
macro_rules! each3 {
    (|$e:ident| $body:expr) => {
        [
            {
                let $e = 0usize;
                $body
            },
            {
                let $e = 1usize;
                $body
            },
            {
                let $e = 2usize;
                $body
            },
        ]
    };
}
pub(crate) use each3;

/// `f32` lanes: 8 per row of pixels, [`F32s::ROWS`] rows (lane `k` is pixel `k % 8` of
/// row `k / 8` of a group).
pub trait F32s:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// The integer lanes of the same backend.
    type I: I32s<F = Self>;
    /// Rows of 8 lanes: 1, or 2 for the 16-lane AVX-512 backend.
    const ROWS: usize;
    /// The lanes as an array (`[f32; 8 · ROWS]`).
    type Arr: Copy + Default + AsRef<[f32]> + AsMut<[f32]>;
    fn splat(v: f32) -> Self;
    fn from_array(a: Self::Arr) -> Self;
    fn to_array(self) -> Self::Arr;
    /// The lanes of row `r` from `s[start + r·stride..][..8]`. A stride of 0 loads the
    /// first row into every row (for groups whose later rows are masked off and may lie
    /// past the buffer).
    fn load_rows(s: &[f32], start: usize, stride: usize) -> Self;
    /// Stores the lanes whose bit is set in `mask` where [`F32s::load_rows`] reads them;
    /// the other places keep their values. With a stride of 0, only the first row's bits
    /// may be set.
    fn store_rows(self, s: &mut [f32], start: usize, stride: usize, mask: u32);
    /// Correctly rounded square root.
    fn sqrt(self) -> Self;
    /// `self · b + c` rounded once (IEEE fusedMultiplyAdd), as `f32::mul_add`.
    fn mul_add(self, b: Self, c: Self) -> Self;
    /// Mask of `self > o` (false for NaN).
    fn gt(self, o: Self) -> Self;
    /// Mask of `self < o` (false for NaN).
    fn lt(self, o: Self) -> Self;
    /// Mask of `self ≤ o` (false for NaN).
    fn le(self, o: Self) -> Self;
    /// `a` where `mask` is set, else `b`.
    fn select(mask: Self, a: Self, b: Self) -> Self;
    /// `self > o ? self : o` per lane (x86's `maxps`: `o` when either is NaN).
    fn max(self, o: Self) -> Self;
    /// `self < o ? self : o` per lane (x86's `minps`: `o` when either is NaN).
    fn min(self, o: Self) -> Self;
    /// The sign bit of lane `i` in bit `i` (for masks: which lanes are set).
    fn bitmask(self) -> u32;
    /// Truncation towards zero, for values within `i32` range.
    fn trunc_i32(self) -> Self::I;
}

/// `i32` lanes, laid out as [`F32s`]'s.
pub trait I32s:
    Copy + Add<Output = Self> + Mul<Output = Self> + BitOr<Output = Self> + BitAnd<Output = Self>
{
    /// The float lanes of the same backend.
    type F: F32s<I = Self>;
    /// As [`F32s::ROWS`].
    const ROWS: usize;
    /// The lanes as an array (`[i32; 8 · ROWS]`).
    type Arr: Copy + Default + AsRef<[i32]> + AsMut<[i32]>;
    fn splat(v: i32) -> Self;
    fn from_array(a: Self::Arr) -> Self;
    fn to_array(self) -> Self::Arr;
    /// As [`F32s::load_rows`].
    fn load_rows(s: &[i32], start: usize, stride: usize) -> Self;
    /// As [`F32s::store_rows`].
    fn store_rows(self, s: &mut [i32], start: usize, stride: usize, mask: u32);
    /// Shift left by `N` bits.
    fn shl<const N: i32>(self) -> Self;
    /// Mask of `self == o`.
    fn eq(self, o: Self) -> Self;
    /// `a` where `mask` is set, else `b`.
    fn select(mask: Self, a: Self, b: Self) -> Self;
    /// The sign bit of lane `i` in bit `i`.
    fn bitmask(self) -> u32;
    /// Conversion to `f32`, rounded to nearest.
    fn to_f32(self) -> Self::F;
    /// The same bits as float lanes (for using an integer mask on floats).
    fn cast_f32(self) -> Self::F;

    /// The lanes of a bit mask: lane `i` is all ones when bit `i` is set.
    fn from_bits(mask: u32) -> Self;
}

/// [`I32s::from_bits`] for 8 lanes.
#[inline(always)]
fn from_bits8<I: I32s<Arr = [i32; 8]>>(mask: u32) -> I {
    let bits = I::from_array([1, 2, 4, 8, 16, 32, 64, 128]);
    (I::splat(mask as i32) & bits).eq(bits)
}

/// The 8 places of one row's group, bounds-checked.
#[inline(always)]
fn row8<T>(s: &mut [T], start: usize) -> &mut [T; 8] {
    (&mut s[start..start + 8]).try_into().expect("8 lanes")
}

/// [`F32s::load_rows`] of the one-row (8-lane) backends.
#[inline(always)]
fn load_row8<F: F32s<Arr = [f32; 8]>>(s: &[f32], start: usize) -> F {
    F::from_array(s[start..start + 8].try_into().expect("8 lanes"))
}

/// [`F32s::store_rows`] of the one-row backends: one blended store of the row.
#[inline(always)]
fn store_row8<F: F32s<Arr = [f32; 8]>>(v: F, s: &mut [f32], start: usize, mask: u32) {
    let slot = row8(s, start);
    let keep = F::I::from_bits(mask).cast_f32();
    *slot = F::select(keep, v, F::from_array(*slot)).to_array();
}

/// [`I32s::load_rows`] of the one-row backends.
#[inline(always)]
fn load_row8_i<I: I32s<Arr = [i32; 8]>>(s: &[i32], start: usize) -> I {
    I::from_array(s[start..start + 8].try_into().expect("8 lanes"))
}

/// [`I32s::store_rows`] of the one-row backends: one blended store of the row.
#[inline(always)]
fn store_row8_i<I: I32s<Arr = [i32; 8]>>(v: I, s: &mut [i32], start: usize, mask: u32) {
    let slot = row8(s, start);
    *slot = I::select(I::from_bits(mask), v, I::from_array(*slot)).to_array();
}

impl F32s for f32x8 {
    type I = i32x8;
    const ROWS: usize = 1;
    type Arr = [f32; 8];
    #[inline(always)]
    fn splat(v: f32) -> Self {
        f32x8::splat(v)
    }
    #[inline(always)]
    fn from_array(a: [f32; 8]) -> Self {
        f32x8::new(a)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        f32x8::to_array(self)
    }
    #[inline(always)]
    fn load_rows(s: &[f32], start: usize, _: usize) -> Self {
        load_row8(s, start)
    }
    #[inline(always)]
    fn store_rows(self, s: &mut [f32], start: usize, _: usize, mask: u32) {
        store_row8(self, s, start, mask);
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32x8::sqrt(self)
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        // Not `wide`'s `mul_add`: without FMA in the build's target it rounds twice.
        let (a, b, c) = (self.to_array(), b.to_array(), c.to_array());
        f32x8::new(std::array::from_fn(|i| a[i].mul_add(b[i], c[i])))
    }
    #[inline(always)]
    fn gt(self, o: Self) -> Self {
        self.simd_gt(o)
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Self {
        self.simd_lt(o)
    }
    #[inline(always)]
    fn le(self, o: Self) -> Self {
        self.simd_le(o)
    }
    #[inline(always)]
    fn select(mask: Self, a: Self, b: Self) -> Self {
        mask.select(a, b)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // Spelled as its definition: `wide`'s own max may treat NaN differently.
        F32s::select(F32s::gt(self, o), self, o)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        F32s::select(F32s::lt(self, o), self, o)
    }
    #[inline(always)]
    fn bitmask(self) -> u32 {
        self.to_bitmask()
    }
    #[inline(always)]
    fn trunc_i32(self) -> i32x8 {
        self.trunc_int()
    }
}

impl I32s for i32x8 {
    type F = f32x8;
    const ROWS: usize = 1;
    type Arr = [i32; 8];
    #[inline(always)]
    fn splat(v: i32) -> Self {
        i32x8::splat(v)
    }
    #[inline(always)]
    fn from_array(a: [i32; 8]) -> Self {
        i32x8::new(a)
    }
    #[inline(always)]
    fn to_array(self) -> [i32; 8] {
        i32x8::to_array(self)
    }
    #[inline(always)]
    fn load_rows(s: &[i32], start: usize, _: usize) -> Self {
        load_row8_i(s, start)
    }
    #[inline(always)]
    fn store_rows(self, s: &mut [i32], start: usize, _: usize, mask: u32) {
        store_row8_i(self, s, start, mask);
    }
    #[inline(always)]
    fn from_bits(mask: u32) -> Self {
        from_bits8(mask)
    }
    #[inline(always)]
    fn shl<const N: i32>(self) -> Self {
        self << N
    }
    #[inline(always)]
    fn eq(self, o: Self) -> Self {
        self.simd_eq(o)
    }
    #[inline(always)]
    fn select(mask: Self, a: Self, b: Self) -> Self {
        mask.select(a, b)
    }
    #[inline(always)]
    fn bitmask(self) -> u32 {
        self.to_bitmask()
    }
    #[inline(always)]
    fn to_f32(self) -> f32x8 {
        self.round_float()
    }
    #[inline(always)]
    fn cast_f32(self) -> f32x8 {
        bytemuck::cast(self)
    }
}

/// `impl $tr for $t` by the intrinsic `$intr` on the register inside `$t`, for the
/// register backends below.
#[cfg(target_arch = "x86_64")]
macro_rules! binop {
    ($t:ident, $tr:ident, $f:ident, $intr:ident) => {
        impl $tr for $t {
            type Output = $t;
            #[inline(always)]
            fn $f(self, o: $t) -> $t {
                // SAFETY: values of this type exist only on CPUs with the instructions
                // its module names (module docs).
                $t(unsafe { $intr(self.0, o.0) })
            }
        }
    };
}

/// The AVX2 backend.
///
/// Its values may only exist on a CPU with AVX2 and FMA: the types are crate-private and
/// instantiated only by the renderer's AVX2 draw loop, which checks the CPU first.
/// Their methods are `#[inline(always)]` without target features of their own, so the
/// intrinsics inline into that loop (which has the features) as single instructions.
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx2 {
    use std::arch::x86_64::*;
    use std::ops::{Add, BitAnd, BitOr, Div, Mul, Sub};

    use super::{F32s, I32s, from_bits8, load_row8, load_row8_i, store_row8, store_row8_i};

    /// Eight `f32` lanes in one `ymm` register.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct F32x8(__m256);

    /// Eight `i32` lanes in one `ymm` register.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct I32x8(__m256i);

    binop!(F32x8, Add, add, _mm256_add_ps);
    binop!(F32x8, Sub, sub, _mm256_sub_ps);
    binop!(F32x8, Mul, mul, _mm256_mul_ps);
    binop!(F32x8, Div, div, _mm256_div_ps);
    binop!(I32x8, Add, add, _mm256_add_epi32);
    binop!(I32x8, Mul, mul, _mm256_mullo_epi32);
    binop!(I32x8, BitOr, bitor, _mm256_or_si256);
    binop!(I32x8, BitAnd, bitand, _mm256_and_si256);

    // SAFETY (every `unsafe` block below): values of these types exist only on CPUs
    // with AVX2 and FMA (module docs); loads and stores go through arrays of exactly 8 lanes.
    impl F32s for F32x8 {
        type I = I32x8;
        const ROWS: usize = 1;
        type Arr = [f32; 8];
        #[inline(always)]
        fn splat(v: f32) -> Self {
            F32x8(unsafe { _mm256_set1_ps(v) })
        }
        #[inline(always)]
        fn from_array(a: [f32; 8]) -> Self {
            F32x8(unsafe { _mm256_loadu_ps(a.as_ptr()) })
        }
        #[inline(always)]
        fn to_array(self) -> [f32; 8] {
            let mut a = [0f32; 8];
            unsafe { _mm256_storeu_ps(a.as_mut_ptr(), self.0) };
            a
        }
        #[inline(always)]
        fn load_rows(s: &[f32], start: usize, _: usize) -> Self {
            load_row8(s, start)
        }
        #[inline(always)]
        fn store_rows(self, s: &mut [f32], start: usize, _: usize, mask: u32) {
            store_row8(self, s, start, mask);
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            F32x8(unsafe { _mm256_sqrt_ps(self.0) })
        }
        #[inline(always)]
        fn mul_add(self, b: Self, c: Self) -> Self {
            F32x8(unsafe { _mm256_fmadd_ps(self.0, b.0, c.0) })
        }
        #[inline(always)]
        fn gt(self, o: Self) -> Self {
            F32x8(unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(self.0, o.0) })
        }
        #[inline(always)]
        fn lt(self, o: Self) -> Self {
            F32x8(unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0) })
        }
        #[inline(always)]
        fn le(self, o: Self) -> Self {
            F32x8(unsafe { _mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0) })
        }
        #[inline(always)]
        fn select(mask: Self, a: Self, b: Self) -> Self {
            F32x8(unsafe { _mm256_blendv_ps(b.0, a.0, mask.0) })
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            F32x8(unsafe { _mm256_max_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            F32x8(unsafe { _mm256_min_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn bitmask(self) -> u32 {
            unsafe { _mm256_movemask_ps(self.0) as u32 }
        }
        #[inline(always)]
        fn trunc_i32(self) -> I32x8 {
            I32x8(unsafe { _mm256_cvttps_epi32(self.0) })
        }
    }

    impl I32s for I32x8 {
        type F = F32x8;
        const ROWS: usize = 1;
        type Arr = [i32; 8];
        #[inline(always)]
        fn splat(v: i32) -> Self {
            I32x8(unsafe { _mm256_set1_epi32(v) })
        }
        #[inline(always)]
        fn from_array(a: [i32; 8]) -> Self {
            I32x8(unsafe { _mm256_loadu_si256(a.as_ptr().cast()) })
        }
        #[inline(always)]
        fn to_array(self) -> [i32; 8] {
            let mut a = [0i32; 8];
            unsafe { _mm256_storeu_si256(a.as_mut_ptr().cast(), self.0) };
            a
        }
        #[inline(always)]
        fn load_rows(s: &[i32], start: usize, _: usize) -> Self {
            load_row8_i(s, start)
        }
        #[inline(always)]
        fn store_rows(self, s: &mut [i32], start: usize, _: usize, mask: u32) {
            store_row8_i(self, s, start, mask);
        }
        #[inline(always)]
        fn from_bits(mask: u32) -> Self {
            from_bits8(mask)
        }
        #[inline(always)]
        fn shl<const N: i32>(self) -> Self {
            I32x8(unsafe { _mm256_slli_epi32::<N>(self.0) })
        }
        #[inline(always)]
        fn eq(self, o: Self) -> Self {
            I32x8(unsafe { _mm256_cmpeq_epi32(self.0, o.0) })
        }
        #[inline(always)]
        fn select(mask: Self, a: Self, b: Self) -> Self {
            I32x8(unsafe { _mm256_blendv_epi8(b.0, a.0, mask.0) })
        }
        #[inline(always)]
        fn bitmask(self) -> u32 {
            unsafe { _mm256_movemask_ps(_mm256_castsi256_ps(self.0)) as u32 }
        }
        #[inline(always)]
        fn to_f32(self) -> F32x8 {
            F32x8(unsafe { _mm256_cvtepi32_ps(self.0) })
        }
        #[inline(always)]
        fn cast_f32(self) -> F32x8 {
            F32x8(unsafe { _mm256_castsi256_ps(self.0) })
        }
    }
}

/// The AVX-512 backend: 16 lanes in one `zmm` register, as two rows of 8 pixels (lanes
/// 0–7 the first row, 8–15 the row below).
///
/// As [`avx2`], its values may only exist on a CPU with what
/// [`crate::render::Isa::Avx512`] names (AVX-512 F, VL, BW and DQ besides AVX2 and FMA):
/// the types are crate-private and instantiated only by the renderer's AVX-512 draw
/// loop, which checks the CPU first. Lane masks live in vector lanes as on the other
/// backends; the compiler turns compare, mask and blend chains into mask registers.
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx512 {
    use std::arch::x86_64::*;
    use std::ops::{Add, BitAnd, BitOr, Div, Mul, Sub};

    use super::{F32s, I32s};

    /// Sixteen `f32` lanes in one `zmm` register.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct F32x16(__m512);

    /// Sixteen `i32` lanes in one `zmm` register.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct I32x16(__m512i);

    binop!(F32x16, Add, add, _mm512_add_ps);
    binop!(F32x16, Sub, sub, _mm512_sub_ps);
    binop!(F32x16, Mul, mul, _mm512_mul_ps);
    binop!(F32x16, Div, div, _mm512_div_ps);
    binop!(I32x16, Add, add, _mm512_add_epi32);
    binop!(I32x16, Mul, mul, _mm512_mullo_epi32);
    binop!(I32x16, BitOr, bitor, _mm512_or_si512);
    binop!(I32x16, BitAnd, bitand, _mm512_and_si512);

    /// The places of both rows of a group: pointers to `start` and `start + stride`,
    /// after bounds checks of both.
    #[inline(always)]
    fn rows<T>(s: &[T], start: usize, stride: usize) -> (*const T, *const T) {
        let (a, b) = (&s[start..start + 8], &s[start + stride..start + stride + 8]);
        (a.as_ptr(), b.as_ptr())
    }

    /// [`rows`] for stores.
    #[inline(always)]
    fn rows_mut<T>(s: &mut [T], start: usize, stride: usize) -> (*mut T, *mut T) {
        assert!(start + stride + 8 <= s.len(), "8 lanes per row");
        let p = s.as_mut_ptr();
        // SAFETY: both offsets plus 8 lie within `s` (checked above).
        unsafe { (p.add(start), p.add(start + stride)) }
    }

    // SAFETY (every `unsafe` block below): values of these types exist only on CPUs
    // with AVX-512 F, VL, BW and DQ (module docs); loads and stores go through arrays of
    // exactly 16 lanes or through `rows`/`rows_mut`, which bounds-check 8 places per row.
    impl F32s for F32x16 {
        type I = I32x16;
        const ROWS: usize = 2;
        type Arr = [f32; 16];
        #[inline(always)]
        fn splat(v: f32) -> Self {
            F32x16(unsafe { _mm512_set1_ps(v) })
        }
        #[inline(always)]
        fn from_array(a: [f32; 16]) -> Self {
            F32x16(unsafe { _mm512_loadu_ps(a.as_ptr()) })
        }
        #[inline(always)]
        fn to_array(self) -> [f32; 16] {
            let mut a = [0f32; 16];
            unsafe { _mm512_storeu_ps(a.as_mut_ptr(), self.0) };
            a
        }
        #[inline(always)]
        fn load_rows(s: &[f32], start: usize, stride: usize) -> Self {
            let (a, b) = rows(s, start, stride);
            F32x16(unsafe {
                _mm512_insertf32x8::<1>(
                    _mm512_castps256_ps512(_mm256_loadu_ps(a)),
                    _mm256_loadu_ps(b),
                )
            })
        }
        #[inline(always)]
        fn store_rows(self, s: &mut [f32], start: usize, stride: usize, mask: u32) {
            // Masked stores: lanes outside the mask are not written, so a stride of 0
            // (both rows at the same places, the second masked off) is harmless.
            let (a, b) = rows_mut(s, start, stride);
            unsafe {
                _mm256_mask_storeu_ps(a, mask as u8, _mm512_castps512_ps256(self.0));
                _mm256_mask_storeu_ps(b, (mask >> 8) as u8, _mm512_extractf32x8_ps::<1>(self.0));
            }
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            F32x16(unsafe { _mm512_sqrt_ps(self.0) })
        }
        #[inline(always)]
        fn mul_add(self, b: Self, c: Self) -> Self {
            F32x16(unsafe { _mm512_fmadd_ps(self.0, b.0, c.0) })
        }
        #[inline(always)]
        fn gt(self, o: Self) -> Self {
            let k = unsafe { _mm512_cmp_ps_mask::<_CMP_GT_OQ>(self.0, o.0) };
            I32x16::from_bits(u32::from(k)).cast_f32()
        }
        #[inline(always)]
        fn lt(self, o: Self) -> Self {
            let k = unsafe { _mm512_cmp_ps_mask::<_CMP_LT_OQ>(self.0, o.0) };
            I32x16::from_bits(u32::from(k)).cast_f32()
        }
        #[inline(always)]
        fn le(self, o: Self) -> Self {
            let k = unsafe { _mm512_cmp_ps_mask::<_CMP_LE_OQ>(self.0, o.0) };
            I32x16::from_bits(u32::from(k)).cast_f32()
        }
        #[inline(always)]
        fn select(mask: Self, a: Self, b: Self) -> Self {
            let k = unsafe { _mm512_movepi32_mask(_mm512_castps_si512(mask.0)) };
            F32x16(unsafe { _mm512_mask_blend_ps(k, b.0, a.0) })
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            F32x16(unsafe { _mm512_max_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            F32x16(unsafe { _mm512_min_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn bitmask(self) -> u32 {
            u32::from(unsafe { _mm512_movepi32_mask(_mm512_castps_si512(self.0)) })
        }
        #[inline(always)]
        fn trunc_i32(self) -> I32x16 {
            I32x16(unsafe { _mm512_cvttps_epi32(self.0) })
        }
    }

    impl I32s for I32x16 {
        type F = F32x16;
        const ROWS: usize = 2;
        type Arr = [i32; 16];
        #[inline(always)]
        fn splat(v: i32) -> Self {
            I32x16(unsafe { _mm512_set1_epi32(v) })
        }
        #[inline(always)]
        fn from_array(a: [i32; 16]) -> Self {
            I32x16(unsafe { _mm512_loadu_epi32(a.as_ptr()) })
        }
        #[inline(always)]
        fn to_array(self) -> [i32; 16] {
            let mut a = [0i32; 16];
            unsafe { _mm512_storeu_epi32(a.as_mut_ptr(), self.0) };
            a
        }
        #[inline(always)]
        fn load_rows(s: &[i32], start: usize, stride: usize) -> Self {
            let (a, b) = rows(s, start, stride);
            I32x16(unsafe {
                _mm512_inserti32x8::<1>(
                    _mm512_castsi256_si512(_mm256_loadu_epi32(a)),
                    _mm256_loadu_epi32(b),
                )
            })
        }
        #[inline(always)]
        fn store_rows(self, s: &mut [i32], start: usize, stride: usize, mask: u32) {
            // As `F32x16::store_rows`.
            let (a, b) = rows_mut(s, start, stride);
            unsafe {
                _mm256_mask_storeu_epi32(a, mask as u8, _mm512_castsi512_si256(self.0));
                _mm256_mask_storeu_epi32(
                    b,
                    (mask >> 8) as u8,
                    _mm512_extracti32x8_epi32::<1>(self.0),
                );
            }
        }
        #[inline(always)]
        fn shl<const N: i32>(self) -> Self {
            // The shift count as a vector (`slli` takes it as an unsigned const
            // parameter); the compiler folds the constant into an immediate shift.
            I32x16(unsafe { _mm512_sll_epi32(self.0, _mm_cvtsi32_si128(N)) })
        }
        #[inline(always)]
        fn eq(self, o: Self) -> Self {
            let k = unsafe { _mm512_cmpeq_epi32_mask(self.0, o.0) };
            Self::from_bits(u32::from(k))
        }
        #[inline(always)]
        fn select(mask: Self, a: Self, b: Self) -> Self {
            let k = unsafe { _mm512_movepi32_mask(mask.0) };
            I32x16(unsafe { _mm512_mask_blend_epi32(k, b.0, a.0) })
        }
        #[inline(always)]
        fn bitmask(self) -> u32 {
            u32::from(unsafe { _mm512_movepi32_mask(self.0) })
        }
        #[inline(always)]
        fn to_f32(self) -> F32x16 {
            F32x16(unsafe { _mm512_cvtepi32_ps(self.0) })
        }
        #[inline(always)]
        fn cast_f32(self) -> F32x16 {
            F32x16(unsafe { _mm512_castsi512_ps(self.0) })
        }
        #[inline(always)]
        fn from_bits(mask: u32) -> Self {
            I32x16(unsafe { _mm512_movm_epi32(mask as u16) })
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use proptest::prelude::*;
    use wide::{f32x8, i32x8};

    use super::{F32s, I32s, avx2, avx512};

    /// Every operation of a backend on the given lanes, as bit patterns, one list of
    /// lanes per operation (the lane masks as one value): the float lanes include NaN,
    /// infinities, zeros of both signs and subnormals.
    fn ops<F: F32s>(a: &[f32], b: &[f32], m: u32, k: &[i32]) -> Vec<Vec<u32>> {
        let floats = |v: &[f32]| {
            let mut arr = F::Arr::default();
            arr.as_mut().copy_from_slice(v);
            F::from_array(arr)
        };
        let mut ints = <F::I as I32s>::Arr::default();
        ints.as_mut().copy_from_slice(k);
        let (x, y) = (floats(a), floats(b));
        let mut out = Vec::new();
        let mut push = |v: F| out.push(v.to_array().as_ref().iter().map(|f| f.to_bits()).collect());
        push(x + y);
        push(x - y);
        push(x * y);
        push(x / y);
        push(x.sqrt());
        // Which NaN's payload a fused multiply-add keeps depends on the operand order
        // the compiler picks; only NaN-ness is compared (see the module docs).
        let canon = |v: F| {
            let mut arr = v.to_array();
            for f in arr.as_mut() {
                if f.is_nan() {
                    *f = f32::NAN;
                }
            }
            F::from_array(arr)
        };
        let three_quarters: Vec<f32> = a.iter().map(|v| v * 0.75).collect();
        push(canon(x.mul_add(y, floats(&three_quarters))));
        push(canon(y.mul_add(y, x)));
        push(x.gt(y));
        push(x.lt(y));
        push(x.le(y));
        push(F::select(x.lt(y), x, y));
        push(x.max(y));
        push(x.min(y));
        push(F::I::from_bits(m).cast_f32());
        let i = F::I::from_array(ints);
        push(i.to_f32());
        push(((i + i.shl::<8>()) | (F::I::splat(7) & i)).cast_f32());
        push((i * F::I::splat(-77_777)).cast_f32());
        push(F::I::select(i.eq(F::I::splat(3)), i, F::I::from_bits(m)).cast_f32());
        // Truncation only where it is defined (the colour stores clamp first).
        let t = F::select(x.lt(F::splat(1e9)), x, F::splat(0.0));
        let t = F::select(t.gt(F::splat(-1e9)), t, F::splat(0.0));
        push(t.trunc_i32().cast_f32());
        let mut v = out;
        v.push(vec![x.lt(y).bitmask()]);
        v.push(vec![i.bitmask()]);
        v
    }

    /// [`ops`] of an 8-lane backend on the two 8-lane halves of 16 lanes, joined as the
    /// 16-lane backend lays them out (masks: the second half's bits above the first's).
    fn ops_by_halves<F: F32s>(a: &[f32], b: &[f32], m: u32, k: &[i32]) -> Vec<Vec<u32>> {
        let lo = ops::<F>(&a[..8], &b[..8], m & 0xFF, &k[..8]);
        let hi = ops::<F>(&a[8..], &b[8..], m >> 8, &k[8..]);
        lo.into_iter()
            .zip(hi)
            .map(|(l, h)| match (l.len(), &h[..]) {
                (1, [h]) => vec![l[0] | h << 8],
                _ => [l, h].concat(),
            })
            .collect()
    }

    /// Loads and masked stores of groups of rows `stride` apart, through the lanes of
    /// `F`, checked against the same writes made place by place.
    fn rows_round_trip<F: F32s>(stride: usize, mask: u32, seed: f32) -> Result<(), TestCaseError> {
        let len = 8 + 2 * stride + 16;
        let before: Vec<f32> = (0..len).map(|i| seed + i as f32).collect();
        let start = 3;
        let group = F::load_rows(&before, start, stride);
        let lanes = group.to_array();
        for (k, v) in lanes.as_ref().iter().enumerate() {
            prop_assert_eq!(
                *v,
                before[start + k / 8 * stride + k % 8],
                "load lane {}",
                k
            );
        }
        let new = group * F::splat(-2.0);
        let mut after = before.clone();
        new.store_rows(&mut after, start, stride, mask);
        let mut want = before.clone();
        for k in 0..8 * F::ROWS {
            if mask >> k & 1 == 1 {
                want[start + k / 8 * stride + k % 8] = -2.0 * lanes.as_ref()[k];
            }
        }
        prop_assert_eq!(after, want);
        Ok(())
    }

    fn lane() -> impl Strategy<Value = f32> {
        prop_oneof![
            any::<u32>().prop_map(f32::from_bits),
            Just(f32::NAN),
            Just(f32::INFINITY),
            Just(-0.0f32),
            Just(0.0f32),
            -10.0f32..10.0,
        ]
    }

    proptest! {
        #[test]
        fn avx2_lanes_equal_wide_lanes(
            a in prop::array::uniform8(lane()),
            b in prop::array::uniform8(lane()),
            m in any::<u8>(),
            k in prop::array::uniform8(any::<i32>()),
        ) {
            // Without AVX2 there is no second backend to compare (and `prop_assume!`
            // would reject every case and fail the run).
            if !crate::render::Isa::Avx2.is_supported() {
                return Ok(());
            }
            let base = ops::<f32x8>(&a, &b, m.into(), &k);
            // SAFETY of the AVX2 lanes: the CPU was checked just above.
            let fast = ops::<avx2::F32x8>(&a, &b, m.into(), &k);
            prop_assert_eq!(base, fast);
        }

        /// The 16-lane backend computes, lane for lane, what the portable 8-lane one does
        /// on each half.
        #[test]
        fn avx512_lanes_equal_wide_lanes_by_halves(
            a in prop::array::uniform16(lane()),
            b in prop::array::uniform16(lane()),
            m in any::<u16>(),
            k in prop::array::uniform16(any::<i32>()),
        ) {
            if !crate::render::Isa::Avx512.is_supported() {
                return Ok(());
            }
            let base = ops_by_halves::<f32x8>(&a, &b, m.into(), &k);
            // SAFETY of the AVX-512 lanes: the CPU was checked just above.
            let fast = ops::<avx512::F32x16>(&a, &b, m.into(), &k);
            prop_assert_eq!(base, fast);
        }

        /// Group loads and masked stores touch exactly the group's places, on every
        /// backend the CPU has; two-row groups also with a stride of 0 (the second row
        /// masked off), as the last row of a target uses them.
        #[test]
        fn row_loads_and_masked_stores_touch_only_the_group(
            stride in 8usize..40,
            mask in any::<u16>(),
            seed in -100.0f32..100.0,
        ) {
            rows_round_trip::<f32x8>(stride, u32::from(mask & 0xFF), seed)?;
            if crate::render::Isa::Avx2.is_supported() {
                rows_round_trip::<avx2::F32x8>(stride, u32::from(mask & 0xFF), seed)?;
            }
            if crate::render::Isa::Avx512.is_supported() {
                rows_round_trip::<avx512::F32x16>(stride, u32::from(mask), seed)?;
                rows_round_trip::<avx512::F32x16>(0, u32::from(mask & 0xFF), seed)?;
            }
        }
    }

    #[test]
    fn from_bits_sets_the_lanes_of_the_mask() {
        for m in 0..=255u32 {
            let lanes = <i32x8 as I32s>::from_bits(m).to_array();
            for (k, v) in lanes.iter().enumerate() {
                assert_eq!(*v, if m >> k & 1 == 1 { -1 } else { 0 }, "mask {m:#b}");
            }
        }
    }
}

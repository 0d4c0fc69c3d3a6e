//! Eight-lane `f32` and `i32` vectors behind two traits, so the hot loops (the `wide`
//! traversal, the fragment stage, the shaders' `fragment8`, the colour stores) are
//! written once and compiled twice:
//!
//! - on [`wide`]'s `f32x8`/`i32x8`, for the build's target (on baseline x86-64 each
//!   is two SSE halves);
//! - on AVX2 registers (the crate-private `avx2` module), instantiated only inside
//!   [`crate::render::Renderer`]'s AVX2 draw loop, which runs after the CPU was checked.
//!
//! `wide` picks its implementation when the crate is compiled, so a function compiled
//! with AVX2 enabled at run time still gets its SSE halves; these traits let that
//! function use 256-bit registers instead.
//!
//! Both backends perform the same IEEE operations lane by lane, with no reassociation,
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

/// Eight `f32` lanes.
pub trait F32s:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// The integer lanes of the same backend.
    type I: I32s<F = Self>;
    fn splat(v: f32) -> Self;
    fn from_array(a: [f32; 8]) -> Self;
    fn to_array(self) -> [f32; 8];
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
    fn bitmask(self) -> u8;
    /// Truncation towards zero, for values within `i32` range.
    fn trunc_i32(self) -> Self::I;
}

/// Eight `i32` lanes.
pub trait I32s:
    Copy + Add<Output = Self> + Mul<Output = Self> + BitOr<Output = Self> + BitAnd<Output = Self>
{
    /// The float lanes of the same backend.
    type F: F32s<I = Self>;
    fn splat(v: i32) -> Self;
    fn from_array(a: [i32; 8]) -> Self;
    fn to_array(self) -> [i32; 8];
    /// Shift left by `N` bits.
    fn shl<const N: i32>(self) -> Self;
    /// Mask of `self == o`.
    fn eq(self, o: Self) -> Self;
    /// `a` where `mask` is set, else `b`.
    fn select(mask: Self, a: Self, b: Self) -> Self;
    /// The sign bit of lane `i` in bit `i`.
    fn bitmask(self) -> u8;
    /// Conversion to `f32`, rounded to nearest.
    fn to_f32(self) -> Self::F;
    /// The same bits as float lanes (for using an integer mask on floats).
    fn cast_f32(self) -> Self::F;

    /// The lanes of an 8-bit mask: lane `i` is all ones when bit `i` is set.
    #[inline(always)]
    fn from_bits(mask: u8) -> Self {
        let bits = Self::from_array([1, 2, 4, 8, 16, 32, 64, 128]);
        (Self::splat(i32::from(mask)) & bits).eq(bits)
    }
}

impl F32s for f32x8 {
    type I = i32x8;
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
    fn bitmask(self) -> u8 {
        self.to_bitmask() as u8
    }
    #[inline(always)]
    fn trunc_i32(self) -> i32x8 {
        self.trunc_int()
    }
}

impl I32s for i32x8 {
    type F = f32x8;
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
    fn bitmask(self) -> u8 {
        self.to_bitmask() as u8
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

    use super::{F32s, I32s};

    /// Eight `f32` lanes in one `ymm` register.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct F32x8(__m256);

    /// Eight `i32` lanes in one `ymm` register.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct I32x8(__m256i);

    macro_rules! binop {
        ($t:ident, $tr:ident, $f:ident, $intr:ident) => {
            impl $tr for $t {
                type Output = $t;
                #[inline(always)]
                fn $f(self, o: $t) -> $t {
                    // SAFETY: values of this type exist only on CPUs with AVX2 and FMA (module docs).
                    $t(unsafe { $intr(self.0, o.0) })
                }
            }
        };
    }
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
        fn bitmask(self) -> u8 {
            unsafe { _mm256_movemask_ps(self.0) as u8 }
        }
        #[inline(always)]
        fn trunc_i32(self) -> I32x8 {
            I32x8(unsafe { _mm256_cvttps_epi32(self.0) })
        }
    }

    impl I32s for I32x8 {
        type F = F32x8;
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
        fn bitmask(self) -> u8 {
            unsafe { _mm256_movemask_ps(_mm256_castsi256_ps(self.0)) as u8 }
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

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use proptest::prelude::*;
    use wide::{f32x8, i32x8};

    use super::avx2;
    use super::{F32s, I32s};

    /// Every operation of both backends on the same lanes, as bit patterns: the
    /// float lanes include NaN, infinities, zeros of both signs and subnormals.
    fn ops<F: F32s>(a: [f32; 8], b: [f32; 8], m: u8, k: [i32; 8]) -> Vec<u32> {
        let (x, y) = (F::from_array(a), F::from_array(b));
        let mut out = Vec::new();
        let mut push = |v: F| out.extend(v.to_array().map(f32::to_bits));
        push(x + y);
        push(x - y);
        push(x * y);
        push(x / y);
        push(x.sqrt());
        // Which NaN's payload a fused multiply-add keeps depends on the operand order
        // the compiler picks; only NaN-ness is compared (see the module docs).
        let canon =
            |v: F| F::from_array(v.to_array().map(|f| if f.is_nan() { f32::NAN } else { f }));
        push(canon(x.mul_add(y, F::from_array(a.map(|v| v * 0.75)))));
        push(canon(y.mul_add(y, x)));
        push(x.gt(y));
        push(x.lt(y));
        push(x.le(y));
        push(F::select(x.lt(y), x, y));
        push(x.max(y));
        push(x.min(y));
        push(F::I::from_bits(m).cast_f32());
        let i = F::I::from_array(k);
        push(i.to_f32());
        push(((i + i.shl::<8>()) | (F::I::splat(7) & i)).cast_f32());
        push((i * F::I::splat(-77_777)).cast_f32());
        push(F::I::select(i.eq(F::I::splat(3)), i, F::I::from_bits(m)).cast_f32());
        // Truncation only where it is defined (the colour stores clamp first).
        let t = F::select(x.lt(F::splat(1e9)), x, F::splat(0.0));
        let t = F::select(t.gt(F::splat(-1e9)), t, F::splat(0.0));
        push(t.trunc_i32().cast_f32());
        let mut v = out;
        v.push(u32::from(x.lt(y).bitmask()));
        v.push(u32::from(i.bitmask()));
        v
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
            let base = ops::<f32x8>(a, b, m, k);
            // SAFETY of the AVX2 lanes: the CPU was checked just above.
            let fast = ops::<avx2::F32x8>(a, b, m, k);
            prop_assert_eq!(base, fast);
        }
    }

    #[test]
    fn from_bits_sets_the_lanes_of_the_mask() {
        for m in 0..=255u8 {
            let lanes = <i32x8 as I32s>::from_bits(m).to_array();
            for (k, v) in lanes.iter().enumerate() {
                assert_eq!(*v, if m >> k & 1 == 1 { -1 } else { 0 }, "mask {m:#b}");
            }
        }
    }
}

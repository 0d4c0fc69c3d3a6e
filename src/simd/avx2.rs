//! The AVX2 backend.
//!
//! Its values may only exist on a CPU with AVX2 and FMA: the types are crate-private and
//! instantiated only by the renderer's AVX2 draw loop, which checks the CPU first.
//! Their methods are `#[inline(always)]` without target features of their own, so the
//! intrinsics inline into that loop (which has the features) as single instructions.

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

//! The AVX-512 backend: 16 lanes in one `zmm` register, as two rows of 8 pixels (lanes
//! 0–7 the first row, 8–15 the row below).
//!
//! As [`avx2`], its values may only exist on a CPU with what
//! [`super::Isa::Avx512`] names (AVX-512 F, VL, BW and DQ besides AVX2 and FMA):
//! the types are crate-private and instantiated only by the renderer's AVX-512 draw
//! loop, which checks the CPU first. Lane masks live in vector lanes as on the other
//! backends; the compiler turns compare, mask and blend chains into mask registers.

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
            _mm256_mask_storeu_epi32(b, (mask >> 8) as u8, _mm512_extracti32x8_epi32::<1>(self.0));
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

//! The portable backend: [`wide`]'s `f32x8` and `i32x8`, for the build's target (on
//! baseline x86-64 each is two SSE halves).

use wide::{f32x8, i32x8};

use super::*;

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

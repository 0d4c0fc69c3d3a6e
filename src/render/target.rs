//! Colour targets: what fragments are written into.

use glam::Vec3;

use crate::raster::map3;
use wide::{f32x8, i32x8};

/// A framebuffer a draw writes shaded fragments into. Generic so the write is
/// inlined into the fragment loop.
pub trait ColorTarget {
    /// Writes the linear RGB colour (components in 0..1) of pixel `index` (row-major).
    fn put(&mut self, index: usize, c: Vec3);
    /// Fills the whole target, resizing to `len` pixels only if needed.
    fn reset(&mut self, len: usize, c: Vec3);

    /// Writes colour lane `k` (red, green, blue lanes) to pixel `start + k` for each
    /// set bit `k` of `mask`; must store what [`ColorTarget::put`] would.
    #[inline(always)]
    fn put8(&mut self, start: usize, mask: u8, c: &[f32x8; 3]) {
        let c = c.map(f32x8::to_array);
        let mut m = mask;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            self.put(start + k, Vec3::new(c[0][k], c[1][k], c[2][k]));
            m &= m - 1;
        }
    }
}

/// 8-bit RGBA. Alpha records coverage: the background is cleared with alpha 0 and
/// every written fragment has alpha 255 (the terminal leaves uncovered samples to its
/// own background).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rgba8(pub Vec<[u8; 4]>);

/// Linear colour to an 8-bit channel (no gamma: the values are shading, not photos).
#[must_use]
#[inline(always)]
pub fn to_u8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// [`to_u8`] on 8 lanes, bit for bit (NaN gives 0 in both).
#[must_use]
#[inline(always)]
pub fn to_u8x8(v: f32x8) -> i32x8 {
    let zero = f32x8::ZERO;
    let v = v.simd_gt(zero).select(v, zero);
    let v = v.simd_lt(f32x8::ONE).select(v, f32x8::ONE);
    (v * f32x8::splat(255.0) + f32x8::splat(0.5)).trunc_int()
}

/// Lane `k` is all ones when bit `k` of `mask` is set, else zero: a mask for `select`.
#[must_use]
#[inline(always)]
pub fn lanes_of(mask: u8) -> i32x8 {
    let bits = i32x8::new([1, 2, 4, 8, 16, 32, 64, 128]);
    (i32x8::splat(i32::from(mask)) & bits).simd_eq(bits)
}

impl ColorTarget for Rgba8 {
    #[inline(always)]
    fn put(&mut self, index: usize, c: Vec3) {
        self.0[index] = [to_u8(c.x), to_u8(c.y), to_u8(c.z), 255];
    }
    #[inline(always)]
    fn put8(&mut self, start: usize, mask: u8, c: &[f32x8; 3]) {
        // Pack to little-endian RGBA words and blend all 8 pixels in one store.
        let [r, g, b] = map3(*c, to_u8x8);
        let px = r | (g << 8) | (b << 16) | i32x8::splat(0xFF << 24);
        let dst: &mut [i32; 8] = bytemuck::cast_slice_mut(&mut self.0[start..start + 8])
            .try_into()
            .expect("8 pixels");
        *dst = lanes_of(mask).select(px, i32x8::new(*dst)).to_array();
    }
    fn reset(&mut self, len: usize, c: Vec3) {
        let px = [to_u8(c.x), to_u8(c.y), to_u8(c.z), 0];
        self.0.clear();
        self.0.resize(len, px);
    }
}

/// f32 luminance (Rec. 709 weights), what the terminal glyph ramps consume.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Luma(pub Vec<f32>);

/// Rec. 709 luminance of a linear colour.
#[must_use]
#[inline(always)]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

impl ColorTarget for Luma {
    #[inline(always)]
    fn put(&mut self, index: usize, c: Vec3) {
        self.0[index] = luminance(c);
    }
    fn reset(&mut self, len: usize, c: Vec3) {
        self.0.clear();
        self.0.resize(len, luminance(c));
    }
}

/// Writes both colour and luminance (the viewer needs both).
impl<A: ColorTarget, B: ColorTarget> ColorTarget for (A, B) {
    #[inline(always)]
    fn put(&mut self, index: usize, c: Vec3) {
        self.0.put(index, c);
        self.1.put(index, c);
    }
    #[inline(always)]
    fn put8(&mut self, start: usize, mask: u8, c: &[f32x8; 3]) {
        self.0.put8(start, mask, c);
        self.1.put8(start, mask, c);
    }
    fn reset(&mut self, len: usize, c: Vec3) {
        self.0.reset(len, c);
        self.1.reset(len, c);
    }
}

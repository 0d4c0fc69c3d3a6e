//! Colour targets: what fragments are written into.

use glam::Vec3;

use crate::simd::{F32s, I32s, each3};

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
    fn put8<F: F32s>(&mut self, start: usize, mask: u8, c: &[F; 3]) {
        let c = each3!(|i| c[i].to_array());
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
    // Not fused: this also runs outside the FMA-compiled draw loop (wireframes), where
    // a fused multiply-add is a library call per channel.
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// [`to_u8`] on 8 lanes, bit for bit (NaN gives 0 in both).
#[must_use]
#[inline(always)]
pub fn to_u8x8<F: F32s>(v: F) -> F::I {
    // max(NaN, 0) is 0, as NaN's `as u8` is in `to_u8`.
    let v = v.max(F::splat(0.0)).min(F::splat(1.0));
    (v * F::splat(255.0) + F::splat(0.5)).trunc_i32()
}

impl ColorTarget for Rgba8 {
    #[inline(always)]
    fn put(&mut self, index: usize, c: Vec3) {
        self.0[index] = [to_u8(c.x), to_u8(c.y), to_u8(c.z), 255];
    }
    #[inline(always)]
    fn put8<F: F32s>(&mut self, start: usize, mask: u8, c: &[F; 3]) {
        // Pack to little-endian RGBA words and blend all 8 pixels in one store.
        let [r, g, b] = each3!(|i| to_u8x8(c[i]));
        let px = r | g.shl::<8>() | b.shl::<16>() | F::I::splat(0xFF << 24);
        let dst: &mut [i32; 8] = bytemuck::cast_slice_mut(&mut self.0[start..start + 8])
            .try_into()
            .expect("8 pixels");
        *dst = F::I::select(F::I::from_bits(mask), px, F::I::from_array(*dst)).to_array();
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
    fn put8<F: F32s>(&mut self, start: usize, mask: u8, c: &[F; 3]) {
        self.0.put8(start, mask, c);
        self.1.put8(start, mask, c);
    }
    fn reset(&mut self, len: usize, c: Vec3) {
        self.0.reset(len, c);
        self.1.reset(len, c);
    }
}

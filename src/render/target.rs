//! Colour targets: what fragments are written into.

use glam::Vec3;

/// A framebuffer a draw writes shaded fragments into. Generic so the write is
/// inlined into the fragment loop.
pub trait ColorTarget {
    /// Writes the linear RGB colour (components in 0..1) of pixel `index` (row-major).
    fn put(&mut self, index: usize, c: Vec3);
    /// Fills the whole target, resizing to `len` pixels only if needed.
    fn reset(&mut self, len: usize, c: Vec3);

    /// Writes `c[k]` to pixel `start + k` for each set bit `k` of `mask`.
    #[inline(always)]
    fn put8(&mut self, start: usize, mask: u8, c: &[Vec3; 8]) {
        let mut m = mask;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            self.put(start + k, c[k]);
            m &= m - 1;
        }
    }
}

/// 8-bit RGBA, the PNG format.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rgba8(pub Vec<[u8; 4]>);

/// Linear colour to an 8-bit channel (no gamma: the values are shading, not photos).
#[must_use]
#[inline(always)]
pub fn to_u8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

impl ColorTarget for Rgba8 {
    #[inline(always)]
    fn put(&mut self, index: usize, c: Vec3) {
        self.0[index] = [to_u8(c.x), to_u8(c.y), to_u8(c.z), 255];
    }
    fn reset(&mut self, len: usize, c: Vec3) {
        let px = [to_u8(c.x), to_u8(c.y), to_u8(c.z), 255];
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
    fn put8(&mut self, start: usize, mask: u8, c: &[Vec3; 8]) {
        self.0.put8(start, mask, c);
        self.1.put8(start, mask, c);
    }
    fn reset(&mut self, len: usize, c: Vec3) {
        self.0.reset(len, c);
        self.1.reset(len, c);
    }
}

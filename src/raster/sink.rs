//! Where traversals send coverage.
//!
//! A traversal reports covered pixels in the widest form it has: single pixels
//! (`scalar`, `planes`, partial blocks), fully covered runs (inside blocks) or 8-pixel
//! masks (`wide`). Sinks are generic parameters, so each traversal is monomorphized
//! for its sink and nothing is dispatched per pixel.

use crate::simd::I32s;

/// Receives the pixels a traversal covers. Every pixel reported lies inside the
/// target and the triangle's bounding box.
pub trait CoverageSink {
    /// Pixel `(x, y)` is covered.
    fn pixel(&mut self, x: u32, y: u32);

    /// Pixels `x0..x1` of row `y` are all covered.
    #[inline]
    fn span(&mut self, y: u32, x0: u32, x1: u32) {
        for x in x0..x1 {
            self.pixel(x, y);
        }
    }

    /// Pixel `x0 + i` of row `y` is covered for every set bit `i` of `mask`. Groups
    /// start anywhere; all 8 of `x0..x0 + 8` lie in the target whenever it is at least
    /// 8 pixels wide.
    #[inline]
    fn mask8(&mut self, y: u32, x0: u32, mask: u8) {
        let mut m = mask;
        while m != 0 {
            self.pixel(x0 + m.trailing_zeros(), y);
            m &= m - 1;
        }
    }

    /// [`CoverageSink::mask8`] with the traversal's edge lanes, for a group of
    /// `L::ROWS` rows of 8 pixels: bit `k` of `mask` (and lane `k` of `g[e]`) is pixel
    /// `x0 + k % 8` of row `y + k / 8`, and lane `k` of `g[e]` is
    /// `⌊(F0e + bias) / 256⌋` at that pixel's centre (see
    /// [`crate::raster::Setup::reduced_edge`]). A sink that needs the edge values (the
    /// fragment stage) takes them from here instead of recomputing them per edge; lanes
    /// outside `mask` hold values too but are not covered, and rows below the last one
    /// of the bounding box never have bits set.
    #[inline]
    fn edge_lanes<L: I32s>(&mut self, y: u32, x0: u32, mask: u32, g: &[L; 3]) {
        let _ = g;
        for r in 0..L::ROWS as u32 {
            let m = (mask >> (8 * r)) as u8;
            if m != 0 {
                self.mask8(y + r, x0, m);
            }
        }
    }
}

/// Per-pixel coverage counts: how many triangles covered each pixel. Used for the
/// `raster` command, for watertightness checks and as the coverage-only benchmark sink.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CountGrid {
    pub width: u32,
    pub height: u32,
    /// Row-major counts.
    pub counts: Vec<u32>,
}

impl CountGrid {
    /// An all-zero grid.
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            counts: vec![0; width as usize * height as usize],
        }
    }

    /// Resets every count to zero without reallocating.
    pub fn clear(&mut self) {
        self.counts.fill(0);
    }

    /// Count at a pixel.
    #[must_use]
    pub fn get(&self, x: u32, y: u32) -> u32 {
        self.counts[y as usize * self.width as usize + x as usize]
    }

    /// The covered pixels in row-major order.
    pub fn covered(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        let w = self.width.max(1);
        self.counts
            .iter()
            .enumerate()
            .filter(|(_, c)| **c > 0)
            .map(move |(i, _)| (i as u32 % w, i as u32 / w))
    }

    #[inline]
    fn row(&mut self, y: u32) -> &mut [u32] {
        let w = self.width as usize;
        let start = y as usize * w;
        &mut self.counts[start..start + w]
    }
}

impl CoverageSink for CountGrid {
    #[inline]
    fn pixel(&mut self, x: u32, y: u32) {
        self.row(y)[x as usize] += 1;
    }

    #[inline]
    fn span(&mut self, y: u32, x0: u32, x1: u32) {
        for c in &mut self.row(y)[x0 as usize..x1 as usize] {
            *c += 1;
        }
    }

    #[inline]
    fn mask8(&mut self, y: u32, x0: u32, mask: u8) {
        let row = self.row(y);
        let x0 = x0 as usize;
        if mask == 0xFF {
            for c in &mut row[x0..x0 + 8] {
                *c += 1;
            }
        } else {
            let mut m = mask;
            while m != 0 {
                row[x0 + m.trailing_zeros() as usize] += 1;
                m &= m - 1;
            }
        }
    }
}

/// Collects covered pixels in the order reported (for tests and the `cells` format).
impl CoverageSink for Vec<(u32, u32)> {
    #[inline]
    fn pixel(&mut self, x: u32, y: u32) {
        self.push((x, y));
    }
}

/// One bit per pixel: the cheapest complete record of coverage (1080p fits in 260 KB).
/// Bit `x % 8` of byte `x / 8` of a row.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BitMask {
    pub width: u32,
    pub height: u32,
    bytes_per_row: usize,
    bits: Vec<u8>,
}

impl BitMask {
    /// An empty mask.
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        let bytes_per_row = (width as usize).div_ceil(8);
        Self {
            width,
            height,
            bytes_per_row,
            bits: vec![0; bytes_per_row * height as usize],
        }
    }

    /// Clears every bit without reallocating.
    pub fn clear(&mut self) {
        self.bits.fill(0);
    }

    /// Whether a pixel is set.
    #[must_use]
    pub fn get(&self, x: u32, y: u32) -> bool {
        self.bits[y as usize * self.bytes_per_row + x as usize / 8] >> (x % 8) & 1 == 1
    }

    /// Number of set pixels.
    #[must_use]
    pub fn count(&self) -> u64 {
        self.bits.iter().map(|w| u64::from(w.count_ones())).sum()
    }
}

impl CoverageSink for BitMask {
    #[inline]
    fn pixel(&mut self, x: u32, y: u32) {
        self.bits[y as usize * self.bytes_per_row + x as usize / 8] |= 1 << (x % 8);
    }

    #[inline]
    fn span(&mut self, y: u32, x0: u32, x1: u32) {
        let row = y as usize * self.bytes_per_row;
        let (mut x, x1) = (x0 as usize, x1 as usize);
        while x < x1 {
            let bit = x % 8;
            let n = (8 - bit).min(x1 - x);
            self.bits[row + x / 8] |= (((1u16 << n) - 1) as u8) << bit;
            x += n;
        }
    }

    #[inline]
    fn mask8(&mut self, y: u32, x0: u32, mask: u8) {
        // A group starting at bit `b` of a byte spans that byte and the next.
        let (i, b) = (y as usize * self.bytes_per_row + x0 as usize / 8, x0 % 8);
        let bits = u16::from(mask) << b;
        self.bits[i] |= bits as u8;
        if bits > 0xFF {
            self.bits[i + 1] |= (bits >> 8) as u8;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{BitMask, CoverageSink};

    /// A group's mask lands on the same bits as its pixels one by one, wherever the
    /// group starts (the `wide` traversal places groups on runs, not on bytes).
    #[test]
    fn bit_mask_groups_start_anywhere() {
        let (w, h) = (21, 2);
        for x0 in 0..=w - 8 {
            for mask in 0..=255u8 {
                let (mut group, mut pixels) = (BitMask::new(w, h), BitMask::new(w, h));
                group.mask8(1, x0, mask);
                for k in 0..8 {
                    if mask >> k & 1 == 1 {
                        pixels.pixel(x0 + k, 1);
                    }
                }
                assert_eq!(group, pixels, "x0 {x0}, mask {mask:#010b}");
            }
        }
    }
}

use wide::{i32x8, i64x4};

use crate::raster::{CoverageSink, Setup};

/// 8 lanes of edge values, one per pixel of a row group.
trait Lanes: Copy {
    /// `base + i·step` in lane `i`.
    fn ramp(base: i64, step: i64) -> Self;
    fn splat(v: i64) -> Self;
    fn add(self, o: Self) -> Self;
    /// Bit `i` set when lane `i` is ≥ 0 in all three.
    fn inside_mask(a: Self, b: Self, c: Self) -> u8;
}

impl Lanes for i32x8 {
    #[inline(always)]
    fn ramp(base: i64, step: i64) -> Self {
        // Exact: `fits_i32` bounded every lane value before this path was chosen.
        i32x8::new(std::array::from_fn(|i| (base + i as i64 * step) as i32))
    }
    #[inline(always)]
    fn splat(v: i64) -> Self {
        i32x8::splat(v as i32)
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self + o
    }
    #[inline(always)]
    fn inside_mask(a: Self, b: Self, c: Self) -> u8 {
        // The OR of three values is negative iff one of them is: one sign-bit mask.
        !((a | b | c).to_bitmask() as u8)
    }
}

/// The `i64` fallback for boxes too large for `i32` lanes: two `i64x4` halves.
#[derive(Clone, Copy)]
struct Lanes64(i64x4, i64x4);

impl Lanes for Lanes64 {
    #[inline(always)]
    fn ramp(base: i64, step: i64) -> Self {
        let l = |o: i64| i64x4::new(std::array::from_fn(|i| base + (i as i64 + o) * step));
        Lanes64(l(0), l(4))
    }
    #[inline(always)]
    fn splat(v: i64) -> Self {
        Lanes64(i64x4::splat(v), i64x4::splat(v))
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Lanes64(self.0 + o.0, self.1 + o.1)
    }
    #[inline(always)]
    fn inside_mask(a: Self, b: Self, c: Self) -> u8 {
        let lo = (a.0 | b.0 | c.0).to_bitmask() as u8;
        let hi = (a.1 | b.1 | c.1).to_bitmask() as u8;
        !(lo | (hi << 4))
    }
}

/// Whether every value the `wide` traversal forms for this setup fits in `i32`:
/// the edge values over the bounding box widened to whole 8-pixel groups, plus the
/// group step `8·I`. Edge functions are affine, so checking the corners suffices.
#[must_use]
pub fn fits_i32(s: &Setup) -> bool {
    let b = s.bbox;
    let groups = i64::from(b.width().div_ceil(8));
    let x0 = i64::from(b.x0);
    let x1 = x0 + groups * 8 - 1;
    let m = s.max_abs_edge(x0, i64::from(b.y0), x1, i64::from(b.y1));
    let step = s
        .step_x()
        .iter()
        .map(|v| (v * 8).unsigned_abs())
        .max()
        .unwrap_or(0);
    m.max(step) <= i32::MAX as u64
}

/// Pixel-parallel traversal: 8 pixels per step, the fast path. Row starts are stepped
/// exactly in `i64`; within a row the lanes step by `8·I` in `i32x8` when the box
/// allows it (almost always), else in two `i64x4`.
pub fn wide<S: CoverageSink>(s: &Setup, sink: &mut S) {
    if fits_i32(s) {
        walk::<i32x8, S>(s, sink);
    } else {
        walk::<Lanes64, S>(s, sink);
    }
}

#[inline(always)]
fn walk<L: Lanes, S: CoverageSink>(s: &Setup, sink: &mut S) {
    let b = s.bbox;
    let (sx, sy) = (s.step_x(), s.step_y());
    let step8 = sx.map(|v| L::splat(v * 8));
    let mut row = s.edges_at_origin();
    for y in b.y0..=b.y1 {
        let mut f = [0, 1, 2].map(|e| L::ramp(row[e], sx[e]));
        let mut x = b.x0;
        loop {
            let mut m = L::inside_mask(f[0], f[1], f[2]);
            let left = b.x1 - x;
            if left < 7 {
                m &= (1u8 << (left + 1)) - 1;
            }
            if m != 0 {
                sink.mask8(y, x, m);
            }
            if left < 8 {
                break;
            }
            x += 8;
            for e in 0..3 {
                f[e] = f[e].add(step8[e]);
            }
        }
        for e in 0..3 {
            row[e] += sy[e];
        }
    }
}

//! Anti-aliasing: supersampled coverage, and the exact area it approximates.
//!
//! `samples` per pixel (1, 4 or 16) are an ordered `n × n` grid at the centres of the
//! pixel's sub-squares: the triangle is scaled by `n` and rasterized by the exact path
//! on an `n`-times larger target, and a pixel's coverage is the fraction of its samples
//! covered. The reference is the exact area of the triangle (on the same 1/256 px
//! grid) inside each pixel square, by polygon clipping in f64.

pub use crate::raster::samples::grid_side;
use crate::raster::traverse::wide;
use crate::raster::{CoverageSink, SUBPIXEL_ONE, Setup, Target, snap};
use crate::workload::Tri2;

/// Samples per pixel of the anti-aliasing variants.
pub const SAMPLE_COUNTS: [u32; 3] = [1, 4, 16];

/// The name of a sample count in tables (`1x`, `4x`, `16x`).
#[must_use]
pub fn aa_name(samples: u32) -> &'static str {
    match samples {
        1 => "1x",
        4 => "4x",
        16 => "16x",
        _ => "?x",
    }
}

/// The triangle snapped to the 1/256 px grid, as the rasterizer sees it.
#[must_use]
pub fn snapped(tri: Tri2) -> Option<Tri2> {
    let mut out = [[0.0; 2]; 3];
    for (o, p) in out.iter_mut().zip(tri) {
        for (c, v) in o.iter_mut().zip(p) {
            *c = snap(v)? as f64 / SUBPIXEL_ONE as f64;
        }
    }
    Some(out)
}

/// Per-pixel sample counts of one triangle within its pixel bounding box.
#[derive(Clone, Debug, Default)]
pub struct Supersampled {
    /// First pixel column and row of the box.
    pub x0: u32,
    pub y0: u32,
    /// Box width in pixels.
    pub width: u32,
    /// Covered samples per pixel, row-major over the box.
    pub counts: Vec<u8>,
    /// Samples per pixel.
    pub samples: u32,
}

impl Supersampled {
    /// The covered fraction of pixel `(x, y)` of the box's rows, 0 outside.
    #[must_use]
    pub fn coverage(&self, x: u32, y: u32) -> f64 {
        if x < self.x0 || y < self.y0 || self.width == 0 {
            return 0.0;
        }
        let (i, j) = ((x - self.x0) as usize, (y - self.y0) as usize);
        if i >= self.width as usize {
            return 0.0;
        }
        self.counts
            .get(j * self.width as usize + i)
            .map_or(0.0, |&c| f64::from(c) / f64::from(self.samples))
    }
}

struct Resolve<'a> {
    out: &'a mut Supersampled,
    n: u32,
}

impl CoverageSink for Resolve<'_> {
    #[inline]
    fn pixel(&mut self, x: u32, y: u32) {
        let o = &mut *self.out;
        let i = (y / self.n - o.y0) as usize * o.width as usize + (x / self.n - o.x0) as usize;
        o.counts[i] += 1;
    }
}

/// Rasterizes `tri` with `samples` per pixel into `out` (its buffer is reused).
pub fn supersample(tri: Tri2, target: Target, samples: u32, out: &mut Supersampled) {
    let n = grid_side(samples);
    out.samples = n * n;
    out.counts.clear();
    out.width = 0;
    let fine = Target::new(target.width * n, target.height * n);
    let scaled = tri.map(|p| p.map(|c| c * f64::from(n)));
    let Ok(s) = Setup::new(scaled, fine) else {
        return;
    };
    let b = s.bbox;
    out.x0 = b.x0 / n;
    out.y0 = b.y0 / n;
    out.width = b.x1 / n - out.x0 + 1;
    let rows = b.y1 / n - out.y0 + 1;
    out.counts.resize(out.width as usize * rows as usize, 0);
    wide(&s, &mut Resolve { out, n });
}

/// Calls `f(x, y, area)` for every pixel of the target whose square the triangle
/// overlaps with positive area, with the exact overlap area (pixel units, f64).
pub fn pixel_areas(tri: Tri2, target: Target, mut f: impl FnMut(u32, u32, f64)) {
    if tri.iter().flatten().any(|c| !c.is_finite()) {
        return;
    }
    let poly = Poly::from(tri);
    let (lo, hi) = poly.y_range();
    let y0 = lo.floor().max(0.0) as u32;
    let y1 = (hi.ceil() as i64).clamp(0, i64::from(target.height)) as u32;
    for y in y0..y1 {
        let band = poly
            .clip(1, f64::from(y), true)
            .clip(1, f64::from(y + 1), false);
        if band.len < 3 {
            continue;
        }
        let (xl, xh) = band.x_range();
        let x0 = xl.floor().max(0.0) as u32;
        let x1 = (xh.ceil() as i64).clamp(0, i64::from(target.width)) as u32;
        for x in x0..x1 {
            let cell = band
                .clip(0, f64::from(x), true)
                .clip(0, f64::from(x + 1), false);
            let a = cell.area();
            if a > 0.0 {
                f(x, y, a);
            }
        }
    }
}

/// A convex polygon of at most 7 vertices (a triangle clipped by four axis lines).
#[derive(Clone, Copy)]
struct Poly {
    v: [[f64; 2]; 7],
    len: usize,
}

impl From<Tri2> for Poly {
    fn from(t: Tri2) -> Self {
        let mut v = [[0.0; 2]; 7];
        v[..3].copy_from_slice(&t);
        Self { v, len: 3 }
    }
}

impl Poly {
    fn y_range(&self) -> (f64, f64) {
        self.range(1)
    }

    fn x_range(&self) -> (f64, f64) {
        self.range(0)
    }

    fn range(&self, c: usize) -> (f64, f64) {
        self.v[..self.len]
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[c]), hi.max(p[c]))
            })
    }

    /// Keeps the part with coordinate `c` ≥ `at` (`keep_above`) or ≤ `at`.
    fn clip(&self, c: usize, at: f64, keep_above: bool) -> Poly {
        let mut out = Poly {
            v: [[0.0; 2]; 7],
            len: 0,
        };
        let side = |p: &[f64; 2]| if keep_above { p[c] - at } else { at - p[c] };
        for i in 0..self.len {
            let (a, b) = (self.v[i], self.v[(i + 1) % self.len]);
            let (da, db) = (side(&a), side(&b));
            if da >= 0.0 && out.len < 7 {
                out.v[out.len] = a;
                out.len += 1;
            }
            if (da >= 0.0) != (db >= 0.0) && out.len < 7 {
                let t = da / (da - db);
                let mut p = [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
                p[c] = at;
                out.v[out.len] = p;
                out.len += 1;
            }
        }
        out
    }

    /// Unsigned area (shoelace formula).
    fn area(&self) -> f64 {
        if self.len < 3 {
            return 0.0;
        }
        let mut s = 0.0;
        for i in 0..self.len {
            let (a, b) = (self.v[i], self.v[(i + 1) % self.len]);
            s += a[0] * b[1] - a[1] * b[0];
        }
        s.abs() * 0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn areas_sum_to_the_triangle_area_and_stay_in_pixels() {
        let tri = [[1.3, 0.7], [17.9, 4.2], [6.1, 12.8]];
        let target = Target::new(32, 32);
        let mut total = 0.0;
        pixel_areas(tri, target, |x, y, a| {
            assert!(x < 32 && y < 32);
            assert!(a > 0.0 && a <= 1.0 + 1e-12, "{a}");
            total += a;
        });
        let want = 0.5
            * ((tri[1][0] - tri[0][0]) * (tri[2][1] - tri[0][1])
                - (tri[1][1] - tri[0][1]) * (tri[2][0] - tri[0][0]))
                .abs();
        assert!((total - want).abs() < 1e-9, "{total} vs {want}");
    }

    #[test]
    fn a_pixel_square_split_in_two_has_half_coverage() {
        let target = Target::new(4, 4);
        let mut seen = vec![];
        pixel_areas([[1.0, 1.0], [2.0, 1.0], [2.0, 2.0]], target, |x, y, a| {
            seen.push((x, y, a));
        });
        assert_eq!(seen, vec![(1, 1, 0.5)]);
        // 16 samples on a 4×4 grid: 6 lie strictly inside, 4 on the diagonal C→A,
        // which goes up and so is a left edge that owns them: 10 of 16.
        let mut ss = Supersampled::default();
        supersample([[1.0, 1.0], [2.0, 1.0], [2.0, 2.0]], target, 16, &mut ss);
        assert_eq!(ss.coverage(1, 1), 0.625);
        assert_eq!(ss.coverage(0, 0), 0.0);
    }

    #[test]
    fn full_pixels_are_fully_covered_at_every_sample_count() {
        let target = Target::new(8, 8);
        let tri = [[-10.0, -10.0], [30.0, -10.0], [-10.0, 30.0]];
        for samples in SAMPLE_COUNTS {
            let mut ss = Supersampled::default();
            supersample(tri, target, samples, &mut ss);
            assert_eq!(ss.coverage(3, 3), 1.0, "{samples}");
        }
    }
}

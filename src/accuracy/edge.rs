//! Edge-function arithmetic variants: the same coverage test computed in different
//! number formats.
//!
//! `fixed8` is the renderer's own path (vertices on the 1/256 px grid, `wide`
//! traversal); `i64` is the same grid walked by the scalar traversal with 64-bit steps;
//! `fixed4` snaps vertices to 1/16 px and then runs the exact path, so its only error is
//! the coarser grid. The float variants get the same snapped vertices and use the
//! textbook formulation, `F = I·x + J·y + K` with `K = Ax·By − Ay·Bx`, with the top-left
//! rule applied to exact zeros: `f32-direct` and `f64` evaluate it at every pixel
//! centre, `f32-incremental` steps it by `I` per pixel and `J` per row. Their errors are therefore the arithmetic's alone: rounding in `K` far from
//! the origin and near edges, and drift along long rows. (Direct evaluation is
//! sign-symmetric on a shared edge, `F_ba = −F_ab` bit for bit, so it cannot crack
//! there; stepping from each triangle's own origin can.)

use super::area::snapped;
use crate::raster::traverse::{scalar, wide};
use crate::raster::{CoverageSink, Setup, Target};
use crate::workload::Tri2;

/// One edge-arithmetic variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EdgeArith {
    /// f32, every pixel evaluated from `I, J, K`.
    F32Direct,
    /// f32, stepped by adds from the bounding-box origin.
    F32Incremental,
    /// f64, every pixel evaluated from `I, J, K`.
    F64,
    /// Vertices on a 1/16 px grid, exact integer edges.
    Fixed4,
    /// Vertices on a 1/256 px grid, exact integer edges: the renderer's default.
    Fixed8,
    /// The 1/256 px grid, 64-bit integers throughout (scalar traversal).
    I64,
}

impl EdgeArith {
    /// Every variant, in table order.
    pub const ALL: [EdgeArith; 6] = [
        EdgeArith::F32Direct,
        EdgeArith::F32Incremental,
        EdgeArith::F64,
        EdgeArith::Fixed4,
        EdgeArith::Fixed8,
        EdgeArith::I64,
    ];

    /// The name in tables and CSV.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            EdgeArith::F32Direct => "f32-direct",
            EdgeArith::F32Incremental => "f32-incremental",
            EdgeArith::F64 => "f64",
            EdgeArith::Fixed4 => "fixed4",
            EdgeArith::Fixed8 => "fixed8",
            EdgeArith::I64 => "i64",
        }
    }

    /// Whether the variant is exact on the 1/256 px grid (equals the oracle).
    #[must_use]
    pub fn exact(self) -> bool {
        matches!(self, EdgeArith::Fixed8 | EdgeArith::I64)
    }

    /// Rasterizes one triangle (pixel coordinates) into `sink`.
    pub fn rasterize<S: CoverageSink>(self, tri: Tri2, target: Target, sink: &mut S) {
        match self {
            EdgeArith::Fixed8 => {
                if let Ok(s) = Setup::new(tri, target) {
                    wide(&s, sink);
                }
            }
            EdgeArith::I64 => {
                if let Ok(s) = Setup::new(tri, target) {
                    scalar(&s, sink);
                }
            }
            EdgeArith::Fixed4 => {
                // Snap to 1/16 px, then express the result on the 1/256 grid exactly.
                let coarse = tri.map(|p| p.map(|c| (c * 16.0).round() / 16.0));
                if let Ok(s) = Setup::new(coarse, target) {
                    wide(&s, sink);
                }
            }
            EdgeArith::F64 => float_edges::<f64, S>(tri, target, false, sink),
            EdgeArith::F32Direct => float_edges::<f32, S>(tri, target, false, sink),
            EdgeArith::F32Incremental => float_edges::<f32, S>(tri, target, true, sink),
        }
    }
}

/// The arithmetic the float variants need.
trait Float:
    Copy
    + PartialOrd
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::AddAssign
{
    const ZERO: Self;
    fn of(v: f64) -> Self;
}

impl Float for f32 {
    const ZERO: Self = 0.0;
    #[inline(always)]
    fn of(v: f64) -> Self {
        v as f32
    }
}

impl Float for f64 {
    const ZERO: Self = 0.0;
    #[inline(always)]
    fn of(v: f64) -> Self {
        v
    }
}

/// Seed 000's edge functions in a float type `T` on unsnapped vertices.
fn float_edges<T: Float, S: CoverageSink>(
    tri: Tri2,
    target: Target,
    incremental: bool,
    sink: &mut S,
) {
    let Some(tri) = snapped(tri) else { return };
    let mut v = tri.map(|p| p.map(T::of));
    let cross = |a: [T; 2], b: [T; 2], c: [T; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let area = cross(v[0], v[1], v[2]);
    if area == T::ZERO || area.partial_cmp(&T::ZERO).is_none() {
        return;
    }
    if area < T::ZERO {
        v.swap(1, 2);
    }
    let mut i = [T::ZERO; 3];
    let mut j = [T::ZERO; 3];
    let mut k = [T::ZERO; 3];
    let mut top_left = [false; 3];
    for e in 0..3 {
        let (a, b) = (v[e], v[(e + 1) % 3]);
        i[e] = a[1] - b[1];
        j[e] = b[0] - a[0];
        k[e] = a[0] * b[1] - a[1] * b[0];
        top_left[e] = b[1] < a[1] || (b[1] == a[1] && b[0] > a[0]);
    }
    // Pixels whose centres lie in the float bounding box, clipped to the target.
    let lo = |c: usize| tri.iter().map(|p| p[c]).fold(f64::INFINITY, f64::min);
    let hi = |c: usize| tri.iter().map(|p| p[c]).fold(f64::NEG_INFINITY, f64::max);
    let first = |l: f64| (l - 0.5).ceil().max(0.0);
    let last = |h: f64, n: u32| (h - 0.5).floor().min(f64::from(n) - 1.0);
    let (x0, x1) = (first(lo(0)), last(hi(0), target.width));
    let (y0, y1) = (first(lo(1)), last(hi(1), target.height));
    if x0 > x1 || y0 > y1 {
        return;
    }
    let (x0, x1, y0, y1) = (x0 as u32, x1 as u32, y0 as u32, y1 as u32);
    let inside = |f: T, e: usize| f > T::ZERO || (f == T::ZERO && top_left[e]);
    let centre = |n: u32| T::of(f64::from(n) + 0.5);
    if incremental {
        let (cx, cy) = (centre(x0), centre(y0));
        let mut row = [0, 1, 2].map(|e| i[e] * cx + j[e] * cy + k[e]);
        for y in y0..=y1 {
            let mut f = row;
            for x in x0..=x1 {
                if (0..3).all(|e| inside(f[e], e)) {
                    sink.pixel(x, y);
                }
                for e in 0..3 {
                    f[e] += i[e];
                }
            }
            for e in 0..3 {
                row[e] += j[e];
            }
        }
    } else {
        for y in y0..=y1 {
            let py = centre(y);
            for x in x0..=x1 {
                let px = centre(x);
                if (0..3).all(|e| inside(i[e] * px + j[e] * py + k[e], e)) {
                    sink.pixel(x, y);
                }
            }
        }
    }
}

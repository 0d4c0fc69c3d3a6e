//! Triangle setup: snapping, winding, edge coefficients, fill-rule bias and bounds.
//!
//! Everything here is computed once per triangle and shared by every traversal, the
//! probe and the 3D pipeline, so they cannot disagree about which pixels are covered.

use crate::simd::each3;

/// Fractional bits of the vertex grid: vertices snap to 1/256 px.
pub const SUBPIXEL_BITS: u32 = 8;
/// One pixel in subpixel units.
pub const SUBPIXEL_ONE: i64 = 1 << SUBPIXEL_BITS;
/// Offset of a pixel centre from its corner, in subpixel units.
pub const HALF_PIXEL: i64 = SUBPIXEL_ONE / 2;
/// Largest accepted |coordinate| in pixels. With 8 subpixel bits a coordinate needs at
/// most 29 bits, an edge delta 30, `K` and `area2` at most 60: setup never overflows `i64`.
pub const GUARD_BAND_PX: f64 = (1u64 << 20) as f64;
/// Largest target side in pixels; pixel centres then need at most 25 bits.
pub const MAX_TARGET_SIDE: u32 = 1 << 16;

/// Snaps a pixel-space coordinate to the subpixel grid (round to nearest, ties away
/// from zero). `None` for NaN, infinities and anything beyond the guard band.
#[must_use]
#[inline]
pub fn snap(v: f64) -> Option<i64> {
    if v.is_finite() && v.abs() <= GUARD_BAND_PX {
        // `f64::round` is a library call on baseline x86-64 and this runs six times per
        // triangle. `as` truncates, and `t − trunc(t)` is exact for |t| < 2^52, so the
        // half-way test on it rounds exactly as `round` does.
        let t = v * SUBPIXEL_ONE as f64;
        let i = t as i64;
        let frac = t - i as f64;
        Some(i + i64::from(frac >= 0.5) - i64::from(frac <= -0.5))
    } else {
        None
    }
}

/// The size of a render target in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Target {
    pub width: u32,
    pub height: u32,
}

impl Target {
    /// A target; sides are clamped to [`MAX_TARGET_SIDE`].
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width: width.min(MAX_TARGET_SIDE),
            height: height.min(MAX_TARGET_SIDE),
        }
    }

    /// Number of pixels.
    #[must_use]
    pub fn len(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// True when the target has no pixels.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// An inclusive rectangle of pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl PixelRect {
    /// Whether the pixel lies inside.
    #[must_use]
    pub fn contains(&self, x: u32, y: u32) -> bool {
        x >= self.x0 && x <= self.x1 && y >= self.y0 && y <= self.y1
    }

    /// Width in pixels.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.x1 - self.x0 + 1
    }

    /// Height in pixels.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.y1 - self.y0 + 1
    }
}

/// Why a triangle produced no setup.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reject {
    /// A coordinate was NaN or infinite.
    NonFinite,
    /// A coordinate lies beyond ±[`GUARD_BAND_PX`].
    BeyondGuardBand,
    /// The snapped vertices are collinear (zero area).
    ZeroArea,
    /// No pixel centre of the target lies in the triangle's bounding box.
    Offscreen,
}

impl std::fmt::Display for Reject {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Reject::NonFinite => "non-finite coordinate",
            Reject::BeyondGuardBand => "beyond the guard band",
            Reject::ZeroArea => "zero area after snapping",
            Reject::Offscreen => "no pixel centre in its bounding box",
        })
    }
}

/// Names of the three edge functions, in index order (`docs/rasterization.md`).
pub const EDGE_NAMES: [&str; 3] = ["F01", "F02", "F03"];

/// One triangle ready for traversal: what the traversals read, and no more, since a
/// threaded draw writes one per triangle and reads it back.
///
/// Edge `e` runs from vertex `e` to vertex `(e + 1) % 3` of the snapped vertices A, B,
/// C in positive-area order: index 0 is `F01` (A→B), 1 is `F02` (B→C), 2 is `F03`
/// (C→A). The constant terms `K0e` are not kept: [`Setup::origin`] holds the same
/// information at the box's first pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Setup {
    /// True when the input was wound the other way and B, C were swapped.
    pub flipped: bool,
    /// `I0e`: change of `F0e` per subpixel step in x.
    pub i: [i64; 3],
    /// `J0e`: change of `F0e` per subpixel step in y.
    pub j: [i64; 3],
    /// 0 for top and left edges, −1 for the others (the fill rule).
    pub bias: [i64; 3],
    /// Doubled area in subpixel² units, always > 0; equals `F01 + F02 + F03` everywhere.
    pub area2: i64,
    /// Pixels whose centres lie in the triangle's bounding box, clipped to the target.
    pub bbox: PixelRect,
    /// Biased `F0e` at the centre of the box's first pixel `(x0, y0)`: where every
    /// traversal starts, computed once because the set-up record, the range checks and
    /// the traversals all start from it.
    pub origin: [i64; 3],
}

impl Setup {
    /// Sets up a triangle given in pixel coordinates.
    pub fn new(tri: [[f64; 2]; 3], target: Target) -> Result<Self, Reject> {
        let mut v = [[0i64; 2]; 3];
        for (s, p) in v.iter_mut().zip(tri) {
            for (c, x) in s.iter_mut().zip(p) {
                if !x.is_finite() {
                    return Err(Reject::NonFinite);
                }
                *c = snap(x).ok_or(Reject::BeyondGuardBand)?;
            }
        }
        Self::from_snapped(v, target)
    }

    /// Sets up a triangle whose vertices are already on the subpixel grid, rejecting
    /// any coordinate beyond the guard band (whose bound keeps set-up within `i64`).
    #[inline(always)]
    pub fn from_fixed(v: [[i64; 2]; 3], target: Target) -> Result<Self, Reject> {
        if !v.iter().flatten().all(|&c| in_band(c)) {
            return Err(Reject::BeyondGuardBand);
        }
        Self::from_snapped(v, target)
    }

    /// [`Setup::from_fixed`] for vertices that [`snap`] gave, and so lie within the
    /// guard band (which keeps every product below in `i64`): the renderer's vertices
    /// are all checked once when projected, not again for each triangle. Inlined so the
    /// renderer builds the setup in place in its per-triangle record.
    #[inline(always)]
    pub(crate) fn from_snapped(mut v: [[i64; 2]; 3], target: Target) -> Result<Self, Reject> {
        debug_assert!(v.iter().flatten().all(|&c| in_band(c)), "{v:?}");
        // The box first: at terminal resolutions many triangles hold no pixel centre.
        let bbox = pixel_bounds(&v, target).ok_or(Reject::Offscreen)?;
        let area2 = signed_area2(&v);
        if area2 == 0 {
            return Err(Reject::ZeroArea);
        }
        let flipped = area2 < 0;
        if flipped {
            v.swap(1, 2);
        }
        let area2 = area2.abs();

        let mut i = [0; 3];
        let mut j = [0; 3];
        let mut k = [0; 3];
        let mut bias = [0; 3];
        for e in 0..3 {
            let a = v[e];
            let b = v[(e + 1) % 3];
            i[e] = a[1] - b[1];
            j[e] = b[0] - a[0];
            k[e] = a[0] * b[1] - a[1] * b[0];
            let left = b[1] < a[1];
            let top = b[1] == a[1] && b[0] > a[0];
            bias[e] = if left || top { 0 } else { -1 };
        }
        let px = i64::from(bbox.x0) * SUBPIXEL_ONE + HALF_PIXEL;
        let py = i64::from(bbox.y0) * SUBPIXEL_ONE + HALF_PIXEL;
        let origin = each3!(|e| i[e] * px + j[e] * py + k[e] + bias[e]);

        Ok(Self {
            flipped,
            i,
            j,
            bias,
            area2,
            bbox,
            origin,
        })
    }

    /// Raw `F0e` (no fill-rule bias) at a point given in subpixel units.
    #[must_use]
    #[inline]
    pub fn edge_at_subpixel(&self, e: usize, px: i64, py: i64) -> i64 {
        // From the box's first pixel centre, where the biased value is `origin`.
        let x0 = i64::from(self.bbox.x0) * SUBPIXEL_ONE + HALF_PIXEL;
        let y0 = i64::from(self.bbox.y0) * SUBPIXEL_ONE + HALF_PIXEL;
        self.origin[e] - self.bias[e] + self.i[e] * (px - x0) + self.j[e] * (py - y0)
    }

    /// Raw `F0e` (no fill-rule bias) at the centre of pixel `(x, y)`, evaluated directly.
    #[must_use]
    #[inline]
    pub fn edge_raw(&self, e: usize, x: i64, y: i64) -> i64 {
        let px = x * SUBPIXEL_ONE + HALF_PIXEL;
        let py = y * SUBPIXEL_ONE + HALF_PIXEL;
        self.edge_at_subpixel(e, px, py)
    }

    /// Screen-space barycentrics `(u, v, w)` of the caller's vertices A, B, C at a point in
    /// subpixel units (`u = F02/area2`, `v = F03/area2`,
    /// `w = F01/area2`), exact up to the final division.
    #[must_use]
    pub fn barycentric_at_subpixel(&self, px: i64, py: i64) -> [f64; 3] {
        let a = self.area2 as f64;
        let f = [0, 1, 2].map(|e| self.edge_at_subpixel(e, px, py) as f64 / a);
        self.unflip([f[1], f[2], f[0]])
    }

    /// Biased `F0e` at the centre of pixel `(x, y)`: the value the traversals test `≥ 0`.
    #[must_use]
    #[inline]
    pub fn edge(&self, e: usize, x: i64, y: i64) -> i64 {
        self.edge_raw(e, x, y) + self.bias[e]
    }

    /// `G0e = ⌊(F0e + bias) / 256⌋` at the centre of pixel `(x, y)`: the value the `wide`
    /// traversal carries in its lanes. At pixel centres `F0e = 256·(I·x + J·y) + c`, so
    /// `G0e` steps by exactly `I` per pixel and `J` per row, has the sign of the biased
    /// `F0e`, and `F0e − 256·G0e` is the same for every pixel of the triangle.
    #[must_use]
    #[inline]
    pub fn reduced_edge(&self, e: usize, x: i64, y: i64) -> i64 {
        self.edge(e, x, y) >> SUBPIXEL_BITS
    }

    /// The three biased edge values at a pixel centre.
    #[must_use]
    #[inline]
    pub fn edges(&self, x: i64, y: i64) -> [i64; 3] {
        [self.edge(0, x, y), self.edge(1, x, y), self.edge(2, x, y)]
    }

    /// Whether the pixel centre is covered, by direct evaluation.
    #[must_use]
    #[inline]
    pub fn covers(&self, x: u32, y: u32) -> bool {
        self.bbox.contains(x, y) && self.edges(x.into(), y.into()).iter().all(|&f| f >= 0)
    }

    /// Per-pixel step of each edge function in x (`I0e` times one pixel).
    #[must_use]
    #[inline]
    pub fn step_x(&self) -> [i64; 3] {
        self.i.map(|i| i * SUBPIXEL_ONE)
    }

    /// Per-pixel step of each edge function in y (`J0e` times one pixel).
    #[must_use]
    #[inline]
    pub fn step_y(&self) -> [i64; 3] {
        self.j.map(|j| j * SUBPIXEL_ONE)
    }

    /// The edge values at the bbox origin, the first value every traversal starts from
    /// ([`Setup::origin`]).
    #[must_use]
    #[inline]
    pub fn edges_at_origin(&self) -> [i64; 3] {
        self.origin
    }

    /// [`Setup::reduced_edge`] at the bbox origin: where the `wide` traversal starts.
    #[must_use]
    #[inline(always)]
    pub fn reduced_at_origin(&self) -> [i64; 3] {
        each3!(|e| self.origin[e] >> SUBPIXEL_BITS)
    }

    /// The same triangle with its box limited to rows `y0..=y1`, or `None` when the box
    /// has no row there. The origin moves by whole rows (exact), so every traversal
    /// gives the same edge values at each pixel as it does over the whole box: what
    /// lets a band of rows be walked on its own.
    #[must_use]
    #[inline(always)]
    pub fn rows(&self, y0: u32, y1: u32) -> Option<Setup> {
        let b = self.bbox;
        let (lo, hi) = (b.y0.max(y0), b.y1.min(y1));
        if lo > hi {
            return None;
        }
        let down = i64::from(lo - b.y0) * SUBPIXEL_ONE;
        Some(Setup {
            bbox: PixelRect {
                y0: lo,
                y1: hi,
                ..b
            },
            origin: each3!(|e| self.origin[e] + self.j[e] * down),
            ..*self
        })
    }

    /// Maps a barycentric triple in setup order (A, B, C after any flip) back to the
    /// caller's vertex order.
    #[must_use]
    #[inline]
    pub fn unflip<T: Copy>(&self, b: [T; 3]) -> [T; 3] {
        if self.flipped { [b[0], b[2], b[1]] } else { b }
    }
}

/// Twice the signed area of snapped vertices `v`, as [`Setup::from_snapped`] finds it:
/// negative for a triangle counter-clockwise in NDC (y-up), which the set-up marks
/// [`Setup::flipped`]. `v` must lie within the guard band, which keeps it in `i64`.
#[must_use]
#[inline(always)]
pub(crate) fn signed_area2(v: &[[i64; 2]; 3]) -> i64 {
    let [a, b, c] = *v;
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Whether a coordinate in subpixels lies within the guard band (as every one [`snap`]
/// returns does).
fn in_band(c: i64) -> bool {
    c.abs() <= (GUARD_BAND_PX as i64) * SUBPIXEL_ONE
}

/// Per axis, the first and last pixel whose centre lies within the snapped vertices'
/// extent (unclamped to any target).
#[inline(always)]
fn centre_span(v: &[[i64; 2]; 3]) -> [[i64; 2]; 2] {
    // Written out: iterator chains here stay out of line in the renderer's loop.
    let lo = |c: usize| v[0][c].min(v[1][c]).min(v[2][c]);
    let hi = |c: usize| v[0][c].max(v[1][c]).max(v[2][c]);
    // Centre of pixel n is n*256 + 128: first centre ≥ lo, last centre ≤ hi.
    let first = |lo: i64| (lo - HALF_PIXEL + SUBPIXEL_ONE - 1).div_euclid(SUBPIXEL_ONE);
    let last = |hi: i64| (hi - HALF_PIXEL).div_euclid(SUBPIXEL_ONE);
    [[first(lo(0)), last(hi(0))], [first(lo(1)), last(hi(1))]]
}

/// Whether the box of a triangle with snapped vertices `v` would hold pixel `(x, y)`
/// of a target that holds the pixel: [`Setup::bbox`]'s test, without the set-up.
#[inline]
#[must_use]
pub fn box_holds(v: &[[i64; 2]; 3], x: u32, y: u32) -> bool {
    let [[x0, x1], [y0, y1]] = centre_span(v);
    (x0..=x1).contains(&i64::from(x)) && (y0..=y1).contains(&i64::from(y))
}

/// The first and last row of the box of a triangle with snapped vertices `v`,
/// unclamped to any target: [`Setup::bbox`]'s rows, without the set-up.
#[inline(always)]
#[must_use]
pub fn box_rows(v: &[[i64; 2]; 3]) -> [i64; 2] {
    centre_span(v)[1]
}

/// Pixels whose centres lie within the vertices' bounding box, clipped to the target.
#[inline(always)]
fn pixel_bounds(v: &[[i64; 2]; 3], target: Target) -> Option<PixelRect> {
    if target.is_empty() {
        return None;
    }
    let [[x0, x1], [y0, y1]] = centre_span(v);
    let (x0, y0) = (x0.max(0), y0.max(0));
    let x1 = x1.min(i64::from(target.width) - 1);
    let y1 = y1.min(i64::from(target.height) - 1);
    if x0 > x1 || y0 > y1 {
        return None;
    }
    Some(PixelRect {
        x0: x0 as u32,
        y0: y0 as u32,
        x1: x1 as u32,
        y1: y1 as u32,
    })
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    proptest! {
        /// The sign that culls a back face before its set-up ([`signed_area2`]) is the
        /// winding the set-up itself finds, and both are the shoelace formula's (in
        /// `i128`): negative for a triangle counter-clockwise in NDC (y up), a front face.
        #[test]
        fn signed_area_gives_the_setups_winding(
            v in prop::array::uniform3((0i64..64 * SUBPIXEL_ONE, 0i64..48 * SUBPIXEL_ONE)),
        ) {
            let v = v.map(|(x, y)| [x, y]);
            let shoelace: i128 = (0..3)
                .map(|i| {
                    let (a, b) = (v[i], v[(i + 1) % 3]);
                    i128::from(a[0]) * i128::from(b[1]) - i128::from(b[0]) * i128::from(a[1])
                })
                .sum();
            prop_assert_eq!(i128::from(signed_area2(&v)), shoelace);
            let area = shoelace;
            match Setup::from_snapped(v, Target::new(64, 48)) {
                Ok(s) => prop_assert_eq!(s.flipped, area < 0),
                Err(Reject::ZeroArea) => prop_assert_eq!(area, 0),
                Err(_) => prop_assert!(area != 0),
            }
        }
    }
}

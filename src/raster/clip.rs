//! Homogeneous clipping, before the divide by w.
//!
//! Triangles are clipped against the near plane (`z ≥ 0` in the directx-style clip
//! space, i.e. `w ≥ near > 0`) and the far plane (`z ≤ w`), so only `w > 0` reaches the
//! rasterizer and nothing behind the eye is ever drawn. x and y are left to the
//! rasterizer's guard band: they are only clipped against planes at the guard band
//! itself (`|x| ≤ g·w`), which a vertex crosses only when it would otherwise be
//! rejected by setup. Everything is in fixed-size arrays: nothing is allocated.

use glam::Vec4;

use super::interp::Varying;

/// The most vertices a triangle can have after six planes (each plane adds at most
/// one to a convex polygon).
pub const MAX_CLIPPED: usize = 9;

/// A clip-space vertex with its varyings.
#[derive(Clone, Copy, Debug)]
pub struct ClipVertex<V> {
    pub pos: Vec4,
    pub var: V,
}

/// A convex polygon of at most [`MAX_CLIPPED`] vertices.
#[derive(Clone, Copy, Debug)]
pub struct Polygon<V> {
    verts: [ClipVertex<V>; MAX_CLIPPED],
    len: usize,
}

impl<V: Copy> Polygon<V> {
    /// The triangle itself, unclipped.
    #[must_use]
    pub fn of(tri: [ClipVertex<V>; 3]) -> Self {
        let mut verts = [tri[0]; MAX_CLIPPED];
        verts[1] = tri[1];
        verts[2] = tri[2];
        Self { verts, len: 3 }
    }

    /// The vertices.
    #[must_use]
    pub fn vertices(&self) -> &[ClipVertex<V>] {
        &self.verts[..self.len]
    }

    /// Fan triangles `(0, i, i+1)`.
    pub fn triangles(&self) -> impl Iterator<Item = [ClipVertex<V>; 3]> + '_ {
        (1..self.len.saturating_sub(1)).map(|i| [self.verts[0], self.verts[i], self.verts[i + 1]])
    }
}

/// What clipping did to a triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClipOutcome {
    /// Entirely inside every plane: draw as is.
    Inside,
    /// Cut by at least one plane; the polygon holds the remaining part.
    Clipped,
    /// Nothing left (behind the eye, beyond far, or non-finite input).
    Rejected,
}

/// Signed distances to the clip planes (inside ≥ 0): near, far, then the guard band.
#[inline(always)]
fn distances(p: Vec4, guard: [f32; 2]) -> [f32; 6] {
    [
        p.z,
        p.w - p.z,
        guard[0] * p.w - p.x,
        guard[0] * p.w + p.x,
        guard[1] * p.w - p.y,
        guard[1] * p.w + p.y,
    ]
}

/// Outcode bits 0–5: the vertex lies outside clip plane 0–5: near (`z < 0`), far
/// (`z > w`), then the guard band's right, left, top and bottom (`x > g·w`,
/// `x < −g·w`, `y > g·w`, `y < −g·w`).
pub const OUT_PLANES: u8 = 0x3f;
/// Outcode bit: `w ≤ 0`.
pub const OUT_W_NOT_POSITIVE: u8 = 0x40;
/// Outcode bit: a coordinate is NaN or infinite (no other bit is then set).
pub const OUT_NOT_FINITE: u8 = 0x80;

/// A vertex's outcode: which planes it lies outside of, whether `w ≤ 0`, whether it
/// is non-finite. Computed once per vertex; [`classify_codes`] combines three.
#[must_use]
#[inline(always)]
pub fn outcode(p: Vec4, guard: [f32; 2]) -> u8 {
    if !p.is_finite() {
        return OUT_NOT_FINITE;
    }
    let d = distances(p, guard);
    let mut code = 0;
    for (plane, d) in d.iter().enumerate() {
        code |= u8::from(*d < 0.0) << plane;
    }
    // `!(w > 0)` rather than `w <= 0`: the same for the finite values that get here.
    code | if p.w > 0.0 { 0 } else { OUT_W_NOT_POSITIVE }
}

/// Where a triangle with these vertex outcodes lies: `Inside` (draw as is),
/// `Rejected` (nothing left: non-finite, or all three outside one plane, or
/// inside every plane yet with a `w ≤ 0`, which only `w = 0` on every vertex allows)
/// or `Clipped` (call [`clip_straddling`]).
#[must_use]
#[inline(always)]
pub fn classify_codes(codes: [u8; 3]) -> ClipOutcome {
    let any = codes[0] | codes[1] | codes[2];
    let all = codes[0] & codes[1] & codes[2];
    if any & OUT_NOT_FINITE != 0 || all & OUT_PLANES != 0 {
        ClipOutcome::Rejected
    } else if any & OUT_PLANES != 0 {
        ClipOutcome::Clipped
    } else if any & OUT_W_NOT_POSITIVE != 0 {
        // w must be positive after the near plane; z ≥ 0 and z ≤ w force w ≥ 0, so
        // this is w = 0 exactly.
        ClipOutcome::Rejected
    } else {
        ClipOutcome::Inside
    }
}

/// Where a triangle lies against the clip planes, without clipping it: `Inside` (draw
/// as is), `Rejected` (nothing left) or `Clipped` (call [`clip_triangle`]). Most
/// triangles of a frame are inside, and this keeps them from building a polygon.
#[must_use]
#[inline]
pub fn classify<V>(tri: &[ClipVertex<V>; 3], guard: [f32; 2]) -> ClipOutcome {
    classify_codes(tri.each_ref().map(|v| outcode(v.pos, guard)))
}

/// Clips a triangle. `guard` is the guard band in NDC units for x and y
/// (see [`guard_band_ndc`]). Returns the outcome and, unless rejected, the polygon.
pub fn clip_triangle<V: Varying>(
    tri: [ClipVertex<V>; 3],
    guard: [f32; 2],
) -> (ClipOutcome, Polygon<V>) {
    match classify(&tri, guard) {
        ClipOutcome::Clipped => match clip_straddling(tri, guard) {
            Some(poly) => (ClipOutcome::Clipped, poly),
            None => (ClipOutcome::Rejected, Polygon::of(tri)),
        },
        outcome => (outcome, Polygon::of(tri)),
    }
}

/// Clips a triangle that [`classify`] found `Clipped` (it crosses a plane and no
/// plane rejects it); `None` when nothing with w > 0 is left, or when rounding made
/// the polygon so far from convex that a plane cut it more than twice (it would
/// outgrow [`MAX_CLIPPED`]; only extreme coordinates do this, e.g. w near 1e34 beside
/// w near 1, and such a triangle is dropped).
pub fn clip_straddling<V: Varying>(tri: [ClipVertex<V>; 3], guard: [f32; 2]) -> Option<Polygon<V>> {
    let mut poly = Polygon::of(tri);
    for plane in 0..6 {
        let mut out = Polygon {
            verts: poly.verts,
            len: 0,
        };
        let n = poly.len;
        for i in 0..n {
            let a = poly.verts[i];
            let b = poly.verts[(i + 1) % n];
            let da = distances(a.pos, guard)[plane];
            let db = distances(b.pos, guard)[plane];
            if da >= 0.0 {
                *out.verts.get_mut(out.len)? = a;
                out.len += 1;
            }
            if (da >= 0.0) != (db >= 0.0) {
                *out.verts.get_mut(out.len)? = intersect(a, b, da, db, plane, guard);
                out.len += 1;
            }
        }
        poly = out;
        if poly.len < 3 {
            return None;
        }
    }
    if poly
        .vertices()
        .iter()
        .any(|v| !v.pos.is_finite() || v.pos.w <= 0.0)
    {
        return None;
    }
    Some(poly)
}

/// Where edge a→b crosses a plane, given the signed distances of its ends (one ≥ 0,
/// one < 0).
///
/// Interpolated from the inside end. That end is inside whichever triangle the edge
/// belongs to, so two triangles sharing the edge (which walk it in opposite
/// directions) compute the very same point, bit for bit: otherwise the clipped shared
/// edge would be two slightly different lines that can crack or double-hit pixels.
/// It is also the accurate way round: the step from the inside end is short next to
/// a far outside end (10^12 at the guard band, where stepping back from the outside
/// end would cancel catastrophically).
///
/// The result is then put exactly on the plane (`z = 0`, `z = w`, `x = ±g·w`,
/// `y = ±g·w`): when both ends are huge (a triangle reaching 10^12 in clip space) the
/// interpolated coordinate cancels, and without this the point can land beyond the
/// guard band and the visible part of the triangle be rejected.
#[inline]
fn intersect<V: Varying>(
    a: ClipVertex<V>,
    b: ClipVertex<V>,
    da: f32,
    db: f32,
    plane: usize,
    guard: [f32; 2],
) -> ClipVertex<V> {
    let (inside, outside, di, dout) = if da >= 0.0 {
        (a, b, da, db)
    } else {
        (b, a, db, da)
    };
    let t = di / (di - dout);
    let mut pos = inside.pos + (outside.pos - inside.pos) * t;
    match plane {
        0 => pos.z = 0.0,
        1 => pos.z = pos.w,
        2 => pos.x = guard[0] * pos.w,
        3 => pos.x = -guard[0] * pos.w,
        4 => pos.y = guard[1] * pos.w,
        _ => pos.y = -guard[1] * pos.w,
    }
    // The near and far planes came first, so the point lies within 0 ≤ z ≤ w up to
    // rounding of the interpolation; keep it there so no depth goes below 0. (Not
    // `clamp`, which panics when w < 0; such points are rejected afterwards.)
    pos.z = pos.z.max(0.0).min(pos.w);
    ClipVertex {
        pos,
        var: V::lerp(&inside.var, &outside.var, t),
    }
}

/// The guard band in NDC units for a `width × height` target: a vertex within it maps
/// to pixel coordinates well inside the rasterizer's ±2^20 px.
#[must_use]
pub fn guard_band_ndc(width: u32, height: u32) -> [f32; 2] {
    let g = super::GUARD_BAND_PX as f32 * 0.5;
    [g / width.max(1) as f32, g / height.max(1) as f32]
}

/// Clips a segment against the same planes as triangles; `None` if nothing is left.
/// Returns the clipped endpoints and their parameters along the original segment.
#[must_use]
pub fn clip_segment(a: Vec4, b: Vec4, guard: [f32; 2]) -> Option<([Vec4; 2], [f32; 2])> {
    if !a.is_finite() || !b.is_finite() {
        return None;
    }
    let (da, db) = (distances(a, guard), distances(b, guard));
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    for p in 0..6 {
        match (da[p] >= 0.0, db[p] >= 0.0) {
            (true, true) => {}
            (false, false) => return None,
            (inside_a, _) => {
                let t = da[p] / (da[p] - db[p]);
                if inside_a {
                    t1 = t1.min(t);
                } else {
                    t0 = t0.max(t);
                }
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    let (p0, p1) = (a + (b - a) * t0, a + (b - a) * t1);
    (p0.w > 0.0 && p1.w > 0.0).then_some(([p0, p1], [t0, t1]))
}

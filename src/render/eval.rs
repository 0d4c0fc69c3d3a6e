//! Everything the scalar path and the lane path compute per pixel, side by side:
//! edge values, depth, perspective and span weights.
//!
//! This file owns the bit-for-bit contract between them. The fragment loop's lanes
//! (`render::fragments`) and the scalar [`Prepared::eval`] (single pixels, the probe)
//! must perform the same IEEE operations in the same order, so each lane function sits
//! next to its scalar twin. A multiply-add is fused only where both say `mul_add`.
//! Change one, change the other; the pipeline and probe tests compare whole frames.

use super::prepare::Prepared;
use crate::raster::SUBPIXEL_BITS;
use crate::raster::interp::{Interpolation, Varying, span_lerp, span_position};
use crate::simd::{F32s, each3};

/// An edge value as the fragment stage sees it: `256·G + rem` in f32, from the reduced
/// value `G` the traversal carries. Exact while the result is below 2^24 (triangles up
/// to a few thousand pixels across), one rounding beyond; the scalar and lane paths
/// both use this form, so they agree bit for bit.
#[inline(always)]
fn edge_value(g: f32, rem: f32) -> f32 {
    // `g·256` is exact (a power-of-two scaling), so this equals the fused form of
    // `edge_value_lanes` bit for bit without being a library call off the FMA path.
    g * 256.0 + rem
}

/// [`edge_value`] on lanes, as one fused multiply-add.
#[inline(always)]
fn edge_value_lanes<F: F32s>(g: F, rem: f32) -> F {
    g.mul_add(F::splat(256.0), F::splat(rem))
}

/// Depth from the edge values `q` of A, B, C (see [`Prepared::zc`]), clamped to
/// [0, 1] as a GPU clamps to its depth range: relative to A, rounding can land an ulp
/// outside the vertices' range (a NaN stays NaN and fails every test).
#[inline(always)]
fn depth_of(q: [f32; 3], z_a: f32, zc: [f32; 2]) -> f32 {
    let d = q[2].mul_add(zc[1], q[1].mul_add(zc[0], z_a));
    // `max`/`min` of the lanes, spelled out: the second operand wins unless the
    // comparison holds, so NaN passes through.
    let d = if 0.0 > d { 0.0 } else { d };
    if 1.0 < d { 1.0 } else { d }
}

/// [`depth_of`] on lanes.
#[inline(always)]
fn depth_lanes<F: F32s>(q: [F; 3], z_a: f32, zc: &[f32; 2]) -> F {
    // `zc` by reference: by value, the pair is loaded as one 64-bit integer and
    // split into two broadcasts (six instructions a group instead of two).
    let d = q[2].mul_add(
        F::splat(zc[1]),
        q[1].mul_add(F::splat(zc[0]), F::splat(z_a)),
    );
    F::splat(1.0).min(F::splat(0.0).max(d))
}

/// Perspective-correct weights from the edge values `q` weighing each vertex and
/// `c[i] = (1/w_i) / area2`, plus the interpolated `1/w` itself: `p_i = q_i·c_i` is
/// `b_i/w_i`, and the weights are `p_i / Σ p_j`. The sum is of non-negative terms
/// inside the triangle, so it never cancels.
#[must_use]
#[inline(always)]
pub fn perspective_weights(q: [f32; 3], c: [f32; 3]) -> ([f32; 3], f32) {
    let p = [q[0] * c[0], q[1] * c[1], q[2] * c[2]];
    let s = q[2].mul_add(c[2], q[1].mul_add(c[1], p[0]));
    let r = 1.0 / s;
    ([p[0] * r, p[1] * r, p[2] * r], s)
}

/// [`perspective_weights`] on lanes.
#[inline(always)]
fn perspective_weights_lanes<F: F32s>(q: [F; 3], pc: [f32; 3]) -> [F; 3] {
    let c = each3!(|i| F::splat(pc[i]));
    let p = [q[0] * c[0], q[1] * c[1], q[2] * c[2]];
    let s = q[2].mul_add(c[2], q[1].mul_add(c[1], p[0]));
    let r = F::splat(1.0) / s;
    [p[0] * r, p[1] * r, p[2] * r]
}

/// The state of one pixel of one triangle: what the renderer computes per fragment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelEval {
    /// The pixel.
    pub x: u32,
    pub y: u32,
    /// Raw `F01, F02, F03` (no fill-rule bias) at the pixel centre.
    pub f: [i64; 3],
    /// Whether the biased test passed (the pixel is covered).
    pub covered: bool,
    /// Screen-space barycentrics `(u, v, w)` of A, B, C (setup order).
    pub bary: [f32; 3],
    /// Perspective-correct barycentrics.
    pub persp: [f32; 3],
    /// Interpolated 1/w.
    pub inv_w: f32,
    /// Interpolated NDC depth.
    pub depth: f32,
}

impl<V: Varying> Prepared<V> {
    /// Evaluates the triangle at pixel `(x, y)` exactly as the fragment loop does.
    #[inline(always)]
    #[must_use]
    pub fn eval(&self, x: u32, y: u32) -> PixelEval {
        let s = &self.setup;
        let f = self.raw_edges(x, y);
        let covered = (0..3).all(|e| f[e] + s.bias[e] >= 0);
        let q = self.vertex_edges(f);
        let ia = self.inv_area2;
        let bary = [q[0] * ia, q[1] * ia, q[2] * ia];
        let depth = depth_of(q, self.z, self.zc);
        let (persp, inv_w) = perspective_weights(q, self.pc);
        PixelEval {
            x,
            y,
            f,
            covered,
            bary,
            persp,
            inv_w,
            depth,
        }
    }

    /// The depth [`Prepared::eval`] gives at pixel `(x, y)`, without the rest.
    #[inline(always)]
    #[must_use]
    pub fn depth_at(&self, x: u32, y: u32) -> f32 {
        let q = self.vertex_edges(self.raw_edges(x, y));
        depth_of(q, self.z, self.zc)
    }

    /// Raw `F01, F02, F03` at the centre of pixel `(x, y)`.
    #[inline(always)]
    fn raw_edges(&self, x: u32, y: u32) -> [i64; 3] {
        let s = &self.setup;
        let (xi, yi) = (i64::from(x), i64::from(y));
        let f01 = s.edge_raw(0, xi, yi);
        let f02 = s.edge_raw(1, xi, yi);
        // Exact: the three edge functions sum to the doubled area everywhere.
        [f01, f02, s.area2 - f01 - f02]
    }

    /// The edge values weighing A, B and C (`F02`, `F03`, `F01`: each vertex's weight
    /// is the edge opposite it) from raw edge values, by the same f32 operations as
    /// [`Prepared::vertex_edges_lanes`].
    #[inline(always)]
    fn vertex_edges(&self, f: [i64; 3]) -> [f32; 3] {
        let s = &self.setup;
        let fl = each3!(|e| {
            let g = (f[e] + s.bias[e]) >> SUBPIXEL_BITS;
            edge_value(g as f32, self.edge_rem[e])
        });
        [fl[1], fl[2], fl[0]]
    }

    /// [`Prepared::vertex_edges`] on lanes, from the reduced edge values `g` (as
    /// floats) that the traversal carries (the bias is already in them).
    #[inline(always)]
    pub(super) fn vertex_edges_lanes<F: F32s>(&self, g: [F; 3]) -> [F; 3] {
        let fl = each3!(|e| edge_value_lanes(g[e], self.edge_rem[e]));
        [fl[1], fl[2], fl[0]]
    }

    /// [`depth_lanes`] of this triangle: [`Prepared::depth_at`] on lanes.
    #[inline(always)]
    pub(super) fn depth_lanes<F: F32s>(&self, q: [F; 3]) -> F {
        depth_lanes(q, self.z, &self.zc)
    }

    /// Perspective-correct weights at the centre of pixel `(x, y)`, which may lie
    /// outside the triangle (the subdivided modes need them at span ends).
    #[inline(always)]
    fn persp_at(&self, x: u32, y: u32) -> [f32; 3] {
        self.eval(x, y).persp
    }

    /// The interpolation weights of A, B, C at an evaluated pixel in `mode`, summing
    /// to 1. ([`Prepared::varyings`] weighs a projective varying's projective form by
    /// the edge values instead under perspective.)
    #[inline(always)]
    #[must_use]
    pub fn weights(&self, e: &PixelEval, mode: Interpolation) -> [f32; 3] {
        match (mode, mode.span()) {
            (Interpolation::Affine, _) => e.bary,
            (_, Some(n)) => {
                let (a, t) = span_position(e.x, n);
                span_lerp(self.persp_at(a, e.y), self.persp_at(a + n, e.y), t)
            }
            _ => e.persp,
        }
    }

    /// Interpolated varyings at an evaluated pixel.
    #[inline(always)]
    #[must_use]
    pub fn varyings(&self, e: &PixelEval, mode: Interpolation) -> V {
        if V::PROJECTIVE && mode == Interpolation::Perspective {
            V::from_relative(&self.rel, self.vertex_edges(e.f))
        } else {
            V::from_relative(&self.rel, self.weights(e, mode))
        }
    }

    /// [`Prepared::varyings`] on lanes: the varyings' form and the weights a group
    /// interpolates them with, from its vertex edge values `q` (8 pixels per row,
    /// `F::ROWS` rows from `(x0, y)`).
    #[inline(always)]
    pub(super) fn weights_lanes<F: F32s>(
        &self,
        q: [F; 3],
        mode: Interpolation,
        x0: u32,
        y: u32,
    ) -> (&[V; 3], [F; 3]) {
        match mode {
            // Projective varyings take the edge values themselves as weights.
            Interpolation::Perspective if V::PROJECTIVE => (&self.rel, q),
            Interpolation::Perspective => (&self.rel, perspective_weights_lanes(q, self.pc)),
            Interpolation::Affine => {
                let ia = F::splat(self.inv_area2);
                (&self.rel, [q[0] * ia, q[1] * ia, q[2] * ia])
            }
            mode => (
                &self.rel,
                span_weights_lanes(self, mode.span().unwrap_or(8), x0, y),
            ),
        }
    }
}

/// The subdivided modes' weights for a group at `(x0, y)` (see
/// [`Prepared::weights_lanes`]): exact perspective weights at the ends of each pixel's
/// span (computed once per distinct span end), linear in between, by the same
/// operations as [`Prepared::weights`].
#[inline(always)]
fn span_weights_lanes<V: Varying, F: F32s>(t: &Prepared<V>, n: u32, x0: u32, y: u32) -> [F; 3] {
    let mut out = [F::Arr::default(); 3];
    let mut ends = (u32::MAX, u32::MAX, [0f32; 3], [0f32; 3]);
    for k in 0..8 * F::ROWS as u32 {
        let (x, y) = (x0 + k % 8, y + k / 8);
        let (a, frac) = span_position(x, n);
        if (ends.0, ends.1) != (a, y) {
            ends = (a, y, t.persp_at(a, y), t.persp_at(a + n, y));
        }
        let w = span_lerp(ends.2, ends.3, frac);
        for v in 0..3 {
            out[v].as_mut()[k as usize] = w[v];
        }
    }
    each3!(|i| F::from_array(out[i]))
}

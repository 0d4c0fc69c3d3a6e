//! The fragment stage: the coverage sink that takes a triangle's pixels or lanes from
//! the traversal and runs depth test, interpolation and shading on them.

use std::marker::PhantomData;

use super::isa::DrawVariant;
use super::options::{DrawOptions, DrawStats};
use super::prepare::{EmitPiece, Prepared};
use super::shader::{ShadeLanes, Shader};
use super::target::ColorTarget;
use crate::counters::{self, Stage};
use crate::raster::depth::{DepthFunc, DepthStore};
use crate::raster::{CoverageSink, Setup, Target};
use crate::simd::{F32s, I32s, each3};

/// The fragment loop of one triangle: receives coverage from the traversal.
///
/// The variant `V` says which options are compile-time constants (see
/// [`DrawVariant`]); the lanes `L` are those of the copy's instruction set. Depth
/// holds the whole buffer's values, or those of the band of rows a thread draws,
/// whose first pixel (`base`) is index 0 of both its depth and its colour `C`.
struct Fragments<'a, S: Shader, C: ColorTarget + 'a, L, V> {
    tri: &'a Prepared<S::Varying>,
    shader: &'a S,
    /// The depth values, their stale tiles under the triangle filled
    /// ([`DepthStore::filled_mut`]), and the frame's index of the first
    /// ([`DepthStore::base`]): taken once per triangle, since the compiler cannot
    /// tell that the colour and depth writes of a group leave the buffer's fields
    /// alone, and would otherwise load them again for every group.
    depth: &'a mut [f32],
    base: usize,
    /// The colour target, held by value for the same reason.
    color: C::Rows<'a>,
    opts: DrawOptions,
    width: usize,
    /// The draw's counters, added to per group. Not per-triangle counts merged at the
    /// triangle's end: the compiler merged those with one 16-byte load of two 8-byte
    /// counters just stored, which the CPU cannot forward from the stores (a stall
    /// per triangle that a time profile of the 65k sphere showed).
    stats: &'a mut DrawStats,
    /// The SIMD backend of the lanes this loop builds itself (see [`Fragments::mask8`]),
    /// and the variant.
    lanes: PhantomData<(L, V)>,
}

impl<S: Shader, C: ColorTarget, L: I32s, V: DrawVariant> CoverageSink
    for Fragments<'_, S, C, L, V>
{
    #[inline(always)]
    fn pixel(&mut self, x: u32, y: u32) {
        let e = self.tri.eval(x, y);
        let i = y as usize * self.width + x as usize - self.base;
        self.stats.fragments += 1;
        let (depth_state, interpolation) = V::state(&self.opts);
        if depth_state.uses_buffer() {
            counters::add(Stage::DepthTests, 1);
            let old = self.depth[i];
            if !depth_state.func.passes(e.depth, old) {
                return;
            }
            if depth_state.write {
                self.depth[i] = e.depth;
            }
        }
        let v = self.tri.varyings(&e, interpolation);
        self.color.put(i, self.shader.fragment(&v));
        self.stats.shaded += 1;
    }

    /// Eight pixels from a traversal without lanes (or with `i64` lanes): the
    /// reduced edge values are formed here, then shaded as in
    /// [`CoverageSink::edge_lanes`]. With two-row lanes, the second row repeats the
    /// first and is masked off.
    #[inline(always)]
    fn mask8(&mut self, y: u32, x0: u32, mask: u8) {
        if x0 as usize + 8 > self.width {
            self.pixels(y, x0, u32::from(mask));
            return;
        }
        let s = &self.tri.setup;
        let (xi, yi) = (i64::from(x0), i64::from(y));
        let g = each3!(|e| {
            let base = s.reduced_edge(e, xi, yi);
            let mut a = <L::F as F32s>::Arr::default();
            for (k, v) in a.as_mut().iter_mut().enumerate() {
                *v = (base + (k % 8) as i64 * s.i[e]) as f32;
            }
            L::F::from_array(a)
        });
        self.shade_lanes(y, x0, u32::from(mask), g);
    }

    /// A group with the `wide` traversal's `i32` edge lanes: one conversion per edge
    /// gives the exact edge values.
    ///
    /// Groups reach past the target only in targets under 8 pixels wide, which the
    /// two-row lanes never see ([`super::DrawCopy::choose`]): their loop then has no call in
    /// it, which would make the compiler keep the lanes in memory across every group.
    #[inline(always)]
    fn edge_lanes<G: I32s>(&mut self, y: u32, x0: u32, mask: u32, g: &[G; 3]) {
        if G::ROWS == 1 && x0 as usize + 8 > self.width {
            self.pixels(y, x0, mask);
            return;
        }
        debug_assert!(x0 as usize + 8 <= self.width, "a group past the target");
        self.shade_lanes(y, x0, mask, each3!(|e| g[e].to_f32()));
    }
}

impl<S: Shader, C: ColorTarget, L: I32s, V: DrawVariant> Fragments<'_, S, C, L, V> {
    /// A group that reaches past the target (only in targets under 8 pixels wide, see
    /// [`CoverageSink::mask8`]), pixel by pixel (bit `k` is pixel `k % 8` of row
    /// `k / 8`).
    ///
    /// Inlined for shaders with lane code ([`Shader::LANE_CODE`]): a call in the group
    /// loop, even one never taken, makes the compiler keep the loop's lanes in memory
    /// (all vector registers are lost across a call). For the others it stays a call:
    /// inlining their single-fragment shading at every group of every copy makes the
    /// build much longer for no speed (they shade lane by lane anyway).
    #[inline(always)]
    fn pixels(&mut self, y: u32, x0: u32, mask: u32) {
        if S::LANE_CODE {
            self.pixels_inline(y, x0, mask);
        } else {
            self.pixels_call(y, x0, mask);
        }
    }

    /// [`Fragments::pixels`] out of line.
    #[inline(never)]
    fn pixels_call(&mut self, y: u32, x0: u32, mask: u32) {
        self.pixels_inline(y, x0, mask);
    }

    /// [`Fragments::pixels`] in line.
    #[inline(always)]
    fn pixels_inline(&mut self, y: u32, x0: u32, mask: u32) {
        let mut m = mask;
        while m != 0 {
            let k = m.trailing_zeros();
            self.pixel(x0 + k % 8, y + k / 8);
            m &= m - 1;
        }
    }

    /// Barycentrics, depth, the depth test and perspective weights of a group (8
    /// pixels per row, `F::ROWS` rows, bit `k` of `mask` for pixel `x0 + k % 8` of row
    /// `y + k / 8`) from their reduced edge values `g` (as floats); shading runs on the
    /// lanes that pass. The same operations in the same order as [`Prepared::eval`].
    #[inline(always)]
    fn shade_lanes<F: F32s>(&mut self, y: u32, x0: u32, mask: u32, g: [F; 3]) {
        let t = self.tri;
        let start = y as usize * self.width + x0 as usize - self.base;
        // Rows below the first only when the mask has lanes there: the last row of the
        // target has none below it.
        let stride = if F::ROWS > 1 && mask >> 8 != 0 {
            self.width
        } else {
            0
        };
        let q = t.vertex_edges_lanes(g);
        let depth = t.depth_lanes(q);
        self.stats.fragments += u64::from(mask.count_ones());
        let (depth_state, interpolation) = V::state(&self.opts);
        let pass = if depth_state.uses_buffer() {
            counters::add(Stage::DepthTests, u64::from(mask.count_ones()));
            let buf = &mut *self.depth;
            let old = F::load_rows(buf, start, stride);
            let test = match depth_state.func {
                DepthFunc::Less => depth.lt(old).bitmask(),
                DepthFunc::LessEqual => depth.le(old).bitmask(),
                DepthFunc::Always => !0,
            };
            let pass = test & mask;
            if pass != 0 && depth_state.write {
                depth.store_rows(buf, start, stride, pass);
            }
            pass
        } else {
            mask
        };
        if pass == 0 {
            return;
        }
        let (rel, w) = t.weights_lanes(q, interpolation, x0, y);
        match self.shader.fragment_lanes(rel, &w, pass) {
            ShadeLanes::Rgb(c) => self.color.put_lanes(start, stride, pass, &c),
            ShadeLanes::Grey(g) => self.color.put_lanes_grey(start, stride, pass, g),
        }
        self.stats.shaded += u64::from(pass.count_ones());
    }
}

/// The per-draw state that takes each prepared piece of a triangle ([`EmitPiece`]),
/// fills the stale depth tiles under it and walks it into a [`Fragments`] sink.
/// `V::WIDE_ONLY` fixes the traversal to `wide` at compile time; otherwise
/// `opts.traversal` picks it. `D` is the whole depth buffer, or one band of its rows
/// (with `C` the same band of the colour target).
pub(super) struct PieceWalker<'a, S, C, L, V, D> {
    shader: &'a S,
    depth: &'a mut D,
    color: &'a mut C,
    opts: DrawOptions,
    width: usize,
    /// The draw's counters so far.
    pub(super) stats: DrawStats,
    lanes: PhantomData<(L, V)>,
}

impl<'a, S, C, L, V, D> PieceWalker<'a, S, C, L, V, D> {
    /// A walker for one draw into `depth` and `color` (both sized for `target`, or
    /// the same band of rows of each).
    #[inline(always)]
    pub(super) fn new(
        shader: &'a S,
        depth: &'a mut D,
        color: &'a mut C,
        opts: &DrawOptions,
        target: Target,
    ) -> Self {
        Self {
            shader,
            depth,
            color,
            opts: *opts,
            width: target.width as usize,
            stats: DrawStats::default(),
            lanes: PhantomData,
        }
    }
}

impl<S: Shader, C: ColorTarget, L: I32s, V: DrawVariant, D: DepthStore> EmitPiece<S::Varying>
    for PieceWalker<'_, S, C, L, V, D>
{
    #[inline(always)]
    fn piece(&mut self, tri: &Prepared<S::Varying>) {
        self.walk(tri, &tri.setup);
    }
}

impl<S: Shader, C: ColorTarget, L: I32s, V: DrawVariant, D: DepthStore>
    PieceWalker<'_, S, C, L, V, D>
{
    /// Walks the part of `tri` in rows `y0..=y1` (a band's or a strip's): its own box if
    /// within them, else its box cut to them ([`Setup::rows`], the same edge values at
    /// every pixel). One call of the walk either way: it is inlined, so a second call
    /// would be a second copy of the traversal and fragment loop.
    #[inline(always)]
    pub(super) fn walk_rows(&mut self, tri: &Prepared<S::Varying>, y0: u32, y1: u32) {
        let b = tri.setup.bbox;
        let cut: Setup;
        let setup = if b.y0 >= y0 && b.y1 <= y1 {
            &tri.setup
        } else {
            let Some(s) = tri.setup.rows(y0, y1) else {
                return;
            };
            cut = s;
            &cut
        };
        self.walk(tri, setup);
    }

    /// Walks `setup`'s box of triangle `tri`: its own ([`EmitPiece::piece`]), or the
    /// part in a band of rows ([`PieceWalker::walk_rows`]).
    #[inline(always)]
    pub(super) fn walk(&mut self, tri: &Prepared<S::Varying>, setup: &Setup) {
        let (depth_state, _) = V::state(&self.opts);
        if depth_state.uses_buffer() {
            // Groups can overhang the box into stale tiles, but only with lanes outside
            // the mask, whose depth the test writes back unchanged.
            let b = setup.bbox;
            self.depth.fill_stale(b.x0, b.y0, b.x1, b.y1);
        }
        let base = self.depth.base();
        let mut frag = Fragments::<S, C, L, V> {
            tri,
            shader: self.shader,
            depth: self.depth.filled_mut(),
            base,
            color: self.color.all_rows(),
            opts: self.opts,
            width: self.width,
            stats: &mut self.stats,
            lanes: PhantomData,
        };
        if V::WIDE_ONLY {
            crate::raster::traverse::wide_lanes::<L, _>(setup, &mut frag);
        } else {
            self.opts.traversal.run_lanes::<L, _>(setup, &mut frag);
        }
    }
}

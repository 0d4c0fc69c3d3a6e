//! The 3D pipeline: vertex transform, clipping, projection, exact setup, traversal,
//! depth test and shading.
//!
//! Screen mapping: NDC x ∈ [−1, 1] maps to pixels [0, width] left to right, NDC y ∈
//! [−1, 1] to [height, 0] (screen space is y-down), and z stays NDC z ∈ [0, 1] for
//! depth. Faces are front-facing when counter-clockwise in NDC (y-up), i.e. when the
//! rasterizer had to flip them to positive area in y-down screen space.
//!
//! Per-triangle work ([`prepare`]) and per-pixel work ([`Prepared::eval`]) are shared
//! by the renderer and the probe, so the probe reports exactly what the renderer did.

mod isa;
pub mod shaders;
pub mod standard;
pub mod target;
pub mod wire;

use std::marker::PhantomData;

use glam::{Vec3, Vec4};

use crate::counters::{self, Stage};
use crate::raster::clip::{
    ClipOutcome, ClipVertex, classify_codes, clip_straddling, guard_band_ndc, outcode,
};
use crate::raster::depth::{DepthBuffer, DepthFunc, DepthState};
use crate::raster::interp::{
    Interpolation, Varying, perspective_weights, span_lerp, span_position,
};
use crate::raster::setup::snap;
use crate::raster::{CoverageSink, SUBPIXEL_BITS, Setup, Target, Traversal};
use crate::simd::{F32s, I32s, each3};
pub use isa::Isa;
pub use target::{ColorTarget, Rgba8};

/// A shader: the vertex stage produces clip-space positions and varyings for vertex
/// indices, the fragment stage a linear RGB colour from interpolated varyings. The
/// varying type is fixed at compile time, so each shader gets its own pipeline.
pub trait Shader {
    type Varying: Varying;
    /// Clip-space position and varyings of vertex `index`.
    fn vertex(&self, index: u32) -> (Vec4, Self::Varying);
    /// Colour of a fragment.
    fn fragment(&self, v: &Self::Varying) -> Vec3;

    /// Whether [`Shader::fragment_lanes`] is lane code of the shader's own rather than
    /// the default loop over single fragments. Only such shaders get the 16-lane
    /// AVX-512 copy of the draw loop (see [`Renderer::isa_for`]), and an inlined
    /// per-pixel fallback in the others: a loop over single fragments gains nothing
    /// from wider lanes, and only makes the build longer.
    const LANE_CODE: bool = false;

    /// Colours of a group of fragments of one triangle at once (8 lanes per row of
    /// pixels, `F::ROWS` rows): lane `k` (for each set bit of `mask`) has weights
    /// `w[..][k]` for the triangle's varyings in relative form `rel` (see
    /// [`Varying::relative`]). The default interpolates and shades lane by lane;
    /// shaders override it with lane code that must give the same bits as
    /// [`Shader::fragment`] (the probe relies on it).
    #[inline(always)]
    fn fragment_lanes<F: F32s>(
        &self,
        rel: &[Self::Varying; 3],
        w: &[F; 3],
        mask: u32,
    ) -> ShadeLanes<F> {
        let w = each3!(|i| w[i].to_array());
        let mut out = [F::Arr::default(); 3];
        let mut m = mask;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            let lane = |a: &F::Arr| a.as_ref()[k];
            let v = Self::Varying::from_relative(rel, [lane(&w[0]), lane(&w[1]), lane(&w[2])]);
            let c = self.fragment(&v);
            for (o, c) in out.iter_mut().zip([c.x, c.y, c.z]) {
                o.as_mut()[k] = c;
            }
            m &= m - 1;
        }
        ShadeLanes::Rgb(each3!(|i| F::from_array(out[i])))
    }
}

/// The colours of a group of fragments from [`Shader::fragment_lanes`].
#[derive(Clone, Copy, Debug)]
pub enum ShadeLanes<F> {
    /// Red, green and blue lanes.
    Rgb([F; 3]),
    /// One value for all three channels: a grey shader says so, and the target
    /// converts one channel instead of three (the stored bits are the same as for
    /// `Rgb([g, g, g])`).
    Grey(F),
}

/// Which faces to skip.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Cull {
    /// Draw both sides.
    #[default]
    None,
    /// Skip faces that are clockwise in NDC (facing away).
    Back,
}

/// Per-draw state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawOptions {
    pub depth: DepthState,
    pub cull: Cull,
    pub interpolation: Interpolation,
    /// Traversal that walks each triangle (all give identical coverage).
    pub traversal: Traversal,
}

impl Default for DrawOptions {
    fn default() -> Self {
        Self {
            depth: DepthState::default(),
            cull: Cull::None,
            interpolation: Interpolation::Perspective,
            traversal: Traversal::Wide,
        }
    }
}

/// Counters of one frame, for the status line and the benchmark.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrawStats {
    /// Triangles submitted.
    pub triangles: u64,
    /// Triangles that reached the traversal (after clipping, setup and culling).
    pub drawn: u64,
    /// Back faces skipped.
    pub culled: u64,
    /// Triangles cut by a clip plane (drawn in part).
    pub clipped: u64,
    /// Triangles with nothing left: behind the eye, beyond far, off screen, zero
    /// area after snapping, or non-finite.
    pub rejected: u64,
    /// Covered pixels that went through the depth test.
    pub fragments: u64,
    /// Fragments that passed the depth test and were shaded.
    pub shaded: u64,
}

impl std::ops::AddAssign for DrawStats {
    fn add_assign(&mut self, o: Self) {
        self.triangles += o.triangles;
        self.drawn += o.drawn;
        self.culled += o.culled;
        self.clipped += o.clipped;
        self.rejected += o.rejected;
        self.fragments += o.fragments;
        self.shaded += o.shaded;
    }
}

/// A triangle after clipping and projection, ready to rasterize. Vertex arrays are in
/// setup order (A, B, C after any winding flip).
#[derive(Clone, Copy, Debug)]
pub struct Prepared<V> {
    /// Index of the mesh triangle it came from.
    pub triangle: u32,
    /// Which piece of the clipped polygon (0 when unclipped).
    pub piece: u8,
    /// Whether clipping cut the original triangle.
    pub clipped: bool,
    pub setup: Setup,
    /// Screen position (pixels) of each vertex before snapping.
    pub screen: [[f32; 2]; 3],
    /// NDC depth of each vertex.
    pub z: [f32; 3],
    /// 1/w of each vertex.
    pub inv_w: [f32; 3],
    /// The varyings in relative form (see [`Varying::relative`]).
    pub rel: [V; 3],
    /// For [`Varying::PROJECTIVE`] varyings, the vertex values times `pc`
    /// ([`Varying::projective_form`]), interpolated with the edge values as weights
    /// under perspective. Otherwise the vertex values, never read.
    pub proj: [V; 3],
    /// `1 / area2`, rounded once to f32: barycentrics are `F · inv_area2`.
    pub inv_area2: f32,
    /// Depth per unit of B's and C's edge value: `(z_B − z_A) / area2` and
    /// `(z_C − z_A) / area2`, so depth is `z_A + F_B·zc[0] + F_C·zc[1]` (two fused
    /// multiply-adds, exactly `z_A` at A).
    pub zc: [f32; 2],
    /// `(1/w_i) / area2` per vertex: the perspective numerators are `F_i · pc[i]`.
    pub pc: [f32; 3],
    /// `F0e − 256·G0e` per edge (see [`Setup::reduced_edge`]): the same at every pixel,
    /// so `F0e = 256·G0e + edge_rem[e]` rebuilds the exact edge value from the lanes of
    /// the `wide` traversal.
    pub edge_rem: [f32; 3],
}

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
        let depth = depth_of(q, self.z[0], self.zc);
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
        depth_of(q, self.z[0], self.zc)
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
    /// is the edge opposite it) from raw edge values, by the same f32 operations as the
    /// lane fragment loop (so both give identical bits).
    #[inline(always)]
    fn vertex_edges(&self, f: [i64; 3]) -> [f32; 3] {
        let s = &self.setup;
        let fl = each3!(|e| {
            let g = (f[e] + s.bias[e]) >> SUBPIXEL_BITS;
            edge_value(g as f32, self.edge_rem[e])
        });
        [fl[1], fl[2], fl[0]]
    }

    /// Perspective-correct weights at the centre of pixel `(x, y)`, which may lie
    /// outside the triangle (the subdivided modes need them at span ends).
    #[inline(always)]
    fn persp_at(&self, x: u32, y: u32) -> [f32; 3] {
        self.eval(x, y).persp
    }

    /// The interpolation weights of A, B, C at an evaluated pixel in `mode`, summing
    /// to 1. ([`Prepared::varyings`] weighs a projective varying's `proj` by the edge
    /// values instead under perspective.)
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
            V::from_relative(&self.proj, self.vertex_edges(e.f))
        } else {
            V::from_relative(&self.rel, self.weights(e, mode))
        }
    }
}

/// Reusable per-draw storage: transformed vertices. Kept by the caller so a steady
/// viewer allocates nothing per frame.
#[derive(Debug)]
pub struct VertexCache<V> {
    pub(crate) verts: Vec<ClipVertex<V>>,
}

impl<V> Default for VertexCache<V> {
    fn default() -> Self {
        Self { verts: Vec::new() }
    }
}

/// Result of preparing one mesh triangle.
pub enum PrepareOutcome {
    Rejected,
    Culled,
    Drawn { clipped: bool },
}

/// Transforms every vertex once into the cache.
pub fn transform<S: Shader>(shader: &S, vertex_count: usize, cache: &mut VertexCache<S::Varying>) {
    cache.verts.clear();
    cache.verts.extend((0..vertex_count as u32).map(|i| {
        let (pos, var) = shader.vertex(i);
        ClipVertex { pos, var }
    }));
}

/// Receives the pieces [`prepare`] makes of a triangle. A trait rather than a closure
/// so the renderer's per-triangle work inlines into its caller (closures are compiled
/// on their own, without the caller's target features).
pub trait EmitPiece<V> {
    fn piece(&mut self, p: &Prepared<V>);
}

impl<V, F: FnMut(&Prepared<V>)> EmitPiece<V> for F {
    #[inline(always)]
    fn piece(&mut self, p: &Prepared<V>) {
        self(p);
    }
}

/// A vertex's clip outcode and projection, computed once per vertex per draw (most
/// vertices are shared by about six triangles) and identically for clipped vertices,
/// so a triangle set up from these is bit for bit the triangle set up from scratch.
#[derive(Clone, Copy, Debug, Default)]
pub struct Projected {
    /// See [`outcode`].
    out: u8,
    /// Whether both screen coordinates snapped (finite and within the guard band).
    snapped: bool,
    inv_w: f32,
    /// Screen position in pixels, before snapping.
    screen: [f32; 2],
    /// NDC depth.
    z: f32,
    /// Snapped screen position in subpixels.
    fixed: [i64; 2],
}

impl Projected {
    /// Classifies and projects a clip-space position for a target.
    #[inline(always)]
    #[must_use]
    pub fn of(pos: Vec4, target: Target, guard: [f32; 2]) -> Self {
        let (fw, fh) = (target.width as f32, target.height as f32);
        let inv_w = 1.0 / pos.w;
        let p = pos * inv_w;
        let screen = [(p.x * 0.5 + 0.5) * fw, (0.5 - p.y * 0.5) * fh];
        let (sx, sy) = (snap(f64::from(screen[0])), snap(f64::from(screen[1])));
        Self {
            out: outcode(pos, guard),
            snapped: sx.is_some() && sy.is_some(),
            inv_w,
            screen,
            z: pos.z * inv_w,
            fixed: [sx.unwrap_or(0), sy.unwrap_or(0)],
        }
    }
}

/// Projects every vertex of `cache` for `target` into `out` (reusing its storage).
pub fn project_vertices<V>(cache: &VertexCache<V>, target: Target, out: &mut Vec<Projected>) {
    let guard = guard_band_ndc(target.width, target.height);
    out.clear();
    out.extend(
        cache
            .verts
            .iter()
            .map(|v| Projected::of(v.pos, target, guard)),
    );
}

/// Clips, projects and sets up mesh triangle `t`, calling `emit` for each piece that
/// reaches the rasterizer. Shared by the renderer and the probe.
#[inline(always)]
pub fn prepare<V: Varying>(
    cache: &VertexCache<V>,
    indices: &[u32],
    t: u32,
    target: Target,
    cull: Cull,
    emit: &mut impl EmitPiece<V>,
) -> PrepareOutcome {
    prepare_projected(cache, None, indices, t, target, cull, emit)
}

/// [`prepare`] with the vertices' projections from [`project_vertices`] (for this
/// cache and target) when given, else computed here: the result is the same.
#[inline(always)]
pub fn prepare_projected<V: Varying>(
    cache: &VertexCache<V>,
    projected: Option<&[Projected]>,
    indices: &[u32],
    t: u32,
    target: Target,
    cull: Cull,
    emit: &mut impl EmitPiece<V>,
) -> PrepareOutcome {
    let base = t as usize * 3;
    let Some(idx) = indices.get(base..base + 3) else {
        return PrepareOutcome::Rejected;
    };
    let fetch = |i: u32| cache.verts.get(i as usize).copied();
    let (Some(a), Some(b), Some(c)) = (fetch(idx[0]), fetch(idx[1]), fetch(idx[2])) else {
        return PrepareOutcome::Rejected;
    };
    let tri = [a, b, c];
    let guard = guard_band_ndc(target.width, target.height);
    let proj = match projected {
        Some(p) => match (
            p.get(idx[0] as usize),
            p.get(idx[1] as usize),
            p.get(idx[2] as usize),
        ) {
            (Some(&pa), Some(&pb), Some(&pc)) => [pa, pb, pc],
            _ => return PrepareOutcome::Rejected,
        },
        None => each3!(|i| Projected::of(tri[i].pos, target, guard)),
    };
    let outcome = classify_codes(each3!(|i| proj[i].out));
    let clipped = outcome == ClipOutcome::Clipped;
    let mut seen = Seen::default();
    match outcome {
        ClipOutcome::Rejected => return PrepareOutcome::Rejected,
        ClipOutcome::Inside => {
            let var = each3!(|i| tri[i].var);
            seen.add(setup_piece((t, 0, clipped), proj, var, target, cull, emit));
        }
        ClipOutcome::Clipped => {
            let Some(poly) = clip_straddling(tri, guard) else {
                return PrepareOutcome::Rejected;
            };
            for (i, tri) in poly.triangles().enumerate() {
                let proj = each3!(|i| Projected::of(tri[i].pos, target, guard));
                let var = each3!(|i| tri[i].var);
                seen.add(setup_piece((t, i, clipped), proj, var, target, cull, emit));
            }
        }
    }
    match (seen.drawn, seen.culled) {
        (true, _) => PrepareOutcome::Drawn { clipped },
        (false, true) => PrepareOutcome::Culled,
        (false, false) => PrepareOutcome::Rejected,
    }
}

/// What became of a triangle's pieces.
#[derive(Default)]
struct Seen {
    drawn: bool,
    culled: bool,
}

impl Seen {
    /// Notes what became of a piece.
    #[inline(always)]
    fn add(&mut self, piece: Piece) {
        match piece {
            Piece::Drawn => self.drawn = true,
            Piece::Culled => self.culled = true,
            Piece::Rejected => {}
        }
    }
}

/// What became of one piece of a triangle.
enum Piece {
    /// Set up and handed to the [`EmitPiece`].
    Drawn,
    Culled,
    Rejected,
}

/// Sets up one (possibly clipped) triangle whose vertices all have w > 0, from their
/// projections, and hands it to `emit`. The record is built where `emit` reads it:
/// returned in an enum and then passed on, it was partly copied once more (about 18
/// more instructions per triangle on the AVX2 copy).
#[inline(always)]
fn setup_piece<V: Varying>(
    (t, piece, clipped): (u32, usize, bool),
    proj: [Projected; 3],
    var: [V; 3],
    target: Target,
    cull: Cull,
    emit: &mut impl EmitPiece<V>,
) -> Piece {
    // Not `iter().all(..)`: it stays out of line in the AVX2 draw loop.
    if !(proj[0].snapped && proj[1].snapped && proj[2].snapped) {
        return Piece::Rejected;
    }
    let Ok(setup) = Setup::from_snapped(each3!(|i| proj[i].fixed), target) else {
        return Piece::Rejected;
    };
    // Counter-clockwise in NDC (y-up) is negative area in y-down screen space.
    if cull == Cull::Back && !setup.flipped {
        return Piece::Culled;
    }
    let order = |i: usize| if setup.flipped && i > 0 { 3 - i } else { i };
    let var = each3!(|i| var[order(i)]);
    // The raw value at the box's origin less 256 times the reduced one.
    let g = setup.reduced_at_origin();
    let edge_rem = each3!(|e| (setup.origin[e] - setup.bias[e] - (g[e] << SUBPIXEL_BITS)) as f32);
    let z = each3!(|i| proj[order(i)].z);
    let inv_w = each3!(|i| proj[order(i)].inv_w);
    // In f64, rounded once: the per-pixel terms then carry one rounding each.
    let ia = 1.0 / setup.area2 as f64;
    let slope = |i: usize| ((f64::from(z[i]) - f64::from(z[0])) * ia) as f32;
    let zc = [slope(1), slope(2)];
    let pc = each3!(|i| (f64::from(inv_w[i]) * ia) as f32);
    let rel = V::relative(&var[0], &var[1], &var[2]);
    emit.piece(&Prepared {
        triangle: t,
        piece: piece as u8,
        clipped,
        setup,
        screen: each3!(|i| proj[order(i)].screen),
        z,
        inv_w,
        zc,
        pc,
        rel,
        proj: V::projective_form(&var, pc),
        inv_area2: ia as f32,
        edge_rem,
    });
    Piece::Drawn
}

/// The fragment loop of one triangle: receives coverage from the traversal.
///
/// `STD` marks the default state (depth test `Less` with writes, perspective-correct
/// interpolation) compiled as constants, so the per-group code carries no checks
/// of the options; every other state runs with `STD = false` and reads `opts`.
struct Fragments<'a, S: Shader, C, L, const STD: bool> {
    tri: &'a Prepared<S::Varying>,
    shader: &'a S,
    depth: &'a mut DepthBuffer,
    color: &'a mut C,
    opts: DrawOptions,
    width: usize,
    /// The draw's counters, added to per group. Not per-triangle counts merged at the
    /// triangle's end: the compiler merged those with one 16-byte load of two 8-byte
    /// counters just stored, which the CPU cannot forward from the stores (a stall
    /// per triangle that a time profile of the 65k sphere showed).
    stats: &'a mut DrawStats,
    /// The SIMD backend of the lanes this loop builds itself (see [`Fragments::mask8`]).
    lanes: PhantomData<L>,
}

impl<S: Shader, C: ColorTarget, L: I32s, const STD: bool> CoverageSink
    for Fragments<'_, S, C, L, STD>
{
    #[inline(always)]
    fn pixel(&mut self, x: u32, y: u32) {
        let e = self.tri.eval(x, y);
        let i = y as usize * self.width + x as usize;
        self.stats.fragments += 1;
        let (depth_state, interpolation) = self.state();
        if depth_state.uses_buffer() {
            counters::add(Stage::DepthTests, 1);
            let old = self.depth.real_mut()[i];
            if !depth_state.func.passes(e.depth, old) {
                return;
            }
            if depth_state.write {
                self.depth.real_mut()[i] = e.depth;
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
    /// two-row lanes never see ([`Renderer::isa_for`]): their loop then has no call in
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

impl<S: Shader, C: ColorTarget, L: I32s, const STD: bool> Fragments<'_, S, C, L, STD> {
    /// The draw's depth state and interpolation: constants when `STD`.
    #[inline(always)]
    fn state(&self) -> (DepthState, Interpolation) {
        Self::state_of(&self.opts)
    }

    /// [`Fragments::state`] of a draw's options.
    #[inline(always)]
    fn state_of(opts: &DrawOptions) -> (DepthState, Interpolation) {
        if STD {
            (DepthState::default(), Interpolation::Perspective)
        } else {
            (opts.depth, opts.interpolation)
        }
    }

    /// A group that reaches past the target (only in targets under 8 pixels wide, see
    /// [`CoverageSink::mask8`]), pixel by pixel (bit `k` is pixel `k % 8` of row
    /// `k / 8`).
    ///
    /// Inlined for shaders with lane code ([`Shader::LANE_CODE`]): a call in the group
    /// loop, even one never taken, makes the compiler keep the loop's lanes in memory
    /// (all vector registers are lost across a call); inlined, the AVX2 copy ran the
    /// sphere in 0.84× the time. For the others it stays a call: inlining their
    /// single-fragment shading at every group of every copy made the build longer.
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
        let start = y as usize * self.width + x0 as usize;
        // Rows below the first only when the mask has lanes there: the last row of the
        // target has none below it.
        let stride = if F::ROWS > 1 && mask >> 8 != 0 {
            self.width
        } else {
            0
        };
        let fl = each3!(|e| edge_value_lanes(g[e], t.edge_rem[e]));
        let q = [fl[1], fl[2], fl[0]];
        let depth = depth_lanes(q, t.z[0], &t.zc);
        self.stats.fragments += u64::from(mask.count_ones());
        let (depth_state, interpolation) = self.state();
        let pass = if depth_state.uses_buffer() {
            counters::add(Stage::DepthTests, u64::from(mask.count_ones()));
            let buf = self.depth.real_mut();
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
        // Projective varyings take the edge values themselves as weights (see
        // `Prepared::varyings`).
        let (rel, w) = match interpolation {
            Interpolation::Perspective if S::Varying::PROJECTIVE => (&t.proj, q),
            Interpolation::Perspective => (&t.rel, perspective_weights_lanes(q, t.pc)),
            Interpolation::Affine => {
                let ia = F::splat(t.inv_area2);
                (&t.rel, [q[0] * ia, q[1] * ia, q[2] * ia])
            }
            mode => (
                &t.rel,
                span_weights_lanes(t, mode.span().unwrap_or(8), x0, y),
            ),
        };
        match self.shader.fragment_lanes(rel, &w, pass) {
            ShadeLanes::Rgb(c) => self.color.put_lanes(start, stride, pass, &c),
            ShadeLanes::Grey(g) => self.color.put_lanes_grey(start, stride, pass, g),
        }
        self.stats.shaded += u64::from(pass.count_ones());
    }
}

/// The subdivided modes' weights for a group at `(x0, y)` (see
/// [`Fragments::shade_lanes`]): exact perspective weights at the ends of each pixel's
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

/// Rasterizes the pieces of a draw's triangles.
/// `WIDE` fixes the traversal to `wide` at compile time (the AVX-512 copy is built
/// for that alone, see [`Renderer::draw`]); otherwise `opts.traversal` picks it.
struct Raster<'a, S, C, L, const STD: bool, const WIDE: bool> {
    shader: &'a S,
    depth: &'a mut DepthBuffer,
    color: &'a mut C,
    opts: DrawOptions,
    width: usize,
    stats: DrawStats,
    lanes: PhantomData<L>,
}

impl<S: Shader, C: ColorTarget, L: I32s, const STD: bool, const WIDE: bool> EmitPiece<S::Varying>
    for Raster<'_, S, C, L, STD, WIDE>
{
    #[inline(always)]
    fn piece(&mut self, tri: &Prepared<S::Varying>) {
        let (depth_state, _) = Fragments::<S, C, L, STD>::state_of(&self.opts);
        if depth_state.uses_buffer() {
            // Groups can overhang the box into stale tiles, but only with lanes outside
            // the mask, whose depth the test writes back unchanged.
            let b = tri.setup.bbox;
            self.depth.make_real(b.x0, b.y0, b.x1, b.y1);
        }
        let mut frag = Fragments::<S, C, L, STD> {
            tri,
            shader: self.shader,
            depth: &mut *self.depth,
            color: &mut *self.color,
            opts: self.opts,
            width: self.width,
            stats: &mut self.stats,
            lanes: PhantomData::<L>,
        };
        if WIDE {
            crate::raster::traverse::wide_lanes::<L, _>(&tri.setup, &mut frag);
        } else {
            self.opts.traversal.run_lanes::<L, _>(&tri.setup, &mut frag);
        }
    }
}

/// Owns the depth buffer and frame counters; draws meshes into a colour target.
#[derive(Debug)]
pub struct Renderer {
    pub target: Target,
    pub depth: DepthBuffer,
    pub stats: DrawStats,
    /// The draw loop's instruction set; [`Isa::detect`] by default.
    pub isa: Isa,
    /// The current draw's vertex projections, reused between draws.
    projected: Vec<Projected>,
}

impl Renderer {
    /// A renderer for a target size.
    #[must_use]
    pub fn new(target: Target) -> Self {
        Self {
            target,
            depth: DepthBuffer::new(target.width, target.height),
            stats: DrawStats::default(),
            isa: Isa::detect(),
            projected: Vec::new(),
        }
    }

    /// Starts a frame: clears depth and colour (reallocating only on resize) and the
    /// counters.
    pub fn begin_frame<C: ColorTarget>(&mut self, target: Target, color: &mut C, background: Vec3) {
        self.begin_frame_with(target, color, background, true);
    }

    /// Starts a frame with or without a depth buffer. Without one, the buffer's memory
    /// is released and nothing is cleared: draws must not use it (a draw that does
    /// gets a fresh one).
    pub fn begin_frame_with<C: ColorTarget>(
        &mut self,
        target: Target,
        color: &mut C,
        background: Vec3,
        depth: bool,
    ) {
        self.target = target;
        if depth {
            self.depth.reset(target.width, target.height);
            counters::add(Stage::DepthClears, target.len() as u64);
        } else {
            self.depth = DepthBuffer::empty(target.width, target.height);
        }
        color.reset(target.len(), background);
        self.stats = DrawStats::default();
    }

    /// Whether this frame has a depth buffer.
    #[must_use]
    pub fn has_depth(&self) -> bool {
        self.depth.has_storage()
            && (self.depth.width(), self.depth.height()) == (self.target.width, self.target.height)
    }

    /// Draws indexed triangles whose vertices are already in `cache` (see [`transform`]).
    pub fn draw<S: Shader, C: ColorTarget>(
        &mut self,
        shader: &S,
        cache: &VertexCache<S::Varying>,
        indices: &[u32],
        opts: &DrawOptions,
        color: &mut C,
    ) {
        if opts.depth.uses_buffer() && !self.has_depth() {
            self.depth.reset(self.target.width, self.target.height);
        }
        #[cfg(target_arch = "x86_64")]
        {
            let isa = self.isa_for::<S>(opts);
            // `S::LANE_CODE` first, as its own condition: a constant `false` there keeps
            // the compiler from building the AVX-512 copy for this shader at all.
            if S::LANE_CODE && isa == Isa::Avx512 {
                // SAFETY: `isa_for` picks an instruction set only when the CPU has it.
                unsafe { isa::avx512::draw(self, shader, cache, indices, opts, color) };
                return;
            }
            if isa != Isa::Baseline {
                // SAFETY: as above; AVX-512 implies AVX2.
                unsafe { isa::avx2::draw(self, shader, cache, indices, opts, color) };
                return;
            }
        }
        isa::baseline::draw(self, shader, cache, indices, opts, color);
    }

    /// The instruction set a draw with `opts` runs on: [`Renderer::isa`] when the CPU
    /// has it and that copy is built for these options (the AVX-512 one is built for
    /// the default state with `wide` only, on targets at least 8 pixels wide, so that
    /// its group loop needs no per-pixel fallback for groups past the target's edge),
    /// else the next one down.
    ///
    /// Only shaders with lane code of their own ([`Shader::LANE_CODE`]) get the AVX-512
    /// copy.
    #[must_use]
    pub fn isa_for<S: Shader>(&self, opts: &DrawOptions) -> Isa {
        let avx512 = S::LANE_CODE && Self::is_fast(opts) && self.target.width >= 8;
        match self.isa {
            Isa::Avx512 if Isa::Avx512.is_supported() && avx512 => Isa::Avx512,
            Isa::Avx2 | Isa::Avx512 if Isa::Avx2.is_supported() => Isa::Avx2,
            _ => Isa::Baseline,
        }
    }

    #[inline(always)]
    fn draw_triangles<S: Shader, C: ColorTarget, L: I32s, const FAST_ONLY: bool>(
        &mut self,
        shader: &S,
        cache: &VertexCache<S::Varying>,
        indices: &[u32],
        opts: &DrawOptions,
        color: &mut C,
    ) {
        let target = self.target;
        let mut projected = std::mem::take(&mut self.projected);
        project_vertices(cache, target, &mut projected);
        let stats = if FAST_ONLY {
            debug_assert!(Self::is_fast(opts));
            self.raster::<S, C, L, true, true>(shader, cache, &projected, indices, opts, color)
        } else if Self::is_std(opts) {
            self.raster::<S, C, L, true, false>(shader, cache, &projected, indices, opts, color)
        } else {
            self.raster::<S, C, L, false, false>(shader, cache, &projected, indices, opts, color)
        };
        self.stats += stats;
        self.projected = projected;
    }

    /// The default depth state and perspective-correct interpolation: the state the
    /// fragment loop compiles as constants (see [`Fragments`]).
    #[inline(always)]
    fn is_std(opts: &DrawOptions) -> bool {
        opts.depth == DepthState::default() && opts.interpolation == Interpolation::Perspective
    }

    /// [`Renderer::is_std`] with the `wide` traversal: what the AVX-512 copy is built for.
    #[inline(always)]
    fn is_fast(opts: &DrawOptions) -> bool {
        Self::is_std(opts) && opts.traversal == Traversal::Wide
    }

    /// The triangle loop of [`Renderer::draw_triangles`] for one `STD` (see
    /// [`Fragments`]).
    #[inline(always)]
    fn raster<S: Shader, C: ColorTarget, L: I32s, const STD: bool, const WIDE: bool>(
        &mut self,
        shader: &S,
        cache: &VertexCache<S::Varying>,
        projected: &[Projected],
        indices: &[u32],
        opts: &DrawOptions,
        color: &mut C,
    ) -> DrawStats {
        let target = self.target;
        let mut raster = Raster::<S, C, L, STD, WIDE> {
            shader,
            depth: &mut self.depth,
            color,
            opts: *opts,
            width: target.width as usize,
            stats: DrawStats::default(),
            lanes: PhantomData::<L>,
        };
        let n = (indices.len() / 3) as u32;
        for t in 0..n {
            raster.stats.triangles += 1;
            let proj = Some(projected);
            match prepare_projected(cache, proj, indices, t, target, opts.cull, &mut raster) {
                PrepareOutcome::Rejected => raster.stats.rejected += 1,
                PrepareOutcome::Culled => raster.stats.culled += 1,
                PrepareOutcome::Drawn { clipped } => {
                    raster.stats.drawn += 1;
                    raster.stats.clipped += u64::from(clipped);
                }
            }
        }
        raster.stats
    }
}

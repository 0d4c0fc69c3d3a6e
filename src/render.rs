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

pub mod shaders;
pub mod standard;
pub mod target;
pub mod wire;

use glam::{Vec3, Vec4};

use crate::raster::clip::{ClipOutcome, ClipVertex, clip_triangle, guard_band_ndc};
use crate::raster::depth::{DepthBuffer, DepthFunc, DepthState};
use crate::raster::interp::{Interpolation, Varying, perspective_weights};
use crate::raster::{CoverageSink, SUBPIXEL_ONE, Setup, Target, Traversal};
pub use target::{ColorTarget, Luma, Rgba8};
use wide::f32x8;

/// A shader: the vertex stage produces clip-space positions and varyings for vertex
/// indices, the fragment stage a linear RGB colour from interpolated varyings. The
/// varying type is fixed at compile time, so each shader gets its own pipeline.
pub trait Shader {
    type Varying: Varying;
    /// Clip-space position and varyings of vertex `index`.
    fn vertex(&self, index: u32) -> (Vec4, Self::Varying);
    /// Colour of a fragment.
    fn fragment(&self, v: &Self::Varying) -> Vec3;

    /// Colours of up to 8 fragments of one triangle at once, as red, green and blue
    /// lanes: lane `k` (for each set bit of `mask`) has weights `w[..][k]` for the vertex
    /// varyings `var`. The default interpolates and shades lane by lane; shaders
    /// override it with `f32x8` code that must give the same bits as
    /// [`Shader::fragment`] (the probe relies on it).
    #[inline(always)]
    fn fragment8(&self, var: &[Self::Varying; 3], w: &[f32x8; 3], mask: u8) -> [f32x8; 3] {
        let w = w.map(f32x8::to_array);
        let mut out = [[0f32; 8]; 3];
        let mut m = mask;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            let v = Self::Varying::weighted(&var[0], &var[1], &var[2], [w[0][k], w[1][k], w[2][k]]);
            let c = self.fragment(&v);
            (out[0][k], out[1][k], out[2][k]) = (c.x, c.y, c.z);
            m &= m - 1;
        }
        out.map(f32x8::new)
    }
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
    pub var: [V; 3],
    /// `1 / area2`, rounded once to f32: barycentrics are `F · inv_area2`.
    pub inv_area2: f32,
}

/// The state of one pixel of one triangle: what the renderer computes per fragment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelEval {
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
        let (xi, yi) = (i64::from(x), i64::from(y));
        let f01 = s.edge_raw(0, xi, yi);
        let f02 = s.edge_raw(1, xi, yi);
        // Exact: the three edge functions sum to the doubled area everywhere.
        let f03 = s.area2 - f01 - f02;
        let covered = f01 + s.bias[0] >= 0 && f02 + s.bias[1] >= 0 && f03 + s.bias[2] >= 0;
        // The 8-lane fragment loop performs these same f32 operations in the same order,
        // so both give identical bits.
        let ia = self.inv_area2;
        let bary = [f02 as f32 * ia, f03 as f32 * ia, f01 as f32 * ia];
        let depth = bary[0] * self.z[0] + bary[1] * self.z[1] + bary[2] * self.z[2];
        let (persp, inv_w) = perspective_weights(bary, self.inv_w);
        PixelEval {
            f: [f01, f02, f03],
            covered,
            bary,
            persp,
            inv_w,
            depth,
        }
    }

    /// Interpolated varyings at an evaluated pixel.
    #[inline(always)]
    #[must_use]
    pub fn varyings(&self, e: &PixelEval, mode: Interpolation) -> V {
        let w = match mode {
            Interpolation::Perspective => e.persp,
            Interpolation::Affine => e.bary,
        };
        V::weighted(&self.var[0], &self.var[1], &self.var[2], w)
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

/// Clips, projects and sets up mesh triangle `t`, calling `emit` for each piece that
/// reaches the rasterizer. Shared by the renderer and the probe.
#[inline]
pub fn prepare<V: Varying>(
    cache: &VertexCache<V>,
    indices: &[u32],
    t: u32,
    target: Target,
    cull: Cull,
    mut emit: impl FnMut(&Prepared<V>),
) -> PrepareOutcome {
    let base = t as usize * 3;
    let Some(tri) = indices.get(base..base + 3) else {
        return PrepareOutcome::Rejected;
    };
    let fetch = |i: u32| cache.verts.get(i as usize).copied();
    let (Some(a), Some(b), Some(c)) = (fetch(tri[0]), fetch(tri[1]), fetch(tri[2])) else {
        return PrepareOutcome::Rejected;
    };
    let (outcome, poly) = clip_triangle([a, b, c], guard_band_ndc(target.width, target.height));
    if outcome == ClipOutcome::Rejected {
        return PrepareOutcome::Rejected;
    }
    let clipped = outcome == ClipOutcome::Clipped;
    let (fw, fh) = (target.width as f32, target.height as f32);
    let mut any = false;
    let mut culled = false;
    for (piece, tri) in poly.triangles().enumerate() {
        let inv_w = tri.map(|v| 1.0 / v.pos.w);
        let screen = [0, 1, 2].map(|i| {
            let p = tri[i].pos * inv_w[i];
            [(p.x * 0.5 + 0.5) * fw, (0.5 - p.y * 0.5) * fh]
        });
        let z = [0, 1, 2].map(|i| tri[i].pos.z * inv_w[i]);
        let xy = screen.map(|p| [f64::from(p[0]), f64::from(p[1])]);
        let Ok(setup) = Setup::new(xy, target) else {
            continue;
        };
        // Counter-clockwise in NDC (y-up) is negative area in y-down screen space.
        if cull == Cull::Back && !setup.flipped {
            culled = true;
            continue;
        }
        let order = |i: usize| if setup.flipped && i > 0 { 3 - i } else { i };
        let p = Prepared {
            triangle: t,
            piece: piece as u8,
            clipped,
            setup,
            screen: [0, 1, 2].map(|i| screen[order(i)]),
            z: [0, 1, 2].map(|i| z[order(i)]),
            inv_w: [0, 1, 2].map(|i| inv_w[order(i)]),
            var: [0, 1, 2].map(|i| tri[order(i)].var),
            inv_area2: (1.0 / setup.area2 as f64) as f32,
        };
        emit(&p);
        any = true;
    }
    match (any, culled) {
        (true, _) => PrepareOutcome::Drawn { clipped },
        (false, true) => PrepareOutcome::Culled,
        (false, false) => PrepareOutcome::Rejected,
    }
}

/// The fragment loop of one triangle: receives coverage from the traversal.
struct Fragments<'a, S: Shader, C> {
    tri: &'a Prepared<S::Varying>,
    shader: &'a S,
    depth: &'a mut DepthBuffer,
    color: &'a mut C,
    opts: DrawOptions,
    width: usize,
    fragments: u64,
    shaded: u64,
}

impl<S: Shader, C: ColorTarget> CoverageSink for Fragments<'_, S, C> {
    #[inline(always)]
    fn pixel(&mut self, x: u32, y: u32) {
        let e = self.tri.eval(x, y);
        let i = y as usize * self.width + x as usize;
        self.fragments += 1;
        let old = self.depth.data[i];
        if !self.opts.depth.func.passes(e.depth, old) {
            return;
        }
        if self.opts.depth.write {
            self.depth.data[i] = e.depth;
        }
        let v = self.tri.varyings(&e, self.opts.interpolation);
        self.color.put(i, self.shader.fragment(&v));
        self.shaded += 1;
    }

    /// Eight aligned pixels at once: exact edge values per lane, then barycentrics,
    /// depth, the depth test and perspective weights in `f32x8`; only shading runs per
    /// lane.
    #[inline(always)]
    fn mask8(&mut self, y: u32, x0: u32, mask: u8) {
        let row = y as usize * self.width;
        let start = row + x0 as usize;
        if x0 as usize + 8 > self.width {
            // The last group of a row whose width is not a multiple of 8.
            let mut m = mask;
            while m != 0 {
                self.pixel(x0 + m.trailing_zeros(), y);
                m &= m - 1;
            }
            return;
        }
        let t = self.tri;
        let s = &t.setup;
        let (xi, yi) = (i64::from(x0), i64::from(y));
        let (f01, f02) = (s.edge_raw(0, xi, yi), s.edge_raw(1, xi, yi));
        let (sx0, sx1) = (s.i[0] * SUBPIXEL_ONE, s.i[1] * SUBPIXEL_ONE);
        let mut e01 = [0f32; 8];
        let mut e02 = [0f32; 8];
        let mut e03 = [0f32; 8];
        for k in 0..8 {
            let a = f01 + k as i64 * sx0;
            let b = f02 + k as i64 * sx1;
            e01[k] = a as f32;
            e02[k] = b as f32;
            e03[k] = (s.area2 - a - b) as f32;
        }
        let ia = f32x8::splat(t.inv_area2);
        let b = [
            f32x8::new(e02) * ia,
            f32x8::new(e03) * ia,
            f32x8::new(e01) * ia,
        ];
        let z = t.z.map(f32x8::splat);
        let depth = b[0] * z[0] + b[1] * z[1] + b[2] * z[2];
        let slot: &mut [f32; 8] = (&mut self.depth.data[start..start + 8])
            .try_into()
            .expect("8 lanes");
        let old = f32x8::new(*slot);
        let covered = f32x8::new(std::array::from_fn(|k| {
            f32::from_bits(0u32.wrapping_sub(u32::from(mask >> k & 1)))
        }));
        let passing = covered
            & match self.opts.depth.func {
                DepthFunc::Less => depth.simd_lt(old),
                DepthFunc::LessEqual => depth.simd_le(old),
                DepthFunc::Always => covered,
            };
        let pass = passing.to_bitmask() as u8;
        self.fragments += u64::from(mask.count_ones());
        if pass == 0 {
            return;
        }
        if self.opts.depth.write {
            *slot = passing.select(depth, old).to_array();
        }
        let w = match self.opts.interpolation {
            Interpolation::Perspective => {
                let iw = t.inv_w.map(f32x8::splat);
                let p = [b[0] * iw[0], b[1] * iw[1], b[2] * iw[2]];
                let r = f32x8::splat(1.0) / (p[0] + p[1] + p[2]);
                [p[0] * r, p[1] * r, p[2] * r]
            }
            Interpolation::Affine => b,
        };
        let colors = self.shader.fragment8(&t.var, &w, pass);
        self.color.put8(start, pass, &colors);
        self.shaded += u64::from(pass.count_ones());
    }
}

/// Owns the depth buffer and frame counters; draws meshes into a colour target.
#[derive(Debug)]
pub struct Renderer {
    pub target: Target,
    pub depth: DepthBuffer,
    pub stats: DrawStats,
}

impl Renderer {
    /// A renderer for a target size.
    #[must_use]
    pub fn new(target: Target) -> Self {
        Self {
            target,
            depth: DepthBuffer::new(target.width, target.height),
            stats: DrawStats::default(),
        }
    }

    /// Starts a frame: clears depth and colour (reallocating only on resize) and the
    /// counters.
    pub fn begin_frame<C: ColorTarget>(&mut self, target: Target, color: &mut C, background: Vec3) {
        self.target = target;
        self.depth.reset(target.width, target.height);
        color.reset(target.len(), background);
        self.stats = DrawStats::default();
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
        let target = self.target;
        let mut stats = DrawStats::default();
        let n = (indices.len() / 3) as u32;
        for t in 0..n {
            stats.triangles += 1;
            let outcome = prepare(cache, indices, t, target, opts.cull, |tri| {
                let mut frag = Fragments {
                    tri,
                    shader,
                    depth: &mut self.depth,
                    color: &mut *color,
                    opts: *opts,
                    width: target.width as usize,
                    fragments: 0,
                    shaded: 0,
                };
                opts.traversal.run(&tri.setup, &mut frag);
                stats.fragments += frag.fragments;
                stats.shaded += frag.shaded;
            });
            match outcome {
                PrepareOutcome::Rejected => stats.rejected += 1,
                PrepareOutcome::Culled => stats.culled += 1,
                PrepareOutcome::Drawn { clipped } => {
                    stats.drawn += 1;
                    stats.clipped += u64::from(clipped);
                }
            }
        }
        self.stats += stats;
    }
}

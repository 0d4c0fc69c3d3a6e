//! The 3D pipeline: vertex transform, clipping, projection, exact setup, traversal,
//! depth test and shading, one file per stage.
//!
//! | file | owns |
//! |---|---|
//! | [`shader`] | [`Shader`], [`ShadeLanes`]: vertex and fragment stages, lane code |
//! | [`options`] | [`DrawOptions`], [`Cull`], [`DrawStats`] |
//! | [`prepare`](mod@prepare) | vertex cache, transform, [`Projected`], clipping, set-up: [`Prepared`] |
//! | [`eval`] | the scalar/lane pairs that must agree bit for bit: [`PixelEval`] |
//! | `fragments` | the coverage sink that tests depth and shades |
//! | [`probe`](mod@probe) | one pixel's raster state, recomputed on demand |
//! | `isa` | the compiled copies of the draw loop and the one choice among them |
//! | `tiles` | drawing on several threads: set-up binned by bands of rows, each band walked in draw order (`tiles/queue`: which thread walks which band); small frames a strip of rows per thread (`tiles/strips`) |
//! | this file | [`Renderer`]: frame state and the triangle loop |
//!
//! Screen mapping ([`ndc_to_screen`]): NDC x ∈ [−1, 1] maps to pixels [0, width] left
//! to right, NDC y ∈ [−1, 1] to [height, 0] (screen space is y-down), and z stays NDC
//! z ∈ [0, 1] for depth. Faces are front-facing when counter-clockwise in NDC (y-up),
//! i.e. when the rasterizer had to flip them to positive area in y-down screen space.
//!
//! Per-triangle work ([`prepare()`]) and per-pixel work ([`Prepared::eval`]) are shared
//! by the renderer and the probe, so the probe reports exactly what the renderer did.
//!
//! # Copies of the draw loop
//!
//! The draw loop is generic over a [`DrawVariant`] (how much of the draw state is a
//! compile-time constant) and compiled once per instruction set ([`Isa`]).
//! [`DrawCopy::choose`] picks the copy for a draw; it is the only place that decides.
//!
//! | variant \ ISA | baseline | AVX2 | AVX-512 |
//! |---|---|---|---|
//! | [`Generic`]: reads every option | yes | yes | no: runs AVX2 |
//! | [`Standard`]: depth `Less` + write, perspective are constants | off x86_64 (there: runs `Generic`) | yes | no: runs AVX2 |
//! | [`Fast`]: `Standard` with the `wide` traversal | no: runs `Standard` | no: runs `Standard` | lane-code shaders, targets ≥ 8 px wide |
//!
//! Why: `Standard` is the viewer's and the benchmark's state, so its per-group code
//! has no option checks; every other state shares `Generic`. AVX-512 pays off only for
//! shaders with lane code of their own ([`Shader::LANE_CODE`]) on the `wide` traversal,
//! and only on targets at least 8 pixels wide (its two-row groups then never need the
//! per-pixel fallback), so it is built for `Fast` alone; a third copy of every variant
//! would mostly lengthen the build. On x86_64 the baseline copy serves only CPUs
//! without AVX2, so it is built for `Generic` alone. The `Fast` copy's call sits
//! behind the constant `S::LANE_CODE`, so it is not even compiled for other shaders.
//! No call may sit in a group loop, taken or not: every vector register is lost
//! across it.

mod choice;
pub mod eval;
mod fragments;
mod isa;
pub mod options;
pub mod prepare;
pub mod probe;
pub mod shader;
pub mod shaders;
pub mod target;
mod tiles;
pub mod wire;

use std::sync::Arc;

use glam::Vec3;

use crate::counters::{self, Stage};
use crate::raster::Target;
use crate::raster::depth::DepthBuffer;
use crate::simd::I32s;
pub use eval::{PixelEval, perspective_weights};
use fragments::PieceWalker;
pub use isa::{DrawCopy, DrawVariant, Fast, Generic, Isa, Standard, Variant};
pub use options::{Cull, DrawOptions, DrawStats};
pub use prepare::{
    EmitPiece, PrepareOutcome, Prepared, Projected, VertexCache, ndc_to_screen, prepare,
    prepare_projected, project_vertices, transform, transform_projected,
};
pub use shader::{ShadeLanes, Shader};
pub use target::{ColorTarget, Rgba8, Rgba8Rows, SplitOff};
pub use tiles::strips::{ALL_ROWS, MAX_STRIPS, strip_ends, vertex_spans};
pub use tiles::{BAND_ROWS, DENSE_BAND_ROWS, band_rows};

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
    /// The threads draws run on ([`Renderer::set_threads`]); none for one thread.
    pool: Option<Arc<rayon::ThreadPool>>,
    /// The threaded draws' set-up records and bins, reused between draws.
    scratch: tiles::Scratch,
    /// The background of a colour clear left to the frame's first threaded draw
    /// ([`Renderer::begin_frame_deferred`]).
    pending_clear: Option<Vec3>,
    /// The least work (pixels + [`TRIANGLE_WORK`] × triangles) a draw must have to
    /// run on several threads: below it, handing the draw out costs more than the
    /// second thread saves. Tests set 0.
    pub min_threaded_work: u64,
    /// The least work a draw must have to run on several threads at all: from here
    /// to [`Renderer::min_threaded_work`], a strip of rows per thread
    /// ([`Spread::Strips`]), if the caller runs on the pool ([`Renderer::plan_frame`]);
    /// below it, the draw is too short for the threads to meet in time. Tests set 0.
    pub min_strip_work: u64,
    /// The most triangles per pixel, counted once per thread, of a draw of at least
    /// [`Renderer::min_threaded_work`] drawn in strips ([`Spread::Strips`]); a denser
    /// one is binned ([`Spread::Bins`]). [`STRIP_DENSITY`] by default; tests set 0 to
    /// bin every such draw.
    pub strip_density: u64,
    /// The fewest vertices whose vertex stage ([`Renderer::transform`]) runs on the
    /// frame's threads; [`MIN_PARALLEL_VERTICES`] by default. Tests set 0.
    pub min_parallel_vertices: usize,
    /// How the current draw is shared among threads.
    spread: Spread,
    /// Whether this frame may use the pool at all ([`Renderer::plan_frame`]).
    frame_threads: bool,
    /// Whether this frame is worth the threads wherever the caller runs (at least
    /// [`Renderer::min_threaded_work`]).
    frame_large: bool,
    /// For a loop that draws paced frames, the measured choice between the pool and
    /// the calling thread ([`Renderer::set_measured`]); `None` uses the pool for
    /// every frame worth it.
    choice: Option<choice::FrameChoice>,
}

/// The fewest vertices the one-thread vertex stage projects in its own pass
/// ([`transform_projected`]): a smaller mesh's vertices are still in the cache when
/// the draw projects them, in its own copy of the loop (AVX2 or AVX-512), which is
/// faster than the vertex stage's.
pub const FUSED_PROJECTION_VERTICES: usize = 1 << 16;

/// The default [`Renderer::min_parallel_vertices`]: a smaller mesh's vertex stage (the
/// bunny's 1 839 vertices take a few microseconds) is not split by rayon, which would
/// make the calling thread wait for a sleeping one, but shared in pieces the calling
/// thread takes too (from [`MIN_CLAIMED_VERTICES`]; on a steady frame).
pub const MIN_PARALLEL_VERTICES: usize = 1 << 12;

/// The fewest vertices whose vertex stage is shared out in claimed pieces: two pieces.
pub const MIN_CLAIMED_VERTICES: usize = 2 * tiles::VERTEX_JOB;

/// Pixels a triangle's share of a draw is worth, for [`Renderer::min_threaded_work`]:
/// set-up and binning, which many small triangles make the larger part.
pub const TRIANGLE_WORK: u64 = 32;

/// The default [`Renderer::min_threaded_work`]: half a megapixel, or some 16 000
/// triangles.
pub const MIN_THREADED_WORK: u64 = 1 << 19;

/// The default [`Renderer::min_strip_work`]: the bunny at the viewer's 400×240
/// samples (0.21 M) gains from strips; the teapot there (0.13 M, 0.14 ms) does not.
pub const MIN_STRIP_WORK: u64 = 1 << 17;

/// The default [`Renderer::strip_density`]. In strips every strip scans every
/// triangle, and a thread that takes another's rows scans the rest again; binned, each
/// triangle is set up once, but every record goes through memory between two parallel
/// steps and the walk waits for the set-up. On two threads strips are faster up to
/// about one triangle per pixel and thread (the 65k sphere at 1920×1080 and at
/// 400×240, the million-triangle sphere at 1920×1080), even at 2.7 and much slower
/// from 5 up (the million-triangle sphere at 400×240; see `docs/performance.md`).
pub const STRIP_DENSITY: u64 = 2;

/// How a draw is shared among the renderer's threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spread {
    /// On the calling thread alone.
    One,
    /// A strip of rows per thread, each setting up the triangles that reach it
    /// (`tiles/strips`): for a draw of at least [`Renderer::min_strip_work`], unless
    /// it is a dense one of at least [`Renderer::min_threaded_work`].
    Strips,
    /// Set up once and binned by bands of rows, then walked band by band (`tiles`):
    /// for draws of at least [`Renderer::min_threaded_work`] denser than
    /// [`Renderer::strip_density`].
    Bins,
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
            pool: None,
            scratch: tiles::Scratch::default(),
            pending_clear: None,
            min_threaded_work: MIN_THREADED_WORK,
            min_strip_work: MIN_STRIP_WORK,
            strip_density: STRIP_DENSITY,
            min_parallel_vertices: MIN_PARALLEL_VERTICES,
            spread: Spread::One,
            frame_threads: true,
            frame_large: true,
            choice: None,
        }
    }

    /// Draws on `threads` threads from now on (at least 1). One thread is the
    /// single-threaded path itself; more run every draw on a pool of that many
    /// threads, built here once (see `tiles`), with the frame and counters one thread
    /// gives. If the pool cannot be built, draws stay on one thread.
    pub fn set_threads(&mut self, threads: usize) {
        if threads == self.threads() {
            return;
        }
        // Times measured with the old pool say nothing about the new one.
        if self.choice.is_some() {
            self.set_measured(true);
        }
        self.pool = (threads > 1)
            .then(|| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .thread_name(|i| format!("termrast-draw-{i}"))
                    .build()
                    .ok()
                    .map(Arc::new)
            })
            .flatten();
    }

    /// The threads draws run on.
    #[must_use]
    pub fn threads(&self) -> usize {
        self.pool.as_ref().map_or(1, |p| p.current_num_threads())
    }

    /// Says how much work the coming frame has in all (pixels + [`TRIANGLE_WORK`] ×
    /// triangles): a frame below [`Renderer::min_threaded_work`] runs wholly on the
    /// calling thread, vertices and clears included, as if there were no pool, unless
    /// the calling thread is one of the pool's ([`Renderer::thread_pool`]) and the
    /// frame has at least [`Renderer::min_strip_work`]: then its draws are shared in
    /// strips ([`Spread::Strips`]).
    ///
    /// With [`Renderer::set_measured`], a frame worth the pool may still be drawn on
    /// the calling thread, if frames of this work have been faster there; the caller
    /// then reports each frame's time ([`Renderer::frame_took`]). `kind` tells frames
    /// of the same amount of work but drawn differently apart (any value that changes
    /// with how the frame is drawn: edges or triangles, culling): each is measured
    /// afresh.
    pub fn plan_frame(&mut self, work: u64, kind: u64) {
        let on_pool = self
            .pool
            .as_ref()
            .is_some_and(|p| p.current_thread_index().is_some());
        self.frame_large = work >= self.min_threaded_work;
        self.frame_threads = self.frame_large || (on_pool && work >= self.min_strip_work);
        if self.frame_threads
            && self.pool.is_some()
            && let Some(choice) = &mut self.choice
            && !choice.pooled(work, kind)
        {
            self.frame_threads = false;
            self.frame_large = false;
        }
    }

    /// Chooses from now on, frame by frame, between the pool and the calling thread
    /// by how long recent frames took each way (`render::choice`): for a loop that
    /// draws frames now and then, such as the viewer, whose idle threads can make a
    /// frame slower on the pool than on one thread. Both ways draw the same frame.
    /// Off by default: a benchmark uses the threads it is given.
    pub fn set_measured(&mut self, on: bool) {
        self.choice = on.then(choice::FrameChoice::default);
    }

    /// Reports how long the frame planned last ([`Renderer::plan_frame`]) took to
    /// draw, for the measured choice; without it, or for a frame the pool was not
    /// considered for, nothing happens.
    pub fn frame_took(&mut self, took: std::time::Duration) {
        if let Some(choice) = &mut self.choice {
            choice.took(took);
        }
    }

    /// Whether the frame planned last may use the pool.
    #[must_use]
    pub fn frame_pooled(&self) -> bool {
        self.pool.is_some() && self.frame_threads
    }

    /// Sets the shares of the vertices that the strips of the frame's draw number
    /// `draw` (from 0) start from, one per thread (in strips, [`Spread::Strips`]):
    /// equal at first, then corrected after each draw by the time each strip took.
    /// Tests set uneven ones.
    pub fn set_strip_shares(&mut self, draw: usize, shares: &[f32]) {
        self.scratch.shares(draw).set(shares);
    }

    /// The renderer's threads, if more than one, whatever the frame: a caller that
    /// runs its frame loop inside (`install`) hands no frame from thread to thread,
    /// and lets small frames be shared too ([`Renderer::plan_frame`]).
    #[must_use]
    pub fn thread_pool(&self) -> Option<&Arc<rayon::ThreadPool>> {
        self.pool.as_ref()
    }

    /// The pool this frame's work runs on, if more than one thread and the frame is
    /// worth it: a caller that runs a whole frame inside it (`install`) hands the
    /// frame to its threads once, instead of once per step.
    #[must_use]
    pub fn pool(&self) -> Option<&Arc<rayon::ThreadPool>> {
        self.pool.as_ref().filter(|_| self.frame_threads)
    }

    /// [`transform_projected`] for the renderer's target, on its threads (the same
    /// vertices, in chunks of the vertex array): the draws that follow use the
    /// projections instead of making their own. Fewer than
    /// [`Renderer::min_parallel_vertices`] are shared in pieces the calling thread
    /// claims too (on a steady frame, from [`MIN_CLAIMED_VERTICES`]). On one thread (or
    /// for fewer vertices), a mesh of fewer than [`FUSED_PROJECTION_VERTICES`] is only
    /// transformed.
    pub fn transform<S: Shader>(
        &self,
        shader: &S,
        vertex_count: usize,
        cache: &mut VertexCache<S::Varying>,
    ) {
        let target = self.target;
        // A small mesh on the threads: in pieces the calling thread takes too, so a
        // sleeping helper never holds it up.
        if let Some(pool) = self.pool()
            && vertex_count < self.min_parallel_vertices
            && vertex_count >= MIN_CLAIMED_VERTICES
            && pool.install(|| tiles::transform_claimed(shader, vertex_count, cache, target))
        {
            return;
        }
        let pool = self
            .pool()
            .filter(|_| vertex_count >= self.min_parallel_vertices);
        let Some(pool) = pool else {
            if vertex_count >= FUSED_PROJECTION_VERTICES {
                transform_projected(shader, vertex_count, cache, target);
            } else {
                transform(shader, vertex_count, cache);
            }
            return;
        };
        pool.install(|| {
            use rayon::prelude::*;
            // A steady frame transforms into the vertices of the last and projects each
            // piece while it is in the cache; a new vertex count makes room first.
            let fresh = cache.verts.len() != vertex_count;
            let vertex = |i| prepare::clip_vertex(shader, i);
            if fresh {
                cache.verts.clear();
                cache.verts.par_extend(
                    (0..vertex_count)
                        .into_par_iter()
                        .with_min_len(tiles::VERTEX_JOB)
                        .map(vertex),
                );
            }
            let projected = prepare::one_per_vertex(&mut cache.projected, vertex_count);
            cache
                .verts
                .par_chunks_mut(tiles::VERTEX_JOB)
                .zip(projected.par_chunks_mut(tiles::VERTEX_JOB))
                .enumerate()
                .for_each(|(k, (verts, out))| {
                    if !fresh {
                        prepare::transform_in_place(shader, k * tiles::VERTEX_JOB, verts);
                    }
                    prepare::project_into(verts, target, out);
                });
            cache.projected_for = Some(target);
        });
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
        self.begin_frame_deferred(target, color, background, depth);
        self.finish_clear(color);
    }

    /// [`Renderer::begin_frame_with`], but on several threads the colour clear is left
    /// to the frame's first draw, whose threads clear each band just before they walk
    /// it (one pass over the frame fewer). The caller must call
    /// [`Renderer::finish_clear`] before it touches the colour target other than by
    /// [`Renderer::draw`].
    pub fn begin_frame_deferred<C: ColorTarget>(
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
        self.pending_clear = None;
        if self.tiled() && color.len() == target.len() {
            self.pending_clear = Some(background);
        } else {
            color.reset(target.len(), background);
        }
        self.stats = DrawStats::default();
        self.scratch.begin_frame();
    }

    /// Clears the colour target if a deferred clear is still pending (no draw of the
    /// frame took it), on the renderer's threads.
    pub fn finish_clear<C: ColorTarget>(&mut self, color: &mut C) {
        let Some(background) = self.pending_clear.take() else {
            return;
        };
        let Some(pool) = self.pool() else {
            color.reset(self.target.len(), background);
            return;
        };
        use rayon::prelude::*;
        let rows = tiles::band_rows(self.target, pool.current_num_threads(), 0);
        let band = rows as usize * self.target.width as usize;
        pool.install(|| {
            color.bands(band).for_each(|mut b| {
                let len = b.len();
                b.reset(len, background);
            });
        });
    }

    /// Whether draws run on several threads ([`tiles`]): with a pool, on a target
    /// with pixels.
    fn tiled(&self) -> bool {
        self.pool.is_some() && self.frame_threads && !self.target.is_empty()
    }

    /// How the current draw is shared among threads (set by [`Renderer::draw`]).
    #[must_use]
    pub fn spread(&self) -> Spread {
        self.spread
    }

    /// How many times, over every draw so far, a thread done with its strip took
    /// rows from one still drawing ([`Spread::Strips`]).
    #[must_use]
    pub fn handovers(&self) -> u64 {
        self.scratch.handovers
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
        let (pixels, triangles) = (self.target.len() as u64, (indices.len() / 3) as u64);
        let work = pixels + TRIANGLE_WORK * triangles;
        let large = self.frame_large && work >= self.min_threaded_work;
        let dense = triangles.saturating_mul(self.threads() as u64)
            > self.strip_density.saturating_mul(pixels);
        self.spread = match () {
            _ if !S::THREADED || !self.tiled() => Spread::One,
            _ if large && dense => Spread::Bins,
            _ if large || work >= self.min_strip_work => Spread::Strips,
            _ => Spread::One,
        };
        if self.spread == Spread::One {
            self.finish_clear(color);
        }
        let copy = self.copy_for::<S>(opts);
        isa::run(copy, self, shader, cache, indices, opts, color);
    }

    /// The copy of the draw loop a draw of shader `S` with `opts` runs on this renderer
    /// (see [`DrawCopy::choose`]).
    #[must_use]
    pub fn copy_for<S: Shader>(&self, opts: &DrawOptions) -> DrawCopy {
        DrawCopy::choose::<S>(self.isa, opts, self.target.width)
    }

    /// The body of every copy of the draw loop ([`isa`]): projects the vertices once,
    /// then walks the triangles with variant `V` on lanes `L`.
    #[inline(always)]
    fn draw_triangles<V: DrawVariant, S: Shader, C: ColorTarget, L: I32s>(
        &mut self,
        shader: &S,
        cache: &VertexCache<S::Varying>,
        indices: &[u32],
        opts: &DrawOptions,
        color: &mut C,
    ) {
        debug_assert!(V::admits(opts), "{opts:?} run on a copy not built for it");
        let target = self.target;
        let mut projected = std::mem::take(&mut self.projected);
        let pv = match cache.projections(target) {
            Some(pv) => pv,
            None => {
                project_vertices(cache, target, &mut projected);
                &projected[..]
            }
        };
        let mut walker =
            PieceWalker::<S, C, L, V, _>::new(shader, &mut self.depth, color, opts, target);
        let n = (indices.len() / 3) as u32;
        for t in 0..n {
            let outcome = prepare_projected(cache, Some(pv), indices, t, target, opts, &mut walker);
            outcome.count(&mut walker.stats, 1);
        }
        self.stats += walker.stats;
        self.projected = projected;
    }
}

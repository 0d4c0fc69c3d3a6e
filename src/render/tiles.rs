//! Drawing on several threads, with the frame one thread would draw, bit for bit.
//!
//! A small draw, or one of up to [`STRIP_DENSITY`](super::STRIP_DENSITY) triangles
//! per pixel and thread, is shared in strips of rows, one step (`strips`). A large
//! and denser one runs in three parallel steps on the renderer's thread pool:
//!
//! 1. **Vertices**: every vertex goes through the vertex stage and is projected once
//!    ([`Projected::of`]), in parallel chunks of the vertex array, in one pass
//!    ([`super::Renderer::transform`]; a draw whose vertices were transformed alone,
//!    those of a small mesh, projects them here, the same way: `vertices`).
//! 2. **Set-up and binning**: the triangles are cut into chunks of consecutive
//!    triangles; each chunk's thread clips and sets up its triangles once
//!    ([`super::prepare_projected`], as on one thread) into the chunk's records, in
//!    draw order, and files each record's index in the bin of every band its box
//!    touches (`bins`).
//! 3. **Walk**: each band is walked by one thread, which takes the bins of every
//!    chunk in chunk order: the triangles of a band reach its depth test and its
//!    colour writes in draw order, as on one thread. A triangle that crosses bands is
//!    walked in each with its box cut to the band's rows
//!    ([`Setup::rows`](crate::raster::Setup::rows), the same edge values at every
//!    pixel), so every pixel gets the same fragments, in the same order, through the
//!    same copy of the draw loop ([`super::DrawCopy::choose`]).
//!    Which thread walks which band, and when, is up to `queue`: costliest first
//!    within each thread's run of bands, so that the threads finish together. The
//!    records were written by whichever core set them up, so the walk asks for the
//!    next one's cache lines while it walks the current one.
//!
//! The tiles are bands of whole rows ([`band_rows`] high) rather than squares: a band
//! is one contiguous slice of the colour target and one of the depth buffer (and its
//! clear bits), so the threads own disjoint borrows and no lock or atomic is needed;
//! and the `wide` walk puts 8-pixel groups anywhere on a row (a group may start left of
//! a narrow box) and the 8-lane copies store a whole group with a blend, so two threads
//! must not share a row. Bands are a multiple of the 8-pixel block and of the depth
//! buffer's clear tile, so the block walk's trivial accept and reject work per band and
//! no clear tile is shared. The records, bins and projections are kept from draw to
//! draw: a steady frame allocates nothing.

use std::any::Any;
use std::ops::Range;

use glam::Vec3;
use rayon::prelude::*;

use super::fragments::PieceWalker;
use super::isa::DrawVariant;
use super::options::{DrawOptions, DrawStats};
use super::prepare::{Projected, VertexCache};
use super::shader::Shader;
use super::target::{ColorTarget, SplitOff};
use super::{Renderer, Spread};
use crate::raster::Target;
use crate::raster::depth::DepthRows;
use crate::simd::{I32s, prefetch};
use queue::plan_bands;
use strips::{Handover, Part, StripPlan};
use vertices::projections;
pub(super) use vertices::transform_claimed;

mod bins;
mod queue;
pub mod strips;
mod vertices;

pub(super) use bins::{Chunk, setup_chunk};

/// The tallest band: a multiple of the block traversal's 8 and of the depth clear
/// tile. Chosen by measurement (see `docs/performance.md`).
pub const BAND_ROWS: u32 = 48;

/// The tallest band of a dense draw (see [`band_rows`]).
pub const DENSE_BAND_ROWS: u32 = 96;

/// Triangles per chunk of a batch (see [`draw`]): a batch's records stay bounded
/// however large the mesh (some 28 MB at most on two threads, when every triangle
/// leaves one), while a mesh of up to 65 536 triangles on two threads is one batch.
/// Each batch costs a hand-over between set-up and walk; chosen by measurement (see
/// `docs/performance.md`).
const CHUNK_TRIANGLES: usize = 8192;

/// Chunks of triangles per thread in the set-up step: enough that a thread that
/// finishes early takes another.
const CHUNKS_PER_THREAD: usize = 4;

/// Vertices per parallel job of the vertex stage, and per claimed piece of a small
/// mesh's projections (`vertices`): small enough that a mesh of a few thousand
/// vertices is shared out, which wakes the pool before the set-up needs it (smaller
/// jobs cost more to hand out than they save).
pub(super) const VERTEX_JOB: usize = 512;

/// Every chunk of a draw, for one varying type.
#[derive(Debug)]
struct Bins<V> {
    chunks: Vec<Chunk<V>>,
}

/// What the threaded path keeps between draws: the chunks of each varying type drawn
/// so far (a scene's objects may differ), and the bands' walking order, so that a
/// steady frame reuses them.
#[derive(Default)]
pub(super) struct Scratch {
    bins: Vec<Box<dyn Any + Send>>,
    /// Band indices, costliest first.
    order: Vec<u32>,
    /// Per band, the work of the batch being walked.
    cost: Vec<u64>,
    /// Per 8 rows, the vertices there (`strips`: where a small frame's work lies).
    pub(super) rows: Vec<u32>,
    /// Per vertex, the rows a box takes from it (`strips::vertex_spans`).
    pub(super) spans: Vec<u32>,
    /// Per draw of a frame (the first [`strips::SHARED_DRAWS`], the rest sharing the
    /// last), each strip's share of the vertices, corrected by the strips' times. Made
    /// by the first draw in strips.
    pub(super) shares: Vec<strips::Shares>,
    /// The draws in strips so far in this frame ([`Scratch::begin_frame`]).
    pub(super) strip_draws: usize,
    /// Rows handed from one strip's thread to another's, over every draw.
    pub(super) handovers: u64,
}

impl std::fmt::Debug for Scratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scratch")
            .field("varying_types", &self.bins.len())
            .finish()
    }
}

impl Scratch {
    /// Starts counting a frame's draws again, so each draw keeps its own shares.
    pub(super) fn begin_frame(&mut self) {
        self.strip_draws = 0;
    }

    /// The shares of the frame's draw number `draw` (the last kept for later ones).
    pub(super) fn shares(&mut self, draw: usize) -> &mut strips::Shares {
        if self.shares.is_empty() {
            self.shares
                .resize(strips::SHARED_DRAWS, strips::Shares::default());
        }
        &mut self.shares[draw.min(strips::SHARED_DRAWS - 1)]
    }

    /// The chunks for varying type `V`: `chunks` of them, each with `bands` empty bins,
    /// and the band order and costs.
    fn chunks<V: Send + 'static>(
        &mut self,
        chunks: usize,
        bands: usize,
    ) -> (&mut [Chunk<V>], &mut Vec<u32>, &mut Vec<u64>) {
        let i = match self.bins.iter().position(|b| (**b).is::<Bins<V>>()) {
            Some(i) => i,
            None => {
                self.bins.push(Box::new(Bins::<V> { chunks: Vec::new() }));
                self.bins.len() - 1
            }
        };
        let bins = self.bins[i]
            .downcast_mut::<Bins<V>>()
            .expect("the entry's type was just checked");
        // Grown, never shrunk: a frame's draws need different counts (a mesh of fewer
        // triangles than chunks), and a dropped chunk's records would be allocated
        // again by the next draw.
        if bins.chunks.len() < chunks {
            bins.chunks.resize_with(chunks, Chunk::default);
        }
        for c in &mut bins.chunks[..chunks] {
            c.starts.resize(bands + 1, 0);
            c.cost.resize(bands, 0);
        }
        self.order.resize(bands, 0);
        self.cost.resize(bands, 0);
        (&mut bins.chunks[..chunks], &mut self.order, &mut self.cost)
    }
}

/// What every thread of a draw reads.
pub(super) struct Job<'a, S: Shader> {
    shader: &'a S,
    cache: &'a VertexCache<S::Varying>,
    projected: &'a [Projected],
    indices: &'a [u32],
    opts: DrawOptions,
    target: Target,
    /// Rows per band (a multiple of 8).
    band_rows: u32,
}

/// The two steps of a threaded draw that run a copy of the draw loop, compiled for
/// the copy's instruction set and variant (implemented in `isa`'s modules).
pub(super) trait TileCopy {
    /// Sets up triangles `range` into `chunk` (see [`setup_chunk`]).
    ///
    /// # Safety
    /// The CPU must have the copy's instruction set.
    unsafe fn setup<S: Shader>(job: &Job<'_, S>, range: Range<u32>, chunk: &mut Chunk<S::Varying>);

    /// Walks band `band` of every chunk into its rows of colour and depth, first
    /// filling the colour rows with `clear` if given (see [`walk_band`]); returns its
    /// fragment counters.
    ///
    /// # Safety
    /// As for [`TileCopy::setup`].
    unsafe fn walk<S: Shader, C: ColorTarget>(
        job: &Job<'_, S>,
        chunks: &[Chunk<S::Varying>],
        band: usize,
        color: &mut C,
        depth: &mut DepthRows<'_>,
        clear: Option<Vec3>,
    ) -> DrawStats;

    /// Draws `part`'s rows of colour and depth of every triangle from its first on,
    /// first filling the colour rows with `clear` if given, handing rows over when
    /// asked (see [`strips::draw_strip`]); returns its counters.
    ///
    /// # Safety
    /// As for [`TileCopy::setup`].
    unsafe fn strip<'d, S: Shader, C: ColorTarget + SplitOff>(
        job: &Job<'_, S>,
        plan: &StripPlan<'_>,
        part: &mut Part<'d, C>,
        handover: &Handover<'d, C>,
        clear: Option<Vec3>,
    ) -> DrawStats;
}

/// Draws on the renderer's pool with copy `T`, in strips or in bins as the renderer
/// chose for the draw ([`super::Spread`]).
///
/// # Safety
/// The CPU must have `T`'s instruction set (as [`super::DrawCopy::choose`] ensures).
pub(super) unsafe fn draw<T: TileCopy, S: Shader, C: ColorTarget>(
    r: &mut Renderer,
    shader: &S,
    cache: &VertexCache<S::Varying>,
    indices: &[u32],
    opts: &DrawOptions,
    color: &mut C,
) {
    // SAFETY: the caller's guarantee.
    unsafe {
        if r.spread() == Spread::Strips {
            strips::draw::<T, S, C>(r, shader, cache, indices, opts, color);
        } else {
            draw_binned::<T, S, C>(r, shader, cache, indices, opts, color);
        }
    }
}

/// Draws on the renderer's pool with copy `T`, set up and binned, then walked by
/// bands: the threaded form of `Renderer::draw_triangles`, with the same frame and
/// counters.
///
/// # Safety
/// As for [`draw`].
unsafe fn draw_binned<T: TileCopy, S: Shader, C: ColorTarget>(
    r: &mut Renderer,
    shader: &S,
    cache: &VertexCache<S::Varying>,
    indices: &[u32],
    opts: &DrawOptions,
    color: &mut C,
) {
    let Some(pool) = r.pool.as_ref() else {
        unreachable!("a threaded draw without a pool");
    };
    let target = r.target;
    let threads = pool.current_num_threads();
    let triangles = indices.len() / 3;
    let band_rows = band_rows(target, threads, triangles);
    let bands = target.height.div_ceil(band_rows) as usize;
    let n = (threads * CHUNKS_PER_THREAD).clamp(1, triangles.max(1));
    let (chunks, order, cost) = r.scratch.chunks::<S::Varying>(n, bands);
    let projected = &mut r.projected;
    let depth = &mut r.depth;
    let mut clear = r.pending_clear.take();
    let stats = pool.install(|| {
        let projected = projections(cache, target, projected);
        let job = Job {
            shader,
            cache,
            projected,
            indices,
            opts: *opts,
            target,
            band_rows,
        };
        let mut stats = DrawStats::default();
        // Batches of triangles, each set up and then walked, so the records of a large
        // mesh are a few megabytes reused, not one record per triangle of the mesh.
        // At least one batch: it also clears the colour if that is pending.
        let batch = n * CHUNK_TRIANGLES;
        for first in (0..triangles.max(1)).step_by(batch) {
            let count = batch.min(triangles.saturating_sub(first));
            let clear = clear.take();
            let part = |c: usize| (first + count * c / n) as u32;
            chunks
                .par_iter_mut()
                .enumerate()
                .with_max_len(1)
                .for_each(|(c, chunk)| {
                    // SAFETY: the caller's guarantee.
                    unsafe { T::setup(&job, part(c)..part(c + 1), chunk) };
                });
            let chunks = &*chunks;
            let colors = color.bands(band_rows as usize * target.width as usize);
            assert_eq!(
                colors.len(),
                bands,
                "the colour target is not the frame's size"
            );
            let bands = colors.zip(depth.bands(band_rows));
            let walk = |b: usize, (mut color, mut depth): (C::Rows<'_>, DepthRows<'_>)| {
                // SAFETY: the caller's guarantee.
                unsafe { T::walk(&job, chunks, b, &mut color, &mut depth, clear) }
            };
            for (b, c) in cost.iter_mut().enumerate() {
                *c = chunks.iter().map(|ch| ch.cost[b]).sum();
            }
            let walked = match plan_bands(order, cost, threads) {
                Some(queues) => queue::walk_in_order(bands, queues, order, &walk),
                None => bands
                    .enumerate()
                    .with_max_len(1)
                    .map(|(b, rows)| walk(b, rows))
                    .reduce(DrawStats::default, |mut a, b| {
                        a += b;
                        a
                    }),
            };
            stats += walked;
            for c in chunks {
                stats += c.stats;
            }
        }
        stats
    });
    r.stats += stats;
}

/// Rows per band for `triangles` drawn into `target` on `threads` threads: about six
/// bands per thread, so that the costliest-first hand-out can even the threads out,
/// but at most [`BAND_ROWS`] (taller bands leave too few to share; shorter ones make
/// more triangles cross a border and be walked twice). A dense draw, whose triangles
/// would take 4 to 256 pixels each if they tiled the target, gets about four bands per
/// thread of at most [`DENSE_BAND_ROWS`]: its many boxes of a few rows would cross
/// short bands by the thousand, each crossing a second walk set-up, while its work is
/// spread evenly enough to share out in fewer bands. (Smaller triangles have boxes of a
/// row or two, which rarely cross.) A multiple of 8 (the block walk's blocks and two
/// depth clear tiles).
#[must_use]
pub fn band_rows(target: Target, threads: usize, triangles: usize) -> u32 {
    let pixels = target.len();
    let dense = (pixels / 256..=pixels / 4).contains(&triangles) && triangles > 0;
    let (per_thread, tallest) = if dense {
        (4, DENSE_BAND_ROWS)
    } else {
        (6, BAND_ROWS)
    };
    let per = target.height / (per_thread * threads.max(1) as u32);
    (per / 8 * 8).clamp(8, tallest)
}

/// Walks band `band` (its rows of `color` and `depth`) through every chunk's bin in
/// chunk order, so in draw order, with variant `V` on lanes `L`: the body of every
/// copy's [`TileCopy::walk`].
#[inline(always)]
pub(super) fn walk_band<V: DrawVariant, S: Shader, C: ColorTarget, L: I32s>(
    job: &Job<'_, S>,
    chunks: &[Chunk<S::Varying>],
    band: usize,
    color: &mut C,
    depth: &mut DepthRows<'_>,
    clear: Option<Vec3>,
) -> DrawStats {
    if let Some(background) = clear {
        // The frame's deferred clear, a band at a time: its lines are then in this
        // core's cache when the walk writes them.
        let len = color.len();
        color.reset(len, background);
    }
    let y0 = band as u32 * job.band_rows;
    let y1 = (y0 + job.band_rows).min(job.target.height) - 1;
    let mut walker =
        PieceWalker::<S, C, L, V, _>::new(job.shader, depth, color, &job.opts, job.target);
    for chunk in chunks {
        let bin = chunk.bin(band);
        for (k, &i) in bin.iter().enumerate() {
            // The next record is on its way while this one is walked (see `prefetch`).
            if let Some(&next) = bin.get(k + 1) {
                prefetch(&chunk.records[next as usize]);
            }
            walker.walk_rows(&chunk.records[i as usize], y0, y1);
        }
    }
    walker.stats
}

#[cfg(test)]
mod tests {
    use super::{BAND_ROWS, DENSE_BAND_ROWS, band_rows};
    use crate::raster::Target;

    /// Bands are whole blocks of 8 rows, at most `BAND_ROWS`, and about six per
    /// thread wherever the target is tall enough for that; a dense draw's at most
    /// `DENSE_BAND_ROWS`, about four per thread.
    #[test]
    fn bands_are_blocks_of_rows_about_six_per_thread() {
        for threads in 1..=8 {
            for height in 1..2000 {
                let target = Target::new(100, height);
                let dense = target.len() / 16;
                for (triangles, per, tallest) in [
                    (0, 6, BAND_ROWS),
                    (20 * target.len(), 6, BAND_ROWS),
                    (dense, 4, DENSE_BAND_ROWS),
                ] {
                    let rows = band_rows(target, threads, triangles);
                    assert!(rows.is_multiple_of(8) && (8..=tallest).contains(&rows));
                    let bands = height.div_ceil(rows) as usize;
                    if rows < tallest && rows > 8 {
                        assert!(
                            (per * threads..2 * per * threads).contains(&bands),
                            "{height} {threads} {triangles}"
                        );
                    }
                }
            }
        }
        let hd = Target::new(1920, 1080);
        assert_eq!(band_rows(Target::new(400, 240), 2, 200), 16);
        assert_eq!(band_rows(hd, 2, 3674), BAND_ROWS);
        assert_eq!(band_rows(hd, 2, 65_024), DENSE_BAND_ROWS);
        assert_eq!(band_rows(hd, 2, 1 << 20), BAND_ROWS);
        assert_eq!(band_rows(Target::new(400, 240), 2, 16_000), 24);
    }
}

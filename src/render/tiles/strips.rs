//! Draws on several threads in one step: one strip of rows per thread, each setting
//! up every triangle that reaches its rows and walking it there at once.
//!
//! Binning ([`super::draw`]) sends every set-up record through memory between two
//! parallel steps. A frame of a few hundred thousand pixels and a few thousand
//! triangles (a model at terminal size) is done in well under a millisecond, and
//! binning then costs more than the second thread saves. A larger draw of up to
//! [`STRIP_DENSITY`](crate::render::STRIP_DENSITY) triangles per pixel and thread
//! (`Renderer::draw`) is faster in strips too: each triangle is walked as soon as it
//! is set up, with few borders to cross. Here there is one
//! step: each thread scans the triangles in draw order, 64 at a time in a tight loop
//! ([`reaching`]), skips those whose box misses its strip, and sets up and walks the
//! others with their boxes cut to its rows
//! ([`Setup::rows`](crate::raster::Setup::rows)), as one thread would. Only triangles
//! crossing a strip's border are set up twice. The scan reads one word per vertex,
//! the rows a box takes from it ([`vertex_spans`]), made once before the strips
//! start: the box's rows run from the least first row of its vertices to the
//! greatest last row. It grows with the triangles, for every strip: a dense draw is
//! binned.
//!
//! The strips are placed by the vertices' first rows (counted per 8 rows before the
//! draw): at first each holds as many, then each draw's shares are corrected by the
//! time each strip took to end ([`Shares`]), since a vertex costs more where its
//! triangles are larger or the other thread starts later. Within a draw, a thread
//! done with its rows takes the lower part of another's, where about half of its
//! work left lies, and the other goes on from the next triangle with the rest
//! (`steal`): so the threads end together even when a core slows down mid-draw. A
//! small frame is worth
//! strips only to a caller that runs on the pool's threads itself
//! (`Renderer::plan_frame`): handing a frame of a few hundred microseconds to a
//! sleeping thread and waiting for it to be handed back costs more than the second
//! thread saves.
//!
//! Every triangle is counted by one strip (its owner), so the counters are one
//! thread's: the rows that hold the first row of its box (clamped to the target)
//! when the triangle is drawn. A triangle with a vertex that needs clipping or did
//! not snap has no box before its set-up: every strip sets it up, and the rows from
//! the top count it (as they count one with a vertex index out of range).

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use glam::Vec3;
use rayon::prelude::*;

use super::{Job, Scratch, TileCopy, projections};
use crate::raster::depth::DepthRows;
use crate::render::fragments::PieceWalker;
use crate::render::isa::DrawVariant;
use crate::render::options::{DrawOptions, DrawStats};
use crate::render::prepare::{EmitPiece, Prepared, VertexCache, prepare_projected};
use crate::render::shader::Shader;
use crate::render::target::SplitOff;
use crate::render::{ColorTarget, Renderer};
use crate::simd::I32s;

mod place;
mod steal;

pub use place::{
    ALL_ROWS, SHARED_DRAWS, Shares, box_rows, handover_row, reaching, strip_ends, vertex_spans,
};
pub(in crate::render) use steal::{Handover, Part};

/// The most strips a draw is cut into: a larger pool leaves its other threads idle.
pub const MAX_STRIPS: usize = 16;

/// What every strip of a draw reads besides the [`Job`].
pub(in crate::render) struct StripPlan<'a> {
    /// Per vertex, the rows a box takes from it ([`vertex_spans`]).
    pub spans: &'a [u32],
}

/// The longest the first strip's thread spins waiting for the others before it
/// waits as rayon does (by sleeping once nothing is left to steal).
const MAX_SPIN: Duration = Duration::from_millis(2);

/// Hands each piece of a triangle to the walker with its box cut to the strip's
/// rows.
struct Cut<'w, W> {
    walker: &'w mut W,
    rows: [u32; 2],
}

impl<V, W: StripWalk<V>> EmitPiece<V> for Cut<'_, W> {
    #[inline(always)]
    fn piece(&mut self, p: &Prepared<V>) {
        let [y0, y1] = self.rows;
        self.walker.walk_rows(p, y0, y1);
    }
}

/// [`PieceWalker::walk_rows`], named so [`Cut`] needs no type parameters of its own.
trait StripWalk<V> {
    fn walk_rows(&mut self, p: &Prepared<V>, y0: u32, y1: u32);
}

impl<S: Shader, C: ColorTarget, L: I32s, V: DrawVariant> StripWalk<S::Varying>
    for PieceWalker<'_, S, C, L, V, DepthRows<'_>>
{
    #[inline(always)]
    fn walk_rows(&mut self, p: &Prepared<S::Varying>, y0: u32, y1: u32) {
        PieceWalker::walk_rows(self, p, y0, y1);
    }
}

/// Triangles a strip scans at a time for those that reach its rows: a bit each in
/// [`reaching`]'s word.
const SCAN_BLOCK: u32 = u64::BITS;

/// Draws `part`'s rows (its colour and depth) of every triangle of the draw from its
/// first on, first filling the colour rows with `clear` if given, with variant `V` on
/// lanes `L`; hands the lower part of its rows to a thread that asks for them
/// (`handover`) and goes on with the rest. Returns the rows' counters. The body of
/// every copy's [`TileCopy::strip`].
#[inline(always)]
pub(in crate::render) fn draw_strip<
    'd,
    V: DrawVariant,
    S: Shader,
    C: ColorTarget + SplitOff,
    L: I32s,
>(
    job: &Job<'_, S>,
    plan: &StripPlan<'_>,
    part: &mut Part<'d, C>,
    handover: &Handover<'d, C>,
    clear: Option<Vec3>,
) -> DrawStats {
    if let Some(background) = clear {
        let len = part.color.len();
        part.color.reset(len, background);
    }
    let mut stats = DrawStats::default();
    let (indices, projected, spans) = (job.indices, job.projected, plan.spans);
    let n = (indices.len() / 3) as u32;
    // One loop, left to hand rows over and entered again: the walk is inlined, and a
    // second call of it would be a second copy of the set-up and walk.
    loop {
        let [y0, y1] = part.rows();
        let mut walker = PieceWalker::<S, C, L, V, _>::new(
            job.shader,
            &mut part.depth,
            &mut part.color,
            &job.opts,
            job.target,
        );
        let mut asked = None;
        let mut block = part.first;
        'scan: while block < n {
            if handover.asked(part.worker, block) {
                asked = Some(block);
                break;
            }
            // The triangles of the next block that these rows draw or count, found in
            // a tight loop: the many that miss a strip then cost a few instructions
            // each and no mispredicted branch.
            let end = n.min(block + SCAN_BLOCK);
            let tris = &indices[block as usize * 3..end as usize * 3];
            let mut reach = reaching(spans, tris, [y0, y1]);
            let first = block;
            block = end;
            while reach != 0 {
                let t = first + reach.trailing_zeros();
                reach &= reach - 1;
                if handover.asked(part.worker, t) {
                    asked = Some(t);
                    break 'scan;
                }
                let base = t as usize * 3;
                let Some([top, _]) = box_rows(spans, &indices[base..base + 3]) else {
                    // A vertex out of range: rejected, counted by the rows from the top.
                    if y0 == 0 {
                        stats.triangles += 1;
                        stats.rejected += 1;
                    }
                    continue;
                };
                // The box reaches these rows, or its first row (clamped to the target)
                // is in them: its owner's. 1 for the owner, added to its counters
                // without a branch: a branch on it after the set-up made the compiler
                // copy the whole set-up and walk for each side.
                let owner = u64::from((y0..=y1).contains(&top));
                let mut cut = Cut {
                    walker: &mut walker,
                    rows: [y0, y1],
                };
                let (cache, target) = (job.cache, job.target);
                let outcome = prepare_projected(
                    cache,
                    Some(projected),
                    indices,
                    t,
                    target,
                    &job.opts,
                    &mut cut,
                );
                outcome.count(&mut stats, owner);
            }
        }
        stats.fragments += walker.stats.fragments;
        stats.shaded += walker.stats.shaded;
        let Some(next) = asked else {
            return stats;
        };
        handover.answer(part, next);
        part.first = next;
    }
}

/// Draws on the renderer's pool with copy `T`, a strip per thread: the one-step
/// form of `Renderer::draw_triangles`, with the same frame and counters.
///
/// # Safety
/// The CPU must have `T`'s instruction set (as [`crate::render::DrawCopy::choose`]
/// ensures).
pub(in crate::render) unsafe fn draw<T: TileCopy, S: Shader, C: ColorTarget>(
    r: &mut Renderer,
    shader: &S,
    cache: &VertexCache<S::Varying>,
    indices: &[u32],
    opts: &DrawOptions,
    color: &mut C,
) {
    let Some(pool) = r.pool.clone() else {
        unreachable!("a threaded draw without a pool");
    };
    let target = r.target;
    assert_eq!(
        color.len(),
        target.len(),
        "the colour target is not the frame's size"
    );
    let store = &mut r.projected;
    let projected = pool.install(|| projections(cache, target, store));
    let scratch = &mut r.scratch;
    vertex_spans(projected, target.height, &mut scratch.spans);
    let wanted = pool.current_num_threads().clamp(1, MAX_STRIPS);
    let (ends, count, draw) = place_strips(scratch, target.height, wanted);
    let ends = &ends[..count];
    let plan = StripPlan {
        spans: &scratch.spans,
    };
    let clear = r.pending_clear.take();
    let job = Job {
        shader,
        cache,
        projected,
        indices,
        opts: *opts,
        target,
        band_rows: 0,
    };
    let mut pixel_ends = [0; MAX_STRIPS];
    for (p, &e) in pixel_ends.iter_mut().zip(ends) {
        *p = e as usize * target.width as usize;
    }
    let mut parts: [Option<Part<'_, C::Rows<'_>>>; MAX_STRIPS] = Default::default();
    let mut colors = [const { None }; MAX_STRIPS];
    let mut k = 0;
    color.split_rows(&pixel_ends[..count], |c| {
        colors[k] = Some(c);
        k += 1;
    });
    let mut k = 0;
    r.depth.split_rows(ends, |depth| {
        parts[k] = colors[k].take().map(|color| Part {
            color,
            depth,
            first: 0,
            worker: k,
        });
        k += 1;
    });
    let handover = Handover::new(count, target.width as usize);
    // Strips run by rayon's join: one that no thread has taken when the calling
    // thread is done with its own (the others asleep) is drawn by the calling thread.
    // A thread done with its strip takes rows from one still drawing; one still
    // drawing when no rows can be had is waited for by spinning, briefly: put to
    // sleep, the calling thread would wake later than the strip ends.
    let (started, done) = (AtomicUsize::new(0), AtomicUsize::new(0));
    // When each strip ended, in nanoseconds from `begin` (at least 1).
    let ended = [const { AtomicU64::new(0) }; MAX_STRIPS];
    let begin = Instant::now();
    let stats = pool.install(|| {
        parts[..count]
            .par_iter_mut()
            .enumerate()
            .with_max_len(1)
            .map(|(i, part)| {
                let Some(part) = part.as_mut() else {
                    return DrawStats::default();
                };
                if i > 0 {
                    started.fetch_add(1, Ordering::AcqRel);
                }
                let start = Instant::now();
                let mut stats = {
                    let _drawing = handover.drawing(part);
                    // SAFETY: the caller's guarantee.
                    unsafe { T::strip(&job, &plan, part, &handover, clear) }
                };
                let end = u64::try_from(begin.elapsed().as_nanos()).unwrap_or(u64::MAX);
                ended[i].store(end.max(1), Ordering::Relaxed);
                let cut = |rows, next| handover_row(plan.spans, indices, rows, next);
                while let Some(mut given) = handover.take(i, cut) {
                    let _drawing = handover.drawing(&given);
                    // SAFETY: the caller's guarantee.
                    stats += unsafe { T::strip(&job, &plan, &mut given, &handover, None) };
                }
                if i > 0 {
                    done.fetch_add(1, Ordering::Release);
                } else {
                    let spin = start.elapsed().min(MAX_SPIN);
                    let start = Instant::now();
                    while done.load(Ordering::Acquire) < started.load(Ordering::Acquire)
                        && start.elapsed() < spin
                    {
                        std::hint::spin_loop();
                    }
                }
                stats
            })
            .reduce(DrawStats::default, |mut a, b| {
                a += b;
                a
            })
    });
    r.stats += stats;
    r.scratch.handovers += handover.given();
    let mut times = [0; MAX_STRIPS];
    for (t, e) in times.iter_mut().zip(&ended) {
        *t = e.load(Ordering::Relaxed);
    }
    correct_shares(&mut r.scratch, draw, wanted, &times[..count]);
}

/// Places the strips of the frame's next draw in strips, `wanted` of them, by the
/// vertices' rows in `scratch.spans` and the draw's shares; returns their ends, how
/// many there are and the draw's number in the frame.
fn place_strips(
    scratch: &mut Scratch,
    height: u32,
    wanted: usize,
) -> ([u32; MAX_STRIPS], usize, usize) {
    let draw = scratch.strip_draws;
    scratch.strip_draws += 1;
    let shares = *scratch.shares(draw);
    let (ends, count) = strip_ends(&scratch.spans, height, shares.of(wanted), &mut scratch.rows);
    (ends, count, draw)
}

/// Corrects draw `draw`'s shares by when its strips ended (`ended`, one per strip
/// drawn, of `wanted`).
fn correct_shares(scratch: &mut Scratch, draw: usize, wanted: usize, ended: &[u64]) {
    let shares = scratch.shares(draw);
    if ended.len() == wanted {
        shares.correct(ended);
    } else {
        // A strip was left without rows: start again from equal shares, so that shares
        // driven to the least (a strip whose thread kept starting late) cannot keep a
        // strip away for good.
        *shares = Shares::default();
    }
}

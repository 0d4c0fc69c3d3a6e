//! Rows handed over while the strips are drawn: a thread whose rows are done asks a
//! thread still drawing for the part of its rows that holds about half of its work
//! left, and the two go on from the next triangle.
//!
//! A strip's share is fixed for the draw, and the other core's speed wanders on a
//! shared machine, so strips rarely end together. A handover keeps the frame one
//! thread's: the thread drawing rows `y0..end` has drawn triangles up to `next` into
//! all of them when it cuts them at a block border `at`; it keeps `y0..at` and the
//! other thread draws triangles from `next` on into `at..end`. Every pixel still
//! gets its fragments in draw order, from one thread at a time, and the rows pass
//! with their colour and depth by a lock, which orders the first thread's writes
//! before the second's.
//!
//! Each thread of the draw has a mailbox whose state says whether it is drawing,
//! asked, or has answered. The drawing thread stores its progress and looks at its
//! state once per triangle (a line no one else writes until it asks); the asking
//! thread reads the progress and the rows to choose the cut (`handover_row`).
//! Everything else happens only when a thread runs out of rows.

use std::hint::spin_loop;
use std::sync::atomic::{AtomicU8, AtomicU32, Ordering};
use std::sync::{Mutex, PoisonError};

use super::MAX_STRIPS;
use crate::raster::depth::DepthRows;
use crate::render::target::SplitOff;

/// Rows are handed over in blocks of this many: the block walk's 8, a multiple of the
/// depth buffer's clear tile, so that two threads never share a block or a tile.
pub const HANDOVER_ROWS: u32 = 8;

/// Rows of the colour target and the depth buffer that one thread draws, from
/// triangle `first` on.
pub(in crate::render) struct Part<'d, C> {
    pub color: C,
    pub depth: DepthRows<'d>,
    /// The first triangle still to be drawn into these rows.
    pub first: u32,
    /// The mailbox of the thread drawing them.
    pub worker: usize,
}

impl<C> Part<'_, C> {
    /// The rows held: the first and the last.
    #[inline(always)]
    pub fn rows(&self) -> [u32; 2] {
        [self.depth.first_row(), self.depth.end().saturating_sub(1)]
    }
}

/// Neither drawing nor asked: before a thread's strip starts, and while it looks for
/// rows.
const IDLE: u8 = 0;
/// Drawing rows, and may be asked for some.
const DRAWING: u8 = 1;
/// Asked by another thread, which waits for the answer.
const ASKED: u8 = 2;
/// Answered: the rows given, or none, are in the slot until the asking thread takes
/// them and sets the state back to [`DRAWING`].
const ANSWERED: u8 = 3;

/// One thread's state and the rows it hands over. A cache line of its own, so that
/// looking at one's state never misses for another's.
#[repr(align(128))]
struct Mailbox<'d, C> {
    state: AtomicU8,
    /// The next triangle the thread draws.
    progress: AtomicU32,
    /// The rows it draws: the first, and the end (exclusive) times 2^16.
    rows: AtomicU32,
    /// Where the thread that asks would have the rows cut (0: in half).
    cut: AtomicU32,
    slot: Mutex<Option<Part<'d, C>>>,
}

/// The mailboxes of a draw's threads.
pub(in crate::render) struct Handover<'d, C> {
    boxes: [Mailbox<'d, C>; MAX_STRIPS],
    /// Threads taking part.
    count: usize,
    /// Pixels per row of the target.
    width: usize,
    /// Rows handed over so far.
    given: AtomicU32,
}

impl<'d, C: SplitOff> Handover<'d, C> {
    /// Mailboxes for `count` threads (at most [`MAX_STRIPS`]) drawing rows `width`
    /// pixels wide.
    pub fn new(count: usize, width: usize) -> Self {
        Self {
            boxes: std::array::from_fn(|_| Mailbox {
                state: AtomicU8::new(IDLE),
                progress: AtomicU32::new(0),
                rows: AtomicU32::new(0),
                cut: AtomicU32::new(0),
                slot: Mutex::new(None),
            }),
            count: count.min(MAX_STRIPS),
            width,
            given: AtomicU32::new(0),
        }
    }

    /// How many times rows were handed over.
    pub fn given(&self) -> u64 {
        u64::from(self.given.load(Ordering::Relaxed))
    }

    /// `part`'s thread starts drawing it: it may be asked for rows until the guard is
    /// dropped, which [`Handover::finish`]es, also when the drawing panics (so no
    /// thread waits for an answer that never comes).
    pub fn drawing(&self, part: &Part<'d, C>) -> Drawing<'_, 'd, C> {
        self.start(part);
        Drawing {
            handover: self,
            worker: part.worker,
        }
    }

    /// `part`'s thread starts drawing it.
    fn start(&self, part: &Part<'d, C>) {
        let mailbox = &self.boxes[part.worker];
        mailbox.progress.store(part.first, Ordering::Relaxed);
        self.publish_rows(part);
        mailbox.state.store(DRAWING, Ordering::Release);
    }

    /// Says which rows `part`'s thread draws, for a thread about to ask for some.
    fn publish_rows(&self, part: &Part<'d, C>) {
        let [first, last] = part.rows();
        let rows = first.min(0xffff) | (last + 1).min(0xffff) << 16;
        self.boxes[part.worker].rows.store(rows, Ordering::Relaxed);
    }

    /// Whether another thread asks `worker`, about to draw triangle `next`, for rows:
    /// looked at between triangles.
    #[inline(always)]
    pub fn asked(&self, worker: usize, next: u32) -> bool {
        let mailbox = &self.boxes[worker];
        mailbox.progress.store(next, Ordering::Relaxed);
        mailbox.state.load(Ordering::Relaxed) == ASKED
    }

    /// Answers the thread that asked: hands it `part`'s rows from the block border it
    /// asked for (or the one in their lower half) to draw from triangle `next` on, or
    /// nothing when `part` holds fewer than two blocks.
    #[cold]
    #[inline(never)]
    pub fn answer(&self, part: &mut Part<'d, C>, next: u32) {
        let [y0, end] = [part.depth.first_row(), part.depth.end()];
        let rows = end - y0;
        let mailbox = &self.boxes[part.worker];
        let asked = mailbox.cut.load(Ordering::Relaxed);
        let given = (rows >= 2 * HANDOVER_ROWS).then(|| {
            let at = if asked.is_multiple_of(HANDOVER_ROWS)
                && asked >= y0 + HANDOVER_ROWS
                && asked + HANDOVER_ROWS <= end
            {
                asked
            } else {
                y0 + rows / 2 / HANDOVER_ROWS * HANDOVER_ROWS
            };
            let depth = part.depth.split_off(at);
            let color = part.color.split_off((at - y0) as usize * self.width);
            Part {
                color,
                depth,
                first: next,
                worker: part.worker,
            }
        });
        if given.is_some() {
            self.given.fetch_add(1, Ordering::Relaxed);
            self.publish_rows(part);
        }
        *mailbox.slot.lock().unwrap_or_else(PoisonError::into_inner) = given;
        mailbox.state.store(ANSWERED, Ordering::Release);
    }

    /// Thread `worker` has drawn all its rows: it answers a thread that asked with
    /// nothing, and waits for one that was answered to take the answer.
    fn finish(&self, worker: usize) {
        let state = &self.boxes[worker].state;
        let mut spins = 0;
        loop {
            match state.compare_exchange(DRAWING, IDLE, Ordering::AcqRel, Ordering::Acquire) {
                Ok(_) | Err(IDLE) => return,
                Err(ASKED) => {
                    *self.boxes[worker]
                        .slot
                        .lock()
                        .unwrap_or_else(PoisonError::into_inner) = None;
                    state.store(ANSWERED, Ordering::Release);
                }
                Err(_) => wait(&mut spins),
            }
        }
    }

    /// Rows for thread `worker`, whose own are drawn: asks each other thread that is
    /// drawing in turn, until one hands some over; `None` when none is drawing or all
    /// that are hold too few rows. `cut` says where it would have the other's rows
    /// (first and end) cut, given the next triangle the other draws: where the work
    /// left there is halved. The rows are drawn under [`Handover::drawing`].
    pub fn take(&self, worker: usize, cut: impl Fn([u32; 2], u32) -> u32) -> Option<Part<'d, C>> {
        let mut declined = 0u32;
        loop {
            let mut busy = false;
            for k in 1..self.count {
                let other = (worker + k) % self.count;
                if declined & (1 << other) != 0 {
                    continue;
                }
                let mailbox = &self.boxes[other];
                let state = &mailbox.state;
                if state.load(Ordering::Acquire) == DRAWING {
                    let rows = mailbox.rows.load(Ordering::Relaxed);
                    let next = mailbox.progress.load(Ordering::Relaxed);
                    let at = cut([rows & 0xffff, rows >> 16], next);
                    mailbox.cut.store(at, Ordering::Relaxed);
                }
                match state.compare_exchange(DRAWING, ASKED, Ordering::AcqRel, Ordering::Relaxed) {
                    Ok(_) => {
                        let mut spins = 0;
                        while state.load(Ordering::Acquire) != ANSWERED {
                            wait(&mut spins);
                        }
                        let given = mailbox
                            .slot
                            .lock()
                            .unwrap_or_else(PoisonError::into_inner)
                            .take();
                        state.store(DRAWING, Ordering::Release);
                        match given {
                            Some(mut part) => {
                                part.worker = worker;
                                return Some(part);
                            }
                            None => declined |= 1 << other,
                        }
                    }
                    // Another thread is asking it: ask again once it is answered.
                    Err(ASKED | ANSWERED) => busy = true,
                    Err(_) => {}
                }
            }
            if !busy {
                return None;
            }
            spin_loop();
        }
    }
}

/// One round of waiting for another thread's answer, which comes within a triangle:
/// spinning at first, then yielding, in case the other thread waits for this one's
/// core.
fn wait(spins: &mut u32) {
    *spins += 1;
    if *spins < 1 << 12 {
        spin_loop();
    } else {
        std::thread::yield_now();
    }
}

/// A thread drawing rows ([`Handover::drawing`]).
pub(in crate::render) struct Drawing<'h, 'd, C: SplitOff> {
    handover: &'h Handover<'d, C>,
    worker: usize,
}

impl<C: SplitOff> Drop for Drawing<'_, '_, C> {
    fn drop(&mut self) {
        self.handover.finish(self.worker);
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicBool, Ordering};

    use super::{HANDOVER_ROWS, Handover, Part};
    use crate::raster::depth::DepthBuffer;
    use crate::render::Rgba8Rows;

    /// Draws "triangles" `first..n` into `part`'s rows, one pixel per row holding how
    /// many triangles reached it (each must find the count equal to its index: every
    /// row sees every triangle once, in order), handing rows over when asked. With
    /// `wait`, waits at triangle `n / 2` to be asked, so that rows change hands
    /// however the threads are scheduled.
    fn draw<'d, 'c>(
        part: &mut Part<'d, Rgba8Rows<'c>>,
        handover: &Handover<'d, Rgba8Rows<'c>>,
        n: u32,
        mut wait: bool,
    ) {
        let mut t = part.first;
        while t < n {
            if wait && t == n / 2 {
                while !handover.asked(part.worker, t) {
                    std::hint::spin_loop();
                }
                wait = false;
            }
            if handover.asked(part.worker, t) {
                handover.answer(part, t);
                part.first = t;
                continue;
            }
            for px in part.color.0.iter_mut() {
                let count = u32::from_le_bytes(*px);
                assert_eq!(count, t, "a row missed a triangle or saw one twice");
                *px = (count + 1).to_le_bytes();
            }
            t += 1;
        }
    }

    /// Threads that finish early take rows from those still drawing, until every row
    /// has seen every triangle once, in order, whoever drew it.
    #[test]
    fn handed_rows_see_every_triangle_once_in_order() {
        for threads in [2, 3, 4] {
            let rows = 8 * HANDOVER_ROWS * threads as u32 + 5;
            let n = 5_000;
            let mut color = vec![[0u8; 4]; rows as usize];
            let mut depth = DepthBuffer::new(1, rows);
            // Uneven strips: the first holds all rows but one block per other thread.
            let mut ends: Vec<u32> = (1..threads as u32)
                .map(|k| rows / 8 * 8 - (threads as u32 - k) * HANDOVER_ROWS)
                .collect();
            ends.push(rows);
            let mut parts = Vec::new();
            let mut colors = Vec::new();
            crate::render::target::split_slice(
                &mut color[..],
                &ends.iter().map(|&e| e as usize).collect::<Vec<_>>(),
                |c| colors.push(Rgba8Rows(c)),
            );
            let mut colors = colors.into_iter();
            depth.split_rows(&ends, |d| {
                let worker = parts.len();
                parts.push(Part {
                    color: colors.next().expect("a colour strip"),
                    depth: d,
                    first: 0,
                    worker,
                });
            });
            let handover = Handover::new(threads, 1);
            let started = AtomicBool::new(false);
            std::thread::scope(|s| {
                for mut part in parts {
                    let (handover, started) = (&handover, &started);
                    s.spawn(move || {
                        let worker = part.worker;
                        handover.start(&part);
                        if worker == 0 {
                            started.store(true, Ordering::Release);
                        } else {
                            // The first strip is drawing when the others ask.
                            while !started.load(Ordering::Acquire) {
                                std::hint::spin_loop();
                            }
                        }
                        draw(&mut part, handover, n, worker == 0);
                        handover.finish(worker);
                        // Cuts asked for anywhere, some of them not at a block border
                        // or leaving a side without a block: those are cut in half.
                        let cut = |[y0, end]: [u32; 2], next: u32| y0 + next % (end - y0 + 1);
                        while let Some(mut given) = handover.take(worker, cut) {
                            assert_eq!(given.worker, worker);
                            let _drawing = handover.drawing(&given);
                            draw(&mut given, handover, n, false);
                        }
                    });
                }
            });
            assert!(handover.given() > 0, "no rows handed over");
            for (row, px) in color.iter().enumerate() {
                assert_eq!(u32::from_le_bytes(*px), n, "row {row} of {threads} threads");
            }
        }
    }

    /// A part is cut where the thread that asked would have it if that is a block
    /// border leaving a block on each side, else at a block border in its lower half;
    /// one of fewer than two blocks is not cut: the thread that asked gets nothing.
    #[test]
    fn a_part_is_cut_in_whole_blocks_or_not_at_all() {
        for (y0, rows, ask, cut) in [
            (8, 40, 0, Some(24)),
            (8, 40, 40, Some(40)),
            (8, 40, 16, Some(16)),
            (8, 40, 44, Some(24)),
            (8, 40, 8, Some(24)),
            (8, 40, 48, Some(24)),
            (16, 16, 24, Some(24)),
            (0, 15, 8, None),
            (8, 23, 0, Some(16)),
        ] {
            let mut color = vec![[0u8; 4]; 3 * (y0 + rows) as usize];
            let mut depth = DepthBuffer::new(3, y0 + rows);
            let mut parts = Vec::new();
            let (_, rest) = color.split_at_mut(3 * y0 as usize);
            let mut rest = Some(Rgba8Rows(rest));
            depth.split_rows(&[y0, y0 + rows], |d| parts.push(d));
            let depth = parts.pop().expect("the rows");
            let mut part = Part {
                color: rest.take().expect("the colour"),
                depth,
                first: 5,
                worker: 1,
            };
            let handover: Handover<'_, Rgba8Rows<'_>> = Handover::new(2, 3);
            handover.start(&part);
            let asked = std::thread::scope(|s| {
                let thief = s.spawn(|| {
                    handover
                        .take(0, |seen, next| {
                            assert_eq!((seen, next), ([y0, y0 + rows], 5));
                            ask
                        })
                        .map(|p| (p.rows(), p.first, p.color.0.len(), p.worker))
                });
                while !handover.asked(1, 5) {
                    std::hint::spin_loop();
                }
                handover.answer(&mut part, 7);
                handover.finish(1);
                thief.join().expect("the thief")
            });
            match cut {
                Some(at) => {
                    assert_eq!(part.rows(), [y0, at - 1]);
                    assert_eq!(part.color.0.len(), 3 * (at - y0) as usize);
                    assert_eq!(
                        asked,
                        Some(([at, y0 + rows - 1], 7, 3 * (y0 + rows - at) as usize, 0))
                    );
                }
                None => {
                    assert_eq!(part.rows(), [y0, y0 + rows - 1]);
                    assert_eq!(asked, None);
                }
            }
        }
    }
}

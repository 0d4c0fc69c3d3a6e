//! The order bands are walked in, and the threads that walk them.

use std::sync::{Mutex, PoisonError};

use rayon::prelude::*;

use crate::render::options::DrawStats;

/// The most bands a draw walks costliest first ([`plan_bands`]): twelve per thread
/// for [`MAX_QUEUES`] threads, the most `band_rows` makes while its bands are under
/// 48 rows; more (a very tall target) go to rayon's work stealing top to bottom. The
/// bands are handed out from an array of this size on the stack, some 15 KB, so
/// ordering them allocates nothing.
pub(super) const MAX_ORDERED_BANDS: usize = 12 * MAX_QUEUES;

/// The most threads a draw hands bands to by [`Queues`]; with more, the bands go to
/// rayon's work stealing in top-to-bottom order.
const MAX_QUEUES: usize = 16;

/// Which band each thread walks next. Each thread has a home run of consecutive bands
/// (as many as the others), which it walks costliest first; a thread whose run is done
/// takes the costliest band left in the longest other run. The costly bands are thus
/// walked early and the cheap ones last, wherever they lie, so the threads finish
/// together (taking the cheapest instead left the owner a band of middle cost to end
/// on alone). The runs are cut by count rather than by cost, so they stay the same
/// from frame to frame (measured: a split by cost is slower on the teapot).
#[derive(Debug, PartialEq, Eq)]
pub(super) struct Queues {
    /// Per thread, the next and the end position of its run in the band order.
    front: [usize; MAX_QUEUES],
    back: [usize; MAX_QUEUES],
    threads: usize,
}

impl Queues {
    /// Runs of `bands` positions for `threads` threads (at most [`MAX_QUEUES`]).
    fn new(bands: usize, threads: usize) -> Self {
        let mut q = Queues {
            front: [0; MAX_QUEUES],
            back: [0; MAX_QUEUES],
            threads,
        };
        for t in 0..threads {
            q.front[t] = bands * t / threads;
            q.back[t] = bands * (t + 1) / threads;
        }
        q
    }

    /// The position in the band order of the next band for the thread at `home`.
    fn take(&mut self, home: usize) -> Option<usize> {
        if self.front[home] < self.back[home] {
            self.front[home] += 1;
            return Some(self.front[home] - 1);
        }
        let other = (0..self.threads).max_by_key(|&t| self.back[t] - self.front[t])?;
        if self.front[other] == self.back[other] {
            return None;
        }
        self.front[other] += 1;
        Some(self.front[other] - 1)
    }
}

/// The order of [`Queues`] into `order` for bands of estimated `cost`: each run
/// costliest first. `None` when the draw has too many bands or threads to be handed
/// out this way ([`MAX_ORDERED_BANDS`], [`MAX_QUEUES`]).
pub(super) fn plan_bands(order: &mut [u32], cost: &[u64], threads: usize) -> Option<Queues> {
    if order.len() > MAX_ORDERED_BANDS || !(1..=MAX_QUEUES).contains(&threads) {
        return None;
    }
    for (b, o) in order.iter_mut().enumerate() {
        *o = b as u32;
    }
    let q = Queues::new(order.len(), threads);
    for t in 0..threads {
        // Unstable: it sorts in place, without a buffer; ties keep no particular
        // order, and the order changes only which thread walks a band, never the frame.
        order[q.front[t]..q.back[t]].sort_unstable_by_key(|&b| std::cmp::Reverse(cost[b as usize]));
    }
    Some(q)
}

/// Walks every band of `bands` with `walk`, the threads taking them from `queues` in
/// `order`; returns the walks' counters summed.
pub(super) fn walk_in_order<R: Send, W>(
    bands: impl IndexedParallelIterator<Item = R>,
    queues: Queues,
    order: &[u32],
    walk: &W,
) -> DrawStats
where
    W: Fn(usize, R) -> DrawStats + Sync,
{
    // The bands' disjoint rows, each handed out once from its slot: an array on the
    // stack, so ordering the bands allocates nothing.
    let slots: [Mutex<Option<R>>; MAX_ORDERED_BANDS] = std::array::from_fn(|_| Mutex::new(None));
    // On this thread alone: a split would wake another for nothing.
    bands
        .with_min_len(usize::MAX)
        .enumerate()
        .for_each(|(b, rows)| *lock(&slots[b]) = Some(rows));
    let threads = queues.threads;
    let queues = Mutex::new(queues);
    let worker = |home: usize| {
        let mut stats = DrawStats::default();
        loop {
            let Some(i) = lock(&queues).take(home) else {
                return stats;
            };
            let b = order[i] as usize;
            let Some(rows) = lock(&slots[b]).take() else {
                unreachable!("band {b} handed out twice");
            };
            stats += walk(b, rows);
        }
    };
    fan_out(0, threads, &worker)
}

/// A lock that a panic elsewhere does not poison for good (the panic propagates
/// through the join anyway).
pub(super) fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Runs `worker(t)` for every `t` in `first..threads` on threads of the current pool
/// at once (by nested joins, which allocate nothing) and sums what they return.
fn fan_out<F: Fn(usize) -> DrawStats + Sync>(
    first: usize,
    threads: usize,
    worker: &F,
) -> DrawStats {
    if first + 1 >= threads {
        return worker(first);
    }
    let (mut a, b) = rayon::join(|| worker(first), || fan_out(first + 1, threads, worker));
    a += b;
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every band is handed out exactly once, whoever asks: a thread first walks its
    /// own run in order, then takes from the front of the longest other run.
    #[test]
    fn every_band_is_handed_out_once() {
        for bands in 0..40 {
            for threads in 1..=5 {
                // Thread `home` asks in a fixed rotation, some never at all.
                for pattern in 0..threads {
                    let mut q = Queues::new(bands, threads);
                    let mut seen = vec![0; bands];
                    let mut k = 0;
                    while let Some(i) = q.take((k * (pattern + 1)) % threads) {
                        seen[i] += 1;
                        k += 1;
                    }
                    assert!(seen.iter().all(|&n| n == 1), "{bands} {threads} {pattern}");
                }
            }
        }
    }

    #[test]
    fn a_thread_walks_its_run_then_the_costliest_of_the_longest_other() {
        let mut q = Queues::new(10, 2);
        assert_eq!(
            (q.front[0], q.back[0], q.front[1], q.back[1]),
            (0, 5, 5, 10)
        );
        assert_eq!(
            (0..5).map(|_| q.take(0)).collect::<Vec<_>>(),
            [0, 1, 2, 3, 4].map(Some)
        );
        assert_eq!(q.take(1), Some(5));
        // Thread 0's run is done: it takes run 1's next (costliest left) position.
        assert_eq!(q.take(0), Some(6));
        assert_eq!(q.take(1), Some(7));
        assert_eq!(q.take(0), Some(8));
        assert_eq!(q.take(1), Some(9));
        assert_eq!((q.take(0), q.take(1)), (None, None));
        // With three runs, a thread done with its own takes from the longest other.
        let mut q = Queues::new(9, 3);
        assert_eq!(
            (0..3).map(|_| q.take(0)).collect::<Vec<_>>(),
            [0, 1, 2].map(Some)
        );
        assert_eq!(q.take(2), Some(6));
        assert_eq!(q.take(0), Some(3), "run 1 is the longest left");
        assert_eq!(
            q.take(0),
            Some(7),
            "runs 1 and 2 are as long: the later one"
        );
    }

    #[test]
    fn runs_are_ordered_costliest_first() {
        let cost = [5, 0, 9, 9, 1, 7, 3, 8];
        let mut order = [0; 8];
        let q = plan_bands(&mut order, &cost, 2).expect("few bands");
        // Runs 0..4 and 4..8, each sorted by descending cost; ties in any order.
        let mut first = order[..4].to_vec();
        assert!(first[..2] == [2, 3] || first[..2] == [3, 2], "{order:?}");
        first.sort_unstable();
        assert_eq!(first, [0, 1, 2, 3]);
        assert_eq!(order[2..4], [0, 1]);
        assert_eq!(order[4..], [7, 5, 6, 4]);
        assert_eq!(q, Queues::new(8, 2));
        assert!(
            plan_bands(
                &mut [0; MAX_ORDERED_BANDS + 1],
                &[0; MAX_ORDERED_BANDS + 1],
                2
            )
            .is_none()
        );
        assert!(plan_bands(&mut order, &cost, MAX_QUEUES + 1).is_none());
    }
}

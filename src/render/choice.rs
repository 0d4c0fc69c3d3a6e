//! Whether a paced frame is drawn on the renderer's threads or on the calling thread
//! alone, by how long recent frames took each way.
//!
//! A loop that draws a frame now and then (the viewer, 30 times a second) leaves the
//! threads idle between frames. On a virtual machine a frame drawn after such a pause
//! runs much slower on two threads than back to back, slower even than on one thread
//! for a mid-sized mesh (`bench render --pause-ms`, `docs/performance.md`). Both ways
//! draw the same frame, bit for bit, so such a loop times both and keeps the faster.
//! Each way is measured first, the pool first; then the faster draws, and every
//! [`PROBE_EVERY`] frames the other is tried again for [`PROBE_FRAMES`]. The first
//! frame of a run of frames drawn one way is not counted: it pays for the change (a
//! pool that has been idle, buffers made the first time).

use std::time::Duration;

/// Frames remembered per way; their median is the way's time.
const KEPT: usize = 5;

/// Frames each way must have counted before the two are compared.
pub const MIN_TIMES: usize = 3;

/// Frames the chosen way draws between two tries of the other.
pub const PROBE_EVERY: u32 = 90;

/// Frames a try of the other way draws: one not counted, then [`MIN_TIMES`], so the
/// way's median is then all of the try's.
pub const PROBE_FRAMES: u32 = MIN_TIMES as u32 + 1;

/// The other way is taken when its time is below this fraction of the chosen way's:
/// two ways that take about as long do not swap back and forth on noise.
const SWITCH_BELOW: f64 = 0.95;

/// The last [`KEPT`] times of one way, in seconds.
#[derive(Clone, Copy, Debug, Default)]
struct Times {
    secs: [f64; KEPT],
    /// How many are held (at most [`KEPT`]).
    len: usize,
    /// Where the next goes.
    next: usize,
}

impl Times {
    fn push(&mut self, took: Duration) {
        self.secs[self.next] = took.as_secs_f64();
        self.next = (self.next + 1) % KEPT;
        self.len = (self.len + 1).min(KEPT);
    }

    /// The median, once [`MIN_TIMES`] are held.
    fn median(&self) -> Option<f64> {
        if self.len < MIN_TIMES {
            return None;
        }
        let mut held = self.secs;
        let held = &mut held[..self.len];
        held.sort_by(f64::total_cmp);
        Some(held[self.len / 2])
    }
}

/// The measured choice between the pool and the calling thread, for frames of one
/// amount and kind of work ([`crate::render::Renderer::plan_frame`]): another amount
/// (another mesh, target size or sampling) or kind (edges drawn instead of triangles,
/// back faces culled) starts the measuring again, as its times say nothing of it.
#[derive(Clone, Debug, Default)]
pub struct FrameChoice {
    /// The work the times are for, and its kind.
    work: u64,
    kind: u64,
    /// Times on the calling thread ([0]) and on the pool ([1]).
    times: [Times; 2],
    /// The way chosen so far: on the pool.
    pooled: bool,
    /// Frames drawn the chosen way since the other was last tried.
    since_probe: u32,
    /// Frames left in the current try of the other way.
    probe_left: u32,
    /// The way the last frame went.
    last: Option<bool>,
    /// The way the frame being drawn was given, and whether its time counts.
    drawing: Option<(bool, bool)>,
}

impl FrameChoice {
    /// Whether the coming frame, of `work` of kind `kind`, goes to the pool.
    pub fn pooled(&mut self, work: u64, kind: u64) -> bool {
        if !similar(work, self.work) || kind != self.kind {
            *self = Self {
                work,
                kind,
                pooled: true,
                ..Self::default()
            };
        }
        let way = if self.times[1].len < MIN_TIMES {
            true
        } else if self.times[0].len < MIN_TIMES {
            false
        } else if self.probe_left > 0 {
            self.probe_left -= 1;
            !self.pooled
        } else if self.since_probe >= PROBE_EVERY {
            self.since_probe = 0;
            self.probe_left = PROBE_FRAMES - 1;
            !self.pooled
        } else {
            self.since_probe += 1;
            self.pooled
        };
        let counts = self.last == Some(way);
        self.last = Some(way);
        self.drawing = Some((way, counts));
        way
    }

    /// Records how long the frame given a way by [`FrameChoice::pooled`] took, and
    /// takes the other way from the next frame on if it is now clearly faster. A time
    /// with no way given (a frame too small for the pool) is ignored, and so is the
    /// first frame of a run drawn one way.
    pub fn took(&mut self, took: Duration) {
        let Some((way, counts)) = self.drawing.take() else {
            return;
        };
        if !counts {
            return;
        }
        self.times[usize::from(way)].push(took);
        if let (Some(one), Some(pool)) = (self.times[0].median(), self.times[1].median()) {
            let (chosen, other) = if self.pooled {
                (pool, one)
            } else {
                (one, pool)
            };
            if other < chosen * SWITCH_BELOW {
                self.pooled = !self.pooled;
                self.since_probe = 0;
                self.probe_left = 0;
            }
        }
    }
}

/// Whether two amounts of work are within an eighth of each other.
fn similar(a: u64, b: u64) -> bool {
    a.abs_diff(b) <= a.max(b) / 8 && (a > 0) == (b > 0)
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::{FrameChoice, MIN_TIMES, PROBE_EVERY, PROBE_FRAMES};

    /// Frames of the first measuring: each way one not counted and `MIN_TIMES`.
    const FIRST: u32 = 2 * PROBE_FRAMES;

    /// A run of the chosen way and a try of the other.
    const CYCLE: u32 = PROBE_EVERY + PROBE_FRAMES;

    /// Draws `frames` frames of `work`; `time(way, n)` is the time of the `n`th frame
    /// in a row drawn that way (from 0). Returns how many went to the pool.
    fn run_with(
        c: &mut FrameChoice,
        work: u64,
        frames: u32,
        time: impl Fn(bool, u32) -> f64,
    ) -> u32 {
        let (mut pooled, mut row, mut last) = (0, 0, None);
        for _ in 0..frames {
            let way = c.pooled(work, 0);
            row = if last == Some(way) { row + 1 } else { 0 };
            last = Some(way);
            pooled += u32::from(way);
            c.took(Duration::from_secs_f64(time(way, row) / 1e3));
        }
        pooled
    }

    /// [`run_with`] with steady times, `pool` and `one` ms.
    fn run(c: &mut FrameChoice, work: u64, frames: u32, pool: f64, one: f64) -> u32 {
        run_with(c, work, frames, |way, _| if way { pool } else { one })
    }

    /// Each way is measured first (the pool first), then the faster draws, with the
    /// other tried for `PROBE_FRAMES` every `PROBE_EVERY` frames.
    #[test]
    fn measures_both_ways_then_keeps_the_faster() {
        let mut c = FrameChoice::default();
        let first: Vec<bool> = (0..FIRST)
            .map(|_| {
                let way = c.pooled(100, 0);
                c.took(Duration::from_millis(if way { 8 } else { 5 }));
                way
            })
            .collect();
        let pool_then_one: Vec<bool> = (0..FIRST).map(|n| n < PROBE_FRAMES).collect();
        assert_eq!(first, pool_then_one);
        assert_eq!(c.times.map(|t| t.len), [MIN_TIMES; 2]);
        // The calling thread (5 ms) beats the pool (8 ms): the pool only in tries.
        assert_eq!(run(&mut c, 100, 10 * CYCLE, 8.0, 5.0), 10 * PROBE_FRAMES);
        // Where the pool is faster, it keeps the frames but the first measuring of the
        // calling thread and its tries.
        let mut c = FrameChoice::default();
        let frames = FIRST + 10 * CYCLE;
        let pooled = run(&mut c, 100, frames, 3.0, 5.0);
        assert_eq!(pooled, frames - PROBE_FRAMES - 10 * PROBE_FRAMES);
    }

    /// The first frame of each run drawn one way is not counted: a pool that is slow
    /// for one frame after a pause still wins on its steady times.
    #[test]
    fn the_first_frame_of_a_run_does_not_count() {
        let mut c = FrameChoice::default();
        let time = |way: bool, row: u32| match (way, row) {
            (true, 0) => 50.0,
            (true, _) => 3.0,
            (false, _) => 5.0,
        };
        let frames = FIRST + 3 * CYCLE;
        let pooled = run_with(&mut c, 100, frames, time);
        assert!(c.pooled);
        assert_eq!(pooled, frames - 4 * PROBE_FRAMES);
    }

    /// A change in conditions (the pool getting faster) turns the choice at the next
    /// try; times within a twentieth of each other do not.
    #[test]
    fn tries_follow_a_change_but_not_noise() {
        let mut c = FrameChoice::default();
        run(&mut c, 100, FIRST + CYCLE, 8.0, 5.0);
        assert!(!c.pooled);
        run(&mut c, 100, CYCLE, 3.0, 5.0);
        assert!(c.pooled, "the pool's faster try should have won");
        // Within a twentieth: whichever is chosen stays.
        for (pool, one) in [(5.2, 5.0), (5.0, 5.2)] {
            let mut c = FrameChoice::default();
            run(&mut c, 100, FIRST + 3 * CYCLE, pool, one);
            assert!(c.pooled, "{pool} {one}");
        }
    }

    /// Another amount or kind of work starts over; a little more or less (within an
    /// eighth) does not. A time with no frame given a way changes nothing.
    #[test]
    fn other_work_measures_again() {
        let mut c = FrameChoice::default();
        run(&mut c, 1000, FIRST + 10, 8.0, 5.0);
        assert!(!c.pooled);
        assert!(!c.pooled(1100, 0), "within an eighth: the same choice");
        c.took(Duration::from_millis(5));
        assert!(
            c.pooled(2000, 0),
            "another mesh or size: measured again, pool first"
        );
        c.took(Duration::from_millis(8));
        assert_eq!(
            c.times.map(|t| t.len),
            [0, 0],
            "a first frame does not count"
        );
        assert!(c.pooled(2000, 0));
        c.took(Duration::from_millis(8));
        assert_eq!(c.times.map(|t| t.len), [0, 1]);
        c.took(Duration::from_millis(1));
        assert_eq!(c.times.map(|t| t.len), [0, 1], "a time without a frame");
        // Another kind of the same work (edges for triangles) starts over too.
        run(&mut c, 2000, FIRST + 10, 8.0, 5.0);
        assert!(!c.pooled);
        assert!(!c.pooled(2000, 0));
        c.took(Duration::from_millis(5));
        assert!(
            c.pooled(2000, 1),
            "another kind: measured again, pool first"
        );
        assert_eq!(c.times.map(|t| t.len), [0, 0]);
        c.took(Duration::from_millis(8));
        // A frame of no work and one of some are not alike.
        assert!(!super::similar(0, 3));
        assert!(super::similar(0, 0));
    }

    /// A renderer given another thread count measures both ways again: its times
    /// were for the old pool.
    #[test]
    fn a_new_thread_count_measures_afresh() {
        use crate::raster::Target;
        use crate::render::Renderer;

        let mut r = Renderer::new(Target::new(64, 64));
        r.set_threads(2);
        r.min_threaded_work = 0;
        r.set_measured(true);
        let frame = |r: &mut Renderer| {
            r.plan_frame(100, 0);
            let pooled = r.pool().is_some();
            // The calling thread much faster.
            r.frame_took(Duration::from_millis(if pooled { 8 } else { 1 }));
            pooled
        };
        for _ in 0..FIRST {
            frame(&mut r);
        }
        assert!(!frame(&mut r), "the calling thread chosen");
        r.set_threads(3);
        let again: Vec<bool> = (0..FIRST).map(|_| frame(&mut r)).collect();
        let pool_then_one: Vec<bool> = (0..FIRST).map(|n| n < PROBE_FRAMES).collect();
        assert_eq!(again, pool_then_one);
    }
}

//! Whether a paced frame is drawn on the renderer's threads or on the calling thread
//! alone, by how long recent frames took each way.
//!
//! A loop that draws a frame now and then (the viewer, 30 times a second) leaves the
//! threads idle between frames. On a virtual machine a frame drawn after such a pause
//! runs much slower on two threads than back to back, slower even than on one thread
//! for a mid-sized mesh (`bench render --pause-ms`, `docs/performance.md`). Both ways
//! draw the same frame, bit for bit, so such a loop times both and keeps the faster:
//! each way first draws [`MIN_TIMES`] frames, then the chosen way draws the frames and
//! the other is tried again once every [`PROBE_EVERY`].

use std::time::Duration;

/// Frames remembered per way; their median is the way's time.
const KEPT: usize = 5;

/// Frames each way draws before the two are compared.
pub const MIN_TIMES: usize = 3;

/// Frames the chosen way draws between two tries of the other.
pub const PROBE_EVERY: u32 = 64;

/// The other way is taken when its time is below this fraction of the chosen way's:
/// two ways that take about as long do not swap back and forth on noise.
const SWITCH_BELOW: f64 = 0.9;

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
/// amount of work ([`crate::render::Renderer::plan_frame`]): another amount (another
/// mesh, target size or sampling) starts the measuring again.
#[derive(Clone, Debug, Default)]
pub struct FrameChoice {
    /// The work the times are for.
    work: u64,
    /// Times on the calling thread ([0]) and on the pool ([1]).
    times: [Times; 2],
    /// The way chosen so far: on the pool.
    pooled: bool,
    /// Frames drawn the chosen way since the other was last tried.
    since_probe: u32,
    /// The way the frame being drawn was given, until its time comes.
    drawing: Option<bool>,
}

impl FrameChoice {
    /// Whether the coming frame, of `work`, goes to the pool.
    pub fn pooled(&mut self, work: u64) -> bool {
        if !similar(work, self.work) {
            *self = Self {
                work,
                pooled: true,
                ..Self::default()
            };
        }
        let way = if self.times[1].len < MIN_TIMES {
            true
        } else if self.times[0].len < MIN_TIMES {
            false
        } else if self.since_probe >= PROBE_EVERY {
            self.since_probe = 0;
            !self.pooled
        } else {
            self.since_probe += 1;
            self.pooled
        };
        self.drawing = Some(way);
        way
    }

    /// Records how long the frame given a way by [`FrameChoice::pooled`] took, and
    /// takes the other way from the next frame on if it is now clearly faster. A time
    /// with no way given (a frame too small for the pool) is ignored.
    pub fn took(&mut self, took: Duration) {
        let Some(way) = self.drawing.take() else {
            return;
        };
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

    use super::{FrameChoice, MIN_TIMES, PROBE_EVERY};

    /// Draws `frames` frames of `work` whose times are `pool` and `one` ms; returns
    /// how many went to the pool.
    fn run(c: &mut FrameChoice, work: u64, frames: u32, pool: f64, one: f64) -> u32 {
        let mut pooled = 0;
        for _ in 0..frames {
            let way = c.pooled(work);
            pooled += u32::from(way);
            c.took(Duration::from_secs_f64(if way { pool } else { one } / 1e3));
        }
        pooled
    }

    /// Each way is measured first (the pool first), then the faster draws, with the
    /// other tried once every `PROBE_EVERY` frames.
    #[test]
    fn measures_both_ways_then_keeps_the_faster() {
        let mut c = FrameChoice::default();
        let first: Vec<bool> = (0..2 * MIN_TIMES)
            .map(|_| {
                let way = c.pooled(100);
                c.took(Duration::from_millis(if way { 8 } else { 5 }));
                way
            })
            .collect();
        assert_eq!(first, [true, true, true, false, false, false]);
        // The calling thread (5 ms) beats the pool (8 ms): the pool only as a probe.
        let frames = 10 * (PROBE_EVERY + 1);
        assert_eq!(run(&mut c, 100, frames, 8.0, 5.0), 10);
        // Where the pool is faster, it keeps the frames but the first calling-thread
        // ones and a probe in every `PROBE_EVERY + 1` after them.
        let mut c = FrameChoice::default();
        let probes = (frames - 2 * MIN_TIMES as u32) / (PROBE_EVERY + 1);
        assert_eq!(
            run(&mut c, 100, frames, 3.0, 5.0),
            frames - MIN_TIMES as u32 - probes
        );
    }

    /// A change in conditions (the pool getting faster) shows in the probes and turns
    /// the choice within a few of them; times within a tenth of each other do not.
    #[test]
    fn probes_follow_a_change_but_not_noise() {
        let mut c = FrameChoice::default();
        run(&mut c, 100, 100, 8.0, 5.0);
        assert!(!c.pooled);
        run(&mut c, 100, 4 * (PROBE_EVERY + 1), 3.0, 5.0);
        assert!(c.pooled, "the pool's faster probes should have won");
        // Within a tenth: whichever is chosen stays.
        let mut c = FrameChoice::default();
        run(&mut c, 100, 300, 5.2, 5.0);
        assert!(c.pooled);
        let mut c = FrameChoice::default();
        run(&mut c, 100, 300, 5.0, 5.2);
        assert!(c.pooled);
    }

    /// Another amount of work starts over; a little more or less (within an eighth)
    /// does not. A time with no frame given a way changes nothing.
    #[test]
    fn other_work_measures_again() {
        let mut c = FrameChoice::default();
        run(&mut c, 1000, 100, 8.0, 5.0);
        assert!(!c.pooled);
        assert!(!c.pooled(1100), "within an eighth: the same choice");
        c.took(Duration::from_millis(5));
        assert!(
            c.pooled(2000),
            "another mesh or size: measured again, pool first"
        );
        c.took(Duration::from_millis(8));
        assert_eq!(c.times[1].len, 1);
        assert_eq!(c.times[0].len, 0);
        c.took(Duration::from_millis(1));
        assert_eq!(c.times[1].len, 1, "a time without a frame is ignored");
        // A frame of no work and one of some are not alike.
        assert!(!super::similar(0, 3));
        assert!(super::similar(0, 0));
    }
}

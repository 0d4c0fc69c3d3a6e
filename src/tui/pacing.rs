//! Frames paced by the terminal's answers, so a slow link never queues more than a
//! frame or two.
//!
//! After each frame the viewer asks the terminal for its Primary Device Attributes
//! (`CSI c`); the terminal answers when it has read everything before the query, so an
//! answer means the frames before it have arrived. The next frame is sent only while
//! fewer than [`MAX_IN_FLIGHT`] frames are unanswered: the frame rate follows what the
//! link and the terminal take, and a key's effect waits behind at most that many
//! frames, whatever the buffers on the way. A terminal that has never answered after
//! [`FIRST_ANSWER_WAIT`] is taken not to answer at all, and frames go unpaced; one
//! that stops answering for [`LOST_ANSWER_WAIT`] is taken to have lost the answers.
//!
//! While the link is what holds frames back (a frame is sent before the answer to the
//! one ahead of it arrives), the time between two answers is the time the link took
//! to carry the later frame: that gives the link's rate, whatever its round trip. A
//! frame is then given a byte budget of [`FRAME_TIME`] at that rate
//! ([`Pacer::budget`]), so that a key's effect never waits behind more than a few
//! tenths of a second of frames, however slow the link.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// Frames that may be on their way to the terminal, unanswered.
pub const MAX_IN_FLIGHT: usize = 2;
/// How long the first answer may take before the terminal is taken not to answer.
pub const FIRST_ANSWER_WAIT: Duration = Duration::from_secs(2);
/// The query sent after each frame.
pub const QUERY: &[u8] = b"\x1b[c";
/// How long unanswered queries are waited for once the terminal has answered before;
/// then they are taken as lost (a multiplexer that swallowed them, say) and forgotten.
pub const LOST_ANSWER_WAIT: Duration = Duration::from_secs(5);
/// The link time a frame may take while the link is the bottleneck.
pub const FRAME_TIME: Duration = Duration::from_millis(60);
/// The smallest budget: enough for the status line and some of the model.
pub const MIN_BUDGET: usize = 2048;
/// The window over which delivered frames and bytes are counted.
const WINDOW: Duration = Duration::from_secs(2);
/// How long a measured link rate stays in force without a new measurement.
const RATE_HOLD: Duration = Duration::from_secs(3);

/// Pacing state.
#[derive(Debug)]
pub struct Pacer {
    /// When each unanswered query was sent and the bytes of its frame, oldest first.
    in_flight: VecDeque<(Instant, u64)>,
    /// When the last answer came.
    last_answer: Option<Instant>,
    /// The link's rate (bytes per second) while it held frames back, and when it was
    /// last measured.
    link_rate: Option<(f64, Instant)>,
    answered_any: bool,
    /// Whether frames are paced at all (queries are sent).
    paced: bool,
    /// The terminal did not answer: frames are not paced.
    pub unpaced: bool,
    /// Round trip of the last answer.
    pub rtt: Option<Duration>,
    /// Answers (delivered frames) and bytes sent in the recent window, with times.
    delivered: VecDeque<Instant>,
    sent: VecDeque<(Instant, u64)>,
    /// Output rate cap in bytes per second, and when the cap next allows a frame.
    pub max_rate: Option<u64>,
    rate_free_at: Option<Instant>,
}

impl Pacer {
    /// A pacer; `paced: false` never waits for answers.
    #[must_use]
    pub fn new(paced: bool, max_rate: Option<u64>) -> Self {
        Self {
            in_flight: VecDeque::with_capacity(MAX_IN_FLIGHT + 1),
            last_answer: None,
            link_rate: None,
            answered_any: false,
            paced,
            unpaced: !paced,
            rtt: None,
            delivered: VecDeque::with_capacity(256),
            sent: VecDeque::with_capacity(256),
            max_rate,
            rate_free_at: None,
        }
    }

    /// Whether the next frame may be sent now.
    pub fn may_send(&mut self, now: Instant) -> bool {
        self.check_answering(now);
        let link = self.unpaced || self.in_flight.len() < MAX_IN_FLIGHT;
        link && self.rate_free_at.is_none_or(|t| now >= t)
    }

    /// Gives up on answers if the first has not come in time, and forgets queries
    /// unanswered for so long that their answers must have been lost.
    fn check_answering(&mut self, now: Instant) {
        let oldest = self.in_flight.front().map(|q| now.duration_since(q.0));
        if !self.answered_any && !self.unpaced && oldest.is_some_and(|d| d >= FIRST_ANSWER_WAIT) {
            self.unpaced = true;
        }
        if self.answered_any && oldest.is_some_and(|d| d >= LOST_ANSWER_WAIT) {
            self.in_flight.clear();
        }
    }

    /// When waiting on the pacer could end by itself (the first answer's wait, a lost
    /// answer's, or the rate cap), if it is what holds the next frame.
    #[must_use]
    pub fn wake_at(&self) -> Option<Instant> {
        let answer = self.in_flight.front().and_then(|q| {
            if !self.answered_any && !self.unpaced {
                Some(q.0 + FIRST_ANSWER_WAIT)
            } else if self.answered_any && self.in_flight.len() >= MAX_IN_FLIGHT {
                Some(q.0 + LOST_ANSWER_WAIT)
            } else {
                None
            }
        });
        match (answer, self.rate_free_at) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// The link's rate in bytes per second, measured while it held frames back
    /// (recently: a link that keeps up has none).
    #[must_use]
    pub fn link_rate(&self, now: Instant) -> Option<f64> {
        self.link_rate
            .filter(|&(_, at)| now.duration_since(at) <= RATE_HOLD)
            .map(|(r, _)| r)
    }

    /// The bytes the next frame may take: [`FRAME_TIME`] at the link's rate while the
    /// link holds frames back, else no limit.
    #[must_use]
    pub fn budget(&self, now: Instant) -> Option<usize> {
        if self.unpaced {
            return None;
        }
        let rate = self.link_rate(now)?;
        Some(((rate * FRAME_TIME.as_secs_f64()) as usize).max(MIN_BUDGET))
    }

    /// Whether a query should follow the frame just written.
    #[must_use]
    pub fn wants_query(&self) -> bool {
        self.paced
    }

    /// A frame of `bytes` (its query included) was written at `now`.
    pub fn sent(&mut self, now: Instant, bytes: u64) {
        if self.paced {
            // Unpaced after no answer, queries still go out (bounded), so a terminal
            // that was only slow to answer the first brings pacing back.
            self.in_flight.push_back((now, bytes));
            if self.in_flight.len() > MAX_IN_FLIGHT + 1 {
                self.in_flight.pop_front();
            }
        }
        if let Some(rate) = self.max_rate.filter(|&r| r > 0) {
            let secs = bytes as f64 / rate as f64;
            self.rate_free_at = Some(now + Duration::from_secs_f64(secs.min(60.0)));
        }
        self.sent.push_back((now, bytes));
        Self::trim(&mut self.sent, now, |s| s.0);
    }

    /// The terminal answered a query at `now`.
    pub fn answered(&mut self, now: Instant) {
        if let Some((t, bytes)) = self.in_flight.pop_front() {
            self.answered_any = true;
            self.unpaced = false;
            self.rtt = Some(now.duration_since(t));
            // Sent before the answer ahead of it came: it waited for the link, which
            // then carried it in the time since that answer.
            if let Some(prev) = self.last_answer.filter(|&a| t < a) {
                let secs = now.duration_since(prev).as_secs_f64().max(1e-3);
                let sample = bytes as f64 / secs;
                let rate = match self.link_rate(now) {
                    Some(r) => 0.7 * r + 0.3 * sample,
                    None => sample,
                };
                self.link_rate = Some((rate, now));
            }
            self.last_answer = Some(now);
            self.delivered.push_back(now);
            Self::trim(&mut self.delivered, now, |&t| t);
        }
    }

    /// Queries not answered yet.
    #[must_use]
    pub fn in_flight(&self) -> usize {
        if self.unpaced {
            0
        } else {
            self.in_flight.len()
        }
    }

    /// Forgets unanswered queries (after the terminal was reset, e.g. on resume).
    pub fn reset(&mut self) {
        self.in_flight.clear();
        self.last_answer = None;
    }

    fn trim<T>(q: &mut VecDeque<T>, now: Instant, time: impl Fn(&T) -> Instant) {
        while q
            .front()
            .is_some_and(|x| now.duration_since(time(x)) > WINDOW)
        {
            q.pop_front();
        }
    }

    /// Frames the terminal confirmed per second, over the recent window.
    #[must_use]
    pub fn delivered_fps(&self, now: Instant) -> f32 {
        let n = self
            .delivered
            .iter()
            .filter(|&&t| now.duration_since(t) <= WINDOW)
            .count();
        n as f32 / WINDOW.as_secs_f32()
    }

    /// Bytes sent per second, over the recent window.
    #[must_use]
    pub fn bytes_per_second(&self, now: Instant) -> f64 {
        let n: u64 = self
            .sent
            .iter()
            .filter(|s| now.duration_since(s.0) <= WINDOW)
            .map(|s| s.1)
            .sum();
        n as f64 / WINDOW.as_secs_f64()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn at_most_two_frames_wait_for_answers() {
        let t = Instant::now();
        let mut p = Pacer::new(true, None);
        assert!(p.may_send(t));
        p.sent(t, 100);
        assert!(p.may_send(t));
        p.sent(t, 100);
        // Two unanswered: the third waits, however long the answer takes once the
        // terminal has answered before.
        assert!(!p.may_send(t + Duration::from_millis(10)));
        p.answered(t + Duration::from_millis(50));
        assert_eq!(p.rtt, Some(Duration::from_millis(50)));
        assert!(p.may_send(t + Duration::from_millis(50)));
        p.sent(t + Duration::from_millis(50), 100);
        assert!(!p.may_send(t + Duration::from_secs(4)));
        assert!(!p.unpaced);
        // Answers missing for longer than a link takes are taken as lost.
        let lost = t + Duration::from_millis(50) + LOST_ANSWER_WAIT;
        assert_eq!(p.wake_at(), Some(t + LOST_ANSWER_WAIT));
        assert!(p.may_send(lost));
        assert_eq!(p.in_flight(), 0);
    }

    /// A link that holds frames back is measured by the time between answers, and
    /// frames get [`FRAME_TIME`] of it; a link that keeps up gives no budget.
    #[test]
    fn a_slow_link_sets_the_frame_budget() {
        let t = Instant::now();
        let ms = |n: u64| t + Duration::from_millis(n);
        let mut p = Pacer::new(true, None);
        // Fast: each frame answered before the next is sent.
        for k in 0..5 {
            p.sent(ms(33 * k), 20_000);
            p.answered(ms(33 * k + 2));
        }
        assert_eq!(p.link_rate(ms(200)), None);
        assert_eq!(p.budget(ms(200)), None);
        // Slow: 10 kB frames sent back to back, answered 80 ms apart (125 kB/s),
        // whatever the round trip.
        let mut p = Pacer::new(true, None);
        p.sent(ms(0), 10_000);
        p.sent(ms(0), 10_000);
        for k in 1..=6 {
            p.answered(ms(300 + 80 * k));
            p.sent(ms(300 + 80 * k), 10_000);
        }
        let rate = p.link_rate(ms(800)).expect("measured");
        assert!((rate - 125_000.0).abs() < 1.0, "{rate}");
        assert_eq!(p.budget(ms(800)), Some(7500));
        // The measurement lapses when the link no longer holds frames back.
        assert_eq!(p.budget(ms(800) + Duration::from_secs(5)), None);
    }

    #[test]
    fn a_terminal_that_never_answers_is_not_waited_for() {
        let t = Instant::now();
        let mut p = Pacer::new(true, None);
        p.sent(t, 100);
        p.sent(t, 100);
        assert!(!p.may_send(t + FIRST_ANSWER_WAIT / 2));
        assert_eq!(p.wake_at(), Some(t + FIRST_ANSWER_WAIT));
        assert!(p.may_send(t + FIRST_ANSWER_WAIT));
        assert!(p.unpaced);
        for i in 0..10 {
            assert!(p.may_send(t + FIRST_ANSWER_WAIT));
            p.sent(t + FIRST_ANSWER_WAIT + Duration::from_millis(i), 100);
        }
        // A late answer brings pacing back.
        p.answered(t + FIRST_ANSWER_WAIT * 2);
        assert!(!p.unpaced);
        assert!(!p.may_send(t + FIRST_ANSWER_WAIT * 2));
    }

    #[test]
    fn the_rate_cap_spaces_frames() {
        let t = Instant::now();
        let mut p = Pacer::new(false, Some(1000));
        p.sent(t, 500);
        assert!(!p.may_send(t + Duration::from_millis(499)));
        assert!(p.may_send(t + Duration::from_millis(500)));
        assert_eq!(p.bytes_per_second(t), 250.0);
    }
}

//! The status line: fields in order of importance, the less important dropped first
//! when the terminal is narrow, and the frame rate measured over recent frames.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// How important a status field is: lower is kept longer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Priority {
    /// The mode, `? help`, the glyph and colour mode: always shown.
    Always,
    /// What is drawn (fill or wire, culling) and the frame rate.
    Drawing,
    /// The link: bytes per second, round trip, delivered frames.
    Link,
    /// Bytes of the last frame.
    Bytes,
    /// Triangle counts.
    Counts,
    /// Where the frame's time went.
    Timing,
}

/// Fields joined by ` | `, kept in their order; `fit` drops the least important until
/// the line fits.
#[derive(Debug, Default)]
pub struct StatusLine {
    fields: Vec<(Priority, String)>,
}

impl StatusLine {
    pub fn clear(&mut self) {
        self.fields.clear();
    }

    pub fn push(&mut self, p: Priority, text: impl Into<String>) {
        self.fields.push((p, text.into()));
    }

    /// The line in at most `width` characters: fields dropped from the least
    /// important (the latest of equal importance first); if even the essential fields
    /// do not fit, the line is cut.
    #[must_use]
    pub fn fit(&self, width: usize) -> String {
        let mut keep: Vec<bool> = vec![true; self.fields.len()];
        let len = |keep: &[bool]| -> usize {
            let (n, chars) = self
                .fields
                .iter()
                .zip(keep)
                .filter(|(_, k)| **k)
                .fold((0usize, 0usize), |(n, c), ((_, t), _)| {
                    (n + 1, c + t.chars().count())
                });
            chars + 3 * n.saturating_sub(1)
        };
        while len(&keep) > width {
            let drop = (0..self.fields.len())
                .filter(|&i| keep[i] && self.fields[i].0 != Priority::Always)
                .max_by_key(|&i| (self.fields[i].0, i));
            match drop {
                Some(i) => keep[i] = false,
                None => break,
            }
        }
        let line = self
            .fields
            .iter()
            .zip(&keep)
            .filter(|(_, k)| **k)
            .map(|((_, t), _)| t.as_str())
            .collect::<Vec<_>>()
            .join(" | ");
        line.chars().take(width).collect()
    }
}

/// Frames per second over the last second of drawn frames, never above the cap.
#[derive(Debug)]
pub struct FpsMeter {
    frames: VecDeque<Instant>,
    pub cap: f32,
}

impl Default for FpsMeter {
    fn default() -> Self {
        Self {
            frames: VecDeque::with_capacity(256),
            cap: 30.0,
        }
    }
}

impl FpsMeter {
    const WINDOW: Duration = Duration::from_secs(1);

    /// A frame was drawn at `now`.
    pub fn frame(&mut self, now: Instant) {
        self.frames.push_back(now);
        while self
            .frames
            .front()
            .is_some_and(|&t| now.duration_since(t) > Self::WINDOW)
        {
            self.frames.pop_front();
        }
    }

    /// Forgets the frames so far (after a pause: the gap is not a slow frame).
    pub fn reset(&mut self) {
        self.frames.clear();
    }

    /// The rate over the window, once it has two frames.
    #[must_use]
    pub fn fps(&self) -> Option<f32> {
        let (first, last) = (self.frames.front()?, self.frames.back()?);
        let span = last.duration_since(*first).as_secs_f32();
        (self.frames.len() >= 2 && span > 0.0)
            .then(|| ((self.frames.len() - 1) as f32 / span).min(self.cap))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_important_fields_go_first() {
        let mut s = StatusLine::default();
        s.push(Priority::Always, "inspect");
        s.push(Priority::Always, "blocks truecolor");
        s.push(Priority::Drawing, "fill");
        s.push(Priority::Timing, "transform 0.2 raster 1.0 ms");
        s.push(Priority::Counts, "tris 992");
        s.push(Priority::Always, "? help");
        assert_eq!(
            s.fit(200),
            "inspect | blocks truecolor | fill | transform 0.2 raster 1.0 ms | tris 992 | ? help"
        );
        assert_eq!(
            s.fit(60),
            "inspect | blocks truecolor | fill | tris 992 | ? help"
        );
        assert_eq!(s.fit(45), "inspect | blocks truecolor | fill | ? help");
        assert_eq!(s.fit(40), "inspect | blocks truecolor | ? help");
        // Too narrow even for the essentials: cut.
        assert_eq!(s.fit(10), "inspect | ");
    }

    #[test]
    fn fps_is_measured_over_a_window_and_capped() {
        let t = Instant::now();
        let mut m = FpsMeter {
            cap: 30.0,
            ..FpsMeter::default()
        };
        assert_eq!(m.fps(), None);
        m.frame(t);
        assert_eq!(m.fps(), None, "one frame is no rate");
        // Two frames 1 µs apart would be a million fps: capped.
        m.frame(t + Duration::from_micros(1));
        assert_eq!(m.fps(), Some(30.0));
        let mut m = FpsMeter::default();
        for k in 0..40 {
            m.frame(t + Duration::from_millis(50 * k));
        }
        let fps = m.fps().unwrap();
        assert!((fps - 20.0).abs() < 0.01, "{fps}");
    }
}

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

/// Fields joined by ` | `, kept in their order; `fit` shortens, then drops, the least
/// important until the line fits.
#[derive(Debug, Default)]
pub struct StatusLine {
    fields: Vec<Field>,
}

#[derive(Debug)]
struct Field {
    priority: Priority,
    text: String,
    /// A shorter form, taken before any field is dropped.
    short: Option<String>,
}

/// What [`StatusLine::fit`] shows of a field.
#[derive(Clone, Copy, PartialEq)]
enum Shown {
    Whole,
    Short,
    Dropped,
}

impl StatusLine {
    pub fn clear(&mut self) {
        self.fields.clear();
    }

    pub fn push(&mut self, p: Priority, text: impl Into<String>) {
        self.fields.push(Field {
            priority: p,
            text: text.into(),
            short: None,
        });
    }

    /// [`StatusLine::push`] with a shorter form for a narrow terminal.
    pub fn push_short(&mut self, p: Priority, text: impl Into<String>, short: impl Into<String>) {
        self.fields.push(Field {
            priority: p,
            text: text.into(),
            short: Some(short.into()),
        });
    }

    /// The line in at most `width` characters: fields shortened, then dropped, from
    /// the least important (the latest of equal importance first), so that every field
    /// keeps its short form before any is dropped; if even the essential fields do not
    /// fit, the line is cut.
    #[must_use]
    pub fn fit(&self, width: usize) -> String {
        let mut shown = vec![Shown::Whole; self.fields.len()];
        let text = |i: usize, shown: &[Shown]| -> Option<&str> {
            let f = &self.fields[i];
            match shown[i] {
                Shown::Whole => Some(&f.text),
                Shown::Short => f.short.as_deref(),
                Shown::Dropped => None,
            }
        };
        let len = |shown: &[Shown]| -> usize {
            let (n, chars) = (0..self.fields.len())
                .filter_map(|i| text(i, shown))
                .fold((0usize, 0usize), |(n, c), t| (n + 1, c + t.chars().count()));
            chars + 3 * n.saturating_sub(1)
        };
        // The least important field (the latest of equal importance) that `can` change.
        let least = |shown: &[Shown], can: &dyn Fn(usize, &[Shown]) -> bool| {
            (0..self.fields.len())
                .filter(|&i| self.fields[i].priority != Priority::Always && can(i, shown))
                .max_by_key(|&i| (self.fields[i].priority, i))
        };
        let shortens =
            |i: usize, shown: &[Shown]| shown[i] == Shown::Whole && self.fields[i].short.is_some();
        let drops = |i: usize, shown: &[Shown]| shown[i] != Shown::Dropped;
        while len(&shown) > width {
            if let Some(i) = least(&shown, &shortens) {
                shown[i] = Shown::Short;
            } else if let Some(i) = least(&shown, &drops) {
                shown[i] = Shown::Dropped;
            } else {
                break;
            }
        }
        let line = (0..self.fields.len())
            .filter_map(|i| text(i, &shown))
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

    /// Every field takes its short form before any is dropped, the least important
    /// first.
    #[test]
    fn fields_are_shortened_before_any_is_dropped() {
        let mut s = StatusLine::default();
        s.push(Priority::Always, "blocks truecolor");
        s.push(Priority::Drawing, "fill");
        s.push_short(
            Priority::Timing,
            "transform 0.2 raster 1.0 ms, 2 threads",
            "raster 1.0 ms, 2 threads",
        );
        s.push_short(Priority::Counts, "tris 992 drawn 0 culled", "tris 992");
        s.push(Priority::Always, "? help");
        let whole = "blocks truecolor | fill | transform 0.2 raster 1.0 ms, 2 threads | tris 992 drawn 0 culled | ? help";
        assert_eq!(s.fit(200), whole);
        assert_eq!(s.fit(whole.len()), whole);
        assert_eq!(
            s.fit(whole.len() - 1),
            "blocks truecolor | fill | raster 1.0 ms, 2 threads | tris 992 drawn 0 culled | ? help"
        );
        assert_eq!(
            s.fit(70),
            "blocks truecolor | fill | raster 1.0 ms, 2 threads | tris 992 | ? help"
        );
        // Then the least important goes, whole.
        assert_eq!(s.fit(69), "blocks truecolor | fill | tris 992 | ? help");
        assert_eq!(s.fit(33), "blocks truecolor | fill | ? help");
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

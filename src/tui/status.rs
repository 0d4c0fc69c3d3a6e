//! The status line: fields in order of importance, shortened and then the less
//! important left out when the terminal is narrow, and the frame rate measured over
//! recent frames.

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

/// Fields joined by ` | `, kept in their order; `fit` shortens them and leaves out the
/// least important until the line fits.
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

    /// [`StatusLine::push`] with a shorter form for a narrow terminal (ignored unless
    /// it is shorter).
    pub fn push_short(&mut self, p: Priority, text: impl Into<String>, short: impl Into<String>) {
        let (text, short) = (text.into(), short.into());
        let shorter = short.chars().count() < text.chars().count();
        self.fields.push(Field {
            priority: p,
            text,
            short: shorter.then_some(short),
        });
    }

    /// The line in at most `width` characters. Fields are left out from the least
    /// important (the latest of equal importance first) until the line fits with every
    /// field in its short form; then the fields kept are given their whole form, the
    /// most important first, as far as they fit. If even the essential fields do not
    /// fit, the line is cut.
    #[must_use]
    pub fn fit(&self, width: usize) -> String {
        let n = self.fields.len();
        let mut shown: Vec<Shown> = self
            .fields
            .iter()
            .map(|f| {
                if f.short.is_some() {
                    Shown::Short
                } else {
                    Shown::Whole
                }
            })
            .collect();
        let text = |i: usize, shown: &[Shown]| -> Option<&str> {
            let f = &self.fields[i];
            match shown[i] {
                Shown::Whole => Some(&f.text),
                Shown::Short => f.short.as_deref(),
                Shown::Dropped => None,
            }
        };
        let len = |shown: &[Shown]| -> usize {
            let (n, chars) = (0..n)
                .filter_map(|i| text(i, shown))
                .fold((0usize, 0usize), |(n, c), t| (n + 1, c + t.chars().count()));
            chars + 3 * n.saturating_sub(1)
        };
        let mut by_importance: Vec<usize> = (0..n).collect();
        by_importance.sort_by_key(|&i| (self.fields[i].priority, i));
        for &i in by_importance.iter().rev() {
            if len(&shown) <= width {
                break;
            }
            if self.fields[i].priority != Priority::Always {
                shown[i] = Shown::Dropped;
            }
        }
        for &i in &by_importance {
            if shown[i] == Shown::Short {
                shown[i] = Shown::Whole;
                if len(&shown) > width {
                    shown[i] = Shown::Short;
                }
            }
        }
        let line = (0..n)
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
    use proptest::prelude::*;

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

    /// Every field takes its short form before any is left out; the room left is
    /// given back to the most important.
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
        // Then the least important goes, and the room it leaves goes to the others.
        assert_eq!(
            s.fit(69),
            "blocks truecolor | fill | tris 992 drawn 0 culled | ? help"
        );
        assert_eq!(s.fit(42), "blocks truecolor | fill | ? help");
        // A "short" form longer than the whole one is never taken.
        let mut s = StatusLine::default();
        for text in ["aaa", "bbb", "ccc"] {
            s.push_short(Priority::Always, text, "LONGER");
        }
        assert_eq!(s.fit(15), "aaa | bbb | ccc");
    }

    fn priority() -> impl Strategy<Value = Priority> {
        prop_oneof![
            Just(Priority::Always),
            Just(Priority::Drawing),
            Just(Priority::Link),
            Just(Priority::Bytes),
            Just(Priority::Counts),
            Just(Priority::Timing),
        ]
    }

    proptest! {
        /// Whatever the fields and width: the line fits; the essential fields are all
        /// there when they fit alone; a field is left out only after every less
        /// important one; each field shows one of its forms.
        #[test]
        fn a_fitted_line_fits_and_leaves_out_the_least_important(
            fields in prop::collection::vec((priority(), "[a-z]{1,12}", prop::option::of("[A-Z]{1,5}")), 0..8),
            width in 0usize..80,
        ) {
            // Each text names its field: an index added, short forms upper case.
            let fields: Vec<(Priority, String, Option<String>)> = fields
                .into_iter()
                .enumerate()
                .map(|(i, (p, t, short))| (p, format!("{t}{i}"), short.map(|s| format!("{s}{i}"))))
                .collect();
            let mut s = StatusLine::default();
            for (p, text, short) in &fields {
                match short {
                    Some(short) => s.push_short(*p, text.clone(), short.clone()),
                    None => s.push(*p, text.clone()),
                }
            }
            let line = s.fit(width);
            prop_assert!(line.chars().count() <= width);
            let essential: Vec<&str> = fields
                .iter()
                .filter(|f| f.0 == Priority::Always)
                .map(|f| f.1.as_str())
                .collect();
            if essential.join(" | ").len() > width {
                return Ok(());
            }
            let parts: Vec<&str> = if line.is_empty() { vec![] } else { line.split(" | ").collect() };
            let mut next = 0;
            let mut kept = vec![false; fields.len()];
            for part in &parts {
                let found = (next..fields.len()).find(|&i| {
                    fields[i].1 == *part || fields[i].2.as_deref() == Some(*part)
                });
                prop_assert!(found.is_some(), "{part:?} in {line:?}");
                let i = found.unwrap();
                kept[i] = true;
                next = i + 1;
            }
            let whole = fields.iter().map(|f| f.1.as_str()).collect::<Vec<_>>().join(" | ");
            if whole.chars().count() <= width {
                prop_assert_eq!(&line, &whole, "the whole line fits");
            }
            // A field left in its short form could not have had its whole form.
            let width_of = |t: &str| t.chars().count();
            for part in &parts {
                if let Some(f) = fields.iter().find(|f| f.2.as_deref() == Some(*part)) {
                    prop_assert!(
                        width_of(&line) - width_of(part) + width_of(&f.1) > width,
                        "{:?} could be whole in {line:?}", f.1
                    );
                }
            }
            // The most important field left out did not fit even with every kept field
            // in its shortest form.
            let shortest = |f: &(Priority, String, Option<String>)| {
                f.2.as_deref().filter(|s| s.len() < f.1.len()).map_or(f.1.len(), str::len)
            };
            let left_out = (0..fields.len()).filter(|&i| !kept[i]).min_by_key(|&i| (fields[i].0, i));
            if let Some(i) = left_out {
                let with: Vec<usize> = (0..fields.len()).filter(|&j| kept[j] || j == i).collect();
                let len: usize = with.iter().map(|&j| shortest(&fields[j])).sum::<usize>()
                    + 3 * (with.len() - 1);
                prop_assert!(len > width, "{:?} left out of {line:?}", fields[i].1);
            }
            for (i, f) in fields.iter().enumerate() {
                if f.0 == Priority::Always {
                    prop_assert!(kept[i], "{line:?} lacks {:?}", f.1);
                }
                for (j, g) in fields.iter().enumerate() {
                    if !kept[i] && kept[j] && g.0 != Priority::Always {
                        prop_assert!((f.0, i) > (g.0, j), "{:?} left out before {:?}: {line:?}", f.1, g.1);
                    }
                }
            }
        }
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

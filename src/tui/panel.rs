//! Panel text laid out for the panel's width: each line is a list of fields (a label
//! with its value, or a word of prose) that are never split. A line that does not fit
//! continues on the next row between two fields, indented, so `area2` stays beside its
//! value and the three `persp` weights stay together however narrow the panel is.
//! A panel taller than its box scrolls, with a marker where rows are hidden.

/// One line of fields.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
struct PanelLine {
    indent: usize,
    fields: Vec<String>,
    /// Shorter fields for a panel too narrow for `fields` on one row.
    short: Option<Vec<String>>,
    /// Between fields: two spaces for fields, one for the words of prose.
    gap: &'static str,
}

impl PanelLine {
    /// Characters on one row.
    fn width(&self, fields: &[String]) -> usize {
        self.indent
            + fields.iter().map(|f| f.chars().count()).sum::<usize>()
            + self.gap.len() * fields.len().saturating_sub(1)
    }
}

/// Lines of fields, laid out by [`PanelText::rows`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PanelText {
    lines: Vec<PanelLine>,
}

impl PanelText {
    /// A line of fields, indented by `indent` spaces.
    pub fn fields<S: Into<String>>(&mut self, indent: usize, fields: impl IntoIterator<Item = S>) {
        self.lines.push(PanelLine {
            indent,
            fields: fields.into_iter().map(Into::into).collect(),
            short: None,
            gap: "  ",
        });
    }

    /// A line of fields with shorter labels for narrow panels (used when `fields`
    /// does not fit on one row).
    pub fn fields_or<S: Into<String>, T: Into<String>>(
        &mut self,
        indent: usize,
        fields: impl IntoIterator<Item = S>,
        short: impl IntoIterator<Item = T>,
    ) {
        self.fields(indent, fields);
        if let Some(l) = self.lines.last_mut() {
            l.short = Some(short.into_iter().map(Into::into).collect());
        }
    }

    /// A line of prose, wrapped between words.
    pub fn prose(&mut self, indent: usize, text: &str) {
        self.lines.push(PanelLine {
            indent,
            fields: text.split_whitespace().map(str::to_owned).collect(),
            short: None,
            gap: " ",
        });
    }

    /// Appends another text's lines.
    pub fn extend(&mut self, other: PanelText) {
        self.lines.extend(other.lines);
    }

    /// The text as rows of at most `width` characters. A field wider than the panel
    /// is cut, with `…`.
    #[must_use]
    pub fn rows(&self, width: usize) -> Vec<String> {
        let width = width.max(1);
        let mut out = Vec::new();
        for line in &self.lines {
            let mut row = " ".repeat(line.indent.min(width - 1));
            let mut row_len = row.chars().count();
            let mut row_empty = true;
            let fields = match &line.short {
                Some(short) if line.width(&line.fields) > width => short,
                _ => &line.fields,
            };
            for f in fields {
                let len = f.chars().count();
                let gap = if row_empty { 0 } else { line.gap.len() };
                if !row_empty && row_len + gap + len > width {
                    out.push(std::mem::take(&mut row));
                    row = " ".repeat((line.indent + 2).min(width - 1));
                    row_len = row.chars().count();
                    row_empty = true;
                }
                if !row_empty {
                    row.push_str(line.gap);
                    row_len += line.gap.len();
                }
                let room = width.saturating_sub(row_len);
                if len > room {
                    row.extend(f.chars().take(room.saturating_sub(1)));
                    row.push('…');
                    row_len = width;
                } else {
                    row.push_str(f);
                    row_len += len;
                }
                row_empty = false;
            }
            out.push(row);
        }
        out
    }

    /// The plain text, one row per line (each line on one row): for tests and logs.
    #[must_use]
    pub fn plain(&self) -> String {
        self.rows(usize::MAX / 2).join("\n")
    }
}

/// The rows of `rows` that a box `height` rows tall shows when scrolled by `scroll`
/// (clamped, and returned): a hidden row above is marked `↑ more above`, one below
/// `↓ more below`, in place of the first and last visible rows.
#[must_use]
pub fn window(rows: &[String], height: usize, scroll: usize) -> (Vec<String>, usize) {
    if rows.len() <= height || height < 3 {
        return (rows.iter().take(height).cloned().collect(), 0);
    }
    // `scroll` is the first row shown; the last page ends with the last row.
    let first = scroll.min(rows.len() + 1 - height);
    let mut out = Vec::with_capacity(height);
    if first > 0 {
        out.push(format!("↑ more above (PgUp)  {first} rows"));
    }
    let mut room = height - out.len();
    let below = first + room < rows.len();
    if below {
        room -= 1;
    }
    out.extend(rows[first..first + room].iter().cloned());
    if below {
        out.push(format!(
            "↓ more below (PgDn)  {} rows",
            rows.len() - first - room
        ));
    }
    (out, first)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text() -> PanelText {
        let mut t = PanelText::default();
        t.fields(
            0,
            [
                ">s5 (125,82)",
                "covered by t123",
                "depth 0.45678",
                "(4 touched)",
            ],
        );
        t.fields(3, ["F01 123", "F02 -456", "F03 789", "area2 1234"]);
        t.prose(2, "a sentence of several words that wraps between them");
        t
    }

    #[test]
    fn fields_are_never_split() {
        let t = text();
        for width in [20, 30, 56, 120] {
            let rows = t.rows(width);
            let joined = rows.join("\n");
            for field in ["(4 touched)", "area2 1234", "covered by t123", "F02 -456"] {
                assert!(
                    rows.iter().any(|r| r.contains(field)),
                    "`{field}` split at width {width}:\n{joined}"
                );
            }
            assert!(rows.iter().all(|r| r.chars().count() <= width), "{joined}");
        }
        // Shorter labels where the long ones do not fit on a row.
        let mut t = PanelText::default();
        t.fields_or(0, ["covered by t12", "(4 touched)"], ["t12", "4 touched"]);
        assert_eq!(t.rows(30), ["covered by t12  (4 touched)"]);
        assert_eq!(t.rows(20), ["t12  4 touched"]);
        // Wide enough: one row per line.
        assert_eq!(text().rows(200).len(), 3);
        // A field wider than the panel is cut, marked.
        assert_eq!(text().rows(8)[0], ">s5 (12…");
    }

    #[test]
    fn a_window_marks_what_it_hides() {
        let rows: Vec<String> = (0..10).map(|i| format!("row {i}")).collect();
        let (w, s) = window(&rows, 4, 0);
        assert_eq!(s, 0);
        assert_eq!(w[..3], rows[..3]);
        assert!(w[3].starts_with("↓ more below"), "{w:?}");
        let (w, s) = window(&rows, 4, 3);
        assert_eq!(s, 3);
        assert!(w[0].starts_with("↑ more above"));
        assert_eq!(w[1..3], rows[3..5]);
        assert!(w[3].starts_with("↓ more below"));
        // Scrolled to the end: the last row shows, no marker below.
        let (w, s) = window(&rows, 4, 100);
        assert_eq!(s, 7);
        assert_eq!(w.last(), rows.last());
        assert!(w[0].starts_with("↑"));
        // Everything fits: no markers.
        let (w, _) = window(&rows[..3], 4, 5);
        assert_eq!(w, rows[..3]);
    }
}

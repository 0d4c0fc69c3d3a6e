//! The ratatui backend that sends what the eye can see and nothing else.
//!
//! It keeps the terminal's cells as they were last sent (`shown`) beside the frame
//! ratatui asks for (`wanted`). A cell changed in this frame is sent when its text or
//! attributes change, or when one of its colours is more than [`DELTA_E`] from what
//! the terminal shows (a distance in OKLab, about two just-noticeable differences):
//! the screen never strays further than that from the true frame. A cell that did not
//! change in this frame but is shown only approximately is sent exactly, so a still
//! model shows the exact frame one frame after it stops. Colours are written only
//! when they change (foreground and background apart; the foreground of a space and
//! the background of a full block are never written, since they do not show), a
//! changed cell keeps the pen's colour when that is within the threshold, and the
//! cursor moves by the shortest sequence. Everything is written to the terminal in
//! one write per frame.
//!
//! On a link too slow for every change ([`LinkBackend::budget`]), the cells outside
//! the model's area ([`LinkBackend::bulk`]: the status line, panels, overlays) go
//! first and in full, then the model's most visible changes up to the budget; the rest
//! follow in later frames.

use std::io::{self, Write};

use ratatui::backend::{Backend, ClearType, WindowSize};
use ratatui::buffer::Cell;
use ratatui::layout::{Position, Rect, Size};
use ratatui::style::{Color, Modifier};

use std::cell::RefCell;

use super::app::used_size;
use crate::memory::refill;
use crate::terminal::color::{OklabCache, Rgb, indexed_rgb, nearest_256};

/// How far (OKLab distance) a changed cell's colour may stray from the true frame.
pub const DELTA_E: f32 = 0.04;

/// The pen: attributes the terminal will draw the next character with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Pen {
    fg: Color,
    bg: Color,
    modifier: Modifier,
}

const DEFAULT_PEN: Pen = Pen {
    fg: Color::Reset,
    bg: Color::Reset,
    modifier: Modifier::empty(),
};

/// A backend writing to `out` through a cell cache.
#[derive(Debug)]
pub struct LinkBackend<W: Write> {
    out: W,
    /// Bytes of the frame being built.
    buf: Vec<u8>,
    cols: u16,
    rows: u16,
    wanted: Vec<Cell>,
    shown: Vec<Cell>,
    /// Cells ratatui changed in this frame.
    changed: Vec<bool>,
    /// Where the terminal's cursor is, if known.
    cursor: Option<(u16, u16)>,
    /// Whether the cursor is hidden, if known (ratatui hides it every frame).
    hidden: Option<bool>,
    pen: Option<Pen>,
    /// The size reported to ratatui; `None` asks the terminal.
    fixed: Option<Size>,
    /// Colour threshold in use ([`DELTA_E`], or 0 to send every change).
    pub threshold: f32,
    /// The part of the screen that may be sent in part when the budget is short (the
    /// model); everything else is sent first, in full.
    pub bulk: Option<Rect>,
    /// Bytes the next frame may take, if limited.
    pub budget: Option<usize>,
    /// Bulk cells waiting to be sent, with how visible their change is.
    candidates: Vec<(f32, u32)>,
    /// Mean bytes per bulk cell sent, to fit the budget.
    cell_bytes: f32,
    /// OKLab of the colours compared lately.
    lab: RefCell<OklabCache>,
}

impl<W: Write> LinkBackend<W> {
    /// A backend for the terminal on `out`, its size from the terminal.
    pub fn new(out: W) -> Self {
        Self::sized(out, None)
    }

    /// A backend of a fixed size (for tests and benchmarks).
    pub fn with_size(out: W, cols: u16, rows: u16) -> Self {
        Self::sized(out, Some(Size::new(cols, rows)))
    }

    fn sized(out: W, fixed: Option<Size>) -> Self {
        let mut b = Self {
            out,
            buf: Vec::with_capacity(1 << 16),
            cols: 0,
            rows: 0,
            wanted: Vec::new(),
            shown: Vec::new(),
            changed: Vec::new(),
            cursor: None,
            hidden: None,
            pen: None,
            fixed,
            threshold: DELTA_E,
            bulk: None,
            budget: None,
            candidates: Vec::new(),
            cell_bytes: 12.0,
            lab: RefCell::default(),
        };
        let s = b.size().unwrap_or(Size::new(80, 24));
        b.reset(s);
        b
    }

    /// Sets the size reported to ratatui (a remote terminal's window change); the next
    /// draw clears and redraws the screen at that size.
    pub fn set_size(&mut self, cols: u16, rows: u16) {
        self.fixed = Some(Size::new(cols, rows));
    }

    /// The writer.
    pub fn writer(&mut self) -> &mut W {
        &mut self.out
    }

    /// Forgets what the terminal shows (after it was cleared, or is not trusted).
    fn reset(&mut self, s: Size) {
        self.cols = s.width;
        self.rows = s.height;
        let n = usize::from(s.width) * usize::from(s.height);
        refill(&mut self.wanted, n, Cell::EMPTY);
        refill(&mut self.shown, n, Cell::EMPTY);
        refill(&mut self.changed, n, false);
        self.cursor = None;
        self.pen = None;
        self.hidden = None;
    }

    /// OKLab distance of two colours; 0 when equal, 1 (far) when either has no fixed
    /// value.
    fn distance(&self, a: Color, b: Color) -> f32 {
        if a == b {
            return 0.0;
        }
        match (fixed_rgb(a), fixed_rgb(b)) {
            (Some(a), Some(b)) => self.lab.borrow_mut().delta_e(a, b),
            _ => 1.0,
        }
    }

    /// Whether the shown cell `s` stands for the wanted `w` closely enough: exactly,
    /// or within the threshold if `approx`.
    fn close_enough(&self, s: &Cell, w: &Cell, approx: bool) -> bool {
        if s.symbol() != w.symbol() || s.modifier != w.modifier {
            return false;
        }
        let near = |a: Color, b: Color| a == b || (approx && self.distance(a, b) <= self.threshold);
        let (fg, bg) = shows(w);
        (!fg || near(s.fg, w.fg)) && (!bg || near(s.bg, w.bg))
    }

    /// How visible sending cell `i` would be: a changed glyph by its contrast, else by
    /// how far its colours move.
    fn visibility(&self, i: usize) -> f32 {
        let (w, s) = (&self.wanted[i], &self.shown[i]);
        if s.symbol() != w.symbol() || s.modifier != w.modifier {
            return 1.0 + self.distance(w.fg, w.bg).min(1.0);
        }
        self.distance(s.fg, w.fg).max(self.distance(s.bg, w.bg))
    }

    /// Whether cell `i` must be sent.
    fn pending(&self, i: usize) -> bool {
        !self.close_enough(&self.shown[i], &self.wanted[i], self.changed[i])
    }

    fn in_bulk(&self, i: usize) -> bool {
        let cols = usize::from(self.cols);
        let (x, y) = ((i % cols) as u16, (i / cols) as u16);
        self.bulk.is_some_and(|r| r.contains(Position { x, y }))
    }

    /// Appends what takes the terminal from `shown` to `wanted`, within the budget.
    fn encode(&mut self) {
        let start = self.buf.len();
        let n = self.wanted.len();
        for i in 0..n {
            if !self.in_bulk(i) && self.pending(i) {
                self.send(i);
            }
        }
        let mut candidates = std::mem::take(&mut self.candidates);
        candidates.clear();
        candidates.extend(
            (0..n)
                .filter(|&i| self.in_bulk(i) && self.pending(i))
                .map(|i| (0.0, i as u32)),
        );
        let room = self
            .budget
            .map(|b| b.saturating_sub(self.buf.len() - start));
        let fits = room.is_none_or(|r| candidates.len() as f32 * self.cell_bytes <= r as f32);
        if !fits {
            // The most visible changes that fit, sent in screen order.
            for c in &mut candidates {
                c.0 = self.visibility(c.1 as usize);
            }
            let k = (room.unwrap_or(0) as f32 / self.cell_bytes) as usize;
            let k = k.clamp(1, candidates.len());
            candidates.select_nth_unstable_by(k - 1, |a, b| b.0.total_cmp(&a.0));
            candidates.truncate(k);
            candidates.sort_unstable_by_key(|c| c.1);
        }
        let bulk_start = self.buf.len();
        let mut sent = 0usize;
        for &(_, i) in &candidates {
            if !fits && self.buf.len() - start >= self.budget.unwrap_or(usize::MAX) {
                break;
            }
            self.send(i as usize);
            sent += 1;
        }
        if sent > 0 {
            let mean = (self.buf.len() - bulk_start) as f32 / sent as f32;
            self.cell_bytes = 0.8 * self.cell_bytes + 0.2 * mean.max(1.0);
        }
        self.candidates = candidates;
        self.changed.fill(false);
    }

    /// Sends cell `i`.
    fn send(&mut self, i: usize) {
        let cols = usize::from(self.cols);
        let (x, y) = ((i % cols) as u16, (i / cols) as u16);
        let mut w = self.wanted[i].clone();
        if w.symbol().is_empty() {
            // The trailing half of a wide character: drawn by the cell before it.
            self.shown[i] = w;
            return;
        }
        self.move_to(x, y);
        // Keep what the pen has where it does not show, or (for a changed cell) where
        // it is within the threshold.
        if let Some(pen) = self.pen.filter(|p| p.modifier == w.modifier) {
            let (fg, bg) = shows(&w);
            let near =
                |a: Color, b: Color| self.changed[i] && self.distance(a, b) <= self.threshold;
            if !fg || near(pen.fg, w.fg) {
                w.fg = pen.fg;
            }
            if !bg || near(pen.bg, w.bg) {
                w.bg = pen.bg;
            }
        }
        if self.changed[i] {
            // A palette colour within the threshold is written in half the bytes.
            for c in [&mut w.fg, &mut w.bg] {
                if let Color::Rgb(r, g, b) = *c {
                    let n = nearest_256([r, g, b]);
                    if self.lab.borrow_mut().delta_e(indexed_rgb(n), [r, g, b]) <= self.threshold {
                        *c = Color::Indexed(n);
                    }
                }
            }
        }
        self.set_pen(Pen {
            fg: w.fg,
            bg: w.bg,
            modifier: w.modifier,
        });
        self.buf.extend_from_slice(w.symbol().as_bytes());
        self.cursor = narrow(w.symbol()).then_some((x + 1, y));
        self.shown[i] = w;
    }

    /// The shortest move of the cursor to `(x, y)`.
    fn move_to(&mut self, x: u16, y: u16) {
        match self.cursor {
            Some((cx, cy)) if (cx, cy) == (x, y) => {}
            Some((cx, cy)) if cy == y && x > cx => {
                let n = x - cx;
                if n == 1 {
                    self.buf.extend_from_slice(b"\x1b[C");
                } else {
                    let _ = write!(self.buf, "\x1b[{n}C");
                }
            }
            Some((_, cy)) if x == 0 && y == cy + 1 => self.buf.extend_from_slice(b"\r\n"),
            _ if (x, y) == (0, 0) => self.buf.extend_from_slice(b"\x1b[H"),
            _ if x == 0 => {
                let _ = write!(self.buf, "\x1b[{}H", y + 1);
            }
            _ => {
                let _ = write!(self.buf, "\x1b[{};{}H", y + 1, x + 1);
            }
        }
        self.cursor = Some((x, y));
    }

    /// Sets only what differs from the current pen, in one SGR sequence.
    fn set_pen(&mut self, p: Pen) {
        let mut cur = self.pen.unwrap_or(Pen {
            // Unknown: force every attribute.
            fg: Color::Indexed(255),
            bg: Color::Indexed(255),
            modifier: Modifier::all(),
        });
        if cur == p {
            return;
        }
        let mut sgr = Sgr::new(&mut self.buf);
        if !(cur.modifier - p.modifier).is_empty() {
            // An attribute is switched off: reset and set what remains.
            sgr.param(format_args!("0"));
            cur = DEFAULT_PEN;
        }
        for (m, code) in [
            (Modifier::BOLD, 1),
            (Modifier::DIM, 2),
            (Modifier::ITALIC, 3),
            (Modifier::UNDERLINED, 4),
            (Modifier::SLOW_BLINK, 5),
            (Modifier::RAPID_BLINK, 6),
            (Modifier::REVERSED, 7),
            (Modifier::HIDDEN, 8),
            (Modifier::CROSSED_OUT, 9),
        ] {
            if p.modifier.contains(m) && !cur.modifier.contains(m) {
                sgr.param(format_args!("{code}"));
            }
        }
        if cur.fg != p.fg {
            sgr.color(p.fg, true);
        }
        if cur.bg != p.bg {
            sgr.color(p.bg, false);
        }
        sgr.end();
        self.pen = Some(p);
    }
}

/// Whether a cell's foreground and background show: a plain space shows no
/// foreground, a plain full block no background.
fn shows(c: &Cell) -> (bool, bool) {
    let plain = c.modifier.is_empty();
    match c.symbol() {
        " " if plain => (false, true),
        "█" if plain => (true, false),
        _ => (true, true),
    }
}

/// The RGB value of a colour whose value is fixed: RGB, or the xterm palette's cube
/// and grey ramp (16–255, which terminals do not redefine in practice; the 16 ANSI
/// colours they do).
fn fixed_rgb(c: Color) -> Option<Rgb> {
    match c {
        Color::Rgb(r, g, b) => Some([r, g, b]),
        Color::Indexed(i) if i >= 16 => Some(indexed_rgb(i)),
        _ => None,
    }
}

/// One SGR sequence being written: parameters separated by `;`.
struct Sgr<'a> {
    buf: &'a mut Vec<u8>,
    first: bool,
}

impl<'a> Sgr<'a> {
    fn new(buf: &'a mut Vec<u8>) -> Self {
        buf.extend_from_slice(b"\x1b[");
        Self { buf, first: true }
    }

    fn param(&mut self, p: std::fmt::Arguments) {
        if !self.first {
            self.buf.push(b';');
        }
        self.first = false;
        let _ = self.buf.write_fmt(p);
    }

    /// A colour, in the foreground (`fg`) or background.
    fn color(&mut self, c: Color, fg: bool) {
        if !self.first {
            self.buf.push(b';');
        }
        self.first = false;
        crate::terminal::ansi::color_params(self.buf, c, fg);
    }

    fn end(self) {
        self.buf.push(b'm');
    }
}

/// Whether a symbol is one cell wide for sure; after any other the cursor's place is
/// taken as unknown, so the next cell is placed absolutely.
fn narrow(s: &str) -> bool {
    let mut it = s.chars();
    match (it.next(), it.next()) {
        (Some(c), None) => matches!(c,
            ' '..='~' | '\u{A0}'..='\u{2FF}' | '\u{2010}'..='\u{2027}' | '\u{2190}'..='\u{21FF}'
            | '\u{2500}'..='\u{25FF}' | '\u{2800}'..='\u{28FF}' | '\u{1FB00}'..='\u{1FBAF}'),
        _ => false,
    }
}

impl<W: Write> Write for LinkBackend<W> {
    fn write(&mut self, data: &[u8]) -> io::Result<usize> {
        self.buf.extend_from_slice(data);
        Ok(data.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Backend::flush(self)
    }
}

impl<W: Write> Backend for LinkBackend<W> {
    type Error = io::Error;

    fn draw<'a, I>(&mut self, content: I) -> io::Result<()>
    where
        I: Iterator<Item = (u16, u16, &'a Cell)>,
    {
        for (x, y, c) in content {
            if x < self.cols && y < self.rows {
                let i = usize::from(y) * usize::from(self.cols) + usize::from(x);
                self.wanted[i] = c.clone();
                self.changed[i] = true;
            }
        }
        self.encode();
        Ok(())
    }

    fn hide_cursor(&mut self) -> io::Result<()> {
        if self.hidden != Some(true) {
            self.buf.extend_from_slice(b"\x1b[?25l");
            self.hidden = Some(true);
        }
        Ok(())
    }

    fn show_cursor(&mut self) -> io::Result<()> {
        if self.hidden != Some(false) {
            self.buf.extend_from_slice(b"\x1b[?25h");
            self.hidden = Some(false);
        }
        Ok(())
    }

    fn get_cursor_position(&mut self) -> io::Result<Position> {
        // Never asked of the terminal: its answer would arrive on the input thread.
        let (x, y) = self.cursor.unwrap_or((0, 0));
        Ok(Position { x, y })
    }

    fn set_cursor_position<P: Into<Position>>(&mut self, position: P) -> io::Result<()> {
        let p = position.into();
        self.move_to(p.x, p.y);
        Ok(())
    }

    fn clear(&mut self) -> io::Result<()> {
        self.clear_region(ClearType::All)
    }

    fn clear_region(&mut self, clear_type: ClearType) -> io::Result<()> {
        // Only the whole screen is cleared in a full-screen viewer; anything else is
        // redrawn cell by cell, since the cache must know what the screen shows.
        let s = self.size()?;
        if clear_type == ClearType::All {
            self.buf.extend_from_slice(b"\x1b[0m\x1b[2J");
        }
        self.reset(s);
        if clear_type != ClearType::All {
            // The cache no longer knows the screen: mark every cell as unknown.
            for c in &mut self.shown {
                c.set_symbol("\u{0}");
            }
        }
        Ok(())
    }

    fn size(&self) -> io::Result<Size> {
        match self.fixed {
            Some(s) => Ok(s),
            None => {
                let (w, h) = ratatui::crossterm::terminal::size()?;
                let (w, h) = used_size(w, h);
                Ok(Size::new(w, h))
            }
        }
    }

    fn window_size(&mut self) -> io::Result<WindowSize> {
        let s = self.size()?;
        Ok(WindowSize {
            columns_rows: s,
            pixels: Size::new(0, 0),
        })
    }

    fn flush(&mut self) -> io::Result<()> {
        if !self.buf.is_empty() {
            self.out.write_all(&self.buf)?;
            self.buf.clear();
        }
        self.out.flush()
    }
}

#[cfg(test)]
mod tests;

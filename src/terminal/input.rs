//! The terminal's input bytes as keys, mouse events and replies to queries.
//!
//! Over a slow link an escape sequence can arrive in pieces (ESC now, `[A` a packet
//! later), so a lone ESC is only the Esc key once no byte has followed it for
//! [`ESC_WAIT`] or the next read does not continue a sequence, and a sequence that has
//! started (`ESC [`) waits up to [`SEQUENCE_WAIT`] for its end. Control characters keep their modifier (Ctrl-Q is
//! not `q`). Replies to the Primary Device Attributes query (`CSI ? … c`) are told
//! apart from keys, for pacing frames, and so are the colours of OSC 4 replies (the
//! terminal's palette, [`super::palette`]). Unknown sequences are dropped whole, and a
//! sequence longer than [`MAX_SEQUENCE`] bytes is garbage and dropped, so pending
//! input stays bounded.

use std::time::{Duration, Instant};

use ratatui::crossterm::event::{
    Event, KeyCode, KeyEvent, KeyEventKind, KeyEventState, KeyModifiers, MouseButton, MouseEvent,
    MouseEventKind,
};

/// How long a lone ESC waits for the rest of a sequence before it is the Esc key.
pub const ESC_WAIT: Duration = Duration::from_millis(300);
/// How long a started sequence (`ESC [`, `ESC O`) waits for its end before it is
/// dropped.
pub const SEQUENCE_WAIT: Duration = Duration::from_secs(1);
/// The longest sequence kept while it is incomplete.
pub const MAX_SEQUENCE: usize = 64;

/// One item of input.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Input {
    /// A key or mouse event.
    Event(Event),
    /// The terminal's answer to `CSI c` (Primary Device Attributes).
    DeviceAttributes,
    /// The terminal's answer to an OSC 4 query: palette index and its colour.
    PaletteColor(u8, [u8; 3]),
}

/// Bytes from the terminal, parsed as they arrive.
#[derive(Debug, Default)]
pub struct Parser {
    buf: Vec<u8>,
    /// When the last byte arrived.
    last: Option<Instant>,
    /// An ESC that ended an earlier read and was not followed by a sequence: the Esc
    /// key, ahead of the buffer.
    esc: bool,
}

/// What the start of the buffer holds.
enum Parsed {
    /// An item (or nothing, for a sequence that means nothing here) and its length.
    Done(Option<Input>, usize),
    /// The start of something whose end has not arrived.
    Incomplete,
}

fn key(code: KeyCode, modifiers: KeyModifiers) -> Option<Input> {
    Some(Input::Event(Event::Key(KeyEvent {
        code,
        modifiers,
        kind: KeyEventKind::Press,
        state: KeyEventState::NONE,
    })))
}

/// Modifiers of the bit field `v`, given the masks of its shift, alt and ctrl bits.
fn modifiers_of(v: u16, [shift, alt, ctrl]: [u16; 3]) -> KeyModifiers {
    let mut m = KeyModifiers::NONE;
    for (bit, k) in [
        (shift, KeyModifiers::SHIFT),
        (alt, KeyModifiers::ALT),
        (ctrl, KeyModifiers::CONTROL),
    ] {
        if v & bit != 0 {
            m |= k;
        }
    }
    m
}

/// Modifiers of an xterm modifier parameter (`1 + bits`: 1 shift, 2 alt, 4 ctrl).
fn modifiers(param: u16) -> KeyModifiers {
    modifiers_of(param.saturating_sub(1), [1, 2, 4])
}

/// The numeric parameters of a CSI sequence (`12;34` → [12, 34]); empty ones are 0.
fn params(p: &[u8]) -> impl Iterator<Item = u16> + '_ {
    p.split(|&b| b == b';').map(|s| {
        s.iter().filter(|d| d.is_ascii_digit()).fold(0u16, |n, &d| {
            n.saturating_mul(10).saturating_add(u16::from(d - b'0'))
        })
    })
}

/// A CSI sequence: `ESC [`, parameter bytes `p`, the final byte `f`.
fn csi(p: &[u8], f: u8) -> Option<Input> {
    let mut ps = params(p);
    let first = ps.next().unwrap_or(0);
    let second = ps.next().unwrap_or(1);
    match (p.first(), f) {
        (Some(b'?'), b'c') => Some(Input::DeviceAttributes),
        (Some(b'<'), b'M' | b'm') => mouse(&p[1..], f == b'M'),
        (Some(b'?' | b'<' | b'>' | b'='), _) => None,
        (_, b'A' | b'B' | b'C' | b'D' | b'H' | b'F') => {
            let code = match f {
                b'A' => KeyCode::Up,
                b'B' => KeyCode::Down,
                b'C' => KeyCode::Right,
                b'D' => KeyCode::Left,
                b'H' => KeyCode::Home,
                _ => KeyCode::End,
            };
            key(code, modifiers(second))
        }
        (_, b'Z') => key(KeyCode::BackTab, KeyModifiers::SHIFT),
        (_, b'~') => {
            let code = match first {
                1 | 7 => KeyCode::Home,
                2 => KeyCode::Insert,
                3 => KeyCode::Delete,
                4 | 8 => KeyCode::End,
                5 => KeyCode::PageUp,
                6 => KeyCode::PageDown,
                _ => return None,
            };
            key(code, modifiers(second))
        }
        _ => None,
    }
}

/// An SGR mouse report `b;x;y` (1-based cell), pressed (`M`) or released (`m`).
fn mouse(p: &[u8], pressed: bool) -> Option<Input> {
    let mut ps = params(p);
    let (b, x, y) = (ps.next()?, ps.next()?, ps.next()?);
    let button = match b & 3 {
        0 => MouseButton::Left,
        1 => MouseButton::Middle,
        _ => MouseButton::Right,
    };
    let kind = if b & 64 != 0 {
        match b & 3 {
            0 => MouseEventKind::ScrollUp,
            1 => MouseEventKind::ScrollDown,
            2 => MouseEventKind::ScrollLeft,
            _ => MouseEventKind::ScrollRight,
        }
    } else if b & 32 != 0 {
        if b & 3 == 3 {
            MouseEventKind::Moved
        } else {
            MouseEventKind::Drag(button)
        }
    } else if pressed {
        MouseEventKind::Down(button)
    } else {
        MouseEventKind::Up(button)
    };
    let modifiers = modifiers_of(b, [4, 8, 16]);
    Some(Input::Event(Event::Mouse(MouseEvent {
        kind,
        column: x.saturating_sub(1),
        row: y.saturating_sub(1),
        modifiers,
    })))
}

/// A byte outside escape sequences, or the start of a UTF-8 character.
fn plain(buf: &[u8], alt: bool) -> Parsed {
    let m = if alt {
        KeyModifiers::ALT
    } else {
        KeyModifiers::NONE
    };
    let b = buf[0];
    let item = match b {
        b'\r' | b'\n' => key(KeyCode::Enter, m),
        b'\t' => key(KeyCode::Tab, m),
        0x7F | 0x08 => key(KeyCode::Backspace, m),
        0x00 => key(KeyCode::Char(' '), m | KeyModifiers::CONTROL),
        0x01..=0x1A => key(
            KeyCode::Char(char::from(b - 1 + b'a')),
            m | KeyModifiers::CONTROL,
        ),
        0x1C..=0x1F => key(
            KeyCode::Char(char::from(b - 0x1C + b'4')),
            m | KeyModifiers::CONTROL,
        ),
        0x20..=0x7E => key(KeyCode::Char(char::from(b)), m),
        _ => {
            let len = match b {
                0xC2..=0xDF => 2,
                0xE0..=0xEF => 3,
                0xF0..=0xF4 => 4,
                _ => return Parsed::Done(None, 1),
            };
            if buf.len() < len {
                return Parsed::Incomplete;
            }
            return match std::str::from_utf8(&buf[..len]) {
                Ok(s) => Parsed::Done(s.chars().next().and_then(|c| key(KeyCode::Char(c), m)), len),
                Err(_) => Parsed::Done(None, 1),
            };
        }
    };
    Parsed::Done(item, 1)
}

/// An operating system command (`ESC ]` already taken from `body`), ended by BEL or
/// `ESC \`: an OSC 4 colour reply is an item, anything else is dropped whole (never
/// read as keys).
fn osc(body: &[u8]) -> Parsed {
    let end = body.iter().enumerate().find_map(|(i, &b)| match b {
        0x07 => Some((i, 1)),
        0x1B => Some((i, 2)),
        _ => None,
    });
    match end {
        // `ESC` must be followed by `\`; its second byte may not have arrived yet.
        Some((i, 2)) if body.get(i + 1).is_none() => Parsed::Incomplete,
        Some((i, 2)) if body[i + 1] != b'\\' => Parsed::Done(None, 2 + i),
        Some((i, len)) => {
            let item =
                super::palette::parse_reply(&body[..i]).map(|(n, c)| Input::PaletteColor(n, c));
            Parsed::Done(item, 2 + i + len)
        }
        None => Parsed::Incomplete,
    }
}

/// Parses the start of `buf` (not empty).
fn parse(buf: &[u8]) -> Parsed {
    if buf[0] != 0x1B {
        return plain(buf, false);
    }
    let Some(&next) = buf.get(1) else {
        return Parsed::Incomplete;
    };
    match next {
        b'[' => {
            // Parameter and intermediate bytes, then a final byte in 0x40..=0x7E.
            match buf[2..].iter().position(|b| (0x40..=0x7E).contains(b)) {
                Some(i) => Parsed::Done(csi(&buf[2..2 + i], buf[2 + i]), 3 + i),
                None if buf[2..].iter().all(|b| (0x20..=0x3F).contains(b)) => Parsed::Incomplete,
                // A byte that cannot be in a sequence: drop up to it.
                None => Parsed::Done(None, 2),
            }
        }
        b']' => osc(&buf[2..]),
        b'O' => match buf.get(2) {
            None => Parsed::Incomplete,
            Some(&f) => {
                let code = match f {
                    b'A' => KeyCode::Up,
                    b'B' => KeyCode::Down,
                    b'C' => KeyCode::Right,
                    b'D' => KeyCode::Left,
                    b'H' => KeyCode::Home,
                    b'F' => KeyCode::End,
                    _ => return Parsed::Done(None, 3),
                };
                Parsed::Done(key(code, KeyModifiers::NONE), 3)
            }
        },
        0x1B => Parsed::Done(key(KeyCode::Esc, KeyModifiers::NONE), 1),
        _ => match plain(&buf[1..], true) {
            Parsed::Done(item, n) => Parsed::Done(item, n + 1),
            Parsed::Incomplete => Parsed::Incomplete,
        },
    }
}

impl Parser {
    /// Adds bytes that arrived at `now`.
    pub fn feed(&mut self, bytes: &[u8], now: Instant) {
        // ESC then, in a later read, a byte that does not start a sequence: the Esc
        // key and that byte (Alt+key comes as one write, ESC and key together).
        if self.buf == [0x1B] && bytes.first().is_some_and(|b| !b"[O".contains(b)) {
            self.buf.clear();
            self.esc = true;
        }
        self.buf.extend_from_slice(bytes);
        self.last = Some(now);
    }

    /// The next complete item, if any. An incomplete sequence at the end is kept until
    /// more bytes arrive or its wait runs out (see [`Parser::deadline`]).
    pub fn next(&mut self, now: Instant) -> Option<Input> {
        if std::mem::take(&mut self.esc) {
            return key(KeyCode::Esc, KeyModifiers::NONE);
        }
        while !self.buf.is_empty() {
            match parse(&self.buf) {
                Parsed::Done(item, n) => {
                    self.buf.drain(..n.min(self.buf.len()));
                    if item.is_some() {
                        return item;
                    }
                }
                Parsed::Incomplete => {
                    let expired = self.deadline().is_some_and(|d| now >= d);
                    if self.buf.len() > MAX_SEQUENCE || expired {
                        // A lone ESC is the Esc key; a broken sequence is dropped.
                        let lone = self.buf == [0x1B];
                        self.buf.clear();
                        if lone {
                            return key(KeyCode::Esc, KeyModifiers::NONE);
                        }
                    } else {
                        return None;
                    }
                }
            }
        }
        None
    }

    /// Bytes held for a sequence whose end has not arrived (at most
    /// [`MAX_SEQUENCE`] once [`Parser::next`] has returned `None`).
    #[must_use]
    pub fn pending(&self) -> usize {
        self.buf.len()
    }

    /// When pending incomplete input resolves on its own (a lone ESC becomes the Esc
    /// key, a broken sequence is dropped), if any is pending.
    #[must_use]
    pub fn deadline(&self) -> Option<Instant> {
        let wait = if self.buf == [0x1B] {
            ESC_WAIT
        } else {
            SEQUENCE_WAIT
        };
        self.last.filter(|_| !self.buf.is_empty()).map(|t| t + wait)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(p: &mut Parser, now: Instant) -> Vec<Input> {
        std::iter::from_fn(|| p.next(now)).collect()
    }

    fn k(code: KeyCode, m: KeyModifiers) -> Input {
        key(code, m).unwrap()
    }

    #[test]
    fn palette_replies_are_items_and_other_commands_are_not_keys() {
        let t = Instant::now();
        let mut p = Parser::default();
        p.feed(
            b"\x1b]4;1;rgb:cdcd/0000/0000\x1b\\\x1b]4;12;rgb:5c/5c/ff\x07",
            t,
        );
        p.feed(b"\x1b]11;rgb:0000/0000/0000\x1b\\x\x1b]4;2;rgb:00", t);
        assert_eq!(
            all(&mut p, t),
            [
                Input::PaletteColor(1, [205, 0, 0]),
                Input::PaletteColor(12, [92, 92, 255]),
                k(KeyCode::Char('x'), KeyModifiers::NONE),
            ]
        );
        // The rest of a reply split across reads, its terminator split too.
        p.feed(b"00/cdcd/0000\x1b", t);
        assert_eq!(all(&mut p, t), []);
        p.feed(b"\\q", t);
        assert_eq!(
            all(&mut p, t),
            [
                Input::PaletteColor(2, [0, 205, 0]),
                k(KeyCode::Char('q'), KeyModifiers::NONE),
            ]
        );
        // A reply that never ends is dropped after its wait, not read as keys.
        p.feed(b"\x1b]4;3;rgb:12/34", t);
        assert_eq!(all(&mut p, t + SEQUENCE_WAIT), []);
    }

    #[test]
    fn keys_and_sequences() {
        let t = Instant::now();
        let mut p = Parser::default();
        p.feed(b"q\x11\x1b[A\x1b[1;2B\x1b[5~\x1bOD\x03\t\xc3\xa9", t);
        assert_eq!(
            all(&mut p, t),
            [
                k(KeyCode::Char('q'), KeyModifiers::NONE),
                k(KeyCode::Char('q'), KeyModifiers::CONTROL),
                k(KeyCode::Up, KeyModifiers::NONE),
                k(KeyCode::Down, KeyModifiers::SHIFT),
                k(KeyCode::PageUp, KeyModifiers::NONE),
                k(KeyCode::Left, KeyModifiers::NONE),
                k(KeyCode::Char('c'), KeyModifiers::CONTROL),
                k(KeyCode::Tab, KeyModifiers::NONE),
                k(KeyCode::Char('é'), KeyModifiers::NONE),
            ]
        );
    }

    #[test]
    fn a_sequence_split_across_reads_is_not_esc() {
        let t = Instant::now();
        let mut p = Parser::default();
        p.feed(b"\x1b", t);
        assert_eq!(p.next(t + Duration::from_millis(100)), None);
        p.feed(b"[", t + Duration::from_millis(150));
        assert_eq!(p.next(t + Duration::from_millis(600)), None);
        p.feed(b"A", t + Duration::from_millis(700));
        let now = t + Duration::from_millis(700);
        assert_eq!(all(&mut p, now), [k(KeyCode::Up, KeyModifiers::NONE)]);
    }

    #[test]
    fn a_lone_esc_is_esc_after_its_wait() {
        let t = Instant::now();
        let mut p = Parser::default();
        p.feed(b"\x1b", t);
        assert_eq!(p.deadline(), Some(t + ESC_WAIT));
        assert_eq!(p.next(t + ESC_WAIT / 2), None);
        assert_eq!(
            p.next(t + ESC_WAIT),
            Some(k(KeyCode::Esc, KeyModifiers::NONE))
        );
        assert_eq!(p.deadline(), None);
        // ESC, then a key in a later read: Esc and the key, not Alt+key.
        p.feed(b"\x1b", t);
        p.feed(b"q", t);
        assert_eq!(
            all(&mut p, t),
            [
                k(KeyCode::Esc, KeyModifiers::NONE),
                k(KeyCode::Char('q'), KeyModifiers::NONE)
            ]
        );
        p.feed(b"\x1bq", t);
        assert_eq!(all(&mut p, t), [k(KeyCode::Char('q'), KeyModifiers::ALT)]);
        // A broken sequence is dropped after its wait, and what follows parses.
        p.feed(b"\x1b[12", t);
        assert_eq!(p.next(t + SEQUENCE_WAIT), None);
        p.feed(b"x", t);
        assert_eq!(all(&mut p, t), [k(KeyCode::Char('x'), KeyModifiers::NONE)]);
    }

    #[test]
    fn replies_mouse_and_garbage() {
        let t = Instant::now();
        let mut p = Parser::default();
        p.feed(
            b"\x1b[?62;22c\x1b[<0;10;5M\x1b[<32;11;5M\x1b[<0;11;5m\x1b[<65;1;1M",
            t,
        );
        let got = all(&mut p, t);
        assert_eq!(got[0], Input::DeviceAttributes);
        let mouse = |kind, column, row| {
            Input::Event(Event::Mouse(MouseEvent {
                kind,
                column,
                row,
                modifiers: KeyModifiers::NONE,
            }))
        };
        assert_eq!(
            got[1..],
            [
                mouse(MouseEventKind::Down(MouseButton::Left), 9, 4),
                mouse(MouseEventKind::Drag(MouseButton::Left), 10, 4),
                mouse(MouseEventKind::Up(MouseButton::Left), 10, 4),
                mouse(MouseEventKind::ScrollDown, 0, 0),
            ]
        );
        // An endless sequence is dropped once it passes the bound.
        p.feed(b"\x1b[", t);
        p.feed(&[b'1'; 100], t);
        assert_eq!(p.next(t), None);
        p.feed(b"a", t);
        assert_eq!(all(&mut p, t), [k(KeyCode::Char('a'), KeyModifiers::NONE)]);
    }
}

//! The 16 ANSI colours as a terminal shows them.
//!
//! Colours 0–15 are the terminal's (its theme's) choice: xterm's defaults, a
//! Solarized theme and a VGA-like console share only the names. A 16-colour frame is
//! fitted to the palette the terminal has, so the viewer asks the terminal for it
//! (OSC 4, [`query`]) and uses xterm's defaults where no answer comes. Indices 16–255
//! (the 6×6×6 cube and the grey ramp) are the same on every terminal that has them.

use super::color::{Rgb, indexed_rgb};

/// The RGB colours a terminal shows for indices 0–15 (16–255 are xterm's everywhere).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Palette {
    /// Where the colours come from, for the status line and the benchmark.
    pub name: &'static str,
    pub ansi: [Rgb; 16],
    /// The terminal said these are its colours (not an assumption): the 256-colour
    /// mode may then use them too.
    pub reported: bool,
}

impl Default for Palette {
    fn default() -> Self {
        Self::XTERM
    }
}

impl Palette {
    /// xterm's default colours, assumed where the terminal does not say.
    pub const XTERM: Self = Self {
        name: "xterm",
        reported: false,
        ansi: [
            [0, 0, 0],
            [205, 0, 0],
            [0, 205, 0],
            [205, 205, 0],
            [0, 0, 238],
            [205, 0, 205],
            [0, 205, 205],
            [229, 229, 229],
            [127, 127, 127],
            [255, 0, 0],
            [0, 255, 0],
            [255, 255, 0],
            [92, 92, 255],
            [255, 0, 255],
            [0, 255, 255],
            [255, 255, 255],
        ],
    };

    /// The 16 colours chafa assumes a terminal has (`term_colors_256` in chafa's
    /// `chafa/internal/chafa-color.c`; the same values in libchafa 1.12.4's data): it
    /// picks indices 0–15 by these values for `-c 16`, and for `-c 256` where one is
    /// nearest.
    pub const CHAFA: Self = Self {
        name: "chafa",
        reported: false,
        ansi: [
            [0x00, 0x00, 0x00],
            [0x80, 0x00, 0x00],
            [0x00, 0x70, 0x00],
            [0x70, 0x70, 0x00],
            [0x00, 0x00, 0x70],
            [0x70, 0x00, 0x70],
            [0x00, 0x70, 0x70],
            [0xc0, 0xc0, 0xc0],
            [0x40, 0x40, 0x40],
            [0xff, 0x00, 0x00],
            [0x00, 0xff, 0x00],
            [0xff, 0xff, 0x00],
            [0x00, 0x00, 0xff],
            [0xff, 0x00, 0xff],
            [0x00, 0xff, 0xff],
            [0xff, 0xff, 0xff],
        ],
    };

    /// The colour of index `i`.
    #[must_use]
    pub fn rgb(&self, i: u8) -> Rgb {
        match self.ansi.get(usize::from(i)) {
            Some(c) => *c,
            None => indexed_rgb(i),
        }
    }

    /// The index (0–15) of the entry nearest `c` (squared sRGB distance; the lowest
    /// index on a tie).
    #[must_use]
    pub fn nearest(&self, c: Rgb) -> u8 {
        let mut best = (i32::MAX, 0u8);
        for (i, p) in self.ansi.iter().enumerate() {
            let d = (0..3)
                .map(|k| (i32::from(p[k]) - i32::from(c[k])).pow(2))
                .sum::<i32>();
            if d < best.0 {
                best = (d, i as u8);
            }
        }
        best.1
    }

    /// This palette with entry `i` set to `c`, as the terminal reported it.
    #[must_use]
    pub fn with(mut self, i: u8, c: Rgb) -> Self {
        if let Some(e) = self.ansi.get_mut(usize::from(i)) {
            *e = c;
            self.name = "terminal";
            self.reported = true;
        }
        self
    }

    /// This palette, as reported by the terminal.
    #[must_use]
    pub fn reported(self) -> Self {
        Self {
            reported: true,
            ..self
        }
    }

    /// The index (0–255) of the 256-colour entry nearest `c`: the cube and grey ramp,
    /// and the 16 colours too where the terminal reported them (an assumed palette
    /// may be a theme's, so then they are left alone).
    #[must_use]
    pub fn nearest_256(&self, c: Rgb) -> u8 {
        let cube = super::color::nearest_256(c);
        if !self.reported {
            return cube;
        }
        let d = |p: Rgb| {
            (0..3)
                .map(|k| (i32::from(p[k]) - i32::from(c[k])).pow(2))
                .sum::<i32>()
        };
        let low = self.nearest(c);
        if d(self.ansi[usize::from(low)]) < d(indexed_rgb(cube)) {
            low
        } else {
            cube
        }
    }
}

/// The OSC 4 queries of colours 0–15 (`ESC ] 4 ; i ; ? ESC \`). A terminal that knows
/// them answers each with `ESC ] 4 ; i ; rgb:RRRR/GGGG/BBBB` and a terminator, in
/// order, before its answer to any query sent after them; one that does not ignores
/// them.
#[must_use]
pub fn query() -> Vec<u8> {
    let mut q = Vec::with_capacity(16 * 12);
    for i in 0..16 {
        q.extend_from_slice(format!("\x1b]4;{i};?\x1b\\").as_bytes());
    }
    q
}

/// The colour of an OSC 4 reply's body (`4;i;rgb:R/G/B`, the part between `ESC ]`
/// and the terminator): the index and its 8-bit RGB. Channels of 1–4 hex digits are
/// scaled to 8 bits, as X11 colour specifications are; anything else is `None`.
#[must_use]
pub fn parse_reply(body: &[u8]) -> Option<(u8, Rgb)> {
    let s = std::str::from_utf8(body).ok()?;
    let rest = s.strip_prefix("4;")?;
    let (index, spec) = rest.split_once(';')?;
    let index: u8 = index.parse().ok()?;
    let mut channels = spec.strip_prefix("rgb:")?.split('/');
    let mut rgb = [0u8; 3];
    for c in &mut rgb {
        let hex = channels.next()?;
        if hex.is_empty() || hex.len() > 4 || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
            return None;
        }
        let v = u32::from_str_radix(hex, 16).ok()?;
        let max = (1u32 << (4 * hex.len())) - 1;
        *c = ((v * 255 + max / 2) / max) as u8;
    }
    channels.next().is_none().then_some((index, rgb))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replies_parse_at_every_channel_width() {
        assert_eq!(
            parse_reply(b"4;7;rgb:e5e5/e5e5/e5e5"),
            Some((7, [229, 229, 229]))
        );
        assert_eq!(parse_reply(b"4;1;rgb:ff/00/80"), Some((1, [255, 0, 128])));
        assert_eq!(parse_reply(b"4;15;rgb:f/8/0"), Some((15, [255, 136, 0])));
        assert_eq!(
            parse_reply(b"4;2;rgb:fff/000/800"),
            Some((2, [255, 0, 128]))
        );
        for bad in [
            &b"4;7;rgb:e5e5/e5e5"[..],
            b"4;7;rgb:e5e5/e5e5/e5e5/e5e5",
            b"4;7;rgb:e5e5e/00/00",
            b"4;7;rgb:zz/00/00",
            b"4;7;rgb://00",
            b"4;300;rgb:00/00/00",
            b"4;7;?",
            b"10;rgb:00/00/00",
            b"\xff",
        ] {
            assert_eq!(parse_reply(bad), None, "{:?}", String::from_utf8_lossy(bad));
        }
    }

    #[test]
    fn the_query_asks_for_every_colour_once() {
        let q = String::from_utf8(query()).unwrap();
        for i in 0..16 {
            assert_eq!(q.matches(&format!("\x1b]4;{i};?\x1b\\")).count(), 1);
        }
    }

    #[test]
    fn nearest_is_exact_on_entries_and_past_16_is_the_cube() {
        for p in [Palette::XTERM, Palette::CHAFA] {
            for i in 0..16u8 {
                let n = p.nearest(p.rgb(i));
                assert_eq!(p.rgb(n), p.rgb(i));
            }
            assert_eq!(p.rgb(196), [255, 0, 0]);
        }
        assert_eq!(Palette::XTERM.with(7, [1, 2, 3]).rgb(7), [1, 2, 3]);
        assert_eq!(Palette::XTERM.with(20, [1, 2, 3]), Palette::XTERM);
    }

    #[test]
    fn the_256_colour_mode_uses_the_16_only_where_reported() {
        // chafa's 7 is #c0c0c0, between the grey ramp's #bcbcbc and #c6c6c6.
        let grey = [0xc0; 3];
        assert_eq!(
            Palette::CHAFA.nearest_256(grey),
            super::super::color::nearest_256(grey)
        );
        assert_eq!(Palette::CHAFA.reported().nearest_256(grey), 7);
        let reported = Palette::XTERM.with(3, [1, 2, 3]);
        assert_eq!(reported.nearest_256([1, 2, 3]), 3);
        assert_eq!(reported.nearest_256([255, 0, 0]), 196);
    }
}

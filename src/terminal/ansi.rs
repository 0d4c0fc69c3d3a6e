//! The output encoder: a frame of cells as the fewest bytes that make a terminal show
//! it, starting from a blank screen with the cursor at the frame's top left.
//!
//! Colours are SGR sequences in their shortest form (`3x`/`9x` for the 16 colours,
//! `38;5;n`, `38;2;r;g;b`), written only when they change, foreground and background
//! separately; a space needs no foreground and a full block no background, so neither
//! is changed for them. Trailing blank cells of a line are not written. No background
//! colour is left set at the end of a line (a terminal would paint scrolled or erased
//! space with it), and every attribute is reset at the end of the frame.

use std::io::{self, Write};

use ratatui::style::Color;

use super::glyphs::CellGlyph;
use super::{ColorMode, Palette};

/// Writes the SGR parameters that set the foreground (`fg`) or background colour `c`
/// in their shortest form (no `ESC [` or `m`): shared by every encoder.
pub fn color_params(out: &mut Vec<u8>, c: Color, fg: bool) {
    let base: u8 = if fg { 30 } else { 40 };
    let _ = match c {
        Color::Rgb(r, g, b) => write!(out, "{};2;{r};{g};{b}", base + 8),
        Color::Indexed(n) => write!(out, "{};5;{n}", base + 8),
        Color::Reset => write!(out, "{}", base + 9),
        named => {
            let i = super::color::ansi16_index(named).unwrap_or(7);
            let code = if i < 8 { base + i } else { base + 60 + i - 8 };
            write!(out, "{code}")
        }
    };
}

/// Writes SGR for whichever of the two colours changed, in one sequence.
fn set_colors(out: &mut Vec<u8>, cur: &mut (Color, Color), want: (Color, Color)) {
    if want == *cur {
        return;
    }
    out.extend_from_slice(b"\x1b[");
    if want.0 != cur.0 {
        color_params(out, want.0, true);
        if want.1 != cur.1 {
            out.push(b';');
        }
    }
    if want.1 != cur.1 {
        color_params(out, want.1, false);
    }
    out.push(b'm');
    *cur = want;
}

/// Encodes `rows` lines of `cols` cells (row-major) for a terminal of colour depth
/// `colors` whose 16 colours are `palette`. With `erase`, each line ends by erasing the rest of the terminal's line,
/// so the frame can be drawn over an earlier one (cursor-home animation).
pub fn write_frame(
    cells: &[CellGlyph],
    cols: usize,
    colors: ColorMode,
    palette: &Palette,
    erase: bool,
    out: &mut impl Write,
) -> io::Result<()> {
    let to = |c: Option<[u8; 3]>| match c {
        Some(c) if colors != ColorMode::None => colors.color(c, palette),
        _ => Color::Reset,
    };
    let mut buf = Vec::with_capacity(cells.len() * 4);
    let mut cur = (Color::Reset, Color::Reset);
    let mut ch_buf = [0u8; 4];
    for line in cells.chunks(cols.max(1)) {
        let blank = |g: &CellGlyph| g.ch == ' ' && to(g.bg) == Color::Reset;
        let end = line.iter().rposition(|g| !blank(g)).map_or(0, |i| i + 1);
        for g in &line[..end] {
            let fg = if g.ch == ' ' { cur.0 } else { to(g.fg) };
            let bg = if g.ch == '█' { cur.1 } else { to(g.bg) };
            set_colors(&mut buf, &mut cur, (fg, bg));
            buf.extend_from_slice(g.ch.encode_utf8(&mut ch_buf).as_bytes());
        }
        let keep_fg = cur.0;
        set_colors(&mut buf, &mut cur, (keep_fg, Color::Reset));
        if erase {
            buf.extend_from_slice(b"\x1b[K");
        }
        buf.push(b'\n');
    }
    if cur != (Color::Reset, Color::Reset) {
        buf.extend_from_slice(b"\x1b[0m");
    }
    out.write_all(&buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell(ch: char, fg: Option<[u8; 3]>, bg: Option<[u8; 3]>) -> CellGlyph {
        CellGlyph {
            ch,
            fg,
            bg,
            ..CellGlyph::EMPTY
        }
    }

    fn encode(cells: &[CellGlyph], cols: usize, colors: ColorMode) -> String {
        let mut out = Vec::new();
        write_frame(cells, cols, colors, &Palette::XTERM, false, &mut out).unwrap();
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn colours_are_written_only_when_they_change() {
        let red = Some([255, 0, 0]);
        let cells = [
            cell('▀', red, None),
            cell('▄', red, None),
            cell(' ', None, red),
            cell('█', red, None),
            cell(' ', None, None),
        ];
        // The space keeps the red foreground; the full block keeps the red background;
        // the trailing blank is not written; the background is cleared at the line's end.
        assert_eq!(
            encode(&cells, 5, ColorMode::Truecolor),
            "\x1b[38;2;255;0;0m▀▄\x1b[48;2;255;0;0m █\x1b[49m\n\x1b[0m"
        );
        assert_eq!(
            encode(&cells, 5, ColorMode::Ansi16),
            "\x1b[91m▀▄\x1b[101m █\x1b[49m\n\x1b[0m"
        );
        assert_eq!(encode(&cells, 5, ColorMode::None), "▀▄ █\n");
    }
}

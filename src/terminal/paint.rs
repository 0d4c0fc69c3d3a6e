//! The cell painter: what a terminal shows, painted back to pixels.
//!
//! Bytes go through a terminal emulator (the `vt100` crate) first, so what is painted
//! is what a terminal would show, not the viewer's own cell model: colours as the
//! escape sequences set them, inverse video, wrapping and scrolling included. Each
//! cell of the emulator's screen is resolved to a character and two RGB colours
//! ([`PaintCell`]) and painted at [`CELL_WIDTH`] × [`CELL_HEIGHT`] pixels with the
//! glyph geometry of [`super::shapes::ink`], the one the glyph fit uses.
//!
//! Indexed colours are resolved with a [`Palette`] (xterm's, chafa's, or any other
//! terminal's), which differ in the 16 ANSI colours only.

use std::collections::HashMap;
use std::num::NonZeroU16;

use image::RgbImage;

use super::color::{Rgb, to_linear, to_srgb};
use super::palette::Palette;
use super::shapes::ink;

/// Pixels per cell across.
pub const CELL_WIDTH: u32 = 8;
/// Pixels per cell down: cells are twice as tall as wide.
pub const CELL_HEIGHT: u32 = 16;
/// Ink samples per pixel along each axis. A pixel takes the mean of
/// `INK_SAMPLES²` point samples of `ink`, the way a font rasteriser anti-aliases: one
/// sample at the pixel centre would turn each braille dot (radius 1.3 px at 8×16)
/// into 4 pixels, a quarter of the cell instead of a third.
pub const INK_SAMPLES: u32 = 4;
/// The terminal's background where no colour is set: black, as the viewer assumes.
pub const DEFAULT_BG: Rgb = [0, 0, 0];
/// The terminal's foreground where no colour is set: xterm's colour 7.
pub const DEFAULT_FG: Rgb = [229, 229, 229];

const CELL_PIXELS: usize = (CELL_WIDTH * CELL_HEIGHT) as usize;

/// One cell as a terminal shows it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PaintCell {
    pub ch: char,
    pub fg: Rgb,
    pub bg: Rgb,
}

impl Default for PaintCell {
    fn default() -> Self {
        Self {
            ch: ' ',
            fg: DEFAULT_FG,
            bg: DEFAULT_BG,
        }
    }
}

/// A screen of resolved cells, row-major.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CellGrid {
    pub cols: u16,
    pub rows: u16,
    pub cells: Vec<PaintCell>,
}

/// A painted screen.
#[derive(Clone, Debug)]
pub struct Painted {
    /// sRGB, `cols · CELL_WIDTH × rows · CELL_HEIGHT` pixels.
    pub image: RgbImage,
    /// Cells whose character [`ink`] does not know, painted as their background.
    pub unpainted: usize,
}

/// Why a grid cannot be emulated or painted.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum PaintError {
    #[error("a screen of {cols}×{rows} cells has nothing to paint")]
    Empty { cols: u16, rows: u16 },
    #[error("a screen of {cols}×{rows} cells is too large to emulate or paint")]
    TooLarge { cols: u16, rows: u16 },
    #[error("a grid of {cols}×{rows} cells was given {len} cells")]
    Mismatch { cols: u16, rows: u16, len: usize },
}

fn vt_color(c: vt100::Color, default: Rgb, palette: &Palette) -> Rgb {
    match c {
        vt100::Color::Default => default,
        vt100::Color::Idx(i) => palette.rgb(i),
        vt100::Color::Rgb(r, g, b) => [r, g, b],
    }
}

/// The cell as shown on xterm's palette (see [`resolve_in`]).
#[must_use]
pub fn resolve(cell: &vt100::Cell) -> PaintCell {
    resolve_in(cell, &Palette::XTERM)
}

/// The cell as shown: the first character of its contents (a blank for none or for
/// the second half of a wide character, which is treated as one cell), its colours
/// with the defaults filled in and indices looked up in `palette`, fg and bg swapped
/// under inverse video.
#[must_use]
pub fn resolve_in(cell: &vt100::Cell, palette: &Palette) -> PaintCell {
    let ch = if cell.is_wide_continuation() {
        ' '
    } else {
        cell.contents().chars().next().unwrap_or(' ')
    };
    let mut fg = vt_color(cell.fgcolor(), DEFAULT_FG, palette);
    let mut bg = vt_color(cell.bgcolor(), DEFAULT_BG, palette);
    if cell.inverse() {
        std::mem::swap(&mut fg, &mut bg);
    }
    PaintCell { ch, fg, bg }
}

fn parser(cols: u16, rows: u16) -> Result<vt100::Parser, PaintError> {
    let r = rows.checked_add(1).and_then(NonZeroU16::new);
    match (r, NonZeroU16::new(cols)) {
        (Some(r), Some(c)) if rows > 0 => Ok(vt100::Parser::new(r, c, 0)),
        (None, Some(_)) => Err(PaintError::TooLarge { cols, rows }),
        _ => Err(PaintError::Empty { cols, rows }),
    }
}

/// Feeds `bytes` to the emulator the way a program's output reaches a terminal:
/// through a tty that turns each `\n` into `\r\n` (`onlcr`), which the emulator,
/// like a real terminal, does not do itself.
fn feed(p: &mut vt100::Parser, bytes: &[u8]) {
    let mut lines = bytes.split(|&b| b == b'\n');
    if let Some(first) = lines.next() {
        p.process(first);
    }
    for line in lines {
        p.process(b"\r\n");
        p.process(line);
    }
}

/// What a terminal of `cols × rows` cells with xterm's palette shows after printing
/// `bytes` (see [`emulate_in`]).
pub fn emulate(bytes: &[u8], cols: u16, rows: u16) -> Result<CellGrid, PaintError> {
    emulate_in(bytes, cols, rows, &Palette::XTERM)
}

/// What a terminal of `cols × rows` cells whose palette is `palette` shows after
/// printing `bytes`.
///
/// The emulator has one row more than the frame: a frame of `rows` lines each ended
/// by a newline leaves the cursor on the line below it, as when a shell prompt
/// follows the picture; with exactly `rows` rows that last newline would scroll the
/// first line away.
pub fn emulate_in(
    bytes: &[u8],
    cols: u16,
    rows: u16,
    palette: &Palette,
) -> Result<CellGrid, PaintError> {
    let mut p = parser(cols, rows)?;
    feed(&mut p, bytes);
    let screen = p.screen();
    let mut cells = Vec::with_capacity(usize::from(cols) * usize::from(rows));
    for r in 0..rows {
        for c in 0..cols {
            let cell = screen.cell(r, c).map(|c| resolve_in(c, palette));
            cells.push(cell.unwrap_or_default());
        }
    }
    Ok(CellGrid { cols, rows, cells })
}

/// The size in cells of what `bytes` print, as (columns, rows): the extent of the cells
/// that hold a character or a colour, on a screen twice as large as `cols × rows`
/// so that output larger than the frame shows as larger instead of wrapping.
pub fn printed_size(bytes: &[u8], cols: u16, rows: u16) -> Result<(u16, u16), PaintError> {
    let (Some(c2), Some(r2)) = (cols.checked_mul(2), rows.checked_mul(2)) else {
        return Err(PaintError::TooLarge { cols, rows });
    };
    let mut p = parser(c2, r2)?;
    feed(&mut p, bytes);
    let screen = p.screen();
    let (mut w, mut h) = (0, 0);
    for r in 0..r2 {
        for c in 0..c2 {
            let Some(cell) = screen.cell(r, c) else {
                continue;
            };
            let used =
                cell.has_contents() || cell.bgcolor() != vt100::Color::Default || cell.inverse();
            if used {
                w = w.max(c + 1);
                h = h.max(r + 1);
            }
        }
    }
    Ok((w, h))
}

/// The ink of `ch` at each pixel of a cell, row-major, or `None` if [`ink`] does not
/// know it.
fn cell_mask(ch: char) -> Option<Box<[f32; CELL_PIXELS]>> {
    let n = INK_SAMPLES;
    let mut mask = Box::new([0.0; CELL_PIXELS]);
    for py in 0..CELL_HEIGHT {
        for px in 0..CELL_WIDTH {
            let mut sum = 0.0;
            for j in 0..n {
                for i in 0..n {
                    let x = (px as f32 + (i as f32 + 0.5) / n as f32) / CELL_WIDTH as f32;
                    let y = (py as f32 + (j as f32 + 0.5) / n as f32) / CELL_HEIGHT as f32;
                    sum += ink(ch, x, y)?;
                }
            }
            mask[(py * CELL_WIDTH + px) as usize] = sum / (n * n) as f32;
        }
    }
    Some(mask)
}

/// Paints every cell: each pixel is `fg·a + bg·(1 − a)` in linear light, `a` the
/// glyph's ink over the pixel. Characters `ink` does not know are counted and
/// painted as their cell's background.
pub fn paint(grid: &CellGrid) -> Result<Painted, PaintError> {
    let (cols, rows) = (grid.cols, grid.rows);
    if cols == 0 || rows == 0 {
        return Err(PaintError::Empty { cols, rows });
    }
    let len = usize::from(cols) * usize::from(rows);
    if grid.cells.len() != len {
        return Err(PaintError::Mismatch {
            cols,
            rows,
            len: grid.cells.len(),
        });
    }
    let (w, h) = (u32::from(cols) * CELL_WIDTH, u32::from(rows) * CELL_HEIGHT);
    let mut buf = vec![0u8; w as usize * h as usize * 3];
    let mut masks: HashMap<char, Option<Box<[f32; CELL_PIXELS]>>> = HashMap::new();
    let mut unpainted = 0;
    let row_bytes = w as usize * 3;
    for (i, cell) in grid.cells.iter().enumerate() {
        let (cx, cy) = (i % usize::from(cols), i / usize::from(cols));
        let mask = masks.entry(cell.ch).or_insert_with(|| cell_mask(cell.ch));
        if mask.is_none() {
            unpainted += 1;
        }
        let lin = |c: Rgb| c.map(to_linear);
        let (fg, bg) = (lin(cell.fg), lin(cell.bg));
        for py in 0..CELL_HEIGHT as usize {
            let row = (cy * CELL_HEIGHT as usize + py) * row_bytes;
            for px in 0..CELL_WIDTH as usize {
                let a = mask
                    .as_ref()
                    .map_or(0.0, |m| m[py * CELL_WIDTH as usize + px]);
                let rgb = if a <= 0.0 {
                    cell.bg
                } else if a >= 1.0 {
                    cell.fg
                } else {
                    std::array::from_fn(|k| to_srgb(fg[k] * a + bg[k] * (1.0 - a)))
                };
                let at = row + (cx * CELL_WIDTH as usize + px) * 3;
                buf[at..at + 3].copy_from_slice(&rgb);
            }
        }
    }
    let image = RgbImage::from_raw(w, h, buf).ok_or(PaintError::TooLarge { cols, rows })?;
    Ok(Painted { image, unpainted })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(ch: char, fg: Rgb, bg: Rgb) -> Painted {
        let grid = CellGrid {
            cols: 1,
            rows: 1,
            cells: vec![PaintCell { ch, fg, bg }],
        };
        paint(&grid).unwrap()
    }

    fn fg_fraction(p: &Painted, fg: Rgb) -> f32 {
        let n = p.image.pixels().filter(|px| px.0 == fg).count();
        n as f32 / CELL_PIXELS as f32
    }

    #[test]
    fn a_full_block_paints_all_foreground() {
        let p = one('█', [255, 0, 0], [0, 0, 255]);
        assert!(p.image.pixels().all(|px| px.0 == [255, 0, 0]));
        assert_eq!(p.unpainted, 0);
        assert_eq!(p.image.dimensions(), (CELL_WIDTH, CELL_HEIGHT));
    }

    #[test]
    fn an_upper_half_block_splits_the_cell() {
        let (fg, bg) = ([200, 10, 10], [10, 200, 10]);
        let p = one('▀', fg, bg);
        for (x, y, px) in p.image.enumerate_pixels() {
            let want = if y < CELL_HEIGHT / 2 { fg } else { bg };
            assert_eq!(px.0, want, "({x}, {y})");
        }
    }

    #[test]
    fn full_braille_inks_about_a_third() {
        let p = one('⣿', [255, 255, 255], [0, 0, 0]);
        // Mean linear light over the cell: the dots' area.
        let sum: f32 = p.image.pixels().map(|px| to_linear(px.0[0])).sum();
        let cover = sum / CELL_PIXELS as f32;
        assert!((cover - 1.0 / 3.0).abs() < 0.03, "{cover}");
        // Fully inked pixels alone are fewer: the dots' rims are blended.
        assert!(fg_fraction(&p, [255, 255, 255]) < cover);
    }

    #[test]
    fn a_blend_is_done_in_linear_light() {
        // ▒ inks half of every pixel: white on black is 50 % light, sRGB 188, not 128.
        let p = one('▒', [255, 255, 255], [0, 0, 0]);
        assert!(p.image.pixels().all(|px| px.0 == [188, 188, 188]));
    }

    #[test]
    fn unknown_characters_are_counted_and_painted_as_background() {
        let p = one('\u{4E00}', [255, 255, 255], [1, 2, 3]);
        assert_eq!(p.unpainted, 1);
        assert!(p.image.pixels().all(|px| px.0 == [1, 2, 3]));
    }

    #[test]
    fn bytes_through_the_emulator_paint_a_red_cell() {
        let grid = emulate("\x1b[38;2;255;0;0m█".as_bytes(), 2, 1).unwrap();
        assert_eq!(grid.cells[0].ch, '█');
        assert_eq!(grid.cells[0].fg, [255, 0, 0]);
        assert_eq!(grid.cells[1], PaintCell::default());
        let p = paint(&grid).unwrap();
        assert_eq!(p.image.get_pixel(3, 7).0, [255, 0, 0]);
        assert_eq!(p.image.get_pixel(11, 7).0, DEFAULT_BG);
    }

    #[test]
    fn the_emulator_resolves_palettes_inverse_and_newlines() {
        // 256-colour fg, bright blue bg (SGR 104, index 12), inverse, and a second
        // line after a plain newline that starts at column 0 (the tty's onlcr).
        let bytes = "\x1b[38;5;196;104mA\x1b[7mB\x1b[0m\nC\n";
        let grid = emulate(bytes.as_bytes(), 3, 2).unwrap();
        let c = &grid.cells;
        assert_eq!(
            (c[0].ch, c[0].fg, c[0].bg),
            ('A', [255, 0, 0], [92, 92, 255])
        );
        assert_eq!(
            (c[1].ch, c[1].fg, c[1].bg),
            ('B', [92, 92, 255], [255, 0, 0])
        );
        assert_eq!((c[3].ch, c[3].fg, c[3].bg), ('C', DEFAULT_FG, DEFAULT_BG));
        assert_eq!(printed_size(bytes.as_bytes(), 3, 2), Ok((2, 2)));
    }

    #[test]
    fn a_full_frame_with_trailing_newlines_keeps_its_first_line() {
        let bytes = b"ab\ncd\n";
        let grid = emulate(bytes, 2, 2).unwrap();
        let text: String = grid.cells.iter().map(|c| c.ch).collect();
        assert_eq!(text, "abcd");
    }

    #[test]
    fn wide_characters_take_one_cell_and_empty_grids_are_errors() {
        let grid = emulate("\u{4E00}x".as_bytes(), 4, 1).unwrap();
        let text: String = grid.cells.iter().map(|c| c.ch).collect();
        assert_eq!(text, "\u{4E00} x ");
        assert_eq!(paint(&grid).unwrap().unpainted, 1);
        assert!(emulate(b"", 0, 5).is_err());
        assert!(emulate(b"", 5, 0).is_err());
        let empty = CellGrid {
            cols: 0,
            rows: 0,
            cells: vec![],
        };
        assert!(paint(&empty).is_err());
    }

    #[test]
    fn palettes_differ_in_the_ansi_colours_only() {
        // chafa's light grey (7) and dark grey (8), and its dim red, against xterm's.
        assert_eq!(Palette::CHAFA.rgb(7), [0xc0; 3]);
        assert_eq!(Palette::CHAFA.rgb(8), [0x40; 3]);
        assert_eq!(Palette::CHAFA.rgb(1), [0x80, 0, 0]);
        assert_eq!(Palette::XTERM.rgb(7), [229; 3]);
        assert_eq!(Palette::XTERM.rgb(8), [127; 3]);
        let differ: Vec<u8> = (0..=255)
            .filter(|&i| Palette::CHAFA.rgb(i) != Palette::XTERM.rgb(i))
            .collect();
        assert_eq!(differ, [1, 2, 3, 4, 5, 6, 7, 8, 12]);
        // The same bytes (SGR 37 and 100: colours 7 and 8; 38;5;1) on either terminal.
        let bytes = "\x1b[37;100mA\x1b[38;5;1;48;5;250mB".as_bytes();
        let x = emulate_in(bytes, 2, 1, &Palette::XTERM).unwrap();
        let c = emulate_in(bytes, 2, 1, &Palette::CHAFA).unwrap();
        assert_eq!((x.cells[0].fg, x.cells[0].bg), ([229; 3], [127; 3]));
        assert_eq!((c.cells[0].fg, c.cells[0].bg), ([0xc0; 3], [0x40; 3]));
        assert_eq!((x.cells[1].fg, c.cells[1].fg), ([205, 0, 0], [0x80, 0, 0]));
        assert_eq!(x.cells[1].bg, c.cells[1].bg);
        assert_eq!(emulate(bytes, 2, 1).unwrap(), x);
    }
}

//! Where each glyph puts its ink in its cell: block elements, quadrants, sextants, the
//! diagonal wedges, shades and braille dots drawn geometrically, printable ASCII and box
//! drawing from an 8×8 bitmap font (`font8x8`).
//!
//! The glyph fit builds its masks from [`ink`] at its sample positions and the cell
//! painter paints with it at pixel centres, so the two agree on what a glyph looks like.
//! Coordinates are the cell's: `x` to the right and `y` down, both in `[0, 1)`; a cell
//! is taken to be twice as tall as it is wide (8×16 pixels in the painter), which only
//! matters for the round braille dots.

/// Braille dot centres, by the pattern's sample index (row-major, 2 × 4).
const DOT_CENTRES: [(f32, f32); 8] = [
    (0.25, 0.125),
    (0.75, 0.125),
    (0.25, 0.375),
    (0.75, 0.375),
    (0.25, 0.625),
    (0.75, 0.625),
    (0.25, 0.875),
    (0.75, 0.875),
];

/// Radius of a braille dot in cell widths: eight dots of radius `r` on a 1 × 2 cell
/// cover `8πr² / 2`, a third of it, as the dots of common terminal fonts do.
pub const DOT_RADIUS: f32 = 0.162_867_5; // √(1 / 12π)

/// The braille pattern bit of each sample index (Unicode numbers the dots down the left
/// column, 1 2 3 7, then the right, 4 5 6 8).
pub const BRAILLE_BITS: [u32; 8] = [0x01, 0x08, 0x02, 0x10, 0x04, 0x20, 0x40, 0x80];

/// The diagonal wedges U+1FB3C–U+1FB67: the part of the cell on the side of the line
/// P→Q that holds corner C, as (C, P, Q) in sixths of the cell's width and height
/// (so 3 is the middle of a side, 2 and 4 the thirds). From the characters' names,
/// e.g. U+1FB3C LOWER LEFT BLOCK DIAGONAL LOWER MIDDLE LEFT TO LOWER CENTRE.
type P6 = (i8, i8);
const WEDGES: [(P6, P6, P6); 44] = [
    ((0, 6), (0, 4), (3, 6)), // U+1FB3C
    ((0, 6), (0, 4), (6, 6)),
    ((0, 6), (0, 2), (3, 6)),
    ((0, 6), (0, 2), (6, 6)),
    ((0, 6), (0, 0), (3, 6)), // U+1FB40
    ((6, 6), (0, 2), (3, 0)),
    ((6, 6), (0, 2), (6, 0)),
    ((6, 6), (0, 4), (3, 0)),
    ((6, 6), (0, 4), (6, 0)),
    ((6, 6), (0, 6), (3, 0)),
    ((6, 6), (0, 4), (6, 2)),
    ((6, 6), (3, 6), (6, 4)),
    ((6, 6), (0, 6), (6, 4)),
    ((6, 6), (3, 6), (6, 2)),
    ((6, 6), (0, 6), (6, 2)),
    ((6, 6), (3, 6), (6, 0)),
    ((0, 6), (3, 0), (6, 2)), // U+1FB4C
    ((0, 6), (0, 0), (6, 2)),
    ((0, 6), (3, 0), (6, 4)),
    ((0, 6), (0, 0), (6, 4)),
    ((0, 6), (3, 0), (6, 6)), // U+1FB50
    ((0, 6), (0, 2), (6, 4)),
    ((6, 0), (0, 4), (3, 6)), // U+1FB52: the complements of U+1FB3C… in the same order
    ((6, 0), (0, 4), (6, 6)),
    ((6, 0), (0, 2), (3, 6)),
    ((6, 0), (0, 2), (6, 6)),
    ((6, 0), (0, 0), (3, 6)),
    ((0, 0), (0, 2), (3, 0)),
    ((0, 0), (0, 2), (6, 0)),
    ((0, 0), (0, 4), (3, 0)),
    ((0, 0), (0, 4), (6, 0)),
    ((0, 0), (0, 6), (3, 0)),
    ((0, 0), (0, 4), (6, 2)),
    ((0, 0), (3, 6), (6, 4)),
    ((0, 0), (0, 6), (6, 4)),
    ((0, 0), (3, 6), (6, 2)), // U+1FB5F
    ((0, 0), (0, 6), (6, 2)),
    ((0, 0), (3, 6), (6, 0)),
    ((6, 0), (3, 0), (6, 2)),
    ((6, 0), (0, 0), (6, 2)),
    ((6, 0), (3, 0), (6, 4)),
    ((6, 0), (0, 0), (6, 4)),
    ((6, 0), (3, 0), (6, 6)),
    ((6, 0), (0, 2), (6, 4)), // U+1FB67
];

/// The sextant pattern (bit 0 top-left … bit 5 bottom-right) of U+1FB00–U+1FB3B,
/// which list the patterns in order but leave out the empty, full and half-column ones.
#[must_use]
pub fn sextant_pattern(ch: char) -> Option<u8> {
    let i = u32::from(ch).checked_sub(0x1FB00).filter(|&i| i < 60)?;
    let mut p = i + 1;
    if p >= 21 {
        p += 1;
    }
    if p >= 42 {
        p += 1;
    }
    Some(p as u8)
}

/// The quadrant bits (1 upper left, 2 upper right, 4 lower left, 8 lower right) of
/// U+2596–U+259F.
const QUADRANT_BITS: [u8; 10] = [4, 8, 1, 13, 9, 7, 11, 2, 6, 14];

fn font_ink(rows: &[u8; 8], x: f32, y: f32) -> f32 {
    let (col, row) = ((x * 8.0) as usize, (y * 8.0) as usize);
    f32::from(rows[row.min(7)] >> col.min(7) & 1)
}

/// Whether (x, y) is on corner `c`'s side of the line p→q (on the line counts as in).
fn wedge_ink((c, p, q): (P6, P6, P6), x: f32, y: f32) -> bool {
    let f = |v: i8| f32::from(v) / 6.0;
    let (px, py, qx, qy) = (f(p.0), f(p.1), f(q.0), f(q.1));
    let side = |x: f32, y: f32| (qx - px) * (y - py) - (qy - py) * (x - px);
    let s = side(x, y);
    let sc = side(f(c.0), f(c.1));
    s == 0.0 || (s > 0.0) == (sc > 0.0)
}

/// Ink of `ch` at the point (x, y) of its cell: 1 or 0 for solid shapes, the covered
/// fraction for the shades ░ ▒ ▓, `None` for a character it does not know.
#[must_use]
pub fn ink(ch: char, x: f32, y: f32) -> Option<f32> {
    let b = |v: bool| Some(f32::from(u8::from(v)));
    let c = u32::from(ch);
    match c {
        0x20 | 0xA0 | 0x2800 => Some(0.0),
        0x21..=0x7E => Some(font_ink(&font8x8::legacy::BASIC_LEGACY[c as usize], x, y)),
        0x2801..=0x28FF => {
            let col = usize::from(x >= 0.5);
            let row = ((y * 4.0) as usize).min(3);
            let i = row * 2 + col;
            let (cx, cy) = DOT_CENTRES[i];
            let (dx, dy) = (x - cx, 2.0 * (y - cy));
            b(c & BRAILLE_BITS[i] != 0 && dx * dx + dy * dy <= DOT_RADIUS * DOT_RADIUS)
        }
        0x2580 => b(y < 0.5),
        0x2581..=0x2587 => b(y >= 1.0 - (c - 0x2580) as f32 / 8.0),
        0x2588 => Some(1.0),
        0x2589..=0x258F => b(x < (0x2590 - c) as f32 / 8.0),
        0x2590 => b(x >= 0.5),
        0x2591..=0x2593 => Some((c - 0x2590) as f32 / 4.0),
        0x2594 => b(y < 0.125),
        0x2595 => b(x >= 0.875),
        0x2596..=0x259F => {
            let q = QUADRANT_BITS[(c - 0x2596) as usize];
            let bit = u8::from(x >= 0.5) + 2 * u8::from(y >= 0.5);
            b(q >> bit & 1 == 1)
        }
        0x2500..=0x257F => Some(font_ink(
            &font8x8::legacy::BOX_LEGACY[(c - 0x2500) as usize],
            x,
            y,
        )),
        0x1FB00..=0x1FB3B => {
            let p = sextant_pattern(ch)?;
            let bit = u8::from(x >= 0.5) + 2 * ((y * 3.0) as u8).min(2);
            b(p >> bit & 1 == 1)
        }
        0x1FB3C..=0x1FB67 => b(wedge_ink(WEDGES[(c - 0x1FB3C) as usize], x, y)),
        0x1FB68..=0x1FB6F | 0x1FB9A | 0x1FB9B => {
            // The triangles from each side to the centre: left, upper, right, lower.
            let tri = [
                x < y && x < 1.0 - y,
                y < x && y < 1.0 - x,
                x > y && x > 1.0 - y,
                y > x && y > 1.0 - x,
            ];
            // U+1FB68…6B are three quarters: all but the left, upper, right or lower
            // one (UPPER AND RIGHT AND LOWER is all but the left); U+1FB6C…6F one.
            // U+1FB9A and 9B are two opposite ones: upper and lower, left and right.
            if c == 0x1FB9A {
                return b(tri[1] || tri[3]);
            }
            if c == 0x1FB9B {
                return b(tri[0] || tri[2]);
            }
            let k = (c - 0x1FB68) as usize;
            if k < 4 { b(!tri[k]) } else { b(tri[k - 4]) }
        }
        _ => None,
    }
}

/// The fraction of a cell a glyph inks, from `n × n` point samples.
#[must_use]
pub fn coverage(ch: char, n: u32) -> Option<f32> {
    let mut sum = 0.0;
    for j in 0..n {
        for i in 0..n {
            let (x, y) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            sum += ink(ch, x, y)?;
        }
    }
    Some(sum / (n * n) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_cover_their_named_fraction() {
        let cases = [
            ('█', 1.0),
            ('▀', 0.5),
            ('▄', 0.5),
            ('▁', 0.125),
            ('▇', 0.875),
            ('▏', 0.125),
            ('▊', 0.75),
            ('▐', 0.5),
            ('▔', 0.125),
            ('▕', 0.125),
            ('▙', 0.75),
            ('▚', 0.5),
            ('▒', 0.5),
            ('\u{1FB6C}', 0.25),
            ('\u{1FB68}', 0.75),
            ('\u{1FB9B}', 0.5),
            ('\u{1FB3D}', 1.0 / 6.0), // lower left, from 2/3 down the left side to the lower right
        ];
        for (ch, want) in cases {
            let got = coverage(ch, 96).unwrap();
            assert!((got - want).abs() < 0.02, "{ch}: {got} vs {want}");
        }
    }

    #[test]
    fn braille_dots_cover_a_third_of_the_cell() {
        let got = coverage('⣿', 240).unwrap();
        assert!((got - 1.0 / 3.0).abs() < 0.01, "{got}");
        // ⠁ is dot 1: the top-left one only.
        assert_eq!(ink('⠁', 0.25, 0.125), Some(1.0));
        assert_eq!(ink('⠁', 0.75, 0.125), Some(0.0));
        assert_eq!(ink('⠁', 0.0, 0.0), Some(0.0));
    }

    #[test]
    fn wedge_pairs_are_complements() {
        for k in 0..22u32 {
            let a = char::from_u32(0x1FB3C + k).unwrap();
            let b = char::from_u32(0x1FB52 + k).unwrap();
            for j in 0..24 {
                for i in 0..24 {
                    let (x, y) = ((i as f32 + 0.37) / 24.0, (j as f32 + 0.61) / 24.0);
                    assert_eq!(
                        ink(a, x, y).unwrap() + ink(b, x, y).unwrap(),
                        1.0,
                        "{a:?} {b:?} at ({x}, {y})"
                    );
                }
            }
        }
    }

    #[test]
    fn three_quarter_triangles_complement_the_quarters() {
        // U+1FB68 is all but the left quarter (U+1FB6C), and so on round the sides.
        for k in 0..4u32 {
            let three = char::from_u32(0x1FB68 + k).unwrap();
            let one = char::from_u32(0x1FB6C + k).unwrap();
            for (x, y) in [(0.1, 0.5), (0.5, 0.1), (0.9, 0.5), (0.5, 0.9), (0.3, 0.2)] {
                assert_eq!(ink(three, x, y).unwrap() + ink(one, x, y).unwrap(), 1.0);
            }
        }
    }

    #[test]
    fn sextants_match_their_patterns() {
        for p in 1..63u8 {
            if p == 21 || p == 42 {
                continue;
            }
            let ch = crate::terminal::glyphs::sextant(p);
            assert_eq!(sextant_pattern(ch), Some(p));
        }
    }

    #[test]
    fn font_glyphs_have_their_shape() {
        // '|' is a vertical stroke: ink in the middle column, none at the sides.
        assert_eq!(ink('|', 0.45, 0.5), Some(1.0));
        assert_eq!(ink('|', 0.05, 0.5), Some(0.0));
        assert_eq!(ink('_', 0.5, 0.95), Some(1.0));
        assert_eq!(ink('_', 0.5, 0.3), Some(0.0));
        assert!(ink('\u{4E00}', 0.5, 0.5).is_none());
    }
}

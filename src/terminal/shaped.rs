//! Cells of the shape-fitted modes (`blocks`, `wedges`, `ascii`): 4 × 8 samples
//! fitted by [`super::fit`], one cell at a time or eight in SIMD lanes straight from
//! the frame's rows, and the fit shown as a glyph and two colours.

use super::color::{ColorMode, to_linear};
use super::fit::{self, Repertoire};
use super::glyphs::{
    CellGlyph, DEFAULT_FG_LEVEL, FitSpace, GlyphMode, Sample, linear_luminance, merge_if_same,
};

/// The repertoire of a shape-fitted mode.
pub(super) fn repertoire(mode: GlyphMode) -> &'static Repertoire {
    match mode {
        GlyphMode::Blocks => Repertoire::blocks(),
        GlyphMode::Wedges => Repertoire::wedges(),
        _ => Repertoire::ascii(),
    }
}

/// Which samples of a cell are covered (bit `i`).
fn covered(samples: &[Sample]) -> u32 {
    samples
        .iter()
        .enumerate()
        .fold(0, |m, (i, s)| m | u32::from(s.covered) << i)
}

/// Fits a cell of 4 × 8 samples with the shapes of `rep`.
pub(super) fn shape_cell(
    rep: &Repertoire,
    samples: &[Sample],
    colors: ColorMode,
    space: FitSpace,
) -> CellGlyph {
    let mut x = [[0f32; 3]; fit::N];
    if colors == ColorMode::None {
        let l: [f32; fit::N] =
            std::array::from_fn(|i| samples.get(i).map_or(0.0, |s| linear_luminance(s.rgb)));
        let (ch, error) = fit::fit_ink(rep, &l, to_linear(DEFAULT_FG_LEVEL));
        let pattern = fit::mask_of(ch).unwrap_or(0);
        return CellGlyph {
            ch,
            pattern,
            error,
            ..CellGlyph::EMPTY
        };
    }
    for (px, s) in x.iter_mut().zip(samples) {
        *px = s.rgb.map(|v| space.encode(v));
    }
    glyph_of(&fit::fit(rep, &x), covered(samples), colors, space)
}

/// Fits up to 8 adjacent cells of a shape-fitted mode in colour, all at once, from the
/// frame's sample rows: `rows[j]` is sample row `j` of the cell row from the first
/// cell's first sample on (RGBA; alpha ≥ 128 is covered). Each of `out` gets
/// [`fit_cell`]'s result for its cell.
pub fn fit_cells8(
    mode: GlyphMode,
    colors: ColorMode,
    space: FitSpace,
    rows: [&[[u8; 4]]; fit::SY],
    out: &mut [CellGlyph],
) {
    debug_assert!(colors != ColorMode::None && out.len() <= 8);
    let n = out.len();
    // Coverage first: most batches of the background end here.
    let covered: [u32; 8] = std::array::from_fn(|l| {
        let mut m = 0;
        if l < n {
            for (j, row) in rows.iter().enumerate() {
                for (i, p) in row[l * fit::SX..(l + 1) * fit::SX].iter().enumerate() {
                    m |= u32::from(p[3] >= 128) << (j * fit::SX + i);
                }
            }
        }
        m
    });
    if covered.iter().all(|&c| c == 0) {
        out.fill(CellGlyph::EMPTY);
        return;
    }
    let table = space.table();
    let lanes: [[[f32; 8]; 3]; fit::N] = std::array::from_fn(|k| {
        let (i, j) = (k % fit::SX, k / fit::SX);
        std::array::from_fn(|c| {
            std::array::from_fn(|l| {
                if l < n {
                    table[usize::from(rows[j][l * fit::SX + i][c])]
                } else {
                    0.0
                }
            })
        })
    });
    let fits = fit::fit_lanes(repertoire(mode), &lanes);
    for (l, g) in out.iter_mut().enumerate() {
        *g = if covered[l] == 0 {
            CellGlyph::EMPTY
        } else {
            glyph_of(&fits[l], covered[l], colors, space)
        };
    }
}

/// The glyph and colours that show a fit: a side with no covered sample is the
/// terminal's own background (with the complementary glyph if that puts it there).
fn glyph_of(f: &fit::Fit, covered: u32, colors: ColorMode, space: FitSpace) -> CellGlyph {
    let srgb = |c: [f32; 3]| c.map(|v| space.decode(v));
    let Some(sh) = f.shape else {
        return CellGlyph {
            error: f.error,
            ..CellGlyph::uniform(srgb(f.on))
        };
    };
    let (inked, bare) = (0..fit::N)
        .filter(|&i| covered >> i & 1 == 1)
        .fold((false, false), |(i, b), k| {
            (i || sh.weights[k] > 0.0, b || sh.weights[k] < 1.0)
        });
    let (ch, pattern, fg, bg) = if !bare {
        (sh.ch, sh.mask, srgb(f.on), None)
    } else if let (false, Some(inv)) = (inked, sh.inverse) {
        (inv, !sh.mask, srgb(f.off), None)
    } else {
        (sh.ch, sh.mask, srgb(f.on), Some(srgb(f.off)))
    };
    merge_if_same(
        CellGlyph {
            ch,
            fg: Some(fg),
            bg,
            pattern,
            error: f.error,
        },
        colors,
    )
}

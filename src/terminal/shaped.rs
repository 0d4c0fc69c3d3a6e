//! Cells of the shape-fitted modes (`blocks`, `wedges`, `ascii`): 4 × 8 samples
//! fitted by [`super::fit`], one cell at a time or eight in SIMD lanes straight from
//! the frame's rows, and the fit shown as a glyph and two colours.

use super::Palette;
use super::color::{ColorMode, Rgb, to_linear};
use super::fit::{self, FitPalette, Repertoire};
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

/// Fits a cell of 4 × 8 samples with the shapes of `rep`, the 16 colours (if
/// `colors` has only those) being `palette`.
pub(super) fn shape_cell(
    rep: &Repertoire,
    samples: &[Sample],
    colors: ColorMode,
    space: FitSpace,
    palette: &Palette,
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
    if colors == ColorMode::Ansi16 {
        let pal = FitPalette::new(palette, |v| space.encode(v));
        return palette_glyph(rep, &x, covered(samples), &pal);
    }
    glyph_of(&fit::fit(rep, &x), covered(samples), colors, space, palette)
}

/// The glyph and two entries of a 16-colour palette that fit samples `x` best (see
/// [`fit::fit_palette`]); a side with no covered sample is the terminal's own
/// background, as in [`glyph_of`].
fn palette_glyph(
    rep: &Repertoire,
    x: &[[f32; 3]; fit::N],
    covered: u32,
    pal: &FitPalette,
) -> CellGlyph {
    let f = fit::fit_palette(rep, x, pal);
    let (on, off) = (pal.rgb[usize::from(f.on)], pal.rgb[usize::from(f.off)]);
    show_shape(f.shape, covered, on, off, f.error)
}

/// The cell showing shape `sh` (`None`: a space on `off`) in `on` over `off`: where no
/// covered sample is bare the background is left to the terminal, and where none is
/// inked the inverse glyph (if any) puts the terminal's background on that side.
fn show_shape(sh: Option<&fit::Shape>, covered: u32, on: Rgb, off: Rgb, error: f32) -> CellGlyph {
    let Some(sh) = sh else {
        return CellGlyph {
            error,
            ..CellGlyph::uniform(off)
        };
    };
    let (inked, bare) = (covered & sh.touched != 0, covered & sh.partial != 0);
    let (ch, pattern, fg, bg) = if !bare {
        (sh.ch, sh.mask, on, None)
    } else if let (false, Some(inv)) = (inked, sh.inverse) {
        (inv, !sh.mask, off, None)
    } else {
        (sh.ch, sh.mask, on, Some(off))
    };
    CellGlyph {
        ch,
        fg: Some(fg),
        bg,
        pattern,
        error,
    }
}

/// Fits up to 8 adjacent cells of a shape-fitted mode in colour, all at once, from the
/// frame's sample rows: `rows[j]` is sample row `j` of the cell row from the first
/// cell's first sample on (RGBA; alpha ≥ 128 is covered). Each of `out` gets
/// [`fit_cell_in`](super::glyphs::fit_cell_in)'s result for its cell.
pub fn fit_cells8(
    mode: GlyphMode,
    colors: ColorMode,
    space: FitSpace,
    palette: &Palette,
    rows: [&[[u8; 4]]; fit::SY],
    out: &mut [CellGlyph],
) {
    debug_assert!(colors != ColorMode::None && out.len() <= 8);
    let n = out.len();
    let rep = repertoire(mode);
    #[cfg(target_arch = "x86_64")]
    if n == 8 && colors != ColorMode::Ansi16 && crate::simd::Isa::Avx2.is_supported() {
        // SAFETY: the CPU has the features the function is compiled for.
        let (covered, fits) = unsafe { gather_fit8_avx2(rep, space, rows) };
        show(out, &covered, fits.as_ref(), colors, space, palette);
        return;
    }
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
    if colors == ColorMode::Ansi16 {
        // The palette fit searches every pair of entries per glyph: one cell at a time.
        let pal = FitPalette::new(palette, |v| space.encode(v));
        for (l, g) in out.iter_mut().enumerate() {
            *g = if covered[l] == 0 {
                CellGlyph::EMPTY
            } else {
                let x = std::array::from_fn(|k| {
                    let p = rows[k / fit::SX][l * fit::SX + k % fit::SX];
                    [0, 1, 2].map(|c| table[usize::from(p[c])])
                });
                palette_glyph(rep, &x, covered[l], &pal)
            };
        }
        return;
    }
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
    show(
        out,
        &covered,
        Some(&fit::fit_lanes(rep, &lanes)),
        colors,
        space,
        palette,
    );
}

/// Each cell's glyph from its coverage and fit (`None`: no cell is covered).
fn show(
    out: &mut [CellGlyph],
    covered: &[u32; 8],
    fits: Option<&[fit::Fit; 8]>,
    colors: ColorMode,
    space: FitSpace,
    palette: &Palette,
) {
    let Some(fits) = fits else {
        out.fill(CellGlyph::EMPTY);
        return;
    };
    for (l, g) in out.iter_mut().enumerate() {
        *g = if covered[l] == 0 {
            CellGlyph::EMPTY
        } else {
            glyph_of(&fits[l], covered[l], colors, space, palette)
        };
    }
}

/// [`fit_cells8`] for 8 whole cells on AVX2: coverage and fit-space values gathered
/// into lanes with vector shuffles (each sample row's 32 pixels are four registers;
/// a transpose puts column `i` of the 8 cells in one), then the lane fit on AVX2
/// registers. The values have the bits of [`FitSpace::table`]'s: sRGB is the same
/// correctly rounded `v / 255`, linear light a gather from the table.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn gather_fit8_avx2<'r>(
    rep: &'r Repertoire,
    space: FitSpace,
    rows: [&[[u8; 4]]; fit::SY],
) -> ([u32; 8], Option<[fit::Fit<'r>; 8]>) {
    use std::arch::x86_64::*;
    // Pixel `(i, j)` of the 8 cells (RGBA as little-endian u32 lanes), `k = j·4 + i`.
    let mut px = [_mm256_setzero_si256(); fit::N];
    // Bit `l` of byte `k`: cell `l`'s sample `k` is covered (alpha ≥ 128, its sign bit).
    let mut cover = [0u8; fit::N];
    let perm = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
    for (j, row) in rows.iter().enumerate() {
        let row = &row[..8 * fit::SX];
        let p = row.as_ptr().cast::<__m256i>();
        // Loops, not closures: a closure would not have the function's target features.
        let mut q = [_mm256_setzero_si256(); 4];
        for (k, v) in q.iter_mut().enumerate() {
            // SAFETY: `row` holds 32 pixels of 4 bytes, four unaligned 32-byte loads.
            *v = _mm256_permutevar8x32_epi32(unsafe { _mm256_loadu_si256(p.add(k)) }, perm);
        }
        // q[k] = cells 2k and 2k + 1 interleaved, column by column (64-bit pairs).
        let (lo01, hi01) = (
            _mm256_unpacklo_epi64(q[0], q[1]),
            _mm256_unpackhi_epi64(q[0], q[1]),
        );
        let (lo23, hi23) = (
            _mm256_unpacklo_epi64(q[2], q[3]),
            _mm256_unpackhi_epi64(q[2], q[3]),
        );
        let cols = [
            _mm256_permute2x128_si256::<0x20>(lo01, lo23),
            _mm256_permute2x128_si256::<0x20>(hi01, hi23),
            _mm256_permute2x128_si256::<0x31>(lo01, lo23),
            _mm256_permute2x128_si256::<0x31>(hi01, hi23),
        ];
        for (i, v) in cols.into_iter().enumerate() {
            let k = j * fit::SX + i;
            px[k] = v;
            cover[k] = _mm256_movemask_ps(_mm256_castsi256_ps(v)) as u8;
        }
    }
    // SAFETY: `cover` is 32 bytes.
    let cover = unsafe { _mm256_loadu_si256(cover.as_ptr().cast()) };
    // Cell `l`'s 32 bits are bit `l` of every byte: shifted to the byte's sign.
    let mut covered = [0u32; 8];
    for (l, c) in covered.iter_mut().enumerate() {
        let s = _mm_cvtsi32_si128(7 - l as i32);
        *c = _mm256_movemask_epi8(_mm256_sll_epi16(cover, s)) as u32;
    }
    if covered == [0; 8] {
        return (covered, None);
    }
    let mut lanes = [[[0f32; 8]; 3]; fit::N];
    let byte = _mm256_set1_epi32(0xFF);
    let table = space.table();
    for (k, v) in px.iter().enumerate() {
        let ch = [
            _mm256_and_si256(*v, byte),
            _mm256_and_si256(_mm256_srli_epi32::<8>(*v), byte),
            _mm256_and_si256(_mm256_srli_epi32::<16>(*v), byte),
        ];
        for (c, b) in ch.into_iter().enumerate() {
            let f = match space {
                FitSpace::Srgb => _mm256_div_ps(_mm256_cvtepi32_ps(b), _mm256_set1_ps(255.0)),
                // SAFETY: every index is a byte, the table has 256 entries.
                FitSpace::Linear => unsafe { _mm256_i32gather_ps::<4>(table.as_ptr(), b) },
            };
            // SAFETY: a store of 8 lanes into an array of 8.
            unsafe { _mm256_storeu_ps(lanes[k][c].as_mut_ptr(), f) };
        }
    }
    (
        covered,
        Some(fit::fit_lanes_on::<crate::simd::avx2::F32x8>(rep, &lanes)),
    )
}

/// The glyph and colours that show a fit: a side with no covered sample is the
/// terminal's own background (with the complementary glyph if that puts it there).
fn glyph_of(
    f: &fit::Fit,
    covered: u32,
    colors: ColorMode,
    space: FitSpace,
    palette: &Palette,
) -> CellGlyph {
    let srgb = |c: [f32; 3]| c.map(|v| space.decode(v));
    // A uniform fit's two colours are both the mean.
    let g = show_shape(f.shape, covered, srgb(f.on), srgb(f.off), f.error);
    if f.shape.is_none() {
        return g;
    }
    merge_if_same(g, colors, palette)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terminal::glyphs::fit_cell;

    #[test]
    fn cells_in_lanes_are_the_cells_one_by_one() {
        // Eight cells of random pixels (a random half of them covered), from a fixed
        // linear congruence; runs of fewer than 8 take the portable gather.
        let mut seed = 0x9E37_79B9u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 24) as u8
        };
        for round in 0..40 {
            let w = 8 * fit::SX;
            let frame: Vec<[u8; 4]> = (0..w * fit::SY)
                .map(|_| {
                    let rgb = [next(), next(), next()];
                    // Some batches all empty, some cells uniform.
                    let a = if round % 5 == 0 { 0 } else { next() };
                    if round % 7 == 3 {
                        [90, 91, 92, a]
                    } else {
                        [rgb[0], rgb[1], rgb[2], a]
                    }
                })
                .collect();
            for (mode, space) in [
                (GlyphMode::Blocks, FitSpace::Srgb),
                (GlyphMode::Wedges, FitSpace::Linear),
                (GlyphMode::Ascii, FitSpace::Srgb),
            ] {
                for n in [8, 5] {
                    let rows: [&[[u8; 4]]; fit::SY] =
                        std::array::from_fn(|j| &frame[j * w..j * w + n * fit::SX]);
                    let mut out = [CellGlyph::default(); 8];
                    fit_cells8(
                        mode,
                        ColorMode::Truecolor,
                        space,
                        &Palette::XTERM,
                        rows,
                        &mut out[..n],
                    );
                    for (l, got) in out[..n].iter().enumerate() {
                        let samples: Vec<Sample> = (0..fit::N)
                            .map(|k| {
                                let p = rows[k / fit::SX][l * fit::SX + k % fit::SX];
                                Sample {
                                    rgb: [p[0], p[1], p[2]],
                                    covered: p[3] >= 128,
                                }
                            })
                            .collect();
                        let want = if samples.iter().any(|s| s.covered) {
                            fit_cell(mode, &samples, ColorMode::Truecolor, space)
                        } else {
                            CellGlyph::EMPTY
                        };
                        assert_eq!(*got, want, "round {round} {mode:?} n {n} cell {l}");
                    }
                }
            }
        }
    }
}

//! The shape fit on a terminal of 16 colours: the glyph and the pair of palette
//! entries that minimise the squared error.
//!
//! Quantising the truecolor fit's two colours afterwards loses most of what the fit
//! found: on a palette with a few greys, a cell of a smooth gradient rounds both
//! colours to one entry and the shape's edge disappears, and the best glyph for two
//! palette colours is often not the best for two free ones. So with a palette the fit
//! searches (glyph, background, foreground) triples: every pair of entries for each of
//! the [`CANDIDATES`] glyphs that fit best with two free colours.
//!
//! For a glyph of weights `α` the error of background `p` and foreground `q` is
//! `E = A|p|² + B|q|² + 2C p·q − 2p·P − 2q·Q + Σx²` with `A = Σ(1−α)²`, `B = Σα²`,
//! `C = Σα(1−α)`, `P = Σ(1−α)x` and `Q = Σαx`: with the palette's dot products
//! `G = pᵢ·pⱼ` formed once, each of the 256 pairs costs three operations. A glyph's
//! error with two free colours is a lower bound of every pair's, so the candidates are
//! tried best first and the search stops once that bound passes the best pair found.
//!
//! A glyph is drawn only where it removes a clear share of the best single entry's
//! error ([`GLYPH_GAIN`]): see there for why.

use super::{N, Repertoire, Shape};
use crate::terminal::Palette;
use crate::terminal::color::Rgb;

/// A palette's 16 colours in a fit space, with their dot products.
#[derive(Clone, Debug)]
pub struct FitPalette {
    pub rgb: [Rgb; 16],
    /// Each entry in the fit space.
    pub x: [[f32; 3]; 16],
    /// `gram[i][j] = xᵢ·xⱼ`.
    gram: [[f32; 16]; 16],
    /// The entries by channel (`chan[c][i]`) and their squared norms, for loops over
    /// the 16 entries that compile to vector operations.
    chan: [[f32; 16]; 3],
    norm: [f32; 16],
}

impl FitPalette {
    /// `palette`'s 16 colours encoded by `encode` (an 8-bit channel to the fit space).
    #[must_use]
    pub fn new(palette: &Palette, encode: impl Fn(u8) -> f32) -> Self {
        let x = palette.ansi.map(|c| c.map(&encode));
        let gram = std::array::from_fn(|i| std::array::from_fn(|j| dot(x[i], x[j])));
        Self {
            rgb: palette.ansi,
            x,
            gram,
            chan: std::array::from_fn(|c| std::array::from_fn(|i| x[i][c])),
            norm: std::array::from_fn(|i| gram[i][i]),
        }
    }
}

/// A cell's glyph and two palette entries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaletteFit<'r> {
    /// The shape, or `None` when one entry is best.
    pub shape: Option<&'r Shape>,
    /// Palette indices of the ink and of the background (equal when uniform).
    pub on: u8,
    pub off: u8,
    /// Squared error of the fit.
    pub error: f32,
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The best (background, foreground) pair of `pal` for a glyph with `Σα = a` and
/// `Σα² = b` over the cell's samples, which sum to `t` and whose ink-weighted sum is
/// `q`; and its error less `Σx²`.
fn best_pair(pal: &FitPalette, a: f32, b: f32, t: [f32; 3], q: [f32; 3]) -> (u8, u8, f32) {
    let (ca, cb, c2) = (N as f32 - 2.0 * a + b, b, 2.0 * (a - b));
    let p = [t[0] - q[0], t[1] - q[1], t[2] - q[2]];
    // Per background i: A|xᵢ|² − 2xᵢ·P; per foreground j: B|xⱼ|² − 2xⱼ·Q. Each pair
    // adds 2C·xᵢ·xⱼ. Elementwise over the 16 entries, so these loops are vector code.
    let side = |w: f32, v: [f32; 3]| -> [f32; 16] {
        let mut out = [0.0; 16];
        for (k, o) in out.iter_mut().enumerate() {
            *o = w * pal.norm[k]
                - 2.0 * (pal.chan[0][k] * v[0] + pal.chan[1][k] * v[1] + pal.chan[2][k] * v[2]);
        }
        out
    };
    let (bg, fg) = (side(ca, p), side(cb, q));
    // The best background for each foreground, then the best foreground.
    let mut col = [f32::INFINITY; 16];
    for (i, row) in pal.gram.iter().enumerate() {
        for (c, g) in col.iter_mut().zip(row) {
            *c = c.min(bg[i] + c2 * g);
        }
    }
    let mut best = (0usize, f32::INFINITY);
    for j in 0..16 {
        let e = fg[j] + col[j];
        if e < best.1 {
            best = (j, e);
        }
    }
    let j = best.0;
    // The background that gave it (the same sums, so the same bits).
    let i = (0..16)
        .find(|&i| bg[i] + c2 * pal.gram[i][j] == col[j])
        .unwrap_or(0);
    (i as u8, j as u8, best.1)
}

/// The share of the best single entry's error a glyph must remove to be drawn. With
/// only a few levels, the glyph of least error at a smooth gradient traces the level
/// boundary through every cell, which shows as a texture of thin stripes that the
/// model does not have; requiring a clear gain keeps flat areas flat and still draws
/// edges (measured with `termrast bench fidelity`: the best trade of SSIM and PSNR).
pub const GLYPH_GAIN: f32 = 0.3;

/// Most shapes of a repertoire.
const MAX_SHAPES: usize = 256;

/// How many shapes, those of least error with two free colours, are tried with every
/// pair. The pair search dominates a 16-colour frame, and searching every shape
/// nearly doubles the frame for no visible gain (`termrast bench fidelity`: the
/// wedges' SSIM moves in the fourth decimal); `docs/performance.md` has the figures.
pub const CANDIDATES: usize = 32;

/// The shape of `rep` and the two entries of `pal` closest to the samples `x` (in the
/// palette's fit space, row-major 4 × 8) in summed squared error, over every shape and
/// pair; a single entry (a space) wins unless a glyph removes `GLYPH_GAIN` of its
/// error.
#[must_use]
pub fn fit_palette<'r>(rep: &'r Repertoire, x: &[[f32; 3]; N], pal: &FitPalette) -> PaletteFit<'r> {
    let (rs, sq) = super::subset_sums(x);
    let t = rs.iter().fold([0.0f32; 3], |a, row| {
        [a[0] + row[15][0], a[1] + row[15][1], a[2] + row[15][2]]
    });
    let n = N as f32;
    // One entry: `N|xᵢ|² − 2xᵢ·T`.
    let (mut single, mut entry) = (f32::INFINITY, 0u8);
    for i in 0..16 {
        let e = n * pal.gram[i][i] - 2.0 * dot(pal.x[i], t);
        if e < single {
            (single, entry) = (e, i as u8);
        }
    }
    // A glyph must reach this (less Σx²) to be drawn.
    let needed = (single + sq) * (1.0 - GLYPH_GAIN) - sq;
    let (mut best_e, mut on, mut off, mut shape) = (needed, 0u8, 0u8, None);
    let tt = dot(t, t);
    // Every shape's least error with two free colours (less Σx²): it bounds every
    // pair's, so the pairs of the best free shapes are searched, best first, until the
    // bound passes the best pair found.
    let mut free = [(f32::INFINITY, 0u16); MAX_SHAPES];
    let shapes = &rep.shapes[..rep.shapes.len().min(MAX_SHAPES)];
    for (k, sh) in shapes.iter().enumerate() {
        let y = sh.weighted(&rs, 0.0, |w| w);
        let score = (sh.b * tt - 2.0 * sh.a * dot(t, y) + n * dot(y, y)) * sh.inv_det;
        free[k] = (-score, k as u16);
    }
    let free = &mut free[..shapes.len()];
    let k = CANDIDATES.min(free.len());
    if k < free.len() {
        free.select_nth_unstable_by(k, |a, b| a.0.total_cmp(&b.0));
    }
    let top = &mut free[..k];
    top.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    for &(bound, s) in top.iter() {
        if bound >= best_e {
            break;
        }
        let sh = &shapes[usize::from(s)];
        let y = sh.weighted(&rs, 0.0, |w| w);
        let (i, j, e) = best_pair(pal, sh.a, sh.b, t, y);
        // A pair of one entry is no glyph, and no better than the single entry.
        if e < best_e && i != j {
            (best_e, on, off, shape) = (e, j, i, Some(sh));
        }
    }
    match shape {
        Some(_) => PaletteFit {
            shape,
            on,
            off,
            error: (best_e + sq).max(0.0),
        },
        None => PaletteFit {
            shape: None,
            on: entry,
            off: entry,
            error: (single + sq).max(0.0),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The error of glyph weights `w` in colours `f` on `b`, summed directly.
    fn direct(w: &[f32; N], x: &[[f32; 3]; N], f: [f32; 3], b: [f32; 3]) -> f32 {
        (0..N)
            .map(|k| {
                (0..3)
                    .map(|c| (b[c] + w[k] * (f[c] - b[c]) - x[k][c]).powi(2))
                    .sum::<f32>()
            })
            .sum()
    }

    fn palette() -> FitPalette {
        FitPalette::new(&Palette::XTERM, |v| f32::from(v) / 255.0)
    }

    /// The least error of glyph weights `w` with two free colours (least squares of
    /// the samples on `[1 − w, w]`, channel by channel).
    fn free(w: &[f32; N], x: &[[f32; 3]; N]) -> f64 {
        let (mut a, mut b, mut c) = (0.0f64, 0.0f64, 0.0f64);
        for &wk in w {
            let (u, v) = (1.0 - f64::from(wk), f64::from(wk));
            (a, b, c) = (a + u * u, b + v * v, c + u * v);
        }
        let det = a * b - c * c;
        (0..3)
            .map(|ch| {
                let (mut p, mut q, mut xx) = (0.0f64, 0.0f64, 0.0f64);
                for (k, &wk) in w.iter().enumerate() {
                    let s = f64::from(x[k][ch]);
                    (p, q, xx) = (
                        p + (1.0 - f64::from(wk)) * s,
                        q + f64::from(wk) * s,
                        xx + s * s,
                    );
                }
                if det <= 1e-9 {
                    // A glyph of one colour: the mean.
                    let n = N as f64;
                    let t = p + q;
                    return xx - t * t / n;
                }
                let (bg, fg) = ((b * p - c * q) / det, (a * q - c * p) / det);
                xx - bg * p - fg * q
            })
            .sum()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// Every pair of entries (and every single entry) for every glyph among the
        /// [`CANDIDATES`] best with free colours, summed sample by sample: nothing
        /// beats the fit. Glyphs whose free error ties with the last candidate may or
        /// may not be among them, so only those strictly better are required.
        #[test]
        fn the_palette_fit_is_the_brute_force_optimum_over_its_candidates(
            cells in prop::collection::vec(prop::array::uniform3(0u8..=255), N),
            split in 0usize..N,
            wedges in any::<bool>(),
        ) {
            let pal = palette();
            // Two regions of colours, as at an edge, or noise.
            let x: [[f32; 3]; N] = std::array::from_fn(|k| {
                let c = if k < split { cells[0] } else { cells[k] };
                c.map(|v| f32::from(v) / 255.0)
            });
            let rep = if wedges { Repertoire::wedges() } else { Repertoire::blocks() };
            let got = fit_palette(rep, &x, &pal);
            let w = got.shape.map_or([0.0; N], |s| s.weights);
            let shown = direct(&w, &x, pal.x[usize::from(got.on)], pal.x[usize::from(got.off)]);
            prop_assert!((shown - got.error).abs() <= 1e-3 * (1.0 + shown), "{shown} {}", got.error);
            let mut single = f32::INFINITY;
            for i in 0..16 {
                single = single.min(direct(&[0.0; N], &x, pal.x[i], pal.x[i]));
            }
            let mut by_free: Vec<f64> = rep.shapes.iter().map(|sh| free(&sh.weights, &x)).collect();
            by_free.sort_by(f64::total_cmp);
            let last = by_free[CANDIDATES.min(by_free.len()) - 1];
            let mut glyph = f32::INFINITY;
            for sh in rep.shapes.iter().filter(|sh| free(&sh.weights, &x) < last - 1e-4) {
                for i in 0..16 {
                    for j in (0..16).filter(|&j| j != i) {
                        glyph = glyph.min(direct(&sh.weights, &x, pal.x[j], pal.x[i]));
                    }
                }
            }
            let tol = 1e-3 * (1.0 + single);
            let needed = single * (1.0 - GLYPH_GAIN);
            if got.shape.is_some() {
                prop_assert!(got.error <= needed + tol, "a glyph of too little gain: {} {single}", got.error);
                prop_assert!(got.error <= glyph + tol, "fit {} brute force {glyph}", got.error);
            } else if glyph < needed - tol {
                prop_assert!(false, "a space where a glyph gains enough: {glyph} {single}");
            } else {
                prop_assert!((got.error - single).abs() <= tol, "space {} brute force {single}", got.error);
            }
        }
    }

    #[test]
    fn an_entry_pair_in_its_shape_fits_exactly() {
        let pal = palette();
        let w = super::super::weights_of('▞').unwrap();
        let (f, b) = (pal.x[12], pal.x[3]);
        let x: [[f32; 3]; N] =
            std::array::from_fn(|k| [0, 1, 2].map(|c| b[c] + w[k] * (f[c] - b[c])));
        let got = fit_palette(Repertoire::blocks(), &x, &pal);
        // ▞ and ▚ are one shape with the colours swapped.
        let want = match got.shape.map(|s| s.ch) {
            Some('▞') => (12, 3),
            Some('▚') => (3, 12),
            other => panic!("{other:?}"),
        };
        assert_eq!((got.on, got.off), want);
        assert!(got.error < 1e-4);
        let grey = fit_palette(Repertoire::blocks(), &[pal.x[8]; N], &pal);
        assert_eq!((grey.shape, grey.on, grey.off), (None, 8, 8));
    }
}

//! The shape fit: a cell's glyph and two colours chosen from a repertoire of glyph
//! shapes so that the squared error over the cell's 4 × 8 samples is the smallest the
//! repertoire allows (the samples' encoding, sRGB or linear light, is the caller's:
//! see [`FitSpace`](super::glyphs::FitSpace)).
//!
//! A glyph drawn with foreground `f` and background `b` covers a fraction `αᵢ` of
//! sample `i`'s box (its weights, from [`shapes::ink`]), which the
//! eye sees as `b + αᵢ(f − b)`. For a fixed glyph the best `b` and `d = f − b` solve a
//! least-squares problem per channel whose normal equations involve only `X = Σxᵢ`
//! (the cell's sum, the same for every glyph) and `Y = Σαᵢxᵢ`; the error left is
//! `Σx² − (B|X|² − 2A·X·Y + n|Y|²)/(nB − A²)` with `A = Σα`, `B = Σα²`. `Σx²` is the
//! same for every glyph, so the fit keeps the glyph with the largest second term. For
//! a glyph that covers each sample wholly or not at all, `b` and `f` are the means of
//! the two sides and the term is the familiar `|S|²/m + |X − S|²/(n − m)`.
//!
//! Each glyph's weights are grouped, row by row, into a few (subset of the row's 4
//! samples, weight) terms: a cell's 16 subset sums per row are formed once, and a
//! glyph's `Y` is about ten of them, so a glyph costs about thirty-five operations.
//! [`fit_lanes`] does the same for 8 cells at once, one per lane.

use std::sync::OnceLock;

use super::shapes;

mod lanes;
mod palette;
pub use lanes::fit_lanes;
pub(super) use lanes::fit_lanes_on;
pub use palette::{FitPalette, PaletteFit, fit_palette};

/// Samples per cell across and down.
pub const SX: usize = 4;
pub const SY: usize = 8;
/// Samples per cell.
pub const N: usize = SX * SY;
/// The mask with every sample set.
pub const FULL: u32 = u32::MAX;
/// Most (row, subset, weight) terms of one glyph.
const MAX_TERMS: usize = 24;

/// The fraction of each sample's box a glyph inks, from a 4 × 4 grid of points in the
/// box (so a multiple of 1/16). `None` for a glyph [`shapes::ink`] does not know.
#[must_use]
pub fn weights_of(ch: char) -> Option<[f32; N]> {
    let mut w = [0.0; N];
    for (k, a) in w.iter_mut().enumerate() {
        let (i, j) = (k % SX, k / SX);
        let mut ink = 0.0;
        for v in 0..4 {
            for u in 0..4 {
                let x = (i as f32 + (u as f32 + 0.5) / 4.0) / SX as f32;
                let y = (j as f32 + (v as f32 + 0.5) / 4.0) / SY as f32;
                ink += shapes::ink(ch, x, y)?;
            }
        }
        *a = ink / 16.0;
    }
    Some(w)
}

/// The samples a glyph inks at least half of.
#[must_use]
pub fn mask_of(ch: char) -> Option<u32> {
    let w = weights_of(ch)?;
    Some((0..N).fold(0, |m, k| m | u32::from(w[k] >= 0.5) << k))
}

/// One term of a glyph's weighted sum: `weight ×` the sum of row `row`'s samples in
/// `subset` (bit `i` for column `i`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Term {
    row: u8,
    subset: u8,
    weight: f32,
}

/// A glyph shape of a repertoire.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shape {
    /// The glyph whose ink is `weights`, drawn in the foreground colour.
    pub ch: char,
    /// A glyph whose ink is `1 − weights`, if the repertoire has one: with it the two
    /// colours can trade places (so an uncovered side can be the terminal's own
    /// background).
    pub inverse: Option<char>,
    /// Ink per sample, row-major.
    pub weights: [f32; N],
    /// The samples inked at least half (bit `j·4 + i` for sample (i, j)).
    pub mask: u32,
    /// The samples it inks at all, and those it does not ink wholly.
    pub(super) touched: u32,
    pub(super) partial: u32,
    terms: [Term; MAX_TERMS],
    n_terms: usize,
    /// `Σα`, `Σα²` and `1 / (nΣα² − (Σα)²)`.
    a: f32,
    b: f32,
    inv_det: f32,
}

impl Shape {
    /// The shape of glyph `ch` with ink `w`; `None` if its ink is the same in every
    /// sample (then it is no better than one colour).
    fn new(ch: char, w: [f32; N]) -> Option<Self> {
        let a: f32 = w.iter().sum();
        let b: f32 = w.iter().map(|v| v * v).sum();
        let det = N as f32 * b - a * a;
        if det <= 1e-3 {
            return None;
        }
        let mut terms = [Term::default(); MAX_TERMS];
        let mut n_terms = 0;
        for row in 0..SY {
            let mut levels: Vec<f32> = w[row * SX..row * SX + SX]
                .iter()
                .copied()
                .filter(|&v| v > 0.0)
                .collect();
            levels.sort_by(f32::total_cmp);
            levels.dedup();
            for weight in levels {
                let subset = (0..SX).fold(0u8, |m, i| m | u8::from(w[row * SX + i] == weight) << i);
                if n_terms == MAX_TERMS {
                    return None;
                }
                terms[n_terms] = Term {
                    row: row as u8,
                    subset,
                    weight,
                };
                n_terms += 1;
            }
        }
        Some(Self {
            ch,
            inverse: None,
            weights: w,
            mask: (0..N).fold(0, |m, k| m | u32::from(w[k] >= 0.5) << k),
            touched: (0..N).fold(0, |m, k| m | u32::from(w[k] > 0.0) << k),
            partial: (0..N).fold(0, |m, k| m | u32::from(w[k] < 1.0) << k),
            terms,
            n_terms,
            a,
            b,
            inv_det: 1.0 / det,
        })
    }

    /// The glyph's weighted sums of the cell's row subset sums `rs`, per channel.
    #[inline(always)]
    fn weighted<T: Copy + std::ops::Add<Output = T> + std::ops::Mul<Output = T>>(
        &self,
        rs: &[[[T; 3]; 16]; SY],
        zero: T,
        splat: impl Fn(f32) -> T,
    ) -> [T; 3] {
        let mut y = [zero; 3];
        for t in &self.terms[..self.n_terms] {
            let v = rs[usize::from(t.row)][usize::from(t.subset)];
            if t.weight == 1.0 {
                y = [y[0] + v[0], y[1] + v[1], y[2] + v[2]];
            } else {
                let w = splat(t.weight);
                y = [y[0] + v[0] * w, y[1] + v[1] * w, y[2] + v[2] * w];
            }
        }
        y
    }
}

/// The glyph shapes a cell may take, one per distinct ink (an ink and its complement
/// count once: swapping the colours turns one into the other).
#[derive(Debug)]
pub struct Repertoire {
    pub shapes: Vec<Shape>,
    /// Glyphs of uniform ink (a shade's covered fraction), for fits without colour.
    pub fills: &'static [(char, f32)],
}

impl Repertoire {
    /// The shapes of `chars`, in order: where two glyphs have the same ink, the first
    /// is kept. Glyphs of the same ink everywhere are left out; a cell of one colour is a
    /// space.
    #[must_use]
    pub fn new(chars: impl IntoIterator<Item = char>) -> Self {
        let mut shapes: Vec<Shape> = Vec::new();
        for ch in chars {
            let Some(w) = weights_of(ch) else { continue };
            let inverse = w.map(|v| 1.0 - v);
            match shapes
                .iter_mut()
                .find(|s| s.weights == w || s.weights == inverse)
            {
                Some(s) if s.weights == inverse && s.inverse.is_none() => s.inverse = Some(ch),
                Some(_) => {}
                None => shapes.extend(Shape::new(ch, w)),
            }
        }
        Self { shapes, fills: &[] }
    }
    /// Half blocks, quadrants, the lower and left eighths with the upper and right
    /// ones, and sextants. Unicode 1.1 blocks come first so that, where a sextant has
    /// the same ink, the more widely drawn glyph is used.
    pub fn blocks() -> &'static Self {
        static R: OnceLock<Repertoire> = OnceLock::new();
        R.get_or_init(|| Self::blocks_and(&[]))
    }

    /// [`Repertoire::blocks`] and the diagonal wedges (U+1FB3C–U+1FB6F).
    pub fn wedges() -> &'static Self {
        static R: OnceLock<Repertoire> = OnceLock::new();
        R.get_or_init(|| Self::blocks_and(&[0x1FB3C..=0x1FB6F]))
    }

    fn blocks_and(more: &[std::ops::RangeInclusive<u32>]) -> Self {
        let ranges = [
            0x2580..=0x2580,
            0x2584..=0x2584,
            0x258C..=0x258C,
            0x2590..=0x2590,
            0x2596..=0x259F,
            0x2581..=0x2587,
            0x2589..=0x258F,
            0x2594..=0x2595,
            0x1FB00..=0x1FB3B,
        ];
        let chars = ranges
            .into_iter()
            .chain(more.iter().cloned())
            .flatten()
            .filter_map(char::from_u32);
        Self {
            fills: &[('░', 0.25), ('▒', 0.5), ('▓', 0.75), ('█', 1.0)],
            ..Self::new(chars)
        }
    }

    /// Printable ASCII, shaped by the `font8x8` bitmaps.
    pub fn ascii() -> &'static Self {
        static R: OnceLock<Repertoire> = OnceLock::new();
        R.get_or_init(|| Self::new((0x21u8..=0x7E).map(char::from)))
    }
}

/// A cell's best glyph shape and colours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit<'r> {
    /// The shape, or `None` when one colour is best (a uniform cell).
    pub shape: Option<&'r Shape>,
    /// The foreground (ink) colour, and the background (the cell's mean when
    /// uniform), clamped to [0, 1].
    pub on: [f32; 3],
    pub off: [f32; 3],
    /// Squared error of the fit, and of the best single colour.
    pub error: f32,
    pub uniform_error: f32,
}

fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The shape and two colours of `rep` closest to the samples `x` (RGB in 0..1,
/// row-major 4 × 8) in summed squared error.
#[must_use]
pub fn fit<'r>(rep: &'r Repertoire, x: &[[f32; 3]; N]) -> Fit<'r> {
    let (rs, sq) = subset_sums(x);
    let t = rs.iter().fold([0.0; 3], |a, row| add(a, row[15]));
    let tt = dot(t, t);
    let uniform_score = tt / N as f32;
    let mut best = uniform_score;
    let mut best_shape = None;
    let mut best_y = t;
    for sh in &rep.shapes {
        let y = sh.weighted(&rs, 0.0, |w| w);
        let score = (sh.b * tt - 2.0 * sh.a * dot(t, y) + N as f32 * dot(y, y)) * sh.inv_det;
        if score > best {
            best = score;
            best_shape = Some(sh);
            best_y = y;
        }
    }
    finish(best_shape, t, best_y, sq, uniform_score, best)
}

/// Each sample row's 16 subset sums (each adding its samples from the highest column
/// down, the order the lanes keep) and the samples' summed squares.
fn subset_sums(x: &[[f32; 3]; N]) -> ([[[f32; 3]; 16]; SY], f32) {
    let mut sq = 0.0;
    let rs = std::array::from_fn(|r| {
        let px = &x[r * SX..r * SX + SX];
        for p in px {
            sq += dot(*p, *p);
        }
        std::array::from_fn(|s| {
            let mut acc = [0.0; 3];
            for (i, p) in px.iter().enumerate().rev() {
                if s >> i & 1 == 1 {
                    acc = add(acc, *p);
                }
            }
            acc
        })
    });
    (rs, sq)
}

/// A [`Fit`] from the winning shape's sums: `t` over the cell, `y` weighted by its ink,
/// `sq` the squared samples, and the uniform and best scores.
fn finish(
    shape: Option<&Shape>,
    t: [f32; 3],
    y: [f32; 3],
    sq: f32,
    uniform_score: f32,
    best: f32,
) -> Fit<'_> {
    let uniform_error = (sq - uniform_score).max(0.0);
    // A shape must beat one colour by more than rounding: on a uniform cell every
    // shape ties with the mean, and a tie is a space.
    match shape.filter(|_| best - uniform_score > 1e-6 * sq) {
        None => {
            let mean = t.map(|v| (v / N as f32).clamp(0.0, 1.0));
            Fit {
                shape: None,
                on: mean,
                off: mean,
                error: uniform_error,
                uniform_error,
            }
        }
        Some(sh) => {
            let n = N as f32;
            let b = [0, 1, 2].map(|c| (sh.b * t[c] - sh.a * y[c]) * sh.inv_det);
            let d = [0, 1, 2].map(|c| (n * y[c] - sh.a * t[c]) * sh.inv_det);
            Fit {
                shape: Some(sh),
                on: [0, 1, 2].map(|c| (b[c] + d[c]).clamp(0.0, 1.0)),
                off: b.map(|v| v.clamp(0.0, 1.0)),
                error: (sq - best).max(0.0),
                uniform_error,
            }
        }
    }
}

/// The glyph of `rep` (either orientation of a shape, one of its fills, or a space)
/// whose ink in colour `ink` on black best matches the luminances `l` after both are
/// box-filtered over 2 × 2 samples: without colour, a cell's brightness can only come
/// from how much of it is inked, so the fit matches ink density at that scale rather
/// than sample by sample (which would threshold every mid-tone to black or white).
#[must_use]
pub fn fit_ink(rep: &Repertoire, l: &[f32; N], ink: f32) -> (char, f32) {
    const BX: usize = SX / 2;
    let block = |v: &[f32; N], k: usize| {
        let (bi, bj) = (k % BX, k / BX);
        v[2 * bj * SX + 2 * bi]
            + v[2 * bj * SX + 2 * bi + 1]
            + v[(2 * bj + 1) * SX + 2 * bi]
            + v[(2 * bj + 1) * SX + 2 * bi + 1]
    };
    let blocks: [f32; N / 4] = std::array::from_fn(|k| block(l, k));
    let error_of = |w: &[f32; N]| {
        (0..blocks.len())
            .map(|k| (blocks[k] - ink * block(w, k)).powi(2))
            .sum::<f32>()
    };
    let mut best = (' ', f32::INFINITY);
    for &(ch, a) in [(' ', 0.0)].iter().chain(rep.fills) {
        let e = error_of(&[a; N]);
        if e < best.1 {
            best = (ch, e);
        }
    }
    for sh in &rep.shapes {
        for (ch, w) in [
            (Some(sh.ch), sh.weights),
            (sh.inverse, sh.weights.map(|v| 1.0 - v)),
        ] {
            let Some(ch) = ch else { continue };
            let e = error_of(&w);
            if e < best.1 {
                best = (ch, e);
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_masks_are_what_their_names_say() {
        assert_eq!(mask_of('▀'), Some(0x0000_FFFF));
        assert_eq!(mask_of('▌'), Some(0x3333_3333));
        assert_eq!(mask_of('▁'), Some(0xF000_0000));
        assert_eq!(mask_of('▎'), Some(0x1111_1111));
        assert_eq!(mask_of(' '), Some(0));
        // The top third of a sextant is the first three sample rows.
        assert_eq!(
            mask_of(super::super::glyphs::sextant(0b11)),
            Some(0x0000_0FFF)
        );
    }

    #[test]
    fn the_repertoire_has_one_shape_per_mask_pair() {
        for rep in [
            Repertoire::blocks(),
            Repertoire::wedges(),
            Repertoire::ascii(),
        ] {
            for (i, a) in rep.shapes.iter().enumerate() {
                for b in &rep.shapes[i + 1..] {
                    let inverse = b.weights.map(|v| 1.0 - v);
                    assert!(
                        a.weights != b.weights && a.weights != inverse,
                        "{} {}",
                        a.ch,
                        b.ch
                    );
                }
            }
        }
        let blocks = Repertoire::blocks();
        assert!(blocks.shapes.len() > 40, "{}", blocks.shapes.len());
        assert!(Repertoire::wedges().shapes.len() > blocks.shapes.len() + 20);
        // ▀ and ▄ are one shape, either way round.
        let half = blocks.shapes.iter().find(|s| s.ch == '▀').unwrap();
        assert_eq!(half.inverse, Some('▄'));
    }

    #[test]
    fn an_exact_shape_fits_with_no_error() {
        // What the eye sees of U+1FB3D in two colours: each sample its box's mix.
        let w = weights_of('\u{1FB3D}').unwrap();
        let x: [[f32; 3]; N] =
            std::array::from_fn(|k| [0.1, 0.2, 0.3].map(|b| b + w[k] * (0.8 - b)));
        let f = fit(Repertoire::wedges(), &x);
        assert_eq!(f.shape.map(|s| s.ch), Some('\u{1FB3D}'));
        assert!(f.error < 1e-4, "{}", f.error);
        assert!((f.on[0] - 0.8).abs() < 1e-4 && (f.off[2] - 0.3).abs() < 1e-4);
        let f = fit(Repertoire::blocks(), &[[0.5; 3]; N]);
        assert_eq!(f.shape, None);
    }

    #[test]
    fn lanes_give_the_scalar_bits() {
        // Eight cells: random colours in random places, from a fixed linear congruence.
        let mut seed = 0x2545_F491u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1 << 24) as f32
        };
        for _ in 0..50 {
            let cells: [[[f32; 3]; N]; 8] =
                std::array::from_fn(|_| std::array::from_fn(|_| [next(), next(), next()]));
            let lanes: [[[f32; 8]; 3]; N] =
                std::array::from_fn(|i| [0, 1, 2].map(|c| std::array::from_fn(|l| cells[l][i][c])));
            for rep in [Repertoire::wedges(), Repertoire::ascii()] {
                // The dispatched lanes (AVX2 where the CPU has it) and the portable ones.
                let got = fit_lanes(rep, &lanes);
                let portable = fit_lanes_on::<wide::f32x8>(rep, &lanes);
                for (l, cell) in cells.iter().enumerate() {
                    assert_eq!(got[l], fit(rep, cell), "lane {l}");
                    assert_eq!(portable[l], fit(rep, cell), "portable lane {l}");
                }
            }
        }
    }

    #[test]
    fn ink_fit_matches_density() {
        assert_eq!(fit_ink(Repertoire::blocks(), &[0.0; N], 1.0).0, ' ');
        assert_eq!(fit_ink(Repertoire::blocks(), &[1.0; N], 1.0).0, '█');
        assert_eq!(fit_ink(Repertoire::blocks(), &[0.5; N], 1.0).0, '▒');
        let mut l = [0.0; N];
        l[16..].fill(1.0);
        assert_eq!(fit_ink(Repertoire::blocks(), &l, 1.0).0, '▄');
    }
}

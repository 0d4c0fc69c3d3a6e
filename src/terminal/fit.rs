//! The shape fit: a cell's glyph and two colours chosen from a repertoire of glyph
//! shapes so that the squared error over the cell's 4 × 8 samples, in linear light, is
//! the smallest the repertoire allows.
//!
//! A glyph drawn with foreground `f` and background `b` shows `f` on its mask `M` (the
//! samples it inks, from [`shapes::ink`](super::shapes::ink)) and `b` on the rest. For a
//! fixed mask the best `f` and `b` are the means of the samples on each side, and the
//! error is `Σx² − |S|²/m − |T − S|²/(n − m)` with `S` the sum over the mask, `m` its
//! size and `T` the sum over the cell. `Σx²` is the same for every glyph, so the fit
//! keeps the glyph with the largest between-group part. Each row of a mask is one of
//! the 16 subsets of the row's 4 samples: a cell's 16 subset sums per row are formed
//! once, and a mask's sum is eight of them, so a glyph costs about thirty additions.

use std::sync::OnceLock;

use super::shapes;
use crate::simd::F32s;

/// Samples per cell across and down.
pub const SX: usize = 4;
pub const SY: usize = 8;
/// Samples per cell.
pub const N: usize = SX * SY;
/// The mask with every sample set.
pub const FULL: u32 = u32::MAX;

/// A glyph shape of a repertoire.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shape {
    /// The glyph that inks `mask` in the foreground colour.
    pub ch: char,
    /// A glyph that inks the complement of `mask`, if the repertoire has one: with it the
    /// two colours can trade places (so an uncovered side can be the terminal's own
    /// background).
    pub inverse: Option<char>,
    /// Bit `j·4 + i` for sample (i, j).
    pub mask: u32,
    rows: [u8; SY],
    inv_in: f32,
    inv_out: f32,
}

impl Shape {
    fn new(ch: char, mask: u32) -> Self {
        let m = mask.count_ones() as f32;
        Self {
            ch,
            inverse: None,
            mask,
            rows: std::array::from_fn(|r| (mask >> (r * SX) & 0xF) as u8),
            inv_in: 1.0 / m,
            inv_out: 1.0 / (N as f32 - m),
        }
    }
}

/// The samples a glyph inks: those whose box it covers at least half of (from a 4 × 4
/// grid of points in each box). `None` for a glyph [`shapes::ink`] does not know.
#[must_use]
pub fn mask_of(ch: char) -> Option<u32> {
    let mut mask = 0;
    for j in 0..SY {
        for i in 0..SX {
            let mut ink = 0.0;
            for v in 0..4 {
                for u in 0..4 {
                    let x = (i as f32 + (u as f32 + 0.5) / 4.0) / SX as f32;
                    let y = (j as f32 + (v as f32 + 0.5) / 4.0) / SY as f32;
                    ink += shapes::ink(ch, x, y)?;
                }
            }
            if ink >= 8.0 {
                mask |= 1 << (j * SX + i);
            }
        }
    }
    Some(mask)
}

/// The glyph shapes a cell may take, one per distinct mask (a mask and its complement
/// count once: swapping the colours turns one into the other).
#[derive(Debug)]
pub struct Repertoire {
    pub shapes: Vec<Shape>,
    /// Glyphs of uniform ink (a shade's covered fraction), for fits without colour.
    pub fills: &'static [(char, f32)],
}

impl Repertoire {
    /// The shapes of `chars`, in order: where two glyphs have the same mask, the first
    /// is kept. Empty and full masks are left out; a cell of one colour is a space.
    #[must_use]
    pub fn new(chars: impl IntoIterator<Item = char>) -> Self {
        let mut shapes: Vec<Shape> = Vec::new();
        for ch in chars {
            let Some(mask) = mask_of(ch) else { continue };
            if mask == 0 || mask == FULL {
                continue;
            }
            match shapes
                .iter_mut()
                .find(|s| s.mask == mask || s.mask == !mask)
            {
                Some(s) if s.mask == !mask && s.inverse.is_none() => s.inverse = Some(ch),
                Some(_) => {}
                None => shapes.push(Shape::new(ch, mask)),
            }
        }
        Self { shapes, fills: &[] }
    }

    /// Half blocks, quadrants, the lower and left eighths with the upper and right
    /// ones, sextants and the diagonal wedges (U+1FB3C–U+1FB6F). Unicode 1.1 blocks
    /// come first so that, where a legacy-computing glyph has the same mask, the more
    /// widely drawn one is used.
    pub fn blocks() -> &'static Self {
        static R: OnceLock<Repertoire> = OnceLock::new();
        R.get_or_init(|| {
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
                0x1FB3C..=0x1FB6F,
            ];
            Self {
                fills: &[('░', 0.25), ('▒', 0.5), ('▓', 0.75), ('█', 1.0)],
                ..Self::new(ranges.into_iter().flatten().filter_map(char::from_u32))
            }
        })
    }

    /// Printable ASCII, shaped by the `font8x8` bitmaps.
    pub fn ascii() -> &'static Self {
        static R: OnceLock<Repertoire> = OnceLock::new();
        R.get_or_init(|| Self::new((0x21u8..=0x7E).map(char::from)))
    }
}

/// A cell's best glyph shape and colours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// The shape, or `None` when one colour is best (a uniform cell).
    pub shape: Option<Shape>,
    /// Mean colour of the samples on the mask (the whole cell when uniform).
    pub on: [f32; 3],
    /// Mean colour of the rest.
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

/// The shape and two colours of `rep` closest to the samples `x` (linear RGB, row-major
/// 4 × 8) in summed squared error.
#[must_use]
pub fn fit(rep: &Repertoire, x: &[[f32; 3]; N]) -> Fit {
    let mut rs = [[[0f32; 3]; 16]; SY];
    let mut sq = 0.0;
    for (r, row) in rs.iter_mut().enumerate() {
        for s in 1..16usize {
            let px = x[r * SX + s.trailing_zeros() as usize];
            row[s] = add(row[s & (s - 1)], px);
        }
        for px in &x[r * SX..r * SX + SX] {
            sq += dot(*px, *px);
        }
    }
    let t = rs.iter().fold([0.0; 3], |a, row| add(a, row[15]));
    let uniform_score = dot(t, t) / N as f32;
    let mut best = uniform_score;
    let mut best_shape = None;
    let mut best_sum = t;
    for sh in &rep.shapes {
        let mut s = [0f32; 3];
        for (row, &sub) in rs.iter().zip(&sh.rows) {
            s = add(s, row[usize::from(sub)]);
        }
        let d = [t[0] - s[0], t[1] - s[1], t[2] - s[2]];
        let score = dot(s, s) * sh.inv_in + dot(d, d) * sh.inv_out;
        if score > best {
            best = score;
            best_shape = Some(sh);
            best_sum = s;
        }
    }
    finish(best_shape, t, best_sum, sq, uniform_score, best)
}

/// A [`Fit`] from the winning shape's sums: `t` over the cell, `s` over the mask, `sq`
/// the squared samples, and the uniform and best between-group scores.
fn finish(
    shape: Option<&Shape>,
    t: [f32; 3],
    s: [f32; 3],
    sq: f32,
    uniform_score: f32,
    best: f32,
) -> Fit {
    let mean = |s: [f32; 3], k: f32| s.map(|v| v * k);
    let uniform_error = (sq - uniform_score).max(0.0);
    match shape {
        None => Fit {
            shape: None,
            on: mean(t, 1.0 / N as f32),
            off: mean(t, 1.0 / N as f32),
            error: uniform_error,
            uniform_error,
        },
        Some(sh) => {
            let d = [t[0] - s[0], t[1] - s[1], t[2] - s[2]];
            Fit {
                shape: Some(*sh),
                on: mean(s, sh.inv_in),
                off: mean(d, sh.inv_out),
                error: (sq - best).max(0.0),
                uniform_error,
            }
        }
    }
}

/// [`fit`] for 8 cells at once, lane `k` holding cell `k`'s samples: the same
/// operations in the same order, so each lane's result has the same bits as [`fit`]'s.
#[must_use]
pub fn fit_lanes<F: F32s<Arr = [f32; 8]>>(rep: &Repertoire, x: &[[F; 3]; N]) -> [Fit; 8] {
    let zero = F::splat(0.0);
    let add3 = |a: [F; 3], b: [F; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
    let dot3 = |a: [F; 3], b: [F; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let mut rs = [[[zero; 3]; 16]; SY];
    let mut sq = zero;
    for (r, row) in rs.iter_mut().enumerate() {
        for s in 1..16usize {
            row[s] = add3(row[s & (s - 1)], x[r * SX + s.trailing_zeros() as usize]);
        }
        for px in &x[r * SX..r * SX + SX] {
            sq = sq + dot3(*px, *px);
        }
    }
    let t = rs.iter().fold([zero; 3], |a, row| add3(a, row[15]));
    let uniform_score = dot3(t, t) / F::splat(N as f32);
    let mut best = uniform_score;
    // The chosen shape's index + 1 (0: uniform) and sum over its mask.
    let mut best_k = zero;
    let mut best_sum = t;
    for (k, sh) in rep.shapes.iter().enumerate() {
        let mut s = [zero; 3];
        for (row, &sub) in rs.iter().zip(&sh.rows) {
            s = add3(s, row[usize::from(sub)]);
        }
        let d = [t[0] - s[0], t[1] - s[1], t[2] - s[2]];
        let score = dot3(s, s) * F::splat(sh.inv_in) + dot3(d, d) * F::splat(sh.inv_out);
        let better = score.gt(best);
        if better.bitmask() != 0 {
            best = F::select(better, score, best);
            best_k = F::select(better, F::splat((k + 1) as f32), best_k);
            best_sum = [0, 1, 2].map(|c| F::select(better, s[c], best_sum[c]));
        }
    }
    let (sq, uniform_score, best, best_k) = (
        sq.to_array(),
        uniform_score.to_array(),
        best.to_array(),
        best_k.to_array(),
    );
    let (t, best_sum) = (t.map(F::to_array), best_sum.map(F::to_array));
    std::array::from_fn(|l| {
        let lane = |v: [[f32; 8]; 3]| [v[0][l], v[1][l], v[2][l]];
        finish(
            (best_k[l] as usize).checked_sub(1).map(|k| &rep.shapes[k]),
            lane(t),
            lane(best_sum),
            sq[l],
            uniform_score[l],
            best[l],
        )
    })
}

/// The glyph of `rep` (either orientation of a shape, one of its fills, or a space) whose ink in
/// colour `ink` on black best matches the luminances `l` after both are box-filtered
/// over 2 × 2 samples: without colour, a cell's brightness can only come from how much
/// of it is inked, so the fit matches ink density at that scale rather than sample by
/// sample (which would threshold every mid-tone to black or white).
#[must_use]
pub fn fit_ink(rep: &Repertoire, l: &[f32; N], ink: f32) -> (char, f32) {
    const BX: usize = SX / 2;
    let mut blocks = [0f32; N / 4];
    for (k, b) in blocks.iter_mut().enumerate() {
        let (bi, bj) = (k % BX, k / BX);
        *b = l[2 * bj * SX + 2 * bi]
            + l[2 * bj * SX + 2 * bi + 1]
            + l[(2 * bj + 1) * SX + 2 * bi]
            + l[(2 * bj + 1) * SX + 2 * bi + 1];
    }
    let count = |mask: u32, k: usize| {
        let (bi, bj) = (k % BX, k / BX);
        let row = |j: usize| (mask >> (j * SX + 2 * bi) & 3).count_ones();
        (row(2 * bj) + row(2 * bj + 1)) as f32
    };
    let error_of = |counts: &dyn Fn(usize) -> f32| {
        (0..blocks.len())
            .map(|k| (blocks[k] - ink * counts(k)).powi(2))
            .sum::<f32>()
    };
    let mut best = (' ', f32::INFINITY);
    for &(ch, a) in [(' ', 0.0)].iter().chain(rep.fills) {
        let e = error_of(&|_| 4.0 * a);
        if e < best.1 {
            best = (ch, e);
        }
    }
    for sh in &rep.shapes {
        for (ch, mask) in [(Some(sh.ch), sh.mask), (sh.inverse, !sh.mask)] {
            let Some(ch) = ch else { continue };
            let e = error_of(&|k| count(mask, k));
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
        for rep in [Repertoire::blocks(), Repertoire::ascii()] {
            for (i, a) in rep.shapes.iter().enumerate() {
                for b in &rep.shapes[i + 1..] {
                    assert!(a.mask != b.mask && a.mask != !b.mask, "{} {}", a.ch, b.ch);
                }
            }
        }
        let blocks = Repertoire::blocks();
        // At 4 × 8 samples some eighths and wedges share a mask; 69 shapes remain.
        assert!(blocks.shapes.len() > 60, "{}", blocks.shapes.len());
        // ▀ and ▄ are one shape, either way round.
        let half = blocks.shapes.iter().find(|s| s.ch == '▀').unwrap();
        assert_eq!(half.inverse, Some('▄'));
    }

    #[test]
    fn an_exact_shape_fits_with_no_error() {
        let mut x = [[0.1, 0.2, 0.3]; N];
        for (k, px) in x.iter_mut().enumerate() {
            if mask_of('\u{1FB3D}').unwrap() >> k & 1 == 1 {
                *px = [0.9, 0.8, 0.7];
            }
        }
        let f = fit(Repertoire::blocks(), &x);
        assert_eq!(f.shape.map(|s| s.ch), Some('\u{1FB3D}'));
        assert!(f.error < 1e-4, "{}", f.error);
        assert!((f.on[0] - 0.9).abs() < 1e-6 && (f.off[2] - 0.3).abs() < 1e-6);
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
            let lanes: [[wide::f32x8; 3]; N] = std::array::from_fn(|i| {
                [0, 1, 2].map(|c| wide::f32x8::new(std::array::from_fn(|l| cells[l][i][c])))
            });
            for rep in [Repertoire::blocks(), Repertoire::ascii()] {
                let got = fit_lanes(rep, &lanes);
                for (l, cell) in cells.iter().enumerate() {
                    assert_eq!(got[l], fit(rep, cell), "lane {l}");
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

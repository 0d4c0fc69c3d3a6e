//! The two-colour split of up to 8 samples (half, quadrant, sextant and braille
//! cells): ordered by luminance, cut where the summed squared colour error of the two
//! groups is smallest.

use super::color::Rgb;
use super::glyphs::{CellGlyph, GlyphMode, Sample};

/// `1/m` for group sizes 0..=8 (0 for an empty group, whose sum is 0 anyway).
const INV: [f32; 9] = [
    0.0,
    1.0,
    1.0 / 2.0,
    1.0 / 3.0,
    1.0 / 4.0,
    1.0 / 5.0,
    1.0 / 6.0,
    1.0 / 7.0,
    1.0 / 8.0,
];

/// Sorts 8 keys ascending by the 19 compare-exchanges of an optimal sorting network:
/// branch-free, where a general sort of 8 keys per cell was a tenth of the glyph fit.
/// Written out so every index is a constant and the keys stay in registers (a loop over
/// a table of pairs went through memory at every exchange).
#[inline]
fn sort8(k: &mut [u32; 8]) {
    macro_rules! exchange {
        ($(($i:literal, $j:literal)),* $(,)?) => {
            $(
                let (a, b) = (k[$i], k[$j]);
                k[$i] = a.min(b);
                k[$j] = a.max(b);
            )*
        };
    }
    exchange!(
        (0, 2),
        (1, 3),
        (4, 6),
        (5, 7),
        (0, 4),
        (1, 5),
        (2, 6),
        (3, 7),
        (0, 1),
        (2, 3),
        (4, 5),
        (6, 7),
        (2, 4),
        (3, 5),
        (1, 4),
        (3, 6),
        (1, 2),
        (3, 4),
        (5, 6),
    );
}

/// The best split of the samples, ordered by luminance, into a dark and a bright group.
/// Prefix sums of colour and squared colour give each split's squared error
/// (`Σx² − (Σx)²/n` per channel) in constant time.
pub(super) fn fit_two_colours(mode: GlyphMode, samples: &[Sample]) -> CellGlyph {
    let n = samples.len().min(8);
    // Sort keys: integer Rec. 709 luminance (exact, unlike the f32 one), uncovered
    // samples first, the sample index in the low bits so ties keep index order.
    let mut keys = [u32::MAX; 8];
    for (k, s) in keys.iter_mut().zip(samples).take(n) {
        let [r, g, b] = s.rgb.map(u32::from);
        *k = u32::from(s.covered) * (2126 * r + 7152 * g + 722 * b + 1);
    }
    for (i, k) in keys.iter_mut().enumerate() {
        *k = *k << 3 | i as u32;
    }
    // Padding keys (u32::MAX) sort last, so the first n are the samples in order.
    sort8(&mut keys);
    let mut order = [0usize; 8];
    for (o, k) in order.iter_mut().zip(keys.iter()) {
        *o = (k & 7) as usize;
    }
    let order = &order[..n];
    // prefix[i] = sums over order[..i]: (Σr, Σg, Σb, Σr²+Σg²+Σb²). At most 8 samples
    // of 255: every sum and squared sum below fits u32 (and f32 exactly, < 2^24).
    let mut prefix = [[0u32; 4]; 9];
    for (i, &k) in order.iter().enumerate() {
        let c = samples[k].rgb.map(u32::from);
        let p = prefix[i];
        prefix[i + 1] = [
            p[0] + c[0],
            p[1] + c[1],
            p[2] + c[2],
            p[3] + c[0] * c[0] + c[1] * c[1] + c[2] * c[2],
        ];
    }
    let sse = |from: usize, to: usize| -> u32 {
        let m = (to - from) as u32;
        if m == 0 {
            return 0;
        }
        let (a, b) = (prefix[from], prefix[to]);
        let sq = b[3] - a[3];
        let lin: u32 = (0..3).map(|c| (b[c] - a[c]).pow(2)).sum();
        sq - lin / m
    };
    // Uncovered samples sort first and can only be background.
    let first_covered = order.iter().position(|&k| samples[k].covered).unwrap_or(n);
    // Σx² is the same for every split, so the split with the least squared error is
    // the one with the largest |S_a|²/a + |S_b|²/b (the between-group part). That is
    // compared in f32 (no division per split: the old two u64 divisions per split
    // were most of the fit), and the integer error computed once at the end.
    let norm2 = |p: &[u32; 4]| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) as f32;
    let total = prefix[n];
    let mut split = first_covered;
    let mut best = f32::NEG_INFINITY;
    for (cut, a) in prefix.iter().enumerate().take(n).skip(first_covered) {
        let b = [total[0] - a[0], total[1] - a[1], total[2] - a[2], 0];
        let part = |s: &[u32; 4], m: usize| norm2(s) * INV[m];
        let score = part(a, cut) + part(&b, n - cut);
        if score > best {
            (best, split) = (score, cut);
        }
    }
    let error = (sse(0, split) + sse(split, n)) as f32;
    let (dark, bright) = order.split_at(split);
    if dark.is_empty() {
        // One group: the cell is best shown as its mean colour.
        return CellGlyph {
            error,
            ..CellGlyph::uniform(mean(samples, 0..n).unwrap_or_default())
        };
    }
    // Braille dots ink a third of the cell, so the group they draw shows at a third of
    // its strength: they go on the smaller group, and the larger one covers the cell.
    let (dots, rest) = if mode == GlyphMode::Braille && bright.len() > dark.len() {
        (dark, bright)
    } else {
        (bright, dark)
    };
    let pattern = dots.iter().fold(0u32, |p, &i| p | 1 << i);
    let fg = mean(samples, dots.iter().copied());
    let bg = if rest.iter().all(|&i| !samples[i].covered) {
        None
    } else {
        mean(samples, rest.iter().copied())
    };
    // A dot inks a third of its sample: its colour is strengthened so that the sample
    // looks like its group's mean from a distance.
    let fg = if mode == GlyphMode::Braille {
        fg.map(|f| dot_colour(f, bg.unwrap_or([0; 3])))
    } else {
        fg
    };
    CellGlyph {
        ch: mode.pattern_glyph(pattern),
        fg,
        bg,
        pattern,
        error,
    }
}

/// The dot colour that makes a braille sample, a dot of a third of its area on `bg`,
/// look like `want` (in linear light, as the eye mixes them), as near as the
/// displayable range allows.
fn dot_colour(want: Rgb, bg: Rgb) -> Rgb {
    use super::color::{to_linear, to_srgb};
    let mut out = [0u8; 3];
    for c in 0..3 {
        let (w, b) = (to_linear(want[c]), to_linear(bg[c]));
        out[c] = to_srgb(b + 3.0 * (w - b));
    }
    out
}

fn mean(samples: &[Sample], idx: impl Iterator<Item = usize> + Clone) -> Option<Rgb> {
    let n = idx.clone().count() as u32;
    if n == 0 {
        return None;
    }
    let mut s = [0u32; 3];
    for i in idx {
        for (acc, v) in s.iter_mut().zip(samples[i].rgb) {
            *acc += u32::from(v);
        }
    }
    Some(s.map(|v| ((v + n / 2) / n) as u8))
}

#[cfg(test)]
mod sort_tests {
    use super::*;

    /// By the zero-one principle a comparator network sorts every input if it sorts
    /// every 0/1 input: all 256 of them.
    #[test]
    fn the_network_sorts_every_zero_one_input() {
        for bits in 0u32..256 {
            let mut k: [u32; 8] = std::array::from_fn(|i| bits >> i & 1);
            sort8(&mut k);
            assert!(k.windows(2).all(|w| w[0] <= w[1]), "{bits:08b} -> {k:?}");
        }
    }
}

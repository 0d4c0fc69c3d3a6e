//! Glyph modes and the choice of a cell's glyph and two colours from its samples.
//!
//! Samples are row-major within the cell. For the block and braille modes the cell is
//! fitted with two colours: samples are ordered by luminance and split where the summed
//! squared colour error of the two groups is smallest; the brighter group sets the
//! glyph's pattern and foreground, the darker one the background (or the terminal's
//! own background when that group is all uncovered).

use super::color::Rgb;

/// How a cell is divided into samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum GlyphMode {
    /// One sample, a luminance ramp of printable ASCII.
    Ascii,
    /// 1×2: upper half block with foreground and background.
    Half,
    /// 2×2 quadrant blocks.
    Quadrant,
    /// 2×3 sextants (Unicode 13 legacy computing symbols).
    Sextant,
    /// 2×4 braille dots.
    #[default]
    Braille,
}

/// The ASCII ramp, darkest first.
pub const ASCII_RAMP: &[u8] = b" .:-=+*#%@";

const QUADRANTS: [char; 16] = [
    ' ', '▘', '▝', '▀', '▖', '▌', '▞', '▛', '▗', '▚', '▐', '▜', '▄', '▙', '▟', '█',
];

impl GlyphMode {
    /// Cycling order.
    pub const ALL: [GlyphMode; 5] = [
        GlyphMode::Ascii,
        GlyphMode::Half,
        GlyphMode::Quadrant,
        GlyphMode::Sextant,
        GlyphMode::Braille,
    ];

    /// Samples per cell, (columns, rows).
    #[must_use]
    pub fn dims(self) -> (u32, u32) {
        match self {
            GlyphMode::Ascii => (1, 1),
            GlyphMode::Half => (1, 2),
            GlyphMode::Quadrant => (2, 2),
            GlyphMode::Sextant => (2, 3),
            GlyphMode::Braille => (2, 4),
        }
    }

    /// Name for the status line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            GlyphMode::Ascii => "ascii",
            GlyphMode::Half => "half",
            GlyphMode::Quadrant => "quadrant",
            GlyphMode::Sextant => "sextant",
            GlyphMode::Braille => "braille",
        }
    }

    /// The glyph showing the samples whose bits are set in `pattern` (bit i = sample
    /// i, row-major).
    #[must_use]
    pub fn pattern_glyph(self, pattern: u8) -> char {
        match self {
            GlyphMode::Ascii => {
                if pattern & 1 == 1 {
                    '#'
                } else {
                    ' '
                }
            }
            GlyphMode::Half => [' ', '▀', '▄', '█'][usize::from(pattern & 3)],
            GlyphMode::Quadrant => QUADRANTS[usize::from(pattern & 15)],
            GlyphMode::Sextant => sextant(pattern & 63),
            GlyphMode::Braille => braille(pattern),
        }
    }
}

/// Sextant glyph for a 6-bit pattern (bit 0 top-left … bit 5 bottom-right). U+1FB00…
/// lists the patterns in order but leaves out the empty, full and half-column ones,
/// which exist elsewhere.
#[must_use]
pub fn sextant(p: u8) -> char {
    match p {
        0 => ' ',
        21 => '▌',
        42 => '▐',
        63 => '█',
        _ => {
            let skip = u32::from(p > 21) + u32::from(p > 42);
            char::from_u32(0x1FB00 + u32::from(p) - 1 - skip).unwrap_or('?')
        }
    }
}

/// Braille glyph for an 8-bit pattern of a 2×4 cell, samples row-major. Braille
/// numbers its dots down the left column (1, 2, 3, then 7) and the right (4, 5, 6, 8).
#[must_use]
pub fn braille(p: u8) -> char {
    const DOT: [u32; 8] = [0x01, 0x08, 0x02, 0x10, 0x04, 0x20, 0x40, 0x80];
    let bits: u32 = (0..8).filter(|i| p >> i & 1 == 1).map(|i| DOT[i]).sum();
    char::from_u32(0x2800 + bits).unwrap_or(' ')
}

/// One sample: its colour and whether any geometry covered it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sample {
    pub rgb: Rgb,
    pub covered: bool,
}

/// Rec. 709 luminance of an 8-bit colour, 0..1.
#[must_use]
pub fn luma(c: Rgb) -> f32 {
    (0.2126 * f32::from(c[0]) + 0.7152 * f32::from(c[1]) + 0.0722 * f32::from(c[2])) / 255.0
}

/// A cell's glyph and colours. `Copy` and allocation-free: the viewer fits every
/// cell every frame; [`explain`] says why, on demand.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CellGlyph {
    pub ch: char,
    /// Foreground colour, or the terminal's default.
    pub fg: Option<Rgb>,
    /// Background colour, or the terminal's default.
    pub bg: Option<Rgb>,
    /// Samples drawn in the foreground.
    pub pattern: u8,
    /// Squared colour error of the fit (0 for exact modes).
    pub error: u32,
}

impl CellGlyph {
    const EMPTY: Self = Self {
        ch: ' ',
        fg: None,
        bg: None,
        pattern: 0,
        error: 0,
    };
}

/// Why [`fit_cell`] chose `g` for these samples, for the inspector.
#[must_use]
pub fn explain(mode: GlyphMode, samples: &[Sample], g: &CellGlyph) -> String {
    if samples.iter().all(|s| !s.covered) {
        return "no sample covered: blank".into();
    }
    if g.fg.is_none() && mode != GlyphMode::Ascii {
        return format!(
            "no colour: ordered dither, {} of {} samples bright enough",
            g.pattern.count_ones(),
            samples.len()
        );
    }
    match mode {
        GlyphMode::Ascii => format!(
            "luminance {:.2} on the ramp \" .:-=+*#%@\" → '{}'",
            luma(samples[0].rgb),
            g.ch
        ),
        GlyphMode::Half => "upper half block: top sample is fg, bottom is bg".into(),
        _ => {
            let bright = g.pattern.count_ones();
            format!(
                "2-colour fit by luminance split: {bright} bright (fg) / {} dark (bg) samples, squared error {}",
                samples.len() as u32 - bright,
                g.error
            )
        }
    }
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

/// Dither rank of each sample (row-major) per mode: thresholds `(rank + ½) / n` spread
/// so that brightness fills a cell evenly.
fn dither_rank(mode: GlyphMode) -> &'static [u8] {
    match mode {
        GlyphMode::Ascii => &[0],
        GlyphMode::Half => &[0, 1],
        GlyphMode::Quadrant => &[0, 2, 3, 1],
        GlyphMode::Sextant => &[0, 3, 4, 1, 2, 5],
        GlyphMode::Braille => &[0, 4, 6, 2, 3, 7, 5, 1],
    }
}

/// Chooses the glyph and colours of a cell from its samples (`mode.dims()` of them).
/// With `colorless`, block and braille modes carry shading by ordered dithering (a
/// sample is drawn when its luminance exceeds its threshold) instead of a two-colour
/// fit, since there are no colours to carry it.
#[must_use]
pub fn fit_cell(mode: GlyphMode, samples: &[Sample], colorless: bool) -> CellGlyph {
    if samples.iter().all(|s| !s.covered) {
        return CellGlyph::EMPTY;
    }
    if colorless && mode != GlyphMode::Ascii {
        let rank = dither_rank(mode);
        let n = samples.len() as f32;
        let pattern = samples
            .iter()
            .zip(rank)
            .enumerate()
            .fold(0u8, |p, (i, (s, &r))| {
                let on = s.covered && luma(s.rgb) >= (f32::from(r) + 0.5) / n;
                p | u8::from(on) << i
            });
        return CellGlyph {
            ch: mode.pattern_glyph(pattern),
            fg: None,
            bg: None,
            pattern,
            error: 0,
        };
    }
    match mode {
        GlyphMode::Ascii => {
            let s = samples[0];
            let l = luma(s.rgb);
            let i = ((l * (ASCII_RAMP.len() - 1) as f32).round() as usize)
                .clamp(1, ASCII_RAMP.len() - 1);
            let ch = ASCII_RAMP[i] as char;
            CellGlyph {
                ch,
                fg: Some(s.rgb),
                bg: None,
                pattern: 1,
                error: 0,
            }
        }
        GlyphMode::Half => {
            let (t, b) = (samples[0], samples[1]);
            let (ch, fg, bg, pattern) = match (t.covered, b.covered) {
                (true, true) => ('▀', Some(t.rgb), Some(b.rgb), 3),
                (true, false) => ('▀', Some(t.rgb), None, 1),
                _ => ('▄', Some(b.rgb), None, 2),
            };
            CellGlyph {
                ch,
                fg,
                bg,
                pattern,
                error: 0,
            }
        }
        _ => fit_two_colours(mode, samples),
    }
}

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
fn fit_two_colours(mode: GlyphMode, samples: &[Sample]) -> CellGlyph {
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
    let best_err = sse(0, split) + sse(split, n);
    let (dark, bright) = order.split_at(split);
    let pattern = bright.iter().fold(0u8, |p, &i| p | 1 << i);
    let fg = mean(samples, bright.iter().copied());
    let bg = mean(
        samples,
        dark.iter().copied().filter(|&i| samples[i].covered),
    );
    let error = best_err;
    CellGlyph {
        ch: mode.pattern_glyph(pattern),
        fg,
        bg,
        pattern,
        error,
    }
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

//! Glyph modes and the choice of a cell's glyph and two colours from its samples.
//!
//! Samples are row-major within the cell. `blocks` and `ascii` take 4 × 8 samples and
//! choose the glyph and two colours that minimise the squared error in linear light
//! over a repertoire of shapes ([`super::fit`]). The other modes split their samples,
//! ordered by luminance, where the summed squared colour error of the two groups is
//! smallest; block modes draw the brighter group in the foreground, braille puts its
//! dots on the smaller group (dots ink only a third of the cell, so the colour that
//! covers the cell's area is the background). A cell of one colour is a space on that
//! background in every mode that has one; without colour, shading is carried by ink
//! density.

use super::color::{ColorMode, Rgb, to_linear, to_srgb};
use super::fit::{self, Repertoire};

/// How a cell is divided into samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum GlyphMode {
    /// Printable ASCII chosen by shape (4×8 samples) with two colours.
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
    /// 4×8 samples fitted with halves, quadrants, sextants, eighths and diagonal
    /// wedges (Unicode 13 legacy computing symbols).
    Blocks,
}

const QUADRANTS: [char; 16] = [
    ' ', '▘', '▝', '▀', '▖', '▌', '▞', '▛', '▗', '▚', '▐', '▜', '▄', '▙', '▟', '█',
];

impl GlyphMode {
    /// Cycling order.
    pub const ALL: [GlyphMode; 6] = [
        GlyphMode::Ascii,
        GlyphMode::Half,
        GlyphMode::Quadrant,
        GlyphMode::Sextant,
        GlyphMode::Braille,
        GlyphMode::Blocks,
    ];

    /// The default glyph mode for a colour depth (see the fidelity table in the README).
    #[must_use]
    pub fn default_for(colors: ColorMode) -> Self {
        match colors {
            ColorMode::None => GlyphMode::Braille,
            _ => GlyphMode::Blocks,
        }
    }

    /// Most samples of any mode's cell.
    pub const MAX_SAMPLES: usize = fit::N;

    /// Samples per cell, (columns, rows).
    #[must_use]
    pub fn dims(self) -> (u32, u32) {
        match self {
            GlyphMode::Ascii | GlyphMode::Blocks => (fit::SX as u32, fit::SY as u32),
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
            GlyphMode::Blocks => "blocks",
        }
    }

    /// The glyph showing the samples whose bits are set in `pattern` (bit i = sample
    /// i, row-major), for the modes whose glyphs are patterns of their samples.
    #[must_use]
    pub fn pattern_glyph(self, pattern: u32) -> char {
        let p = pattern as u8;
        match self {
            GlyphMode::Ascii | GlyphMode::Blocks => {
                if pattern == 0 {
                    ' '
                } else {
                    '█'
                }
            }
            GlyphMode::Half => [' ', '▀', '▄', '█'][usize::from(p & 3)],
            GlyphMode::Quadrant => QUADRANTS[usize::from(p & 15)],
            GlyphMode::Sextant => sextant(p & 63),
            GlyphMode::Braille => braille(p),
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
    let bits: u32 = (0..8)
        .filter(|i| p >> i & 1 == 1)
        .map(|i| super::shapes::BRAILLE_BITS[i])
        .sum();
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
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellGlyph {
    pub ch: char,
    /// Foreground colour, or the terminal's default.
    pub fg: Option<Rgb>,
    /// Background colour, or the terminal's default.
    pub bg: Option<Rgb>,
    /// Samples drawn in the foreground.
    pub pattern: u32,
    /// Squared colour error of the fit (8-bit sRGB units, or linear light for the
    /// shape-fitted modes; 0 for exact modes).
    pub error: f32,
}

impl Default for CellGlyph {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl CellGlyph {
    /// A space on the terminal's own background.
    pub const EMPTY: Self = Self {
        ch: ' ',
        fg: None,
        bg: None,
        pattern: 0,
        error: 0.0,
    };

    /// A space on a background of `c`.
    fn uniform(c: Rgb) -> Self {
        Self {
            bg: Some(c),
            ..Self::EMPTY
        }
    }
}

/// Why [`fit_cell`] chose `g` for these samples, for the inspector.
#[must_use]
pub fn explain(mode: GlyphMode, samples: &[Sample], g: &CellGlyph) -> String {
    if samples.iter().all(|s| !s.covered) {
        return "no sample covered: blank".into();
    }
    let shaped = matches!(mode, GlyphMode::Ascii | GlyphMode::Blocks);
    if g.fg.is_none() && g.bg.is_none() {
        return if shaped {
            format!(
                "no colour: the glyph whose ink density best matches the samples' \
                 (2×2-sample boxes), squared error {:.3}",
                g.error
            )
        } else {
            format!(
                "no colour: ordered dither, {} of {} samples bright enough",
                g.pattern.count_ones(),
                samples.len()
            )
        };
    }
    if g.ch == ' ' {
        return "one colour fits best: a space on that background".into();
    }
    match mode {
        GlyphMode::Half => "upper half block: top sample is fg, bottom is bg".into(),
        GlyphMode::Ascii | GlyphMode::Blocks => {
            let (rep, what) = if mode == GlyphMode::Blocks {
                (Repertoire::blocks(), "block shapes")
            } else {
                (Repertoire::ascii(), "ASCII shapes")
            };
            format!(
                "best of {} {what} and two colours in linear light: {} fg samples, \
                 squared error {:.4}",
                rep.shapes.len() + 1,
                g.pattern.count_ones(),
                g.error
            )
        }
        _ => {
            let on = g.pattern.count_ones();
            let rule = if mode == GlyphMode::Braille {
                "the smaller group on the dots"
            } else {
                "the brighter group in fg"
            };
            format!(
                "2-colour fit by luminance split, {rule}: {on} fg / {} bg samples, squared error {}",
                samples.len() as u32 - on,
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
        GlyphMode::Half => &[0, 1],
        GlyphMode::Quadrant => &[0, 2, 3, 1],
        GlyphMode::Sextant => &[0, 3, 4, 1, 2, 5],
        _ => &[0, 4, 6, 2, 3, 7, 5, 1],
    }
}

/// The shade glyph (` ░▒▓█`) nearest a luminance, for uniform cells without colour.
fn shade(l: f32) -> char {
    [' ', '░', '▒', '▓', '█'][((l * 4.0).round() as usize).min(4)]
}

/// Chooses the glyph and colours of a cell from its samples (`mode.dims()` of them)
/// for a terminal of colour depth `colors`. Without colour, block and braille modes
/// carry shading by ordered dithering (a sample is drawn when its luminance exceeds its
/// threshold), and the shape-fitted modes by ink density.
#[must_use]
pub fn fit_cell(mode: GlyphMode, samples: &[Sample], colors: ColorMode) -> CellGlyph {
    if samples.iter().all(|s| !s.covered) {
        return CellGlyph::EMPTY;
    }
    let colorless = colors == ColorMode::None;
    if matches!(mode, GlyphMode::Ascii | GlyphMode::Blocks) {
        return shape_cell(repertoire(mode), samples, colors);
    }
    let uniform = samples.iter().all(|s| *s == samples[0]);
    if colorless {
        if uniform {
            return CellGlyph {
                ch: shade(luma(samples[0].rgb)),
                ..CellGlyph::EMPTY
            };
        }
        let rank = dither_rank(mode);
        let n = samples.len() as f32;
        let pattern = samples
            .iter()
            .zip(rank)
            .enumerate()
            .fold(0u32, |p, (i, (s, &r))| {
                let on = s.covered && luma(s.rgb) >= (f32::from(r) + 0.5) / n;
                p | u32::from(on) << i
            });
        // Every dot lit would still show the background between them.
        let all = (1u32 << samples.len()) - 1;
        let ch = if mode == GlyphMode::Braille && pattern == all {
            '█'
        } else {
            mode.pattern_glyph(pattern)
        };
        return CellGlyph {
            ch,
            pattern,
            ..CellGlyph::EMPTY
        };
    }
    if uniform {
        return CellGlyph::uniform(samples[0].rgb);
    }
    let g = match mode {
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
                error: 0.0,
            }
        }
        _ => fit_two_colours(mode, samples),
    };
    merge_if_same(g, colors)
}

/// A cell whose two colours are one palette entry in this colour depth is a space on
/// it: the same picture in fewer bytes.
fn merge_if_same(g: CellGlyph, colors: ColorMode) -> CellGlyph {
    match (g.fg, g.bg) {
        (Some(f), Some(b)) if colors.same(f, b) => CellGlyph {
            error: g.error,
            ..CellGlyph::uniform(b)
        },
        _ => g,
    }
}

/// The repertoire of a shape-fitted mode.
fn repertoire(mode: GlyphMode) -> &'static Repertoire {
    if mode == GlyphMode::Blocks {
        Repertoire::blocks()
    } else {
        Repertoire::ascii()
    }
}

/// The samples of a cell in linear light, and which are covered (bit `i`).
fn linear(samples: &[Sample]) -> ([[f32; 3]; fit::N], u32) {
    let mut x = [[0f32; 3]; fit::N];
    let mut covered = 0;
    for (i, (px, s)) in x.iter_mut().zip(samples).enumerate() {
        *px = s.rgb.map(to_linear);
        covered |= u32::from(s.covered) << i;
    }
    (x, covered)
}

/// Fits a cell of 4 × 8 samples with the shapes of `rep`.
fn shape_cell(rep: &Repertoire, samples: &[Sample], colors: ColorMode) -> CellGlyph {
    let (x, covered) = linear(samples);
    if colors == ColorMode::None {
        let l: [f32; fit::N] = std::array::from_fn(|i| {
            let [r, g, b] = x[i];
            0.2126 * r + 0.7152 * g + 0.0722 * b
        });
        let (ch, error) = fit::fit_ink(rep, &l, to_linear(DEFAULT_FG_LEVEL));
        let pattern = fit::mask_of(ch).unwrap_or(0);
        return CellGlyph {
            ch,
            pattern,
            error,
            ..CellGlyph::EMPTY
        };
    }
    glyph_of(&fit::fit(rep, &x), covered, colors)
}

/// Fits up to 8 cells of 4 × 8 samples (`cells[k]` holds cell `k`'s) in colour, all at
/// once: [`fit_cell`]'s result for each, in its lanes.
pub fn fit_cells8(
    mode: GlyphMode,
    cells: &[[Sample; fit::N]],
    colors: ColorMode,
    out: &mut [CellGlyph],
) {
    debug_assert!(colors != ColorMode::None && cells.len() <= 8 && out.len() == cells.len());
    let mut lanes = [[[0f32; 8]; 3]; fit::N];
    let mut covered = [0u32; 8];
    for (l, cell) in cells.iter().enumerate() {
        for (i, s) in cell.iter().enumerate() {
            for c in 0..3 {
                lanes[i][c][l] = to_linear(s.rgb[c]);
            }
            covered[l] |= u32::from(s.covered) << i;
        }
    }
    let x = lanes.map(|px| px.map(wide::f32x8::new));
    let fits = fit::fit_lanes(repertoire(mode), &x);
    for (l, g) in out.iter_mut().enumerate() {
        *g = if covered[l] == 0 {
            CellGlyph::EMPTY
        } else {
            glyph_of(&fits[l], covered[l], colors)
        };
    }
}

/// The glyph and colours that show a fit: a side with no covered sample is the
/// terminal's own background (with the complementary glyph if that puts it there).
fn glyph_of(f: &fit::Fit, covered: u32, colors: ColorMode) -> CellGlyph {
    let srgb = |c: [f32; 3]| c.map(to_srgb);
    let Some(sh) = f.shape else {
        return CellGlyph {
            error: f.error,
            ..CellGlyph::uniform(srgb(f.on))
        };
    };
    let (ch, pattern, fg, bg) = if covered & !sh.mask == 0 {
        (sh.ch, sh.mask, srgb(f.on), None)
    } else if let (0, Some(inv)) = (covered & sh.mask, sh.inverse) {
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

/// The terminal's default foreground level assumed without colour (xterm's colour 7).
pub const DEFAULT_FG_LEVEL: u8 = 229;

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

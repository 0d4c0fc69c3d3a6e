//! Glyph modes and the choice of a cell's glyph and two colours from its samples.
//!
//! Samples are row-major within the cell. `wedges`, `blocks` and `ascii` take 4 × 8
//! samples and choose the glyph and two colours that minimise the squared error (in
//! sRGB-encoded values by default, see [`FitSpace`]) over a repertoire of shapes
//! ([`super::fit`]). The other modes split their samples,
//! ordered by luminance, where the summed squared colour error of the two groups is
//! smallest; block modes draw the brighter group in the foreground, braille puts its
//! dots on the smaller group (dots ink only a third of the cell, so the colour that
//! covers the cell's area is the background) in a colour strengthened so that a dot's
//! sample looks like its group from a distance. A cell of one colour is a space on that
//! background in every mode that has one; without colour, shading is carried by ink
//! density.

use super::Palette;
use super::color::{ColorMode, Rgb, to_linear, to_srgb};
use super::fit;
pub use super::shaped::fit_cells8;
use super::shaped::{repertoire, shape_cell};
use super::split::fit_two_colours;

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
    /// 4×8 samples fitted with halves, quadrants, sextants and eighths.
    Blocks,
    /// As `blocks`, with the diagonal wedges too (U+1FB3C–U+1FB6F, Unicode 13 legacy
    /// computing symbols, which not every terminal draws).
    Wedges,
}

const QUADRANTS: [char; 16] = [
    ' ', '▘', '▝', '▀', '▖', '▌', '▞', '▛', '▗', '▚', '▐', '▜', '▄', '▙', '▟', '█',
];

impl GlyphMode {
    /// Cycling order.
    pub const ALL: [GlyphMode; 7] = [
        GlyphMode::Ascii,
        GlyphMode::Half,
        GlyphMode::Quadrant,
        GlyphMode::Sextant,
        GlyphMode::Braille,
        GlyphMode::Blocks,
        GlyphMode::Wedges,
    ];

    /// The default glyph mode, the best in the fidelity benchmark at every colour depth:
    /// `wedges` where the terminal draws them, else `blocks`.
    #[must_use]
    pub fn default_for(wedges: bool) -> Self {
        if wedges {
            GlyphMode::Wedges
        } else {
            GlyphMode::Blocks
        }
    }

    /// Whether the glyph and colours are fitted to 4×8 samples by shape.
    #[must_use]
    pub fn is_shaped(self) -> bool {
        matches!(
            self,
            GlyphMode::Ascii | GlyphMode::Blocks | GlyphMode::Wedges
        )
    }

    /// Most samples of any mode's cell.
    pub const MAX_SAMPLES: usize = fit::N;

    /// Samples per cell, (columns, rows).
    #[must_use]
    pub fn dims(self) -> (u32, u32) {
        match self {
            GlyphMode::Ascii | GlyphMode::Blocks | GlyphMode::Wedges => {
                (fit::SX as u32, fit::SY as u32)
            }
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
            GlyphMode::Wedges => "wedges",
        }
    }

    /// The glyph showing the samples whose bits are set in `pattern` (bit i = sample
    /// i, row-major), for the modes whose glyphs are patterns of their samples.
    #[must_use]
    pub fn pattern_glyph(self, pattern: u32) -> char {
        let p = pattern as u8;
        match self {
            GlyphMode::Ascii | GlyphMode::Blocks | GlyphMode::Wedges => {
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

/// The encoding in which the shape-fitted modes measure squared colour error (the
/// colours a glyph shows are blended by the eye in linear light either way).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum FitSpace {
    /// sRGB-encoded values, close to perceived lightness: an error in the dark counts
    /// as much as one in the light, so a silhouette keeps its black background instead
    /// of a grey halo (the better of the two in the fidelity benchmark).
    #[default]
    Srgb,
    /// Linear light: errors weighted by physical intensity.
    Linear,
}

impl FitSpace {
    /// Name for the status line and the benchmark.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            FitSpace::Srgb => "srgb",
            FitSpace::Linear => "linear",
        }
    }

    /// An 8-bit sRGB channel in this space, 0..1.
    #[inline]
    pub(super) fn encode(self, v: u8) -> f32 {
        self.table()[usize::from(v)]
    }

    /// [`FitSpace::encode`] of every 8-bit value.
    pub(super) fn table(self) -> &'static [f32; 256] {
        static SRGB: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
        static LINEAR: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
        match self {
            FitSpace::Srgb => SRGB.get_or_init(|| std::array::from_fn(|v| v as f32 / 255.0)),
            FitSpace::Linear => LINEAR.get_or_init(|| std::array::from_fn(|v| to_linear(v as u8))),
        }
    }

    /// A value of this space (clamped to 0..1) as the nearest 8-bit sRGB channel.
    #[inline]
    pub(super) fn decode(self, v: f32) -> u8 {
        match self {
            FitSpace::Srgb => (v.clamp(0.0, 1.0) * 255.0).round() as u8,
            FitSpace::Linear => to_srgb(v),
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
    pub(super) fn uniform(c: Rgb) -> Self {
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
    let shaped = mode.is_shaped();
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
        GlyphMode::Ascii | GlyphMode::Blocks | GlyphMode::Wedges => {
            let rep = repertoire(mode);
            let what = match mode {
                GlyphMode::Ascii => "ASCII shapes",
                GlyphMode::Blocks => "block shapes",
                _ => "block and wedge shapes",
            };
            format!(
                "best of {} {what} and two colours: {} fg samples, squared error {:.4}",
                rep.shapes.len() + 1,
                g.pattern.count_ones(),
                g.error
            )
        }
        _ => {
            let on = g.pattern.count_ones();
            let rule = if mode == GlyphMode::Braille {
                "the smaller group on the dots, their colour strengthened for the third \
                 of a sample a dot inks"
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

/// Relative luminance of an 8-bit sRGB colour in linear light, 0..1.
#[must_use]
pub fn linear_luminance(c: Rgb) -> f32 {
    let [r, g, b] = c.map(to_linear);
    0.2126 * r + 0.7152 * g + 0.0722 * b
}

/// The shade glyph (` ░▒▓█`) nearest an ink fraction, for uniform cells without colour.
fn shade(l: f32) -> char {
    [' ', '░', '▒', '▓', '█'][((l * 4.0).round() as usize).min(4)]
}

/// Chooses the glyph and colours of a cell from its samples (`mode.dims()` of them)
/// for a terminal of colour depth `colors` with xterm's 16 colours, the shape-fitted modes measuring error in
/// `space`. Without colour, block and braille modes carry shading by ordered dithering
/// (a sample is drawn when its luminance exceeds its threshold), and the shape-fitted
/// modes by ink density (in linear light, as ink blends).
#[must_use]
pub fn fit_cell(
    mode: GlyphMode,
    samples: &[Sample],
    colors: ColorMode,
    space: FitSpace,
) -> CellGlyph {
    fit_cell_in(mode, samples, colors, space, &Palette::XTERM)
}

/// [`fit_cell`] for a terminal whose 16 colours are `palette`: in 16 colours the
/// shape-fitted modes choose the glyph and two entries of it together.
#[must_use]
pub fn fit_cell_in(
    mode: GlyphMode,
    samples: &[Sample],
    colors: ColorMode,
    space: FitSpace,
    palette: &Palette,
) -> CellGlyph {
    if samples.iter().all(|s| !s.covered) {
        return CellGlyph::EMPTY;
    }
    let colorless = colors == ColorMode::None;
    if mode.is_shaped() {
        return shape_cell(repertoire(mode), samples, colors, space, palette);
    }
    let uniform = samples.iter().all(|s| *s == samples[0]);
    if colorless {
        // Ink blends with the black background in linear light: a cell shows `ink` of
        // the foreground where inked, and a braille dot inks a third of its sample.
        let fg = to_linear(DEFAULT_FG_LEVEL);
        if uniform {
            return CellGlyph {
                ch: shade(linear_luminance(samples[0].rgb) / fg),
                ..CellGlyph::EMPTY
            };
        }
        let ink = if mode == GlyphMode::Braille {
            fg / 3.0
        } else {
            fg
        };
        let rank = dither_rank(mode);
        let n = samples.len() as f32;
        let pattern = samples
            .iter()
            .zip(rank)
            .enumerate()
            .fold(0u32, |p, (i, (s, &r))| {
                let on = s.covered && linear_luminance(s.rgb) >= (f32::from(r) + 0.5) / n * ink;
                p | u32::from(on) << i
            });
        let all = (1u32 << samples.len()) - 1;
        if mode == GlyphMode::Braille && pattern == all {
            // Every dot lit is the most braille can ink (a third of the cell); a shade
            // glyph of the cell's mean shows more of it, and no dark gaps.
            let mean = samples.iter().map(|s| linear_luminance(s.rgb)).sum::<f32>() / n;
            return CellGlyph {
                ch: match shade(mean / fg) {
                    ' ' => '░',
                    c => c,
                },
                ..CellGlyph::EMPTY
            };
        }
        return CellGlyph {
            ch: mode.pattern_glyph(pattern),
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
    merge_if_same(g, colors, palette)
}

/// A cell whose two colours are one palette entry in this colour depth is a space on
/// it: the same picture in fewer bytes.
pub(super) fn merge_if_same(g: CellGlyph, colors: ColorMode, palette: &Palette) -> CellGlyph {
    match (g.fg, g.bg) {
        (Some(f), Some(b)) if colors.same(f, b, palette) => CellGlyph {
            error: g.error,
            ..CellGlyph::uniform(b)
        },
        _ => g,
    }
}

/// The terminal's default foreground level assumed without colour (xterm's colour 7).
pub const DEFAULT_FG_LEVEL: u8 = 229;

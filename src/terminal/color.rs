//! Colour depth: detection from the environment and quantisation.

use ratatui::style::Color;

use super::palette::Palette;

/// An 8-bit RGB colour.
pub type Rgb = [u8; 3];

/// How many colours the terminal shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum ColorMode {
    /// 24-bit colour.
    Truecolor,
    /// The xterm 256-colour palette.
    #[value(name = "256")]
    Ansi256,
    /// The 16 ANSI colours.
    #[value(name = "16")]
    Ansi16,
    /// No colour: shading is carried by the glyphs alone.
    None,
}

impl ColorMode {
    /// Cycling order.
    pub const ALL: [ColorMode; 4] = [
        ColorMode::Truecolor,
        ColorMode::Ansi256,
        ColorMode::Ansi16,
        ColorMode::None,
    ];

    /// Name for the status line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            ColorMode::Truecolor => "truecolor",
            ColorMode::Ansi256 => "256",
            ColorMode::Ansi16 => "16",
            ColorMode::None => "none",
        }
    }

    /// Detects the colour depth from environment variables (`get` returns a
    /// variable's value). `NO_COLOR` (non-empty) wins; then `COLORTERM` =
    /// `truecolor`/`24bit`; then `TERM`: `*-direct` is truecolor (SSH often drops
    /// `COLORTERM` but keeps `TERM`), `*256color*` is 256, `dumb` is none; anything
    /// else is 16.
    pub fn detect(get: impl Fn(&str) -> Option<String>) -> Self {
        if get("NO_COLOR").is_some_and(|v| !v.is_empty()) {
            return ColorMode::None;
        }
        if let Some(ct) = get("COLORTERM") {
            let ct = ct.to_ascii_lowercase();
            if ct == "truecolor" || ct == "24bit" {
                return ColorMode::Truecolor;
            }
        }
        let term = get("TERM").unwrap_or_default().to_ascii_lowercase();
        if term.ends_with("-direct") || term.contains("truecolor") {
            ColorMode::Truecolor
        } else if term.contains("256color") {
            ColorMode::Ansi256
        } else if term == "dumb" || term.is_empty() {
            ColorMode::None
        } else {
            ColorMode::Ansi16
        }
    }

    /// Whether two colours look the same in this mode (the same palette entry) on a
    /// terminal whose 16 colours are `palette`.
    #[must_use]
    pub fn same(self, a: Rgb, b: Rgb, palette: &Palette) -> bool {
        a == b || (self != ColorMode::Truecolor && self.color(a, palette) == self.color(b, palette))
    }

    /// The ratatui colour for an RGB colour in this mode (`Reset` in `None`), the 16
    /// colours being `palette`.
    #[must_use]
    pub fn color(self, c: Rgb, palette: &Palette) -> Color {
        match self {
            ColorMode::Truecolor => Color::Rgb(c[0], c[1], c[2]),
            ColorMode::Ansi256 => Color::Indexed(palette.nearest_256(c)),
            ColorMode::Ansi16 => ANSI16[usize::from(palette.nearest(c))],
            ColorMode::None => Color::Reset,
        }
    }
}

/// sRGB-encoded 8-bit value to linear light, 0..1.
#[must_use]
pub fn to_linear(v: u8) -> f32 {
    linear_table()[usize::from(v)]
}

/// An 8-bit sRGB colour in OKLab (Björn Ottosson, 2020): lightness and two opponent
/// axes in which Euclidean distance follows perceived difference (a just-noticeable
/// difference is about 0.02).
#[must_use]
pub fn oklab(c: Rgb) -> [f32; 3] {
    let [r, g, b] = c.map(to_linear);
    let l = cbrt(0.412_221_46 * r + 0.536_332_55 * g + 0.051_445_995 * b);
    let m = cbrt(0.211_903_5 * r + 0.680_699_5 * g + 0.107_396_96 * b);
    let s = cbrt(0.088_302_46 * r + 0.281_718_85 * g + 0.629_978_7 * b);
    [
        0.210_454_26 * l + 0.793_617_8 * m - 0.004_072_047 * s,
        1.977_998_5 * l - 2.428_592_2 * m + 0.450_593_7 * s,
        0.025_904_037 * l + 0.782_771_77 * m - 0.808_675_77 * s,
    ]
}

/// The cube root of `x ≥ 0`, to f32 precision: a first guess from the exponent bits and
/// two Halley steps (the library's `cbrtf` was a tenth of a viewer frame, through the
/// cell cache's colour distances).
#[inline]
fn cbrt(x: f32) -> f32 {
    if x <= 0.0 {
        return 0.0;
    }
    let mut y = f32::from_bits(x.to_bits() / 3 + 709_921_077);
    for _ in 0..2 {
        let y3 = y * y * y;
        y *= (y3 + 2.0 * x) / (2.0 * y3 + x);
    }
    y
}

/// Perceived difference of two colours: Euclidean distance in [`oklab`].
#[must_use]
pub fn delta_e(a: Rgb, b: Rgb) -> f32 {
    let (p, q) = (oklab(a), oklab(b));
    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
}

/// [`oklab`] of recently seen colours, in a direct-mapped table: the cell cache compares
/// a few colours per changed cell every frame, and a frame has few distinct colours.
#[derive(Clone, Debug)]
pub struct OklabCache {
    /// `rgb | 1 << 24` of each slot's colour (0: empty).
    keys: Box<[u32]>,
    labs: Box<[[f32; 3]]>,
}

impl Default for OklabCache {
    fn default() -> Self {
        Self {
            keys: vec![0; Self::SLOTS].into_boxed_slice(),
            labs: vec![[0.0; 3]; Self::SLOTS].into_boxed_slice(),
        }
    }
}

impl OklabCache {
    const SLOTS: usize = 4096;

    /// [`oklab`] of `c`.
    #[inline]
    pub fn lab(&mut self, c: Rgb) -> [f32; 3] {
        let key = u32::from(c[0]) << 16 | u32::from(c[1]) << 8 | u32::from(c[2]) | 1 << 24;
        let slot = (key.wrapping_mul(0x9E37_79B1) >> 20) as usize;
        if self.keys[slot] != key {
            self.keys[slot] = key;
            self.labs[slot] = oklab(c);
        }
        self.labs[slot]
    }

    /// [`delta_e`] of two colours.
    #[inline]
    pub fn delta_e(&mut self, a: Rgb, b: Rgb) -> f32 {
        let (p, q) = (self.lab(a), self.lab(b));
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    }
}

fn linear_table() -> &'static [f32; 256] {
    static T: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    T.get_or_init(|| {
        std::array::from_fn(|i| {
            let c = i as f32 / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        })
    })
}

/// Linear light to the nearest sRGB-encoded 8-bit value (exact: a search of the table
/// of all 256 values).
#[must_use]
pub fn to_srgb(l: f32) -> u8 {
    let t = linear_table();
    // The first value whose linear level is at least l, then the nearer of it and the
    // one below.
    let i = t.partition_point(|&v| v < l).min(255);
    if i > 0 && (l - t[i - 1]) <= (t[i] - l) {
        (i - 1) as u8
    } else {
        i as u8
    }
}

const ANSI16: [Color; 16] = [
    Color::Black,
    Color::Red,
    Color::Green,
    Color::Yellow,
    Color::Blue,
    Color::Magenta,
    Color::Cyan,
    Color::Gray,
    Color::DarkGray,
    Color::LightRed,
    Color::LightGreen,
    Color::LightYellow,
    Color::LightBlue,
    Color::LightMagenta,
    Color::LightCyan,
    Color::White,
];

/// The palette index (0–15) of one of the 16 named colours.
#[must_use]
pub fn ansi16_index(c: Color) -> Option<u8> {
    ANSI16.iter().position(|x| *x == c).map(|i| i as u8)
}

fn dist2(a: Rgb, b: Rgb) -> i32 {
    (0..3)
        .map(|i| (i32::from(a[i]) - i32::from(b[i])).pow(2))
        .sum()
}

/// Nearest entry of the xterm 256-colour palette: the 6×6×6 cube (16–231) or the grey
/// ramp (232–255).
#[must_use]
pub fn nearest_256(c: Rgb) -> u8 {
    let level = |v: u8| usize::from(CUBE_LEVEL_OF[usize::from(v)]);
    let (r, g, b) = (level(c[0]), level(c[1]), level(c[2]));
    let cube = [CUBE_LEVELS[r], CUBE_LEVELS[g], CUBE_LEVELS[b]];
    let avg = (u32::from(c[0]) + u32::from(c[1]) + u32::from(c[2])) / 3;
    let gi = ((avg.saturating_sub(8)) / 10).min(23) as u8;
    let grey = 8 + 10 * gi;
    if dist2([grey; 3], c) < dist2(cube, c) {
        232 + gi
    } else {
        16 + 36 * r as u8 + 6 * g as u8 + b as u8
    }
}

/// The six levels of each channel in the xterm 6×6×6 colour cube (indices 16–231).
const CUBE_LEVELS: [u8; 6] = [0, 95, 135, 175, 215, 255];

/// The cube level nearest each channel value (the lower one on a tie): a table, since
/// the 256-colour mode quantises two colours of every cell.
const CUBE_LEVEL_OF: [u8; 256] = {
    let mut t = [0u8; 256];
    let mut v = 0;
    while v < 256 {
        let mut best = 0;
        let mut i = 1;
        while i < 6 {
            if (CUBE_LEVELS[i] as i32 - v as i32).abs()
                < (CUBE_LEVELS[best] as i32 - v as i32).abs()
            {
                best = i;
            }
            i += 1;
        }
        t[v] = best as u8;
        v += 1;
    }
    t
};

/// The RGB colour xterm shows for palette index `i`: the 16 ANSI colours, the 6×6×6
/// cube (16–231) or the grey ramp `8 + 10k` (232–255). The inverse of
/// [`nearest_256`], for painting what a terminal shows.
#[must_use]
pub fn indexed_rgb(i: u8) -> Rgb {
    match i {
        0..=15 => Palette::XTERM.ansi[usize::from(i)],
        16..=231 => {
            let c = i - 16;
            [c / 36, c / 6 % 6, c % 6].map(|l| CUBE_LEVELS[usize::from(l)])
        }
        _ => [8 + 10 * (i - 232); 3],
    }
}

/// Linear light in `[0, 1]` (clamped) encoded with the sRGB transfer curve, in `[0, 1]`.
#[must_use]
#[inline]
pub fn linear_to_srgb(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_light_round_trips() {
        for v in 0..=255u8 {
            assert_eq!(to_srgb(to_linear(v)), v);
        }
        assert_eq!(to_srgb(-1.0), 0);
        assert_eq!(to_srgb(2.0), 255);
        assert!((to_linear(128) - 0.2158).abs() < 1e-3);
    }

    #[test]
    fn palette_indices_round_trip() {
        // Every cube and grey-ramp entry is its own nearest colour (the 16 ANSI
        // colours repeat some of them and are not searched by `nearest_256`).
        for i in 16..=255u8 {
            assert_eq!(nearest_256(indexed_rgb(i)), i, "index {i}");
        }
        assert_eq!(indexed_rgb(16), [0, 0, 0]);
        assert_eq!(indexed_rgb(196), [255, 0, 0]);
        assert_eq!(indexed_rgb(231), [255, 255, 255]);
        assert_eq!(indexed_rgb(232), [8, 8, 8]);
        assert_eq!(indexed_rgb(255), [238, 238, 238]);
        assert_eq!(indexed_rgb(7), [229, 229, 229]);
    }

    #[test]
    fn nearest_256_is_close() {
        // The cube's widest gap is 95 (0 to 95), so its nearest entry is at most 47.5
        // off per channel; the grey ramp is taken only when it is nearer still. Over a
        // grid of colours the mean error stays small.
        let mut total = 0i64;
        let mut n = 0i64;
        for r in (0..=255u8).step_by(15) {
            for g in (0..=255u8).step_by(15) {
                for b in (0..=255u8).step_by(15) {
                    let c = [r, g, b];
                    let got = indexed_rgb(nearest_256(c));
                    let d = dist2(got, c);
                    assert!(d <= 3 * 48 * 48, "{c:?} -> {got:?}");
                    total += i64::from(d);
                    n += 1;
                }
            }
        }
        let rms = ((total / n) as f64 / 3.0).sqrt();
        assert!(rms < 20.0, "rms channel error {rms}");
    }

    #[test]
    fn the_cache_gives_the_same_distances() {
        let mut cache = OklabCache::default();
        for i in 0..20_000u32 {
            let c = |k: u32| {
                let v = (i.wrapping_mul(2_654_435_761) >> k) as u8;
                [v, v.wrapping_mul(7), v.wrapping_add(i as u8)]
            };
            let (a, b) = (c(3), c(11));
            assert_eq!(cache.delta_e(a, b).to_bits(), delta_e(a, b).to_bits());
        }
    }

    #[test]
    fn the_cube_root_is_the_library_s() {
        for k in 0..=20_000 {
            let x = k as f32 / 20_000.0;
            let (got, want) = (cbrt(x), x.cbrt());
            assert!((got - want).abs() <= 2e-7, "{x}: {got} {want}");
        }
        assert_eq!(cbrt(0.0), 0.0);
        assert_eq!(cbrt(-1.0), 0.0);
    }

    #[test]
    fn transfer_curve_round_trips() {
        for v in 0..=255u8 {
            assert_eq!((linear_to_srgb(to_linear(v)) * 255.0).round() as u8, v);
        }
        assert_eq!(to_linear(0), 0.0);
        assert!((to_linear(255) - 1.0).abs() < 1e-6);
        assert!((to_linear(188) - 0.5).abs() < 0.005);
    }
}

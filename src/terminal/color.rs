//! Colour depth: detection from the environment and quantisation.

use ratatui::style::Color;

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

    /// Whether two colours look the same in this mode (the same palette entry).
    #[must_use]
    pub fn same(self, a: Rgb, b: Rgb) -> bool {
        a == b || (self != ColorMode::Truecolor && self.color(a) == self.color(b))
    }

    /// The ratatui colour for an RGB colour in this mode (`Reset` in `None`).
    #[must_use]
    pub fn color(self, c: Rgb) -> Color {
        match self {
            ColorMode::Truecolor => Color::Rgb(c[0], c[1], c[2]),
            ColorMode::Ansi256 => Color::Indexed(nearest_256(c)),
            ColorMode::Ansi16 => ANSI16[nearest(&ANSI16_RGB, c)],
            ColorMode::None => Color::Reset,
        }
    }
}

/// sRGB-encoded 8-bit value to linear light, 0..1.
#[must_use]
pub fn to_linear(v: u8) -> f32 {
    linear_table()[usize::from(v)]
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

/// xterm's default RGB values of the 16 ANSI colours.
const ANSI16_RGB: [Rgb; 16] = [
    [0, 0, 0],
    [205, 0, 0],
    [0, 205, 0],
    [205, 205, 0],
    [0, 0, 238],
    [205, 0, 205],
    [0, 205, 205],
    [229, 229, 229],
    [127, 127, 127],
    [255, 0, 0],
    [0, 255, 0],
    [255, 255, 0],
    [92, 92, 255],
    [255, 0, 255],
    [0, 255, 255],
    [255, 255, 255],
];

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

fn dist2(a: Rgb, b: Rgb) -> i32 {
    (0..3)
        .map(|i| (i32::from(a[i]) - i32::from(b[i])).pow(2))
        .sum()
}

fn nearest(palette: &[Rgb], c: Rgb) -> usize {
    (0..palette.len())
        .min_by_key(|&i| dist2(palette[i], c))
        .unwrap_or(0)
}

/// Nearest entry of the xterm 256-colour palette: the 6×6×6 cube (16–231) or the grey
/// ramp (232–255).
#[must_use]
pub fn nearest_256(c: Rgb) -> u8 {
    const LEVELS: [u8; 6] = [0, 95, 135, 175, 215, 255];
    let level = |v: u8| {
        (0..6)
            .min_by_key(|&i| (i32::from(LEVELS[i]) - i32::from(v)).abs())
            .unwrap_or(0)
    };
    let (r, g, b) = (level(c[0]), level(c[1]), level(c[2]));
    let cube = [LEVELS[r], LEVELS[g], LEVELS[b]];
    let avg = (u32::from(c[0]) + u32::from(c[1]) + u32::from(c[2])) / 3;
    let gi = ((avg.saturating_sub(8)) / 10).min(23) as u8;
    let grey = 8 + 10 * gi;
    if dist2([grey; 3], c) < dist2(cube, c) {
        232 + gi
    } else {
        16 + 36 * r as u8 + 6 * g as u8 + b as u8
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
}

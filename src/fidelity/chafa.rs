//! chafa, the character-art converter, as the benchmark's point of comparison.
//!
//! chafa is optional: [`Chafa::find`] looks for it on the `PATH`, and the benchmark
//! runs without it. It is given the full-size reference render and does its own
//! downscale and symbol fit; its output goes through the same emulator and painter
//! as termrast's, so both are scored on what a terminal would show.

use std::path::Path;
use std::process::{Command, Stdio};

use crate::terminal::ColorMode;
use crate::terminal::paint::{DEFAULT_BG, DEFAULT_FG};

/// Symbol sets to compare, as chafa's `--symbols` takes them (`default`: chafa's own
/// choice, no `--symbols`). Each block-element set is given `space` and `solid` (the
/// blank and the full block), as every termrast mode has them: without them chafa
/// fills black areas with the least-inked symbol it has, which in `-c none` paints
/// the whole background (SSIM below 0.1). Braille and ASCII have their own blanks.
/// `vhalf` (▀ ▄) is the one comparable to termrast's `half`; chafa's `half` adds the
/// left and right halves.
pub const SYMBOL_SETS: [&str; 10] = [
    "default",
    "ascii",
    "braille",
    "half+space+solid",
    "vhalf+space+solid",
    "quad+space+solid",
    "sextant+space+solid",
    "wedge+space+solid",
    "block+space+solid",
    "sextant+wedge+block+half+quad+space+solid",
];

/// chafa found on the `PATH`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Chafa {
    /// The first line of `chafa --version`.
    pub version: String,
}

/// chafa's `--colors` name for a colour depth.
#[must_use]
pub fn colors_arg(mode: ColorMode) -> &'static str {
    match mode {
        ColorMode::Truecolor => "full",
        ColorMode::Ansi256 => "256",
        ColorMode::Ansi16 => "16",
        ColorMode::None => "none",
    }
}

fn hex(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

impl Chafa {
    /// chafa if `chafa --version` runs and succeeds, or why not.
    pub fn find() -> Result<Self, String> {
        let out = Command::new("chafa")
            .arg("--version")
            .stdin(Stdio::null())
            .output()
            .map_err(|e| format!("chafa is not available ({e})"))?;
        if !out.status.success() {
            return Err(format!("`chafa --version` failed ({})", out.status));
        }
        let text = String::from_utf8_lossy(&out.stdout);
        Ok(Self {
            version: text.lines().next().unwrap_or("chafa").trim().to_owned(),
        })
    }

    /// The arguments of one conversion of `image` to `cols × rows` cells.
    #[must_use]
    pub fn args(
        image: &Path,
        cols: u16,
        rows: u16,
        symbols: &str,
        colors: ColorMode,
    ) -> Vec<String> {
        let mut a: Vec<String> = [
            "--format",
            "symbols",
            "--animate",
            "off",
            "--polite",
            "on",
            "--font-ratio",
            "1/2",
        ]
        .map(String::from)
        .into();
        a.push("--size".into());
        a.push(format!("{cols}x{rows}"));
        a.push("--colors".into());
        a.push(colors_arg(colors).into());
        // The painter's default colours, so chafa fits its symbols to the colours the
        // terminal is taken to have (they matter for `none` and inverse video).
        a.push("--fg".into());
        a.push(hex(DEFAULT_FG));
        a.push("--bg".into());
        a.push(hex(DEFAULT_BG));
        if symbols != "default" {
            a.push("--symbols".into());
            a.push(symbols.into());
        }
        a.push(image.display().to_string());
        a
    }

    /// Converts `image` to `cols × rows` cells; returns chafa's output bytes, or why it
    /// failed.
    pub fn convert(
        &self,
        image: &Path,
        cols: u16,
        rows: u16,
        symbols: &str,
        colors: ColorMode,
    ) -> Result<Vec<u8>, String> {
        let out = Command::new("chafa")
            .args(Self::args(image, cols, rows, symbols, colors))
            .stdin(Stdio::null())
            .output()
            .map_err(|e| format!("chafa could not be run ({e})"))?;
        if !out.status.success() {
            let err = String::from_utf8_lossy(&out.stderr);
            return Err(format!(
                "chafa --symbols {symbols} -c {} failed ({}): {}",
                colors_arg(colors),
                out.status,
                err.trim()
            ));
        }
        if out.stdout.is_empty() {
            return Err(format!(
                "chafa --symbols {symbols} -c {} printed nothing",
                colors_arg(colors)
            ));
        }
        Ok(out.stdout)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_name_the_size_colours_and_symbols() {
        let a = Chafa::args(Path::new("r.png"), 200, 60, "braille", ColorMode::Ansi256);
        let s = a.join(" ");
        assert!(
            s.contains("--size 200x60") && s.contains("--colors 256"),
            "{s}"
        );
        assert!(
            s.contains("--symbols braille") && s.ends_with("r.png"),
            "{s}"
        );
        assert!(s.contains("--fg #e5e5e5 --bg #000000"), "{s}");
        let d = Chafa::args(Path::new("r.png"), 8, 4, "default", ColorMode::None).join(" ");
        assert!(
            !d.contains("--symbols") && d.contains("--colors none"),
            "{d}"
        );
    }
}

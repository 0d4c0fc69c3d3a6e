//! `termrast bench bytes`: bytes per frame of the spinning viewer through the cell
//! cache, and what its threshold costs the eye (see [`crate::fidelity::spin`]).

use std::io::Write;

use clap::Args;

use crate::fidelity::spin::{self, SpinConfig};
use crate::terminal::{ColorMode, GlyphMode};

/// Arguments of `bench bytes`.
#[derive(Debug, Args)]
pub struct BytesArgs {
    /// Models (`teapot`, `bunny`, `sphere:N`, a model file).
    #[arg(default_values_t = ["teapot".to_string(), "bunny".to_string()])]
    pub models: Vec<String>,
    /// Cells, WxH.
    #[arg(long, default_value = "200x60", value_parser = super::parse_size)]
    pub size: crate::raster::Target,
    /// Frames per sequence (the first, a full screen, is not counted).
    #[arg(long, default_value_t = 13, value_parser = clap::value_parser!(u32).range(2..=1000))]
    pub frames: u32,
    /// Radians the model turns between frames (0.026: the viewer at 30 fps).
    #[arg(long, default_value_t = 0.026)]
    pub step: f32,
    /// Count bytes only (no screens painted and scored).
    #[arg(long)]
    pub no_score: bool,
    /// Glyph modes (all by default).
    #[arg(long, value_delimiter = ',')]
    pub glyphs: Vec<GlyphMode>,
    /// Colour depths (all by default).
    #[arg(long, value_delimiter = ',')]
    pub colors: Vec<ColorMode>,
}

/// Measures every model × glyph mode × colour depth and prints a table.
pub fn run(args: &BytesArgs, out: &mut impl Write) -> Result<(), super::CliError> {
    if !args.step.is_finite() {
        return Err(super::CliError::Usage(format!(
            "--step {} is not a number of radians",
            args.step
        )));
    }
    let config = SpinConfig {
        cols: u16::try_from(args.size.width).unwrap_or(u16::MAX),
        rows: u16::try_from(args.size.height).unwrap_or(u16::MAX),
        frames: args.frames as usize,
        step: args.step,
        score: !args.no_score,
    };
    let glyphs = if args.glyphs.is_empty() {
        GlyphMode::ALL.to_vec()
    } else {
        args.glyphs.clone()
    };
    let colors = if args.colors.is_empty() {
        ColorMode::ALL.to_vec()
    } else {
        args.colors.clone()
    };
    writeln!(
        out,
        "{}×{} cells, {} frames turning {} rad each; bytes per frame through the cell cache \
         and sending every changed cell exactly, and the mean SSIM of what the terminal shows",
        config.cols,
        config.rows,
        config.frames - 1,
        config.step
    )?;
    writeln!(
        out,
        "{:<10} {:<9} {:<10} {:>12} {:>12} {:>11} {:>11} {:>9}",
        "model", "glyphs", "colours", "cache B", "exact B", "cache SSIM", "exact SSIM", "ΔSSIM"
    )?;
    for name in &args.models {
        let model = crate::scene::Scene::for_model(name)?;
        for &g in &glyphs {
            for &c in &colors {
                let r = spin::measure(&config, name, &model, g, c)?;
                let (a, b, d) = r
                    .ssim
                    .map_or(("-".into(), "-".into(), "-".into()), |(a, b)| {
                        (
                            format!("{a:.4}"),
                            format!("{b:.4}"),
                            format!("{:+.4}", a - b),
                        )
                    });
                writeln!(
                    out,
                    "{:<10} {:<9} {:<10} {:>12.0} {:>12.0} {:>11} {:>11} {:>9}",
                    name,
                    g.name(),
                    c.name(),
                    r.cached_bytes,
                    r.exact_bytes,
                    a,
                    b,
                    d
                )?;
            }
        }
    }
    Ok(())
}

//! The command line: argument definitions and the commands behind them.
//!
//! The binary calls [`main`]; everything here is library code so the tests can drive it.

pub mod line_cmd;
pub mod raster_cmd;
pub mod render_cmd;

use std::io::{self, Write};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::raster::Target;

/// Terminal 3D rasterizer with an exact edge-function core.
#[derive(Debug, Parser)]
#[command(name = "termrast", version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Rasterize 2D triangles read from stdin (`x0 y0 x1 y1 x2 y2` per line, pixels).
    Raster(raster_cmd::RasterArgs),
    /// Draw a line with the midpoint (Bresenham) algorithm, optionally traced.
    Line(line_cmd::LineArgs),
    /// Render one frame of a model to a PNG file.
    Render(render_cmd::PngArgs),
    /// Benchmarks.
    #[command(subcommand)]
    Bench(BenchCommand),
}

/// `termrast bench ...`
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// The standard scene: prints `median_ms=… min_ms=… triangles=… covered_px=… mpx_per_s=…`.
    Render(render_cmd::BenchRenderArgs),
}

/// Errors of the commands, each naming what it is about.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    #[error(transparent)]
    Raster(#[from] raster_cmd::RasterError),
    #[error(transparent)]
    Mesh(#[from] crate::mesh::MeshError),
    #[error(transparent)]
    Line(#[from] line_cmd::LineError),
    #[error("{0}: {1}")]
    Image(std::path::PathBuf, image::ImageError),
    #[error(transparent)]
    Io(#[from] io::Error),
}

/// Parses `WxH` (e.g. `80x24`) into a target size.
pub fn parse_size(s: &str) -> Result<Target, String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size `{s}` is not WxH, e.g. 80x24"))?;
    let side = |v: &str, name: &str| -> Result<u32, String> {
        let n: u32 = v
            .trim()
            .parse()
            .map_err(|_| format!("{name} `{v}` in size `{s}` is not a whole number"))?;
        if n == 0 || n > crate::raster::setup::MAX_TARGET_SIDE {
            return Err(format!(
                "{name} {n} in size `{s}` must be between 1 and {}",
                crate::raster::setup::MAX_TARGET_SIDE
            ));
        }
        Ok(n)
    };
    Ok(Target::new(side(w, "width")?, side(h, "height")?))
}

/// Runs the parsed command line, writing errors to stderr.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result: Result<(), CliError> = match cli.command {
        Some(Command::Raster(args)) => {
            raster_cmd::run(&args, io::stdin().lock(), io::stdout().lock()).map_err(Into::into)
        }
        Some(Command::Render(args)) => render_cmd::png(&args),
        Some(Command::Line(args)) => {
            line_cmd::run(&args, &mut io::stdout().lock()).map_err(Into::into)
        }
        Some(Command::Bench(BenchCommand::Render(args))) => render_cmd::bench_render(&args)
            .and_then(|r| writeln!(io::stdout(), "{r}").map_err(Into::into)),
        None => preview(&mut io::stdout().lock()).map_err(Into::into),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(io::stderr(), "termrast: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Luminance ramp of the text preview, darkest first.
const RAMP: &[u8] = b" .:-=+*#%@";

/// Without a subcommand: one 80×24 text frame of the embedded teapot (cells are about
/// twice as tall as wide), followed by the list of commands.
pub fn preview(out: &mut impl Write) -> io::Result<()> {
    use crate::mesh::Mesh;
    use crate::render::standard::{StandardFrame, StandardView};
    use crate::render::{DrawOptions, Luma};
    let mut mesh = Mesh::teapot();
    mesh.ensure_normals();
    let model = crate::render::standard::Model::new(mesh);
    let target = Target::new(80, 24);
    let mut frame = StandardFrame::new(target);
    let mut luma = Luma::default();
    let view = StandardView {
        pixel_aspect: 0.5,
        ..StandardView::at(0.6)
    };
    frame.draw(
        &model,
        &view,
        target,
        &DrawOptions::default(),
        Default::default(),
        &mut luma,
    );
    for row in luma.0.chunks(80) {
        let line: String = row
            .iter()
            .map(|&l| RAMP[((l * 9.0).round() as usize).min(9)] as char)
            .collect();
        writeln!(out, "{}", line.trim_end())?;
    }
    use clap::CommandFactory;
    writeln!(out, "{}", Cli::command().render_help())
}

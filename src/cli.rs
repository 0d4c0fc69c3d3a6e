//! The command line: argument definitions and the commands behind them.
//!
//! The binary calls [`main`]; everything here is library code so the tests can drive it.

pub mod accuracy_cmd;
pub mod bytes_cmd;
pub mod effects_cmd;
pub mod fidelity_cmd;
pub mod line_cmd;
pub mod link_cmd;
pub mod load_cmd;
pub mod raster_cmd;
pub mod render_cmd;
pub mod suggest;
pub mod view_cmd;

use std::io::{self, Write};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::raster::Target;

/// Terminal 3D rasterizer with an exact edge-function core.
///
/// Without a subcommand it opens the viewer: `termrast [MODEL]` is `termrast view [MODEL]`.
#[derive(Debug, Parser)]
#[command(
    name = "termrast",
    version,
    about,
    args_conflicts_with_subcommands = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    #[command(flatten)]
    pub view: view_cmd::ViewArgs,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Spin a model in the terminal, with a per-cell raster inspector (the default).
    View(view_cmd::ViewArgs),
    /// Rasterize 2D triangles read from stdin (`x0 y0 x1 y1 x2 y2` per line, pixels).
    Raster(raster_cmd::RasterArgs),
    /// Draw a line with the midpoint (Bresenham) algorithm, optionally traced.
    Line(line_cmd::LineArgs),
    /// Render frames as ANSI text to stdout (for pipes and scripts), or a PNG with --out.
    Render(render_cmd::PngArgs),
    /// Serve the viewer over SSH: each watcher (`ssh -p 2222 HOST`) gets their own view
    /// of one shared model or scene.
    Serve(crate::serve::config::ServeArgs),
    /// Benchmarks.
    #[command(subcommand)]
    Bench(BenchCommand),
}

/// `termrast bench ...`
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// The standard scene: prints `median_ms=… min_ms=… triangles=… covered_px=… mpx_per_s=…`.
    Render(render_cmd::BenchRenderArgs),
    /// The accuracy/speed table: every accuracy choice timed and checked against exact
    /// references (edge arithmetic, traversal, interpolation, anti-aliasing, depth).
    Accuracy(accuracy_cmd::AccuracyArgs),
    /// What each scene effect costs: ms/frame with and without it.
    Effects(effects_cmd::EffectsArgs),
    /// How close what a terminal shows comes to the image: SSIM, PSNR and bytes per
    /// frame of every glyph mode and colour depth (and chafa's, if installed),
    /// through a terminal emulator.
    Fidelity(fidelity_cmd::FidelityArgs),
    /// The viewer behind a slow link (a pseudo-terminal drained at a set rate through
    /// a 2 MB buffer into a terminal emulator): key-to-screen time and frame rate.
    Link(link_cmd::LinkArgs),
    /// Bytes per frame of the spinning viewer through its cell cache, against sending
    /// every changed cell, and what the cache costs the eye (SSIM through a terminal
    /// emulator), for every glyph mode and colour depth.
    Bytes(bytes_cmd::BytesArgs),
    /// `termrast serve` under load: SSH watchers that read frames at a set rate and
    /// answer the viewer's queries as a terminal does; frames/s each, server memory.
    Serve(crate::serve::bench::BenchServeArgs),
    /// Load time and peak memory of a large model (a sphere of 1M triangles) in every
    /// format, each loaded by a child process of its own.
    Load(load_cmd::LoadArgs),
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
    View(#[from] crate::tui::ViewError),
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    #[error(transparent)]
    Fidelity(#[from] crate::fidelity::FidelityError),
    #[error(transparent)]
    Link(#[from] crate::slowlink::LinkError),
    #[error(transparent)]
    Serve(#[from] crate::serve::ServeError),
    #[error(transparent)]
    Io(#[from] io::Error),
    #[error("{}: {source}", path.display())]
    File {
        path: std::path::PathBuf,
        source: io::Error,
    },
    #[error("{0}")]
    Usage(String),
}

impl CliError {
    /// Whether this is a write to a pipe whose reader has gone (`termrast render … |
    /// head`): the output is no longer wanted, so the command ends quietly, as a tool
    /// killed by `SIGPIPE` does.
    #[must_use]
    pub fn reader_gone(&self) -> bool {
        let io = match self {
            CliError::Io(e)
            | CliError::Raster(raster_cmd::RasterError::Io(e))
            | CliError::Line(line_cmd::LineError::Io(e))
            | CliError::Serve(crate::serve::ServeError::Io(e)) => e,
            _ => return false,
        };
        io.kind() == io::ErrorKind::BrokenPipe
    }
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
    let (w, h) = (side(w, "width")?, side(h, "height")?);
    if u64::from(w) * u64::from(h) > MAX_PIXELS {
        return Err(format!(
            "size `{s}` has {} pixels; at most {MAX_PIXELS} (8K) are supported",
            u64::from(w) * u64::from(h)
        ));
    }
    Ok(Target::new(w, h))
}

/// `--threads`: a count of drawing threads, 1 to 256.
pub fn parse_threads(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n @ 1..=256) => Ok(n),
        Ok(n) => Err(format!("{n} threads: give 1 to 256")),
        Err(_) => Err(format!("`{s}` is not a whole number of threads")),
    }
}

/// The drawing threads `--threads` asks for: the machine's cores when not given.
#[must_use]
pub fn threads_or_cores(threads: Option<usize>) -> usize {
    threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, usize::from))
}

/// Parses an instruction set name, refusing one the running CPU lacks (it would
/// silently fall back to the baseline, and a benchmark would measure the wrong code).
pub fn parse_isa(s: &str) -> Result<crate::render::Isa, String> {
    use crate::render::Isa;
    let names = || Isa::ALL.map(Isa::name).join(", ");
    let isa = Isa::ALL
        .into_iter()
        .find(|isa| isa.name() == s)
        .ok_or_else(|| format!("unknown instruction set `{s}`; one of {}", names()))?;
    if !isa.is_supported() {
        let have: Vec<_> = Isa::supported().map(Isa::name).collect();
        return Err(format!(
            "this CPU cannot run `{s}`; it supports {}",
            have.join(", ")
        ));
    }
    Ok(isa)
}

/// Largest target in pixels (2^25, a little over 8K): colour and depth buffers then
/// stay within about 270 MB instead of failing to allocate.
pub const MAX_PIXELS: u64 = 1 << 25;

/// Runs the parsed command line, writing errors to stderr.
pub fn main() -> ExitCode {
    let args: Vec<std::ffi::OsString> = std::env::args_os().collect();
    // Before clap: it would take a mistyped subcommand for the viewer's model.
    if let Some(e) = suggest::mistyped_subcommand(&args) {
        e.exit();
    }
    let cli = Cli::parse_from(args);
    let result: Result<(), CliError> = match cli.command {
        Some(Command::Raster(args)) => {
            raster_cmd::run(&args, io::stdin().lock(), io::stdout().lock()).map_err(Into::into)
        }
        Some(Command::Render(args)) => render_cmd::png(&args),
        Some(Command::Line(args)) => {
            line_cmd::run(&args, &mut io::stdout().lock()).map_err(Into::into)
        }
        Some(Command::Bench(BenchCommand::Render(args))) => match &args.compare {
            Some(counts) => render_cmd::bench_compare(&args, counts, &mut io::stdout().lock()),
            None => render_cmd::bench_render(&args)
                .and_then(|r| writeln!(io::stdout(), "{r}").map_err(Into::into)),
        },
        Some(Command::Bench(BenchCommand::Accuracy(args))) => {
            accuracy_cmd::run_cmd(&args, &mut io::stdout().lock())
        }
        Some(Command::Bench(BenchCommand::Effects(args))) => {
            effects_cmd::run(&args, &mut io::stdout().lock())
        }
        Some(Command::Bench(BenchCommand::Fidelity(args))) => {
            fidelity_cmd::run(&args, &mut io::stdout().lock())
        }
        Some(Command::Bench(BenchCommand::Link(args))) => {
            link_cmd::run(&args, &mut io::stdout().lock())
        }
        Some(Command::Bench(BenchCommand::Bytes(args))) => {
            bytes_cmd::run(&args, &mut io::stdout().lock())
        }
        Some(Command::Bench(BenchCommand::Serve(args))) => {
            crate::serve::bench::run(&args, &mut io::stdout().lock()).map_err(Into::into)
        }
        Some(Command::Serve(args)) => crate::serve::run(&args).map_err(Into::into),
        Some(Command::Bench(BenchCommand::Load(args))) => {
            load_cmd::run(&args, &mut io::stdout().lock())
        }
        Some(Command::View(args)) => view_cmd::view(&args),
        None => view_cmd::view(&cli.view),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // Ended by a signal: the shell's convention, and nothing to say.
        Err(CliError::View(crate::tui::ViewError::Signal(sig))) => {
            ExitCode::from(u8::try_from(128 + sig).unwrap_or(255))
        }
        // The shell's status for a command ended by `SIGPIPE` (128 + 13).
        Err(e) if e.reader_gone() => ExitCode::from(141),
        Err(e) => {
            let _ = writeln!(io::stderr(), "termrast: {e}");
            ExitCode::FAILURE
        }
    }
}

//! `termrast bench link`: the viewer behind a slow link (see [`crate::slowlink`]).

use std::io::Write;

use clap::Args;

use crate::slowlink::{self, Config};

/// Arguments of `bench link`.
#[derive(Debug, Args)]
pub struct LinkArgs {
    /// Models to view (`teapot`, `bunny`, `sphere:N`, a model file or a scene file).
    #[arg(default_values_t = ["teapot".to_string(), "bunny".to_string()])]
    pub models: Vec<String>,
    /// Link rates in bytes per second.
    #[arg(long, value_delimiter = ',', default_values_t = [125_000u64, 250_000])]
    pub rate: Vec<u64>,
    /// Key presses timed per run.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub presses: u32,
    /// Glyph mode passed to the viewer (its default otherwise).
    #[arg(long)]
    pub glyphs: Option<String>,
    /// Viewer options to add (e.g. `--no-pacing`), one per flag.
    #[arg(long = "viewer-arg", allow_hyphen_values = true)]
    pub viewer_args: Vec<String>,
}

/// Runs every model at every rate and prints a table.
pub fn run(args: &LinkArgs, out: &mut impl Write) -> Result<(), super::CliError> {
    let exe = std::env::current_exe()?;
    writeln!(
        out,
        "link at 200×60 cells, 2 MB buffer; key `b` (culling), time until the emulated status line shows it"
    )?;
    writeln!(
        out,
        "{:<12} {:>9} {:>11} {:>11} {:>8} {:>10} {:>10}",
        "model", "rate kB/s", "median ms", "max ms", "missed", "fps", "peak buf"
    )?;
    for model in &args.models {
        for &rate in &args.rate {
            let mut config = Config::new(exe.clone(), model, rate.max(1));
            config.presses = args.presses as usize;
            if let Some(g) = &args.glyphs {
                config.args.extend(["--glyphs".to_string(), g.clone()]);
            }
            config.args.extend(args.viewer_args.iter().cloned());
            let r = slowlink::run(&config)?;
            let ms = |d: Option<std::time::Duration>| {
                d.map_or("-".to_string(), |d| format!("{:.0}", d.as_secs_f64() * 1e3))
            };
            let max = r.latencies.iter().flatten().max().copied();
            writeln!(
                out,
                "{:<12} {:>9.0} {:>11} {:>11} {:>8} {:>10.1} {:>10}",
                model,
                rate as f64 / 1e3,
                ms(r.median()),
                ms(max),
                r.latencies.iter().filter(|l| l.is_none()).count(),
                r.delivered_fps,
                r.max_buffered
            )?;
        }
    }
    Ok(())
}

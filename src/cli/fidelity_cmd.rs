//! `termrast bench fidelity`: the fidelity table (the logic is [`crate::fidelity`]).

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;

use crate::fidelity::{self, Config, report};

/// A cell grid, columns × rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cells {
    pub cols: u16,
    pub rows: u16,
}

/// Parses `COLSxROWS`, e.g. `200x60`.
pub fn parse_cells(s: &str) -> Result<Cells, String> {
    let (c, r) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size `{s}` is not COLSxROWS, e.g. 200x60"))?;
    let n = |v: &str, name: &str| -> Result<u16, String> {
        match v.trim().parse::<u16>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(format!(
                "{name} `{v}` in size `{s}` is not a whole number from 1 to 65535"
            )),
        }
    };
    Ok(Cells {
        cols: n(c, "columns")?,
        rows: n(r, "rows")?,
    })
}

/// Arguments of `termrast bench fidelity`.
#[derive(Debug, Args)]
pub struct FidelityArgs {
    /// Cell grid, COLSxROWS; each cell is painted at 8×16 pixels.
    #[arg(long, value_parser = parse_cells, default_value = "200x60")]
    pub size: Cells,
    /// One view per model instead of three.
    #[arg(long)]
    pub quick: bool,
    /// Also write every row of every view as CSV to FILE.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Write the reference and every painted screen as PNGs into DIR.
    #[arg(long, value_name = "DIR")]
    pub keep: Option<PathBuf>,
    /// Leave chafa out even when it is installed.
    #[arg(long)]
    pub no_chafa: bool,
}

/// Runs the benchmark and prints the table and its notes.
pub fn run(args: &FidelityArgs, out: &mut impl Write) -> Result<(), super::CliError> {
    let start = Instant::now();
    let mut config = Config::new(
        args.size.cols,
        args.size.rows,
        fidelity::standard_views(args.quick),
    )?;
    config.chafa = !args.no_chafa;
    config.keep.clone_from(&args.keep);
    let outcome = fidelity::run(&config)?;
    let views = config.views.len();
    writeln!(
        out,
        "fidelity at {}×{} cells ({}×{} px), mean over {views} view{}; * = best SSIM of its colour depth and palette",
        config.cols,
        config.rows,
        config.pixels().0,
        config.pixels().1,
        if views == 1 { "" } else { "s" }
    )?;
    report::write_table(out, &report::summarise(&outcome.measurements))?;
    writeln!(out)?;
    for note in &outcome.notes {
        writeln!(out, "note: {note}")?;
    }
    if let Some(path) = &args.csv {
        let mut csv = Vec::new();
        report::write_csv(&mut csv, &outcome.measurements)?;
        std::fs::write(path, csv).map_err(|e| fidelity::FidelityError::Io(path.clone(), e))?;
        writeln!(out, "note: every view's rows written to {}", path.display())?;
    }
    writeln!(
        out,
        "{} frames scored in {:.1} s",
        outcome.measurements.len(),
        start.elapsed().as_secs_f64()
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_sizes_parse() {
        assert_eq!(
            parse_cells("200x60"),
            Ok(Cells {
                cols: 200,
                rows: 60
            })
        );
        assert!(parse_cells("0x60").is_err());
        assert!(parse_cells("200").is_err());
        assert!(parse_cells("200x70000").is_err());
    }
}

//! `termrast line X0 Y0 X1 Y1`: the midpoint algorithm's pixels and, with `--trace`,
//! its decisions step by step.

use std::fmt::Write as _;
use std::io::{self, Write};

use clap::{Args, ValueEnum};

use crate::raster::Target;
use crate::raster::line::{Line, LineRangeError, MAX_LINE_COORD, NoTrace, Step};

/// Largest grid printed without `--size`.
const MAX_GRID_SIDE: i64 = 400;

/// Most pixels `--trace` or `--format cells` shows (with `--size`, of the part inside
/// the target): about 100 MB of steps and text. Checked before the walk.
pub const MAX_LISTED: i64 = 1_000_000;

/// Arguments of `termrast line`.
#[derive(Debug, Args)]
#[command(allow_negative_numbers = true)]
pub struct LineArgs {
    pub x0: i64,
    pub y0: i64,
    pub x1: i64,
    pub y1: i64,
    /// Print the decision table: d before each step, E or NE, d after (at most
    /// 1000000 steps; with --size only the pixels inside count).
    #[arg(long)]
    pub trace: bool,
    /// `grid` draws the pixels (`#`; at most 400×400 without --size), `cells` lists
    /// them as `x,y` (at most 1000000; with --size only the pixels inside count).
    #[arg(long, value_enum, default_value_t = LineFormat::Grid)]
    pub format: LineFormat,
    /// Clip to a WxH target (only pixels inside it are drawn and traced).
    #[arg(long, value_parser = super::parse_size)]
    pub size: Option<Target>,
}

/// Output formats of `line`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LineFormat {
    Grid,
    Cells,
}

/// What can go wrong.
#[derive(Debug, thiserror::Error)]
pub enum LineError {
    #[error(transparent)]
    Range(#[from] LineRangeError),
    #[error("coordinate {0} is out of range: line coordinates must be within ±2^40")]
    Coordinate(i64),
    #[error(
        "the line has {pixels} pixels; {what} shows at most {MAX_LISTED} \
         (with --size WxH, only those inside count)"
    )]
    TooManyPixels { pixels: i64, what: &'static str },
    #[error("the grid would be {0}×{1} cells; use --format cells or --size WxH")]
    GridTooLarge(i64, i64),
    #[error(transparent)]
    Io(#[from] io::Error),
}

/// The trace as a table, one row per step.
#[must_use]
pub fn trace_table(line: &Line, steps: &[Step]) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "line ({},{}) -> ({},{}): octant {}, reflections: {}",
        line.a.0,
        line.a.1,
        line.b.0,
        line.b.1,
        line.octant,
        line.reflections()
    );
    let _ = writeln!(
        t,
        "dx={} dy={} incrE={} incrNE={} d0={}   E = {}, NE = {}",
        line.dx,
        line.dy,
        line.incr_e,
        line.incr_ne,
        line.d0(),
        line.direction(crate::raster::line::Move::E),
        line.direction(crate::raster::line::Move::NE)
    );
    let _ = writeln!(
        t,
        "{:>5} {:>12} {:>8}  {:<8} {:>8}",
        "step", "pixel", "d", "decision", "d after"
    );
    for s in steps {
        let px = format!("({},{})", s.pixel.0, s.pixel.1);
        match s.decision {
            Some((d, mv, after)) => {
                let _ = writeln!(
                    t,
                    "{:>5} {:>12} {:>8}  {:<8} {:>8}",
                    s.k,
                    px,
                    d,
                    mv.name(),
                    after
                );
            }
            None => {
                let _ = writeln!(t, "{:>5} {:>12} {:>8}  {:<8}", s.k, px, "-", "end");
            }
        }
    }
    t
}

/// Runs `termrast line`.
///
/// Every size is checked before the walk, so a line too long to show fails at once
/// in bounded memory.
pub fn run(args: &LineArgs, out: &mut impl Write) -> Result<(), LineError> {
    let coords = [args.x0, args.y0, args.x1, args.y1];
    if let Some(&c) = coords
        .iter()
        .find(|c| c.unsigned_abs() > MAX_LINE_COORD as u64)
    {
        return Err(LineError::Coordinate(c));
    }
    let line = Line::new((args.x0, args.y0), (args.x1, args.y1))?;
    // Pixels the walk visits: the whole line, or its part inside the target.
    let walked = match args.size {
        Some(t) => line
            .clip_range(t.width.into(), t.height.into())
            .map_or(0, |(k0, k1)| k1 - k0 + 1),
        None => line.len(),
    };
    let what = match (args.trace, args.format) {
        (true, LineFormat::Cells) => Some("--trace with --format cells"),
        (true, LineFormat::Grid) => Some("--trace"),
        (false, LineFormat::Cells) => Some("--format cells"),
        (false, LineFormat::Grid) => None,
    };
    if let Some(what) = what
        && walked > MAX_LISTED
    {
        return Err(LineError::TooManyPixels {
            pixels: walked,
            what,
        });
    }
    // The grid's extent: the target, or the line's bounding box.
    let (x0, y0, x1, y1) = match args.size {
        Some(t) => (0, 0, i64::from(t.width) - 1, i64::from(t.height) - 1),
        None => (
            args.x0.min(args.x1),
            args.y0.min(args.y1),
            args.x0.max(args.x1),
            args.y0.max(args.y1),
        ),
    };
    let (w, h) = (x1 - x0 + 1, y1 - y0 + 1);
    if args.format == LineFormat::Grid
        && args.size.is_none()
        && (w > MAX_GRID_SIDE || h > MAX_GRID_SIDE)
    {
        return Err(LineError::GridTooLarge(w, h));
    }
    let mut pixels = Vec::new();
    let mut steps: Vec<Step> = Vec::new();
    let plot = |x, y| pixels.push((x, y));
    match (args.size, args.trace) {
        (Some(t), true) => line.draw_clipped(t.width.into(), t.height.into(), plot, &mut steps),
        (Some(t), false) => line.draw_clipped(t.width.into(), t.height.into(), plot, &mut NoTrace),
        (None, true) => line.draw(plot, &mut steps),
        (None, false) => line.draw(plot, &mut NoTrace),
    }
    if args.trace {
        out.write_all(trace_table(&line, &steps).as_bytes())?;
    }
    match args.format {
        LineFormat::Cells => {
            let cells: Vec<String> = pixels.iter().map(|(x, y)| format!("{x},{y}")).collect();
            writeln!(out, "{}", cells.join(" "))?;
        }
        LineFormat::Grid => {
            let mut grid = vec![b'.'; (w * h) as usize];
            for (x, y) in &pixels {
                grid[((y - y0) * w + (x - x0)) as usize] = b'#';
            }
            if args.size.is_none() {
                writeln!(out, "origin ({x0},{y0})")?;
            }
            for row in grid.chunks(w as usize) {
                out.write_all(row)?;
                out.write_all(b"\n")?;
            }
        }
    }
    Ok(())
}

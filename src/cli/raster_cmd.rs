//! `termrast raster`: 2D triangles from stdin to a coverage grid on stdout.

use std::io::{self, BufRead, Write};

use clap::{Args, ValueEnum};

use crate::raster::{CountGrid, Setup, Target, Traversal};

/// Arguments of `termrast raster`.
#[derive(Debug, Args)]
pub struct RasterArgs {
    /// Target size in pixels, WxH.
    #[arg(long, value_parser = super::parse_size, default_value = "32x16")]
    pub size: Target,
    /// Which traversal to run (all give identical coverage).
    #[arg(long, value_enum, default_value_t = Traversal::Wide)]
    pub traversal: Traversal,
    /// Output: `grid` (`#` covered), `cells` (covered `x,y` per triangle, a line each)
    /// or `counts` (how many triangles covered each pixel: `.`, 1–9, `+` for more).
    #[arg(long, value_enum, default_value_t = Format::Grid)]
    pub format: Format,
}

/// Output formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    Grid,
    Cells,
    Counts,
}

/// What can go wrong.
#[derive(Debug, thiserror::Error)]
pub enum RasterError {
    #[error("stdin line {line}: {message}")]
    BadLine { line: usize, message: String },
    #[error(transparent)]
    Io(#[from] io::Error),
}

/// Parses one input line: `None` for blank lines and `#` comments.
pub fn parse_triangle(text: &str) -> Result<Option<[[f64; 2]; 3]>, String> {
    let text = text.trim();
    if text.is_empty() || text.starts_with('#') {
        return Ok(None);
    }
    let nums: Vec<&str> = text.split_whitespace().collect();
    if nums.len() != 6 {
        return Err(format!(
            "expected 6 numbers `x0 y0 x1 y1 x2 y2`, found {}",
            nums.len()
        ));
    }
    let mut v = [0f64; 6];
    for (slot, s) in v.iter_mut().zip(&nums) {
        *slot = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    }
    Ok(Some([[v[0], v[1]], [v[2], v[3]], [v[4], v[5]]]))
}

/// Runs the command over `input`, writing the chosen format to `out`.
pub fn run(args: &RasterArgs, input: impl BufRead, mut out: impl Write) -> Result<(), RasterError> {
    let target = args.size;
    let mut grid = CountGrid::new(target.width, target.height);
    let mut cells: Vec<(u32, u32)> = Vec::new();
    for (n, line) in input.lines().enumerate() {
        let line = line?;
        let tri = parse_triangle(&line).map_err(|message| RasterError::BadLine {
            line: n + 1,
            message,
        })?;
        let Some(tri) = tri else { continue };
        let setup = Setup::new(tri, target).ok();
        match args.format {
            Format::Cells => {
                cells.clear();
                if let Some(s) = &setup {
                    args.traversal.run(s, &mut cells);
                }
                cells.sort_unstable_by_key(|&(x, y)| (y, x));
                let row: Vec<String> = cells.iter().map(|(x, y)| format!("{x},{y}")).collect();
                writeln!(out, "{}", row.join(" "))?;
            }
            Format::Grid | Format::Counts => {
                if let Some(s) = &setup {
                    args.traversal.run(s, &mut grid);
                }
            }
        }
    }
    if args.format != Format::Cells {
        write_grid(&grid, args.format, &mut out)?;
    }
    Ok(())
}

fn write_grid(grid: &CountGrid, format: Format, out: &mut impl Write) -> io::Result<()> {
    let mut line = String::with_capacity(grid.width as usize + 1);
    for y in 0..grid.height {
        line.clear();
        for x in 0..grid.width {
            let c = grid.get(x, y);
            line.push(match (format, c) {
                (_, 0) => '.',
                (Format::Counts, 1..=9) => char::from(b'0' + c as u8),
                (Format::Counts, _) => '+',
                _ => '#',
            });
        }
        line.push('\n');
        out.write_all(line.as_bytes())?;
    }
    Ok(())
}

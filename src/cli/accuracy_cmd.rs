//! `termrast bench accuracy`: the accuracy/speed table, its CSV and a chart.

use std::fmt::Write as _;
use std::io::Write;
use std::path::PathBuf;

use clap::Args;
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::Color;
use ratatui::symbols::Marker;
use ratatui::text::Line as TextLine;
use ratatui::widgets::canvas::{Canvas, Line};
use ratatui::widgets::{Block, Widget};

use crate::accuracy::cases::{self, HardCase};
use crate::accuracy::edge::EdgeArith;
use crate::accuracy::timing::{Comparison, Timing};
use crate::accuracy::{Config, Errors, Family, Row, run};
use crate::raster::Target;

/// Arguments of `termrast bench accuracy`.
#[derive(Debug, Args)]
pub struct AccuracyArgs {
    /// Terminal sizes only (80x24, 200x60) with thinner workloads: every variant, in
    /// seconds.
    #[arg(long)]
    pub quick: bool,
    /// Also write every measurement (one row per variant, workload and size) as CSV.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Draw time against error per family for the largest size, with the Pareto front.
    #[arg(long)]
    pub chart: bool,
}

/// Runs the matrix and prints the tables (and chart), progress on stderr.
pub fn run_cmd(args: &AccuracyArgs, out: &mut impl Write) -> Result<(), super::CliError> {
    let config = if args.quick {
        Config::quick()
    } else {
        Config::full()
    };
    let rows = run(&config, |what| eprintln!("measuring {what}"));
    let cases = cases::all();
    out.write_all(report(&rows, &config, &cases).as_bytes())?;
    if let (true, Some(&size)) = (args.chart, config.sizes.last()) {
        out.write_all(chart(&rows, size).as_bytes())?;
    }
    if let Some(path) = &args.csv {
        std::fs::write(path, csv(&rows)).map_err(|e| {
            super::CliError::Io(std::io::Error::new(
                e.kind(),
                format!("{}: {e}", path.display()),
            ))
        })?;
    }
    Ok(())
}

/// One variant's measurements at one size, summed over its workloads.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    pub family: Option<Family>,
    pub variant: &'static str,
    /// Nanoseconds of one run of every workload: medians and interval ends summed.
    pub time: Timing,
    pub triangles: u64,
    pub pixels: u64,
    /// Summed counts, the largest maxima, and means averaged over the workloads.
    pub errors: Errors,
}

impl Summary {
    /// Nanoseconds per triangle over all workloads.
    #[must_use]
    pub fn ns_per_triangle(&self) -> f64 {
        self.time.median / self.triangles.max(1) as f64
    }

    /// Million pixels per second over all workloads.
    #[must_use]
    pub fn mpx_per_s(&self) -> f64 {
        self.pixels as f64 / self.time.median.max(1.0) * 1e3
    }

    /// Against the family's baseline variant: `baseline` for itself, `within noise`
    /// when the intervals overlap, else the difference in per cent of the baseline.
    #[must_use]
    pub fn versus(&self, base: &Summary) -> String {
        if self.variant == base.variant {
            return "baseline".into();
        }
        match self.time.compare(&base.time) {
            Comparison::WithinNoise => "within noise".into(),
            Comparison::Slower | Comparison::Faster => {
                let pct =
                    (self.time.median / base.time.median.max(f64::MIN_POSITIVE) - 1.0) * 100.0;
                format!("{pct:+.0}%")
            }
        }
    }

    /// The family's headline error (what the chart plots).
    #[must_use]
    pub fn error(&self) -> f64 {
        match self.family {
            Some(Family::Edge | Family::Traversal) => self.errors.mismatches.unwrap_or(0) as f64,
            Some(Family::Interpolation) => self.errors.attr_max_px.unwrap_or(0.0),
            Some(Family::AntiAliasing) => self.errors.aa_mean.unwrap_or(0.0),
            Some(Family::Depth) => self.errors.zfight.unwrap_or(0.0),
            None => 0.0,
        }
    }
}

fn add<T: std::ops::Add<Output = T>>(a: Option<T>, b: Option<T>) -> Option<T> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a + b),
        (a, b) => a.or(b),
    }
}

fn max(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    }
}

/// Sums the rows of each variant of `family` at `size`, in table order.
#[must_use]
pub fn summarize(rows: &[Row], family: Family, size: Target) -> Vec<Summary> {
    let mut out: Vec<Summary> = Vec::new();
    let mut means: Vec<[(f64, u32); 3]> = Vec::new();
    for r in rows
        .iter()
        .filter(|r| r.family == family && r.target == size)
    {
        let i = match out.iter().position(|s| s.variant == r.variant) {
            Some(i) => i,
            None => {
                out.push(Summary {
                    family: Some(family),
                    variant: r.variant,
                    ..Summary::default()
                });
                means.push([(0.0, 0); 3]);
                out.len() - 1
            }
        };
        let s = &mut out[i];
        let e = &r.errors;
        s.time = s.time.plus(&r.time);
        s.triangles += r.triangles;
        s.pixels += r.pixels;
        let t = &mut s.errors;
        t.mismatches = add(t.mismatches, e.mismatches);
        t.holes = add(t.holes, e.holes);
        t.double_hits = add(t.double_hits, e.double_hits);
        t.attr_max = max(t.attr_max, e.attr_max);
        t.attr_max_px = max(t.attr_max_px, e.attr_max_px);
        t.aa_max = max(t.aa_max, e.aa_max);
        t.zfight = max(t.zfight, e.zfight);
        // Means are averaged over the workloads that have them.
        for (m, v) in means[i]
            .iter_mut()
            .zip([e.attr_mean, e.attr_mean_px, e.aa_mean])
        {
            if let Some(v) = v {
                *m = (m.0 + v, m.1 + 1);
            }
        }
    }
    for (s, m) in out.iter_mut().zip(means) {
        let mean = |(sum, n): (f64, u32)| (n > 0).then(|| sum / f64::from(n));
        s.errors.attr_mean = mean(m[0]);
        s.errors.attr_mean_px = mean(m[1]);
        s.errors.aa_mean = mean(m[2]);
    }
    out
}

fn opt_u(v: Option<u64>) -> String {
    v.map_or_else(|| "—".into(), |v| v.to_string())
}

fn opt_e(v: Option<f64>) -> String {
    v.map_or_else(|| "—".into(), |v| format!("{v:.2e}"))
}

/// The printed report: per size, one table per family with one row per variant;
/// then the hard cases.
#[must_use]
pub fn report(rows: &[Row], config: &Config, hard: &[HardCase]) -> String {
    let mut s = String::new();
    let p = &config.timing;
    let _ = writeln!(
        s,
        "termrast bench accuracy{}: median of at least {} rounds per measurement, more until \
         its 95% interval is within ±{}% or {} ms are spent; ± is that interval summed over \
         the workloads; \"within noise\": the intervals of a variant and its family's \
         baseline overlap\n",
        if config.scale < 1.0 { " --quick" } else { "" },
        p.min_rounds,
        p.target_spread * 100.0,
        p.budget.as_millis(),
    );
    for &size in &config.sizes {
        let _ = writeln!(s, "== {}x{} ==", size.width, size.height);
        for family in Family::ALL {
            let sums = summarize(rows, family, size);
            if sums.is_empty() {
                continue;
            }
            let workloads: Vec<&str> = {
                let mut w: Vec<&str> = rows
                    .iter()
                    .filter(|r| r.family == family && r.target == size)
                    .map(|r| r.workload)
                    .collect();
                w.dedup();
                w.sort_unstable();
                w.dedup();
                w
            };
            let _ = writeln!(s, "{} ({})", family.name(), workloads.join(", "));
            let (h, cols): (&str, fn(&Summary) -> String) = match family {
                Family::Edge | Family::Traversal => ("mismatches  holes  double hits", |m| {
                    format!(
                        "{:>10}  {:>5}  {:>11}",
                        opt_u(m.errors.mismatches),
                        opt_u(m.errors.holes),
                        opt_u(m.errors.double_hits)
                    )
                }),
                Family::Interpolation => ("max err (px)  mean err (px)  max err (uv)", |m| {
                    format!(
                        "{:>12}  {:>13}  {:>12}",
                        opt_e(m.errors.attr_max_px),
                        opt_e(m.errors.attr_mean_px),
                        opt_e(m.errors.attr_max)
                    )
                }),
                Family::AntiAliasing => ("mean |cov−area|  max |cov−area|", |m| {
                    format!(
                        "{:>15}  {:>14}",
                        opt_e(m.errors.aa_mean),
                        opt_e(m.errors.aa_max)
                    )
                }),
                Family::Depth => ("z-fighting", |m| {
                    format!(
                        "{:>10}",
                        m.errors
                            .zfight
                            .map_or_else(|| "—".into(), |z| format!("{:.3}%", z * 100.0))
                    )
                }),
            };
            let base = sums
                .iter()
                .find(|m| m.variant == family.baseline())
                .unwrap_or(&sums[0]);
            let _ = writeln!(
                s,
                "  {:<20} {:>10} {:>7} {:>10}  {:<14}  {h}",
                "variant",
                "ns/tri",
                "±",
                "Mpx/s",
                format!("vs {}", base.variant)
            );
            for m in &sums {
                let _ = writeln!(
                    s,
                    "  {:<20} {:>10.1} {:>7} {:>10.1}  {:<14}  {}",
                    m.variant,
                    m.ns_per_triangle(),
                    m.time.spread_label(),
                    m.mpx_per_s(),
                    m.versus(base),
                    cols(m)
                );
            }
            s.push('\n');
        }
    }
    let _ = writeln!(s, "== hard cases (coverage against the i128 oracle) ==");
    let _ = write!(s, "  {:<36}", "case");
    for v in EdgeArith::ALL {
        let _ = write!(s, " {:>15}", v.name());
    }
    s.push('\n');
    for case in hard {
        let _ = write!(s, "  {:<36}", case.name);
        for v in EdgeArith::ALL {
            let w = cases::wrong(v, case);
            let cell = if case.tiles_target {
                format!("{}/{}/{}", w.mismatches, w.holes, w.double_hits)
            } else {
                w.mismatches.to_string()
            };
            let _ = write!(s, " {cell:>15}");
        }
        s.push('\n');
    }
    let _ = writeln!(
        s,
        "  (pixels wrong; for tilings: wrong/holes/double hits)\n"
    );
    s
}

/// Every row as CSV with a header: the measurements, then the time's interval
/// (`ns_low`, `ns_high`, the 95 % interval of `median_ns`), its spread in per cent and
/// the rounds it was measured over.
#[must_use]
pub fn csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "family,variant,workload,width,height,triangles,pixels,median_ns,ns_per_triangle,mpx_per_s,mismatches,holes,double_hits,attr_max,attr_mean,attr_max_px,attr_mean_px,aa_mean,aa_max,zfight,ns_low,ns_high,spread_pct,rounds\n",
    );
    let u = |v: Option<u64>| v.map(|v| v.to_string()).unwrap_or_default();
    let f = |v: Option<f64>| v.map(|v| format!("{v:e}")).unwrap_or_default();
    for r in rows {
        let e = &r.errors;
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{:.0},{:.2},{:.3},{},{},{},{},{},{},{},{},{},{},{:.0},{:.0},{:.2},{}",
            r.family.name(),
            r.variant,
            r.workload,
            r.target.width,
            r.target.height,
            r.triangles,
            r.pixels,
            r.time.median,
            r.ns_per_triangle(),
            r.mpx_per_s(),
            u(e.mismatches),
            u(e.holes),
            u(e.double_hits),
            f(e.attr_max),
            f(e.attr_mean),
            f(e.attr_max_px),
            f(e.attr_mean_px),
            f(e.aa_mean),
            f(e.aa_max),
            f(e.zfight),
            r.time.low,
            r.time.high,
            r.time.spread() * 100.0,
            r.time.rounds,
        );
    }
    s
}

/// Indices of the summaries on the Pareto front: no other is at least as fast and at
/// least as accurate, and better in one.
#[must_use]
pub fn pareto(sums: &[Summary]) -> Vec<usize> {
    (0..sums.len())
        .filter(|&i| {
            let (t, e) = (sums[i].ns_per_triangle(), sums[i].error());
            !sums.iter().any(|o| {
                let (ot, oe) = (o.ns_per_triangle(), o.error());
                ot <= t && oe <= e && (ot < t || oe < e)
            })
        })
        .collect()
}

/// Time (x, ns per triangle, log scale) against error (y, log scale) per family, each
/// variant drawn as a letter, the Pareto front joined by a line.
#[must_use]
pub fn chart(rows: &[Row], size: Target) -> String {
    let mut s = String::new();
    for family in Family::ALL {
        let sums = summarize(rows, family, size);
        if sums.is_empty() {
            continue;
        }
        let front = pareto(&sums);
        // Errors of exactly 0 are drawn on the bottom edge.
        let nonzero = sums.iter().map(Summary::error).filter(|&e| e > 0.0);
        let floor = nonzero.clone().fold(f64::INFINITY, f64::min);
        let floor = if floor.is_finite() {
            floor / 10.0
        } else {
            1e-9
        };
        let point = |m: &Summary| {
            (
                m.ns_per_triangle().max(1e-3).log10(),
                m.error().max(floor).log10(),
            )
        };
        let pts: Vec<(f64, f64)> = sums.iter().map(point).collect();
        let (x0, x1) = bounds(pts.iter().map(|p| p.0));
        let (y0, y1) = bounds(pts.iter().map(|p| p.1));
        let area = Rect::new(0, 0, 72, 16);
        let mut buf = Buffer::empty(area);
        let mut front_pts: Vec<(f64, f64)> = front.iter().map(|&i| pts[i]).collect();
        front_pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        Canvas::default()
            .block(Block::bordered().title(TextLine::from(format!(
                " {}: x ns/triangle {:.0}–{:.0}, y error (both log) ",
                family.name(),
                10f64.powf(x0),
                10f64.powf(x1),
            ))))
            .marker(Marker::Braille)
            .x_bounds([x0, x1])
            .y_bounds([y0, y1])
            .paint(|ctx| {
                for w in front_pts.windows(2) {
                    ctx.draw(&Line::new(w[0].0, w[0].1, w[1].0, w[1].1, Color::Reset));
                }
                ctx.layer();
                for (k, p) in pts.iter().enumerate() {
                    ctx.print(p.0, p.1, letter(k).to_string());
                }
            })
            .render(area, &mut buf);
        for y in 0..area.height {
            let line: String = (0..area.width)
                .map(|x| buf[(x, y)].symbol().to_string())
                .collect();
            let _ = writeln!(s, "{}", line.trim_end());
        }
        let _ = writeln!(s, "  error: {}", family.error_name());
        for (k, m) in sums.iter().enumerate() {
            let _ = writeln!(
                s,
                "  {} {:<20} {:>10.1} ns/tri  error {:.3e}{}",
                letter(k),
                m.variant,
                m.ns_per_triangle(),
                m.error(),
                if front.contains(&k) {
                    "  (Pareto front)"
                } else {
                    ""
                }
            );
        }
        s.push('\n');
    }
    s
}

fn letter(k: usize) -> char {
    char::from(b'a' + (k % 26) as u8)
}

/// A range around values with a margin (a unit range if they are all equal).
fn bounds(v: impl Iterator<Item = f64> + Clone) -> (f64, f64) {
    let lo = v.clone().fold(f64::INFINITY, f64::min);
    let hi = v.fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() || !hi.is_finite() {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.08).max(0.1);
    (lo - pad, hi + pad)
}

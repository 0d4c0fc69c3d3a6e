//! The benchmark's table (averaged over views) and CSV (every view).

use std::io::{self, Write};

use super::bench::{Measurement, Source};
use crate::terminal::ColorMode;

/// One row of the table: a source, method and colour depth averaged over the views.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub source: Source,
    pub method: String,
    pub colors: ColorMode,
    /// Mean SSIM over the views.
    pub ssim: f64,
    /// Mean PSNR over the views, dB.
    pub psnr: f64,
    /// Mean bytes per frame.
    pub bytes: f64,
    /// Unknown characters, summed over the views.
    pub unpainted: usize,
    pub views: usize,
}

/// Averages the measurements of each source, method and colour depth over the views.
/// Rows are grouped by colour depth (in `ColorMode::ALL` order), termrast's first,
/// each in the order first measured.
#[must_use]
pub fn summarise(ms: &[Measurement]) -> Vec<Summary> {
    let mut rows: Vec<Summary> = Vec::new();
    for m in ms {
        let same =
            |s: &&mut Summary| s.source == m.source && s.method == m.method && s.colors == m.colors;
        if let Some(s) = rows.iter_mut().find(|s| same(s)) {
            s.ssim += m.score.ssim;
            s.psnr += m.score.psnr;
            s.bytes += m.bytes as f64;
            s.unpainted += m.unpainted;
            s.views += 1;
        } else {
            rows.push(Summary {
                source: m.source,
                method: m.method.clone(),
                colors: m.colors,
                ssim: m.score.ssim,
                psnr: m.score.psnr,
                bytes: m.bytes as f64,
                unpainted: m.unpainted,
                views: 1,
            });
        }
    }
    for s in &mut rows {
        let n = s.views as f64;
        s.ssim /= n;
        s.psnr /= n;
        s.bytes /= n;
    }
    let depth = |c: ColorMode| ColorMode::ALL.iter().position(|&d| d == c);
    rows.sort_by_key(|s| (depth(s.colors), s.source == Source::Chafa));
    rows
}

/// The table: one block per colour depth, the best SSIM of each block starred.
pub fn write_table(out: &mut impl Write, rows: &[Summary]) -> io::Result<()> {
    writeln!(
        out,
        "{:<10} {:<9} {:<41} {:>7}  {:>8} {:>12} {:>10}",
        "colours", "source", "glyphs / symbols", "SSIM", "PSNR dB", "bytes/frame", "unpainted"
    )?;
    for (i, s) in rows.iter().enumerate() {
        if i > 0 && rows[i - 1].colors != s.colors {
            writeln!(out)?;
        }
        let best = rows
            .iter()
            .filter(|r| r.colors == s.colors)
            .all(|r| r.ssim <= s.ssim);
        writeln!(
            out,
            "{:<10} {:<9} {:<41} {:>7.4}{} {:>8.2} {:>12.0} {:>10}",
            s.colors.name(),
            s.source.name(),
            s.method,
            s.ssim,
            if best { '*' } else { ' ' },
            s.psnr,
            s.bytes,
            s.unpainted
        )?;
    }
    Ok(())
}

/// Every measurement, one line per view.
pub fn write_csv(out: &mut impl Write, ms: &[Measurement]) -> io::Result<()> {
    writeln!(
        out,
        "view,source,method,colors,ssim,psnr_db,bytes,unpainted,printed_cols,printed_rows"
    )?;
    for m in ms {
        writeln!(
            out,
            "{},{},{},{},{:.6},{:.4},{},{},{},{}",
            m.view,
            m.source.name(),
            m.method,
            m.colors.name(),
            m.score.ssim,
            m.score.psnr,
            m.bytes,
            m.unpainted,
            m.printed.0,
            m.printed.1
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fidelity::metrics::Score;

    fn m(view: &str, source: Source, method: &str, colors: ColorMode, ssim: f64) -> Measurement {
        Measurement {
            view: view.into(),
            source,
            method: method.into(),
            colors,
            score: Score { ssim, psnr: 20.0 },
            bytes: 100,
            unpainted: 1,
            printed: (20, 8),
        }
    }

    #[test]
    fn views_are_averaged_and_depths_grouped() {
        let ms = [
            m("a", Source::Chafa, "quad", ColorMode::None, 0.2),
            m("a", Source::Termrast, "half", ColorMode::Truecolor, 0.5),
            m("b", Source::Termrast, "half", ColorMode::Truecolor, 0.7),
            m("a", Source::Termrast, "half", ColorMode::None, 0.4),
        ];
        let rows = summarise(&ms);
        assert_eq!(rows.len(), 3);
        assert_eq!((rows[0].colors, rows[0].views), (ColorMode::Truecolor, 2));
        assert!((rows[0].ssim - 0.6).abs() < 1e-12 && rows[0].unpainted == 2);
        assert_eq!(
            (rows[1].source, rows[2].source),
            (Source::Termrast, Source::Chafa)
        );
        let mut table = Vec::new();
        write_table(&mut table, &rows).unwrap();
        let table = String::from_utf8(table).unwrap();
        assert!(
            table.contains("0.4000*") && table.contains("0.2000 "),
            "{table}"
        );
        let mut csv = Vec::new();
        write_csv(&mut csv, &ms).unwrap();
        assert_eq!(String::from_utf8(csv).unwrap().lines().count(), 5);
    }
}

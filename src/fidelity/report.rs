//! The benchmark's table (averaged over views) and CSV (every view).

use std::io::{self, Write};

use super::bench::PALETTES;
use super::bench::{Measurement, Source};
use crate::terminal::ColorMode;
use crate::terminal::Palette;

/// One row of the table: a source, method, colour depth and palette averaged over the
/// views.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub source: Source,
    pub method: String,
    pub colors: ColorMode,
    pub palette: Palette,
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

/// Averages the measurements of each source, method, colour depth and palette over the
/// views. Rows are grouped by colour depth (in `ColorMode::ALL` order), then palette
/// (xterm's first), termrast's first, each in the order first measured.
#[must_use]
pub fn summarise(ms: &[Measurement]) -> Vec<Summary> {
    let mut rows: Vec<Summary> = Vec::new();
    for m in ms {
        let same = |s: &&mut Summary| {
            s.source == m.source
                && s.method == m.method
                && s.colors == m.colors
                && s.palette == m.palette
        };
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
                palette: m.palette,
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
    let palette = |p: Palette| PALETTES.iter().position(|&q| q == p);
    rows.sort_by_key(|s| {
        (
            depth(s.colors),
            palette(s.palette),
            s.source == Source::Chafa,
        )
    });
    rows
}

/// How the table names a row's palette: only the indexed depths have one.
fn palette_name(s: &Summary) -> &'static str {
    match s.colors {
        ColorMode::Ansi256 | ColorMode::Ansi16 => s.palette.name,
        ColorMode::Truecolor | ColorMode::None => "-",
    }
}

/// The table: one block per colour depth and palette, the best SSIM of each block
/// starred (rows on different palettes are different terminals).
pub fn write_table(out: &mut impl Write, rows: &[Summary]) -> io::Result<()> {
    writeln!(
        out,
        "{:<10} {:<8} {:<9} {:<41} {:>7}  {:>8} {:>12} {:>10}",
        "colours",
        "palette",
        "source",
        "glyphs / symbols",
        "SSIM",
        "PSNR dB",
        "bytes/frame",
        "unpainted"
    )?;
    let block = |s: &Summary| (s.colors, s.palette);
    for (i, s) in rows.iter().enumerate() {
        if i > 0 && block(&rows[i - 1]) != block(s) {
            writeln!(out)?;
        }
        let best = rows
            .iter()
            .filter(|r| block(r) == block(s))
            .all(|r| r.ssim <= s.ssim);
        writeln!(
            out,
            "{:<10} {:<8} {:<9} {:<41} {:>7.4}{} {:>8.2} {:>12.0} {:>10}",
            s.colors.name(),
            palette_name(s),
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
        "view,source,method,colors,palette,ssim,psnr_db,bytes,unpainted,printed_cols,printed_rows"
    )?;
    for m in ms {
        writeln!(
            out,
            "{},{},{},{},{},{:.6},{:.4},{},{},{},{}",
            m.view,
            m.source.name(),
            m.method,
            m.colors.name(),
            m.palette.name,
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
            palette: Palette::XTERM,
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

    #[test]
    fn palettes_are_rows_of_their_own_each_with_its_best() {
        let on = |p: Palette, source, ssim| Measurement {
            palette: p,
            ..m("a", source, "quad", ColorMode::Ansi16, ssim)
        };
        let ms = [
            on(Palette::CHAFA, Source::Chafa, 0.9),
            on(Palette::XTERM, Source::Chafa, 0.5),
            on(Palette::XTERM, Source::Termrast, 0.7),
            on(Palette::CHAFA, Source::Termrast, 0.6),
            m("a", Source::Termrast, "quad", ColorMode::Truecolor, 0.8),
        ];
        let rows = summarise(&ms);
        let key: Vec<_> = rows
            .iter()
            .map(|r| (r.colors, r.palette, r.source))
            .collect();
        assert_eq!(
            key,
            [
                (ColorMode::Truecolor, Palette::XTERM, Source::Termrast),
                (ColorMode::Ansi16, Palette::XTERM, Source::Termrast),
                (ColorMode::Ansi16, Palette::XTERM, Source::Chafa),
                (ColorMode::Ansi16, Palette::CHAFA, Source::Termrast),
                (ColorMode::Ansi16, Palette::CHAFA, Source::Chafa),
            ]
        );
        let mut table = Vec::new();
        write_table(&mut table, &rows).unwrap();
        let table = String::from_utf8(table).unwrap();
        let lines: Vec<&str> = table.lines().collect();
        // A blank line between blocks; a star for the best of each palette's block.
        assert_eq!(lines.len(), 1 + 5 + 2, "{table}");
        assert!(lines[1].starts_with("truecolor  -  "), "{table}");
        assert!(lines[3].contains("xterm    termrast") && lines[3].contains("0.7000*"));
        assert!(lines[4].contains("0.5000 "), "{table}");
        assert!(lines[6].contains("chafa    termrast") && lines[6].contains("0.6000 "));
        assert!(lines[7].contains("0.9000*"), "{table}");
        let mut csv = Vec::new();
        write_csv(&mut csv, &ms).unwrap();
        let csv = String::from_utf8(csv).unwrap();
        assert!(
            csv.lines()
                .nth(1)
                .unwrap()
                .starts_with("a,chafa,quad,16,chafa,")
        );
    }
}

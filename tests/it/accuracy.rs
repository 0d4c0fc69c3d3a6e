//! The accuracy matrix on a small configuration: every variant present under its
//! name, exact variants exact, and the errors ordered as they must be; times reported
//! with their spread (never asserted fast or slow), in the table, the CSV and `bench
//! effects`.

use std::time::Duration;

use termrast::accuracy::timing::Policy;
use termrast::accuracy::{Config, Family, Row, run};
use termrast::cli::accuracy_cmd::{chart, csv, pareto, report, summarize};
use termrast::cli::effects_cmd::{self, EFFECTS, EffectsArgs};
use termrast::raster::Target;

/// Three short rounds per measurement (a target spread of 100 % is met at once).
fn quick_policy() -> Policy {
    Policy {
        min_round: Duration::from_micros(200),
        ..Policy::new(3, 1.0, Duration::ZERO)
    }
}

fn small() -> (Config, Vec<Row>) {
    let config = Config {
        sizes: vec![Target::new(48, 16)],
        scale: 0.2,
        timing: quick_policy(),
    };
    let rows = run(&config, |_| {});
    (config, rows)
}

#[test]
fn every_variant_is_measured_and_exact_ones_are_exact() {
    let (config, rows) = small();
    let size = config.sizes[0];
    let names = |f: Family| -> Vec<&str> {
        summarize(&rows, f, size)
            .iter()
            .map(|s| s.variant)
            .collect()
    };
    assert_eq!(
        names(Family::Edge),
        [
            "f32-direct",
            "f32-incremental",
            "f64",
            "fixed4",
            "fixed8",
            "i64"
        ]
    );
    assert_eq!(
        names(Family::Traversal),
        ["scalar", "planes", "block", "wide"]
    );
    assert_eq!(
        names(Family::Interpolation),
        [
            "affine",
            "perspective",
            "perspective-4",
            "perspective-8",
            "perspective-16"
        ]
    );
    assert_eq!(names(Family::AntiAliasing), ["1x", "4x", "16x"]);
    assert_eq!(
        names(Family::Depth),
        [
            "depth-f32",
            "depth-unorm24",
            "depth-unorm16",
            "depth-f32-reversed"
        ]
    );
    for r in &rows {
        let t = r.time;
        assert!(t.median > 0.0 && t.median.is_finite(), "{r:?}");
        assert!(t.low <= t.median && t.median <= t.high, "{r:?}");
        assert_eq!(t.rounds, 3, "{r:?}");
        let exact = matches!(r.variant, "fixed8" | "i64") || r.family == Family::Traversal;
        if exact {
            assert_eq!(r.errors.mismatches, Some(0), "{} {}", r.variant, r.workload);
            assert_eq!(r.errors.holes.unwrap_or(0), 0);
            assert_eq!(r.errors.double_hits.unwrap_or(0), 0);
        }
    }
    // More samples, less coverage error.
    let aa = summarize(&rows, Family::AntiAliasing, size);
    assert!(
        aa[0].errors.aa_mean > aa[1].errors.aa_mean && aa[1].errors.aa_mean > aa[2].errors.aa_mean,
        "{aa:?}"
    );
    // Perspective beats affine; reversed f32 depth fights no more than f32, unorm16 more.
    let interp = summarize(&rows, Family::Interpolation, size);
    assert!(interp[1].errors.attr_max_px < interp[0].errors.attr_max_px);
    let depth = summarize(&rows, Family::Depth, size);
    assert!(
        depth[3].errors.zfight <= depth[0].errors.zfight
            && depth[2].errors.zfight >= depth[0].errors.zfight
    );
}

#[test]
fn report_csv_and_chart_name_every_variant() {
    let (config, rows) = small();
    let text = report(&rows, &config, &termrast::accuracy::cases::all());
    let table = csv(&rows);
    let plot = chart(&rows, config.sizes[0]);
    assert_eq!(table.lines().count(), rows.len() + 1);
    assert!(
        table.lines().all(|l| l.split(',').count() == 24),
        "fixed column count"
    );
    // The original columns keep their places; the spread columns come last.
    let header: Vec<&str> = table.lines().next().unwrap().split(',').collect();
    assert_eq!(header[7], "median_ns");
    assert_eq!(header[19], "zfight");
    assert_eq!(header[20..], ["ns_low", "ns_high", "spread_pct", "rounds"]);
    for line in table.lines().skip(1) {
        let f: Vec<f64> = line
            .split(',')
            .map(|v| v.parse().unwrap_or(f64::NAN))
            .collect();
        assert!(f[20] <= f[7] && f[7] <= f[21] && f[22] >= 0.0, "{line}");
        assert_eq!(f[23], 3.0, "{line}");
    }
    for r in &rows {
        assert!(
            text.contains(r.variant) && plot.contains(r.variant),
            "{}",
            r.variant
        );
    }
    // Every variant's line in the table has its spread and its comparison with the
    // family's baseline, which is named in the header.
    for f in Family::ALL {
        assert!(
            text.contains(&format!("vs {}", f.baseline())),
            "{}",
            f.name()
        );
    }
    let variant_lines: Vec<&str> = text
        .lines()
        .take_while(|l| !l.starts_with("== hard cases"))
        .filter(|l| rows.iter().any(|r| l.trim_start().starts_with(r.variant)))
        .collect();
    assert!(variant_lines.len() >= 22, "{text}");
    for l in &variant_lines {
        assert!(l.contains('±') && l.contains('%'), "{l}");
        let differs = l
            .split_whitespace()
            .any(|w| (w.starts_with('+') || w.starts_with('-')) && w.len() > 2 && w.ends_with('%'));
        assert!(
            l.contains("baseline") || l.contains("within noise") || differs,
            "{l}"
        );
    }
    assert_eq!(text.matches("baseline  ").count(), Family::ALL.len());
    // Every family's chart marks a Pareto front, and it is never empty.
    for f in Family::ALL {
        assert!(!pareto(&summarize(&rows, f, config.sizes[0])).is_empty());
    }
    assert!(plot.matches("(Pareto front)").count() >= Family::ALL.len());
}

#[test]
fn bench_effects_prints_every_row_with_its_spread() {
    let args = EffectsArgs {
        rounds: 3,
        spread: 100.0,
        budget: 0.001,
        sizes: vec![Target::new(40, 24)],
    };
    let mut out = Vec::new();
    effects_cmd::run(&args, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    for (name, _, _) in EFFECTS {
        let line = text
            .lines()
            .find(|l| l.starts_with(name))
            .unwrap_or_else(|| panic!("{name} missing:\n{text}"));
        assert!(line.contains('±'), "{line}");
    }
    assert!(text.contains("Δ against \"depth test\""), "{text}");
}

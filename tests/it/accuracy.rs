//! The accuracy matrix on a small configuration: every variant present under its
//! name, exact variants exact, and the errors ordered as they must be.

use termrast::accuracy::{Config, Family, Row, run};
use termrast::cli::accuracy_cmd::{chart, csv, pareto, report, summarize};
use termrast::raster::Target;

fn small() -> (Config, Vec<Row>) {
    let config = Config {
        sizes: vec![Target::new(48, 16)],
        scale: 0.2,
        repeats: 1,
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
        ["scalar", "seed-simd", "block", "wide"]
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
        assert!(r.median_ns > 0.0 && r.median_ns.is_finite(), "{r:?}");
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
        table.lines().all(|l| l.split(',').count() == 20),
        "fixed column count"
    );
    for r in &rows {
        assert!(
            text.contains(r.variant) && plot.contains(r.variant),
            "{}",
            r.variant
        );
    }
    // Every family's chart marks a Pareto front, and it is never empty.
    for f in Family::ALL {
        assert!(!pareto(&summarize(&rows, f, config.sizes[0])).is_empty());
    }
    assert!(plot.matches("(Pareto front)").count() >= Family::ALL.len());
}

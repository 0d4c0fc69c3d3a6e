//! `termrast bench effects`: what each scene effect costs per frame.
//!
//! The rows of a size are drawn in interleaved rounds (one frame of every row, then
//! the next), each row until the 95 % interval of its median frame time is within the
//! target spread or its time budget is spent ([`crate::accuracy::timing`]). A row's
//! difference from the depth-test row is printed only when their intervals do not
//! overlap; otherwise it is `within noise`.

use std::io::Write;
use std::path::Path;
use std::time::Duration;

use clap::Args;

use crate::accuracy::timing::{Comparison, Policy, Timing, measure_each};
use crate::raster::Target;
use crate::scene::Scene;
use crate::scene::render::{SceneFrame, SceneView};

/// Arguments of `termrast bench effects`.
#[derive(Debug, Args)]
pub struct EffectsArgs {
    /// Fewest timed rounds per row and size (a round is one frame, or a few when
    /// frames are shorter than 0.5 ms); more until the median's 95% interval is within
    /// --spread or --budget is spent.
    #[arg(long, alias = "frames", default_value_t = 5, value_parser = clap::value_parser!(u32).range(3..))]
    pub rounds: u32,
    /// Target spread of each row: the half-width of its interval, per cent of the
    /// median.
    #[arg(long, default_value_t = 2.0, value_parser = parse_positive)]
    pub spread: f64,
    /// Time budget per row and size, seconds (the fewest rounds are always run).
    #[arg(long, default_value_t = 1.0, value_parser = parse_positive)]
    pub budget: f64,
    /// Target sizes in samples.
    #[arg(long, value_delimiter = ',', value_parser = super::parse_size, default_value = "400x240,1920x1080")]
    pub sizes: Vec<Target>,
}

/// The model every row draws: the standard camera on a sphere, which has texture
/// coordinates and vertex colours.
pub const EFFECTS_MODEL: &str = "sphere:8192";

/// Each row: a name and the scene keys it adds. Every row but the first has the
/// depth test on, so it shows the cost of its one effect on top of that.
pub const EFFECTS: [(&str, &str, &str); 17] = [
    ("nothing (flat colour, no depth buffer)", "", ""),
    ("depth test", "", ""),
    ("back-face culling", "", "cull = true"),
    ("lighting: flat", "lighting = \"flat\"", ""),
    ("lighting: Gouraud", "lighting = \"gouraud\"", ""),
    ("lighting: Lambert per pixel", "lighting = \"lambert\"", ""),
    ("lighting: Blinn-Phong", "lighting = \"blinn-phong\"", ""),
    (
        "Lambert + a point light",
        "lighting = \"lambert\"\n[[light]]\nkind = \"point\"\nposition = [1.5, 1.0, 2.0]\nintensity = 4.0",
        "",
    ),
    ("vertex colours", "vertex_colors = true", ""),
    (
        "texture, nearest",
        "texture = \"nearest\"\nimage = \"checker\"",
        "",
    ),
    (
        "texture, bilinear",
        "texture = \"bilinear\"\nimage = \"checker\"",
        "",
    ),
    ("fog", "", "fog = { start = 2.0, end = 3.5 }"),
    ("depth shading", "", "depth_shading = true"),
    ("wireframe, hidden lines removed", "", "wireframe = true"),
    ("silhouettes", "", "silhouette = true"),
    ("antialias 4", "", "@4"),
    ("antialias 16", "", "@16"),
];

/// The scene text of a row.
#[must_use]
pub fn effect_scene(row: usize) -> String {
    let (_, material, effects) = EFFECTS[row];
    let (antialias, effects) = match effects.strip_prefix('@') {
        Some(n) => (n, ""),
        None => ("1", effects),
    };
    // Lights declared by a row come after the object in TOML only as a table array
    // of their own: split them off the material keys.
    let (material, lights) = match material.find("[[light]]") {
        Some(i) => (&material[..i], &material[i..]),
        None => (material, ""),
    };
    let depth = if row == 0 { "false" } else { "true" };
    let ambient = if lights.is_empty() {
        ""
    } else {
        "[[light]]\nkind = \"ambient\"\nintensity = 0.1\n"
    };
    format!(
        "[render]\nantialias = {antialias}\n{ambient}{lights}\n[[object]]\nmodel = \"{EFFECTS_MODEL}\"\nrotation = [20, 0, 0]\nspin = {{ speed = 0.5 }}\n[object.material]\n{material}\n[object.effects]\ndepth_test = {depth}\n{effects}\n"
    )
}

/// A positive, finite number.
fn parse_positive(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("`{s}` is not a positive number")),
    }
}

/// The row every other is compared with.
pub const BASELINE_ROW: usize = 1;

/// Milliseconds per frame of every row at one size: the rows drawn in interleaved
/// rounds, the spin advancing 0.05 s a frame.
fn measure_rows(scenes: &[Scene], target: Target, policy: &Policy) -> Vec<Timing> {
    let mut frames: Vec<SceneFrame> = scenes.iter().map(SceneFrame::new).collect();
    let mut drawn = vec![0u32; scenes.len()];
    measure_each(policy, scenes.len(), |i| {
        let view = SceneView {
            time: drawn[i] as f32 * 0.05,
            ..SceneView::default()
        };
        drawn[i] += 1;
        frames[i].draw(&scenes[i], target, &view);
    })
    .iter()
    .map(|t| t.scaled(1e-6))
    .collect()
}

/// The Δ column: the difference in ms from the baseline when the intervals are apart,
/// `within noise` when they overlap.
#[must_use]
pub fn delta_label(time: &Timing, base: &Timing) -> String {
    match time.compare(base) {
        Comparison::WithinNoise => "within noise".into(),
        Comparison::Slower | Comparison::Faster => format!("{:+.3}", time.median - base.median),
    }
}

/// Runs every row at every size and prints the table, progress on stderr.
pub fn run(args: &EffectsArgs, out: &mut impl Write) -> Result<(), super::CliError> {
    let policy = Policy::new(
        args.rounds as usize,
        args.spread / 100.0,
        Duration::from_secs_f64(args.budget),
    );
    let scenes = (0..EFFECTS.len())
        .map(|row| Scene::from_text(&effect_scene(row), Path::new("bench effects")))
        .collect::<Result<Vec<_>, _>>()?;
    let times: Vec<Vec<Timing>> = args
        .sizes
        .iter()
        .map(|&size| {
            eprintln!("measuring {}x{}", size.width, size.height);
            measure_rows(&scenes, size, &policy)
        })
        .collect();
    out.write_all(table(&args.sizes, &times, &policy).as_bytes())?;
    Ok(())
}

/// The printed table: per row and size the median ms per frame, its spread, the
/// rounds, and the difference from the depth-test row.
#[must_use]
pub fn table(sizes: &[Target], times: &[Vec<Timing>], policy: &Policy) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "termrast bench effects: {EFFECTS_MODEL}, ms per frame, the median of at least {} \
         rounds per row and size, more until its 95% interval is within ±{}% or {:.1} s are \
         spent; ± is that interval, n the rounds; Δ against \"{}\", \"within noise\" where \
         the intervals overlap\n",
        policy.min_rounds,
        policy.target_spread * 100.0,
        policy.budget.as_secs_f64(),
        EFFECTS[BASELINE_ROW].0,
    );
    let _ = write!(s, "{:<40}", "effect");
    for size in sizes {
        let _ = write!(
            s,
            " | {:>13} {:>6} {:>4} | {:>12}",
            format!("{}x{} ms", size.width, size.height),
            "±",
            "n",
            "Δ ms"
        );
    }
    s.push('\n');
    for (row, (name, _, _)) in EFFECTS.iter().enumerate() {
        let _ = write!(s, "{name:<40}");
        for col in times {
            let (t, base) = (&col[row], &col[BASELINE_ROW]);
            let delta = if row == BASELINE_ROW {
                "baseline".into()
            } else {
                delta_label(t, base)
            };
            let _ = write!(
                s,
                " | {:>13.3} {:>6} {:>4} | {delta:>12}",
                t.median,
                t.spread_label(),
                t.rounds
            );
        }
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(median: f64, low: f64, high: f64) -> Timing {
        Timing {
            median,
            low,
            high,
            rounds: 7,
        }
    }

    #[test]
    fn a_difference_inside_the_noise_is_not_a_saving_or_a_cost() {
        let base = ms(1.646, 1.60, 1.70);
        assert_eq!(delta_label(&ms(1.664, 1.62, 1.75), &base), "within noise");
        assert_eq!(delta_label(&ms(1.620, 1.55, 1.61), &base), "within noise");
        assert_eq!(delta_label(&ms(2.555, 2.50, 2.60), &base), "+0.909");
        assert_eq!(delta_label(&ms(0.946, 0.90, 1.00), &base), "-0.700");
    }

    #[test]
    fn the_table_names_every_row_with_its_spread() {
        let sizes = [Target::new(400, 240), Target::new(1920, 1080)];
        let col = |k: f64| -> Vec<Timing> {
            (0..EFFECTS.len())
                .map(|r| {
                    // Row 2 is 1 % slower than the baseline, the others 10 % a row.
                    let m = k * if r == 2 { 1.11 } else { 1.0 + r as f64 * 0.1 };
                    ms(m, m * 0.97, m * 1.02)
                })
                .collect()
        };
        let times = [col(1.0), col(10.0)];
        let policy = Policy::new(5, 0.02, Duration::from_secs(1));
        let text = table(&sizes, &times, &policy);
        assert_eq!(text.lines().count(), EFFECTS.len() + 3);
        for (row, (name, _, _)) in EFFECTS.iter().enumerate() {
            let line = text
                .lines()
                .find(|l| l.starts_with(name))
                .unwrap_or_else(|| panic!("{name}"));
            assert_eq!(line.matches("±3.0%").count(), 2, "{line}");
            if row > BASELINE_ROW + 1 {
                assert!(
                    line.contains('+') && !line.contains("within noise"),
                    "{line}"
                );
            }
        }
        let base_line = text
            .lines()
            .find(|l| l.starts_with(EFFECTS[BASELINE_ROW].0));
        assert_eq!(base_line.unwrap().matches("baseline").count(), 2);
        // The row 1 % slower than the baseline, intervals overlapping, is noise.
        assert_eq!(
            text.lines().nth(5).unwrap().matches("within noise").count(),
            2
        );
    }
}

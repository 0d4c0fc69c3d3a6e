//! The benchmark commands' own runs, end to end: a tiny fidelity run and the effects
//! table's scenes. They live here, not beside the code, because they draw frames: a
//! unit test that draws would compile every copy of the draw loop into the library's
//! test build a second time.

use std::path::Path;

use termrast::cli::effects_cmd::{EFFECTS, effect_scene};
use termrast::fidelity::bench::{palettes, variants};
use termrast::fidelity::{Config, run, standard_views};
use termrast::scene::Scene;
use termrast::terminal::{ColorMode, Palette};

#[test]
fn a_tiny_run_gives_sane_rows() {
    let views = vec![standard_views(true).remove(0)];
    let mut config = Config::new(20, 8, views).unwrap();
    config.chafa = false;
    let o = run(&config).unwrap();
    let n = variants().count()
        * ColorMode::ALL
            .iter()
            .map(|&c| palettes(c).len())
            .sum::<usize>();
    assert_eq!(o.measurements.len(), n);
    for m in &o.measurements {
        let s = m.score.ssim;
        assert!(s > 0.0 && s <= 1.0, "{m:?}");
        assert!(
            m.bytes > 0 && m.printed.0 <= 20 && m.printed.1 <= 8,
            "{m:?}"
        );
        assert_eq!(m.unpainted, 0, "{m:?}");
        if m.colors == ColorMode::Truecolor {
            assert!(s > 0.3, "{m:?}");
        }
    }
    assert!(o.notes.iter().any(|n| n.contains("--no-chafa")));
    // At 16 colours termrast renders a frame for each palette, fitted to it and
    // painted on it: the shape-fitted modes choose other glyphs and colours.
    let on = |p: Palette| {
        o.measurements
            .iter()
            .filter(move |m| m.colors == ColorMode::Ansi16 && m.palette == p)
    };
    assert_eq!(on(Palette::XTERM).count(), variants().count());
    assert_eq!(on(Palette::CHAFA).count(), variants().count());
    let differ = on(Palette::XTERM)
        .zip(on(Palette::CHAFA))
        .filter(|(x, c)| {
            assert_eq!(x.method, c.method);
            x.score != c.score
        })
        .count();
    assert!(differ >= 3, "{differ}");
}

#[test]
fn every_row_is_a_valid_scene_with_its_effect_on() {
    for row in 0..EFFECTS.len() {
        let scene = Scene::from_text(&effect_scene(row), Path::new("bench effects"))
            .unwrap_or_else(|e| panic!("row {row}: {e}"));
        let plan = &scene.plan;
        assert_eq!(plan.depth_buffer, row != 0, "row {row}");
        let on: Vec<&str> = plan.objects[0]
            .lines
            .iter()
            .filter(|l| l.on)
            .map(|l| l.stage)
            .collect();
        // Each row past the depth test turns on something the depth-test row has not.
        if row > 1 {
            let base = Scene::from_text(&effect_scene(1), Path::new("b")).unwrap();
            let base_on = base.plan.objects[0].lines.iter().filter(|l| l.on).count();
            assert!(on.len() > base_on || plan.samples > 1, "row {row}: {on:?}");
        }
    }
}

//! Default framing: every built-in model and example scene, spinning, leaves at least
//! one empty cell row and column on each side of the view at 80×24, 200×60 and 60×60.

use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::style::Color;
use termrast::cli::view_cmd::load_model;
use termrast::scene::Scene;
use termrast::terminal::{ColorMode, GlyphMode};
use termrast::tui::app::App;
use termrast::tui::viewport::ViewSettings;

const SIZES: [(u16, u16); 3] = [(80, 24), (200, 60), (60, 60)];

/// The view's outer rows and columns (the status line is the terminal's last row) that
/// show anything: a glyph, or a background colour.
fn touched_edges(t: &Terminal<TestBackend>) -> Vec<String> {
    let buf = t.backend().buffer();
    let (w, h) = (buf.area.width, buf.area.height - 1);
    let shows = |x: u16, y: u16| {
        let c = &buf[(x, y)];
        c.symbol() != " " || c.bg != Color::Reset
    };
    let mut out = Vec::new();
    for (name, hit) in [
        ("top", (0..w).any(|x| shows(x, 0))),
        ("bottom", (0..w).any(|x| shows(x, h - 1))),
        ("left", (0..h).any(|y| shows(0, y))),
        ("right", (0..h).any(|y| shows(w - 1, y))),
    ] {
        if hit {
            out.push(name.to_string());
        }
    }
    out
}

fn settings(glyphs: GlyphMode) -> ViewSettings {
    ViewSettings {
        glyphs,
        colors: ColorMode::Truecolor,
        ..ViewSettings::default()
    }
}

#[test]
fn built_in_models_fit_the_view_at_any_angle() {
    for spec in ["teapot", "bunny", "sphere:20000"] {
        let model = load_model(spec).unwrap();
        for glyphs in [GlyphMode::Braille, GlyphMode::Blocks] {
            let mut app = App::new(model.clone(), settings(glyphs));
            for (cols, rows) in SIZES {
                let mut t = Terminal::new(TestBackend::new(cols, rows)).unwrap();
                for k in 0..8 {
                    app.settings.angle = k as f32 * std::f32::consts::FRAC_PI_4;
                    t.draw(|f| app.draw(f)).unwrap();
                    let touched = touched_edges(&t);
                    assert!(
                        touched.is_empty(),
                        "{spec} {} at {cols}x{rows}, angle {}: touches {touched:?}",
                        glyphs.name(),
                        app.settings.angle
                    );
                }
            }
        }
    }
}

#[test]
fn example_scenes_fit_the_view_as_they_spin() {
    let mut paths: Vec<_> = std::fs::read_dir("examples/scenes")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    assert!(paths.len() >= 5);
    for path in paths {
        let scene = Scene::load(&path).unwrap();
        let mut app = App::with_scene(scene, settings(GlyphMode::Braille));
        for (cols, rows) in SIZES {
            let mut t = Terminal::new(TestBackend::new(cols, rows)).unwrap();
            for k in 0..6 {
                app.scene.as_mut().unwrap().time = k as f32 * 1.7;
                t.draw(|f| app.draw(f)).unwrap();
                let touched = touched_edges(&t);
                assert!(
                    touched.is_empty(),
                    "{} at {cols}x{rows}, t = {}: touches {touched:?}",
                    path.display(),
                    k as f32 * 1.7
                );
            }
        }
    }
}

//! Default framing: every built-in model and example scene, spinning, leaves at least
//! one empty cell row and column on each side of the view at 80×24, 200×60 and 60×60,
//! at any cell aspect, and `render --out` leaves an empty pixel border at any size.

use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::style::Color;
use termrast::raster::Target;
use termrast::render::Rgba8;
use termrast::scene::Scene;
use termrast::scene::render::{SceneFrame, SceneView};
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
        let model = Scene::for_model(spec).unwrap();
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
        let mut app = App::new(scene, settings(GlyphMode::Braille));
        for (cols, rows) in SIZES {
            let mut t = Terminal::new(TestBackend::new(cols, rows)).unwrap();
            for k in 0..6 {
                app.scene.time = k as f32 * 1.7;
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

/// Other cell shapes (`--cell-aspect`) frame the model the same way.
#[test]
fn any_cell_aspect_keeps_the_margin() {
    let model = Scene::for_model("bunny").unwrap();
    for aspect in [0.35, 0.6, 1.0] {
        let mut app = App::new(
            model.clone(),
            ViewSettings {
                cell_aspect: aspect,
                ..settings(GlyphMode::Blocks)
            },
        );
        for (cols, rows) in SIZES {
            let mut t = Terminal::new(TestBackend::new(cols, rows)).unwrap();
            for k in 0..4 {
                app.settings.angle = k as f32 * std::f32::consts::FRAC_PI_2;
                t.draw(|f| app.draw(f)).unwrap();
                let touched = touched_edges(&t);
                assert!(
                    touched.is_empty(),
                    "cell aspect {aspect} at {cols}x{rows}: touches {touched:?}"
                );
            }
        }
    }
}

/// Whether a frame's outer rows and columns are all uncovered (alpha 0).
fn border_is_clear(color: &Rgba8, target: Target) -> bool {
    let (w, h) = (target.width as usize, target.height as usize);
    let px = |x: usize, y: usize| color.0[y * w + x][3];
    (0..w).all(|x| px(x, 0) == 0 && px(x, h - 1) == 0)
        && (0..h).all(|y| px(0, y) == 0 && px(w - 1, y) == 0)
}

/// `render --out`: the model's bounding sphere fits images of any shape, and so do
/// example scenes without a camera of their own.
#[test]
fn png_frames_keep_the_margin() {
    let targets = [(320, 240), (240, 320), (100, 100), (900, 120)].map(|(w, h)| Target::new(w, h));
    for spec in ["teapot", "bunny", "sphere:20000"] {
        let scene = Scene::for_model(spec).unwrap();
        let mut frame = SceneFrame::new(&scene);
        for target in targets {
            for k in 0..4 {
                let angle = k as f32 * std::f32::consts::FRAC_PI_2;
                let view = SceneView {
                    yaw: angle,
                    ..SceneView::default()
                };
                frame.draw(&scene, target, &view);
                let color = &frame.color;
                assert!(color.0.iter().any(|p| p[3] != 0), "{spec} not drawn at all");
                assert!(
                    border_is_clear(color, target),
                    "{spec} at {}x{}, angle {angle}: touches the edge",
                    target.width,
                    target.height
                );
            }
        }
    }
    for path in [
        "examples/scenes/minimal.toml",
        "examples/scenes/lit-teapot.toml",
    ] {
        let scene = Scene::load(std::path::Path::new(path)).unwrap();
        for target in targets {
            let mut frame = SceneFrame::new(&scene);
            frame.draw(&scene, target, &SceneView::default());
            assert!(
                border_is_clear(&frame.color, target),
                "{path} at {}x{}: touches the edge",
                target.width,
                target.height
            );
        }
    }
}

//! Glyph selection, colour detection, and the viewer drawn into ratatui's TestBackend.

use ratatui::Terminal;
use ratatui::backend::TestBackend;
use termrast::render::wire::Mode;
use termrast::scene::Scene;
use termrast::terminal::glyphs::{FitSpace, Sample, braille, fit_cell, sextant};
use termrast::terminal::{ColorMode, GlyphMode, Palette};
use termrast::tui::app::App;
use termrast::tui::inspector::{inspector_text, line_at_sample, line_text};
use termrast::tui::viewport::ViewSettings;

fn s(rgb: [u8; 3]) -> Sample {
    Sample { rgb, covered: true }
}
const OFF: Sample = Sample {
    rgb: [0, 0, 0],
    covered: false,
};

#[test]
fn half_block_uses_top_as_foreground() {
    let g = fit_cell(
        GlyphMode::Half,
        &[s([200, 10, 10]), s([10, 10, 200])],
        ColorMode::Truecolor,
        FitSpace::Srgb,
    );
    assert_eq!(
        (g.ch, g.fg, g.bg),
        ('▀', Some([200, 10, 10]), Some([10, 10, 200]))
    );
    let g = fit_cell(
        GlyphMode::Half,
        &[OFF, s([9, 9, 9])],
        ColorMode::Truecolor,
        FitSpace::Srgb,
    );
    assert_eq!((g.ch, g.fg, g.bg), ('▄', Some([9, 9, 9]), None));
    assert_eq!(
        fit_cell(
            GlyphMode::Half,
            &[OFF, OFF],
            ColorMode::Truecolor,
            FitSpace::Srgb
        )
        .ch,
        ' '
    );
}

#[test]
fn quadrant_fit_picks_the_bright_half() {
    // Top half bright, bottom half dark → upper half block, two colours.
    let w = s([250, 250, 250]);
    let d = s([20, 20, 20]);
    let g = fit_cell(
        GlyphMode::Quadrant,
        &[w, w, d, d],
        ColorMode::Truecolor,
        FitSpace::Srgb,
    );
    assert_eq!(
        (g.ch, g.fg, g.bg, g.error),
        ('▀', Some([250; 3]), Some([20; 3]), 0.0)
    );
    // One covered corner on an empty background.
    let g = fit_cell(
        GlyphMode::Quadrant,
        &[OFF, OFF, OFF, w],
        ColorMode::Truecolor,
        FitSpace::Srgb,
    );
    assert_eq!((g.ch, g.bg), ('▗', None));
    // One colour is a space on that background.
    let g = fit_cell(
        GlyphMode::Quadrant,
        &[w, w, w, w],
        ColorMode::Truecolor,
        FitSpace::Srgb,
    );
    assert_eq!((g.ch, g.bg), (' ', Some([250; 3])));
}

#[test]
fn braille_and_sextant_bit_layouts() {
    // Samples are row-major in a 2×4 cell; braille dots 1,2,3,7 run down the left.
    assert_eq!(braille(0), '\u{2800}');
    assert_eq!(braille(0b0000_0001), '⠁'); // top-left: dot 1
    assert_eq!(braille(0b0000_0010), '⠈'); // top-right: dot 4
    assert_eq!(braille(0b0100_0000), '⡀'); // bottom-left: dot 7
    assert_eq!(braille(0b1000_0000), '⢀'); // bottom-right: dot 8
    assert_eq!(braille(0xFF), '⣿');
    assert_eq!(braille(0b0101_0101), '⡇'); // left column
    // Sextants: U+1FB00 onwards, skipping the half columns and empty/full.
    assert_eq!(sextant(1), '\u{1FB00}');
    assert_eq!(sextant(21), '▌');
    assert_eq!(sextant(42), '▐');
    assert_eq!(sextant(22), '\u{1FB14}');
    assert_eq!(sextant(62), '\u{1FB3B}');
    assert_eq!(sextant(63), '█');
    let all: std::collections::HashSet<char> = (0..64).map(sextant).collect();
    assert_eq!(all.len(), 64, "every pattern has its own glyph");
}

#[test]
fn colorless_modes_dither_by_luminance() {
    let grey = |v: u8| s([v, v, v]);
    // Uniform cells are shades: no braille dots over the default background.
    let uniform = |v| {
        fit_cell(
            GlyphMode::Braille,
            &[grey(v); 8],
            ColorMode::None,
            FitSpace::Srgb,
        )
        .ch
    };
    assert_eq!(uniform(0), ' ');
    assert_eq!(uniform(128), '░');
    assert_eq!(uniform(200), '▓');
    assert_eq!(uniform(255), '█');
    // Other cells dither: more dots for brighter samples.
    let cell = |v: u8| {
        let mut c = [grey(v); 8];
        c[0] = grey(v.saturating_sub(1));
        let g = fit_cell(GlyphMode::Braille, &c, ColorMode::None, FitSpace::Srgb);
        assert_eq!((g.fg, g.bg), (None, None));
        g
    };
    let dots = |v: u8| cell(v).pattern.count_ones();
    assert_eq!(dots(1), 0);
    assert!(dots(32) < dots(64) && dots(64) < dots(128));
    // Brighter than every dot lit can show (a third of the cell): a shade instead.
    assert_eq!((cell(200).ch, cell(200).pattern), ('▓', 0));
}

#[test]
fn colour_detection_table() {
    let cases: &[(&[(&str, &str)], ColorMode)] = &[
        (
            &[("COLORTERM", "truecolor"), ("TERM", "xterm-256color")],
            ColorMode::Truecolor,
        ),
        (&[("COLORTERM", "24bit")], ColorMode::Truecolor),
        (&[("TERM", "xterm-direct")], ColorMode::Truecolor),
        (&[("TERM", "xterm-256color")], ColorMode::Ansi256),
        (&[("TERM", "screen-256color")], ColorMode::Ansi256),
        (&[("TERM", "xterm")], ColorMode::Ansi16),
        (&[("TERM", "vt100")], ColorMode::Ansi16),
        (&[("TERM", "dumb")], ColorMode::None),
        (&[], ColorMode::None),
        (
            &[("NO_COLOR", "1"), ("COLORTERM", "truecolor")],
            ColorMode::None,
        ),
        (
            &[("NO_COLOR", ""), ("TERM", "xterm-256color")],
            ColorMode::Ansi256,
        ),
    ];
    for (env, want) in cases {
        let got = ColorMode::detect(|k| {
            env.iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| v.to_string())
        });
        assert_eq!(got, *want, "{env:?}");
    }
    assert_eq!(
        ColorMode::Ansi256.color([255, 0, 0], &Palette::XTERM),
        ratatui::style::Color::Indexed(196)
    );
    assert_eq!(
        ColorMode::Ansi256.color([128, 128, 128], &Palette::XTERM),
        ratatui::style::Color::Indexed(244)
    );
    assert_eq!(
        ColorMode::Ansi16.color([250, 250, 250], &Palette::XTERM),
        ratatui::style::Color::White
    );
    // On a palette whose white is elsewhere, the nearest entry is that one.
    let mut swapped = Palette::XTERM;
    swapped.ansi.swap(9, 15);
    assert_eq!(
        ColorMode::Ansi16.color([250, 250, 250], &swapped),
        ratatui::style::Color::LightRed
    );
}

fn teapot() -> Scene {
    Scene::for_model("teapot").unwrap()
}

fn app(glyphs: GlyphMode) -> App {
    let settings = ViewSettings {
        glyphs,
        colors: ColorMode::None,
        ..ViewSettings::default()
    };
    let mut a = App::new(teapot(), settings);
    a.paused = true;
    a
}

/// The screen as text, without the status line (its timings vary run to run).
fn screen(t: &Terminal<TestBackend>) -> String {
    let text = t.backend().to_string();
    text.lines()
        .filter(|l| !l.contains("? help"))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn viewport_snapshots_in_every_glyph_mode() {
    for mode in GlyphMode::ALL {
        let mut a = app(mode);
        let mut t = Terminal::new(TestBackend::new(80, 24)).unwrap();
        t.draw(|f| a.draw(f)).unwrap();
        insta::assert_snapshot!(format!("viewport_{}", mode.name()), screen(&t));
    }
}

#[test]
fn inspector_and_line_panel_snapshots() {
    let mut a = app(GlyphMode::Quadrant);
    a.inspect = true;
    a.scene.scene.set_mode(Mode::FillWire);
    a.cursor = (31, 19);
    let mut t = Terminal::new(TestBackend::new(120, 40)).unwrap();
    t.draw(|f| a.draw(f)).unwrap();
    let text = inspector_text(&a.viewport, &a.scene, a.cursor.0, a.cursor.1, 0).plain();
    assert!(
        [
            "F01", "F02", "F03", "area2", " u ", " v ", " w ", "1/w", "depth", "block"
        ]
        .iter()
        .all(|k| text.contains(k)),
        "{text}"
    );
    insta::assert_snapshot!("inspector_cell_31_19", text);
    let (focus, sl) =
        line_at_sample(&a.viewport, &a.scene, (31, 19, 0)).expect("a line near the cell");
    let panel = line_text(focus, &sl).plain();
    assert!(
        ["octant", "dx", "dy", "incrE", "incrNE", " d "]
            .iter()
            .all(|f| panel.contains(f)),
        "{panel}"
    );
    insta::assert_snapshot!("line_panel_cell_31_19", panel);
    // Stepping along the line moves the cursor with it.
    let before = a.cursor;
    for _ in 0..6 {
        a.handle(&ratatui::crossterm::event::Event::Key(
            ratatui::crossterm::event::KeyEvent::from(ratatui::crossterm::event::KeyCode::Char(
                ']',
            )),
        ));
    }
    assert_ne!(a.cursor, before);
    assert_eq!(a.line_focus.map(|f| f.edge), Some(focus.edge));
    insta::assert_snapshot!("screen_inspect", screen(&t));
}

fn key(a: &mut App, code: ratatui::crossterm::event::KeyCode) {
    use ratatui::crossterm::event::{Event, KeyEvent};
    a.handle(&Event::Key(KeyEvent::from(code)));
}

fn status_line(t: &Terminal<TestBackend>) -> String {
    let text = t.backend().to_string();
    text.lines().last().unwrap_or_default().to_string()
}

/// The status line says what is drawn: culling on or off, the lines of a wireframe;
/// no frame rate while paused; `p` on a model says there is no plan.
#[test]
fn the_status_line_says_what_is_drawn() {
    use ratatui::crossterm::event::KeyCode;
    let mut a = app(GlyphMode::Blocks);
    let mut t = Terminal::new(TestBackend::new(200, 40)).unwrap();
    t.draw(|f| a.draw(f)).unwrap();
    let s = status_line(&t);
    assert!(
        s.contains("fill no cull") && s.contains("paused") && !s.contains("fps"),
        "{s}"
    );
    key(&mut a, KeyCode::Char('b'));
    key(&mut a, KeyCode::Char('w'));
    t.draw(|f| a.draw(f)).unwrap();
    let s = status_line(&t);
    let lines: u64 = s
        .split_once("wire ")
        .and_then(|(_, r)| r.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .expect("a line count");
    assert!(lines > 100 && s.contains(" cull"), "{s}");
    key(&mut a, KeyCode::Char('p'));
    t.draw(|f| a.draw(f)).unwrap();
    assert!(
        status_line(&t).contains("no scene plan"),
        "{}",
        status_line(&t)
    );
}

/// A scene's line panel traces its objects' edges, and stepping moves the cursor.
#[test]
fn the_line_panel_works_for_scenes() {
    use ratatui::crossterm::event::KeyCode;
    let scene =
        termrast::scene::Scene::load(std::path::Path::new("examples/scenes/lit-teapot.toml"))
            .unwrap();
    let mut a = App::new(
        scene,
        ViewSettings {
            glyphs: GlyphMode::Blocks,
            colors: ColorMode::Truecolor,
            ..ViewSettings::default()
        },
    );
    let mut t = Terminal::new(TestBackend::new(140, 45)).unwrap();
    key(&mut a, KeyCode::Char('i'));
    t.draw(|f| a.draw(f)).unwrap();
    let screen = t.backend().to_string();
    assert!(screen.contains("object 0 edge v"), "{screen}");
    assert!(!screen.contains("no line here"), "{screen}");
    let before = (a.cursor, a.sub);
    for _ in 0..5 {
        key(&mut a, KeyCode::Char(']'));
    }
    assert_ne!(
        (a.cursor, a.sub),
        before,
        "stepping did not move the cursor"
    );
    assert!(a.line_focus.is_some_and(|f| f.object == Some(0)));
}

/// `w` and `b` act on a scene file's objects: the status line and the plan follow.
#[test]
fn w_and_b_change_what_a_scene_draws() {
    use ratatui::crossterm::event::KeyCode;
    let scene =
        termrast::scene::Scene::load(std::path::Path::new("examples/scenes/lit-teapot.toml"))
            .unwrap();
    let mut a = App::new(
        scene,
        ViewSettings {
            glyphs: GlyphMode::Blocks,
            ..ViewSettings::default()
        },
    );
    let mut t = Terminal::new(TestBackend::new(200, 40)).unwrap();
    t.draw(|f| a.draw(f)).unwrap();
    let s = status_line(&t);
    assert!(s.contains("fill no cull"), "{s}");
    key(&mut a, KeyCode::Char('w'));
    key(&mut a, KeyCode::Char('b'));
    t.draw(|f| a.draw(f)).unwrap();
    let s = status_line(&t);
    let lines: u64 = s
        .split_once("wire ")
        .and_then(|(_, r)| r.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .expect("a line count");
    assert!(lines > 100 && s.contains(" cull"), "{s}");
    let plan = a.scene.scene.plan.to_string();
    assert!(
        plan.contains("wireframe: on") && plan.contains("back-face culling: on"),
        "{plan}"
    );
}

/// The plan overlay wraps long lines instead of cutting them.
#[test]
fn the_plan_overlay_wraps() {
    use ratatui::crossterm::event::KeyCode;
    let scene =
        termrast::scene::Scene::load(std::path::Path::new("examples/scenes/phong-bunny.toml"))
            .unwrap();
    let plan = scene.plan.to_string();
    let mut a = App::new(scene, ViewSettings::default());
    let mut t = Terminal::new(TestBackend::new(50, 60)).unwrap();
    key(&mut a, KeyCode::Char('p'));
    t.draw(|f| a.draw(f)).unwrap();
    let screen: String = t
        .backend()
        .to_string()
        .lines()
        .flat_map(|l| l.split('│').nth(1))
        .collect::<Vec<_>>()
        .join(" ");
    for word in plan.split_whitespace().filter(|w| w.len() > 3) {
        assert!(
            screen.contains(word),
            "`{word}` cut from the plan:\n{screen}"
        );
    }
}

#[test]
fn tiny_terminal_gets_a_message() {
    let mut a = app(GlyphMode::Braille);
    let mut t = Terminal::new(TestBackend::new(20, 5)).unwrap();
    t.draw(|f| a.draw(f)).unwrap();
    assert!(t.backend().to_string().contains("too small"));
}

mod fit_property {
    use super::*;
    use proptest::prelude::*;
    use termrast::terminal::glyphs::luma;

    /// Brute force: every luminance-ordered split, errors computed from group means.
    fn best_error(samples: &[Sample]) -> f64 {
        let mut order: Vec<usize> = (0..samples.len()).collect();
        let key = |s: &Sample| if s.covered { luma(s.rgb) } else { -1.0 };
        order.sort_by(|&a, &b| key(&samples[a]).total_cmp(&key(&samples[b])));
        let sse = |g: &[usize]| -> f64 {
            if g.is_empty() {
                return 0.0;
            }
            (0..3)
                .map(|c| {
                    let v: Vec<f64> = g.iter().map(|&i| f64::from(samples[i].rgb[c])).collect();
                    let m = v.iter().sum::<f64>() / v.len() as f64;
                    v.iter().map(|x| (x - m).powi(2)).sum::<f64>()
                })
                .sum()
        };
        (0..samples.len())
            .filter(|&cut| order[cut..].iter().all(|&i| samples[i].covered))
            .map(|cut| sse(&order[..cut]) + sse(&order[cut..]))
            .fold(f64::INFINITY, f64::min)
    }

    proptest! {
        #[test]
        fn two_colour_fit_is_optimal(raw in prop::collection::vec((any::<[u8; 3]>(), 0u8..4), 8)) {
            let samples: Vec<Sample> = raw.iter().map(|&(rgb, c)| Sample { rgb: if c == 0 { [0; 3] } else { rgb }, covered: c != 0 }).collect();
            for (mode, n) in [(GlyphMode::Quadrant, 4), (GlyphMode::Sextant, 6), (GlyphMode::Braille, 8)] {
                let s = &samples[..n];
                if s.iter().all(|x| !x.covered) {
                    continue;
                }
                let g = fit_cell(mode, s, ColorMode::Truecolor, FitSpace::Srgb);
                // Integer error with the mean's remainder truncated: within n of exact.
                let want = best_error(s);
                prop_assert!((f64::from(g.error) - want).abs() <= n as f64 + 1e-6, "{} vs {}", g.error, want);
                if g.ch == ' ' {
                    prop_assert!(g.bg.is_some() && g.fg.is_none());
                    continue;
                }
                prop_assert_eq!(g.ch, mode.pattern_glyph(g.pattern));
                if mode == GlyphMode::Braille {
                    // The dots are on the smaller group.
                    prop_assert!(g.pattern.count_ones() <= 4, "{}", g.pattern.count_ones());
                } else {
                    // Foreground samples are covered ones.
                    prop_assert!((0..n).all(|i| g.pattern >> i & 1 == 0 || s[i].covered));
                }
            }
        }
    }
}

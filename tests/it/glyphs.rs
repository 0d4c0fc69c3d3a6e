//! The glyph fits against brute force, and what a terminal emulator shows of a frame:
//! no braille dots over the default background where a cell is one colour.

use proptest::prelude::*;
use termrast::cli::view_cmd::write_ansi;
use termrast::scene::Scene;
use termrast::scene::render::SceneFrame;
use termrast::terminal::color::{to_linear, to_srgb};
use termrast::terminal::fit::{self, N, Repertoire, mask_of, weights_of};
use termrast::terminal::glyphs::{FitSpace, Sample, fit_cell};
use termrast::terminal::{ColorMode, GlyphMode};
use termrast::tui::viewport::{ViewSettings, Viewport};

/// Every glyph the blocks mode may use, as the issue lists them: space and full block,
/// the halves, the 16 quadrants, the 64 sextants, the lower and left eighths and the
/// diagonal wedges.
fn block_glyphs() -> Vec<char> {
    let mut v = vec![' ', '█', '▀', '▄', '▌', '▐'];
    v.extend(
        [
            0x2596..=0x259F,
            0x2581..=0x2587,
            0x2589..=0x258F,
            0x1FB00..=0x1FB3B,
            0x1FB3C..=0x1FB6F,
        ]
        .into_iter()
        .flatten()
        .filter_map(char::from_u32),
    );
    v
}

/// The least squared error of any glyph of `glyphs` drawn in the best two colours for
/// it, each sample seen as its box's mix `b + α(f − b)`: per channel, least squares
/// over `b` and `f − b`, solved directly in f64.
fn brute_force(glyphs: &[char], x: &[[f32; 3]; N]) -> f64 {
    let uniform = {
        (0..3)
            .map(|c| {
                let m = x.iter().map(|p| f64::from(p[c])).sum::<f64>() / N as f64;
                x.iter().map(|p| (f64::from(p[c]) - m).powi(2)).sum::<f64>()
            })
            .sum::<f64>()
    };
    glyphs
        .iter()
        .filter_map(|&ch| {
            let w = weights_of(ch).expect("a known glyph").map(f64::from);
            let (n, a, b) = (
                N as f64,
                w.iter().sum::<f64>(),
                w.iter().map(|v| v * v).sum::<f64>(),
            );
            let det = n * b - a * a;
            (det > 1e-3).then(|| {
                (0..3)
                    .map(|c| {
                        let xs = x.map(|p| f64::from(p[c]));
                        let sx: f64 = xs.iter().sum();
                        let sy: f64 = (0..N).map(|i| w[i] * xs[i]).sum();
                        let bg = (b * sx - a * sy) / det;
                        let d = (n * sy - a * sx) / det;
                        (0..N).map(|i| (xs[i] - bg - w[i] * d).powi(2)).sum::<f64>()
                    })
                    .sum::<f64>()
            })
        })
        .fold(uniform, f64::min)
}

fn samples_strategy() -> impl Strategy<Value = [[f32; 3]; N]> {
    // Random colours, and cells of a few colours in random places (the common case of
    // an edge through a cell), where ties between shapes are likely.
    let palette = prop::collection::vec(any::<[u8; 3]>(), 1..4);
    (
        palette,
        prop::collection::vec(any::<u8>(), N),
        any::<bool>(),
    )
        .prop_map(|(pal, pick, free)| {
            std::array::from_fn(|i| {
                let c = if free {
                    [pick[i], pick[(i + 7) % N], pick[(i + 13) % N]]
                } else {
                    pal[usize::from(pick[i]) % pal.len()]
                };
                c.map(to_linear)
            })
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn block_fit_is_the_brute_force_optimum(x in samples_strategy()) {
        let f = fit::fit(Repertoire::wedges(), &x);
        let want = brute_force(&block_glyphs(), &x);
        let f2 = fit::fit(Repertoire::blocks(), &x);
        let no_wedges: Vec<char> = block_glyphs().into_iter().filter(|c| !('\u{1FB3C}'..='\u{1FB6F}').contains(c)).collect();
        let want2 = brute_force(&no_wedges, &x);
        prop_assert!((f64::from(f2.error) - want2).abs() <= 1e-4 * (1.0 + want2), "{} vs {want2}", f2.error);
        prop_assert!((f64::from(f.error) - want).abs() <= 1e-4 * (1.0 + want), "{} vs {want}", f.error);
        // The colours are the fit's: the error of drawing the glyph in them is the
        // reported one (up to clamping to [0, 1], which only adds error).
        if let Some(sh) = f.shape {
            let e: f64 = (0..N)
                .map(|i| {
                    (0..3)
                        .map(|c| {
                            let seen = f.off[c] + sh.weights[i] * (f.on[c] - f.off[c]);
                            f64::from(x[i][c] - seen).powi(2)
                        })
                        .sum::<f64>()
                })
                .sum();
            prop_assert!(e + 1e-3 >= f64::from(f.error), "{e} < {}", f.error);
        }
    }

    #[test]
    fn ascii_fit_is_the_brute_force_optimum(x in samples_strategy()) {
        let f = fit::fit(Repertoire::ascii(), &x);
        let glyphs: Vec<char> = (0x20u8..=0x7E).map(char::from).collect();
        let want = brute_force(&glyphs, &x);
        prop_assert!((f64::from(f.error) - want).abs() <= 1e-4 * (1.0 + want), "{} vs {want}", f.error);
    }

    /// What the cell shows: the glyph inks exactly the foreground samples, and a side
    /// with no covered sample is the terminal's own background.
    #[test]
    fn block_cells_show_their_fit(x in samples_strategy(), cover in any::<u32>()) {
        let samples: Vec<Sample> = (0..N)
            .map(|i| {
                let covered = cover >> i & 1 == 1;
                Sample { rgb: if covered { x[i].map(to_srgb) } else { [0; 3] }, covered }
            })
            .collect();
        let g = fit_cell(GlyphMode::Wedges, &samples, ColorMode::Truecolor, FitSpace::Srgb);
        if cover == 0 {
            prop_assert_eq!((g.ch, g.fg, g.bg), (' ', None, None));
            return Ok(());
        }
        prop_assert_eq!(mask_of(g.ch), Some(g.pattern), "{:?}", g.ch);
        if g.ch == ' ' {
            prop_assert!(g.fg.is_none() && g.bg.is_some());
        } else {
            prop_assert!(g.fg.is_some());
            // The terminal's own background shows only where no covered sample is.
            let w = weights_of(g.ch).unwrap();
            if g.bg.is_none() {
                prop_assert!((0..N).all(|i| !samples[i].covered || w[i] == 1.0));
            }
        }
    }
}

#[test]
fn every_listed_glyph_is_in_the_repertoire() {
    let rep = Repertoire::wedges();
    for ch in block_glyphs() {
        let m = mask_of(ch).unwrap();
        if m == 0 || m == fit::FULL {
            continue;
        }
        assert!(
            rep.shapes.iter().any(|s| s.mask == m || s.mask == !m),
            "{ch:?} ({:X}) has no shape",
            u32::from(ch)
        );
    }
}

#[test]
fn braille_dots_go_on_the_smaller_group() {
    let (w, d) = (
        Sample {
            rgb: [240; 3],
            covered: true,
        },
        Sample {
            rgb: [30; 3],
            covered: true,
        },
    );
    // Seven bright samples and one dark: the dark one is the dot, the bright area the
    // background (before, seven dim dots showed the bright area at a third).
    let g = fit_cell(
        GlyphMode::Braille,
        &[w, w, w, w, w, w, w, d],
        ColorMode::Truecolor,
        FitSpace::Srgb,
    );
    assert_eq!((g.ch, g.fg, g.bg), ('⢀', Some([30; 3]), Some([240; 3])));
    // A bright edge over the empty background: the covered samples stay dots whenever
    // they are the smaller group.
    let off = Sample::default();
    let g = fit_cell(
        GlyphMode::Braille,
        &[w, off, w, off, off, off, off, off],
        ColorMode::Truecolor,
        FitSpace::Srgb,
    );
    assert_eq!((g.fg, g.bg), (Some([240; 3]), None));
}

/// The frame as a terminal shows it: the ANSI text through a terminal emulator.
fn emulate(vp: &Viewport) -> vt100::Parser {
    let mut bytes = Vec::new();
    write_ansi(vp, &mut bytes).unwrap();
    // A terminal's line discipline turns each newline into CR LF.
    let text = String::from_utf8(bytes).unwrap().replace('\n', "\r\n");
    let size = |n: u16| std::num::NonZeroU16::new(n.max(1)).unwrap();
    let mut p = vt100::Parser::new(size(vp.rows + 1), size(vp.cols), 0);
    p.process(text.as_bytes());
    p
}

#[test]
fn uniform_cells_show_no_braille_over_the_default_background() {
    let text = "[[object]]\nmodel = \"cube.obj\"\nrotation = [30, 40, 0]\n\
                [object.material]\nlighting = \"flat\"\n[object.effects]\ndepth_test = true\n";
    let scene = Scene::from_text(text, std::path::Path::new("examples/scenes/flat.toml")).unwrap();
    for colors in ColorMode::ALL {
        let settings = ViewSettings {
            glyphs: GlyphMode::Braille,
            colors,
            ..ViewSettings::default()
        };
        let mut vp = Viewport::default();
        let mut frame = SceneFrame::new(&scene);
        vp.render_scene(&scene, &mut frame, &settings, (80, 24), 0.7);
        let term = emulate(&vp);
        let (mut uniform, mut full) = (0, 0);
        for cy in 0..vp.rows {
            for cx in 0..vp.cols {
                let cell = term.screen().cell(cy, cx).unwrap();
                let ch = cell.contents().chars().next().unwrap_or(' ');
                let braille = ('\u{2801}'..='\u{28FF}').contains(&ch);
                let over_default = cell.bgcolor() == vt100::Color::Default;
                assert!(
                    !(ch == '⣿' && over_default),
                    "{}: ⣿ over the default background at ({cx},{cy})",
                    colors.name()
                );
                let (s, n) = vp.samples(cx, cy);
                if s[..n].iter().all(|x| x.covered && *x == s[0]) {
                    uniform += 1;
                    full += usize::from(ch == '█' || ch == ' ');
                    assert!(
                        !(braille && over_default),
                        "{}: uniform cell ({cx},{cy}) shows {ch:?} over the default background",
                        colors.name()
                    );
                }
            }
        }
        assert!(
            uniform > 50,
            "{}: only {uniform} uniform cells",
            colors.name()
        );
        if colors != ColorMode::None {
            assert_eq!(full, uniform, "{}", colors.name());
        }
    }
}

//! The glyph fits against brute force, and what a terminal emulator shows of a frame:
//! no braille dots over the default background where a cell is one colour, and colour
//! ASCII as bright as the model.

use proptest::prelude::*;
use termrast::cli::view_cmd::write_ansi;
use termrast::scene::Scene;
use termrast::terminal::color::{to_linear, to_srgb};
use termrast::terminal::fit::{self, N, Repertoire, mask_of, weights_of};
use termrast::terminal::glyphs::{FitSpace, Sample, fit_cell};
use termrast::terminal::paint::{self, CELL_HEIGHT, CELL_WIDTH};
use termrast::terminal::{ColorMode, GlyphMode};
use termrast::tui::viewport::{SceneState, ViewSettings, Viewport};

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
    // The dot inks a third of its sample, so its colour is as much darker than the
    // background as it can be (black): the sample still looks lighter than 30.
    assert_eq!((g.ch, g.fg, g.bg), ('⢀', Some([0; 3]), Some([240; 3])));
    // A bright edge over the empty background: the covered samples stay dots whenever
    // they are the smaller group.
    let off = Sample::default();
    let g = fit_cell(
        GlyphMode::Braille,
        &[w, off, w, off, off, off, off, off],
        ColorMode::Truecolor,
        FitSpace::Srgb,
    );
    // Dots of 240 over black would show at a third: they are drawn at full white.
    assert_eq!((g.fg, g.bg), (Some([255; 3]), None));
    // A dot that needs less than three times its strength gets exactly that, in linear
    // light: a third of the dot colour's light over the black between.
    let dim = Sample {
        rgb: [60; 3],
        covered: true,
    };
    let g = fit_cell(
        GlyphMode::Braille,
        &[dim, off, off, off, off, off, off, off],
        ColorMode::Truecolor,
        FitSpace::Srgb,
    );
    let fg = g.fg.unwrap()[0];
    let shown = termrast::terminal::color::to_linear(fg) / 3.0;
    let want = termrast::terminal::color::to_linear(60);
    assert!((shown - want).abs() < 0.002, "{fg}: {shown} against {want}");
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
        let mut state = SceneState::new(scene.clone());
        state.time = 0.7;
        vp.render(&mut state, &settings, (80, 24));
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

/// Relative luminance in linear light of an sRGB colour.
fn luminance(c: [u8; 3]) -> f32 {
    let l = c.map(to_linear);
    0.2126 * l[0] + 0.7152 * l[1] + 0.0722 * l[2]
}

/// Colour ASCII as a terminal shows it, on a flat-shaded cube and the lit teapot: every
/// cell inside the model has a background colour (the ASCII is not drawn over the
/// terminal's black), and the bright cells paint as much light as the model's samples
/// there (a foreground-only character inks a fraction of its cell: about a third of the
/// brightness).
#[test]
fn colour_ascii_keeps_the_models_brightness() {
    let text = "[[object]]\nmodel = \"cube.obj\"\nrotation = [30, 40, 0]\n\
                [object.material]\nlighting = \"flat\"\n[object.effects]\ndepth_test = true\n";
    let scene = Scene::from_text(text, std::path::Path::new("examples/scenes/flat.toml")).unwrap();
    let teapot = Scene::for_model("teapot").unwrap();
    for (name, fit_space) in [
        ("flat cube", FitSpace::Srgb),
        ("teapot", FitSpace::Srgb),
        ("teapot", FitSpace::Linear),
    ] {
        let settings = ViewSettings {
            glyphs: GlyphMode::Ascii,
            colors: ColorMode::Truecolor,
            fit_space,
            ..ViewSettings::default()
        };
        let mut vp = Viewport::default();
        let mut state = if name == "teapot" {
            SceneState::new(teapot.clone())
        } else {
            SceneState::new(scene.clone())
        };
        if name != "teapot" {
            state.time = 0.7;
        }
        vp.render(&mut state, &settings, (80, 24));
        let term = emulate(&vp);
        let mut bytes = Vec::new();
        write_ansi(&vp, &mut bytes).unwrap();
        let grid = paint::emulate(&bytes, vp.cols, vp.rows).unwrap();
        let painted = paint::paint(&grid).unwrap();
        assert_eq!(painted.unpainted, 0, "{name}");
        let (mut inside, mut inked) = (0, 0);
        // (model, shown) light of each bright cell inside the model.
        let mut bright: Vec<(f32, f32, u16, u16)> = Vec::new();
        for cy in 0..vp.rows {
            for cx in 0..vp.cols {
                let (s, n) = vp.samples(cx, cy);
                let s = &s[..n];
                if !s.iter().all(|x| x.covered) {
                    continue;
                }
                inside += 1;
                let cell = term.screen().cell(cy, cx).unwrap();
                assert_ne!(
                    cell.bgcolor(),
                    vt100::Color::Default,
                    "{name}: cell ({cx},{cy}) inside the model shows {:?} over the default background",
                    cell.contents()
                );
                inked += usize::from(cell.contents().trim() != "");
                let model = s.iter().map(|x| luminance(x.rgb)).sum::<f32>() / n as f32;
                if model < 0.2 {
                    continue;
                }
                let (x0, y0) = (u32::from(cx) * CELL_WIDTH, u32::from(cy) * CELL_HEIGHT);
                let mut sum = 0.0;
                for y in y0..y0 + CELL_HEIGHT {
                    for x in x0..x0 + CELL_WIDTH {
                        sum += luminance(painted.image.get_pixel(x, y).0);
                    }
                }
                bright.push((model, sum / (CELL_WIDTH * CELL_HEIGHT) as f32, cx, cy));
            }
        }
        assert!(
            inside > 100 && bright.len() > 100,
            "{name}: {inside} cells inside, {} bright",
            bright.len()
        );
        // Over the bright area, the model's light within 3 %.
        let model_light: f32 = bright.iter().map(|b| b.0).sum();
        let shown_light: f32 = bright.iter().map(|b| b.1).sum();
        let ratio = shown_light / model_light;
        assert!(
            (ratio - 1.0).abs() <= 0.03,
            "{name} {fit_space:?}: the bright cells show {ratio:.3} of the model's light"
        );
        // Cell by cell: nine in ten within 5 %, and none far off. A fit in sRGB values
        // darkens a cell whose samples spread widely (a highlight) by up to about a
        // quarter; a fit in linear light keeps each cell's light.
        let off = |b: &(f32, f32, u16, u16)| (b.1 / b.0 - 1.0).abs();
        let close = bright.iter().filter(|b| off(b) <= 0.05).count();
        assert!(
            close * 10 >= bright.len() * 9,
            "{name} {fit_space:?}: {close} of {} bright cells within 5 %",
            bright.len()
        );
        let most = match fit_space {
            FitSpace::Srgb => 0.35,
            FitSpace::Linear => 0.1,
        };
        for b in &bright {
            assert!(
                off(b) <= most,
                "{name} {fit_space:?}: cell ({},{}) shows {:.3} of the model's {:.3}",
                b.2,
                b.3,
                b.1,
                b.0
            );
        }
        if name == "teapot" {
            // Shading varies over the teapot, so characters are drawn, not only spaces.
            assert!(inked > 100, "{name}: only {inked} cells inked");
        }
    }
}

//! Whole viewer frames (`cargo bench --bench viewer`): transform, raster, glyph
//! fitting, ratatui's diff, the perceptual cell cache and the write to a byte-counting
//! sink, at 200×60 cells in braille, blocks, wedges and ascii modes, the model turning
//! between frames as it does in the viewer.

use std::cell::Cell;
use std::io;
use std::rc::Rc;

use criterion::{BenchmarkId, Criterion, criterion_group};
use ratatui::Terminal;
use termrast::scene::Scene;
use termrast::terminal::{ColorMode, GlyphMode};
use termrast::tui::Counting;
use termrast::tui::app::App;
use termrast::tui::link::LinkBackend;
use termrast::tui::viewport::ViewSettings;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("viewer-frame-200x60");
    for (name, spec) in [("teapot", "teapot"), ("bunny", "bunny")] {
        for (glyphs, colors) in [
            (GlyphMode::Braille, ColorMode::Truecolor),
            (GlyphMode::Braille, ColorMode::Ansi256),
            (GlyphMode::Blocks, ColorMode::Truecolor),
            (GlyphMode::Wedges, ColorMode::Truecolor),
            (GlyphMode::Wedges, ColorMode::Ansi256),
            (GlyphMode::Wedges, ColorMode::Ansi16),
            (GlyphMode::Ascii, ColorMode::Truecolor),
        ] {
            let settings = ViewSettings {
                glyphs,
                colors,
                ..ViewSettings::default()
            };
            let mut app = App::new(Scene::for_model(spec).expect("model"), settings);
            let bytes = Rc::new(Cell::new(0u64));
            let sink = Counting {
                inner: io::sink(),
                bytes: Rc::clone(&bytes),
            };
            let mut term = Terminal::with_options(
                LinkBackend::with_size(sink, 200, 61),
                ratatui::TerminalOptions {
                    viewport: ratatui::Viewport::Fixed(ratatui::layout::Rect::new(0, 0, 200, 61)),
                },
            )
            .expect("terminal");
            let frame = std::time::Duration::from_millis(33);
            let mut frames = 0u64;
            let id = format!("{}-{}", glyphs.name(), colors.name());
            g.bench_function(BenchmarkId::new(name, &id), |b| {
                b.iter(|| {
                    app.tick(frame);
                    term.draw(|f| app.draw(f)).expect("draw");
                    frames += 1;
                });
            });
            eprintln!(
                "{name} {id}: {} bytes per frame",
                bytes.get() / frames.max(1)
            );
        }
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
/// `VIEWER_BREAKDOWN=1 cargo bench --bench viewer`: where a frame's time goes instead
/// of criterion's run (medians over 400 frames of the bunny at 200×60 cells).
fn breakdown() {
    use std::time::{Duration, Instant};
    use termrast::terminal::fit;
    use termrast::terminal::glyphs::{FitSpace, fit_cells8};
    let med = |v: &mut Vec<Duration>| {
        v.sort();
        v[v.len() / 2].as_secs_f64() * 1e3
    };
    for glyphs in [GlyphMode::Braille, GlyphMode::Blocks, GlyphMode::Wedges] {
        let settings = ViewSettings {
            glyphs,
            colors: ColorMode::Truecolor,
            ..ViewSettings::default()
        };
        let mut app = App::new(Scene::for_model("bunny").expect("model"), settings);
        let sink = Counting {
            inner: io::sink(),
            bytes: Rc::new(Cell::new(0u64)),
        };
        let mut term = Terminal::with_options(
            LinkBackend::with_size(sink, 200, 61),
            ratatui::TerminalOptions {
                viewport: ratatui::Viewport::Fixed(ratatui::layout::Rect::new(0, 0, 200, 61)),
            },
        )
        .expect("terminal");
        let (mut total, mut tf, mut rs, mut gl, mut rest) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let (mut fit1, mut lanes1, mut gather1) = (Vec::new(), Vec::new(), Vec::new());
        let mut batches = 0;
        let mut out = [termrast::terminal::CellGlyph::default(); 8];
        for _ in 0..400 {
            app.tick(Duration::from_millis(33));
            let t0 = Instant::now();
            term.draw(|f| app.draw(f)).expect("draw");
            let all = t0.elapsed();
            let vp = &app.viewport;
            let [a, b] = app.scene.frame.timing;
            total.push(all);
            tf.push(a);
            rs.push(b);
            gl.push(vp.glyph_time);
            rest.push(all.saturating_sub(a + b + vp.glyph_time));
            if glyphs == GlyphMode::Braille {
                continue;
            }
            // The same frame's cells fitted on one thread: whole batches, the gather
            // alone, and the lane fit alone.
            let w = vp.target.width as usize;
            let px = &vp.color.0;
            let (cols, rows) = (usize::from(vp.cols), usize::from(vp.rows));
            let mut lanes_all = Vec::new();
            let t = Instant::now();
            for cy in 0..rows {
                for x0 in (0..cols).step_by(8) {
                    let n = (cols - x0).min(8);
                    let start = cy * fit::SY * w + x0 * fit::SX;
                    let sample_rows: [&[[u8; 4]]; fit::SY] = std::array::from_fn(|j| {
                        let at = start + j * w;
                        &px[at..at + n * fit::SX]
                    });
                    fit_cells8(
                        glyphs,
                        ColorMode::Truecolor,
                        FitSpace::Srgb,
                        &termrast::terminal::Palette::XTERM,
                        sample_rows,
                        &mut out[..n],
                    );
                }
            }
            fit1.push(t.elapsed());
            let t = Instant::now();
            for cy in 0..rows {
                for x0 in (0..cols).step_by(8) {
                    let n = (cols - x0).min(8);
                    let start = cy * fit::SY * w + x0 * fit::SX;
                    let any = (0..fit::SY).any(|j| {
                        let at = start + j * w;
                        px[at..at + n * fit::SX].iter().any(|p| p[3] >= 128)
                    });
                    if !any {
                        continue;
                    }
                    let lanes: [[[f32; 8]; 3]; fit::N] = std::array::from_fn(|k| {
                        let (i, j) = (k % fit::SX, k / fit::SX);
                        std::array::from_fn(|c| {
                            std::array::from_fn(|l| {
                                if l < n {
                                    f32::from(px[start + j * w + l * fit::SX + i][c]) / 255.0
                                } else {
                                    0.0
                                }
                            })
                        })
                    });
                    lanes_all.push(lanes);
                }
            }
            gather1.push(t.elapsed());
            batches = lanes_all.len();
            let rep = if glyphs == GlyphMode::Blocks {
                fit::Repertoire::blocks()
            } else {
                fit::Repertoire::wedges()
            };
            let t = Instant::now();
            for l in &lanes_all {
                std::hint::black_box(fit::fit_lanes(rep, std::hint::black_box(l)));
            }
            lanes1.push(t.elapsed());
        }
        println!(
            "bunny {}: frame {:.3} ms = transform {:.3} + raster {:.3} + glyphs {:.3} (2 threads) + rest {:.3}",
            glyphs.name(),
            med(&mut total),
            med(&mut tf),
            med(&mut rs),
            med(&mut gl),
            med(&mut rest)
        );
        if glyphs != GlyphMode::Braille {
            println!(
                "  one thread: fit_cells8 over all cells {:.3} ms; gather (+copy) {:.3}; fit_lanes alone {:.3} ({batches} non-empty batches)",
                med(&mut fit1),
                med(&mut gather1),
                med(&mut lanes1)
            );
        }
    }
}

fn main() {
    if std::env::var_os("VIEWER_BREAKDOWN").is_some() {
        breakdown();
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}

//! Whole viewer frames (`cargo bench --bench viewer`): transform, raster, glyph
//! fitting, ratatui's diff, the perceptual cell cache and the write to a byte-counting sink, at 200×60 cells in
//! braille and blocks modes, the model turning between frames as it does in the viewer.

use std::cell::Cell;
use std::io;
use std::rc::Rc;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use ratatui::Terminal;
use termrast::cli::view_cmd::load_model;
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
            (GlyphMode::Ascii, ColorMode::Truecolor),
        ] {
            let settings = ViewSettings {
                glyphs,
                colors,
                ..ViewSettings::default()
            };
            let mut app = App::new(load_model(spec).expect("model"), settings);
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
criterion_main!(benches);

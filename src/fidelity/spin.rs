//! The spinning model as the viewer sends it (`termrast bench bytes`): the bytes per
//! frame through the cell cache ([`crate::tui::link`]) beside sending every changed
//! cell exactly, and what the cache's threshold costs the eye, scored as the fidelity
//! benchmark scores a frame (emulated, painted, SSIM against the frame's reference).
//!
//! Both encoders see the same frames, diffed as ratatui diffs them (only cells that
//! changed since the previous frame reach the backend), and each feeds a terminal
//! emulator of its own, so the screens compared are what a terminal shows after the
//! whole sequence so far.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;

use super::FidelityError;
use super::metrics;
use super::reference;
use crate::scene::Scene;
use crate::scene::render::SceneView;
use crate::terminal::{ColorMode, GlyphMode, paint};
use crate::tui::link::{DELTA_E, LinkBackend};
use crate::tui::viewport::{SceneState, ViewSettings, Viewport};

/// What to measure.
#[derive(Clone, Debug)]
pub struct SpinConfig {
    pub cols: u16,
    pub rows: u16,
    /// Frames per sequence (the first, a full screen, is not counted).
    pub frames: usize,
    /// Radians the model turns between frames (0.026 is the viewer's 30 fps spin).
    pub step: f32,
    /// Score the screens (SSIM) as well as count bytes.
    pub score: bool,
}

impl Default for SpinConfig {
    fn default() -> Self {
        Self {
            cols: 200,
            rows: 60,
            frames: 13,
            step: 0.026,
            score: true,
        }
    }
}

/// One model in one glyph mode and colour depth.
#[derive(Clone, Debug, PartialEq)]
pub struct SpinRow {
    pub model: String,
    pub glyphs: GlyphMode,
    pub colors: ColorMode,
    /// Mean bytes per frame through the cell cache.
    pub cached_bytes: f64,
    /// Mean bytes per frame sending every changed cell exactly.
    pub exact_bytes: f64,
    /// Mean SSIM of the screens (cache, exact), if scored.
    pub ssim: Option<(f64, f64)>,
}

/// An encoder and what its terminal has received so far.
struct Stream {
    backend: LinkBackend<Vec<u8>>,
    received: Vec<u8>,
}

impl Stream {
    fn new(cols: u16, rows: u16, threshold: f32) -> Self {
        let mut backend = LinkBackend::with_size(Vec::new(), cols, rows);
        backend.threshold = threshold;
        Self {
            backend,
            received: Vec::new(),
        }
    }

    /// Sends a frame's changed cells; returns its bytes.
    fn send(&mut self, prev: &Buffer, next: &Buffer) -> Result<usize, FidelityError> {
        use ratatui::backend::Backend;
        let updates = prev.diff(next);
        let io = FidelityError::Encode;
        self.backend.draw(updates.into_iter()).map_err(io)?;
        Backend::flush(&mut self.backend).map_err(io)?;
        let out = std::mem::take(self.backend.writer());
        self.received.extend_from_slice(&out);
        Ok(out.len())
    }

    fn screen(&self, cols: u16, rows: u16) -> Result<image::RgbImage, FidelityError> {
        let grid = paint::emulate(&self.received, cols, rows)?;
        Ok(paint::paint(&grid)?.image)
    }
}

/// Measures one model in one glyph mode and colour depth.
pub fn measure(
    config: &SpinConfig,
    name: &str,
    model: &Scene,
    glyphs: GlyphMode,
    colors: ColorMode,
) -> Result<SpinRow, FidelityError> {
    let (cols, rows) = (config.cols, config.rows);
    let area = Rect::new(0, 0, cols, rows);
    let mut vp = Viewport::default();
    let mut streams = [
        Stream::new(cols, rows, DELTA_E),
        Stream::new(cols, rows, 0.0),
    ];
    let mut prev = Buffer::empty(area);
    let mut bytes = [0usize; 2];
    let mut ssim = [0f64; 2];
    let mut reference: Option<(SceneView, metrics::Reference)> = None;
    let mut state = SceneState::new(model.clone());
    let (w, h) = (
        u32::from(cols) * paint::CELL_WIDTH,
        u32::from(rows) * paint::CELL_HEIGHT,
    );
    for k in 0..config.frames {
        let settings = ViewSettings {
            glyphs,
            colors,
            angle: 0.6 + config.step * k as f32,
            ..ViewSettings::default()
        };
        vp.render(&mut state, &settings, (cols, rows));
        let mut next = Buffer::empty(area);
        ratatui::widgets::Widget::render(&vp, area, &mut next);
        for (s, total) in streams.iter_mut().zip(&mut bytes) {
            let n = s.send(&prev, &next)?;
            if k > 0 {
                *total += n;
            }
        }
        prev = next;
        if config.score && k > 0 {
            let camera = SceneView {
                pixel_aspect: 1.0,
                ..vp.view
            };
            let metric = match reference.take() {
                Some((c, m)) if c == camera => m,
                _ => {
                    let images = reference::render(model, &camera, w, h);
                    metrics::Reference::new(&images.image)?
                }
            };
            for (s, total) in streams.iter().zip(&mut ssim) {
                *total += metric.score(&s.screen(cols, rows)?)?.ssim;
            }
            reference = Some((camera, metric));
        }
    }
    let counted = config.frames.saturating_sub(1).max(1) as f64;
    Ok(SpinRow {
        model: name.to_owned(),
        glyphs,
        colors,
        cached_bytes: bytes[0] as f64 / counted,
        exact_bytes: bytes[1] as f64 / counted,
        ssim: config.score.then(|| (ssim[0] / counted, ssim[1] / counted)),
    })
}

//! The viewport: the model rendered at sub-sample resolution into the cells it is
//! given, as a ratatui widget.

use std::time::{Duration, Instant};

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::widgets::Widget;

use crate::raster::Target;
use crate::render::standard::{Model, StandardFrame, StandardView};
use crate::render::wire::Mode;
use crate::render::{Cull, DrawOptions, Rgba8};
use crate::terminal::glyphs::{Sample, fit_cell};
use crate::terminal::{CellGlyph, ColorMode, GlyphMode};

/// What the viewer shows and how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSettings {
    pub glyphs: GlyphMode,
    pub colors: ColorMode,
    pub mode: Mode,
    /// Cell width over cell height.
    pub cell_aspect: f32,
    /// Camera zoom (1 = the standard distance 2.6).
    pub zoom: f32,
    pub angle: f32,
    pub tilt: f32,
    pub cull: bool,
}

impl Default for ViewSettings {
    fn default() -> Self {
        Self {
            glyphs: GlyphMode::Braille,
            colors: ColorMode::Truecolor,
            mode: Mode::Fill,
            cell_aspect: 0.5,
            zoom: 1.0,
            angle: 0.6,
            tilt: 0.25,
            cull: false,
        }
    }
}

impl ViewSettings {
    /// The camera and model rotation for this frame, for a glyph mode's samples.
    #[must_use]
    pub fn view(&self) -> StandardView {
        let (sx, sy) = self.glyphs.dims();
        let mut v = StandardView::at(self.angle);
        v.tilt = self.tilt;
        v.camera.eye.z /= self.zoom.max(0.05);
        v.pixel_aspect = self.cell_aspect * sy as f32 / sx as f32;
        v
    }

    /// Draw options of the viewer.
    #[must_use]
    pub fn options(&self) -> DrawOptions {
        DrawOptions {
            cull: if self.cull { Cull::Back } else { Cull::None },
            ..DrawOptions::default()
        }
    }
}

/// Buffers and results of the last rendered frame. Everything is reused; buffers are
/// resized only when the viewport or the glyph mode changes.
#[derive(Debug)]
pub struct Viewport {
    pub frame: StandardFrame,
    pub color: Rgba8,
    pub cells: Vec<CellGlyph>,
    pub cols: u16,
    pub rows: u16,
    /// Sample target of the last frame.
    pub target: Target,
    pub settings: ViewSettings,
    /// Time spent fitting glyphs.
    pub glyph_time: Duration,
    pub wire_pixels: u64,
}

impl Default for Viewport {
    fn default() -> Self {
        Self {
            frame: StandardFrame::new(Target::new(1, 1)),
            color: Rgba8::default(),
            cells: Vec::new(),
            cols: 0,
            rows: 0,
            target: Target::new(1, 1),
            settings: ViewSettings::default(),
            glyph_time: Duration::ZERO,
            wire_pixels: 0,
        }
    }
}

impl Viewport {
    /// Renders the model for a `cols × rows` cell area and fits every cell's glyph.
    pub fn render(&mut self, model: &Model, settings: &ViewSettings, cols: u16, rows: u16) {
        let (sx, sy) = settings.glyphs.dims();
        let target = Target::new(u32::from(cols) * sx, u32::from(rows) * sy);
        self.settings = *settings;
        self.cols = cols;
        self.rows = rows;
        self.target = target;
        let view = settings.view();
        self.wire_pixels = self.frame.draw(
            model,
            &view,
            target,
            &settings.options(),
            settings.mode,
            &mut self.color,
        );
        let start = Instant::now();
        self.cells.clear();
        self.cells
            .resize(usize::from(cols) * usize::from(rows), CellGlyph::default());
        for cy in 0..rows {
            for cx in 0..cols {
                let (s, n) = self.samples(cx, cy);
                self.cells[usize::from(cy) * usize::from(cols) + usize::from(cx)] =
                    fit_cell(settings.glyphs, &s[..n], settings.colors == ColorMode::None);
            }
        }
        self.glyph_time = start.elapsed();
    }

    /// The samples of cell `(cx, cy)`, row-major, and how many there are.
    #[must_use]
    pub fn samples(&self, cx: u16, cy: u16) -> ([Sample; 8], usize) {
        let (sx, sy) = self.settings.glyphs.dims();
        let mut out = [Sample::default(); 8];
        let w = self.target.width as usize;
        for j in 0..sy {
            for i in 0..sx {
                let x = usize::from(cx) * sx as usize + i as usize;
                let y = usize::from(cy) * sy as usize + j as usize;
                if let Some(p) = self.color.0.get(y * w + x) {
                    out[(j * sx + i) as usize] = Sample {
                        rgb: [p[0], p[1], p[2]],
                        covered: p[3] == 255,
                    };
                }
            }
        }
        (out, (sx * sy) as usize)
    }

    /// The glyph of a cell.
    #[must_use]
    pub fn cell(&self, cx: u16, cy: u16) -> Option<&CellGlyph> {
        (cx < self.cols && cy < self.rows)
            .then(|| &self.cells[usize::from(cy) * usize::from(self.cols) + usize::from(cx)])
    }
}

impl Widget for &Viewport {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let colors = self.settings.colors;
        let color = |c: Option<[u8; 3]>| match (c, colors) {
            (Some(c), m) if m != ColorMode::None => m.color(c),
            _ => Color::Reset,
        };
        for cy in 0..self.rows.min(area.height) {
            for cx in 0..self.cols.min(area.width) {
                let Some(g) = self.cell(cx, cy) else { continue };
                if let Some(cell) = buf.cell_mut((area.x + cx, area.y + cy)) {
                    cell.set_char(g.ch);
                    cell.set_style(Style::default().fg(color(g.fg)).bg(color(g.bg)));
                }
            }
        }
    }
}

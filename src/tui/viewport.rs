//! The viewport: a scene (a model is a one-object scene) rendered at sub-sample
//! resolution into the cells it is given, as a ratatui widget.

use std::time::{Duration, Instant};

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::widgets::Widget;

use crate::raster::Target;
use crate::render::Rgba8;
use crate::render::wire::WireCount;
use crate::scene::Scene;
use crate::scene::render::{SceneFrame, SceneView};
use crate::terminal::fit;
use crate::terminal::glyphs::{FitSpace, Sample, fit_cell_in, fit_cells8};
use crate::terminal::{CellGlyph, ColorMode, GlyphMode, Palette};

/// What the viewer shows and how; how the scene is drawn (filled or as edges,
/// culled) is the scene's own ([`Scene::set_mode`], [`Scene::set_cull`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSettings {
    pub glyphs: GlyphMode,
    pub colors: ColorMode,
    /// Cell width over cell height.
    pub cell_aspect: f32,
    /// Camera zoom (1 = the scene's framing or camera).
    pub zoom: f32,
    /// Radians about y, then about x: the model's turn, or the camera's orbit about
    /// a scene file's target (see [`crate::scene::Rig`]).
    pub angle: f32,
    pub tilt: f32,
    /// Where the shape-fitted modes measure colour error.
    pub fit_space: FitSpace,
    /// The terminal's 16 colours (xterm's unless it said otherwise).
    pub palette: Palette,
}

impl Default for ViewSettings {
    fn default() -> Self {
        Self {
            glyphs: GlyphMode::Braille,
            colors: ColorMode::Truecolor,
            cell_aspect: 0.5,
            zoom: 1.0,
            angle: 0.6,
            tilt: 0.25,
            fit_space: FitSpace::Srgb,
            palette: Palette::XTERM,
        }
    }
}

impl ViewSettings {
    /// The view of a frame at `time` seconds, for the glyph mode's samples (whose
    /// pixel aspect follows from the cell's).
    #[must_use]
    pub fn view(&self, time: f32) -> SceneView {
        let (sx, sy) = self.glyphs.dims();
        SceneView {
            time,
            yaw: self.angle,
            pitch: self.tilt,
            zoom: self.zoom,
            pixel_aspect: self.cell_aspect * sy as f32 / sx as f32,
        }
    }

    /// Takes colour `i` of the terminal's palette as it reported it; whether that
    /// changes what a 16-colour frame looks like.
    pub fn terminal_color(&mut self, i: u8, c: crate::terminal::Rgb) -> bool {
        let p = self.palette.with(i, c);
        let changed = p != self.palette;
        self.palette = p;
        changed && matches!(self.colors, ColorMode::Ansi16 | ColorMode::Ansi256)
    }
}

/// A scene in the viewer: what it is, its pipelines and buffers, and its time.
#[derive(Debug)]
pub struct SceneState {
    pub scene: Scene,
    pub frame: SceneFrame,
    /// Seconds of animation (stops while paused).
    pub time: f32,
}

impl SceneState {
    /// A scene with its pipelines, at time 0.
    #[must_use]
    pub fn new(scene: Scene) -> Self {
        let frame = SceneFrame::new(&scene);
        Self {
            scene,
            frame,
            time: 0.0,
        }
    }
}

/// Buffers and results of the last rendered frame. Everything is reused; buffers are
/// resized only when the viewport or the glyph mode changes.
#[derive(Debug)]
pub struct Viewport {
    pub color: Rgba8,
    pub cells: Vec<CellGlyph>,
    pub cols: u16,
    pub rows: u16,
    /// Sample target of the last frame.
    pub target: Target,
    pub settings: ViewSettings,
    /// The view of the last frame.
    pub view: SceneView,
    /// Time spent fitting glyphs.
    pub glyph_time: Duration,
    /// What the wireframe drew.
    pub wire: WireCount,
}

impl Default for Viewport {
    fn default() -> Self {
        Self {
            color: Rgba8::default(),
            cells: Vec::new(),
            cols: 0,
            rows: 0,
            target: Target::new(1, 1),
            settings: ViewSettings::default(),
            view: SceneView::default(),
            glyph_time: Duration::ZERO,
            wire: WireCount::default(),
        }
    }
}

impl Viewport {
    /// Renders a scene at its time, seen as the view settings say, for a
    /// `cols × rows` cell area, and fits every cell's glyph; silhouette edges are
    /// drawn over the cells as `/ \ | _`.
    pub fn render(
        &mut self,
        s: &mut SceneState,
        settings: &ViewSettings,
        (cols, rows): (u16, u16),
    ) {
        let target = self.lay_out(settings, cols, rows);
        self.view = settings.view(s.time);
        let frame = &mut s.frame;
        // One colour buffer passes between the two: the frame is drawn into the
        // viewport's last one, which then holds it.
        std::mem::swap(&mut self.color, &mut frame.color);
        frame.draw(&s.scene, target, &self.view);
        self.wire = frame.wire;
        std::mem::swap(&mut self.color, &mut frame.color);
        self.fit_cells();
        for e in &frame.silhouettes {
            self.overlay_edge(e.a, e.b);
        }
    }

    /// Draws a silhouette edge (sample coordinates) over the cells it crosses, with
    /// the glyph closest to its direction on screen (cells are `cell_aspect` as wide
    /// as they are tall).
    fn overlay_edge(&mut self, a: glam::Vec2, b: glam::Vec2) {
        let (sx, sy) = self.settings.glyphs.dims();
        let cell = |p: glam::Vec2| {
            (
                (p.x / sx as f32).floor() as i64,
                (p.y / sy as f32).floor() as i64,
            )
        };
        let (ca, cb) = (cell(a), cell(b));
        let d = b - a;
        let ch = edge_glyph(d.x / sx as f32 * self.settings.cell_aspect, d.y / sy as f32);
        let Ok(line) = crate::raster::line::Line::new(ca, cb) else {
            return;
        };
        let (cols, rows) = (i64::from(self.cols), i64::from(self.rows));
        line.draw_clipped(
            cols,
            rows,
            |x, y| {
                let g = &mut self.cells[(y * cols + x) as usize];
                g.ch = ch;
                g.fg = Some(g.fg.unwrap_or([230, 230, 230]));
            },
            &mut crate::raster::line::NoTrace,
        );
    }

    /// Takes the settings and cell area of a frame; returns its sample target.
    fn lay_out(&mut self, settings: &ViewSettings, cols: u16, rows: u16) -> Target {
        let (sx, sy) = settings.glyphs.dims();
        self.settings = *settings;
        self.cols = cols;
        self.rows = rows;
        self.target = Target::new(u32::from(cols) * sx, u32::from(rows) * sy);
        self.target
    }

    /// Fits every cell's glyph and colours to its samples, rows of cells shared out
    /// among the CPU's cores (each cell's fit is independent of the others).
    fn fit_cells(&mut self) {
        use rayon::prelude::*;
        let cols = usize::from(self.cols);
        let start = Instant::now();
        let mut cells = std::mem::take(&mut self.cells);
        crate::memory::refill(
            &mut cells,
            cols * usize::from(self.rows),
            CellGlyph::default(),
        );
        if cols > 0 {
            let this = &*self;
            cells
                .par_chunks_mut(cols)
                .enumerate()
                .for_each(|(cy, row)| this.fit_row(cy, row));
        }
        self.cells = cells;
        self.glyph_time = start.elapsed();
    }

    /// Fits cell row `cy` into `out`.
    fn fit_row(&self, cy: usize, out: &mut [CellGlyph]) {
        let (mode, colors, space, palette) = (
            self.settings.glyphs,
            self.settings.colors,
            self.settings.fit_space,
            &self.settings.palette,
        );
        let cols = out.len();
        if mode.dims() == (fit::SX as u32, fit::SY as u32) && colors != ColorMode::None {
            // The shape fit runs 8 cells at a time, in lanes, straight from the frame's
            // rows; a batch of empty cells (most of the background) is skipped.
            let w = self.target.width as usize;
            let row0 = cy * fit::SY * w;
            for x0 in (0..cols).step_by(8) {
                let n = (cols - x0).min(8);
                let start = row0 + x0 * fit::SX;
                let sample_rows: [&[[u8; 4]]; fit::SY] = std::array::from_fn(|j| {
                    let at = start + j * w;
                    &self.color.0[at..at + n * fit::SX]
                });
                fit_cells8(
                    mode,
                    colors,
                    space,
                    palette,
                    sample_rows,
                    &mut out[x0..x0 + n],
                );
            }
        } else {
            // One sample buffer filled in place: returning it by value per cell cost a
            // stalled wide copy of bytes just written one at a time.
            let mut s = [Sample::default(); GlyphMode::MAX_SAMPLES];
            for (cx, cell) in out.iter_mut().enumerate() {
                let n = self.samples_into(cx as u16, cy as u16, &mut s);
                *cell = fit_cell_in(mode, &s[..n], colors, space, palette);
            }
        }
    }

    /// The samples of cell `(cx, cy)`, row-major, and how many there are.
    #[must_use]
    pub fn samples(&self, cx: u16, cy: u16) -> ([Sample; GlyphMode::MAX_SAMPLES], usize) {
        let mut out = [Sample::default(); GlyphMode::MAX_SAMPLES];
        let n = self.samples_into(cx, cy, &mut out);
        (out, n)
    }

    /// [`Viewport::samples`] into `out`.
    #[inline]
    fn samples_into(&self, cx: u16, cy: u16, out: &mut [Sample; GlyphMode::MAX_SAMPLES]) -> usize {
        let (sx, sy) = self.settings.glyphs.dims();
        let w = self.target.width as usize;
        for j in 0..sy {
            for i in 0..sx {
                let x = usize::from(cx) * sx as usize + i as usize;
                let y = usize::from(cy) * sy as usize + j as usize;
                // Alpha is coverage: 255 or 0, or a fraction after supersampling.
                out[(j * sx + i) as usize] =
                    self.color
                        .0
                        .get(y * w + x)
                        .map_or(Sample::default(), |p| Sample {
                            rgb: [p[0], p[1], p[2]],
                            covered: p[3] >= 128,
                        });
            }
        }
        (sx * sy) as usize
    }

    /// Whether any sample of cell `(cx, cy)` is covered.
    #[must_use]
    pub fn covered(&self, cx: u16, cy: u16) -> bool {
        let (samples, n) = self.samples(cx, cy);
        samples[..n].iter().any(|s| s.covered)
    }

    /// The covered cell nearest the centre of the covered cells (the middle of the
    /// model's projection), if any cell is covered.
    #[must_use]
    pub fn central_covered_cell(&self) -> Option<(u16, u16)> {
        let cells = (0..self.rows)
            .flat_map(|y| (0..self.cols).map(move |x| (x, y)))
            .filter(|&(x, y)| self.covered(x, y));
        let (mut n, mut sx, mut sy) = (0f64, 0f64, 0f64);
        for (x, y) in cells.clone() {
            n += 1.0;
            sx += f64::from(x);
            sy += f64::from(y);
        }
        let (mx, my) = (sx / n.max(1.0), sy / n.max(1.0));
        // Cells are about twice as tall as wide: distance in cell widths.
        cells.min_by(|a, b| {
            let d = |c: &(u16, u16)| {
                (f64::from(c.0) - mx).powi(2) + (2.0 * (f64::from(c.1) - my)).powi(2)
            };
            d(a).total_cmp(&d(b))
        })
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
        let (colors, palette) = (self.settings.colors, &self.settings.palette);
        let color = |c: Option<[u8; 3]>| match (c, colors) {
            (Some(c), m) if m != ColorMode::None => m.color(c, palette),
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

/// The glyph closest to an edge's direction, given in cell widths across (`dx`,
/// already scaled to the cell's aspect) and cell heights down (`dy`).
#[must_use]
pub fn edge_glyph(dx: f32, dy: f32) -> char {
    // Angle above the horizontal, folded to [0°, 180°): y is down on screen.
    let mut deg = (-dy).atan2(dx).to_degrees();
    if deg < 0.0 {
        deg += 180.0;
    }
    match deg {
        d if !(22.5..157.5).contains(&d) => '_',
        d if d < 67.5 => '/',
        d if d < 112.5 => '|',
        _ => '\\',
    }
}

#[cfg(test)]
mod tests {
    use super::edge_glyph;

    #[test]
    fn edge_glyphs_follow_the_direction_on_screen() {
        // y is down on screen: (1, -1) rises to the right.
        assert_eq!(edge_glyph(1.0, 0.0), '_');
        assert_eq!(edge_glyph(-1.0, 0.1), '_');
        assert_eq!(edge_glyph(0.0, 1.0), '|');
        assert_eq!(edge_glyph(0.1, -1.0), '|');
        assert_eq!(edge_glyph(1.0, -1.0), '/');
        assert_eq!(edge_glyph(-1.0, 1.0), '/');
        assert_eq!(edge_glyph(1.0, 1.0), '\\');
        assert_eq!(edge_glyph(-1.0, -1.0), '\\');
    }
}

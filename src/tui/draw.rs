//! The viewer's layout and drawing: the model, the inspector and line panels (beside
//! the model when the terminal is wide enough, below it otherwise), the status line
//! and the help and plan overlays.

use std::fmt::Write as _;
use std::time::Duration;

use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Modifier, Style};
use ratatui::text::Line;
use ratatui::widgets::{Block, Borders, Clear, Paragraph, Wrap};

use super::app::{App, MIN_COLS, MIN_ROWS, PANEL_COLS};
use super::inspector::{inspector_text, line_text};
use super::panel::{PanelText, window};
use super::status::Priority;
use crate::render::wire::Mode;

/// The viewer's layout.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Areas {
    /// Everything above the status line.
    pub main: Rect,
    /// The model.
    pub view: Rect,
    /// The inspector and line panels (empty when closed).
    pub panel: Rect,
    pub status: Rect,
}

/// The panel's height below the model: about half the rows, leaving the model three.
fn panel_rows_below(main: Rect) -> u16 {
    (main.height / 2).max(8).min(main.height.saturating_sub(3))
}

impl App {
    /// Where everything goes on a screen of `area`: the panel beside the model when
    /// there is room for both, else below it.
    #[must_use]
    pub fn areas(&self, area: Rect) -> Areas {
        let [main, status] =
            Layout::vertical([Constraint::Min(1), Constraint::Length(1)]).areas(area);
        let (view, panel) = if !self.inspect {
            (main, Rect::default())
        } else if main.width >= MIN_COLS + PANEL_COLS {
            let [v, p] = Layout::horizontal([Constraint::Min(1), Constraint::Length(PANEL_COLS)])
                .areas(main);
            (v, p)
        } else {
            let [v, p] = Layout::vertical([
                Constraint::Min(1),
                Constraint::Length(panel_rows_below(main)),
            ])
            .areas(main);
            (v, p)
        };
        Areas {
            main,
            view,
            panel,
            status,
        }
    }

    /// The model's part of a screen of `area` when nothing covers it (help and plan
    /// overlays do): what may be sent in part over a slow link.
    #[must_use]
    pub fn model_area(&self, area: Rect) -> Option<Rect> {
        (!self.help && !self.show_plan && area.width >= MIN_COLS && area.height >= MIN_ROWS)
            .then(|| self.areas(area).view)
    }

    /// Renders the model for the current layout and draws everything.
    pub fn draw(&mut self, f: &mut Frame) {
        let area = f.area();
        if area.width < MIN_COLS || area.height < MIN_ROWS {
            let msg = format!(
                "terminal too small: {}x{}, need {MIN_COLS}x{MIN_ROWS} (q quits)",
                area.width, area.height
            );
            f.render_widget(Paragraph::new(msg).wrap(Wrap { trim: true }), area);
            return;
        }
        let Areas {
            main,
            view,
            panel,
            status,
        } = self.areas(area);
        self.view_area = view;
        self.panel_area = panel;
        self.viewport
            .render(&mut self.scene, &self.settings, (view.width, view.height));
        self.place_cursor_on_model();
        self.cursor = (
            self.cursor.0.min(view.width - 1),
            self.cursor.1.min(view.height - 1),
        );
        f.render_widget(&self.viewport, view);
        if self.inspect {
            let pos = (view.x + self.cursor.0, view.y + self.cursor.1);
            if let Some(c) = f.buffer_mut().cell_mut(pos) {
                c.set_style(Style::default().add_modifier(Modifier::REVERSED));
            }
            self.draw_panel(f, panel);
        }
        self.update_status();
        let line = self.status.fit(usize::from(status.width));
        f.render_widget(Paragraph::new(Line::from(line)), status);
        if self.help {
            draw_help(f, main);
        } else if self.show_plan {
            self.draw_plan(f, main);
        }
    }

    fn draw_plan(&self, f: &mut Frame, area: Rect) {
        let text = self.scene.scene.plan.to_string();
        let w = 76.min(area.width);
        let inner = usize::from(w.saturating_sub(2)).max(1);
        // Rows the plan takes once wrapped to the box.
        let rows: usize = text
            .lines()
            .map(|l| l.chars().count().div_ceil(inner).max(1))
            .sum();
        let h = (rows as u16 + 2).min(area.height);
        let r = Rect::new(area.x + (area.width - w) / 2, area.y, w, h);
        f.render_widget(Clear, r);
        f.render_widget(
            Paragraph::new(text).wrap(Wrap { trim: false }).block(
                Block::default()
                    .borders(Borders::ALL)
                    .title(" plan (p closes) "),
            ),
            r,
        );
    }

    /// The inspector and the line panel in `area`: stacked when the area is narrow,
    /// side by side when it is a wide strip below the model.
    fn draw_panel(&mut self, f: &mut Frame, area: Rect) {
        let (cx, cy) = self.cursor;
        let text = inspector_text(&self.viewport, &self.scene, cx, cy, self.sub);
        let line = match self.focused_line() {
            Some((focus, sl)) => line_text(focus, &sl),
            None => {
                let mut t = PanelText::default();
                t.prose(0, "no line here");
                t
            }
        };
        let wide_strip = area.width >= 2 * PANEL_COLS.min(48) && area.width > area.height * 3;
        let [top, bottom] = if wide_strip {
            Layout::horizontal([Constraint::Min(20), Constraint::Length(area.width * 2 / 5)])
                .areas(area)
        } else {
            let line_rows = line.rows(usize::from(area.width.saturating_sub(2))).len() as u16 + 2;
            let line_rows = line_rows.min(area.height / 2).max(3);
            Layout::vertical([Constraint::Min(3), Constraint::Length(line_rows)]).areas(area)
        };
        let title = if !self.scene.scene.is_model() {
            " inspector (Tab: sample, PgUp/PgDn, p: plan) "
        } else {
            " inspector (Tab: sample, PgUp/PgDn) "
        };
        self.panel_scroll = draw_box(f, top, &text, self.panel_scroll, title);
        draw_box(f, bottom, &line, 0, " line ([ ] step) ");
    }

    /// Rewrites the status line: the fields in order, each with its importance (the
    /// line is fitted to the terminal's width when drawn).
    pub fn update_status(&mut self) {
        let scene = &self.scene.scene;
        let frame = &self.scene.frame;
        let stats = frame.stats;
        let [tf, rs] = frame.timing;
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let s = &mut self.status;
        s.clear();
        if let Some(n) = &self.notice {
            s.push(Priority::Always, n.clone());
        }
        if self.inspect {
            s.push(Priority::Always, "inspect: click or arrows select a cell");
        }
        if self.paused {
            s.push(Priority::Always, "paused");
        }
        s.push(
            Priority::Always,
            format!(
                "{} {}",
                self.settings.glyphs.name(),
                self.settings.colors.name()
            ),
        );
        let lines = self.viewport.wire.lines;
        let mut drawing = match scene.mode() {
            Some(Mode::Fill) => "fill".to_string(),
            Some(Mode::Wire) => format!("wire {lines} lines"),
            Some(Mode::FillWire) => format!("fill+wire {lines} lines"),
            None => format!("fill/wire by object {lines} lines"),
        };
        drawing.push_str(match scene.cull() {
            Some(true) => " cull",
            Some(false) => " no cull",
            None => " cull by object",
        });
        s.push(Priority::Drawing, drawing);
        if let (false, Some(fps)) = (self.paused, self.fps.fps()) {
            s.push(Priority::Drawing, format!("{fps:.0} fps"));
        }
        let threads = if frame.renderer.frame_pooled() {
            format!("{} threads", frame.renderer.threads())
        } else {
            "1 thread".to_string()
        };
        s.push_short(
            Priority::Timing,
            format!(
                "transform {:.1} raster+shade {:.1} glyphs {:.1} output {:.1} ms, {threads}",
                ms(tf),
                ms(rs),
                ms(self.viewport.glyph_time),
                ms(self.output_time),
            ),
            format!("raster+shade {:.1} ms, {threads}", ms(rs)),
        );
        s.push_short(
            Priority::Counts,
            format!(
                "tris {} drawn {} culled {} clipped",
                stats.drawn, stats.culled, stats.clipped
            ),
            format!("tris {}", stats.drawn),
        );
        s.push(Priority::Bytes, format!("{} B", self.bytes));
        let l = self.link;
        let mut link = format!("{:.0} kB/s", l.bytes_per_second / 1e3);
        match l.rtt {
            _ if l.unpaced => link.push_str(" unpaced (no answer)"),
            Some(rtt) => {
                let _ = write!(link, " rtt {:.0} ms", ms(rtt));
            }
            None => {}
        }
        let short = link.clone();
        if let (false, Some(_)) = (l.unpaced, l.rtt) {
            let _ = write!(link, " {:.0} fps delivered", l.delivered_fps);
        }
        if let Some(b) = l.budget {
            let _ = write!(link, " {:.1} kB/frame", b as f64 / 1e3);
        }
        s.push_short(Priority::Link, link, short);
        s.push(Priority::Always, "? help");
        if !scene.is_model() {
            s.push(
                Priority::Drawing,
                format!("plan: {} (p)", scene.plan.summary()),
            );
        }
    }
}

/// A bordered box of panel text, scrolled by `scroll` (clamped; returned).
fn draw_box(f: &mut Frame, area: Rect, text: &PanelText, scroll: usize, title: &str) -> usize {
    let inner = (
        usize::from(area.width.saturating_sub(2)),
        usize::from(area.height.saturating_sub(2)),
    );
    let rows = text.rows(inner.0.max(1));
    let (shown, scroll) = window(&rows, inner.1, scroll);
    let lines: Vec<Line> = shown.into_iter().map(Line::from).collect();
    f.render_widget(Clear, area);
    f.render_widget(
        Paragraph::new(lines).block(Block::default().borders(Borders::ALL).title(title)),
        area,
    );
    scroll
}

fn draw_help(f: &mut Frame, area: Rect) {
    let text = "space     pause / resume\n\
                arrows    rotate; in inspect mode move the cursor (also h j k l)\n\
                Shift+arrows, H J K L   move the cursor 8 cells\n\
                + -       zoom (also the mouse wheel)\n\
                w         fill / wireframe / fill + wireframe\n\
                g         glyphs: ascii, half, quadrant, sextant, braille, blocks, wedges\n\
                c         colours: truecolor, 256, 16, none\n\
                b         back-face culling on / off\n\
                i         inspect mode (freezes the model; click a cell to select it)\n\
                Tab       next sub-sample of the cell\n\
                PgUp PgDn scroll the inspector (also the wheel over it)\n\
                [ ]       step along the line in the line panel\n\
                drag      rotate\n\
                p         the scene's plan (scenes only)\n\
                ?         this help        Esc  close      q / Ctrl-C  quit";
    let w = 76.min(area.width);
    let h = 17.min(area.height);
    let r = Rect::new(
        area.x + (area.width - w) / 2,
        area.y + (area.height - h) / 2,
        w,
        h,
    );
    f.render_widget(Clear, r);
    f.render_widget(
        Paragraph::new(text)
            .wrap(Wrap { trim: false })
            .block(Block::default().borders(Borders::ALL).title(" keys ")),
        r,
    );
}

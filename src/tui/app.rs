//! Viewer state, input handling and layout.

use std::fmt::Write as _;
use std::time::Duration;

use ratatui::Frame;
use ratatui::crossterm::event::{
    Event, KeyCode, KeyEvent, KeyEventKind, KeyModifiers, MouseButton, MouseEventKind,
};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Modifier, Style};
use ratatui::text::Line;
use ratatui::widgets::{Block, Borders, Clear, Paragraph, Wrap};

use super::inspector::{inspector_text, line_at, line_text, sample_pixel, scene_inspector_text};
use super::viewport::{ViewSettings, Viewport};
use crate::render::standard::Model;
use crate::render::wire::{Mode, project_edge};
use crate::scene::Scene;
use crate::scene::render::SceneFrame;
use crate::terminal::{ColorMode, GlyphMode};

/// Smallest usable terminal.
pub const MIN_COLS: u16 = 24;
pub const MIN_ROWS: u16 = 8;
/// Width of the inspector panel.
pub const PANEL_COLS: u16 = 58;

/// Rotation speed while spinning, radians per second.
const SPIN: f32 = 0.8;

/// The viewer.
#[derive(Debug)]
pub struct App {
    pub model: Model,
    pub settings: ViewSettings,
    pub viewport: Viewport,
    pub paused: bool,
    pub inspect: bool,
    pub help: bool,
    pub quit: bool,
    /// Selected cell and sub-sample.
    pub cursor: (u16, u16),
    pub sub: usize,
    /// A line being stepped through: edge and step.
    pub line_focus: Option<([u32; 2], i64)>,
    /// Status figures of the last frame.
    pub fps: f32,
    pub output_time: Duration,
    pub bytes: u64,
    /// The status line text, reused every frame.
    pub status: String,
    /// Said once at the start of the status line, until the first key.
    pub notice: Option<String>,
    /// What the link to the terminal carries, for the status line.
    pub link: LinkStatus,
    drag: Option<(u16, u16)>,
    /// Area of the viewport on screen, from the last draw.
    view_area: Rect,
    /// A scene shown instead of the model, with its buffers and clock.
    pub scene: Option<SceneState>,
    /// Show the scene's plan.
    pub show_plan: bool,
}

/// The link to the terminal as the status line shows it.
#[derive(Clone, Copy, Debug, Default)]
pub struct LinkStatus {
    /// Bytes sent per second, recently.
    pub bytes_per_second: f64,
    /// Round trip of the last answered frame, if frames are paced.
    pub rtt: Option<Duration>,
    /// Frames the terminal confirmed per second.
    pub delivered_fps: f32,
    /// The terminal does not answer queries: frames are not paced.
    pub unpaced: bool,
    /// Bytes a frame may take while the link holds frames back.
    pub budget: Option<usize>,
}

/// A scene in the viewer: what it is, its pipelines and buffers, and its time.
#[derive(Debug)]
pub struct SceneState {
    pub scene: Scene,
    pub frame: SceneFrame,
    /// Seconds of animation (stops while paused).
    pub time: f32,
}

/// The viewer's layout.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Areas {
    /// Everything above the status line.
    pub main: Rect,
    /// The model.
    pub view: Rect,
    /// The inspector panel (empty when closed).
    pub panel: Rect,
    pub status: Rect,
}

impl App {
    /// A viewer for a model.
    #[must_use]
    pub fn new(model: Model, settings: ViewSettings) -> Self {
        Self {
            model,
            settings,
            viewport: Viewport::default(),
            paused: false,
            inspect: false,
            help: false,
            quit: false,
            cursor: (0, 0),
            sub: 0,
            line_focus: None,
            fps: 0.0,
            output_time: Duration::ZERO,
            bytes: 0,
            status: String::with_capacity(256),
            notice: None,
            link: LinkStatus::default(),
            drag: None,
            view_area: Rect::default(),
            scene: None,
            show_plan: false,
        }
    }

    /// A viewer for a scene: its objects spin as the file says, and the arrows and
    /// mouse orbit the camera about its target.
    #[must_use]
    pub fn with_scene(scene: Scene, settings: ViewSettings) -> Self {
        let frame = SceneFrame::new(&scene);
        let mut app = Self::new(Model::new(crate::mesh::Mesh::default()), settings);
        app.settings.angle = 0.0;
        app.settings.tilt = 0.0;
        app.scene = Some(SceneState {
            scene,
            frame,
            time: 0.0,
        });
        app
    }

    /// Advances the animation by `dt`.
    pub fn tick(&mut self, dt: Duration) {
        if let Some(s) = &mut self.scene {
            if !self.paused {
                s.time += dt.as_secs_f32();
            }
            return;
        }
        if !self.paused {
            self.settings.angle =
                (self.settings.angle + SPIN * dt.as_secs_f32()) % std::f32::consts::TAU;
        }
    }

    fn cycle<T: Copy + PartialEq>(all: &[T], v: T) -> T {
        let i = all.iter().position(|x| *x == v).unwrap_or(0);
        all[(i + 1) % all.len()]
    }

    /// Handles one input event; returns whether the picture may have changed.
    pub fn handle(&mut self, ev: &Event) -> bool {
        match ev {
            Event::Key(k) if k.kind != KeyEventKind::Release => self.key(*k),
            Event::Mouse(m) => {
                let (x, y) = (m.column, m.row);
                let a = self.view_area;
                let inside = x >= a.x && y >= a.y && x < a.x + a.width && y < a.y + a.height;
                match m.kind {
                    MouseEventKind::Down(MouseButton::Left) if inside => {
                        self.cursor = (x - a.x, y - a.y);
                        self.line_focus = None;
                        self.drag = Some((x, y));
                    }
                    MouseEventKind::Drag(MouseButton::Left) => {
                        if let Some((px, py)) = self.drag {
                            self.settings.angle += (f32::from(x) - f32::from(px)) * 0.05;
                            self.settings.tilt += (f32::from(y) - f32::from(py)) * 0.08;
                            self.drag = Some((x, y));
                        }
                    }
                    MouseEventKind::Up(_) => self.drag = None,
                    MouseEventKind::ScrollUp => self.zoom(1.1),
                    MouseEventKind::ScrollDown => self.zoom(1.0 / 1.1),
                    _ => return false,
                }
                true
            }
            Event::Resize(..) => true,
            _ => false,
        }
    }

    fn zoom(&mut self, f: f32) {
        self.settings.zoom = (self.settings.zoom * f).clamp(0.2, 20.0);
    }

    fn move_cursor(&mut self, dx: i32, dy: i32) {
        let (w, h) = (self.viewport.cols.max(1), self.viewport.rows.max(1));
        let x = (i32::from(self.cursor.0) + dx).clamp(0, i32::from(w) - 1) as u16;
        let y = (i32::from(self.cursor.1) + dy).clamp(0, i32::from(h) - 1) as u16;
        self.cursor = (x, y);
        self.line_focus = None;
    }

    /// Steps along the inspected line; the cursor follows.
    fn step_line(&mut self, by: i64) {
        let (sx, sy) = self.settings.glyphs.dims();
        let (x, y) = sample_pixel(&self.viewport, self.cursor.0, self.cursor.1, self.sub);
        let focus = self
            .line_focus
            .or_else(|| line_at(&self.viewport, &self.model, x, y).map(|(e, _, k)| (e, k)));
        let Some((edge, k)) = focus else { return };
        let Some(sl) = project_edge(&self.viewport.frame.cache, edge, self.viewport.target) else {
            return;
        };
        let k = (k + by).clamp(0, sl.line.dx);
        let (px, py) = sl.line.pixel(k, sl.line.minor_at(k));
        let (tw, th) = (
            i64::from(self.viewport.target.width),
            i64::from(self.viewport.target.height),
        );
        if (0..tw).contains(&px) && (0..th).contains(&py) {
            self.cursor = ((px / i64::from(sx)) as u16, (py / i64::from(sy)) as u16);
            self.sub = ((py % i64::from(sy)) * i64::from(sx) + px % i64::from(sx)) as usize;
        }
        self.line_focus = Some((edge, k));
    }

    fn key(&mut self, k: KeyEvent) -> bool {
        self.notice = None;
        let ctrl = k.modifiers.contains(KeyModifiers::CONTROL);
        if ctrl && k.code == KeyCode::Char('c') {
            self.quit = true;
            return true;
        }
        // Ctrl or Alt with a key is not the key (Ctrl-Q is not q).
        if k.modifiers
            .intersects(KeyModifiers::CONTROL | KeyModifiers::ALT)
        {
            return false;
        }
        match k.code {
            // Esc closes what is open and never quits: a sequence split over a slow link
            // may begin with a stray one.
            KeyCode::Esc => {
                if self.help || self.show_plan {
                    self.help = false;
                    self.show_plan = false;
                } else {
                    self.inspect = false;
                }
            }
            KeyCode::Char('q') => {
                if self.help || self.show_plan {
                    self.help = false;
                    self.show_plan = false;
                } else {
                    self.quit = true;
                }
            }
            KeyCode::Char('?') => self.help = !self.help,
            KeyCode::Char('p') if self.scene.is_some() => self.show_plan = !self.show_plan,
            KeyCode::Char(' ') => self.paused = !self.paused,
            KeyCode::Char('i') => self.inspect = !self.inspect,
            KeyCode::Char('w') => self.settings.mode = Self::cycle(&Mode::ALL, self.settings.mode),
            KeyCode::Char('g') => {
                self.settings.glyphs = Self::cycle(&GlyphMode::ALL, self.settings.glyphs);
                self.sub = 0;
                self.line_focus = None;
            }
            KeyCode::Char('c') => {
                self.settings.colors = Self::cycle(&ColorMode::ALL, self.settings.colors)
            }
            KeyCode::Char('b') => self.settings.cull = !self.settings.cull,
            KeyCode::Char('+') | KeyCode::Char('=') => self.zoom(1.1),
            KeyCode::Char('-') => self.zoom(1.0 / 1.1),
            KeyCode::Tab => {
                let (sx, sy) = self.settings.glyphs.dims();
                self.sub = (self.sub + 1) % (sx * sy) as usize;
                self.line_focus = None;
            }
            KeyCode::Char(']') => self.step_line(1),
            KeyCode::Char('[') => self.step_line(-1),
            code => {
                let dir = match code {
                    KeyCode::Left | KeyCode::Char('h') => (-1, 0),
                    KeyCode::Right | KeyCode::Char('l') => (1, 0),
                    KeyCode::Up | KeyCode::Char('k') => (0, -1),
                    KeyCode::Down | KeyCode::Char('j') => (0, 1),
                    _ => return false,
                };
                if self.inspect {
                    self.move_cursor(dir.0, dir.1);
                } else {
                    self.settings.angle += dir.0 as f32 * 0.1;
                    self.settings.tilt += dir.1 as f32 * 0.1;
                }
            }
        }
        true
    }

    /// Where everything goes on a screen of `area`.
    #[must_use]
    pub fn areas(&self, area: Rect) -> Areas {
        let [main, status] =
            Layout::vertical([Constraint::Min(1), Constraint::Length(1)]).areas(area);
        let show_panel = self.inspect && main.width >= MIN_COLS + PANEL_COLS;
        let [view, panel] = if show_panel {
            Layout::horizontal([Constraint::Min(1), Constraint::Length(PANEL_COLS)]).areas(main)
        } else {
            [main, Rect::default()]
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
        let show_panel = panel != Rect::default();
        self.view_area = view;
        match &mut self.scene {
            Some(s) => self.viewport.render_scene(
                &s.scene,
                &mut s.frame,
                &self.settings,
                (view.width, view.height),
                s.time,
            ),
            None => self
                .viewport
                .render(&self.model, &self.settings, view.width, view.height),
        }
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
        }
        if show_panel {
            self.draw_panel(f, panel);
        }
        self.update_status();
        f.render_widget(Paragraph::new(Line::from(self.status.as_str())), status);
        if self.help {
            self.draw_help(f, main);
        } else if self.show_plan {
            self.draw_plan(f, main);
        }
    }

    fn draw_plan(&self, f: &mut Frame, area: Rect) {
        let Some(s) = &self.scene else { return };
        let text = s.scene.plan.to_string();
        let w = 76.min(area.width);
        let h = (text.lines().count() as u16 + 2).min(area.height);
        let r = Rect::new(area.x + (area.width - w) / 2, area.y, w, h);
        f.render_widget(Clear, r);
        f.render_widget(
            Paragraph::new(text).block(
                Block::default()
                    .borders(Borders::ALL)
                    .title(" plan (p closes) "),
            ),
            r,
        );
    }

    fn draw_panel(&self, f: &mut Frame, area: Rect) {
        let (cx, cy) = self.cursor;
        if let Some(s) = &self.scene {
            let text = scene_inspector_text(&self.viewport, s, cx, cy, self.sub);
            f.render_widget(
                Paragraph::new(text).wrap(Wrap { trim: false }).block(
                    Block::default()
                        .borders(Borders::ALL)
                        .title(" inspector (Tab: sample, p: plan) "),
                ),
                area,
            );
            return;
        }
        let text = inspector_text(&self.viewport, &self.model, cx, cy, self.sub);
        let (x, y) = sample_pixel(&self.viewport, cx, cy, self.sub);
        let line = match self.line_focus {
            Some((edge, k)) => project_edge(&self.viewport.frame.cache, edge, self.viewport.target)
                .map(|sl| (edge, sl, k)),
            None => line_at(&self.viewport, &self.model, x, y),
        };
        let line = line.map_or("no line here".to_string(), |(e, sl, k)| {
            line_text(e, &sl, k)
        });
        let line_rows = line
            .lines()
            .map(|l| l.chars().count() as u16 / (PANEL_COLS - 2) + 1)
            .sum::<u16>()
            + 2;
        let [top, bottom] =
            Layout::vertical([Constraint::Min(3), Constraint::Length(line_rows)]).areas(area);
        f.render_widget(
            Paragraph::new(text).wrap(Wrap { trim: false }).block(
                Block::default()
                    .borders(Borders::ALL)
                    .title(" inspector (Tab: sample) "),
            ),
            top,
        );
        f.render_widget(
            Paragraph::new(line).wrap(Wrap { trim: false }).block(
                Block::default()
                    .borders(Borders::ALL)
                    .title(" line ([ ] step) "),
            ),
            bottom,
        );
    }

    /// Rewrites the status line (into a buffer kept across frames): state, speed,
    /// time split, triangle counts, bytes written.
    pub fn update_status(&mut self) {
        let s = match &self.scene {
            Some(sc) => sc.frame.stats,
            None => self.viewport.frame.renderer.stats,
        };
        let [tf, rs] = self.viewport.frame.timing;
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let mode = match self.settings.mode {
            Mode::Fill => "fill",
            Mode::Wire => "wire",
            Mode::FillWire => "fill+wire",
        };
        // State first, so it stays visible when a narrow terminal cuts the line.
        self.status.clear();
        if let Some(n) = &self.notice {
            let _ = write!(self.status, "{n} | ");
        }
        let _ = write!(
            self.status,
            "{}{}{} {} {} | {:.0} fps | transform {:.1} raster+shade {:.1} glyphs {:.1} output {:.1} ms | tris {} drawn {} culled {} clipped | {} B",
            if self.paused { "paused | " } else { "" },
            if self.inspect { "inspect | " } else { "" },
            self.settings.glyphs.name(),
            self.settings.colors.name(),
            mode,
            self.fps,
            ms(tf),
            ms(rs),
            ms(self.viewport.glyph_time),
            ms(self.output_time),
            s.drawn,
            s.culled,
            s.clipped,
            self.bytes,
        );
        let l = self.link;
        let _ = write!(self.status, " | {:.0} kB/s", l.bytes_per_second / 1e3);
        match l.rtt {
            _ if l.unpaced => {
                let _ = write!(self.status, " unpaced (no answer)");
            }
            Some(rtt) => {
                let _ = write!(
                    self.status,
                    " rtt {:.0} ms {:.0} fps delivered",
                    ms(rtt),
                    l.delivered_fps
                );
            }
            None => {}
        }
        if let Some(b) = l.budget {
            let _ = write!(self.status, " {:.1} kB/frame", b as f64 / 1e3);
        }
        self.status.push_str(" | ? help");
        if let Some(sc) = &self.scene {
            let _ = write!(self.status, " | plan: {} (p)", sc.scene.plan.summary());
        }
    }

    fn draw_help(&self, f: &mut Frame, area: Rect) {
        let text = "space     pause / resume\n\
                    arrows    rotate (move the cursor in inspect mode); also h j k l\n\
                    + -       zoom (also the mouse wheel)\n\
                    w         fill / wireframe / fill + wireframe\n\
                    g         glyphs: ascii, half, quadrant, sextant, braille\n\
                    c         colours: truecolor, 256, 16, none\n\
                    b         back-face culling on / off\n\
                    i         inspect mode (click a cell to select it)\n\
                    Tab       next sub-sample of the cell\n\
                    [ ]       step along the line in the line panel\n\
                    drag      rotate\n\
                    p         the scene's plan (scenes only)\n\
                    ?         this help        Esc  close      q / Ctrl-C  quit";
        let w = 72.min(area.width);
        let h = 15.min(area.height);
        let r = Rect::new(
            area.x + (area.width - w) / 2,
            area.y + (area.height - h) / 2,
            w,
            h,
        );
        f.render_widget(Clear, r);
        f.render_widget(
            Paragraph::new(text).block(Block::default().borders(Borders::ALL).title(" keys ")),
            r,
        );
    }
}

//! Viewer state and input handling (drawing and layout: [`super::draw`]).

use std::time::{Duration, Instant};

use ratatui::crossterm::event::{
    Event, KeyCode, KeyEvent, KeyEventKind, KeyModifiers, MouseButton, MouseEventKind,
};
use ratatui::layout::{Position, Rect};

use super::inspector::{LineFocus, line_at_sample, project_focus};
use super::status::{FpsMeter, StatusLine};
use super::viewport::{SceneState, ViewSettings, Viewport};
use crate::render::wire::Mode;
use crate::scene::{Rig, Scene};
use crate::terminal::{ColorMode, GlyphMode};

/// Smallest usable terminal.
pub const MIN_COLS: u16 = 24;
pub const MIN_ROWS: u16 = 8;
/// The most cells the viewer uses: a larger terminal shows it in its top-left corner
/// of this size, so its buffers (which grow with the cells) stay bounded. Wider than a
/// 4K screen in an 8-pixel font.
pub const MAX_COLS: u16 = 512;
pub const MAX_ROWS: u16 = 256;

/// The part of a terminal of `cols` × `rows` cells the viewer uses (see [`MAX_COLS`]).
#[must_use]
pub fn used_size(cols: u16, rows: u16) -> (u16, u16) {
    (cols.min(MAX_COLS), rows.min(MAX_ROWS))
}

/// Width of the inspector panel beside the model.
pub const PANEL_COLS: u16 = 58;
/// Cells the cursor moves with Shift (or H J K L).
pub const CURSOR_JUMP: i32 = 8;

/// Rotation speed while spinning, radians per second.
const SPIN: f32 = 0.8;

/// The viewer.
#[derive(Debug)]
pub struct App {
    /// What is shown (a model is its default scene), with its buffers and clock.
    pub scene: SceneState,
    pub settings: ViewSettings,
    pub viewport: Viewport,
    pub paused: bool,
    /// Paused by entering inspect mode (so leaving it resumes).
    paused_by_inspect: bool,
    pub inspect: bool,
    pub help: bool,
    pub quit: bool,
    /// Selected cell and sub-sample.
    pub cursor: (u16, u16),
    pub sub: usize,
    /// Put the cursor on the model at the next frame (inspect mode was entered).
    place_cursor: bool,
    /// A line being stepped through.
    pub line_focus: Option<LineFocus>,
    /// First row of the inspector panel shown (PgUp / PgDn, the wheel over it).
    pub panel_scroll: usize,
    /// Frame rate of the frames drawn.
    pub fps: FpsMeter,
    pub output_time: Duration,
    pub bytes: u64,
    /// The status line of the last frame.
    pub status: StatusLine,
    /// Said once at the start of the status line, until the first key.
    pub notice: Option<String>,
    /// What the link to the terminal carries, for the status line.
    pub link: LinkStatus,
    /// A press of the left button: where, and whether it has dragged since.
    drag: Option<(u16, u16, bool)>,
    /// Where the model and the panel are on screen, from the last draw.
    pub(super) view_area: Rect,
    pub(super) panel_area: Rect,
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

impl App {
    /// A viewer for a scene. A model's default scene turns on its turntable, seen
    /// turned and tilted as `settings` say; a scene file runs its clock (its objects
    /// spin as it says) and is first seen from its own camera, which the arrows and
    /// the mouse then orbit.
    #[must_use]
    pub fn new(scene: Scene, settings: ViewSettings) -> Self {
        let mut settings = settings;
        if scene.rig == Rig::Orbit {
            settings.angle = 0.0;
            settings.tilt = 0.0;
        }
        Self {
            scene: SceneState::new(scene),
            settings,
            viewport: Viewport::default(),
            paused: false,
            paused_by_inspect: false,
            inspect: false,
            help: false,
            quit: false,
            cursor: (0, 0),
            sub: 0,
            place_cursor: false,
            line_focus: None,
            panel_scroll: 0,
            fps: FpsMeter::default(),
            output_time: Duration::ZERO,
            bytes: 0,
            status: StatusLine::default(),
            notice: None,
            link: LinkStatus::default(),
            drag: None,
            view_area: Rect::default(),
            panel_area: Rect::default(),
            show_plan: false,
        }
    }

    /// Advances the animation by `dt`: the turntable turns, a scene file's clock runs.
    pub fn tick(&mut self, dt: Duration) {
        if self.paused {
            return;
        }
        match self.scene.scene.rig {
            Rig::Turntable { .. } => {
                self.settings.angle =
                    (self.settings.angle + SPIN * dt.as_secs_f32()) % std::f32::consts::TAU;
            }
            Rig::Orbit => self.scene.time += dt.as_secs_f32(),
        }
    }

    /// A frame was drawn at `now` (for the frame rate).
    pub fn frame_drawn(&mut self, now: Instant) {
        if self.paused {
            self.fps.reset();
        } else {
            self.fps.frame(now);
        }
    }

    fn cycle<T: Copy + PartialEq>(all: &[T], v: T) -> T {
        let i = all.iter().position(|x| *x == v).unwrap_or(0);
        all[(i + 1) % all.len()]
    }

    fn set_paused(&mut self, paused: bool) {
        self.paused = paused;
        self.paused_by_inspect = false;
    }

    /// Enters or leaves inspect mode: entering freezes the model (the numbers stay
    /// still while read) and puts the cursor on it; leaving resumes what it froze.
    fn set_inspect(&mut self, on: bool) {
        if on == self.inspect {
            return;
        }
        self.inspect = on;
        self.panel_scroll = 0;
        if on {
            self.place_cursor = true;
            if !self.paused {
                self.paused = true;
                self.paused_by_inspect = true;
            }
        } else if self.paused_by_inspect {
            self.set_paused(false);
        }
    }

    /// Handles one input event; returns whether the picture may have changed.
    pub fn handle(&mut self, ev: &Event) -> bool {
        match ev {
            Event::Key(k) if k.kind != KeyEventKind::Release => self.key(*k),
            Event::Mouse(m) => {
                let at = Position::new(m.column, m.row);
                let (view, panel) = (self.view_area, self.panel_area);
                match m.kind {
                    MouseEventKind::Down(MouseButton::Left) => {
                        self.drag = Some((m.column, m.row, false));
                    }
                    MouseEventKind::Drag(MouseButton::Left) => {
                        // Dragging rotates; the selected cell stays.
                        if let Some((px, py, _)) = self.drag {
                            self.settings.angle += (f32::from(m.column) - f32::from(px)) * 0.05;
                            self.settings.tilt += (f32::from(m.row) - f32::from(py)) * 0.08;
                            self.drag = Some((m.column, m.row, true));
                        }
                    }
                    MouseEventKind::Up(_) => {
                        // A click (no drag) on the model selects a cell.
                        if let Some((_, _, false)) = self.drag.take()
                            && view.contains(at)
                        {
                            self.set_inspect(true);
                            self.place_cursor = false;
                            self.cursor = (m.column - view.x, m.row - view.y);
                            self.line_focus = None;
                            self.panel_scroll = 0;
                        }
                    }
                    MouseEventKind::ScrollUp if panel.contains(at) => self.scroll_panel(-3),
                    MouseEventKind::ScrollDown if panel.contains(at) => self.scroll_panel(3),
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

    fn scroll_panel(&mut self, by: i64) {
        self.panel_scroll = (self.panel_scroll as i64 + by).max(0) as usize;
    }

    fn move_cursor(&mut self, dx: i32, dy: i32) {
        let (w, h) = (self.viewport.cols.max(1), self.viewport.rows.max(1));
        let x = (i32::from(self.cursor.0) + dx).clamp(0, i32::from(w) - 1) as u16;
        let y = (i32::from(self.cursor.1) + dy).clamp(0, i32::from(h) - 1) as u16;
        self.cursor = (x, y);
        self.line_focus = None;
        self.panel_scroll = 0;
    }

    /// Puts the cursor on the model, if it is waiting to go there.
    pub(super) fn place_cursor_on_model(&mut self) {
        if std::mem::take(&mut self.place_cursor)
            && let Some(c) = self.viewport.central_covered_cell()
        {
            self.cursor = c;
            self.line_focus = None;
        }
    }

    /// The line panel's line: the one being stepped through, or the one under the
    /// selected sample.
    pub(super) fn focused_line(&self) -> Option<(LineFocus, crate::render::wire::ScreenLine)> {
        match self.line_focus {
            Some(f) => project_focus(&self.scene, f).map(|sl| (f, sl)),
            None => line_at_sample(
                &self.viewport,
                &self.scene,
                (self.cursor.0, self.cursor.1, self.sub),
            ),
        }
    }

    /// Steps along the inspected line; the cursor follows.
    fn step_line(&mut self, by: i64) {
        let Some((mut f, sl)) = self.focused_line() else {
            return;
        };
        f.k = (f.k + by).clamp(0, sl.line.dx);
        let (px, py) = sl.line.pixel(f.k, sl.line.minor_at(f.k));
        // The line is in the frame's (supersampled) grid.
        let side = i64::from(crate::raster::samples::grid_side(
            self.scene.scene.plan.samples,
        ));
        let (px, py) = (px.div_euclid(side), py.div_euclid(side));
        let (sx, sy) = self.settings.glyphs.dims();
        let (tw, th) = (
            i64::from(self.viewport.target.width),
            i64::from(self.viewport.target.height),
        );
        if (0..tw).contains(&px) && (0..th).contains(&py) {
            self.cursor = ((px / i64::from(sx)) as u16, (py / i64::from(sy)) as u16);
            self.sub = ((py % i64::from(sy)) * i64::from(sx) + px % i64::from(sx)) as usize;
        }
        self.line_focus = Some(f);
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
        let shift = k.modifiers.contains(KeyModifiers::SHIFT);
        match k.code {
            // Esc closes what is open and never quits: a sequence split over a slow link
            // may begin with a stray one.
            KeyCode::Esc => {
                if self.help || self.show_plan {
                    self.help = false;
                    self.show_plan = false;
                } else {
                    self.set_inspect(false);
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
            KeyCode::Char('p') if !self.scene.scene.is_model() => self.show_plan = !self.show_plan,
            KeyCode::Char('p') => {
                self.notice = Some("no scene plan: p shows the plan of a scene file".into());
            }
            KeyCode::Char(' ') => self.set_paused(!self.paused),
            KeyCode::Char('i') => self.set_inspect(!self.inspect),
            KeyCode::Char('w') => {
                let s = &mut self.scene.scene;
                s.set_mode(Self::cycle(&Mode::ALL, s.mode().unwrap_or(Mode::Fill)));
            }
            KeyCode::Char('g') => {
                self.settings.glyphs = Self::cycle(&GlyphMode::ALL, self.settings.glyphs);
                self.sub = 0;
                self.line_focus = None;
            }
            KeyCode::Char('c') => {
                self.settings.colors = Self::cycle(&ColorMode::ALL, self.settings.colors)
            }
            KeyCode::Char('b') => {
                let s = &mut self.scene.scene;
                s.set_cull(!s.cull().unwrap_or(false));
            }
            KeyCode::Char('+') | KeyCode::Char('=') => self.zoom(1.1),
            KeyCode::Char('-') => self.zoom(1.0 / 1.1),
            KeyCode::PageUp => self.scroll_panel(-10),
            KeyCode::PageDown => self.scroll_panel(10),
            KeyCode::Tab => {
                let (sx, sy) = self.settings.glyphs.dims();
                self.sub = (self.sub + 1) % (sx * sy) as usize;
                self.line_focus = None;
                self.panel_scroll = 0;
            }
            KeyCode::Char(']') => self.step_line(1),
            KeyCode::Char('[') => self.step_line(-1),
            code => {
                let (dir, jump) = match code {
                    KeyCode::Left | KeyCode::Char('h') => ((-1, 0), shift),
                    KeyCode::Right | KeyCode::Char('l') => ((1, 0), shift),
                    KeyCode::Up | KeyCode::Char('k') => ((0, -1), shift),
                    KeyCode::Down | KeyCode::Char('j') => ((0, 1), shift),
                    KeyCode::Char('H') => ((-1, 0), true),
                    KeyCode::Char('L') => ((1, 0), true),
                    KeyCode::Char('K') => ((0, -1), true),
                    KeyCode::Char('J') => ((0, 1), true),
                    _ => return false,
                };
                let by = if jump { CURSOR_JUMP } else { 1 };
                if self.inspect {
                    self.move_cursor(dir.0 * by, dir.1 * by);
                } else {
                    self.settings.angle += dir.0 as f32 * 0.1 * by as f32;
                    self.settings.tilt += dir.1 as f32 * 0.1 * by as f32;
                }
            }
        }
        true
    }
}

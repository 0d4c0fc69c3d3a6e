//! The interactive viewer: a spinning mesh on the cell grid, with a per-cell raster
//! inspector and a line panel.
//!
//! The terminal is restored (raw mode, alternate screen, mouse capture, cursor) on
//! quit, on panic (a chained panic hook) and on SIGINT, SIGTERM and SIGHUP (a flag the
//! loop checks). Each frame is written in one go inside a synchronized update, and
//! ratatui writes only the cells that changed. A paused viewer waits for input without
//! a timeout, so it uses no CPU.

pub mod app;
pub mod inspector;
pub mod viewport;

use std::cell::Cell;
use std::io::{self, IsTerminal, Stdout, Write};
use std::rc::Rc;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use ratatui::Terminal;
use ratatui::backend::CrosstermBackend;
use ratatui::crossterm::event::{self, DisableMouseCapture, EnableMouseCapture};
use ratatui::crossterm::terminal::{
    BeginSynchronizedUpdate, EndSynchronizedUpdate, EnterAlternateScreen, LeaveAlternateScreen,
    disable_raw_mode, enable_raw_mode,
};
use ratatui::crossterm::{cursor, execute, queue};

use app::App;

/// Counts the bytes written to the terminal into a shared counter.
#[derive(Debug)]
pub struct Counting<W> {
    pub inner: W,
    pub bytes: Rc<Cell<u64>>,
}

impl<W: Write> Write for Counting<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.bytes.set(self.bytes.get() + n as u64);
        Ok(n)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// Why the viewer could not run.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    #[error(
        "stdout is not a terminal; the viewer needs one. For pipes and scripts use \
         `termrast render [MODEL] --cols 80 --rows 24` (text frames) or \
         `termrast render [MODEL] --out frame.png`"
    )]
    NotATerminal,
    #[error("{0}")]
    Unsupported(String),
    #[error("terminal: {0}")]
    Io(#[from] io::Error),
}

fn restore() {
    let mut out = io::stdout();
    let _ = execute!(out, DisableMouseCapture, LeaveAlternateScreen, cursor::Show);
    let _ = disable_raw_mode();
}

/// Restores the terminal when dropped, whatever path leaves the viewer.
struct Guard;

impl Drop for Guard {
    fn drop(&mut self) {
        restore();
    }
}

/// Runs the viewer until the user quits or a signal arrives.
pub fn run(mut app: App, fps: u32) -> Result<(), ViewError> {
    if !io::stdout().is_terminal() {
        return Err(ViewError::NotATerminal);
    }
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [
        signal_hook::consts::SIGTERM,
        signal_hook::consts::SIGINT,
        signal_hook::consts::SIGHUP,
    ] {
        signal_hook::flag::register(sig, Arc::clone(&stop))?;
    }
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        restore();
        previous(info);
    }));
    enable_raw_mode()?;
    let _guard = Guard;
    execute!(
        io::stdout(),
        EnterAlternateScreen,
        EnableMouseCapture,
        cursor::Hide
    )?;
    let bytes = Rc::new(Cell::new(0));
    let writer = Counting {
        inner: io::stdout(),
        bytes: Rc::clone(&bytes),
    };
    let mut terminal = Terminal::new(CrosstermBackend::new(writer))?;
    terminal.clear()?;
    main_loop(&mut app, &mut terminal, fps.max(1), &stop, &bytes)
}

fn main_loop(
    app: &mut App,
    terminal: &mut Terminal<CrosstermBackend<Counting<Stdout>>>,
    fps: u32,
    stop: &AtomicBool,
    bytes: &Cell<u64>,
) -> Result<(), ViewError> {
    let period = Duration::from_secs_f64(1.0 / f64::from(fps));
    let mut last = Instant::now();
    let mut dirty = true;
    while !app.quit && !stop.load(Ordering::Relaxed) {
        let now = Instant::now();
        app.tick(now - last);
        if dirty || !app.paused {
            let frame_time = now - last;
            last = now;
            let start_bytes = bytes.get();
            queue!(terminal.backend_mut(), BeginSynchronizedUpdate)?;
            let t0 = Instant::now();
            let mut render_time = Duration::ZERO;
            terminal.draw(|f| {
                let r = Instant::now();
                app.draw(f);
                render_time = r.elapsed();
            })?;
            queue!(terminal.backend_mut(), EndSynchronizedUpdate)?;
            terminal.backend_mut().flush()?;
            app.output_time = t0.elapsed().saturating_sub(render_time);
            app.bytes = bytes.get() - start_bytes;
            if !app.paused && frame_time > Duration::ZERO {
                app.fps = 0.8 * app.fps + 0.2 / frame_time.as_secs_f32();
            }
            dirty = false;
        } else {
            last = now;
        }
        // Spinning: wait until the next frame is due. Paused: wait for input, waking
        // twice a second only to notice signals.
        let wait = if app.paused {
            Duration::from_millis(500)
        } else {
            period.saturating_sub(last.elapsed())
        };
        if event::poll(wait)? {
            loop {
                dirty |= app.handle(&event::read()?);
                if !event::poll(Duration::ZERO)? {
                    break;
                }
            }
        }
    }
    Ok(())
}

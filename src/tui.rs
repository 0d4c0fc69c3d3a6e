//! The interactive viewer: a spinning mesh on the cell grid, with a per-cell raster
//! inspector and a line panel.
//!
//! The viewer leaves with its terminal: end of input or an error reading or writing
//! the terminal ends it, and so do SIGHUP, SIGTERM, SIGINT and SIGQUIT (exit status
//! 128 + the signal; if the main thread is stuck writing to a stalled link, a
//! watchdog leaves half a second later). The terminal is restored on quit, on panic
//! (a chained panic hook) and on those signals; Ctrl-Z (or SIGTSTP) restores it and
//! suspends, and resuming re-enters the alternate screen and redraws everything.
//!
//! Input is read raw on its own thread and parsed by [`crate::terminal::input`];
//! signals arrive on another thread; both wake the loop through one channel, so a
//! paused viewer sleeps until something happens. Each frame is written in one go
//! inside a synchronized update, followed by a query the terminal answers once it has
//! read the frame: frames are paced by those answers ([`pacing`]).

pub mod app;
pub mod draw;
pub mod gate;
pub mod inspector;
pub mod link;
pub mod pacing;
pub mod panel;
pub mod remote;
pub mod status;
pub mod viewport;

use std::cell::Cell;
use std::io::{self, IsTerminal, Read, Stdout, Write};
use std::rc::Rc;
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use ratatui::Terminal;
use ratatui::crossterm::event::{
    DisableMouseCapture, EnableMouseCapture, Event, KeyCode, KeyEvent, KeyModifiers,
};
use ratatui::crossterm::terminal::{
    BeginSynchronizedUpdate, EndSynchronizedUpdate, EnterAlternateScreen, LeaveAlternateScreen,
    disable_raw_mode, enable_raw_mode,
};
use ratatui::crossterm::{cursor, execute, queue};

use app::{App, LinkStatus};
use pacing::Pacer;

use crate::terminal::input::{Input, Parser};

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
    #[error("the terminal went away (end of input)")]
    Gone,
    /// No key or mouse input for this long (a remote viewer's idle limit).
    #[error("idle for {0:?}")]
    Idle(Duration),
    /// Ended by a signal: the process exits with 128 + its number.
    #[error("ended by signal {0}")]
    Signal(i32),
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

/// How the viewer runs.
#[derive(Clone, Copy, Debug)]
pub struct RunOptions {
    /// Frame rate cap.
    pub fps: u32,
    /// Output rate cap, bytes per second.
    pub max_rate: Option<u64>,
    /// Pace frames by the terminal's answers.
    pub paced: bool,
    /// Ask the terminal for its 16 colours (OSC 4) and fit 16-colour frames to them.
    pub ask_palette: bool,
}

/// What wakes the loop.
#[derive(Debug)]
pub enum Wake {
    Bytes(Vec<u8>),
    /// End of input, or an error reading it: the terminal is gone.
    Eof,
    Signal(i32),
    /// A remote terminal's new size in cells (its own size is not ours to ask).
    Resize(u16, u16),
}

/// Signals that end the viewer.
const ENDING: [i32; 4] = [
    signal_hook::consts::SIGTERM,
    signal_hook::consts::SIGINT,
    signal_hook::consts::SIGHUP,
    signal_hook::consts::SIGQUIT,
];

/// Starts the input and signal threads.
fn spawn_wakers() -> io::Result<mpsc::Receiver<Wake>> {
    let (tx, rx) = mpsc::channel();
    let input = tx.clone();
    std::thread::Builder::new()
        .name("input".into())
        .spawn(move || {
            let mut buf = [0u8; 4096];
            // The terminal's input: stdin, or the controlling terminal when stdin is
            // redirected.
            let mut source: Box<dyn Read> = if io::stdin().is_terminal() {
                Box::new(io::stdin())
            } else {
                match std::fs::File::open("/dev/tty") {
                    Ok(f) => Box::new(f),
                    Err(_) => {
                        let _ = input.send(Wake::Eof);
                        return;
                    }
                }
            };
            loop {
                match source.read(&mut buf) {
                    Ok(0) | Err(_) => {
                        let _ = input.send(Wake::Eof);
                        return;
                    }
                    Ok(n) => {
                        if input.send(Wake::Bytes(buf[..n].to_vec())).is_err() {
                            return;
                        }
                    }
                }
            }
        })?;
    let mut signals = signal_hook::iterator::Signals::new(ENDING.iter().copied().chain([
        signal_hook::consts::SIGTSTP,
        signal_hook::consts::SIGCONT,
        signal_hook::consts::SIGWINCH,
    ]))?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            for sig in signals.forever() {
                let _ = tx.send(Wake::Signal(sig));
                if ENDING.contains(&sig) {
                    watchdog(sig);
                }
            }
        })?;
    Ok(rx)
}

/// How far the main thread has got in leaving, for the watchdog.
static LEAVING: AtomicU8 = AtomicU8::new(RUNNING);
const RUNNING: u8 = 0;
/// The main loop has returned; the terminal is being restored.
const RESTORING: u8 = 1;
/// The terminal is restored; the process is about to exit by itself.
const RESTORED: u8 = 2;

/// After an ending signal: the main thread leaves at once unless it is stuck writing
/// to a stalled terminal; then this leaves for it, without escape sequences (the
/// output is what is stuck). It ends the process with `_exit`, never `exit`: two
/// threads running the C library's exit handlers at once can deadlock.
fn watchdog(sig: i32) {
    let start = Instant::now();
    loop {
        std::thread::sleep(Duration::from_millis(50));
        let waited = start.elapsed();
        let state = LEAVING.load(Ordering::Acquire);
        // A main thread that is restoring gets longer: it is not stuck, only slow.
        let patience = if state == RESTORING { 2000 } else { 500 };
        if state == RESTORED {
            return;
        }
        if waited >= Duration::from_millis(patience) {
            let _ = disable_raw_mode();
            signal_hook::low_level::exit(128 + sig);
        }
    }
}

fn enter(out: &mut impl Write) -> io::Result<()> {
    enable_raw_mode()?;
    execute!(out, EnterAlternateScreen, EnableMouseCapture, cursor::Hide)
}

/// Runs the viewer until the user quits, the terminal goes away or a signal ends it.
pub fn run(mut app: App, options: RunOptions) -> Result<(), ViewError> {
    if !io::stdout().is_terminal() {
        return Err(ViewError::NotATerminal);
    }
    let wakes = spawn_wakers()?;
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        restore();
        previous(info);
    }));
    let guard = Guard;
    enter(&mut io::stdout())?;
    let bytes = Rc::new(Cell::new(0));
    let writer = Counting {
        inner: io::stdout(),
        bytes: Rc::clone(&bytes),
    };
    let mut terminal = Terminal::new(link::LinkBackend::new(writer))?;
    terminal.clear()?;
    if options.ask_palette {
        // Answers come back as input, before the answer to the first frame's query.
        terminal
            .backend_mut()
            .write_all(&crate::terminal::palette::query())?;
    }
    app.fps.cap = options.fps.max(1) as f32;
    let mut pacer = Pacer::new(options.paced, options.max_rate);
    let mut parser = Parser::default();
    let result = main_loop(
        &mut app,
        &mut terminal,
        options.fps.max(1),
        Ctx {
            wakes: &wakes,
            parser: &mut parser,
            pacer: &mut pacer,
            bytes: &bytes,
            local: true,
            gate: None,
            idle: None,
        },
    );
    LEAVING.store(RESTORING, Ordering::Release);
    // Leaving anyway: whatever arrives meanwhile changes nothing.
    let _ = settle(&wakes, &mut parser, &mut pacer);
    drop(terminal);
    drop(guard);
    LEAVING.store(RESTORED, Ordering::Release);
    result
}

/// Before the terminal leaves raw mode, waits a little for the answers to queries
/// still on their way, so they reach the viewer and not the shell after it. Returns
/// what ends the viewer if it arrives meanwhile (an ending signal, end of input).
fn settle(
    wakes: &mpsc::Receiver<Wake>,
    parser: &mut Parser,
    pacer: &mut Pacer,
) -> Option<ViewError> {
    let until = Instant::now() + Duration::from_millis(300);
    while pacer.in_flight() > 0 {
        let left = until.checked_duration_since(Instant::now())?;
        match wakes.recv_timeout(left) {
            Ok(Wake::Bytes(b)) => {
                let now = Instant::now();
                parser.feed(&b, now);
                while let Some(input) = parser.next(now) {
                    if input == Input::DeviceAttributes {
                        pacer.answered(now);
                    }
                }
                // Palette answers and keys arriving now change nothing: leaving.
            }
            Ok(Wake::Signal(sig)) if ENDING.contains(&sig) => {
                return Some(ViewError::Signal(sig));
            }
            Ok(Wake::Signal(_) | Wake::Resize(..)) => {}
            Ok(Wake::Eof) | Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Some(ViewError::Gone);
            }
            Err(mpsc::RecvTimeoutError::Timeout) => return None,
        }
    }
    None
}

type Term<W = Stdout> = Terminal<link::LinkBackend<Counting<W>>>;

/// What the frame loop reads and counts, apart from the terminal it draws on.
struct Ctx<'a> {
    wakes: &'a mpsc::Receiver<Wake>,
    parser: &'a mut Parser,
    pacer: &'a mut Pacer,
    bytes: &'a Cell<u64>,
    /// The process's own terminal: Ctrl-Z and job-control signals suspend and resume
    /// it. A remote terminal has no job control here.
    local: bool,
    /// Shared by the viewers of one process, so their frames share the CPU by time.
    gate: Option<gate::Seat<'a>>,
    /// Leave after this long without a key or mouse event.
    idle: Option<Duration>,
}

/// Draws one frame and the pacing query after it.
fn draw<W: Write>(
    app: &mut App,
    terminal: &mut Term<W>,
    pacer: &mut Pacer,
    bytes: &Cell<u64>,
    gate: Option<gate::Seat<'_>>,
) -> io::Result<()> {
    let start_bytes = bytes.get();
    let size = terminal.size()?;
    let backend = terminal.backend_mut();
    backend.bulk = app.model_area(ratatui::layout::Rect::new(0, 0, size.width, size.height));
    backend.budget = pacer.budget(Instant::now());
    queue!(terminal.backend_mut(), BeginSynchronizedUpdate)?;
    let t0 = Instant::now();
    let mut render_time = Duration::ZERO;
    terminal.draw(|f| {
        let _turn = gate.map(gate::Seat::enter);
        let r = Instant::now();
        app.draw(f);
        render_time = r.elapsed();
    })?;
    queue!(terminal.backend_mut(), EndSynchronizedUpdate)?;
    if pacer.wants_query() {
        terminal.backend_mut().write_all(pacing::QUERY)?;
    }
    terminal.backend_mut().flush()?;
    app.output_time = t0.elapsed().saturating_sub(render_time);
    app.bytes = bytes.get() - start_bytes;
    pacer.sent(Instant::now(), app.bytes);
    Ok(())
}

/// Ctrl-Z: restores the terminal, stops, and on resuming takes it again. Answers to
/// queries still on their way are waited for first, so they reach the viewer and not
/// the shell that takes the terminal over.
fn suspend<W: Write>(
    terminal: &mut Term<W>,
    (wakes, parser): (&mpsc::Receiver<Wake>, &mut Parser),
    pacer: &mut Pacer,
) -> Result<(), ViewError> {
    if let Some(end) = settle(wakes, parser, pacer) {
        return Err(end);
    }
    restore();
    signal_hook::low_level::raise(signal_hook::consts::SIGSTOP)?;
    Ok(resume(terminal, pacer)?)
}

fn resume<W: Write>(terminal: &mut Term<W>, pacer: &mut Pacer) -> io::Result<()> {
    enter(terminal.backend_mut())?;
    pacer.reset();
    terminal.clear()
}

fn main_loop<W: Write>(
    app: &mut App,
    terminal: &mut Term<W>,
    fps: u32,
    ctx: Ctx<'_>,
) -> Result<(), ViewError> {
    let Ctx {
        wakes,
        parser,
        pacer,
        bytes,
        local,
        gate,
        idle,
    } = ctx;
    let period = Duration::from_secs_f64(1.0 / f64::from(fps));
    let mut last = Instant::now();
    let mut last_input = last;
    let mut next_frame = last;
    let mut dirty = true;
    // Resumed from our own suspension, before its SIGCONT arrived.
    let mut resumed = false;
    let ctrl_z = Event::Key(KeyEvent::new(KeyCode::Char('z'), KeyModifiers::CONTROL));
    while !app.quit {
        let now = Instant::now();
        let wanted = dirty || !app.paused;
        if wanted && now >= next_frame && pacer.may_send(now) {
            app.tick(now - last);
            last = now;
            app.link = LinkStatus {
                bytes_per_second: pacer.bytes_per_second(now),
                rtt: pacer.rtt,
                delivered_fps: pacer.delivered_fps(now),
                unpaced: pacer.unpaced && pacer.wants_query(),
                budget: pacer.budget(now),
            };
            draw(app, terminal, pacer, bytes, gate)?;
            app.frame_drawn(now);
            next_frame = now + period;
            dirty = false;
        } else {
            if !app.paused {
                app.tick(now - last);
            }
            last = now;
        }
        // Input is read between any two frames: a frame that takes longer than the
        // period (a huge model, a busy machine) must not keep the keys from the viewer.
        let now = Instant::now();
        // Sleep until the next frame is due (or what holds it, the pacer, may let it
        // go), a pending escape resolves, or input or a signal arrives.
        let idle_at = idle.map(|d| last_input + d);
        if idle_at.is_some_and(|t| now >= t) {
            return Err(ViewError::Idle(idle.unwrap_or_default()));
        }
        let wake_at = [
            wanted.then(|| next_frame.max(pacer.wake_at().unwrap_or(next_frame))),
            parser.deadline(),
            idle_at,
        ]
        .into_iter()
        .flatten()
        .min();
        let timeout = wake_at.map_or(Duration::from_secs(3600), |t| {
            t.saturating_duration_since(now)
        });
        let wake = match wakes.recv_timeout(timeout) {
            Ok(w) => Some(w),
            Err(mpsc::RecvTimeoutError::Timeout) => None,
            Err(mpsc::RecvTimeoutError::Disconnected) => Some(Wake::Eof),
        };
        match wake {
            Some(Wake::Bytes(b)) => parser.feed(&b, Instant::now()),
            Some(Wake::Eof) => return Err(ViewError::Gone),
            Some(Wake::Signal(sig)) if ENDING.contains(&sig) => {
                return Err(ViewError::Signal(sig));
            }
            Some(Wake::Resize(cols, rows)) => {
                terminal.backend_mut().set_size(cols, rows);
                dirty = true;
            }
            Some(Wake::Signal(_)) if !local => {}
            Some(Wake::Signal(signal_hook::consts::SIGTSTP)) => {
                suspend(terminal, (wakes, parser), pacer)?;
                resumed = true;
                dirty = true;
            }
            // The continue that ends our own suspension: already resumed.
            Some(Wake::Signal(signal_hook::consts::SIGCONT)) if resumed => resumed = false,
            Some(Wake::Signal(signal_hook::consts::SIGCONT)) => {
                resume(terminal, pacer)?;
                dirty = true;
            }
            Some(Wake::Signal(signal_hook::consts::SIGWINCH)) => {
                // Past the viewer's limit a resize leaves the size it draws at alone,
                // so ratatui would not repaint; a terminal that cleared or reflowed on
                // the resize would keep what it made of the screen.
                // A size the terminal cannot tell is left to the next draw to report.
                let past = ratatui::crossterm::terminal::size()
                    .is_ok_and(|(w, h)| app::used_size(w, h) != (w, h));
                if past {
                    terminal.clear()?;
                }
                dirty = true;
            }
            Some(Wake::Signal(_)) => dirty = true,
            None => {}
        }
        let now = Instant::now();
        while let Some(input) = parser.next(now) {
            match input {
                Input::DeviceAttributes => pacer.answered(now),
                Input::PaletteColor(i, c) => dirty |= app.settings.terminal_color(i, c),
                Input::Event(e) if local && e == ctrl_z => {
                    suspend(terminal, (wakes, parser), pacer)?;
                    resumed = true;
                    dirty = true;
                }
                Input::Event(e) => {
                    last_input = now;
                    dirty |= app.handle(&e);
                }
            }
        }
    }
    Ok(())
}

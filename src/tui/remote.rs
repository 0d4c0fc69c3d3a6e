//! The viewer on a terminal that is not the process's own: frames go to any writer
//! and input, window changes and the end arrive on a channel (an SSH session's
//! channel, say). The frame loop, pacing and cell cache are the local viewer's; what
//! differs is that nothing here touches the process's terminal, signals or job
//! control, and that viewers sharing a process take turns rendering
//! ([`RenderGate`]).

use std::cell::Cell;
use std::io::{self, Write};
use std::rc::Rc;
use std::sync::mpsc;
use std::sync::{Condvar, Mutex};
use std::time::Duration;

use ratatui::Terminal;
use ratatui::crossterm::event::{DisableMouseCapture, EnableMouseCapture};
use ratatui::crossterm::terminal::{EnterAlternateScreen, LeaveAlternateScreen};
use ratatui::crossterm::{cursor, execute};

use super::app::App;
use super::pacing::Pacer;
use super::{Counting, Ctx, RunOptions, ViewError, Wake, link, main_loop, settle};
use crate::terminal::input::Parser;

/// At most `n` frames render at once, admitted in the order they asked: with many
/// viewers in one process each gets an equal share of frames when the CPU is short,
/// and none can starve the others by asking more often.
#[derive(Debug)]
pub struct RenderGate {
    /// Next ticket to hand out, and tickets below which may render.
    state: Mutex<(u64, u64)>,
    turn: Condvar,
}

/// A frame's turn at the CPU; the next waiting frame goes when it is dropped.
#[derive(Debug)]
pub struct Turn<'a>(&'a RenderGate);

impl RenderGate {
    /// A gate letting `n` frames render at once (at least one).
    #[must_use]
    pub fn new(n: usize) -> Self {
        Self {
            state: Mutex::new((0, n.max(1) as u64)),
            turn: Condvar::new(),
        }
    }

    /// Waits for this frame's turn.
    pub fn enter(&self) -> Turn<'_> {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        let ticket = s.0;
        s.0 += 1;
        while ticket >= s.1 {
            s = self.turn.wait(s).unwrap_or_else(|e| e.into_inner());
        }
        Turn(self)
    }
}

impl Drop for Turn<'_> {
    fn drop(&mut self) {
        let mut s = self.0.state.lock().unwrap_or_else(|e| e.into_inner());
        s.1 += 1;
        drop(s);
        self.0.turn.notify_all();
    }
}

/// A terminal at the far end of a channel.
#[derive(Debug)]
pub struct Remote<'a, W> {
    /// Where frames go.
    pub out: W,
    /// Its size in cells, until a [`Wake::Resize`] says otherwise.
    pub cols: u16,
    pub rows: u16,
    /// Input bytes, window changes, the end of input and ending signals.
    pub wakes: mpsc::Receiver<Wake>,
    /// Shared with the other viewers of this process.
    pub gate: Option<&'a RenderGate>,
    /// Leave after this long without a key or mouse event.
    pub idle: Option<Duration>,
}

/// Runs the viewer on a remote terminal until its user quits, its input ends, an
/// ending signal arrives on its channel or it is idle too long. The screen is left
/// as found (main screen, cursor shown, mouse reporting off) unless writing failed.
/// Returns why it ended and the bytes written.
pub fn run<W: Write>(
    mut app: App,
    options: RunOptions,
    remote: Remote<'_, W>,
) -> (Result<(), ViewError>, u64) {
    let bytes = Rc::new(Cell::new(0));
    let result = run_counted(&mut app, options, remote, &bytes);
    (result, bytes.get())
}

fn run_counted<W: Write>(
    app: &mut App,
    options: RunOptions,
    remote: Remote<'_, W>,
    bytes: &Rc<Cell<u64>>,
) -> Result<(), ViewError> {
    let mut writer = Counting {
        inner: remote.out,
        bytes: Rc::clone(bytes),
    };
    execute!(
        writer,
        EnterAlternateScreen,
        EnableMouseCapture,
        cursor::Hide
    )?;
    let backend = link::LinkBackend::with_size(writer, remote.cols.max(1), remote.rows.max(1));
    let mut terminal = Terminal::new(backend)?;
    terminal.clear()?;
    if options.ask_palette {
        terminal
            .backend_mut()
            .write_all(&crate::terminal::palette::query())?;
    }
    app.fps.cap = options.fps.max(1) as f32;
    let mut pacer = Pacer::new(options.paced, options.max_rate);
    let mut parser = Parser::default();
    let result = main_loop(
        app,
        &mut terminal,
        options.fps.max(1),
        Ctx {
            wakes: &remote.wakes,
            parser: &mut parser,
            pacer: &mut pacer,
            bytes,
            local: false,
            gate: remote.gate,
            idle: remote.idle,
        },
    );
    // A terminal that cannot be written to cannot be restored either.
    if matches!(result, Err(ViewError::Io(_))) {
        return result;
    }
    let _ = settle(&remote.wakes, &mut parser, &mut pacer);
    let restored: io::Result<()> = execute!(
        terminal.backend_mut(),
        DisableMouseCapture,
        LeaveAlternateScreen,
        cursor::Show
    );
    result.and(restored.map_err(ViewError::from))
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicUsize, Ordering};

    use super::*;

    /// No more than `n` turns at once, however many threads ask.
    #[test]
    fn the_gate_admits_n_at_once() {
        let gate = Arc::new(RenderGate::new(2));
        let (inside, most) = (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)));
        let threads: Vec<_> = (0..6)
            .map(|_| {
                let (gate, inside, most) = (gate.clone(), inside.clone(), most.clone());
                std::thread::spawn(move || {
                    for _ in 0..50 {
                        let _t = gate.enter();
                        let k = inside.fetch_add(1, Ordering::SeqCst) + 1;
                        most.fetch_max(k, Ordering::SeqCst);
                        std::thread::yield_now();
                        inside.fetch_sub(1, Ordering::SeqCst);
                    }
                })
            })
            .collect();
        for t in threads {
            t.join().expect("no panic");
        }
        assert!(most.load(Ordering::SeqCst) <= 2);
    }
}

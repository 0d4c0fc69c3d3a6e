//! The viewer on a terminal that is not the process's own: frames go to any writer
//! and input, window changes and the end arrive on a channel (an SSH session's
//! channel, say). The frame loop, pacing and cell cache are the local viewer's; what
//! differs is that nothing here touches the process's terminal, signals or job
//! control, and that viewers sharing a process take turns rendering
//! ([`RenderGate`], each viewer with its own [`Account`]).

use std::cell::Cell;
use std::io::{self, Write};
use std::rc::Rc;
use std::sync::mpsc;
use std::time::Duration;

use ratatui::Terminal;
use ratatui::crossterm::event::{DisableMouseCapture, EnableMouseCapture};
use ratatui::crossterm::terminal::{EnterAlternateScreen, LeaveAlternateScreen};
use ratatui::crossterm::{cursor, execute};

use super::app::App;
pub use super::gate::RenderGate;
use super::gate::{Account, Seat};
use super::pacing::Pacer;
use super::{Counting, Ctx, RunOptions, ViewError, Wake, link, main_loop, settle};
use crate::terminal::input::Parser;

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
    let account = Account::default();
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
            gate: remote.gate.map(|gate| Seat {
                gate,
                account: &account,
            }),
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

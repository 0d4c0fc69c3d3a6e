//! One watcher: the viewer on its own thread, fed by its SSH channel.
//!
//! The viewer's frame loop is blocking code (it sleeps on its input channel and
//! writes whole frames), so each watcher runs it on a thread of its own, which
//! sleeps between frames; the frames themselves take turns at the CPU through the
//! server's [`RenderGate`] (as many at once as there are cores, first come first
//! served), and fit their cells on the shared rayon pool.
//!
//! Output is bounded end to end: the viewer sends at most two frames ahead of its
//! terminal's answers ([`crate::tui::pacing`]); each frame is handed to an async task
//! through a one-frame queue, and that task writes it within the client's SSH
//! window. A client that stops reading therefore stalls only its own viewer, which
//! holds at most a frame or two, and is dropped after [`Shared::stall`]. Input is bounded
//! the same way: at most [`INPUT_QUEUE`] reads wait for the viewer, and the rest of
//! a flood is dropped.

use std::io::{self, Write};
use std::sync::Arc;
use std::sync::mpsc::{self, SyncSender, TrySendError};
use std::time::Duration;

use russh::server::{Handle, Msg};
use russh::{ChannelId, ChannelWriteHalf};
use tokio::io::AsyncWriteExt;
use tokio::sync::oneshot;

use crate::cli::view_cmd::{LookArgs, PaletteArg};
use crate::scene::Scene;
use crate::terminal::glyphs::FitSpace;
use crate::terminal::locale;
use crate::tui::app::App;
use crate::tui::remote::{self, RenderGate};
use crate::tui::{RunOptions, ViewError, Wake};

/// Reads of input that may wait for the viewer; a flood beyond is dropped.
pub const INPUT_QUEUE: usize = 32;
/// The largest terminal served, in cells: a bigger one is drawn in this much of it
/// (each watcher's frame buffers grow with its size).
pub const MAX_COLS: u16 = 400;
pub const MAX_ROWS: u16 = 200;
/// Environment variables taken from a client (they only choose glyphs and colours).
pub const ENV_KEPT: [&str; 6] = [
    "COLORTERM",
    "LANG",
    "LC_ALL",
    "LC_CTYPE",
    "NO_COLOR",
    "TERM_PROGRAM",
];

/// What every watcher shares.
#[derive(Debug)]
pub struct Shared {
    pub scene: Arc<Scene>,
    pub gate: Arc<RenderGate>,
    pub fps: u32,
    pub idle: Option<Duration>,
    /// How long a frame may wait for the client to take it before the session is
    /// closed.
    pub stall: Duration,
}

/// What a client asked for its session before the shell.
#[derive(Clone, Debug, Default)]
pub struct Request {
    /// TERM and the size in cells, from the pty request.
    pub pty: Option<(String, u16, u16)>,
    /// Variables of [`ENV_KEPT`] it sent.
    pub env: Vec<(String, String)>,
}

impl Request {
    /// The client's environment as the viewer's detection reads it. A client that
    /// sends no locale is taken to use UTF-8, as practically every terminal does
    /// (OpenSSH sends `LANG` only when configured to).
    #[must_use]
    pub fn var(&self, k: &str) -> Option<String> {
        if k == "TERM" {
            return self.pty.as_ref().map(|p| p.0.clone());
        }
        let found = self
            .env
            .iter()
            .find(|(n, _)| n == k)
            .map(|(_, v)| v.clone());
        let has_locale = self
            .env
            .iter()
            .any(|(n, v)| matches!(n.as_str(), "LANG" | "LC_ALL" | "LC_CTYPE") && !v.is_empty());
        match k {
            "LANG" if !has_locale => Some("C.UTF-8".into()),
            _ => found,
        }
    }

    /// Takes an environment request; returns whether it was kept.
    pub fn set_env(&mut self, name: &str, value: &str) -> bool {
        let keep = ENV_KEPT.contains(&name) && value.len() <= 256 && self.env.len() < 16;
        if keep {
            self.env.retain(|(n, _)| n != name);
            self.env.push((name.to_string(), value.to_string()));
        }
        keep
    }
}

/// The size a client asked for, within what is served.
#[must_use]
pub fn clamp_size(cols: u32, rows: u32) -> (u16, u16) {
    let c = cols.clamp(1, u32::from(MAX_COLS)) as u16;
    let r = rows.clamp(1, u32::from(MAX_ROWS)) as u16;
    (c, r)
}

/// Why a watcher's session ended (for the log and the farewell line).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum End {
    /// The watcher pressed `q` (or Ctrl-C).
    Quit,
    /// The client closed the channel or went away.
    Gone,
    Idle(Duration),
    /// The server is stopping.
    Shutdown,
    /// The client took no output for this long.
    Stalled(Duration),
    /// Its terminal cannot show the viewer.
    Unsupported(String),
    Error(String),
}

impl std::fmt::Display for End {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            End::Quit => write!(f, "quit"),
            End::Gone => write!(f, "client closed"),
            End::Idle(d) => write!(f, "idle {}s", d.as_secs()),
            End::Shutdown => write!(f, "server stopping"),
            End::Stalled(d) => write!(f, "stalled (read nothing for {}s)", d.as_secs()),
            End::Unsupported(w) => write!(f, "unsupported terminal: {w}"),
            End::Error(e) => write!(f, "error: {e}"),
        }
    }
}

impl End {
    /// What the watcher is told after the viewer leaves, if anything.
    #[must_use]
    pub fn farewell(&self) -> Option<String> {
        match self {
            End::Quit | End::Gone | End::Stalled(_) | End::Error(_) => None,
            End::Idle(d) => Some(format!(
                "termrast: closed after {} s without a key",
                d.as_secs()
            )),
            End::Shutdown => Some("termrast: the server is shutting down".into()),
            End::Unsupported(w) => Some(format!("termrast: {w}")),
        }
    }
}

/// A running watcher, as its connection sees it.
#[derive(Debug)]
pub struct Watcher {
    wakes: SyncSender<Wake>,
    /// Input reads dropped because the viewer was behind.
    pub dropped: u64,
}

impl Watcher {
    /// The client's keyboard and mouse bytes, and its answers to queries.
    pub fn input(&mut self, data: &[u8]) {
        if let Err(TrySendError::Full(_)) = self.wakes.try_send(Wake::Bytes(data.to_vec())) {
            self.dropped += 1;
        }
    }

    /// Something the viewer must get, however far behind it is: waits for room off
    /// the async threads.
    pub fn tell(&self, w: Wake) {
        let tx = self.wakes.clone();
        if let Err(TrySendError::Full(w)) = tx.try_send(w)
            && let Ok(rt) = tokio::runtime::Handle::try_current()
        {
            rt.spawn_blocking(move || tx.send(w));
        }
    }

    /// A handle to end the watcher from elsewhere (server shutdown).
    #[must_use]
    pub fn sender(&self) -> SyncSender<Wake> {
        self.wakes.clone()
    }
}

/// Frames to the channel's writer task; blocks while the client is a frame behind.
struct ChannelOut(tokio::sync::mpsc::Sender<Vec<u8>>);

impl Write for ChannelOut {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0
            .blocking_send(buf.to_vec())
            .map_err(|_| io::Error::new(io::ErrorKind::BrokenPipe, "the client is gone"))?;
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// What a finished watcher reports: why it ended and the bytes its viewer wrote.
pub type Outcome = (End, u64);

/// Starts the viewer for a session with a pty; `done` gets the outcome once the
/// channel is closed.
pub fn start(
    shared: &Arc<Shared>,
    req: &Request,
    write: ChannelWriteHalf<Msg>,
    handle: Handle,
    id: ChannelId,
    done: oneshot::Sender<Outcome>,
    kill: oneshot::Sender<()>,
) -> io::Result<Watcher> {
    let (wake_tx, wake_rx) = mpsc::sync_channel(INPUT_QUEUE);
    let (out_tx, mut out_rx) = tokio::sync::mpsc::channel::<Vec<u8>>(1);
    let (cols, rows) = req.pty.as_ref().map_or((80, 24), |p| (p.1, p.2));
    let env = |k: &str| req.var(k);
    let unsupported = locale::no_full_screen(env("TERM").as_deref());
    let look = LookArgs {
        glyphs: None,
        color: None,
        fit_space: FitSpace::Srgb,
        palette: PaletteArg::Auto,
        cell_aspect: 0.5,
    };
    let settings = look.settings_in(env);
    let notice = look.notice_in(env);
    let (view_tx, view_rx) = oneshot::channel::<Outcome>();
    let shared2 = Arc::clone(shared);
    std::thread::Builder::new()
        .name("watcher".into())
        .spawn(move || {
            let outcome = match unsupported {
                Some(why) => (End::Unsupported(why), 0),
                None => {
                    let mut app = App::new((*shared2.scene).clone(), settings);
                    app.notice = notice;
                    let options = RunOptions {
                        fps: shared2.fps,
                        max_rate: None,
                        paced: true,
                        ask_palette: true,
                    };
                    let out = remote::Remote {
                        out: ChannelOut(out_tx),
                        cols,
                        rows,
                        wakes: wake_rx,
                        gate: Some(&shared2.gate),
                        idle: shared2.idle,
                    };
                    let (r, bytes) = remote::run(app, options, out);
                    (end_of(r), bytes)
                }
            };
            let _ = view_tx.send(outcome);
        })?;
    let stall = shared.stall;
    tokio::spawn(async move {
        // Frames to the client, within its window; a frame it leaves waiting for
        // `stall` ends the session.
        let mut w = write.make_writer();
        let mut stalled = false;
        while let Some(buf) = out_rx.recv().await {
            match tokio::time::timeout(stall, w.write_all(&buf)).await {
                Ok(Ok(())) => {}
                Ok(Err(_)) => break,
                Err(_) => {
                    stalled = true;
                    break;
                }
            }
        }
        // Unblocks the viewer if it is still writing.
        drop(out_rx);
        let (end, bytes) = view_rx
            .await
            .unwrap_or((End::Error("the viewer panicked".into()), 0));
        if stalled {
            // Nothing more reaches a client that takes nothing, and the connection's
            // queue to it is full: it is closed outright.
            let _ = done.send((End::Stalled(stall), bytes));
            let _ = kill.send(());
            return;
        }
        if let Some(text) = end.farewell() {
            let _ = handle.data(id, format!("{text}\r\n").into_bytes()).await;
        }
        let code = if matches!(end, End::Quit | End::Shutdown) {
            0
        } else {
            1
        };
        let _ = handle.exit_status_request(id, code).await;
        let _ = handle.eof(id).await;
        let _ = handle.close(id).await;
        let _ = done.send((end, bytes));
    });
    Ok(Watcher {
        wakes: wake_tx,
        dropped: 0,
    })
}

fn end_of(r: Result<(), ViewError>) -> End {
    match r {
        Ok(()) => End::Quit,
        Err(ViewError::Gone) => End::Gone,
        Err(ViewError::Idle(d)) => End::Idle(d),
        Err(ViewError::Signal(_)) => End::Shutdown,
        Err(ViewError::Io(e)) if e.kind() == io::ErrorKind::BrokenPipe => End::Gone,
        Err(e) => End::Error(e.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_client_environment_chooses_glyphs_and_colours_only() {
        let mut r = Request {
            pty: Some(("xterm-256color".into(), 80, 24)),
            env: Vec::new(),
        };
        assert_eq!(r.var("TERM").as_deref(), Some("xterm-256color"));
        // No locale sent: UTF-8 assumed.
        assert_eq!(r.var("LANG").as_deref(), Some("C.UTF-8"));
        assert!(r.set_env("COLORTERM", "truecolor"));
        assert!(!r.set_env("LD_PRELOAD", "/tmp/x.so"));
        assert!(!r.set_env("PATH", "/tmp"));
        assert!(!r.set_env("LANG", &"x".repeat(300)));
        assert!(r.set_env("LC_ALL", "C"));
        assert_eq!(r.var("LANG"), None);
        assert_eq!(r.var("COLORTERM").as_deref(), Some("truecolor"));
        assert_eq!(clamp_size(0, 100_000), (1, MAX_ROWS));
        assert_eq!(clamp_size(80, 24), (80, 24));
    }
}

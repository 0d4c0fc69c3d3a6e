//! A slow link to test the viewer against: the viewer in a pseudo-terminal whose
//! output is drained at a set rate through a buffer the size of an SSH channel's
//! window into a terminal emulator (`vt100`) that answers the viewer's device
//! attribute queries when it reaches them, as a terminal at the far end would.
//! Keys are pressed and the time until the emulated screen shows their effect is
//! measured (Linux only: it needs `openpty`).
//!
//! The key is `b` (back-face culling on, then off): its effect is `cull` turning to
//! `no cull` in the status line and back, while the model keeps spinning, so every
//! frame in the link's buffers stands between the key and its effect.

use std::path::PathBuf;
use std::time::{Duration, Instant};

/// What to run and how slow the link is.
#[derive(Clone, Debug)]
pub struct Config {
    /// The termrast binary.
    pub exe: PathBuf,
    /// Arguments after `view`: the model and options.
    pub args: Vec<String>,
    /// Link rate, bytes per second.
    pub rate: u64,
    /// Bytes the link may hold (OpenSSH's channel window: 2 MB).
    pub buffer: usize,
    pub cols: u16,
    pub rows: u16,
    /// Key presses to time.
    pub presses: usize,
    /// Longest wait for one key's effect.
    pub timeout: Duration,
    /// The 16 colours the emulated terminal reports to OSC 4 queries (`None`: it
    /// ignores them, as tmux and many terminals do).
    pub palette: Option<[[u8; 3]; 16]>,
}

impl Config {
    /// A link of `rate` bytes per second with a 2 MB buffer, 200×61 cells.
    #[must_use]
    pub fn new(exe: PathBuf, model: &str, rate: u64) -> Self {
        Self {
            exe,
            args: vec![model.to_string()],
            rate,
            buffer: 2 << 20,
            cols: 200,
            rows: 61,
            presses: 8,
            timeout: Duration::from_secs(20),
            palette: None,
        }
    }
}

/// What the run measured.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// Key-to-screen time of each press (`None`: not seen within the timeout).
    pub latencies: Vec<Option<Duration>>,
    /// Frames the emulator reached per second (queries answered).
    pub delivered_fps: f64,
    /// Bytes per second that crossed the link.
    pub bytes_per_second: f64,
    /// Most bytes waiting in the link's buffer at once.
    pub max_buffered: usize,
}

impl Report {
    /// The median of the seen latencies.
    #[must_use]
    pub fn median(&self) -> Option<Duration> {
        let mut v: Vec<Duration> = self.latencies.iter().flatten().copied().collect();
        v.sort();
        v.get(v.len() / 2).copied()
    }
}

/// Why a run could not be made.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    #[error("the link harness needs Linux (openpty)")]
    Unsupported,
    #[error("pseudo-terminal: {0}")]
    Io(#[from] std::io::Error),
    #[error("the viewer did not draw within {0:?}")]
    NoStart(Duration),
}

#[cfg(target_os = "linux")]
pub use linux::{run, screen_after};

/// Runs the viewer behind a slow link (Linux only).
#[cfg(not(target_os = "linux"))]
pub fn run(_: &Config) -> Result<Report, LinkError> {
    Err(LinkError::Unsupported)
}

/// The emulated screen `after` the viewer's first frame (Linux only).
#[cfg(not(target_os = "linux"))]
pub fn screen_after(_: &Config, _: Duration) -> Result<vt100::Screen, LinkError> {
    Err(LinkError::Unsupported)
}

#[cfg(target_os = "linux")]
mod linux {
    use std::collections::VecDeque;
    use std::fs::File;
    use std::io::{Read, Write};
    use std::os::fd::{FromRawFd, OwnedFd};
    use std::os::unix::process::CommandExt;
    use std::process::{Command, Stdio};
    use std::sync::{Arc, Condvar, Mutex};

    use super::{Config, Duration, Instant, LinkError, Report};

    /// The link's buffer: bytes written by the viewer, not yet delivered.
    struct Pipe {
        queue: Mutex<(VecDeque<u8>, bool)>,
        room: Condvar,
    }

    fn openpty(cols: u16, rows: u16) -> std::io::Result<(OwnedFd, OwnedFd)> {
        let (mut master, mut slave) = (0, 0);
        let ws = libc::winsize {
            ws_row: rows,
            ws_col: cols,
            ws_xpixel: 0,
            ws_ypixel: 0,
        };
        // SAFETY: the out-pointers are valid; a null name and termios are allowed.
        let r = unsafe {
            libc::openpty(
                &mut master,
                &mut slave,
                std::ptr::null_mut(),
                std::ptr::null(),
                &ws,
            )
        };
        if r != 0 {
            return Err(std::io::Error::last_os_error());
        }
        // SAFETY: openpty returned two open descriptors that nothing else owns.
        Ok(unsafe { (OwnedFd::from_raw_fd(master), OwnedFd::from_raw_fd(slave)) })
    }

    /// The far end of the link: delivers what the rate allows to the emulator.
    struct Link {
        pipe: Arc<Pipe>,
        rate: f64,
        tail: Vec<u8>,
        credit: f64,
        last: Instant,
        chunk: Vec<u8>,
        delivered: u64,
        frames: u64,
        max_buffered: usize,
        palette: Option<[[u8; 3]; 16]>,
    }

    impl Link {
        /// Waits a tick and delivers what the link carried in it, answering the
        /// queries the emulator reaches; returns whether the viewer's output ended.
        fn step(&mut self, parser: &mut vt100::Parser, writer: &mut File) -> std::io::Result<bool> {
            std::thread::sleep(Duration::from_millis(5));
            let now = Instant::now();
            self.credit += self.rate * now.duration_since(self.last).as_secs_f64();
            self.last = now;
            let done = {
                let mut q = self
                    .pipe
                    .queue
                    .lock()
                    .map_err(|_| std::io::Error::other("poisoned"))?;
                self.max_buffered = self.max_buffered.max(q.0.len());
                let n = (self.credit as usize).min(q.0.len());
                self.credit -= n as f64;
                if q.0.is_empty() {
                    // An idle link does not save up.
                    self.credit = self.credit.min(self.rate * 0.01);
                }
                self.chunk.clear();
                self.chunk.extend(q.0.drain(..n));
                self.pipe.room.notify_all();
                q.1 && q.0.is_empty()
            };
            parser.process(&self.chunk);
            self.delivered += self.chunk.len() as u64;
            // Answers in the order the queries were reached, as a terminal does.
            for q in queries(&mut self.tail, &self.chunk) {
                match q {
                    None => {
                        self.frames += 1;
                        writer.write_all(b"\x1b[?62;22c")?;
                    }
                    Some(i) => {
                        if let Some(p) = &self.palette {
                            let [r, g, b] = p[usize::from(i)].map(|v| u16::from(v) * 257);
                            let reply = format!("\x1b]4;{i};rgb:{r:04x}/{g:04x}/{b:04x}\x1b\\");
                            writer.write_all(reply.as_bytes())?;
                        }
                    }
                }
            }
            Ok(done)
        }
    }

    /// The queries in the delivered stream (`tail`: the last bytes before `chunk`), in
    /// order: `ESC [ c` is `None`, an OSC 4 query of colour `i` (`ESC ] 4 ; i ; ?`) is
    /// `Some(i)`. Each is counted where it ends, so one that ended in an earlier chunk
    /// is not counted again.
    fn queries(tail: &mut Vec<u8>, chunk: &[u8]) -> Vec<Option<u8>> {
        const KEEP: usize = 8;
        let old = tail.len();
        tail.extend_from_slice(chunk);
        let mut found = Vec::new();
        for at in 0..tail.len() {
            let rest = &tail[at..];
            if rest.starts_with(b"\x1b[c") && at + 3 > old {
                found.push(None);
            } else if let Some(body) = rest.strip_prefix(b"\x1b]4;") {
                let digits = body.iter().take_while(|b| b.is_ascii_digit()).count();
                let end = 4 + digits + 2;
                if digits > 0 && body[digits..].starts_with(b";?") && at + end > old {
                    let i = std::str::from_utf8(&body[..digits])
                        .ok()
                        .and_then(|s| s.parse().ok());
                    found.extend(i.filter(|&i: &u8| i < 16).map(Some));
                }
            }
        }
        let keep = tail.len().saturating_sub(KEEP);
        tail.drain(..keep);
        found
    }

    /// Whether the emulated status line says culling is on.
    fn status_says_cull(p: &vt100::Parser, rows: u16) -> bool {
        p.screen()
            .rows(0, 400)
            .nth(usize::from(rows - 1))
            .is_some_and(|l| l.contains(" cull |") && !l.contains("no cull"))
    }

    /// The viewer running behind the link.
    struct Running {
        child: std::process::Child,
        writer: File,
        link: Link,
        parser: vt100::Parser,
    }

    /// Starts the viewer behind the link and waits for its first frame.
    fn start(config: &Config) -> Result<Running, LinkError> {
        let (master, slave) = openpty(config.cols, config.rows)?;
        let mut child = {
            let mut cmd = Command::new(&config.exe);
            cmd.arg("view")
                .args(&config.args)
                .env("TERM", "xterm-256color")
                .env("COLORTERM", "truecolor")
                .env("LANG", "C.UTF-8")
                .stdin(Stdio::from(slave.try_clone()?))
                .stdout(Stdio::from(slave.try_clone()?))
                .stderr(Stdio::null());
            // SAFETY: only async-signal-safe calls between fork and exec.
            unsafe {
                cmd.pre_exec(|| {
                    if libc::setsid() < 0 || libc::ioctl(0, libc::TIOCSCTTY, 0) < 0 {
                        return Err(std::io::Error::last_os_error());
                    }
                    Ok(())
                });
            }
            cmd.spawn()?
        };
        drop(slave);
        let mut reader = File::from(master.try_clone()?);
        let mut writer = File::from(master);
        let pipe = Arc::new(Pipe {
            queue: Mutex::new((VecDeque::new(), false)),
            room: Condvar::new(),
        });
        let buffer = config.buffer;
        let fill = Arc::clone(&pipe);
        std::thread::spawn(move || {
            let mut buf = vec![0u8; 1 << 16];
            loop {
                let n = match reader.read(&mut buf) {
                    Ok(0) | Err(_) => 0,
                    Ok(n) => n,
                };
                let Ok(mut q) = fill.queue.lock() else { return };
                if n == 0 {
                    q.1 = true;
                    return;
                }
                q.0.extend(&buf[..n]);
                // A full window stops the reading, so the viewer's writes block.
                while q.0.len() >= buffer {
                    q = match fill.room.wait(q) {
                        Ok(q) => q,
                        Err(_) => return,
                    };
                }
            }
        });

        let mut parser = vt100::Parser::new(
            std::num::NonZeroU16::new(config.rows).unwrap_or(std::num::NonZeroU16::MIN),
            std::num::NonZeroU16::new(config.cols).unwrap_or(std::num::NonZeroU16::MIN),
            0,
        );
        let mut link = Link {
            pipe,
            rate: config.rate as f64,
            tail: Vec::with_capacity(8),
            credit: 0.0,
            last: Instant::now(),
            chunk: Vec::with_capacity(1 << 16),
            delivered: 0,
            frames: 0,
            max_buffered: 0,
            palette: config.palette,
        };
        let start = Instant::now();
        // Wait for the first frame.
        let first_wait = Duration::from_secs(30);
        while !parser.screen().contents().contains("fps |") {
            if link.step(&mut parser, &mut writer)? || start.elapsed() > first_wait {
                let _ = child.kill();
                let _ = child.wait();
                return Err(LinkError::NoStart(first_wait));
            }
        }
        Ok(Running {
            child,
            writer,
            link,
            parser,
        })
    }

    /// Sends `q` and waits up to 5 s for the viewer to leave (then kills it).
    fn quit(r: &mut Running) -> Result<(), LinkError> {
        let _ = r.writer.write_all(b"q");
        let quit = Instant::now();
        while quit.elapsed() < Duration::from_secs(5) {
            if r.link.step(&mut r.parser, &mut r.writer)? || r.child.try_wait()?.is_some() {
                break;
            }
        }
        if r.child.try_wait()?.is_none() {
            let _ = r.child.kill();
        }
        let _ = r.child.wait();
        Ok(())
    }

    /// The emulated screen `after` the viewer's first frame.
    pub fn screen_after(config: &Config, after: Duration) -> Result<vt100::Screen, LinkError> {
        let mut r = start(config)?;
        let t = Instant::now();
        while t.elapsed() < after {
            if r.link.step(&mut r.parser, &mut r.writer)? {
                break;
            }
        }
        let screen = r.parser.screen().clone();
        quit(&mut r)?;
        Ok(screen)
    }

    /// Runs the viewer behind the link and times `config.presses` key presses.
    pub fn run(config: &Config) -> Result<Report, LinkError> {
        let mut r = start(config)?;
        let Running {
            writer,
            link,
            parser,
            ..
        } = &mut r;
        let mut report = Report::default();
        let measure_from = Instant::now();
        let (delivered0, frames0) = (link.delivered, link.frames);
        let mut cull = false;
        for _ in 0..config.presses {
            // Let the link fill with spinning frames before each press.
            let settle = Instant::now();
            while settle.elapsed() < Duration::from_millis(700) {
                link.step(parser, writer)?;
            }
            writer.write_all(b"b")?;
            cull = !cull;
            let pressed = Instant::now();
            let mut seen = None;
            while pressed.elapsed() < config.timeout {
                if link.step(parser, writer)? {
                    break;
                }
                if status_says_cull(parser, config.rows) == cull {
                    seen = Some(pressed.elapsed());
                    break;
                }
            }
            report.latencies.push(seen);
        }
        let secs = measure_from.elapsed().as_secs_f64();
        report.delivered_fps = (link.frames - frames0) as f64 / secs;
        report.bytes_per_second = (link.delivered - delivered0) as f64 / secs;
        report.max_buffered = link.max_buffered;
        quit(&mut r)?;
        Ok(report)
    }
}

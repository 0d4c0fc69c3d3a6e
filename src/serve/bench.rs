//! `termrast bench serve`: a load generator for `termrast serve`.
//!
//! It starts the server (this binary, `--public`, a free loopback port) and connects
//! SSH watchers (russh clients) that ask for a pty and a shell as OpenSSH does, read
//! every byte, and answer the viewer's device-attributes queries (`CSI c`) as a
//! terminal does once it has reached them, so each watcher is paced as a real one
//! would be. A slow watcher takes its bytes at a set rate, answering a query only
//! when its link would have delivered it (as [`crate::slowlink`] does for a pty).
//! Frames per second are the answers per second, which is what each terminal was
//! delivered; memory is the server's resident set before and with the watchers.

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, Command, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::Args;
use russh::ChannelMsg;
use russh::client;

use super::ServeError;

/// Arguments of `termrast bench serve`.
#[derive(Debug, Args, Clone)]
pub struct BenchServeArgs {
    /// The model or scene served.
    #[arg(default_value = "teapot")]
    pub model: String,
    /// Watchers reading as fast as the server sends.
    #[arg(long, default_value_t = 16, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=4096))]
    pub watchers: usize,
    /// Their terminal size.
    #[arg(long, default_value = "80x24", value_parser = parse_cells)]
    pub size: (u16, u16),
    /// Seconds measured (after 2 s of warm-up).
    #[arg(long, default_value_t = 10.0)]
    pub seconds: f64,
    /// Then one more watcher on a link of this many bytes per second, and the fast
    /// watchers measured again beside it.
    #[arg(long, value_name = "BYTES/S")]
    pub slow: Option<u64>,
    /// The server's frame rate cap per watcher.
    #[arg(long, default_value_t = 30)]
    pub fps: u32,
}

fn parse_cells(s: &str) -> Result<(u16, u16), String> {
    let (w, h) = s.split_once('x').ok_or("size is COLSxROWS, e.g. 80x24")?;
    let p = |v: &str| {
        v.parse::<u16>()
            .ok()
            .filter(|&n| n > 0)
            .ok_or(format!("bad size `{s}`"))
    };
    Ok((p(w)?, p(h)?))
}

/// One watcher's counts.
#[derive(Debug, Default)]
struct Tally {
    /// Times of the answered queries (delivered frames).
    answers: Vec<Instant>,
    bytes: u64,
    /// Why it ended before the benchmark did.
    failed: Option<String>,
}

impl Tally {
    fn fps(&self, from: Instant, to: Instant) -> f64 {
        let n = self
            .answers
            .iter()
            .filter(|&&t| t >= from && t < to)
            .count();
        n as f64 / to.duration_since(from).as_secs_f64()
    }
}

struct Client;

impl client::Handler for Client {
    type Error = russh::Error;

    async fn check_server_key(
        &mut self,
        _: &russh::keys::PublicKeyOrCertificate,
    ) -> Result<bool, Self::Error> {
        Ok(true)
    }
}

/// A watcher: connects, asks for a pty of `size`, and reads until `stop`, taking
/// `rate` bytes per second if given.
async fn watch(
    port: u16,
    size: (u16, u16),
    rate: Option<u64>,
    tally: Arc<std::sync::Mutex<Tally>>,
    stop: Arc<tokio::sync::Notify>,
) -> Result<(), russh::Error> {
    // As OpenSSH does for an interactive session: no Nagle delay on the answers.
    let config = Arc::new(client::Config {
        nodelay: true,
        ..Default::default()
    });
    let mut h = client::connect(config, ("127.0.0.1", port), Client).await?;
    h.authenticate_none("bench").await?;
    let mut ch = h.channel_open_session().await?;
    ch.set_env(false, "COLORTERM", "truecolor").await?;
    ch.request_pty(
        false,
        "xterm-256color",
        size.0.into(),
        size.1.into(),
        0,
        0,
        &[],
    )
    .await?;
    ch.request_shell(false).await?;
    // Where the slow link has got to: bytes arriving now are delivered after those
    // ahead of them.
    let mut link_free = Instant::now();
    let mut tail: Vec<u8> = Vec::new();
    loop {
        let msg = tokio::select! {
            m = ch.wait() => m,
            () = stop.notified() => break,
        };
        let Some(msg) = msg else { break };
        let ChannelMsg::Data { data } = msg else {
            continue;
        };
        let now = Instant::now();
        if let Some(r) = rate {
            link_free = link_free.max(now) + Duration::from_secs_f64(data.len() as f64 / r as f64);
            tokio::time::sleep_until(link_free.into()).await;
        }
        // Queries split across packets are found with the previous packet's tail.
        tail.extend_from_slice(&data);
        let queries = tail.windows(3).filter(|w| *w == b"\x1b[c").count();
        let keep = tail.len().min(2);
        tail.drain(..tail.len() - keep);
        for _ in 0..queries {
            ch.data(&b"\x1b[?62;22c"[..]).await?;
        }
        let mut t = tally.lock().unwrap_or_else(|e| e.into_inner());
        t.bytes += data.len() as u64;
        let at = Instant::now();
        t.answers.extend(std::iter::repeat_n(at, queries));
    }
    let _ = ch.data(&b"q"[..]).await;
    let _ = h.disconnect(russh::Disconnect::ByApplication, "", "").await;
    Ok(())
}

/// The server's resident memory in kB.
fn rss_kb(pid: u32) -> u64 {
    std::fs::read_to_string(format!("/proc/{pid}/status"))
        .unwrap_or_default()
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.split_whitespace().next()?.parse().ok())
        .unwrap_or(0)
}

/// The server's CPU time so far (user + system), in seconds.
fn cpu_s(pid: u32) -> f64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
    // After the command name's closing parenthesis: state is field 3, utime 14, stime 15.
    let rest = stat.rsplit_once(')').map_or("", |r| r.1);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    // SAFETY: sysconf has no preconditions.
    let hz = unsafe { libc::sysconf(libc::_SC_CLK_TCK) }.max(1) as f64;
    (ticks(11) + ticks(12)) / hz
}

/// Starts `termrast serve` on a free loopback port; returns it and the port.
fn start_server(args: &BenchServeArgs, dir: &std::path::Path) -> Result<(Child, u16), ServeError> {
    let n = (args.watchers + 2).to_string();
    let mut child = Command::new(std::env::current_exe()?)
        .args(["serve", &args.model, "--public", "--listen", "127.0.0.1:0"])
        .args([
            "--max-clients",
            &n,
            "--max-per-address",
            &n,
            "--max-startups",
            &n,
        ])
        .args(["--fps", &args.fps.to_string(), "--host-key"])
        .arg(dir.join("host_key"))
        .stdin(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()?;
    let err = child
        .stderr
        .take()
        .ok_or(ServeError::Usage("no stderr".into()))?;
    let mut lines = BufReader::new(err).lines();
    let port = loop {
        match lines.next() {
            Some(Ok(l)) => {
                if let Some(rest) = l.split("listening on ").nth(1) {
                    let port = rest
                        .split_whitespace()
                        .next()
                        .and_then(|a| a.rsplit(':').next()?.parse().ok());
                    break port.ok_or_else(|| ServeError::Usage(format!("no port in `{l}`")))?;
                }
            }
            _ => {
                let _ = child.kill();
                return Err(ServeError::Usage("the server did not start".into()));
            }
        }
    };
    // Its log lines are not this report's.
    std::thread::spawn(move || lines.for_each(drop));
    Ok((child, port))
}

/// Runs the benchmark and writes its report.
pub fn run(args: &BenchServeArgs, out: &mut impl Write) -> Result<(), ServeError> {
    let dir = std::env::temp_dir().join(format!("termrast-bench-serve-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let (mut child, port) = start_server(args, &dir)?;
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()?;
    std::thread::sleep(Duration::from_millis(500));
    let rss0 = rss_kb(child.id());
    let stop = Arc::new(tokio::sync::Notify::new());
    let size = args.size;
    let spawn = |rate: Option<u64>| {
        let tally = Arc::new(std::sync::Mutex::new(Tally::default()));
        let (t, s) = (Arc::clone(&tally), Arc::clone(&stop));
        let task = rt.spawn(async move {
            let r = watch(port, size, rate, Arc::clone(&t), s).await;
            if let Err(e) = r {
                t.lock().unwrap_or_else(|e| e.into_inner()).failed = Some(e.to_string());
            }
        });
        (tally, task)
    };
    let fast: Vec<_> = (0..args.watchers).map(|_| spawn(None)).collect();
    let measure = Duration::from_secs_f64(args.seconds.max(1.0));
    std::thread::sleep(Duration::from_secs(2));
    let (t0, c0) = (Instant::now(), cpu_s(child.id()));
    std::thread::sleep(measure);
    let (t1, c1) = (Instant::now(), cpu_s(child.id()));
    let rss1 = rss_kb(child.id());
    let fps = |from, to| -> Vec<f64> {
        fast.iter()
            .map(|(t, _)| t.lock().unwrap_or_else(|e| e.into_inner()).fps(from, to))
            .collect()
    };
    let base = fps(t0, t1);
    let (w, h) = args.size;
    writeln!(
        out,
        "{} watchers at {w}x{h} on {} for {:.0} s ({} fps cap):",
        args.watchers,
        args.model,
        measure.as_secs_f64(),
        args.fps
    )?;
    report(out, "each", &base)?;
    let failed: Vec<String> = fast
        .iter()
        .filter_map(|(t, _)| t.lock().ok()?.failed.clone())
        .collect();
    if let Some(first) = failed.first() {
        writeln!(out, "  {} watcher(s) failed: {first}", failed.len())?;
    }
    let bytes: u64 = fast
        .iter()
        .map(|(t, _)| t.lock().map_or(0, |t| t.bytes))
        .sum();
    writeln!(
        out,
        "  {:.0} kB/s per watcher",
        bytes as f64 / 1e3 / t1.duration_since(t0).as_secs_f64() / args.watchers.max(1) as f64
    )?;
    writeln!(
        out,
        "  server CPU: {:.0} % of one core",
        100.0 * (c1 - c0) / t1.duration_since(t0).as_secs_f64()
    )?;
    let per = rss1.saturating_sub(rss0) as f64 / args.watchers.max(1) as f64;
    writeln!(
        out,
        "  server memory: {:.1} MB alone, {:.1} MB with them: {per:.0} kB per watcher",
        rss0 as f64 / 1e3,
        rss1 as f64 / 1e3
    )?;
    if let Some(rate) = args.slow {
        let (slow, _task) = spawn(Some(rate));
        std::thread::sleep(Duration::from_secs(3));
        let t2 = Instant::now();
        std::thread::sleep(measure);
        let t3 = Instant::now();
        let beside = fps(t2, t3);
        let slow_fps = slow.lock().map_or(0.0, |t| t.fps(t2, t3));
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        writeln!(
            out,
            "with one more watcher on a {:.0} kB/s link:",
            rate as f64 / 1e3
        )?;
        report(out, "the others", &beside)?;
        writeln!(
            out,
            "  the slow one: {slow_fps:.1} fps; the others' mean {:+.1} % against without it",
            100.0 * (mean(&beside) / mean(&base).max(1e-9) - 1.0)
        )?;
    }
    stop.notify_waiters();
    rt.shutdown_timeout(Duration::from_secs(2));
    // SAFETY: kill has no memory preconditions; the pid is our child's.
    unsafe {
        libc::kill(child.id() as i32, libc::SIGTERM);
    }
    let _ = child.wait();
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

fn report(out: &mut impl Write, what: &str, fps: &[f64]) -> std::io::Result<()> {
    let mut v = fps.to_vec();
    v.sort_by(f64::total_cmp);
    let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
    writeln!(
        out,
        "  fps {what}: min {:.1}, median {:.1}, mean {mean:.1}",
        v.first().copied().unwrap_or(0.0),
        v.get(v.len() / 2).copied().unwrap_or(0.0)
    )
}

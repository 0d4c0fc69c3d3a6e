//! `termrast serve` with a real OpenSSH client: watchers in tmux see the model, each
//! their own view; refusals; faults (a killed client, one that never reads, a flood
//! past the limit); the host key's file; SIGTERM; random keyboard input. The tests
//! that need `ssh`, `ssh-keygen` or `tmux` say so and skip when they are missing
//! (CI installs them).

use std::io::{BufRead, BufReader, Read};
use std::net::TcpStream;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::thread::sleep;
use std::time::{Duration, Instant};

/// Long enough for a loaded 2-core machine.
const WAIT: Duration = Duration::from_secs(30);

fn have(tool: &str, arg: &str) -> bool {
    Command::new(tool)
        .arg(arg)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok()
}

/// Whether ssh, ssh-keygen (and tmux when `tmux`) are installed; says so if not.
fn tools(tmux: bool, test: &str) -> bool {
    let ok = have("ssh", "-V") && have("ssh-keygen", "-?") && (!tmux || have("tmux", "-V"));
    if !ok {
        eprintln!(
            "{test}: skipped, needs ssh, ssh-keygen{}",
            if tmux { " and tmux" } else { "" }
        );
    }
    ok
}

/// Polls `done` until it holds or [`WAIT`] passes; returns whether it held.
fn until(mut done: impl FnMut() -> bool) -> bool {
    let start = Instant::now();
    while start.elapsed() < WAIT {
        if done() {
            return true;
        }
        sleep(Duration::from_millis(100));
    }
    done()
}

/// A directory of its own for a test.
fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("termrast-serve-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch dir");
    d
}

/// An Ed25519 key pair `dir/name`, `dir/name.pub`.
fn keygen(dir: &Path, name: &str) -> PathBuf {
    let p = dir.join(name);
    let ok = Command::new("ssh-keygen")
        .args(["-q", "-t", "ed25519", "-N", "", "-f"])
        .arg(&p)
        .status()
        .expect("ssh-keygen")
        .success();
    assert!(ok, "ssh-keygen failed");
    p
}

/// A running `termrast serve` and what it printed on stderr.
struct Server {
    child: Child,
    port: u16,
    log: Arc<Mutex<String>>,
}

impl Server {
    fn start(dir: &Path, args: &[&str]) -> Server {
        let mut child = Command::new(env!("CARGO_BIN_EXE_termrast"))
            .arg("serve")
            .args(["--listen", "127.0.0.1:0", "--host-key"])
            .arg(dir.join("host_key"))
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("termrast serve");
        let log = Arc::new(Mutex::new(String::new()));
        let err = child.stderr.take().expect("stderr");
        let sink = Arc::clone(&log);
        std::thread::spawn(move || {
            for line in BufReader::new(err).lines().map_while(Result::ok) {
                let mut l = sink.lock().unwrap();
                l.push_str(&line);
                l.push('\n');
            }
        });
        let mut s = Server {
            child,
            port: 0,
            log,
        };
        assert!(
            until(|| s.log().contains("listening on")),
            "no start:\n{}",
            s.log()
        );
        let log = s.log();
        let at = log.find("listening on 127.0.0.1:").unwrap() + "listening on 127.0.0.1:".len();
        s.port = log[at..]
            .split(|c: char| !c.is_ascii_digit())
            .next()
            .unwrap()
            .parse()
            .unwrap();
        s
    }

    fn log(&self) -> String {
        self.log.lock().unwrap().clone()
    }

    /// The ssh command line for this server with `key` (or none).
    fn ssh(&self, key: Option<&Path>, extra: &str) -> String {
        let id = key.map_or("-o IdentityFile=/dev/null".to_string(), |k| {
            format!("-i {}", k.display())
        });
        // ssh takes an option's first value: the caller's LogLevel, if any, goes first.
        let level = if extra.contains("LogLevel") {
            ""
        } else {
            "-o LogLevel=ERROR"
        };
        format!(
            "ssh -F /dev/null -p {} {id} -o IdentitiesOnly=yes -o BatchMode=yes \
             -o StrictHostKeyChecking=no -o UserKnownHostsFile=/dev/null {level} {extra} localhost",
            self.port
        )
    }

    /// Runs `ssh … extra localhost rest` to the end; returns its status and output.
    fn run(&self, key: Option<&Path>, extra: &str, rest: &str) -> (i32, String) {
        let cmd = format!("{} {rest} </dev/null 2>&1", self.ssh(key, extra));
        let o = Command::new("timeout")
            .args(["60", "sh", "-c", &cmd])
            .output()
            .expect("sh");
        (
            o.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&o.stdout).into_owned(),
        )
    }

    fn rss_kb(&self) -> u64 {
        let s = std::fs::read_to_string(format!("/proc/{}/status", self.child.id()))
            .unwrap_or_default();
        s.lines()
            .find_map(|l| l.strip_prefix("VmRSS:"))
            .and_then(|v| v.split_whitespace().next()?.parse().ok())
            .unwrap_or(0)
    }

    fn alive(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(None))
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A tmux server of its own; each client a session in it.
struct Tmux(String);

impl Tmux {
    fn new(tag: &str) -> Tmux {
        Tmux(format!("termrast-serve-{tag}-{}", std::process::id()))
    }

    fn tmux(&self, args: &[&str]) -> String {
        let o = Command::new("tmux")
            .arg("-L")
            .arg(&self.0)
            .args(args)
            .output()
            .expect("tmux");
        String::from_utf8_lossy(&o.stdout).into_owned()
    }

    /// A session `name` of `cols × rows` running `cmd`, then a line with its status.
    fn open(&self, name: &str, cols: u16, rows: u16, cmd: &str) {
        let shell = format!("TERM=xterm-256color {cmd}; echo EXIT=$?; sleep 600");
        self.tmux(&[
            "-u",
            "new-session",
            "-d",
            "-s",
            name,
            "-x",
            &cols.to_string(),
            "-y",
            &rows.to_string(),
            &shell,
        ]);
    }

    fn screen(&self, name: &str) -> String {
        self.tmux(&["capture-pane", "-p", "-t", name])
    }

    fn keys(&self, name: &str, keys: &str) {
        self.tmux(&["send-keys", "-t", name, keys]);
    }

    fn wait(&self, name: &str, done: impl Fn(&str) -> bool) -> String {
        until(|| done(&self.screen(name)));
        self.screen(name)
    }

    /// Waits until the watcher shows frames (the status line's rate).
    fn watching(&self, name: &str) -> String {
        let s = self.wait(name, |s| s.contains("fps |"));
        assert!(s.contains("fps |"), "{name} shows no viewer:\n{s}");
        s
    }

    /// Waits until the screen changes (the model turns): frames still arrive.
    fn moving(&self, name: &str) -> bool {
        let before = self.screen(name);
        until(|| self.screen(name) != before)
    }

    fn pane_pid(&self, name: &str) -> u32 {
        self.tmux(&["display", "-p", "-t", name, "#{pane_pid}"])
            .trim()
            .parse()
            .expect("pid")
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        self.tmux(&["kill-server"]);
    }
}

fn status(screen: &str) -> &str {
    screen
        .lines()
        .rfind(|l| !l.trim().is_empty())
        .unwrap_or_default()
}

fn rows_used(screen: &str) -> usize {
    let lines: Vec<&str> = screen.lines().collect();
    lines
        .iter()
        .rposition(|l| !l.trim().is_empty())
        .map_or(0, |i| i + 1)
}

/// A server admitting one key, and that key.
fn keyed(tag: &str, args: &[&str]) -> (PathBuf, PathBuf, Server) {
    let dir = scratch(tag);
    let key = keygen(&dir, "id");
    let mut a = vec!["--authorized-keys", dir.join("id.pub").to_str().unwrap()]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
    a.extend(args.iter().map(|s| s.to_string()));
    let refs: Vec<&str> = a.iter().map(String::as_str).collect();
    let server = Server::start(&dir, &refs);
    (dir, key, server)
}

#[test]
fn two_watchers_see_their_own_views_resize_and_quit_alone() {
    if !tools(true, "two_watchers") {
        return;
    }
    let (_dir, key, server) = keyed("two", &[]);
    let t = Tmux::new("two");
    t.open("a", 100, 30, &server.ssh(Some(&key), "-t"));
    t.open("b", 60, 20, &server.ssh(Some(&key), "-t"));
    let (a, b) = (t.watching("a"), t.watching("b"));
    assert_eq!(rows_used(&a), 30, "a's status line is its last row:\n{a}");
    assert_eq!(rows_used(&b), 20, "b's status line is its last row:\n{b}");
    // The inspector opens in a's view only.
    t.keys("a", "i");
    let a = t.wait("a", |s| s.contains("inspector"));
    assert!(a.contains("inspector") && a.contains("samples"), "{a}");
    assert!(!t.screen("b").contains("inspector"));
    // A window change re-lays b out at its new size.
    t.tmux(&["resize-window", "-t", "b", "-x", "90", "-y", "28"]);
    let b = t.wait("b", |s| rows_used(s) == 28 && status(s).contains("fps |"));
    assert_eq!(rows_used(&b), 28, "b after resize:\n{b}");
    // q ends a's session; b keeps watching.
    t.keys("a", "q");
    let a = t.wait("a", |s| s.contains("EXIT="));
    assert!(a.contains("EXIT=0"), "a after q:\n{a}");
    assert!(t.moving("b"), "b stopped when a quit");
    t.keys("b", "q");
    assert!(t.wait("b", |s| s.contains("EXIT=")).contains("EXIT=0"));
    assert!(
        until(|| server.log().matches("end=quit").count() == 2),
        "{}",
        server.log()
    );
    let log = server.log();
    assert!(
        log.contains("key=SHA256:") && log.contains("size=100x30"),
        "{log}"
    );
}

#[test]
fn refusals_run_nothing_and_the_server_keeps_serving() {
    if !tools(true, "refusals") {
        return;
    }
    let (dir, key, server) = keyed("refuse", &["--max-per-address", "16"]);
    let t = Tmux::new("refuse");
    t.open("w", 80, 24, &server.ssh(Some(&key), "-t"));
    t.watching("w");
    let marker = dir.join("ran");
    let m = marker.display().to_string();
    // A command.
    let (rc, out) = server.run(Some(&key), "", &format!("touch {m}"));
    assert_ne!(rc, 0, "exec ran: {out}");
    assert!(out.contains("exec request failed"), "{out}");
    // No pty: told so.
    let (rc, out) = server.run(Some(&key), "-T", "");
    assert_ne!(rc, 0);
    assert!(out.contains("needs a terminal"), "{out}");
    // sftp (a subsystem).
    let (rc, out) = server.run(Some(&key), "-s", "sftp");
    assert_ne!(rc, 0, "sftp: {out}");
    assert!(out.contains("subsystem request failed"), "{out}");
    // Remote forwarding.
    let (rc, out) = server.run(
        Some(&key),
        "-N -o ExitOnForwardFailure=yes -R 127.0.0.1:0:127.0.0.1:22",
        "",
    );
    assert_ne!(rc, 0);
    assert!(out.contains("forwarding failed"), "{out}");
    // Local forwarding: the client's local port gets nothing through.
    let local = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let fwd = format!("-N -L 127.0.0.1:{local}:127.0.0.1:{}", server.port);
    let mut l = Command::new("sh")
        .args(["-c", &format!("exec {}", server.ssh(Some(&key), &fwd))])
        .stdin(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("ssh -L");
    let mut got = Vec::new();
    let connected = until(|| match TcpStream::connect(("127.0.0.1", local)) {
        Ok(mut c) => {
            c.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
            let _ = c.read_to_end(&mut got);
            true
        }
        Err(_) => false,
    });
    let _ = l.kill();
    let _ = l.wait();
    assert!(connected, "ssh -L never listened");
    assert!(
        !String::from_utf8_lossy(&got).contains("SSH-"),
        "forwarded: {got:?}"
    );
    // Agent and X11 forwarding are asked for and refused; the viewer still comes up.
    // A wrong key and no key.
    let other = keygen(&dir, "other");
    let (rc, out) = server.run(Some(&other), "-T", "");
    assert_ne!(rc, 0);
    assert!(out.contains("Permission denied"), "{out}");
    let (rc, out) = server.run(None, "-T", "");
    assert_ne!(rc, 0);
    assert!(out.contains("Permission denied"), "{out}");
    assert!(!marker.exists(), "a refused command ran");
    // The watcher kept watching, and a new one gets in (with agent and X11 asked).
    assert!(t.moving("w"), "the watcher stopped");
    t.open("n", 80, 24, &server.ssh(Some(&key), "-t -A -X"));
    t.watching("n");
    until(|| server.log().contains("refused: port forwarding"));
    let log = server.log();
    for why in [
        "refused: exec",
        "refused: no pty",
        "refused: subsystem",
        "refused: remote forwarding",
        "refused: port forwarding",
        "not authenticated",
    ] {
        assert!(log.contains(why), "no `{why}` in the log:\n{log}");
    }
}

#[test]
fn public_needs_no_key_and_beyond_loopback_needs_a_choice() {
    if !tools(false, "public") {
        return;
    }
    let dir = scratch("public");
    let o = Command::new(env!("CARGO_BIN_EXE_termrast"))
        .args(["serve", "--listen", "0.0.0.0:0", "--host-key"])
        .arg(dir.join("hk"))
        .output()
        .expect("serve");
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--public") && err.contains("--authorized-keys"),
        "{err}"
    );
    let server = Server::start(&dir, &["--public"]);
    let (rc, out) = server.run(None, "-T", "");
    assert_eq!(rc, 1, "{out}");
    assert!(
        out.contains("needs a terminal"),
        "admitted without a key: {out}"
    );
    assert!(
        until(|| server.log().contains("key=public")),
        "{}",
        server.log()
    );
}

#[test]
fn the_host_key_is_made_private_and_refused_when_others_can_read_it() {
    let dir = scratch("hostkey");
    let mut server = Server::start(&dir, &["--public"]);
    let key = dir.join("host_key");
    let mode = std::fs::metadata(&key).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o600);
    assert!(server.log().contains("SHA256:"), "{}", server.log());
    let _ = server.child.kill();
    let _ = server.child.wait();
    std::fs::set_permissions(&key, std::fs::Permissions::from_mode(0o644)).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_termrast"))
        .args(["serve", "--public", "--listen", "127.0.0.1:0", "--host-key"])
        .arg(&key)
        .output()
        .expect("serve");
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("readable by group or others"), "{err}");
}

#[test]
fn sigterm_and_idle_end_sessions_with_a_message() {
    if !tools(true, "sigterm") {
        return;
    }
    let (_dir, key, mut server) = keyed("term", &["--idle-timeout", "3s"]);
    let t = Tmux::new("term");
    // Not waited for as a watcher: on a loaded machine it may be idle before a look.
    t.open("idle", 80, 24, &server.ssh(Some(&key), "-t"));
    let s = t.wait("idle", |s| s.contains("EXIT="));
    assert!(s.contains("without a key"), "idle session:\n{s}");
    t.open("w", 80, 24, &server.ssh(Some(&key), "-t"));
    t.watching("w");
    let _ = Command::new("kill")
        .args(["-TERM", &server.child.id().to_string()])
        .status();
    let s = t.wait("w", |s| s.contains("EXIT="));
    assert!(s.contains("shutting down"), "after SIGTERM:\n{s}");
    assert!(until(|| !server.alive()), "server still running");
    assert!(server.child.wait().unwrap().success());
    assert!(
        until(|| server.log().contains("end=server stopping")),
        "{}",
        server.log()
    );
}

mod input;
mod limits;

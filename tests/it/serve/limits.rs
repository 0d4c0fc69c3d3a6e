//! The limits and faults of `termrast serve`: connections that never authenticate,
//! a login that comes late, a client that takes nothing, one killed mid-frame, a
//! flood past `--max-clients`, random bytes typed through ssh.

use std::io::Read;
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::thread::sleep;
use std::time::{Duration, Instant};

use super::{Server, Tmux, WAIT, keyed, tools, until};

/// The server's first line to a new connection, or what it sent before closing.
fn greeting(port: u16) -> (TcpStream, String) {
    let mut s = TcpStream::connect(("127.0.0.1", port)).expect("connect");
    s.set_read_timeout(Some(WAIT)).unwrap();
    let mut got = Vec::new();
    let mut b = [0u8; 1];
    while !got.ends_with(b"\n") && matches!(s.read(&mut b), Ok(1)) {
        got.push(b[0]);
    }
    (s, String::from_utf8_lossy(&got).into_owned())
}

/// Connections that never authenticate take no watcher's place, are bounded by
/// --max-startups (past it, closed before a word) and are closed after the grace time.
#[test]
fn unauthenticated_connections_are_bounded_apart_from_watchers() {
    if !tools(true, "startups") {
        return;
    }
    let (dir, key, mut server) = keyed(
        "startups",
        &[
            "--max-clients",
            "1",
            "--max-per-address",
            "64",
            "--max-startups",
            "4",
            "--login-grace-time",
            "10s",
        ],
    );
    let silent: Vec<TcpStream> = (0..2)
        .map(|_| {
            let (s, hello) = greeting(server.port);
            assert!(hello.starts_with("SSH-2.0-termrast"), "{hello:?}");
            s
        })
        .collect();
    // One who connects now but authenticates only once `go` exists (its bytes are
    // held back until then).
    let go = dir.join("go");
    let late = Command::new("timeout")
        .args(["60", "sh", "-c"])
        .arg(format!(
            "{} </dev/null 2>&1",
            server.ssh(
                Some(&key),
                &format!(
                    "-T -o ProxyCommand=\"bash -c 'exec 3<>/dev/tcp/127.0.0.1/{} 4<&0; \
                     (until [ -e {} ]; do sleep 0.05; done; cat <&4) >&3 & cat <&3'\"",
                    server.port,
                    go.display()
                )
            )
        ))
        .stdout(Stdio::piped())
        .spawn()
        .expect("ssh");
    // The one watcher's place is not the silent ones'.
    let t = Tmux::new("startups");
    t.open("w", 80, 24, &server.ssh(Some(&key), "-t"));
    t.watching("w");
    // The late one authenticates with every place taken: told so in its session.
    std::fs::write(&go, "").expect("go");
    let out = late.wait_with_output().expect("ssh");
    let out = String::from_utf8_lossy(&out.stdout);
    assert!(out.contains("termrast: 1 watchers already"), "{out}");
    // Another who comes now is told the server is full, in the banner.
    let (rc, out) = server.run(Some(&key), "-T -o LogLevel=INFO", "");
    assert_ne!(rc, 0);
    assert!(out.contains("1 watchers already"), "{out}");
    assert!(t.moving("w"), "the watcher stopped");
    t.keys("w", "q");
    assert!(t.wait("w", |s| s.contains("EXIT=")).contains("EXIT=0"));
    assert!(until(|| server.log().contains("end=quit")));
    // With the place free, two more silent ones fill --max-startups; the next is
    // closed at once, unanswered.
    let more: Vec<TcpStream> = (0..2)
        .map(|_| {
            let (s, hello) = greeting(server.port);
            assert!(hello.starts_with("SSH-2.0-termrast"), "{hello:?}");
            s
        })
        .collect();
    let (_, hello) = greeting(server.port);
    assert_eq!(
        hello,
        "",
        "a connection past --max-startups was answered:\n{}",
        server.log()
    );
    assert!(
        until(|| server.log().contains("past --max-startups")),
        "{}",
        server.log()
    );
    assert!(server.alive());
    drop((silent, more));
    // With --login-grace-time 2s, a silent connection is closed after it, and its
    // place is free again.
    let (_dir, _key, graced) = keyed(
        "grace",
        &["--login-grace-time", "2s", "--max-startups", "1"],
    );
    let (mut s, hello) = greeting(graced.port);
    assert!(hello.starts_with("SSH-2.0-termrast"), "{hello:?}");
    let start = Instant::now();
    let _ = s.read_to_end(&mut Vec::new());
    let took = start.elapsed();
    assert!(
        took >= Duration::from_millis(1500) && took < WAIT,
        "closed after {took:?}"
    );
    assert!(
        until(|| graced.log().contains(" key=- ")),
        "{}",
        graced.log()
    );
    let (_, hello) = greeting(graced.port);
    assert!(hello.starts_with("SSH-2.0-termrast"), "{hello:?}");
}

/// A client that never reads: a 200×60 terminal (`script`'s pty) whose output pipe
/// is never drained, and which never answers a query (so it is sent frames unpaced).
fn stuck_client(server: &Server, key: &Path) -> Child {
    let cmd = format!(
        "stty cols 200 rows 60; exec {}",
        server.ssh(Some(key), "-tt")
    );
    Command::new("script")
        .args(["-q", "-e", "-c", &cmd, "/dev/null"])
        .env("TERM", "xterm-256color")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("script")
}

/// A client that takes nothing fills its window; its connection is closed
/// --stall-timeout later, and the others keep watching.
#[test]
fn a_client_that_takes_nothing_is_closed_after_the_stall_timeout() {
    if !tools(true, "stall") {
        return;
    }
    let (_dir, key, mut server) = keyed("stall", &["--stall-timeout", "2s"]);
    let t = Tmux::new("stall");
    t.open("w", 80, 24, &server.ssh(Some(&key), "-t"));
    t.watching("w");
    let mut stuck = stuck_client(&server, &key);
    let stalled =
        |l: &str| l.contains("size=200x60") && l.contains("end=stalled (read nothing for 2s)");
    assert!(
        until(|| server.log().lines().any(stalled)),
        "the stuck client was not closed:\n{}",
        server.log()
    );
    let _ = stuck.kill();
    let _ = stuck.wait();
    assert!(server.alive());
    assert!(t.moving("w"), "the watcher stopped");
}

#[test]
fn faults_stall_only_their_own_client() {
    if !tools(true, "faults") {
        return;
    }
    let (dir, key, mut server) =
        keyed("faults", &["--max-clients", "4", "--max-per-address", "16"]);
    let t = Tmux::new("faults");
    t.open("w", 80, 24, &server.ssh(Some(&key), "-t"));
    t.watching("w");
    // A client killed mid-frame.
    t.open(
        "k",
        120,
        40,
        &format!("exec {}", server.ssh(Some(&key), "-t")),
    );
    t.watching("k");
    let pid = t.pane_pid("k");
    let _ = Command::new("kill").args(["-9", &pid.to_string()]).status();
    assert!(
        until(|| server.log().contains("size=120x40")),
        "killed client not logged:\n{}",
        server.log()
    );
    let mut stuck = stuck_client(&server, &key);
    sleep(Duration::from_secs(3));
    let rss = server.rss_kb();
    assert!(t.moving("w"), "the watcher stalled with the stuck client");
    sleep(Duration::from_secs(5));
    let grown = server.rss_kb().saturating_sub(rss);
    assert!(
        grown < 64 * 1024,
        "server grew {grown} kB with a stuck client"
    );
    // A flood past --max-clients (4: w and the stuck one are in). Each holds its
    // connection open, so the admitted stay admitted.
    let flood: Vec<Child> = (0..6)
        .map(|i| {
            let out = dir.join(format!("flood{i}"));
            let cmd = format!(
                "exec {} >{} 2>&1",
                server.ssh(Some(&key), "-tt -o LogLevel=INFO"),
                out.display()
            );
            Command::new("sh")
                .args(["-c", &cmd])
                .env("TERM", "xterm-256color")
                .stdin(Stdio::piped())
                .spawn()
                .expect("ssh")
        })
        .collect();
    let refused = || {
        (0..6)
            .filter(|i| {
                std::fs::read_to_string(dir.join(format!("flood{i}")))
                    .is_ok_and(|o| o.contains("watchers already"))
            })
            .count()
    };
    assert!(until(|| refused() >= 4), "{} refused of 6", refused());
    sleep(Duration::from_secs(1));
    assert_eq!(refused(), 4, "two more admitted, the rest refused");
    for mut c in flood {
        let _ = c.kill();
        let _ = c.wait();
    }
    assert!(server.alive());
    assert!(t.moving("w"), "the watcher stopped during the flood");
    let _ = stuck.kill();
    let _ = stuck.wait();
    // Random bytes as another client's keyboard (through ssh, escapes and all): the
    // watcher and the server do not notice.
    // Once the killed, the flood and the stuck client are gone (a line each).
    assert!(
        until(|| server.log().matches(" end=").count() >= 8),
        "{}",
        server.log()
    );
    t.open("r", 70, 20, &server.ssh(Some(&key), "-t -e none"));
    t.watching("r");
    let mut x: u32 = 0x2545_f491;
    for _ in 0..8 {
        let bytes: Vec<String> = (0..64)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                format!("{:02x}", x & 0xff)
            })
            .collect();
        let mut args = vec!["send-keys", "-t", "r", "-H"];
        args.extend(bytes.iter().map(String::as_str));
        t.tmux(&args);
    }
    assert!(server.alive(), "random input ended the server");
    assert!(t.moving("w"), "the watcher stopped during random input");
    t.keys("w", "q");
    assert!(t.wait("w", |s| s.contains("EXIT=")).contains("EXIT=0"));
}

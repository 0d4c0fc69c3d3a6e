//! The viewer in a real terminal (tmux): keys reach it, the inspector shows its fields,
//! and the terminal is restored after `q` and after SIGTERM. Skipped, with a note, when
//! tmux is not installed (CI installs it).

use std::process::Command;
use std::thread::sleep;
use std::time::{Duration, Instant};

struct Tmux {
    socket: String,
}

impl Tmux {
    fn new(tag: &str) -> Option<Self> {
        Command::new("tmux")
            .arg("-V")
            .output()
            .ok()
            .filter(|o| o.status.success())?;
        let t = Tmux {
            socket: format!("termrast-{tag}-{}", std::process::id()),
        };
        let ok = t
            .run(&[
                "-u",
                "new-session",
                "-d",
                "-s",
                "t",
                "-x",
                "130",
                "-y",
                "40",
                "sh",
            ])
            .is_some();
        ok.then_some(t)
    }

    fn run(&self, args: &[&str]) -> Option<String> {
        let o = Command::new("tmux")
            .arg("-L")
            .arg(&self.socket)
            .args(args)
            .output()
            .ok()?;
        o.status
            .success()
            .then(|| String::from_utf8_lossy(&o.stdout).into_owned())
    }

    fn keys(&self, keys: &[&str]) {
        for k in keys {
            self.run(&["send-keys", "-t", "t", k]);
            sleep(Duration::from_millis(40));
        }
    }

    fn screen(&self) -> String {
        self.run(&["capture-pane", "-p", "-t", "t"])
            .unwrap_or_default()
    }

    fn wait_for(&self, needle: &str) -> String {
        let start = Instant::now();
        loop {
            let s = self.screen();
            if s.contains(needle) || start.elapsed() > Duration::from_secs(10) {
                return s;
            }
            sleep(Duration::from_millis(100));
        }
    }

    /// alternate screen, mouse reporting, cursor visible.
    fn flags(&self) -> String {
        self.run(&[
            "display",
            "-p",
            "-t",
            "t",
            "#{alternate_on} #{mouse_any_flag} #{cursor_flag}",
        ])
        .unwrap_or_default()
        .trim()
        .to_string()
    }

    fn start_viewer(&self) {
        self.start_viewer_with("TERM=xterm-256color LANG=C.UTF-8", "");
    }

    /// Starts the viewer with environment assignments `env` and arguments `args`.
    fn start_viewer_with(&self, env: &str, args: &str) {
        let cmd = format!(
            "{env} {} {args}; echo EXIT=$?",
            env!("CARGO_BIN_EXE_termrast")
        );
        self.keys(&["clear", "Enter", &cmd, "Enter"]);
        let s = self.wait_for("fps |");
        assert!(s.contains("fps |"), "viewer did not start:\n{s}");
    }

    fn assert_restored(&self) {
        let s = self.wait_for("EXIT=");
        assert!(s.contains("EXIT=0"), "viewer did not exit cleanly:\n{s}");
        assert_eq!(self.flags(), "0 0 1", "alternate screen, mouse, cursor");
        self.keys(&["stty -a | tr ' ' '\\n' | grep -x -- '-*icanon'", "Enter"]);
        sleep(Duration::from_millis(300));
        let s = self.screen();
        assert!(
            s.lines().any(|l| l.trim() == "icanon"),
            "raw mode left on:\n{s}"
        );
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        self.run(&["kill-server"]);
    }
}

#[test]
fn inspect_pause_quit_and_restore() {
    let Some(t) = Tmux::new("keys") else {
        eprintln!("tmux not installed: skipping the terminal end-to-end test");
        return;
    };
    t.start_viewer();
    assert_eq!(
        t.flags(),
        "1 1 0",
        "viewer runs on the alternate screen with the mouse on"
    );
    t.keys(&["i", " "]);
    for _ in 0..30 {
        t.keys(&["Right"]);
    }
    t.keys(&["Down", "Down"]);
    let s = t.wait_for("inspector");
    for field in ["inspector", "paused", "samples", "line"] {
        assert!(s.contains(field), "missing {field}:\n{s}");
    }
    t.keys(&["?"]);
    assert!(t.wait_for("keys").contains("quit"));
    t.keys(&["Escape", "q"]);
    t.assert_restored();
}

#[test]
fn sigterm_restores_the_terminal() {
    let Some(t) = Tmux::new("term") else {
        eprintln!("tmux not installed: skipping the terminal end-to-end test");
        return;
    };
    t.start_viewer();
    // Signal only the viewer of this test's pane (other tests run their own).
    let shell = t
        .run(&["display", "-p", "-t", "t", "#{pane_pid}"])
        .unwrap_or_default();
    let out = Command::new("pkill")
        .args(["-TERM", "-P", shell.trim()])
        .status();
    assert!(out.is_ok_and(|s| s.success()), "pkill found the viewer");
    t.assert_restored();
}

#[test]
fn a_non_utf8_locale_falls_back_to_ascii_and_says_so() {
    let Some(t) = Tmux::new("locale") else {
        eprintln!("tmux not installed: skipping the terminal end-to-end test");
        return;
    };
    t.start_viewer_with("TERM=xterm-256color LANG=C LC_ALL=C", "");
    let s = t.wait_for("not UTF-8");
    assert!(
        s.contains("locale C is not UTF-8: ascii glyphs"),
        "no notice:\n{s}"
    );
    let status = s.lines().rfind(|l| l.contains("fps |")).unwrap_or_default();
    assert!(status.contains("ascii"), "not ascii:\n{status}");
    // Nothing outside ASCII reaches the screen.
    assert!(s.is_ascii(), "non-ASCII glyphs on screen:\n{s}");
    // The notice is said once: a key clears it.
    t.keys(&["g"]);
    sleep(Duration::from_millis(300));
    assert!(!t.screen().contains("not UTF-8"));
    t.keys(&["q"]);
    t.assert_restored();
}

#[test]
fn a_dumb_terminal_gets_a_message_not_a_full_screen_interface() {
    let Some(t) = Tmux::new("dumb") else {
        eprintln!("tmux not installed: skipping the terminal end-to-end test");
        return;
    };
    let cmd = format!(
        "TERM=dumb {} ; echo EXIT=$?",
        env!("CARGO_BIN_EXE_termrast")
    );
    t.keys(&["clear", "Enter", &cmd, "Enter"]);
    let s = t.wait_for("EXIT=");
    assert!(
        s.contains("TERM=dumb") && s.contains("termrast render"),
        "{s}"
    );
    assert!(s.contains("EXIT=1"), "{s}");
    assert_eq!(t.flags(), "0 0 1", "the terminal was left as it was");
}

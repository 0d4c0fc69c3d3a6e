//! The viewer in a real terminal (tmux): keys reach it, the inspector shows its fields,
//! and the terminal is restored after `q` and after SIGTERM. Skipped, with a note, when
//! tmux is not installed (CI installs it).

use std::process::Command;
use std::thread::sleep;
use std::time::{Duration, Instant};

mod lifecycle;
mod screen;

struct Tmux {
    socket: String,
}

impl Tmux {
    fn new(tag: &str) -> Option<Self> {
        Self::with_shell(tag, "sh")
    }

    /// A session running `shell` (a job-control shell for Ctrl-Z).
    fn with_shell(tag: &str, shell: &str) -> Option<Self> {
        Self::sized(tag, shell, 130, 40)
    }

    /// A session of `cols × rows` running `shell`.
    fn sized(tag: &str, shell: &str, cols: u16, rows: u16) -> Option<Self> {
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
                &cols.to_string(),
                "-y",
                &rows.to_string(),
                shell,
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
        self.wait_until(|s| s.contains(needle))
    }

    /// The screen once `done` holds for it, or after ten seconds.
    fn wait_until(&self, done: impl Fn(&str) -> bool) -> String {
        let start = Instant::now();
        loop {
            let s = self.screen();
            if done(&s) || start.elapsed() > Duration::from_secs(10) {
                return s;
            }
            sleep(Duration::from_millis(100));
        }
    }

    /// The screen once `done` holds for it and two captures 100 ms apart are the same
    /// (a frame is not caught half written), or after ten seconds.
    fn wait_settled(&self, done: impl Fn(&str) -> bool) -> String {
        let last = std::cell::RefCell::new(String::new());
        self.wait_until(|s| {
            let same = *last.borrow() == s;
            *last.borrow_mut() = s.to_string();
            same && done(s)
        })
    }

    /// The screen once the shell has printed the viewer's exit status (the `EXIT=`
    /// in the typed command line does not count).
    fn wait_for_exit(&self) -> String {
        self.wait_until(|s| s.lines().any(|l| l.starts_with("EXIT=")))
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
        self.assert_restored_with(0);
    }

    /// The viewer exited with `code` and left the terminal as it found it.
    fn assert_restored_with(&self, code: i32) {
        let s = self.wait_for_exit();
        assert!(
            s.contains(&format!("EXIT={code}")),
            "viewer did not exit with {code}:\n{s}"
        );
        // No answer to the viewer's pacing queries leaked to the shell.
        assert!(!s.contains("[?"), "terminal replies leaked:\n{s}");
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

/// The status line (the screen's last non-empty row).
fn status(screen: &str) -> &str {
    screen
        .lines()
        .rfind(|l| !l.trim().is_empty())
        .unwrap_or_default()
}

/// The selected cell, from the inspector's first line (`cell (x,y)`).
fn selected_cell(screen: &str) -> Option<(i32, i32)> {
    let at = screen.find("cell (")? + "cell (".len();
    let rest = &screen[at..];
    let (x, rest) = rest.split_once(',')?;
    let (y, _) = rest.split_once(')')?;
    Some((x.trim().parse().ok()?, y.trim().parse().ok()?))
}

/// The model's part of the screen: every row, cut before column `cols`.
fn model_rows(screen: &str, cols: usize) -> String {
    screen
        .lines()
        .map(|l| l.chars().take(cols).collect::<String>())
        .collect::<Vec<_>>()
        .join("\n")
}

impl Tmux {
    /// The viewer's process: the child of the pane's shell.
    fn viewer_pid(&self) -> String {
        let shell = self
            .run(&["display", "-p", "-t", "t", "#{pane_pid}"])
            .unwrap_or_default();
        let out = Command::new("pgrep")
            .args(["-P", shell.trim()])
            .output()
            .expect("pgrep");
        String::from_utf8_lossy(&out.stdout).trim().to_string()
    }

    fn signal(&self, sig: &str) {
        let pid = self.viewer_pid();
        let ok = Command::new("kill").args([sig, &pid]).status();
        assert!(ok.is_ok_and(|s| s.success()), "kill {sig} {pid}");
    }
}

/// Whether a process is gone (or only a zombie waiting to be reaped).
fn gone(pid: &str) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat")).map_or(true, |s| {
        s.rsplit(')')
            .next()
            .is_some_and(|r| r.trim_start().starts_with('Z'))
    })
}

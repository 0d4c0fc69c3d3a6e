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
    t.keys(&["i"]);
    let s = t.wait_for("inspector");
    for field in ["inspector", "samples", "line", "paused", "click or arrows"] {
        assert!(s.contains(field), "missing {field}:\n{s}");
    }
    // The cursor lands on the model: its selected sample is covered.
    let selected = s.lines().find(|l| l.contains("│>s")).unwrap_or_default();
    assert!(
        !selected.is_empty() && !selected.contains("not covered"),
        "the cursor is not on the model:\n{s}"
    );
    // Frozen: the model stays still while the numbers are read.
    let view_cols = 130 - 58;
    let a = model_rows(&t.screen(), view_cols);
    sleep(Duration::from_millis(400));
    assert_eq!(
        a,
        model_rows(&t.screen(), view_cols),
        "the model moved in inspect mode"
    );
    // Shift+Right moves the cursor 8 cells, Right one.
    let (x0, y0) = selected_cell(&t.screen()).expect("a selected cell");
    t.keys(&["S-Right", "Right", "Down"]);
    sleep(Duration::from_millis(300));
    assert_eq!(selected_cell(&t.screen()), Some((x0 + 9, y0 + 1)));
    // Space spins the model again, the inspector still open.
    t.keys(&[" "]);
    sleep(Duration::from_millis(400));
    let s = t.screen();
    assert!(
        s.contains("inspector") && !status(&s).contains("paused"),
        "{s}"
    );
    assert_ne!(
        model_rows(&s, view_cols),
        a,
        "space did not resume the spin"
    );
    t.keys(&["?"]);
    assert!(t.wait_for("keys").contains("quit"));
    t.keys(&["Escape", "q"]);
    t.assert_restored();
}

/// The panel's lines at the usual sizes: every field on one row, never split.
#[test]
fn panel_fields_are_never_split() {
    for (cols, rows) in [(140, 45), (200, 60)] {
        let Some(t) = Tmux::sized("panel", "sh", cols, rows) else {
            eprintln!("tmux not installed: skipping the terminal end-to-end test");
            return;
        };
        t.start_viewer();
        t.keys(&["i"]);
        let s = t.wait_for("overdraw");
        // Each label has its values beside it, on the same row.
        for (label, values) in [
            ("area2", 1),
            ("persp", 3),
            ("F01", 1),
            ("1/w", 1),
            ("incrNE", 1),
        ] {
            assert!(
                s.lines().any(|l| numbers_after(l, label) >= values),
                "{cols}x{rows}: `{label}` without its {values} value(s) on its row:\n{s}"
            );
        }
        assert!(
            s.lines()
                .any(|l| l.contains("touched") && l.contains("│>s")),
            "{cols}x{rows}: the touched count left its sample's row:\n{s}"
        );
        // No row of the panel ends inside a number or a label.
        for l in s.lines().filter(|l| l.contains('│')) {
            let inner = l.rsplit('│').nth(1).unwrap_or_default();
            assert!(
                !inner.trim_end().ends_with(['(', '-']),
                "{cols}x{rows}: a row ends mid-field: {inner:?}"
            );
        }
        t.keys(&["q"]);
    }
}

/// How many numbers follow `label` on `line` (the panel's border excluded).
fn numbers_after(line: &str, label: &str) -> usize {
    let Some(at) = line.find(&format!("{label} ")) else {
        return 0;
    };
    line[at + label.len()..]
        .split_whitespace()
        .take_while(|w| w.trim_end_matches('│').parse::<f64>().is_ok())
        .count()
}

/// At 80×24 the side panel does not fit: the inspector goes below the model.
#[test]
fn the_inspector_works_at_80x24() {
    let Some(t) = Tmux::sized("small", "sh", 80, 24) else {
        eprintln!("tmux not installed: skipping the terminal end-to-end test");
        return;
    };
    t.start_viewer();
    assert!(status(&t.screen()).contains("? help"), "{}", t.screen());
    t.keys(&["i"]);
    let s = t.wait_for("inspector");
    assert!(s.contains("inspector") && s.contains("cell ("), "{s}");
    // The panel is below the model: its title row starts at the left edge.
    let title = s
        .lines()
        .find(|l| l.contains("inspector"))
        .unwrap_or_default();
    assert!(title.starts_with('┌'), "not below the model:\n{s}");
    assert!(status(&s).contains("? help"), "status lost `? help`:\n{s}");
    t.keys(&["Escape", "q"]);
    t.assert_restored();
}

/// The frame rate shown never exceeds the cap.
#[test]
fn fps_never_exceeds_the_cap() {
    let Some(t) = Tmux::new("fps") else {
        eprintln!("tmux not installed: skipping the terminal end-to-end test");
        return;
    };
    t.start_viewer_with("TERM=xterm-256color LANG=C.UTF-8", "--fps 12");
    for _ in 0..8 {
        let s = t.screen();
        let line = status(&s);
        let fps: Option<f32> = line
            .split(" | ")
            .find_map(|f| f.strip_suffix(" fps").and_then(|n| n.trim().parse().ok()));
        if let Some(fps) = fps {
            assert!(fps <= 12.0, "{fps} fps above the cap: {line}");
        }
        sleep(Duration::from_millis(150));
    }
    t.keys(&["q"]);
    t.assert_restored();
}

/// The status line's timings name the way the frame was drawn (on one thread here),
/// in their short form too once the terminal narrows.
#[test]
fn the_status_line_names_the_drawing_threads() {
    let Some(t) = Tmux::sized("threads", "sh", 260, 40) else {
        eprintln!("tmux not installed: skipping the terminal end-to-end test");
        return;
    };
    t.start_viewer_with("TERM=xterm-256color LANG=C.UTF-8", "--threads 1");
    let s = t.wait_until(|s| status(s).contains(" ms, "));
    assert!(status(&s).contains(" ms, 1 thread |"), "{}", status(&s));
    t.run(&["resize-window", "-t", "t", "-x", "140", "-y", "40"]);
    let s = t.wait_until(|s| status(s).contains("| raster+shade "));
    assert!(status(&s).contains(" ms, 1 thread |"), "{}", status(&s));
    t.keys(&["q"]);
    t.assert_restored();
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

#[test]
fn ending_signals_restore_the_terminal_and_set_the_exit_status() {
    for (sig, code) in [("-TERM", 143), ("-INT", 130), ("-QUIT", 131), ("-HUP", 129)] {
        let Some(t) = Tmux::new("term") else {
            eprintln!("tmux not installed: skipping the terminal end-to-end test");
            return;
        };
        t.start_viewer();
        t.signal(sig);
        t.assert_restored_with(code);
    }
}

#[test]
fn ctrl_q_and_esc_do_not_quit() {
    let Some(t) = Tmux::new("ctrlq") else {
        eprintln!("tmux not installed: skipping the terminal end-to-end test");
        return;
    };
    t.start_viewer();
    t.keys(&["C-q", "Escape", "Q"]);
    sleep(Duration::from_millis(800));
    assert_eq!(t.flags(), "1 1 0", "the viewer quit:\n{}", t.screen());
    t.keys(&["q"]);
    t.assert_restored();
}

#[test]
fn the_viewer_leaves_with_its_terminal() {
    for keys in [&[][..], &[" "][..]] {
        let Some(t) = Tmux::new("hangup") else {
            eprintln!("tmux not installed: skipping the terminal end-to-end test");
            return;
        };
        t.start_viewer();
        t.keys(keys);
        sleep(Duration::from_millis(300));
        let pid = t.viewer_pid();
        assert!(!pid.is_empty() && !gone(&pid));
        t.run(&["kill-server"]);
        let start = Instant::now();
        while !gone(&pid) && start.elapsed() < Duration::from_secs(3) {
            sleep(Duration::from_millis(50));
        }
        assert!(
            start.elapsed() < Duration::from_secs(1),
            "viewer {pid} (keys {keys:?}) still running {:?} after its terminal closed",
            start.elapsed()
        );
    }
}

#[test]
fn ctrl_z_suspends_and_fg_redraws() {
    let Some(t) = Tmux::with_shell("suspend", "bash --norc --noprofile -i") else {
        eprintln!("tmux not installed: skipping the terminal end-to-end test");
        return;
    };
    // No `; echo EXIT` here: bash would run it as soon as the job stops.
    let cmd = format!("TERM=xterm-256color {}", env!("CARGO_BIN_EXE_termrast"));
    t.keys(&["clear", "Enter", &cmd, "Enter"]);
    assert!(
        t.wait_for("fps |").contains("fps |"),
        "viewer did not start"
    );
    t.keys(&["C-z"]);
    let s = t.wait_for("Stopped");
    assert!(s.contains("Stopped"), "not suspended:\n{s}");
    assert_eq!(
        t.flags(),
        "0 0 1",
        "suspended without restoring the terminal"
    );
    t.keys(&["clear", "Enter", "fg", "Enter"]);
    let s = t.wait_for("fps |");
    assert!(s.contains("fps |"), "not redrawn after fg:\n{s}");
    assert_eq!(t.flags(), "1 1 0");
    // SIGTSTP from elsewhere (`kill -TSTP`) does the same.
    t.signal("-TSTP");
    let s = t.wait_for("Stopped");
    assert!(s.contains("Stopped"), "not suspended by SIGTSTP:\n{s}");
    assert_eq!(
        t.flags(),
        "0 0 1",
        "SIGTSTP left the terminal as the viewer had it"
    );
    t.keys(&["clear", "Enter", "fg", "Enter"]);
    let s = t.wait_for("fps |");
    assert!(s.contains("fps |"), "not redrawn after the second fg:\n{s}");
    assert_eq!(t.flags(), "1 1 0");
    t.keys(&["q"]);
    t.keys(&["echo EXIT=$?", "Enter"]);
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
    let s = t.wait_for_exit();
    assert!(
        s.contains("TERM=dumb") && s.contains("termrast render"),
        "{s}"
    );
    assert!(s.contains("EXIT=1"), "{s}");
    assert_eq!(t.flags(), "0 0 1", "the terminal was left as it was");
}

/// The colours tmux shows (`capture-pane -e`) for a model of two materials, red on
/// the left and blue on the right, and the loader's warning on the terminal after `q`.
#[test]
fn a_model_shows_its_materials_colours_in_the_terminal() {
    let Some(t) = Tmux::new("materials") else {
        eprintln!("tmux not installed: skipped");
        return;
    };
    let dir = std::env::temp_dir().join(format!("termrast-tmux-mtl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("c.mtl"),
        "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\nKd 1 2\n",
    )
    .unwrap();
    let obj = dir.join("two.obj");
    std::fs::write(
        &obj,
        "mtllib c.mtl\nv -1 -1 0\nv 0 -1 0\nv 0 1 0\nv -1 1 0\nv 0 -1 0\nv 1 -1 0\nv 1 1 0\nv 0 1 0\n\
         usemtl red\nf 1 2 3 4\nusemtl blue\nf 5 6 7 8\n",
    )
    .unwrap();
    t.start_viewer_with(
        "TERM=xterm-256color COLORTERM=truecolor LANG=C.UTF-8",
        &format!("{} --glyphs blocks", obj.display()),
    );
    // Paused, so the square faces the camera and stays.
    t.keys(&["Space"]);
    sleep(Duration::from_millis(500));
    let shown = t
        .run(&["capture-pane", "-e", "-p", "-t", "t"])
        .unwrap_or_default();
    let sgr = truecolor_colours(&shown);
    let red = sgr
        .iter()
        .filter(|c| c[0] > 100 && c[1] < 30 && c[2] < 30)
        .count();
    let blue = sgr
        .iter()
        .filter(|c| c[2] > 100 && c[0] < 30 && c[1] < 30)
        .count();
    assert!(
        red > 0 && blue > 0,
        "red {red}, blue {blue} colours shown:\n{shown}"
    );
    t.keys(&["q"]);
    let after = t.wait_for_exit();
    assert!(
        after.contains("warning:") && after.contains("c.mtl:5:"),
        "{after}"
    );
}

/// The truecolor foreground and background colours (`38;2;r;g;b`, `48;2;…`) in
/// captured text.
fn truecolor_colours(text: &str) -> Vec<[u8; 3]> {
    let mut out = Vec::new();
    for part in text.split("\x1b[").skip(1) {
        let params: Vec<&str> = part
            .split(|c: char| c.is_ascii_alphabetic())
            .next()
            .unwrap_or("")
            .split(';')
            .collect();
        let mut i = 0;
        while i + 4 < params.len() {
            if (params[i] == "38" || params[i] == "48") && params.get(i + 1) == Some(&"2") {
                let c: Vec<u8> = params[i + 2..(i + 5).min(params.len())]
                    .iter()
                    .filter_map(|p| p.parse().ok())
                    .collect();
                if let [r, g, b] = c[..] {
                    out.push([r, g, b]);
                }
                i += 5;
            } else {
                i += 1;
            }
        }
    }
    out
}

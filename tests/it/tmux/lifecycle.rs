//! The viewer's life in tmux: signals, Ctrl-Q and Esc, a terminal that goes away,
//! Ctrl-Z and `fg`, a non-UTF-8 locale and a dumb terminal.

use std::thread::sleep;
use std::time::{Duration, Instant};

use super::{Tmux, gone};

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

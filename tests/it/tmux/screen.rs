//! What the viewer shows in tmux: the inspector and its panel at several sizes, the
//! frame-rate cap, the status line's threads, a model's material colours, a terminal
//! larger than the viewer uses.

use std::thread::sleep;
use std::time::Duration;

use termrast::tui::app::{MAX_COLS, MAX_ROWS};

use super::{Tmux, model_rows, selected_cell, status};

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
        // The whole panel, and not a frame caught half written.
        let s = t.wait_settled(|s| s.contains("overdraw") && s.contains("incrNE"));
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
    let line = status(&s);
    assert!(
        line.contains("| raster+shade ") && !line.contains("transform"),
        "{line}"
    );
    assert!(line.contains(" ms, 1 thread |"), "{line}");
    t.keys(&["q"]);
    t.assert_restored();
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

/// A terminal larger than the viewer uses shows it in its top-left `MAX_COLS` ×
/// `MAX_ROWS` cells: the status line on the last of those rows, nothing right of them;
/// and the viewer follows the terminal down to an ordinary size.
#[test]
fn a_huge_terminal_shows_the_viewer_in_its_corner() {
    let (cols, rows) = (MAX_COLS + 88, MAX_ROWS + 44);
    let Some(t) = Tmux::sized("huge", "sh", cols, rows) else {
        eprintln!("tmux not installed: skipping the terminal end-to-end test");
        return;
    };
    t.start_viewer_with("TERM=xterm-256color LANG=C.UTF-8", "");
    let s = t.wait_until(|s| status(s).contains(" ms, "));
    let lines: Vec<&str> = s.lines().collect();
    let last = lines.iter().rposition(|l| !l.trim().is_empty());
    assert_eq!(last, Some(usize::from(MAX_ROWS) - 1), "{}", status(&s));
    let widest = lines.iter().map(|l| l.trim_end().chars().count()).max();
    assert!(widest <= Some(usize::from(MAX_COLS)), "{widest:?} columns");
    // A terminal that clears its screen on a resize (simulated: the clear written to
    // the pane's terminal, then a resize that leaves the viewer's size alone) gets
    // the whole screen again, the status line's unchanging start included.
    let row = usize::from(MAX_ROWS) - 1;
    let start = |s: &str| s.lines().nth(row).unwrap_or_default().trim().to_string();
    let before = start(&s);
    let head: String = before.chars().take(12).collect();
    assert!(head.len() >= 6, "{before}");
    let tty = t.run(&["display", "-p", "-t", "t", "#{pane_tty}"]);
    let tty = tty.expect("the pane's terminal").trim().to_string();
    std::fs::OpenOptions::new()
        .write(true)
        .open(&tty)
        .and_then(|mut f| std::io::Write::write_all(&mut f, b"\x1b[H\x1b[2J"))
        .expect("the pane's terminal takes the clear");
    let (c, r) = ((cols + 10).to_string(), (rows + 10).to_string());
    t.run(&["resize-window", "-t", "t", "-x", &c, "-y", &r]);
    let s = t.wait_until(|s| start(s).starts_with(&head));
    assert!(
        start(&s).starts_with(&head),
        "{head:?} again: {:?}",
        start(&s)
    );
    t.run(&["resize-window", "-t", "t", "-x", "120", "-y", "40"]);
    let bottom = |s: &str| {
        let lines: Vec<&str> = s.lines().collect();
        lines.iter().rposition(|l| !l.trim().is_empty())
    };
    let s = t.wait_until(|s| bottom(s) == Some(39) && status(s).contains(" ms, "));
    assert_eq!(bottom(&s), Some(39), "the status line on the last row: {s}");
    t.keys(&["q"]);
    t.assert_restored();
}

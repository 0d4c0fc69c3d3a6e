//! The viewer behind a slow link (`termrast::slowlink`): through a pseudo-terminal
//! drained at a set rate, every key press reaches the emulated screen, frames keep
//! arriving (their queries are answered), the link's buffer stays far from full, and
//! on a link too slow for whole frames each frame keeps to its budget.

use termrast::slowlink::{self, Config, Report};

fn run(rate: u64) -> Option<Report> {
    if !cfg!(target_os = "linux") {
        eprintln!("the link harness needs Linux: skipping");
        return None;
    }
    let mut config = Config::new(env!("CARGO_BIN_EXE_termrast").into(), "teapot", rate);
    config.presses = 3;
    config.args.extend(["--glyphs".into(), "braille".into()]);
    let r = slowlink::run(&config).expect("the harness runs");
    assert_eq!(r.latencies.len(), 3);
    assert!(
        r.latencies.iter().all(Option::is_some),
        "a key's effect never showed: {r:?}"
    );
    assert!(r.delivered_fps > 1.0, "frames stalled: {r:?}");
    Some(r)
}

#[test]
fn keys_get_through_a_slow_link() {
    let Some(r) = run(250_000) else { return };
    // Pacing keeps at most a couple of frames in the link, far from its 2 MB.
    assert!(
        r.max_buffered < 256 << 10,
        "the link's buffer filled: {r:?}"
    );
}

/// At 60 kB/s a whole teapot frame (about 40 kB) would take most of a second; the
/// budget (60 ms of the measured rate, 3.6 kB) keeps frames small.
#[test]
fn frames_keep_to_the_budget_of_a_slower_link() {
    let Some(r) = run(60_000) else { return };
    let per_frame = r.bytes_per_second / r.delivered_fps;
    assert!(
        per_frame < 12_000.0,
        "{per_frame:.0} bytes per frame: {r:?}"
    );
}

/// How often each of the 16 colours shows on an emulated screen above its status line:
/// a cell's background, and its foreground where it has a glyph.
fn index_counts(screen: &vt100::Screen, rows: u16, cols: u16) -> [usize; 16] {
    let mut n = [0; 16];
    for r in 0..rows.saturating_sub(1) {
        for c in 0..cols {
            let Some(cell) = screen.cell(r, c) else {
                continue;
            };
            let inked = !cell.contents().trim().is_empty();
            for (color, shows) in [(cell.fgcolor(), inked), (cell.bgcolor(), true)] {
                if let (vt100::Color::Idx(i @ 0..=15), true) = (color, shows) {
                    n[usize::from(i)] += 1;
                }
            }
        }
    }
    n
}

/// A 16-colour terminal that reports its palette (OSC 4) gets frames fitted to it: on
/// one whose index 9 is white and 15 red, the white teapot's light cells are drawn in
/// 9, never in 15; on one that does not answer, xterm's palette is assumed and they
/// are drawn in 15 (or 7), never in 9.
#[test]
fn sixteen_colour_frames_are_fitted_to_the_palette_the_terminal_reports() {
    if !cfg!(target_os = "linux") {
        eprintln!("the link harness needs Linux: skipping");
        return;
    }
    let mut config = Config::new(env!("CARGO_BIN_EXE_termrast").into(), "teapot", 1 << 20);
    config
        .args
        .extend(["--glyphs", "blocks", "--color", "16"].map(String::from));
    let (cols, rows) = (config.cols, config.rows);
    let xterm = slowlink::screen_after(&config, std::time::Duration::from_millis(600))
        .expect("the harness runs");
    let mut palette = termrast::terminal::Palette::XTERM.ansi;
    palette.swap(9, 15);
    config.palette = Some(palette);
    let answered = slowlink::screen_after(&config, std::time::Duration::from_millis(600))
        .expect("the harness runs");
    let (x, a) = (
        index_counts(&xterm, rows, cols),
        index_counts(&answered, rows, cols),
    );
    assert!(x[15] + x[7] > 50 && x[9] == 0, "no answer: {x:?}");
    assert!(a[9] > 50 && a[15] == 0, "answered palette: {a:?}");
}

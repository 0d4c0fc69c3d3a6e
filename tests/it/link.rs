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

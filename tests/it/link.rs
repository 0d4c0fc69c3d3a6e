//! The viewer behind a slow link (`termrast::slowlink`): through a pseudo-terminal
//! drained at 250 kB/s, every key press reaches the emulated screen, frames keep
//! arriving (their queries are answered), and the link's buffer never fills.

#[test]
fn keys_get_through_a_slow_link() {
    if !cfg!(target_os = "linux") {
        eprintln!("the link harness needs Linux: skipping");
        return;
    }
    let mut config =
        termrast::slowlink::Config::new(env!("CARGO_BIN_EXE_termrast").into(), "teapot", 250_000);
    config.presses = 3;
    config.args.extend(["--glyphs".into(), "braille".into()]);
    let r = termrast::slowlink::run(&config).expect("the harness runs");
    assert_eq!(r.latencies.len(), 3);
    assert!(
        r.latencies.iter().all(Option::is_some),
        "a key's effect never showed: {r:?}"
    );
    assert!(r.delivered_fps > 1.0, "frames stalled: {r:?}");
    // Pacing keeps at most a couple of frames in the link, far from its 2 MB.
    assert!(
        r.max_buffered < 512 << 10,
        "the link's buffer filled: {r:?}"
    );
}

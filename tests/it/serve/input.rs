//! Random bytes as a watcher's keyboard, through the session's input handling.

use proptest::prelude::*;
use termrast::tui::app::App;
use termrast::tui::remote::{self, Remote, RenderGate};
use termrast::tui::{RunOptions, ViewError, Wake};

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]
    /// Any bytes as a watcher's keyboard (split anywhere, resizes between; weighted
    /// towards keys and sequences): the
    /// session ends cleanly when its input does, with its screen restored.
    #[test]
    fn random_input_never_breaks_a_session(
        chunks in prop::collection::vec(prop::collection::vec(crate::input::byte(), 0..64), 0..12),
        sizes in prop::collection::vec((0u16..300, 0u16..120), 0..3),
    ) {
        let scene = termrast::scene::Scene::for_model("teapot").unwrap();
        let app = App::new(scene, termrast::tui::viewport::ViewSettings::default());
        let (tx, rx) = std::sync::mpsc::sync_channel(64);
        for (i, c) in chunks.into_iter().enumerate() {
            tx.send(Wake::Bytes(c)).unwrap();
            if let Some(&(w, h)) = sizes.get(i) {
                tx.send(Wake::Resize(w.max(1), h.max(1))).unwrap();
            }
        }
        tx.send(Wake::Eof).unwrap();
        let gate = RenderGate::new(1);
        let mut out = Vec::new();
        let options = RunOptions { fps: 240, max_rate: None, paced: false, ask_palette: false };
        let remote = Remote { out: &mut out, cols: 40, rows: 12, wakes: rx, gate: Some(&gate), idle: None };
        let (r, bytes) = remote::run(app, options, remote);
        prop_assert!(matches!(r, Ok(()) | Err(ViewError::Gone)), "{r:?}");
        prop_assert_eq!(bytes as usize, out.len());
        prop_assert!(out.ends_with(b"\x1b[?25h"), "screen not restored");
    }
}

/// A viewer whose every frame takes longer than its period still reads its keys:
/// `q` queued behind the first frame ends the session.
#[test]
fn keys_are_read_when_frames_overrun_their_period() {
    let scene = termrast::scene::Scene::for_model("teapot").unwrap();
    let app = App::new(scene, termrast::tui::viewport::ViewSettings::default());
    let (tx, rx) = std::sync::mpsc::sync_channel(4);
    tx.send(Wake::Bytes(b"q".to_vec())).unwrap();
    let (done_tx, done_rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let gate = RenderGate::new(1);
        let mut out = Vec::new();
        // A period of 0.1 ms: no frame is drawn within it.
        let options = RunOptions {
            fps: 10_000,
            max_rate: None,
            paced: false,
            ask_palette: false,
        };
        let remote = Remote {
            out: &mut out,
            cols: 120,
            rows: 40,
            wakes: rx,
            gate: Some(&gate),
            idle: None,
        };
        let _ = done_tx.send(remote::run(app, options, remote).0.is_ok());
        drop(tx);
    });
    let ended = done_rx.recv_timeout(std::time::Duration::from_secs(30));
    assert_eq!(ended, Ok(true), "q was not read while frames kept coming");
}

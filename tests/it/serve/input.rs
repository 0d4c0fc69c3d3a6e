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

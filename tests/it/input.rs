//! Random bytes as a watcher's keyboard input, through the path a session's input
//! takes (the input parser, then the viewer's key and mouse handling, then a frame):
//! nothing panics, pending input stays bounded, and the view stays drawable.

use std::time::{Duration, Instant};

use proptest::prelude::*;
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use termrast::scene::Scene;
use termrast::terminal::input::{Input, MAX_SEQUENCE, Parser};
use termrast::tui::app::App;
use termrast::tui::viewport::ViewSettings;

/// Bytes weighted towards what makes sequences: ESC, CSI and OSC openers,
/// parameters, final bytes, the keys the viewer knows, and anything at all.
pub fn byte() -> impl Strategy<Value = u8> {
    prop_oneof![
        3 => Just(0x1B),
        2 => prop::sample::select(b"[]O<;?0123456789Mm~ABCDHFPQRSc\x07\\".to_vec()),
        2 => prop::sample::select(b"qiwgcbp?+-hjklHJKL[] \t\r".to_vec()),
        3 => any::<u8>(),
    ]
}

/// Reads as a session gets them: chunks of bytes, each after a pause in ms.
fn reads() -> impl Strategy<Value = Vec<(Vec<u8>, u64)>> {
    prop::collection::vec((prop::collection::vec(byte(), 0..48), 0u64..1500), 1..24)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn random_keyboard_input_leaves_the_viewer_drawable(seq in reads()) {
        let mut app = App::new(Scene::for_model("teapot").unwrap(), ViewSettings::default());
        let mut parser = Parser::default();
        let mut term = Terminal::new(TestBackend::new(48, 14)).unwrap();
        let mut now = Instant::now();
        for (i, (bytes, pause)) in seq.iter().enumerate() {
            now += Duration::from_millis(*pause);
            parser.feed(bytes, now);
            while let Some(input) = parser.next(now) {
                match input {
                    Input::Event(e) => {
                        app.handle(&e);
                    }
                    Input::PaletteColor(i, c) => {
                        app.settings.terminal_color(i, c);
                    }
                    Input::DeviceAttributes => {}
                }
            }
            prop_assert!(parser.pending() <= MAX_SEQUENCE, "{} bytes pending", parser.pending());
            if app.quit {
                break;
            }
            if i % 4 == 3 {
                term.draw(|f| app.draw(f)).unwrap();
            }
        }
        // Whatever the input left pending resolves by itself once its wait is over.
        now += Duration::from_secs(2);
        while let Some(input) = parser.next(now) {
            if let Input::Event(e) = input {
                app.handle(&e);
            }
        }
        prop_assert_eq!(parser.pending(), 0);
        prop_assert!(parser.deadline().is_none());
        prop_assert!((0.2..=20.0).contains(&app.settings.zoom));
        prop_assert!(app.settings.angle.is_finite() && app.settings.tilt.is_finite());
        term.draw(|f| app.draw(f)).unwrap();
        // The last row is the status line, whatever mode the input left.
        let buf = term.backend().buffer();
        let status: String = (0..48).map(|x| buf[(x, 13)].symbol().to_string()).collect();
        prop_assert!(!status.trim().is_empty(), "no status line");
    }
}

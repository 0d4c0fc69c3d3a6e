use proptest::prelude::*;
use ratatui::Terminal;
use ratatui::buffer::Cell;
use ratatui::style::{Color, Modifier};

use super::LinkBackend;
use crate::terminal::color::delta_e;

const COLS: u16 = 12;
const ROWS: u16 = 5;

/// A frame: per cell a symbol and two colours from a small set, so that frames
/// share cells and colours differ by a little as well as a lot.
type Frame = Vec<(char, [u8; 3], [u8; 3], bool)>;

fn frames() -> impl Strategy<Value = Vec<Frame>> {
    let cell = (
        prop::sample::select(vec![' ', '▀', '⣿', 'a', '🭂', '█']),
        prop::array::uniform3(prop::sample::select(vec![0u8, 1, 2, 100, 101, 250])),
        prop::array::uniform3(prop::sample::select(vec![0u8, 3, 128, 129, 255])),
        prop::bool::weighted(0.1),
    );
    prop::collection::vec(prop::collection::vec(cell, usize::from(COLS * ROWS)), 1..6)
}

fn draw(t: &mut Terminal<LinkBackend<Vec<u8>>>, frame: &Frame) -> Vec<u8> {
    t.draw(|f| {
        let buf = f.buffer_mut();
        for (i, &(ch, fg, bg, rev)) in frame.iter().enumerate() {
            let (x, y) = (i as u16 % COLS, i as u16 / COLS);
            let c: &mut Cell = &mut buf[(x, y)];
            c.set_char(ch)
                .set_fg(Color::Rgb(fg[0], fg[1], fg[2]))
                .set_bg(Color::Rgb(bg[0], bg[1], bg[2]));
            if rev {
                c.set_style(ratatui::style::Style::default().add_modifier(Modifier::REVERSED));
            }
        }
    })
    .unwrap();
    std::mem::take(t.backend_mut().writer())
}

fn rgb(c: vt100::Color) -> Option<[u8; 3]> {
    match c {
        vt100::Color::Rgb(r, g, b) => Some([r, g, b]),
        _ => None,
    }
}

/// The largest colour error of the emulated screen against the frame, if every
/// cell shows the frame's character and attributes.
fn screen_error(p: &vt100::Parser, frame: &Frame) -> Result<f32, String> {
    let mut worst = 0f32;
    for (i, &(ch, fg, bg, rev)) in frame.iter().enumerate() {
        let (x, y) = (i as u16 % COLS, i as u16 / COLS);
        let cell = p.screen().cell(y, x).unwrap();
        if cell.contents() != ch.to_string() || cell.inverse() != rev {
            return Err(format!("({x},{y}) shows {:?}, not {ch:?}", cell.contents()));
        }
        let (Some(f), Some(b)) = (rgb(cell.fgcolor()), rgb(cell.bgcolor())) else {
            return Err(format!("({x},{y}) lost its colours"));
        };
        worst = worst.max(delta_e(f, fg)).max(delta_e(b, bg));
    }
    Ok(worst)
}

fn terminal(threshold: f32) -> Terminal<LinkBackend<Vec<u8>>> {
    let mut b = LinkBackend::with_size(Vec::new(), COLS, ROWS);
    b.threshold = threshold;
    Terminal::new(b).unwrap()
}

proptest! {
    /// What the emulator shows is the frame exactly (threshold 0), or within the
    /// threshold, after every frame of a random sequence; the same frame again sends
    /// nothing once it is exact.
    #[test]
    fn the_screen_is_the_frame(seq in frames(), exact in any::<bool>()) {
        let threshold = if exact { 0.0 } else { super::DELTA_E };
        let mut t = terminal(threshold);
        let nz = |v| std::num::NonZeroU16::new(v).unwrap();
        let mut p = vt100::Parser::new(nz(ROWS), nz(COLS), 0);
        for frame in &seq {
            p.process(&draw(&mut t, frame));
            let e = screen_error(&p, frame).map_err(TestCaseError::fail)?;
            prop_assert!(e <= threshold + 1e-6, "colour error {e}");
        }
        let last = seq.last().unwrap();
        // A still frame: the next draw makes it exact, the one after sends nothing.
        p.process(&draw(&mut t, last));
        prop_assert_eq!(screen_error(&p, last).map_err(TestCaseError::fail)?, 0.0);
        prop_assert!(draw(&mut t, last).is_empty());
    }
}

#[test]
fn small_colour_changes_are_not_sent_and_big_ones_are() {
    let mut t = terminal(super::DELTA_E);
    let n = usize::from(COLS * ROWS);
    let frame = |v: u8| -> Frame { vec![('█', [v, v, v], [0, 0, 0], false); n] };
    let first = draw(&mut t, &frame(100));
    assert!(!first.is_empty());
    // One level of 255 is far below the threshold: only the still frame's exact
    // values follow, one frame later.
    assert!(draw(&mut t, &frame(101)).is_empty());
    assert!(!draw(&mut t, &frame(101)).is_empty());
    assert!(draw(&mut t, &frame(101)).is_empty());
    assert!(draw(&mut t, &frame(200)).len() > n);
}

use proptest::prelude::*;
use ratatui::Terminal;
use ratatui::buffer::Cell;
use ratatui::style::{Color, Modifier};

use super::LinkBackend;
use crate::terminal::color::{delta_e, indexed_rgb};

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
        vt100::Color::Idx(i) if i >= 16 => Some(indexed_rgb(i)),
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
        // A plain space shows no foreground, a plain full block no background.
        let shows_fg = rev || ch != ' ';
        let shows_bg = rev || ch != '█';
        if shows_fg {
            let f = rgb(cell.fgcolor()).ok_or(format!("({x},{y}) lost its foreground"))?;
            worst = worst.max(delta_e(f, fg));
        }
        if shows_bg {
            let b = rgb(cell.bgcolor()).ok_or(format!("({x},{y}) lost its background"))?;
            worst = worst.max(delta_e(b, bg));
        }
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

/// One changed cell costs its move, one SGR sequence with only what changed, and the
/// glyph; a space's foreground is never written.
#[test]
fn sequences_are_minimal() {
    let mut t = terminal(0.0);
    let n = usize::from(COLS * ROWS);
    let mut frame: Frame = vec![('a', [1, 2, 3], [4, 5, 6], false); n];
    draw(&mut t, &frame);
    frame[2 * usize::from(COLS) + 5].1 = [7, 8, 9];
    assert_eq!(draw(&mut t, &frame), b"\x1b[3;6H\x1b[38;2;7;8;9ma");
    // Two neighbours: the second needs no move; the same pen, no SGR.
    frame[2 * usize::from(COLS) + 6].1 = [7, 8, 9];
    frame[2 * usize::from(COLS) + 5].2 = [4, 5, 7];
    assert_eq!(
        draw(&mut t, &frame),
        b"\x1b[3;6H\x1b[48;2;4;5;7ma\x1b[48;2;4;5;6ma"
    );
    // A space on the same background: only the background would show.
    frame[0] = (' ', [200, 0, 0], [4, 5, 6], false);
    assert_eq!(draw(&mut t, &frame), b"\x1b[H ");
}

/// A frame over budget sends every cell outside the model's area, then the model's
/// most visible changes within the budget; later frames send the rest, and the screen
/// ends exact.
#[test]
fn a_budget_sends_the_status_first_and_the_most_visible_changes() {
    let mut t = terminal(super::DELTA_E);
    let n = usize::from(COLS * ROWS);
    let cols = usize::from(COLS);
    let nz = |v| std::num::NonZeroU16::new(v).unwrap();
    let mut p = vt100::Parser::new(nz(ROWS), nz(COLS), 0);
    let grey = |v: u8| ('▀', [v, v, v], [0, 0, 0], false);
    let mut frame: Frame = vec![grey(40); n];
    p.process(&draw(&mut t, &frame));
    // The model is rows 0..4; the last row is the status line.
    t.backend_mut().bulk = Some(ratatui::layout::Rect::new(0, 0, COLS, ROWS - 1));
    t.backend_mut().budget = Some(60);
    for (i, c) in frame.iter_mut().enumerate() {
        // A slight change everywhere, a big one in one cell of the model.
        *c = grey(if i == 7 { 250 } else { 60 });
        if i >= n - cols {
            c.0 = 's';
        }
    }
    let bytes = draw(&mut t, &frame);
    p.process(&bytes);
    let screen = p.screen();
    assert!(
        (0..COLS).all(|x| screen.cell(ROWS - 1, x).unwrap().contents() == "s"),
        "the status line is sent in full"
    );
    let big = screen.cell(0, 7).unwrap().fgcolor();
    assert!(
        rgb(big).is_some_and(|c| delta_e(c, [250; 3]) <= super::DELTA_E),
        "the most visible change is sent: {big:?}"
    );
    // The status line went first; the model's part, after it, kept to the budget
    // (less than a cell over: the last cell sent may cross it).
    let model_part = bytes.len() - bytes.iter().rposition(|&b| b == b's').unwrap_or(0);
    assert!(model_part <= 60 + 30, "model part {model_part} bytes");
    // Still frames bring the rest, until the screen is exact.
    for _ in 0..40 {
        p.process(&draw(&mut t, &frame));
    }
    assert_eq!(screen_error(&p, &frame), Ok(0.0));
    assert!(draw(&mut t, &frame).is_empty());
}

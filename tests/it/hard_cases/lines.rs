//! Lines in every octant, clipped, with endpoints at ±10^6.

use super::*;

/// Pass: lines in each of the eight octants from one centre have one pixel per major
/// step and report eight different octants; clipped to a target, lines with endpoints
/// at ±10^6 draw exactly the unclipped walk's pixels inside it (the property tests
/// with an exact rational reference are in `lines.rs`).
#[test]
fn lines_in_every_octant_and_far_endpoints_clip_exactly() {
    let c = (50i64, 40i64);
    let ends = [
        (90, 55),
        (65, 90),
        (35, 90),
        (10, 55),
        (10, 25),
        (35, -10),
        (65, -10),
        (90, 25),
    ];
    let mut octants = Vec::new();
    for e in ends {
        let l = Line::new(c, e).expect("in range");
        octants.push(l.octant);
        let mut n = 0;
        l.draw(|_, _| n += 1, &mut NoTrace);
        assert_eq!(n, (e.0 - c.0).abs().max((e.1 - c.1).abs()) + 1);
    }
    octants.sort_unstable();
    octants.dedup();
    assert_eq!(octants.len(), 8);
    let (w, h) = (100i64, 80i64);
    for (a, b) in [
        ((-1_000_000, 37), (1_000_000, 41)),
        ((3, -1_000_000), (97, 1_000_000)),
        ((-1_000_000, -1_000_000), (1_000_000, 1_000_000)),
        ((1_000_000, -999_999), (-1_000_000, 1_000_077)),
    ] {
        let l = Line::new(a, b).expect("in range");
        let mut clipped = Vec::new();
        l.draw_clipped(w, h, |x, y| clipped.push((x, y)), &mut NoTrace);
        let mut inside = Vec::new();
        l.draw(
            |x, y| {
                if (0..w).contains(&x) && (0..h).contains(&y) {
                    inside.push((x, y));
                }
            },
            &mut NoTrace,
        );
        assert!(!clipped.is_empty(), "{a:?}->{b:?}");
        assert_eq!(clipped, inside, "{a:?}->{b:?}");
    }
}

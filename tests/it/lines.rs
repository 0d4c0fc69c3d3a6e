//! Midpoint lines: the classic worked examples, all octants, symmetry, an exact reference,
//! clipping and connectivity.

use proptest::prelude::*;
use termrast::raster::line::{Line, Move, NoTrace, Step};

fn pixels(a: (i64, i64), b: (i64, i64)) -> Vec<(i64, i64)> {
    let mut v = Vec::new();
    Line::new(a, b)
        .unwrap()
        .draw(|x, y| v.push((x, y)), &mut NoTrace);
    v
}

fn trace(a: (i64, i64), b: (i64, i64)) -> Vec<Step> {
    let mut steps = Vec::new();
    Line::new(a, b).unwrap().draw(|_, _| {}, &mut steps);
    steps
}

fn decisions(steps: &[Step]) -> Vec<(i64, Move)> {
    steps
        .iter()
        .filter_map(|s| s.decision.map(|(d, m, _)| (d, m)))
        .collect()
}

#[test]
fn worked_example() {
    // (5,8)→(9,11): d = 2 → NE, 0 → E, 6 → NE, 4 → NE.
    let steps = trace((5, 8), (9, 11));
    assert_eq!(
        decisions(&steps),
        vec![(2, Move::NE), (0, Move::E), (6, Move::NE), (4, Move::NE)]
    );
    assert_eq!(
        pixels((5, 8), (9, 11)),
        vec![(5, 8), (6, 9), (7, 9), (8, 10), (9, 11)]
    );
    let l = Line::new((5, 8), (9, 11)).unwrap();
    assert_eq!((l.dx, l.dy, l.incr_e, l.incr_ne, l.d0()), (4, 3, 6, -2, 2));
}

#[test]
fn other_worked_cases() {
    // −1 < m < 0: flipped about the x axis; ties (d = 0) stay on the start's row.
    assert_eq!(
        pixels((0, 4), (4, 2)),
        vec![(0, 4), (1, 4), (2, 3), (3, 3), (4, 2)]
    );
    assert_eq!(
        decisions(&trace((0, 4), (4, 2))),
        vec![(0, Move::E), (4, Move::NE), (0, Move::E), (4, Move::NE)]
    );
    // m > 1: x and y swapped.
    assert_eq!(
        pixels((1, 2), (3, 6)),
        vec![(1, 2), (1, 3), (2, 4), (2, 5), (3, 6)]
    );
    // Steep with negative slope, the case a common mistake never runs.
    assert_eq!(
        pixels((3, 2), (1, 6)),
        vec![(3, 2), (3, 3), (2, 4), (2, 5), (1, 6)]
    );
    assert_eq!(pixels((1, 6), (3, 2)).len(), 5);
}

#[test]
fn axis_aligned_and_diagonal_lines() {
    assert_eq!(
        pixels((2, 3), (6, 3)),
        (2..=6).map(|x| (x, 3)).collect::<Vec<_>>()
    );
    assert_eq!(
        pixels((2, 7), (2, 3)),
        (3..=7).map(|y| (2, y)).collect::<Vec<_>>()
    );
    assert_eq!(
        pixels((0, 0), (4, 4)),
        (0..=4).map(|i| (i, i)).collect::<Vec<_>>()
    );
    assert_eq!(
        pixels((4, 0), (0, 4)),
        (0..=4).map(|i| (i, 4 - i)).collect::<Vec<_>>()
    );
    assert_eq!(pixels((7, 7), (7, 7)), vec![(7, 7)]);
}

#[test]
fn every_octant_is_reported() {
    let dirs = [
        (5, 2),
        (2, 5),
        (-2, 5),
        (-5, 2),
        (-5, -2),
        (-2, -5),
        (2, -5),
        (5, -2),
    ];
    for (o, (dx, dy)) in dirs.into_iter().enumerate() {
        assert_eq!(Line::new((0, 0), (dx, dy)).unwrap().octant as usize, o);
    }
}

/// Independent reference: for each major coordinate, the minor coordinate nearest the
/// ideal line, a tie (the midpoint exactly on the line) going toward the start's minor
/// coordinate; exact rational arithmetic, no decision variable.
fn reference(a: (i64, i64), b: (i64, i64)) -> Vec<(i64, i64)> {
    let steep = (b.1 - a.1).abs() > (b.0 - a.0).abs();
    let (p, q) = if steep {
        ((a.1, a.0), (b.1, b.0))
    } else {
        (a, b)
    };
    let (p, q) = if q.0 < p.0 { (q, p) } else { (p, q) };
    let (du, dv) = (i128::from(q.0 - p.0), i128::from(q.1 - p.1));
    let mut out = Vec::new();
    for u in p.0..=q.0 {
        let v = if du == 0 {
            i128::from(p.1)
        } else {
            // v* = p.1 + (u − p.0)·dv/du; nearest integer, ties toward p.1.
            let num = i128::from(u - p.0) * dv;
            let fl = num.div_euclid(du);
            let rem2 = 2 * num.rem_euclid(du);
            let up = if dv >= 0 { rem2 > du } else { rem2 >= du };
            i128::from(p.1) + fl + i128::from(up)
        };
        let v = v as i64;
        out.push(if steep { (v, u) } else { (u, v) });
    }
    out
}

fn sorted(mut v: Vec<(i64, i64)>) -> Vec<(i64, i64)> {
    v.sort_unstable();
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    #[test]
    fn lines_match_the_reference_and_are_symmetric(
        x0 in -300i64..300, y0 in -300i64..300, x1 in -300i64..300, y1 in -300i64..300,
    ) {
        let (a, b) = ((x0, y0), (x1, y1));
        let px = pixels(a, b);
        prop_assert_eq!(sorted(px.clone()), sorted(reference(a, b)));
        prop_assert_eq!(sorted(px.clone()), sorted(pixels(b, a)));
        let (adx, ady) = ((x1 - x0).abs(), (y1 - y0).abs());
        prop_assert_eq!(px.len() as i64, adx.max(ady) + 1);
        prop_assert!(px.contains(&a) && px.contains(&b));
        // One pixel per column (x-major) or per row (y-major), 8-connected.
        let major = |p: &(i64, i64)| if ady > adx { p.1 } else { p.0 };
        let mut majors: Vec<i64> = px.iter().map(major).collect();
        majors.dedup();
        prop_assert_eq!(majors.len(), px.len());
        for w in px.windows(2) {
            prop_assert!((w[0].0 - w[1].0).abs() <= 1 && (w[0].1 - w[1].1).abs() <= 1);
        }
    }

    #[test]
    fn clipped_lines_equal_unclipped_restricted(
        x0 in -200i64..260, y0 in -200i64..200, x1 in -200i64..260, y1 in -200i64..200,
        w in 1i64..64, h in 1i64..48,
    ) {
        let line = Line::new((x0, y0), (x1, y1)).unwrap();
        let mut clipped = Vec::new();
        line.draw_clipped(w, h, |x, y| clipped.push((x, y)), &mut NoTrace);
        let inside: Vec<_> = pixels((x0, y0), (x1, y1)).into_iter()
            .filter(|&(x, y)| (0..w).contains(&x) && (0..h).contains(&y)).collect();
        prop_assert_eq!(clipped, inside);
    }
}

proptest! {
    // Each case walks a 2-million-pixel reference line.
    #![proptest_config(ProptestConfig::with_cases(40))]

    #[test]
    fn million_pixel_endpoints_clip_exactly(
        x0 in -1_000_000i64..1_000_000, y0 in -1_000_000i64..1_000_000,
        tx in 0i64..40, ty in 0i64..30,
    ) {
        // Aim the line through the target so most cases draw something.
        let (x1, y1) = (2 * tx - x0, 2 * ty - y0);
        let line = Line::new((x0, y0), (x1, y1)).unwrap();
        let (w, h) = (80, 60);
        let mut clipped = Vec::new();
        let mut steps: Vec<Step> = Vec::new();
        line.draw_clipped(w, h, |x, y| clipped.push((x, y)), &mut steps);
        let want: Vec<_> = reference((x0, y0), (x1, y1)).into_iter()
            .filter(|&(x, y)| (0..w).contains(&x) && (0..h).contains(&y)).collect();
        prop_assert_eq!(sorted(clipped), sorted(want));
        // The trace's d values equal the closed form: no drift from starting mid-line.
        for s in steps.iter().filter(|s| s.decision.is_some()) {
            prop_assert_eq!(s.decision.unwrap().0, line.d_at(s.k));
        }
    }
}

#[test]
fn closed_polygon_has_no_gaps() {
    let poly = [(3, 2), (40, 9), (35, 30), (12, 33), (-4, 17)];
    let mut grid = std::collections::HashSet::new();
    for i in 0..poly.len() {
        for p in pixels(poly[i], poly[(i + 1) % poly.len()]) {
            grid.insert(p);
        }
    }
    // Walk the outline: every drawn pixel has at least two 8-neighbours (a closed
    // curve), and each vertex is shared by its two edges.
    for &(x, y) in &grid {
        let n = (-1..=1)
            .flat_map(|dx| (-1..=1).map(move |dy| (x + dx, y + dy)))
            .filter(|&q| q != (x, y) && grid.contains(&q))
            .count();
        assert!(n >= 2, "({x},{y}) has {n} neighbours");
    }
    for v in poly {
        assert!(grid.contains(&v));
    }
}

#[test]
fn out_of_range_coordinates_are_refused() {
    assert!(Line::new((0, 0), (1 << 41, 0)).is_err());
}

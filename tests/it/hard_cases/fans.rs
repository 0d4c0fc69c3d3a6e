//! Shared edges and fans: watertight tilings, exact variants on every hard case.

use super::*;

/// Points along the perimeter of `[x0,x1]×[y0,y1]` (clockwise on screen), at steps of
/// `steps[i]` subpixels, so consecutive fan triangles include many slivers.
fn perimeter(x0: f64, y0: f64, x1: f64, y1: f64, steps: &[u32]) -> Vec<[f64; 2]> {
    let w = x1 - x0;
    let h = y1 - y0;
    let total = 2.0 * (w + h);
    let mut pts = Vec::new();
    let mut d = 0.0;
    let mut i = 0;
    while d < total {
        let p = if d < w {
            [x0 + d, y0]
        } else if d < w + h {
            [x1, y0 + d - w]
        } else if d < 2.0 * w + h {
            [x1 - (d - w - h), y1]
        } else {
            [x0, y1 - (d - 2.0 * w - h)]
        };
        pts.push(p);
        d += f64::from(steps[i % steps.len()]) / 256.0;
        i += 1;
    }
    // The corners must be vertices for the fan to tile the rectangle exactly.
    for c in [[x1, y0], [x1, y1], [x0, y1]] {
        if !pts.contains(&c) {
            let at = pts
                .iter()
                .position(|p| {
                    let dist = |q: [f64; 2]| {
                        if q[1] == y0 {
                            q[0] - x0
                        } else if q[0] == x1 {
                            w + q[1] - y0
                        } else if q[1] == y1 {
                            w + h + x1 - q[0]
                        } else {
                            2.0 * w + h + y1 - q[1]
                        }
                    };
                    dist(*p) > dist(c)
                })
                .unwrap_or(pts.len());
            pts.insert(at, c);
        }
    }
    pts
}

fn fan_counts(centre: [f64; 2], ring: &[[f64; 2]], target: Target, t: Traversal) -> CountGrid {
    let mut grid = CountGrid::new(target.width, target.height);
    for i in 0..ring.len() {
        accumulate(&mut grid, [centre, ring[i], ring[(i + 1) % ring.len()]], t);
    }
    grid
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Every pixel centre of the rectangle is covered exactly once, nothing outside.
    #[test]
    fn fan_is_watertight(
        cx in 2.0f64..46.0, cy in 2.0f64..30.0,
        steps in prop::collection::vec(1u32..700, 1..12),
    ) {
        let target = Target::new(56, 40);
        let (x0, y0, x1, y1) = (1.0, 1.0, 47.0, 31.0);
        let centre = [(cx * 256.0).round() / 256.0, (cy * 256.0).round() / 256.0];
        let ring = perimeter(x0, y0, x1, y1, &steps);
        for t in Traversal::ALL {
            let g = fan_counts(centre, &ring, target, t);
            for y in 0..target.height {
                for x in 0..target.width {
                    let inside = (1..47).contains(&x) && (1..31).contains(&y);
                    prop_assert_eq!(g.get(x, y), u32::from(inside), "({},{}) {}", x, y, t.name());
                }
            }
        }
    }

    /// The same with the fan centre far outside the target (hundreds of thousands of px).
    #[test]
    fn fan_with_far_centre_is_watertight(
        cx in -400_000.0f64..-1000.0, cy in -300_000.0f64..20.0,
        steps in prop::collection::vec(1u32..900, 1..8),
    ) {
        let target = Target::new(48, 32);
        let (x0, y0, x1, y1) = (-500_000.0, -400_000.0, 40.0, 24.0);
        let centre = [cx.round(), cy.round()];
        // Only the part of the perimeter near the target is finely subdivided.
        let mut ring = vec![[x0, y0], [x1, y0]];
        ring.extend(perimeter(-8.0, -8.0, x1, y1, &steps).into_iter()
            .filter(|p| p[0] == x1 && p[1] > -8.0 || p[1] == y1 && p[0] > -8.0 && p[0] < x1));
        ring.push([x0, y1]);
        for t in Traversal::ALL {
            let g = fan_counts(centre, &ring, target, t);
            for y in 0..target.height {
                for x in 0..target.width {
                    let inside = x < 40 && y < 24;
                    prop_assert_eq!(g.get(x, y), u32::from(inside), "({},{}) {}", x, y, t.name());
                }
            }
        }
    }
}

/// Pass: every 2D hard case (fans about interior and far-away centres, the sliver
/// fan, needles, degenerate, huge and tiny triangles, long spans) is exact in
/// `fixed8` and `i64`, and in every traversal; tilings have no holes and no double
/// hits.
#[test]
fn exact_variants_and_traversals_get_every_hard_case_right() {
    for case in cases::all() {
        for v in [EdgeArith::Fixed8, EdgeArith::I64] {
            assert_eq!(
                cases::wrong(v, &case),
                cases::Wrong::default(),
                "{} {}",
                case.name,
                v.name()
            );
        }
        for t in Traversal::ALL {
            let mut grid = CountGrid::new(case.target.width, case.target.height);
            for &tri in &case.triangles {
                let mut got = Vec::new();
                if let Ok(s) = Setup::new(tri, case.target) {
                    t.run(&s, &mut got);
                }
                assert_eq!(
                    cases::mismatches(tri, case.target, &mut got),
                    0,
                    "{} {}",
                    case.name,
                    t.name()
                );
                accumulate(&mut grid, tri, t);
            }
            if case.tiles_target {
                assert!(
                    grid.counts.iter().all(|&c| c == 1),
                    "{} {}: holes or double hits",
                    case.name,
                    t.name()
                );
            }
        }
    }
}

/// Draws clip-space triangles with the depth test off: fragments per pixel.
fn writes(clip: Vec<Vec4>, indices: &[u32], target: Target) -> Vec<u32> {
    let shader = Direct {
        attr: vec![Vec3::ONE; clip.len()],
        clip,
    };
    let mut r = Renderer::new(target);
    let mut out = Exact::default();
    let mut cache = VertexCache::default();
    r.begin_frame(target, &mut out, Vec3::ZERO);
    transform(&shader, shader.clip.len(), &mut cache);
    let opts = DrawOptions {
        depth: DepthState {
            func: DepthFunc::Always,
            write: false,
        },
        ..DrawOptions::default()
    };
    r.draw(&shader, &cache, indices, &opts, &mut out);
    out.writes
}

/// Pass: a fan mesh through the whole 3D pipeline writes every pixel exactly once,
/// also when its shared edges cross the near plane or run out to beyond the guard
/// band (both are clipped, and a shared edge must clip to the same point in both
/// triangles).
#[test]
fn fans_through_the_pipeline_write_each_pixel_once() {
    let target = Target::new(64, 48);
    // A ring of points around a centre, in clip space with w = 1 except where noted.
    let ring = |r: f32, n: usize| -> Vec<Vec4> {
        (0..n)
            .map(|i| {
                let a = i as f32 / n as f32 * std::f32::consts::TAU + 0.1;
                Vec4::new(r * a.cos(), r * a.sin() * 1.3, 0.5, 1.0)
            })
            .collect()
    };
    let fan = |centre: Vec4, ring: Vec<Vec4>| {
        let n = ring.len() as u32;
        let mut clip = vec![centre];
        clip.extend(ring);
        let idx: Vec<u32> = (0..n).flat_map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
        (clip, idx)
    };
    // Interior centre, ring well outside the view: the fan covers the target.
    let (clip, idx) = fan(Vec4::new(0.13, -0.07, 0.5, 1.0), ring(3.0, 37));
    assert!(writes(clip, &idx, target).iter().all(|&c| c == 1));
    // Ring out beyond the guard band (2^20 px): x, y clipped at the guard planes.
    let (clip, idx) = fan(Vec4::new(0.2, 0.1, 0.5, 1.0), ring(1.0e5, 29));
    assert!(writes(clip, &idx, target).iter().all(|&c| c == 1));
    // A planar fan (z = 0.6x + 0.2w) whose ring crosses the near plane: the radial
    // edges to the ring points behind it are clipped from both neighbouring
    // triangles. What remains is the convex part of the ring with NDC x ≥ −1/3, so
    // every row and column of covered pixels must be one unbroken run.
    let plane = |x: f32, y: f32, w: f32| Vec4::new(x, y, 0.6 * x + 0.2 * w, w);
    let ring: Vec<Vec4> = ring(0.8, 43)
        .into_iter()
        .map(|p| plane(p.x, p.y, 1.0))
        .collect();
    assert!(ring.iter().any(|p| p.z < 0.0) && ring.iter().any(|p| p.z > 0.0));
    let (clip, idx) = fan(plane(0.1, 0.05, 1.0), ring);
    let w = writes(clip, &idx, target);
    assert!(w.iter().all(|&c| c <= 1), "no double hits");
    let at = |x: usize, y: usize| w[y * 64 + x];
    let run_ok = |cells: Vec<u32>| {
        let first = cells.iter().position(|&c| c == 1);
        let last = cells.iter().rposition(|&c| c == 1);
        match (first, last) {
            (Some(a), Some(b)) => cells[a..=b].iter().all(|&c| c == 1),
            _ => true,
        }
    };
    for y in 0..48 {
        assert!(
            run_ok((0..64).map(|x| at(x, y)).collect()),
            "crack in row {y}"
        );
    }
    for x in 0..64 {
        assert!(
            run_ok((0..48).map(|y| at(x, y)).collect()),
            "crack in column {x}"
        );
        // Left of the cut (pixel centres at NDC x < −1/3, i.e. x + 0.5 < 64/3): nothing.
        if (x as f32) + 0.5 < 64.0 / 3.0 {
            assert!(
                (0..48).all(|y| at(x, y) == 0),
                "column {x} is behind the near plane"
            );
        }
    }
    assert!(w.iter().filter(|&&c| c == 1).count() > 300);
}

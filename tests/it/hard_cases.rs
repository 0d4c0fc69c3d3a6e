//! The hard-case stability suite: the cases where rasterizers crack, leak, drift or
//! panic, in one place. Each test's pass criterion is in its doc comment.
//!
//! "Exact" means equal to the independent i128 oracle on the 1/256 px grid, pixel for
//! pixel. The float edge variants of `termrast bench accuracy` run through the same
//! 2D cases (`termrast::accuracy::cases`); their errors are reported, not asserted
//! (`cargo test --test hard_cases -- --nocapture` prints them), and are the numbers
//! the accuracy table shows.

use crate::common::{Direct, Exact, accumulate, assert_all_match_oracle, coverage, draw};
use glam::{Vec3, Vec4};
use proptest::prelude::*;
use termrast::accuracy::cases;
use termrast::accuracy::depth::{DepthFormat, DepthPass};
use termrast::accuracy::edge::EdgeArith;
use termrast::camera::Camera;
use termrast::raster::clip::{
    ClipOutcome, ClipVertex, MAX_CLIPPED, classify_codes, clip_straddling, guard_band_ndc, outcode,
};
use termrast::raster::depth::{DepthFunc, DepthState};
use termrast::raster::interp::Interpolation;
use termrast::raster::line::{Line, NoTrace};
use termrast::raster::traverse::seed_simd_lanes;
use termrast::raster::{CountGrid, Reject, Setup, Target, Traversal};
use termrast::render::probe::probe;
use termrast::render::{Cull, DrawOptions, Prepared, Renderer, VertexCache, prepare, transform};

const T: Target = Target {
    width: 96,
    height: 64,
};

// ---------------------------------------------------------------------------------
// Shared edges and fans
// ---------------------------------------------------------------------------------

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

/// Pass: nothing (the float variants are reported, as in the accuracy table).
#[test]
fn float_variants_on_the_hard_cases_are_reported() {
    for case in cases::all() {
        let line: Vec<String> = EdgeArith::ALL
            .iter()
            .map(|&v| {
                let w = cases::wrong(v, &case);
                format!(
                    "{} {}/{}/{}",
                    v.name(),
                    w.mismatches,
                    w.holes,
                    w.double_hits
                )
            })
            .collect();
        println!("{:<38} {}", case.name, line.join("  "));
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

// ---------------------------------------------------------------------------------
// Slivers, needles, collinear and repeated vertices; huge and tiny
// ---------------------------------------------------------------------------------

/// Pass: NaN, infinities and coordinates beyond the ±2^20 px guard band are rejected
/// by setup with the reason; at the guard band itself coverage is exact.
#[test]
fn hostile_inputs_are_rejected_cleanly() {
    let ok = [[1.0, 1.0], [30.0, 2.0], [4.0, 40.0]];
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for i in 0..6 {
            let mut t = ok;
            t[i / 2][i % 2] = bad;
            assert_eq!(Setup::new(t, T), Err(Reject::NonFinite));
        }
    }
    let mut far = ok;
    far[1][0] = 2_000_000.0;
    assert_eq!(Setup::new(far, T), Err(Reject::BeyondGuardBand));
    // Right at the guard band the triangle is exact and covers the whole target.
    let g = termrast::raster::GUARD_BAND_PX;
    let huge = [[-g, -g], [g, -g], [0.0, g]];
    assert_all_match_oracle(huge, T);
    assert_eq!(
        coverage(Traversal::Wide, huge, T).covered().count(),
        T.len()
    );
    assert_eq!(
        Setup::new([[-5.0, -5.0], [-1.0, -5.0], [-5.0, -1.0]], T),
        Err(Reject::Offscreen)
    );
}

/// Pass: a triangle whose clipped polygon rounding makes slightly non-convex (w of
/// 1e34 beside w of 1: the guard-band planes then cut it more than twice) is dropped
/// instead of outgrowing the polygon's nine vertices; it used to index past them.
#[test]
fn clipping_a_polygon_rounding_made_non_convex_does_not_overflow() {
    let target = Target::new(24, 16);
    let guard = guard_band_ndc(target.width, target.height);
    let pos = [
        Vec4::new(0.0, -0.0, 33_554_432.0, 1.038_459_4e34),
        Vec4::new(1.0, -0.333_893, 1.640_763_4, 0.0),
        Vec4::new(2.569_394, 1.0, -1.214_852_7, 0.166_220_95),
    ];
    let tri = pos.map(|pos| ClipVertex { pos, var: () });
    if let Some(poly) = clip_straddling(tri, guard) {
        assert!(poly.vertices().len() <= MAX_CLIPPED);
        assert!(poly.vertices().iter().all(|v| v.pos.w > 0.0));
    }
    // And through the whole pipeline, both windings, every traversal.
    for traversal in Traversal::ALL {
        let shader = Direct {
            attr: vec![Vec3::X, Vec3::Y, Vec3::Z],
            clip: pos.to_vec(),
        };
        let opts = DrawOptions {
            traversal,
            ..DrawOptions::default()
        };
        let mut r = Renderer::new(target);
        let mut color = Exact::default();
        let mut cache = VertexCache::default();
        r.begin_frame(target, &mut color, Vec3::ZERO);
        transform(&shader, 3, &mut cache);
        r.draw(&shader, &cache, &[0, 1, 2, 2, 1, 0], &opts, &mut color);
        assert!(r.depth.to_vec().iter().all(|d| (0.0..=1.0).contains(d)));
    }
}

/// Pass: triangles smaller than one subpixel step are exact (usually empty; a
/// 1/256 px triangle on a centre owned by its left/top edges covers that one pixel).
#[test]
fn tiny_triangles_below_a_subpixel() {
    // Smaller than 1/256 px: they snap to a point (zero area) or to one subpixel step.
    for (x, y) in [(3.5, 3.5), (3.501, 3.499), (10.0, 2.0)] {
        let tri = [[x, y], [x + 0.001, y], [x, y + 0.001]];
        assert_all_match_oracle(tri, T);
    }
    // A 1/256 px right triangle with its corner exactly on a centre: left/top edges own it.
    let tri = [
        [4.5, 4.5],
        [4.5 + 1.0 / 256.0, 4.5],
        [4.5, 4.5 + 1.0 / 256.0],
    ];
    assert_all_match_oracle(tri, T);
    assert_eq!(coverage(Traversal::Scalar, tri, T).covered().count(), 1);
}

/// Pass: a triangle whose clip-space vertices lie far beyond the guard band is
/// clipped to it and still covers exactly the part of the target it should: here,
/// all of it, with finite depth.
#[test]
fn vertices_beyond_the_guard_band_are_clipped_not_lost() {
    let target = Target::new(40, 30);
    for far in [1.0e4f32, 1.0e7, 1.0e12, 1.0e30] {
        let clip = vec![
            Vec4::new(-far, -far, 0.5, 1.0),
            Vec4::new(far, -far, 0.5, 1.0),
            Vec4::new(0.0, far, 0.5, 1.0),
        ];
        let (img, r) = draw(
            &Direct {
                clip,
                attr: vec![Vec3::X, Vec3::Y, Vec3::Z],
            },
            &[0, 1, 2],
            target,
            &DrawOptions::default(),
        );
        assert!(
            img.colors.iter().all(Option::is_some),
            "{far}: covers the target"
        );
        assert!(
            r.depth.to_vec().iter().all(|d| (d - 0.5).abs() < 1e-6),
            "{far}"
        );
        for c in img.colors.iter().flatten() {
            assert!(c.is_finite());
        }
    }
}

/// Pass: NaN or an infinity in any component of any vertex discards the triangle
/// (nothing drawn, counted as rejected), never panics, and leaves the other
/// triangles of the draw untouched.
#[test]
fn nan_and_infinity_anywhere_are_discarded() {
    let target = Target::new(32, 24);
    let good = vec![
        Vec4::new(-0.9, -0.9, 0.5, 1.0),
        Vec4::new(0.9, -0.9, 0.5, 1.0),
        Vec4::new(0.0, 0.9, 0.5, 1.0),
    ];
    let other = vec![
        Vec4::new(-1.0, 0.95, 0.2, 1.0),
        Vec4::new(-0.95, 1.0, 0.2, 1.0),
        Vec4::new(-1.0, 1.0, 0.2, 1.0),
    ];
    let (reference, _) = draw(
        &Direct {
            clip: other.clone(),
            attr: vec![Vec3::ONE; 3],
        },
        &[0, 1, 2],
        target,
        &DrawOptions::default(),
    );
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for v in 0..3 {
            for c in 0..4 {
                let mut clip = good.clone();
                clip[v][c] = bad;
                clip.extend(other.clone());
                let (img, r) = draw(
                    &Direct {
                        clip,
                        attr: vec![Vec3::ONE; 6],
                    },
                    &[0, 1, 2, 3, 4, 5],
                    target,
                    &DrawOptions::default(),
                );
                assert_eq!(r.stats.rejected, 1, "{bad} in vertex {v} component {c}");
                assert_eq!(
                    img.colors, reference.colors,
                    "{bad} in vertex {v} component {c}"
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------
// Incremental drift on long spans
// ---------------------------------------------------------------------------------

/// Pass: on 5000 px rows, values stepped by adds equal direct evaluation at every
/// pixel, and coverage is exact to the end of each row.
#[test]
fn incremental_values_equal_direct_evaluation_on_long_spans() {
    // Rows over 4096 px long: the seed-simd lanes (stepped by adds only) equal the
    // directly evaluated edge functions at every covered pixel, including row ends.
    let target = Target::new(5000, 6);
    let s = Setup::new([[0.3, 0.2], [4999.7, 1.1], [2.2, 5.9]], target).unwrap();
    assert!(s.bbox.width() > 4096);
    let mut last_per_row = [0u32; 6];
    seed_simd_lanes(&s, [1.0, 0.5, 0.25], |x, y, lanes| {
        let direct = s.edges(x.into(), y.into());
        assert_eq!(&lanes.f[1..], &direct[..], "({x},{y})");
        last_per_row[y as usize] = last_per_row[y as usize].max(x);
    });
    assert!(last_per_row.iter().any(|&x| x > 4096));
    let wide = coverage(
        Traversal::Wide,
        [[0.3, 0.2], [4999.7, 1.1], [2.2, 5.9]],
        target,
    );
    for (y, &x) in last_per_row.iter().enumerate() {
        assert_eq!(wide.get(x, y as u32), 1);
    }
    assert_all_match_oracle([[0.3, 0.2], [4999.7, 1.1], [2.2, 5.9]], target);
}

/// Pass: a box too large for `i32` lanes takes the `i64` lanes and stays exact.
#[test]
fn wide_takes_the_i64_path_when_i32_would_overflow() {
    use termrast::raster::traverse::fits_i32;
    let target = Target::new(300, 200);
    let small = Setup::new([[1.0, 1.0], [250.0, 20.0], [30.0, 190.0]], target).unwrap();
    let huge_tri = [[-900_000.0, -3.0], [900_000.0, 50.5], [10.0, 199.0]];
    let huge = Setup::new(huge_tri, target).unwrap();
    assert!(fits_i32(&small) && !fits_i32(&huge));
    assert_all_match_oracle(huge_tri, target);
}

// ---------------------------------------------------------------------------------
// w ≤ 0, w = 0, tiny w, entirely behind the eye
// ---------------------------------------------------------------------------------

/// Pass: vertices with w < 0, w = 0, w = −0 or w = 1e-30 never produce a pixel from
/// behind the eye or a depth outside [0, 1]; triangles entirely behind draw nothing.
#[test]
fn vertices_behind_or_at_the_eye_never_leak() {
    let target = Target::new(48, 32);
    let front = Vec4::new(0.0, 0.5, 0.5, 1.0);
    let cases = [
        ("w < 0", Vec4::new(0.3, -0.4, -0.8, -0.5)),
        ("w = 0", Vec4::new(0.3, -0.4, 0.0, 0.0)),
        ("w = 1e-30", Vec4::new(0.3, -0.4, 1e-31, 1e-30)),
        ("w = -0", Vec4::new(0.3, -0.4, -0.0, -0.0)),
        ("nan", Vec4::new(f32::NAN, 0.0, 0.5, 1.0)),
        ("inf", Vec4::new(f32::INFINITY, 0.0, 0.5, 1.0)),
    ];
    for (name, bad) in cases {
        for (i0, i1) in [(0, 1), (1, 0)] {
            let clip = vec![front, Vec4::new(-0.6, -0.6, 0.5, 1.0), bad];
            let mut idx = [0u32, 1, 2];
            idx.swap(i0, i1);
            let (img, r) = draw(
                &Direct {
                    clip,
                    attr: vec![Vec3::ONE; 3],
                },
                &idx,
                target,
                &DrawOptions::default(),
            );
            for (i, c) in img.colors.iter().enumerate() {
                if c.is_some() {
                    let d = r.depth.at(i);
                    assert!(
                        d.is_finite() && (0.0..=1.0).contains(&d),
                        "{name}: depth {d}"
                    );
                }
            }
        }
        // Entirely behind the eye: nothing at all.
        let clip = vec![
            Vec4::new(0.0, 0.0, -1.0, -1.0),
            Vec4::new(0.5, 0.0, -1.0, -1.0),
            bad,
        ];
        let (img, r) = draw(
            &Direct {
                clip,
                attr: vec![Vec3::ONE; 3],
            },
            &[0, 1, 2],
            target,
            &DrawOptions::default(),
        );
        assert!(img.colors.iter().all(Option::is_none), "{name}");
        assert_eq!(r.stats.rejected, 1);
    }
}

/// Pass: a triangle straddling the near plane draws exactly the pixels of the part in
/// front (the polygon clipped by hand), with the same attributes.
#[test]
fn near_plane_straddling_renders_exactly_the_front_part() {
    // Clip space chosen so the near-plane crossings are at t = 1/2 exactly (z goes
    // from −1 to 1 along the cut edges): clipping is exact in f32, and the result
    // must equal drawing the hand-clipped quad.
    let target = Target::new(64, 48);
    let a = Vec4::new(-0.5, -0.5, 0.5, 1.0);
    let b = Vec4::new(0.6, -0.4, 0.5, 1.0);
    let c = Vec4::new(0.1, 0.7, -0.5, 1.0); // z < 0: in front of the eye but before near
    let attr = vec![Vec3::X, Vec3::Y, Vec3::Z];
    let (img, r) = draw(
        &Direct {
            clip: vec![a, b, c],
            attr: attr.clone(),
        },
        &[0, 1, 2],
        target,
        &DrawOptions::default(),
    );
    assert_eq!(r.stats.clipped, 1);
    let mid = |p: Vec4, q: Vec4| (p + q) * 0.5;
    let quad = vec![a, b, mid(b, c), mid(a, c)];
    let qattr = vec![
        Vec3::X,
        Vec3::Y,
        (Vec3::Y + Vec3::Z) * 0.5,
        (Vec3::X + Vec3::Z) * 0.5,
    ];
    let (want, _) = draw(
        &Direct {
            clip: quad,
            attr: qattr,
        },
        &[0, 1, 2, 0, 2, 3],
        target,
        &DrawOptions::default(),
    );
    let covered = |e: &Exact| e.colors.iter().map(Option::is_some).collect::<Vec<_>>();
    assert_eq!(covered(&img), covered(&want));
    for (g, w) in img.colors.iter().zip(&want.colors) {
        if let (Some(g), Some(w)) = (g, w) {
            assert!((*g - *w).abs().max_element() < 1e-5);
        }
    }
}

// ---------------------------------------------------------------------------------
// Depth precision for close planes at near and far distances
// ---------------------------------------------------------------------------------

/// Pass: in every depth format, two parallel planes whose depths differ by more than
/// the format's resolvable step at that distance sort correctly in both draw orders.
/// Below the step they may fight; how often is reported (the accuracy table's
/// z-fighting column), not asserted.
#[test]
fn close_planes_sort_when_the_gap_exceeds_the_format_step() {
    let target = Target::new(32, 32);
    let cam = Camera::default();
    let vp = cam.projection(32, 32, 1.0) * cam.view();
    const QUAD: [u32; 6] = [0, 1, 2, 0, 2, 3];
    let plane = |d: f32| -> Vec<Vec3> {
        let s = d;
        [(-s, -s), (s, -s), (s, s), (-s, s)]
            .map(|(x, y)| Vec3::new(x, y, cam.eye.z - d))
            .to_vec()
    };
    for format in DepthFormat::ALL {
        let m = format.projection(vp);
        // Depth of a plane at view distance d in this format's stored units.
        let depth = |d: f32| {
            let c = m * Vec4::new(0.0, 0.0, cam.eye.z - d, 1.0);
            c.z / c.w
        };
        let step = |z: f32| match format {
            DepthFormat::Unorm16 => 1.0 / 65535.0,
            DepthFormat::Unorm24 => 1.0 / 16_777_215.0,
            DepthFormat::F32 | DepthFormat::F32Reversed => z.abs() * f32::EPSILON,
        };
        let mut pass = DepthPass::new(target, format);
        let (mut asserted, mut fought) = (0, 0);
        for d in [0.15f32, 0.5, 1.0, 3.0, 9.5] {
            for rel in [1e-2f32, 1e-3, 1e-4, 1e-5, 1e-6] {
                let (near, far) = (d, d * (1.0 + rel));
                let resolvable = (depth(near) - depth(far)).abs()
                    > 4.0 * step(depth(near)).max(step(depth(far)));
                for near_first in [false, true] {
                    pass.clear();
                    let order = if near_first {
                        [(near, 1), (far, 0)]
                    } else {
                        [(far, 0), (near, 1)]
                    };
                    for (dist, id) in order {
                        pass.draw(&plane(dist), &QUAD, m, id);
                    }
                    let wrong = pass.ids.iter().filter(|&&i| i == 0).count();
                    if resolvable {
                        assert_eq!(wrong, 0, "{} d {d} rel {rel}", format.name());
                        asserted += 1;
                    } else if wrong > 0 {
                        fought += 1;
                    }
                }
            }
        }
        assert!(asserted >= 8, "{}: {asserted} resolvable", format.name());
        println!(
            "{}: {asserted} resolvable cases sorted, {fought} unresolvable ones fought",
            format.name()
        );
    }
}

// ---------------------------------------------------------------------------------
// Perspective interpolation: steep gradients in small triangles far from the origin
// ---------------------------------------------------------------------------------

/// Pass: a 3 px triangle near pixel (65 000, 65 000) of a 65 536² target, with 1/w
/// varying 1000:1 across it, gets perspective weights within 2e-6 of an f64
/// computation from the exact edge values at every covered pixel, and exactly the
/// vertex's own weight at a pixel on a vertex. (Barycentrics come from exact integer
/// edge functions, so distance from the origin costs nothing.)
#[test]
fn perspective_weights_stay_exact_in_small_triangles_far_from_the_origin() {
    let target = Target::new(65_536, 65_536);
    let (ox, oy) = (65_000.0, 65_000.0);
    let (fw, fh) = (f32::from(u16::MAX) + 1.0, f32::from(u16::MAX) + 1.0);
    // Clip space positions for screen points (sx, sy) with a given w.
    let at = |sx: f32, sy: f32, w: f32| {
        Vec4::new(
            (sx / fw * 2.0 - 1.0) * w,
            (1.0 - sy / fh * 2.0) * w,
            0.5 * w,
            w,
        )
    };
    let clip = vec![
        at(ox + 0.5, oy + 0.5, 0.01),
        at(ox + 3.5, oy + 0.8, 10.0),
        at(ox + 1.2, oy + 3.5, 1.0),
    ];
    let shader = Direct {
        clip,
        attr: vec![Vec3::X, Vec3::Y, Vec3::Z],
    };
    let mut cache = VertexCache::default();
    transform(&shader, 3, &mut cache);
    let mut checked = 0;
    prepare(
        &cache,
        &[0, 1, 2],
        0,
        target,
        Cull::None,
        &mut |p: &Prepared<Vec3>| {
            let s = p.setup;
            for y in s.bbox.y0..=s.bbox.y1 {
                for x in s.bbox.x0..=s.bbox.x1 {
                    let e = p.eval(x, y);
                    assert_eq!(p.depth_at(x, y).to_bits(), e.depth.to_bits());
                    if !e.covered {
                        continue;
                    }
                    let a = s.area2 as f64;
                    let b = [e.f[1] as f64 / a, e.f[2] as f64 / a, e.f[0] as f64 / a];
                    let q: Vec<f64> = (0..3).map(|i| b[i] * f64::from(p.inv_w[i])).collect();
                    let sum: f64 = q.iter().sum();
                    for (i, (got, q)) in e.persp.iter().zip(&q).enumerate() {
                        let want = q / sum;
                        assert!(
                            (f64::from(*got) - want).abs() < 2e-6,
                            "({x},{y}) {i}: {got} vs {want}"
                        );
                    }
                    checked += 1;
                }
            }
            // Vertex A sits on the centre of pixel (65000, 65000) (which the fill rule
            // leaves to a neighbour, but the weights are defined there): the other two
            // vertices' weights are exactly 0, so every varying is exactly A's.
            let e = p.eval(65_000, 65_000);
            assert_eq!((e.f[1], e.f[2]), (p.setup.area2, 0));
            assert_eq!((e.persp[1], e.persp[2]), (0.0, 0.0));
            assert!((e.persp[0] - 1.0).abs() < 1e-6, "{:?}", e.persp);
            assert_eq!(p.varyings(&e, Interpolation::Perspective), Vec3::X);
        },
    );
    assert!(checked >= 3, "{checked}");
}

// ---------------------------------------------------------------------------------
// Lines: all octants, clipped, endpoints at ±10^6
// ---------------------------------------------------------------------------------

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

// ---------------------------------------------------------------------------------
// Fuzzing the whole pipeline with arbitrary bit patterns
// ---------------------------------------------------------------------------------

/// Interesting f32 values, mixed with arbitrary bit patterns.
fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => any::<u32>().prop_map(f32::from_bits),
        1 => prop::sample::select(vec![0.0f32, -0.0, 1.0, -1.0, 1e-30, -1e-30, 1e30, -1e30,
            f32::MAX, f32::MIN, f32::MIN_POSITIVE, f32::NAN, f32::INFINITY, f32::NEG_INFINITY]),
        2 => -4.0f32..4.0,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    /// Pass: arbitrary f32 bit patterns as clip-space vertices, through transform,
    /// clipping, setup, every traversal, depth and shading, and the probe: no panic,
    /// no write outside the target, depth stays in [0, 1] where written.
    #[test]
    fn arbitrary_vertices_never_panic_or_escape(
        v in prop::array::uniform12(any_f32()),
        traversal in prop::sample::select(Traversal::ALL.to_vec()),
        px in 0u32..24, py in 0u32..16,
    ) {
        let target = Target::new(24, 16);
        let clip: Vec<Vec4> = v.chunks(4).map(|c| Vec4::new(c[0], c[1], c[2], c[3])).collect();
        let shader = Direct { attr: vec![Vec3::X, Vec3::Y, Vec3::Z], clip };
        let mut r = Renderer::new(target);
        let mut out = Exact::default();
        let mut cache = VertexCache::default();
        r.begin_frame(target, &mut out, Vec3::ZERO);
        transform(&shader, 3, &mut cache);
        let opts = DrawOptions { traversal, ..DrawOptions::default() };
        r.draw(&shader, &cache, &[0, 1, 2, 2, 1, 0], &opts, &mut out);
        for (i, &d) in r.depth.to_vec().iter().enumerate() {
            if out.colors[i].is_some_and(|c| c.is_finite()) {
                prop_assert!((0.0..=1.0).contains(&d), "depth {d}");
            }
        }
        let p = probe(&cache, &[0, 1, 2, 2, 1, 0], target, &opts, px, py);
        prop_assert_eq!(p.final_depth.to_bits(), r.depth.at((py * 24 + px) as usize).to_bits());
    }

    /// Pass: arbitrary f64 bit patterns as 2D vertices never make a traversal report
    /// a pixel outside the target or the bounding box, and exact traversals equal the
    /// oracle whenever setup accepts the triangle.
    #[test]
    fn arbitrary_2d_vertices_stay_inside(bits in prop::array::uniform6(any::<u64>())) {
        let v = bits.map(f64::from_bits);
        let tri = [[v[0], v[1]], [v[2], v[3]], [v[4], v[5]]];
        for t in Traversal::ALL {
            let _ = coverage(t, tri, T);
        }
    }
}

/// A clip-space coordinate: ordinary values, values on and near the planes, and the
/// hostile ones (zero, subnormal-small, huge, infinite, NaN).
fn clip_coord() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -3.0f32..3.0,
        1 => Just(0.0f32),
        1 => Just(-0.0f32),
        1 => Just(1.0f32),
        1 => Just(1e-30f32),
        1 => Just(-1e-30f32),
        1 => Just(1e30f32),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NAN),
    ]
}

/// The clip classification as first written: plane by plane over the distances, no
/// outcodes. The renderer classifies from per-vertex outcodes instead.
fn classify_reference(tri: &[Vec4; 3], guard: [f32; 2]) -> ClipOutcome {
    if tri.iter().any(|p| !p.is_finite()) {
        return ClipOutcome::Rejected;
    }
    let d = tri.map(|p| {
        [
            p.z,
            p.w - p.z,
            guard[0] * p.w - p.x,
            guard[0] * p.w + p.x,
            guard[1] * p.w - p.y,
            guard[1] * p.w + p.y,
        ]
    });
    let mut outcome = ClipOutcome::Inside;
    for plane in 0..6 {
        let outside = d.iter().filter(|d| d[plane] < 0.0).count();
        if outside == 3 {
            return ClipOutcome::Rejected;
        }
        if outside > 0 {
            outcome = ClipOutcome::Clipped;
        }
    }
    if outcome == ClipOutcome::Inside && !tri.iter().all(|p| p.w > 0.0) {
        return ClipOutcome::Rejected;
    }
    outcome
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Outcodes combine to exactly the plane-by-plane classification, hostile values
    /// included.
    #[test]
    fn outcodes_classify_as_the_planes_do(c in prop::array::uniform12(clip_coord())) {
        let tri = [0, 1, 2].map(|i| Vec4::new(c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]));
        let guard = guard_band_ndc(64, 32);
        let codes = tri.map(|p| outcode(p, guard));
        prop_assert_eq!(classify_codes(codes), classify_reference(&tri, guard), "{:?}", tri);
    }
}

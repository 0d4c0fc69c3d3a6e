//! Coverage core: the four traversals against the i128 oracle and the fill rule.
//! Watertight fans, drift, hostile and degenerate input are in `hard_cases.rs`.

use crate::common::{accumulate, assert_all_match_oracle, coverage, oracle_grid};
use proptest::prelude::*;
use termrast::raster::traverse::planes_lanes;
use termrast::raster::{CountGrid, Setup, Target, Traversal};

const T: Target = Target {
    width: 96,
    height: 64,
};

#[test]
fn worked_example_barycentrics() {
    // P=(10,20), Q=(70,30), R=(60,80), p=(55,43) → (0.2, 0.5, 0.3), the classic worked example.
    let s = Setup::new(
        [[10.0, 20.0], [70.0, 30.0], [60.0, 80.0]],
        Target::new(128, 128),
    )
    .unwrap();
    let [u, v, w] = s.barycentric_at_subpixel(55 * 256, 43 * 256);
    assert_eq!(
        [u, v, w],
        [0.2, 0.5, 0.3].map(|x: f64| (x * 3100.0).round() / 3100.0)
    );
    assert!((u - 0.2).abs() < 1e-12 && (v - 0.5).abs() < 1e-12 && (w - 0.3).abs() < 1e-12);
    // The other winding gives the same weights for the same vertices.
    let f = Setup::new(
        [[10.0, 20.0], [60.0, 80.0], [70.0, 30.0]],
        Target::new(128, 128),
    )
    .unwrap();
    assert!(f.flipped);
    let [u2, v2, w2] = f.barycentric_at_subpixel(55 * 256, 43 * 256);
    assert!((u2 - 0.2).abs() < 1e-12 && (v2 - 0.3).abs() < 1e-12 && (w2 - 0.5).abs() < 1e-12);
    assert_eq!(s.area2, 3100 * 256 * 256);
}

#[test]
fn diagonal_split_square_is_15_plus_10() {
    let target = Target::new(8, 8);
    // Upper-right half: the diagonal is its left edge, so it owns the 5 centres on it.
    let upper = [[0.0, 0.0], [5.0, 0.0], [5.0, 5.0]];
    let lower = [[0.0, 0.0], [5.0, 5.0], [0.0, 5.0]];
    for t in Traversal::ALL {
        let a = coverage(t, upper, target);
        let b = coverage(t, lower, target);
        assert_eq!(a.covered().count(), 15, "{}", t.name());
        assert_eq!(b.covered().count(), 10, "{}", t.name());
        for y in 0..8 {
            for x in 0..8 {
                let sum = a.get(x, y) + b.get(x, y);
                assert_eq!(sum, u32::from(x < 5 && y < 5), "({x},{y}) {}", t.name());
            }
        }
        assert!(
            (0..5).all(|i| a.get(i, i) == 1),
            "diagonal belongs to the left edge"
        );
    }
}

#[test]
fn four_tiny_triangles_around_a_centre() {
    // A 1-px diamond around the centre of pixel (3,3), split into 4 triangles meeting at
    // m = centre + (dx, dy)/256. For every shift exactly one triangle owns the centre.
    let target = Target::new(8, 8);
    let c = [3.5, 3.5];
    let ring = [
        [c[0], c[1] - 0.5],
        [c[0] + 0.5, c[1]],
        [c[0], c[1] + 0.5],
        [c[0] - 0.5, c[1]],
    ];
    for dx in -1..=1 {
        for dy in -1..=1 {
            let m = [c[0] + f64::from(dx) / 256.0, c[1] + f64::from(dy) / 256.0];
            for t in Traversal::ALL {
                let mut grid = CountGrid::new(8, 8);
                for i in 0..4 {
                    let tri = [m, ring[i], ring[(i + 1) % 4]];
                    assert_all_match_oracle(tri, target);
                    accumulate(&mut grid, tri, t);
                }
                assert_eq!(grid.get(3, 3), 1, "shift ({dx},{dy}) {}", t.name());
                assert_eq!(grid.covered().count(), 1, "only the centre pixel");
            }
        }
    }
}

/// A random triangle with sides from 2^-4 px to 4096 px around a random centre.
fn triangle() -> impl Strategy<Value = [[f64; 2]; 3]> {
    (
        -4.0f64..12.0,
        -40.0f64..140.0,
        -40.0f64..100.0,
        prop::array::uniform6(-1.0f64..1.0),
    )
        .prop_map(|(log_size, cx, cy, d)| {
            let s = log_size.exp2();
            [
                [cx + s * d[0], cy + s * d[1]],
                [cx + s * d[2], cy + s * d[3]],
                [cx + s * d[4], cy + s * d[5]],
            ]
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn traversals_equal_oracle(tri in triangle()) {
        assert_all_match_oracle(tri, T);
    }

    #[test]
    fn translation_by_whole_pixels_shifts_the_mask(
        tri in triangle(), dx in -20i32..20, dy in -20i32..20,
    ) {
        let big = Target::new(96, 64);
        let moved = tri.map(|p| [p[0] + f64::from(dx), p[1] + f64::from(dy)]);
        let a = coverage(Traversal::Wide, tri, big);
        let b = coverage(Traversal::Wide, moved, big);
        for y in 0..big.height as i32 {
            for x in 0..big.width as i32 {
                let (mx, my) = (x + dx, y + dy);
                if (0..big.width as i32).contains(&mx) && (0..big.height as i32).contains(&my) {
                    prop_assert_eq!(a.get(x as u32, y as u32), b.get(mx as u32, my as u32));
                }
            }
        }
    }

    #[test]
    fn collinear_triangles_cover_nothing(
        ax in -2000i64..30000, ay in -2000i64..20000,
        dx in -3000i64..3000, dy in -3000i64..3000, t1 in -5i64..5, t2 in -5i64..5,
    ) {
        let p = |t: i64| [(ax + t * dx) as f64 / 256.0, (ay + t * dy) as f64 / 256.0];
        let tri = [p(0), p(t1), p(t2)];
        prop_assert!(Setup::new(tri, T).is_err());
        for t in Traversal::ALL {
            prop_assert_eq!(coverage(t, tri, T).covered().count(), 0);
        }
    }

    /// 1000 px long, 1/256 px wide needles at any angle.
    #[test]
    fn needles_match_oracle(ax in -100.0f64..150.0, ay in -100.0f64..120.0, angle in 0.0f64..6.3) {
        let (dx, dy) = (angle.cos(), angle.sin());
        let a = [ax, ay];
        let b = [ax + 1000.0 * dx, ay + 1000.0 * dy];
        let c = [b[0] - dy / 256.0, b[1] + dx / 256.0];
        assert_all_match_oracle([a, b, c], T);
        assert_all_match_oracle([a, c, b], T);
    }

    /// `Setup::from_fixed` on subpixel vertices anywhere near the guard band: rejects
    /// exactly the triangles with a coordinate beyond it, and otherwise starts every
    /// walk (`Setup::origin`) from the edge functions of its own vertices at the box's
    /// first pixel centre, evaluated in i128 with the fill rule's bias.
    #[test]
    fn setup_origin_is_the_edge_functions_at_the_first_pixel(
        v in prop::array::uniform6(prop_oneof![
            -3000i64..30000,
            -(1i64 << 28) - 2..=-(1i64 << 28) + 2,
            (1i64 << 28) - 2..=(1i64 << 28) + 2,
            any::<i32>().prop_map(i64::from),
        ]),
    ) {
        let limit = (termrast::raster::GUARD_BAND_PX as i64) << 8;
        let fixed = [[v[0], v[1]], [v[2], v[3]], [v[4], v[5]]];
        match Setup::from_fixed(fixed, T) {
            Err(e) => {
                let beyond = v.iter().any(|c| c.abs() > limit);
                prop_assert_eq!(e == termrast::raster::Reject::BeyondGuardBand, beyond);
            }
            Ok(s) => {
                prop_assert!(v.iter().all(|c| c.abs() <= limit));
                let centre = |p: u32| i128::from(p) * 256 + 128;
                let (px, py) = (centre(s.bbox.x0), centre(s.bbox.y0));
                // The vertices in setup order (positive area).
                let sv = s.unflip(fixed);
                for e in 0..3 {
                    let (a, b) = (sv[e].map(i128::from), sv[(e + 1) % 3].map(i128::from));
                    let f = (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0]);
                    prop_assert_eq!(i128::from(s.origin[e]), f + i128::from(s.bias[e]), "edge {}", e);
                }
            }
        }
    }

    /// Arbitrary bit patterns: never a panic, never a pixel outside the target or bbox,
    /// and the same answer as the oracle (which also rejects NaN, inf and huge values).
    #[test]
    fn arbitrary_bits_never_escape(bits in prop::array::uniform6(any::<u64>()), pick in prop::array::uniform6(0u8..4)) {
        let v: Vec<f64> = bits.iter().zip(pick).map(|(&b, p)| match p {
            0 => f64::from_bits(b),
            1 => f64::from(f32::from_bits(b as u32)),
            _ => (b % 300_000) as f64 / 256.0 - 500.0,
        }).collect();
        let tri = [[v[0], v[1]], [v[2], v[3]], [v[4], v[5]]];
        assert_all_match_oracle(tri, T);
    }
}

#[test]
fn plane_lanes_give_one_over_z_and_barycentrics() {
    // Lane 0 is the 1/z plane: at each covered pixel, (1/z, w, u, v) from the lanes
    // equals the perspective formula evaluated from the exact barycentrics.
    let target = Target::new(64, 64);
    let tri = [[3.0, 2.0], [60.0, 9.0], [20.0, 61.0]];
    let zinv = [1.0, 0.25, 0.1];
    let s = Setup::new(tri, target).unwrap();
    let mut n = 0;
    planes_lanes(&s, zinv, |x, y, lanes| {
        let [iz, w, u, v] = lanes.normalized();
        let px = i64::from(x) * 256 + 128;
        let py = i64::from(y) * 256 + 128;
        let [bu, bv, bw] = s.barycentric_at_subpixel(px, py);
        assert!((u - bu).abs() < 1e-12 && (v - bv).abs() < 1e-12 && (w - bw).abs() < 1e-12);
        let want = bu * zinv[0] + bv * zinv[1] + bw * zinv[2];
        assert!((iz - want).abs() < 1e-8, "1/z {iz} vs {want}");
        n += 1;
    });
    assert!(n > 1000);
}

#[test]
fn oracle_agrees_with_the_fill_rule_on_shared_edges() {
    // The oracle itself: two triangles of a random quad never double-cover.
    let quad = [[2.25, 3.5], [40.0, 1.0], [44.5, 30.125], [5.0, 28.0]];
    let a = oracle_grid([quad[0], quad[1], quad[2]], T);
    let b = oracle_grid([quad[0], quad[2], quad[3]], T);
    assert!(a.counts.iter().zip(&b.counts).all(|(x, y)| x + y <= 1));
}

#[test]
fn benchmark_workloads_tile_exactly() {
    // The bench workloads are themselves watertightness tests: the sliver fan and the
    // jittered grid each cover every pixel of the target exactly once.
    use termrast::workload::{sliver_fan, tiling};
    let (w, h) = (320, 200);
    for tris in [sliver_fan(700, w, h, 3), tiling(7, 4, w, h, 2)] {
        for t in Traversal::ALL {
            let mut g = CountGrid::new(w, h);
            for tri in &tris {
                accumulate(&mut g, *tri, t);
            }
            assert!(g.counts.iter().all(|&c| c == 1), "{}", t.name());
        }
    }
}

/// `snap` rounds half away from zero exactly as `f64::round` does (it avoids the
/// library call), including values one ulp either side of a half.
#[test]
fn snap_rounds_like_f64_round() {
    use termrast::raster::{GUARD_BAND_PX, snap};
    let reference = |v: f64| (v * 256.0).round() as i64;
    let mut cases = vec![
        0.0,
        -0.0,
        2.5 / 256.0,
        -2.5 / 256.0,
        GUARD_BAND_PX,
        -GUARD_BAND_PX,
    ];
    for k in -600i32..600 {
        let half = (f64::from(k) + 0.5) / 256.0;
        cases.extend([half, half.next_up(), half.next_down()]);
    }
    cases.push(0.499_999_999_999_999_94 / 256.0);
    for v in cases {
        assert_eq!(snap(v), Some(reference(v)), "{v:e}");
    }
    assert_eq!(snap(GUARD_BAND_PX.next_up()), None);
    assert_eq!(snap(f64::NAN), None);
    proptest!(|(v in -GUARD_BAND_PX..=GUARD_BAND_PX)| {
        prop_assert_eq!(snap(v), Some(reference(v)));
    });
}

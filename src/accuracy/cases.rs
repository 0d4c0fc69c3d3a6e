//! Hard 2D cases for coverage: the stability suite (`tests/it/hard_cases.rs`) asserts the
//! exact variants on them and reports the float variants; `termrast bench accuracy`
//! prints the same counts, so the suite and the table agree.

use super::edge::EdgeArith;
use crate::raster::oracle;
use crate::raster::{CountGrid, GUARD_BAND_PX, Target};
use crate::workload::{Rng, Tri2, perimeter_point, sliver_fan};

/// A named set of triangles on a target.
#[derive(Clone, Debug)]
pub struct HardCase {
    pub name: &'static str,
    pub target: Target,
    pub triangles: Vec<Tri2>,
    /// The triangles tile the whole target exactly: every pixel must be covered once.
    pub tiles_target: bool,
}

/// A fan of triangles around `centre` through `ring` (closed), in order.
fn fan(centre: [f64; 2], ring: &[[f64; 2]]) -> Vec<Tri2> {
    (0..ring.len())
        .map(|i| [centre, ring[i], ring[(i + 1) % ring.len()]])
        .collect()
}

/// Points along the border of `[0, w] × [0, h]` at `steps` (clockwise from the origin).
fn border(w: f64, h: f64, n: usize, rng: &mut Rng) -> Vec<[f64; 2]> {
    let per = 2.0 * (w + h);
    let mut ts: Vec<f64> = (0..n).map(|_| rng.range(0.0, per)).collect();
    ts.extend([0.0, w, w + h, 2.0 * w + h]);
    ts.sort_by(f64::total_cmp);
    ts.dedup();
    ts.into_iter().map(|d| perimeter_point(d, w, h)).collect()
}

/// Every hard case, in suite order.
#[must_use]
pub fn all() -> Vec<HardCase> {
    let t = Target::new(96, 64);
    let (w, h) = (f64::from(t.width), f64::from(t.height));
    let mut rng = Rng::new(7);
    let mut cases = Vec::new();

    // Shared edges: a fan about an interior centre with unsnapped ring points.
    let ring = border(w, h, 60, &mut rng);
    cases.push(HardCase {
        name: "fan (shared edges)",
        target: t,
        triangles: fan([w * 0.37, h * 0.61], &ring),
        tiles_target: true,
    });
    // A fan whose centre is 1e5 px outside the target: wedges to points along a line
    // just right of it, so long and nearly parallel edges tile the target.
    let mut ys: Vec<f64> = (0..50).map(|_| rng.range(-10.0, h + 10.0)).collect();
    ys.extend([-10.0, h + 10.0]);
    ys.sort_by(f64::total_cmp);
    let centre = [-1.0e5, h * 0.5];
    cases.push(HardCase {
        name: "fan centred 1e5 px away",
        target: t,
        triangles: ys
            .windows(2)
            .map(|p| [centre, [w + 10.0, p[0]], [w + 10.0, p[1]]])
            .collect(),
        tiles_target: true,
    });
    // The sliver fan of the benchmarks: thousands of needles meeting at a point.
    cases.push(HardCase {
        name: "sliver fan",
        target: t,
        triangles: sliver_fan(400, t.width, t.height, 11),
        tiles_target: true,
    });
    // Needles: 1/256 px wide and 80 px long, at many angles, and collinear or
    // repeated vertices (zero area: must cover nothing).
    let mut needles = Vec::new();
    for k in 0..40 {
        let a = f64::from(k) * 0.157;
        let (c, s) = (a.cos(), a.sin());
        let p = [48.0 + rng.range(-0.5, 0.5), 32.0 + rng.range(-0.5, 0.5)];
        let q = [p[0] + 80.0 * c, p[1] + 80.0 * s];
        needles.push([p, q, [q[0] - s / 256.0, q[1] + c / 256.0]]);
    }
    cases.push(HardCase {
        name: "needles 1/256 px wide",
        target: t,
        triangles: needles,
        tiles_target: false,
    });
    let degenerate = vec![
        [[3.0, 3.0], [40.0, 20.0], [77.0, 37.0]],
        [[10.5, 10.5], [10.5, 10.5], [60.0, 50.0]],
        [[5.0, 5.0], [5.0, 5.0], [5.0, 5.0]],
        [[0.1, 30.2], [95.7, 30.2], [50.0, 30.2]],
    ];
    cases.push(HardCase {
        name: "collinear / repeated vertices",
        target: t,
        triangles: degenerate,
        tiles_target: false,
    });
    // Huge coordinates: at the guard band (accepted), and far from the origin with
    // a small triangle (precision of K = Ax·By − Ay·Bx).
    let g = GUARD_BAND_PX;
    let mut huge = vec![
        [[-g, -g], [g, -g], [0.0, g]],
        [[g, g], [-g, g * 0.999], [0.3, -g]],
    ];
    for _ in 0..30 {
        let (cx, cy) = (rng.range(0.0, w), rng.range(0.0, h));
        let far = 9.0e5;
        huge.push([
            [cx + far, cy],
            [cx - far, cy + rng.range(-3.0, 3.0)],
            [cx, cy + rng.range(4.0, 9.0)],
        ]);
    }
    cases.push(HardCase {
        name: "huge coordinates (to the guard band)",
        target: t,
        triangles: huge,
        tiles_target: false,
    });
    // Tiny triangles: below 1/256 px (snap to nothing or one step) around centres.
    let mut tiny = Vec::new();
    for _ in 0..300 {
        let p = [
            (rng.range(1.0, w - 1.0)).floor() + 0.5 + rng.range(-0.004, 0.004),
            (rng.range(1.0, h - 1.0)).floor() + 0.5 + rng.range(-0.004, 0.004),
        ];
        let s = rng.range(0.0005, 0.006);
        tiny.push([p, [p[0] + s, p[1] + s * 0.3], [p[0] - s * 0.2, p[1] + s]]);
    }
    cases.push(HardCase {
        name: "tiny (< 1/256 px to 1.5/256 px)",
        target: t,
        triangles: tiny,
        tiles_target: false,
    });
    // Long spans: rows 4000 px long, where incremental float stepping drifts.
    let long = Target::new(4000, 8);
    cases.push(HardCase {
        name: "long spans (4000 px rows)",
        target: long,
        triangles: vec![
            [[0.3, 0.2], [3999.7, 1.1], [2.2, 7.9]],
            [[3999.7, 1.1], [3998.1, 7.7], [2.2, 7.9]],
            [[0.0, 0.0], [4000.0, 0.0], [0.0, 0.2]],
        ],
        tiles_target: false,
    });
    cases
}

/// What a variant got wrong on a case.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Wrong {
    /// Pixels covered by the variant but not the oracle, or the other way, summed
    /// over triangles.
    pub mismatches: u64,
    /// For cases that tile the target: pixels nobody covered.
    pub holes: u64,
    /// For cases that tile the target: pixels covered more than once.
    pub double_hits: u64,
}

/// Runs a variant over a case and compares it with the i128 oracle.
#[must_use]
pub fn wrong(variant: EdgeArith, case: &HardCase) -> Wrong {
    let t = case.target;
    let mut out = Wrong::default();
    let mut grid = CountGrid::new(t.width, t.height);
    let mut got: Vec<(u32, u32)> = Vec::new();
    for &tri in &case.triangles {
        got.clear();
        variant.rasterize(tri, t, &mut got);
        for &(x, y) in &got {
            grid.counts[y as usize * t.width as usize + x as usize] += 1;
        }
        out.mismatches += mismatches(tri, t, &mut got);
    }
    if case.tiles_target {
        out.holes = grid.counts.iter().filter(|&&c| c == 0).count() as u64;
        out.double_hits = grid.counts.iter().filter(|&&c| c > 1).count() as u64;
    }
    out
}

/// Size of the symmetric difference between `got` (any order, sorted in place) and
/// the oracle's coverage of `tri`.
pub fn mismatches(tri: Tri2, t: Target, got: &mut [(u32, u32)]) -> u64 {
    got.sort_unstable_by_key(|&(x, y)| (y, x));
    let want = oracle_pixels(tri, t);
    symmetric_difference(got, &want)
}

/// The oracle's covered pixels of one triangle in row-major order.
#[must_use]
pub fn oracle_pixels(tri: Tri2, t: Target) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    oracle::for_each_covered(tri, t.width, t.height, |x, y| out.push((x, y)));
    out
}

/// `|a Δ b|` for two sorted (row-major) pixel lists.
#[must_use]
pub fn symmetric_difference(a: &[(u32, u32)], b: &[(u32, u32)]) -> u64 {
    let key = |p: &(u32, u32)| (p.1, p.0);
    let (mut i, mut j, mut n) = (0, 0, 0u64);
    while i < a.len() && j < b.len() {
        match key(&a[i]).cmp(&key(&b[j])) {
            std::cmp::Ordering::Equal => {
                i += 1;
                j += 1;
            }
            std::cmp::Ordering::Less => {
                n += 1;
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                n += 1;
                j += 1;
            }
        }
    }
    n + (a.len() - i) as u64 + (b.len() - j) as u64
}

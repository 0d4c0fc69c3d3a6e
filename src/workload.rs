//! Deterministic 2D workloads shared by the benchmarks, the accuracy table and tests.
//!
//! A tiny xorshift generator keeps them reproducible without a dependency.

/// A triangle in pixel coordinates.
pub type Tri2 = [[f64; 2]; 3];

/// Small deterministic generator (xorshift64*), enough for reproducible workloads.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed (0 is mapped to a fixed non-zero state).
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Self(seed.max(1).wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// `n` tiny triangles with sides of 1–4 px scattered over a `w × h` target.
#[must_use]
pub fn tiny_triangles(n: usize, w: u32, h: u32, seed: u64) -> Vec<Tri2> {
    let mut r = Rng::new(seed);
    (0..n)
        .map(|_| {
            let (cx, cy) = (r.range(0.0, f64::from(w)), r.range(0.0, f64::from(h)));
            let s = r.range(1.0, 4.0);
            let mut p = || [cx + r.range(-0.5, 0.5) * s, cy + r.range(-0.5, 0.5) * s];
            [p(), p(), p()]
        })
        .collect()
}

/// `2·cols·rows` triangles tiling a `w × h` target exactly (a grid of split quads with
/// jittered interior vertices): large, traversal-bound triangles.
#[must_use]
pub fn tiling(cols: u32, rows: u32, w: u32, h: u32, seed: u64) -> Vec<Tri2> {
    let mut r = Rng::new(seed);
    let (sx, sy) = (
        f64::from(w) / f64::from(cols),
        f64::from(h) / f64::from(rows),
    );
    let mut grid = vec![[0.0; 2]; ((cols + 1) * (rows + 1)) as usize];
    for j in 0..=rows {
        for i in 0..=cols {
            let interior = i > 0 && j > 0 && i < cols && j < rows;
            let jit = |r: &mut Rng, s: f64| {
                if interior {
                    r.range(-0.3, 0.3) * s
                } else {
                    0.0
                }
            };
            grid[(j * (cols + 1) + i) as usize] = [
                f64::from(i) * sx + jit(&mut r, sx),
                f64::from(j) * sy + jit(&mut r, sy),
            ];
        }
    }
    let at = |i: u32, j: u32| grid[(j * (cols + 1) + i) as usize];
    let mut out = Vec::with_capacity((2 * cols * rows) as usize);
    for j in 0..rows {
        for i in 0..cols {
            out.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            out.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    out
}

/// A fan of `n` slivers: a centre joined to points along the target's border at
/// irregular subpixel spacing. Tiles the `w × h` target exactly.
#[must_use]
pub fn sliver_fan(n: usize, w: u32, h: u32, seed: u64) -> Vec<Tri2> {
    let mut r = Rng::new(seed);
    let (fw, fh) = (f64::from(w), f64::from(h));
    let centre = [fw * 0.43, fh * 0.57];
    let perimeter = 2.0 * (fw + fh);
    let mut ts: Vec<f64> = (0..n).map(|_| r.range(0.0, perimeter)).collect();
    ts.extend([0.0, fw, fw + fh, 2.0 * fw + fh]);
    ts.sort_by(f64::total_cmp);
    let point = |d: f64| perimeter_point((d * 256.0).round() / 256.0, fw, fh);
    (0..ts.len())
        .map(|i| [centre, point(ts[i]), point(ts[(i + 1) % ts.len()])])
        .collect()
}

/// The point at distance `d` along the border of `[0, w] × [0, h]`, clockwise on
/// screen from the origin (top edge, right, bottom, left).
#[must_use]
pub fn perimeter_point(d: f64, w: f64, h: f64) -> [f64; 2] {
    if d <= w {
        [d, 0.0]
    } else if d <= w + h {
        [w, d - w]
    } else if d <= 2.0 * w + h {
        [w - (d - w - h), h]
    } else {
        [0.0, h - (d - 2.0 * w - h)]
    }
}

use wide::i64x4;

use crate::raster::{CoverageSink, Setup};

/// Largest number of fractional bits given to lane 0 (the 1/z plane).
const MAX_ZINV_BITS: u32 = 30;

/// The four planes at one pixel: `(F00, F01, F02, F03)` (see `docs/rasterization.md`).
///
/// Lanes 1–3 are the biased edge functions (the coverage test is lanes 1–3 ≥ 0).
/// Lane 0 is the 1/z plane, `F00 = F02/zA + F03/zB + F01/zC = area2/z`,
/// held in fixed point so the whole vector steps by exact integer adds: each vertex's
/// 1/z is quantized to `zinv_bits` fractional bits relative to the largest one, with
/// `zinv_bits` chosen per triangle as large as the bounding box allows without overflow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneLanes {
    /// Raw lane values.
    pub f: [i64; 4],
    /// Fill-rule bias in lanes 1–3, subtracted back for barycentrics.
    pub bias: [i64; 3],
    /// Doubled area: `F01 + F02 + F03` without bias.
    pub area2: i64,
    /// Scale of lane 0: `1/z = f[0] · zinv_unit / area2`.
    pub zinv_unit: f64,
}

impl PlaneLanes {
    /// The lanes divided by the doubled area: `(1/z, w, u, v)`,
    /// with `u, v, w` the weights of A, B, C.
    #[must_use]
    pub fn normalized(&self) -> [f64; 4] {
        let a = self.area2 as f64;
        [
            self.f[0] as f64 * self.zinv_unit / a,
            (self.f[1] - self.bias[0]) as f64 / a,
            (self.f[2] - self.bias[1]) as f64 / a,
            (self.f[3] - self.bias[2]) as f64 / a,
        ]
    }
}

/// Seed 000 §4: one `i64x4` per pixel, stepped by the vectors `I` and `J`, calling
/// `visit(x, y, lanes)` for each covered pixel. `zinv` holds 1/z of the caller's
/// vertices A, B, C (in the order given to [`Setup::new`]).
pub fn planes_lanes<V: FnMut(u32, u32, &PlaneLanes)>(s: &Setup, zinv: [f64; 3], mut visit: V) {
    let b = s.bbox;
    let zinv = s.unflip(zinv);
    let (x0, y0) = (i64::from(b.x0), i64::from(b.y0));
    // Largest |raw F| over the visited pixels, including the one step past each end.
    let (x1, y1) = (i64::from(b.x1) + 1, i64::from(b.y1) + 1);
    let mut bound = 0u64;
    for e in 0..3 {
        let m = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
            .iter()
            .map(|&(x, y)| s.edge_raw(e, x, y).unsigned_abs())
            .max()
            .unwrap_or(0);
        bound = bound.saturating_add(m);
    }
    let bits = (64 - bound.leading_zeros()).min(62);
    let k = (62 - bits).min(MAX_ZINV_BITS);
    let zmax = zinv.iter().fold(0.0f64, |m, z| m.max(z.abs()));
    let (q_abc, zinv_unit) = if zmax.is_finite() && zmax > 0.0 {
        let one = (1u64 << k) as f64;
        (zinv.map(|z| (z / zmax * one).round() as i64), zmax / one)
    } else {
        ([0; 3], 0.0)
    };
    // Weight of edge e in lane 0: F01 pairs with C, F02 with A, F03 with B.
    let q = [q_abc[2], q_abc[0], q_abc[1]];

    let (sx, sy) = (s.step_x(), s.step_y());
    let f0 = s.edges_at_origin();
    // Lane 0 combines the unbiased edge values.
    let lane0 = |f: [i64; 3]| (0..3).map(|e| q[e] * f[e]).sum::<i64>();
    let f0_raw = [0, 1, 2].map(|e| f0[e] - s.bias[e]);
    let step_i = i64x4::new([lane0(sx), sx[0], sx[1], sx[2]]);
    let step_j = i64x4::new([lane0(sy), sy[0], sy[1], sy[2]]);
    let mut cy = i64x4::new([lane0(f0_raw), f0[0], f0[1], f0[2]]);
    let mut lanes = PlaneLanes {
        f: [0; 4],
        bias: s.bias,
        area2: s.area2,
        zinv_unit,
    };
    let zero = i64x4::splat(0);
    for y in b.y0..=b.y1 {
        let mut cx = cy;
        for x in b.x0..=b.x1 {
            // Sign bits of lanes 1..3: any set means outside.
            if cx.simd_lt(zero).to_bitmask() & 0b1110 == 0 {
                lanes.f = cx.to_array();
                visit(x, y, &lanes);
            }
            cx += step_i;
        }
        cy += step_j;
    }
}

/// Coverage through the 4-lane plane layout (lane 0 carries a constant 1/z).
pub fn planes<S: CoverageSink>(s: &Setup, sink: &mut S) {
    planes_lanes(s, [1.0; 3], |x, y, _| sink.pixel(x, y));
}

//! The shape fit of 8 cells at once, one per SIMD lane: [`fit`](super::fit)'s
//! operations in the same order, so each lane's result has the same bits.

use super::{Fit, N, Repertoire, SX, SY, finish};
use crate::simd::F32s;

#[inline(always)]
fn add3<F: F32s>(a: [F; 3], b: [F; 3]) -> [F; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline(always)]
fn dot3<F: F32s>(a: [F; 3], b: [F; 3]) -> F {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// [`fit`](super::fit) for 8 cells at once, lane `k` holding cell `k`'s samples: the
/// same operations in the same order, so each lane's result has the same bits.
/// Runs on AVX2 registers when the CPU has them.
#[must_use]
pub fn fit_lanes<'r>(rep: &'r Repertoire, x: &[[[f32; 8]; 3]; N]) -> [Fit<'r>; 8] {
    #[cfg(target_arch = "x86_64")]
    if crate::simd::Isa::Avx2.is_supported() {
        // SAFETY: the CPU has the features the function is compiled for.
        return unsafe { fit_lanes_avx2(rep, x) };
    }
    fit_lanes_on::<wide::f32x8>(rep, x)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn fit_lanes_avx2<'r>(rep: &'r Repertoire, x: &[[[f32; 8]; 3]; N]) -> [Fit<'r>; 8] {
    fit_lanes_on::<crate::simd::avx2::F32x8>(rep, x)
}

#[inline(always)]
pub(in crate::terminal) fn fit_lanes_on<'r, F: F32s<Arr = [f32; 8]>>(
    rep: &'r Repertoire,
    x: &[[[f32; 8]; 3]; N],
) -> [Fit<'r>; 8] {
    let zero = F::splat(0.0);
    let mut sq = zero;
    // Each subset's sum adds its samples from the highest column down, as `fit` does:
    // the sum without its lowest column, plus that column (one add each).
    // Loops, not closures: a closure is compiled without the caller's target features,
    // so its lane operations would be calls.
    let mut rs = [[[zero; 3]; 16]; SY];
    for (r, row) in rs.iter_mut().enumerate() {
        let mut p = [[zero; 3]; SX];
        for (i, q) in p.iter_mut().enumerate() {
            for c in 0..3 {
                q[c] = F::from_array(x[r * SX + i][c]);
            }
            sq = sq + dot3(*q, *q);
        }
        let [p0, p1, p2, p3] = [
            add3([zero; 3], p[0]),
            add3([zero; 3], p[1]),
            add3([zero; 3], p[2]),
            add3([zero; 3], p[3]),
        ];
        let (s2, s4, s8) = (p1, p2, p3);
        let s6 = add3(s4, p[1]);
        let s10 = add3(s8, p[1]);
        let s12 = add3(s8, p[2]);
        let s14 = add3(s12, p[1]);
        *row = [
            [zero; 3],
            p0,
            s2,
            add3(s2, p[0]),
            s4,
            add3(s4, p[0]),
            s6,
            add3(s6, p[0]),
            s8,
            add3(s8, p[0]),
            s10,
            add3(s10, p[0]),
            s12,
            add3(s12, p[0]),
            s14,
            add3(s14, p[0]),
        ];
    }
    let mut t = [zero; 3];
    for row in &rs {
        t = add3(t, row[15]);
    }
    let tt = dot3(t, t);
    let uniform_score = tt / F::splat(N as f32);
    let mut best = uniform_score;
    // The chosen shape's index + 1 (0: uniform) and weighted sum.
    let mut best_k = zero;
    let mut best_y = t;
    for (k, sh) in rep.shapes.iter().enumerate() {
        let mut y = [zero; 3];
        for term in &sh.terms[..sh.n_terms] {
            let v = rs[usize::from(term.row)][usize::from(term.subset)];
            if term.weight == 1.0 {
                y = add3(y, v);
            } else {
                let w = F::splat(term.weight);
                y = add3(y, [v[0] * w, v[1] * w, v[2] * w]);
            }
        }
        let score = (F::splat(sh.b) * tt - F::splat(2.0 * sh.a) * dot3(t, y)
            + F::splat(N as f32) * dot3(y, y))
            * F::splat(sh.inv_det);
        let better = score.gt(best);
        if better.bitmask() != 0 {
            best = F::select(better, score, best);
            best_k = F::select(better, F::splat((k + 1) as f32), best_k);
            best_y = [
                F::select(better, y[0], best_y[0]),
                F::select(better, y[1], best_y[1]),
                F::select(better, y[2], best_y[2]),
            ];
        }
    }
    let (sq, uniform_score, best, best_k) = (
        sq.to_array(),
        uniform_score.to_array(),
        best.to_array(),
        best_k.to_array(),
    );
    let t = [t[0].to_array(), t[1].to_array(), t[2].to_array()];
    let best_y = [
        best_y[0].to_array(),
        best_y[1].to_array(),
        best_y[2].to_array(),
    ];
    std::array::from_fn(|l| {
        finish(
            (best_k[l] as usize).checked_sub(1).map(|k| &rep.shapes[k]),
            [t[0][l], t[1][l], t[2][l]],
            [best_y[0][l], best_y[1][l], best_y[2][l]],
            sq[l],
            uniform_score[l],
            best[l],
        )
    })
}

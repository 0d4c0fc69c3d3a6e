//! Vertices projected eight at a time: [`Projected::of`]'s operations lane by lane, so
//! every field is bit for bit the one-vertex projection's. The division by `w`, the
//! outcode's six plane distances and the snap are done in vector lanes; only the
//! assembly of each record is per vertex.

use wide::{f32x8, i32x8};

use super::Projected;
use crate::raster::clip::{ClipVertex, OUT_NOT_FINITE, OUT_W_NOT_POSITIVE, guard_band_ndc};
use crate::raster::setup::GUARD_BAND_PX;
use crate::raster::{SUBPIXEL_ONE, Target};
use crate::simd::{F32s, I32s};

/// `out` with one slot per vertex of `n`, its old contents left in place where it
/// already had `n` (a steady frame), to be overwritten.
pub(crate) fn one_per_vertex(out: &mut Vec<Projected>, n: usize) -> &mut [Projected] {
    if out.len() != n {
        out.clear();
        out.resize(n, Projected::default());
    }
    out
}

/// Projects `verts` for `target` into `out` (of the same length).
pub(crate) fn project_into<V>(verts: &[ClipVertex<V>], target: Target, out: &mut [Projected]) {
    assert_eq!(verts.len(), out.len(), "one projection per vertex");
    let guard = guard_band_ndc(target.width, target.height);
    let mut vs = verts.chunks_exact(8);
    let mut os = out.chunks_exact_mut(8);
    for (v, o) in (&mut vs).zip(&mut os) {
        project8(v, target, guard, o);
    }
    for (v, o) in vs.remainder().iter().zip(os.into_remainder()) {
        *o = Projected::of(v.pos, target, guard);
    }
}

/// A coordinate snapped in lanes, as [`crate::raster::setup::snap`] does in `f64`:
/// `t = v·256` is exact in `f32` (a power of two, and |t| ≤ 2^28 within the guard
/// band), as are its truncation and `t − trunc(t)`, so the half-way test and the
/// result are the same. Returns the snapped lanes (0 where a lane did not snap) and
/// the mask of those that did (finite and within the guard band).
#[inline(always)]
fn snap8(v: f32x8) -> ([i32; 8], u32) {
    let band = f32x8::splat(GUARD_BAND_PX as f32);
    let ok = v.le(band).bitmask() & (f32x8::splat(0.0) - band).le(v).bitmask();
    let t = v * f32x8::splat(SUBPIXEL_ONE as f32);
    let trunc = t.trunc_i32();
    let frac = t - trunc.to_f32();
    let up = i32x8::from_bits(f32x8::splat(0.5).le(frac).bitmask()) & i32x8::splat(1);
    // All ones, −1, where the lane rounds down.
    let down = i32x8::from_bits(frac.le(f32x8::splat(-0.5)).bitmask());
    (((trunc + up + down) & i32x8::from_bits(ok)).to_array(), ok)
}

/// Transposes an 8×8 bit matrix: bit `k` of byte `p` becomes bit `p` of byte `k`
/// (three exchanges of ever larger blocks).
#[inline(always)]
fn transpose8(mut x: u64) -> u64 {
    let t = (x ^ (x >> 7)) & 0x00AA_00AA_00AA_00AA;
    x ^= t ^ (t << 7);
    let t = (x ^ (x >> 14)) & 0x0000_CCCC_0000_CCCC;
    x ^= t ^ (t << 14);
    let t = (x ^ (x >> 28)) & 0x0000_0000_F0F0_F0F0;
    x ^ t ^ (t << 28)
}

// The outcode bits `project8` gathers by position: planes 0–5, then these two.
const _: () = assert!(OUT_W_NOT_POSITIVE == 1 << 6 && OUT_NOT_FINITE == 1 << 7);

/// Eight vertices' projections (see [`Projected::of`] for each field).
#[inline(always)]
fn project8<V>(v: &[ClipVertex<V>], target: Target, guard: [f32; 2], out: &mut [Projected]) {
    // Written out rather than `array::from_fn`, whose call the compiler leaves out of
    // line in some builds.
    let v = &v[..8];
    let lane = |c: usize| {
        f32x8::from([
            v[0].pos[c],
            v[1].pos[c],
            v[2].pos[c],
            v[3].pos[c],
            v[4].pos[c],
            v[5].pos[c],
            v[6].pos[c],
            v[7].pos[c],
        ])
    };
    let (x, y, z, w) = (lane(0), lane(1), lane(2), lane(3));
    let zero = f32x8::splat(0.0);
    // `0·c` is ±0 for finite `c`, NaN for infinities and NaN.
    let finite = [x, y, z, w]
        .iter()
        .fold(0xff, |m, &c| m & (c * zero).le(zero).bitmask());
    let (gx, gy) = (f32x8::splat(guard[0]) * w, f32x8::splat(guard[1]) * w);
    // Byte `p` holds outcode bit `p` of every lane: the six planes, `w ≤ 0`, non-finite.
    let rows = [z, w - z, gx - x, gx + x, gy - y, gy + y].map(|d| d.lt(zero).bitmask());
    let mut bits = u64::from(!finite & 0xff) << 56 | u64::from(!w.gt(zero).bitmask() & 0xff) << 48;
    for (p, r) in rows.iter().enumerate() {
        bits |= u64::from(r & 0xff) << (8 * p);
    }
    let codes = transpose8(bits).to_le_bytes();
    let inv_w = f32x8::splat(1.0) / w;
    let half = f32x8::splat(0.5);
    let size = |s: u32| f32x8::splat(s as f32);
    let sx = (x * inv_w * half + half) * size(target.width);
    let sy = (half - y * inv_w * half) * size(target.height);
    let ((fx, okx), (fy, oky)) = (snap8(sx), snap8(sy));
    let z = (z * inv_w).to_array();
    let (inv_w, sx, sy) = (inv_w.to_array(), sx.to_array(), sy.to_array());
    for (k, o) in out.iter_mut().enumerate() {
        let code = codes[k];
        *o = Projected {
            // A non-finite vertex has no other bit.
            out: if code & OUT_NOT_FINITE != 0 {
                OUT_NOT_FINITE
            } else {
                code
            },
            snapped: (okx & oky) >> k & 1 == 1,
            inv_w: inv_w[k],
            screen: [sx[k], sy[k]],
            z: z[k],
            fixed: [i64::from(fx[k]), i64::from(fy[k])],
        };
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec4;
    use proptest::prelude::*;

    use super::project_into;
    use crate::raster::Target;
    use crate::raster::clip::ClipVertex;
    use crate::render::Projected;

    /// A clip coordinate: ordinary values, and those that test every branch (zero,
    /// signed zeros, the guard band's edges, huge, infinite, NaN).
    fn coord() -> impl Strategy<Value = f32> {
        prop_oneof![
            4 => -3.0f32..3.0,
            1 => prop::sample::select(vec![
                0.0, -0.0, 1.0, -1.0, 1e-30, -1e-30, 1e30, -1e30, 3.5e4, -3.5e4,
                f32::MAX, f32::MIN, f32::INFINITY, f32::NEG_INFINITY, f32::NAN,
                f32::MIN_POSITIVE,
            ]),
            1 => any::<f32>(),
        ]
    }

    proptest! {
        /// Every field of every lane is the one-vertex projection's, bit for bit (the
        /// `Debug` form shows each float's exact value and each NaN as NaN).
        #[test]
        fn lanes_project_as_one_vertex(
            pos in prop::collection::vec((coord(), coord(), coord(), coord()), 0..40),
            (w, h) in (1u32..4000, 1u32..4000),
        ) {
            let target = Target::new(w, h);
            let verts: Vec<ClipVertex<()>> = pos
                .iter()
                .map(|&(x, y, z, w)| ClipVertex { pos: Vec4::new(x, y, z, w), var: () })
                .collect();
            let mut lanes = vec![Projected::default(); verts.len()];
            project_into(&verts, target, &mut lanes);
            let guard = crate::raster::clip::guard_band_ndc(w, h);
            for (v, l) in verts.iter().zip(&lanes) {
                let one = Projected::of(v.pos, target, guard);
                prop_assert_eq!(format!("{one:?}"), format!("{l:?}"), "{:?}", v.pos);
            }
        }
    }

    /// The bit transpose against its definition, on every single bit and random
    /// patterns.
    #[test]
    fn transpose8_swaps_rows_and_columns() {
        let slow = |x: u64| {
            let mut t = 0u64;
            for p in 0..8 {
                for k in 0..8 {
                    t |= (x >> (8 * p + k) & 1) << (8 * k + p);
                }
            }
            t
        };
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        for i in 0..64 {
            assert_eq!(super::transpose8(1 << i), slow(1 << i));
            x = x.rotate_left(13).wrapping_mul(0x2545_F491_4F6C_DD1D);
            assert_eq!(super::transpose8(x), slow(x));
        }
    }

    /// Coordinates that snap exactly half-way between subpixels, on both sides of
    /// zero, and at the guard band's edge, where rounding and the range test decide.
    #[test]
    fn half_way_and_band_edge_snap_as_one_vertex() {
        let target = Target::new(2, 2);
        let guard = crate::raster::clip::guard_band_ndc(2, 2);
        let mut verts = Vec::new();
        // Screen x = (ndc·0.5 + 0.5)·2 = ndc + 1: ndc = s − 1 puts it at s pixels.
        for s in [
            0.5f32 / 256.0,
            1.5 / 256.0,
            -0.5 / 256.0,
            -2.5 / 256.0,
            1048576.0,
            -1048576.0,
        ] {
            for d in [0.0f32, 1e-7, -1e-7] {
                let x = s + d - 1.0;
                verts.push(ClipVertex {
                    pos: Vec4::new(x, -x, 0.5, 1.0),
                    var: (),
                });
            }
        }
        let mut lanes = vec![Projected::default(); verts.len()];
        project_into(&verts, target, &mut lanes);
        for (v, l) in verts.iter().zip(&lanes) {
            let one = Projected::of(v.pos, target, guard);
            assert_eq!(format!("{one:?}"), format!("{l:?}"), "{:?}", v.pos);
        }
    }
}

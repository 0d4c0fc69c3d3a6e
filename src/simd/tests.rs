use proptest::prelude::*;
use wide::{f32x8, i32x8};

use super::{F32s, I32s, avx2, avx512};

/// Every operation of a backend on the given lanes, as bit patterns, one list of
/// lanes per operation (the lane masks as one value): the float lanes include NaN,
/// infinities, zeros of both signs and subnormals.
fn ops<F: F32s>(a: &[f32], b: &[f32], m: u32, k: &[i32]) -> Vec<Vec<u32>> {
    let floats = |v: &[f32]| {
        let mut arr = F::Arr::default();
        arr.as_mut().copy_from_slice(v);
        F::from_array(arr)
    };
    let mut ints = <F::I as I32s>::Arr::default();
    ints.as_mut().copy_from_slice(k);
    let (x, y) = (floats(a), floats(b));
    let mut out = Vec::new();
    let mut push = |v: F| out.push(v.to_array().as_ref().iter().map(|f| f.to_bits()).collect());
    push(x + y);
    push(x - y);
    push(x * y);
    push(x / y);
    push(x.sqrt());
    // Which NaN's payload a fused multiply-add keeps depends on the operand order
    // the compiler picks; only NaN-ness is compared (see the module docs).
    let canon = |v: F| {
        let mut arr = v.to_array();
        for f in arr.as_mut() {
            if f.is_nan() {
                *f = f32::NAN;
            }
        }
        F::from_array(arr)
    };
    let three_quarters: Vec<f32> = a.iter().map(|v| v * 0.75).collect();
    push(canon(x.mul_add(y, floats(&three_quarters))));
    push(canon(y.mul_add(y, x)));
    push(x.gt(y));
    push(x.lt(y));
    push(x.le(y));
    push(F::select(x.lt(y), x, y));
    push(x.max(y));
    push(x.min(y));
    push(F::I::from_bits(m).cast_f32());
    let i = F::I::from_array(ints);
    push(i.to_f32());
    push(((i + i.shl::<8>()) | (F::I::splat(7) & i)).cast_f32());
    push((i * F::I::splat(-77_777)).cast_f32());
    push(F::I::select(i.eq(F::I::splat(3)), i, F::I::from_bits(m)).cast_f32());
    // Truncation only where it is defined (the colour stores clamp first).
    let t = F::select(x.lt(F::splat(1e9)), x, F::splat(0.0));
    let t = F::select(t.gt(F::splat(-1e9)), t, F::splat(0.0));
    push(t.trunc_i32().cast_f32());
    let mut v = out;
    v.push(vec![x.lt(y).bitmask()]);
    v.push(vec![i.bitmask()]);
    v
}

/// [`ops`] of an 8-lane backend on the two 8-lane halves of 16 lanes, joined as the
/// 16-lane backend lays them out (masks: the second half's bits above the first's).
fn ops_by_halves<F: F32s>(a: &[f32], b: &[f32], m: u32, k: &[i32]) -> Vec<Vec<u32>> {
    let lo = ops::<F>(&a[..8], &b[..8], m & 0xFF, &k[..8]);
    let hi = ops::<F>(&a[8..], &b[8..], m >> 8, &k[8..]);
    lo.into_iter()
        .zip(hi)
        .map(|(l, h)| match (l.len(), &h[..]) {
            (1, [h]) => vec![l[0] | h << 8],
            _ => [l, h].concat(),
        })
        .collect()
}

/// Loads and masked stores of groups of rows `stride` apart, through the lanes of
/// `F`, checked against the same writes made place by place.
fn rows_round_trip<F: F32s>(stride: usize, mask: u32, seed: f32) -> Result<(), TestCaseError> {
    let len = 8 + 2 * stride + 16;
    let before: Vec<f32> = (0..len).map(|i| seed + i as f32).collect();
    let start = 3;
    let group = F::load_rows(&before, start, stride);
    let lanes = group.to_array();
    for (k, v) in lanes.as_ref().iter().enumerate() {
        prop_assert_eq!(
            *v,
            before[start + k / 8 * stride + k % 8],
            "load lane {}",
            k
        );
    }
    let new = group * F::splat(-2.0);
    let mut after = before.clone();
    new.store_rows(&mut after, start, stride, mask);
    let mut want = before.clone();
    for k in 0..8 * F::ROWS {
        if mask >> k & 1 == 1 {
            want[start + k / 8 * stride + k % 8] = -2.0 * lanes.as_ref()[k];
        }
    }
    prop_assert_eq!(after, want);
    Ok(())
}

fn lane() -> impl Strategy<Value = f32> {
    prop_oneof![
        any::<u32>().prop_map(f32::from_bits),
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(-0.0f32),
        Just(0.0f32),
        -10.0f32..10.0,
    ]
}

proptest! {
    #[test]
    fn avx2_lanes_equal_wide_lanes(
        a in prop::array::uniform8(lane()),
        b in prop::array::uniform8(lane()),
        m in any::<u8>(),
        k in prop::array::uniform8(any::<i32>()),
    ) {
        // Without AVX2 there is no second backend to compare (and `prop_assume!`
        // would reject every case and fail the run).
        if !super::Isa::Avx2.is_supported() {
            return Ok(());
        }
        let base = ops::<f32x8>(&a, &b, m.into(), &k);
        // SAFETY of the AVX2 lanes: the CPU was checked just above.
        let fast = ops::<avx2::F32x8>(&a, &b, m.into(), &k);
        prop_assert_eq!(base, fast);
    }

    /// The 16-lane backend computes, lane for lane, what the portable 8-lane one does
    /// on each half.
    #[test]
    fn avx512_lanes_equal_wide_lanes_by_halves(
        a in prop::array::uniform16(lane()),
        b in prop::array::uniform16(lane()),
        m in any::<u16>(),
        k in prop::array::uniform16(any::<i32>()),
    ) {
        if !super::Isa::Avx512.is_supported() {
            return Ok(());
        }
        let base = ops_by_halves::<f32x8>(&a, &b, m.into(), &k);
        // SAFETY of the AVX-512 lanes: the CPU was checked just above.
        let fast = ops::<avx512::F32x16>(&a, &b, m.into(), &k);
        prop_assert_eq!(base, fast);
    }

    /// Group loads and masked stores touch exactly the group's places, on every
    /// backend the CPU has; two-row groups also with a stride of 0 (the second row
    /// masked off), as the last row of a target uses them.
    #[test]
    fn row_loads_and_masked_stores_touch_only_the_group(
        stride in 8usize..40,
        mask in any::<u16>(),
        seed in -100.0f32..100.0,
    ) {
        rows_round_trip::<f32x8>(stride, u32::from(mask & 0xFF), seed)?;
        if super::Isa::Avx2.is_supported() {
            rows_round_trip::<avx2::F32x8>(stride, u32::from(mask & 0xFF), seed)?;
        }
        if super::Isa::Avx512.is_supported() {
            rows_round_trip::<avx512::F32x16>(stride, u32::from(mask), seed)?;
            rows_round_trip::<avx512::F32x16>(0, u32::from(mask & 0xFF), seed)?;
        }
    }
}

#[test]
fn from_bits_sets_the_lanes_of_the_mask() {
    for m in 0..=255u32 {
        let lanes = <i32x8 as I32s>::from_bits(m).to_array();
        for (k, v) in lanes.iter().enumerate() {
            assert_eq!(*v, if m >> k & 1 == 1 { -1 } else { 0 }, "mask {m:#b}");
        }
    }
}

//! `f32` and `i32` lane vectors behind two traits, so the hot loops (the `wide`
//! traversal, the fragment stage, the shaders' `fragment_lanes`, the colour stores) are
//! written once and compiled three times:
//!
//! - on [`wide`]'s `f32x8`/`i32x8`, for the build's target (on baseline x86-64 each
//!   is two SSE halves);
//! - on AVX2 registers (the crate-private `avx2` module), instantiated only inside
//!   [`crate::render::Renderer`]'s AVX2 draw loop, which runs after the CPU was checked;
//! - on 16-lane AVX-512 registers (`avx512`), only inside the AVX-512 draw loop.
//!
//! Lanes come in rows of 8 pixels: the 8-lane backends hold one row of a group, the
//! 16-lane one two rows (lane `k` is pixel `k % 8` of row `k / 8`). Small triangles
//! cover a few pixels of many rows, so two rows per group halve the groups of the
//! dense meshes, where a 16-pixel row would leave most lanes empty.
//!
//! `wide` picks its implementation when the crate is compiled, so a function compiled
//! with AVX2 enabled at run time still gets its SSE halves; these traits let that
//! function use 256-bit (or 512-bit) registers instead.
//!
//! All backends perform the same IEEE operations lane by lane, with no reassociation,
//! so they give identical bits (the tests compare whole frames). Fused multiply-add is
//! one of those operations ([`F32s::mul_add`], one rounding): one instruction on the
//! AVX2 path (which requires FMA, as every AVX2 CPU has it), the correctly rounded
//! `f32::mul_add` lane by lane on the baseline. (The one exception is which NaN payload
//! a fused multiply-add of NaNs keeps, which x86 ties to the operand order the compiler
//! picks; no output depends on it: NaN fails every depth test and clamps to 0 in
//! colour.) Masks are lanes of all ones or all zeros.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Sub};

/// `[body(0), body(1), body(2)]` with `e` bound to each index, expanded in place.
///
/// Per-edge and per-channel lane code uses this rather than a closure: a closure is a
/// function of its own, compiled without the AVX2 draw loop's target features, so the
/// intrinsics in its body would stay out-of-line calls.
macro_rules! each3 {
    (|$e:ident| $body:expr) => {
        [
            {
                let $e = 0usize;
                $body
            },
            {
                let $e = 1usize;
                $body
            },
            {
                let $e = 2usize;
                $body
            },
        ]
    };
}
pub(crate) use each3;

/// `f32` lanes: 8 per row of pixels, [`F32s::ROWS`] rows (lane `k` is pixel `k % 8` of
/// row `k / 8` of a group).
pub trait F32s:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// The integer lanes of the same backend.
    type I: I32s<F = Self>;
    /// Rows of 8 lanes: 1, or 2 for the 16-lane AVX-512 backend.
    const ROWS: usize;
    /// The lanes as an array (`[f32; 8 · ROWS]`).
    type Arr: Copy + Default + AsRef<[f32]> + AsMut<[f32]>;
    fn splat(v: f32) -> Self;
    fn from_array(a: Self::Arr) -> Self;
    fn to_array(self) -> Self::Arr;
    /// The lanes of row `r` from `s[start + r·stride..][..8]`. A stride of 0 loads the
    /// first row into every row (for groups whose later rows are masked off and may lie
    /// past the buffer).
    fn load_rows(s: &[f32], start: usize, stride: usize) -> Self;
    /// Stores the lanes whose bit is set in `mask` where [`F32s::load_rows`] reads them;
    /// the other places keep their values. With a stride of 0, only the first row's bits
    /// may be set.
    fn store_rows(self, s: &mut [f32], start: usize, stride: usize, mask: u32);
    /// Correctly rounded square root.
    fn sqrt(self) -> Self;
    /// `self · b + c` rounded once (IEEE fusedMultiplyAdd), as `f32::mul_add`.
    fn mul_add(self, b: Self, c: Self) -> Self;
    /// Mask of `self > o` (false for NaN).
    fn gt(self, o: Self) -> Self;
    /// Mask of `self < o` (false for NaN).
    fn lt(self, o: Self) -> Self;
    /// Mask of `self ≤ o` (false for NaN).
    fn le(self, o: Self) -> Self;
    /// `a` where `mask` is set, else `b`.
    fn select(mask: Self, a: Self, b: Self) -> Self;
    /// `self > o ? self : o` per lane (x86's `maxps`: `o` when either is NaN).
    fn max(self, o: Self) -> Self;
    /// `self < o ? self : o` per lane (x86's `minps`: `o` when either is NaN).
    fn min(self, o: Self) -> Self;
    /// The sign bit of lane `i` in bit `i` (for masks: which lanes are set).
    fn bitmask(self) -> u32;
    /// Truncation towards zero, for values within `i32` range.
    fn trunc_i32(self) -> Self::I;
}

/// `i32` lanes, laid out as [`F32s`]'s.
pub trait I32s:
    Copy + Add<Output = Self> + Mul<Output = Self> + BitOr<Output = Self> + BitAnd<Output = Self>
{
    /// The float lanes of the same backend.
    type F: F32s<I = Self>;
    /// As [`F32s::ROWS`].
    const ROWS: usize;
    /// The lanes as an array (`[i32; 8 · ROWS]`).
    type Arr: Copy + Default + AsRef<[i32]> + AsMut<[i32]>;
    fn splat(v: i32) -> Self;
    fn from_array(a: Self::Arr) -> Self;
    fn to_array(self) -> Self::Arr;
    /// As [`F32s::load_rows`].
    fn load_rows(s: &[i32], start: usize, stride: usize) -> Self;
    /// As [`F32s::store_rows`].
    fn store_rows(self, s: &mut [i32], start: usize, stride: usize, mask: u32);
    /// Shift left by `N` bits.
    fn shl<const N: i32>(self) -> Self;
    /// Mask of `self == o`.
    fn eq(self, o: Self) -> Self;
    /// `a` where `mask` is set, else `b`.
    fn select(mask: Self, a: Self, b: Self) -> Self;
    /// The sign bit of lane `i` in bit `i`.
    fn bitmask(self) -> u32;
    /// Conversion to `f32`, rounded to nearest.
    fn to_f32(self) -> Self::F;
    /// The same bits as float lanes (for using an integer mask on floats).
    fn cast_f32(self) -> Self::F;

    /// The lanes of a bit mask: lane `i` is all ones when bit `i` is set.
    fn from_bits(mask: u32) -> Self;
}

/// [`I32s::from_bits`] for 8 lanes.
#[inline(always)]
fn from_bits8<I: I32s<Arr = [i32; 8]>>(mask: u32) -> I {
    let bits = I::from_array([1, 2, 4, 8, 16, 32, 64, 128]);
    (I::splat(mask as i32) & bits).eq(bits)
}

/// The 8 places of one row's group, bounds-checked.
#[inline(always)]
fn row8<T>(s: &mut [T], start: usize) -> &mut [T; 8] {
    (&mut s[start..start + 8]).try_into().expect("8 lanes")
}

/// [`F32s::load_rows`] of the one-row (8-lane) backends.
#[inline(always)]
fn load_row8<F: F32s<Arr = [f32; 8]>>(s: &[f32], start: usize) -> F {
    F::from_array(s[start..start + 8].try_into().expect("8 lanes"))
}

/// [`F32s::store_rows`] of the one-row backends: one blended store of the row.
#[inline(always)]
fn store_row8<F: F32s<Arr = [f32; 8]>>(v: F, s: &mut [f32], start: usize, mask: u32) {
    let slot = row8(s, start);
    let keep = F::I::from_bits(mask).cast_f32();
    *slot = F::select(keep, v, F::from_array(*slot)).to_array();
}

/// [`I32s::load_rows`] of the one-row backends.
#[inline(always)]
fn load_row8_i<I: I32s<Arr = [i32; 8]>>(s: &[i32], start: usize) -> I {
    I::from_array(s[start..start + 8].try_into().expect("8 lanes"))
}

/// [`I32s::store_rows`] of the one-row backends: one blended store of the row.
#[inline(always)]
fn store_row8_i<I: I32s<Arr = [i32; 8]>>(v: I, s: &mut [i32], start: usize, mask: u32) {
    let slot = row8(s, start);
    *slot = I::select(I::from_bits(mask), v, I::from_array(*slot)).to_array();
}

/// `impl $tr for $t` by the intrinsic `$intr` on the register inside `$t`, for the
/// register backends below.
#[cfg(target_arch = "x86_64")]
macro_rules! binop {
    ($t:ident, $tr:ident, $f:ident, $intr:ident) => {
        impl $tr for $t {
            type Output = $t;
            #[inline(always)]
            fn $f(self, o: $t) -> $t {
                // SAFETY: values of this type exist only on CPUs with the instructions
                // its module names (module docs).
                $t(unsafe { $intr(self.0, o.0) })
            }
        }
    };
}

mod cpu;
mod portable;

pub use cpu::{Isa, prefetch};

#[cfg(target_arch = "x86_64")]
pub(crate) mod avx2;
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx512;

#[cfg(all(test, target_arch = "x86_64"))]
mod tests;

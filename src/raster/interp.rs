//! Varyings and their interpolation (seed 000 §3–4).
//!
//! A draw's varyings are one concrete type chosen at compile time, so the per-pixel
//! weighted sum is inlined for exactly the attributes the shader uses: a shader with
//! `()` varyings interpolates nothing.
//!
//! Screen-space barycentrics `(u, v, w)` come from the exact integer edge values
//! divided by the doubled area (so they are exact up to one rounding and do not lose
//! precision far from the origin). Perspective-correct weights follow eq. 16–23:
//! interpolate `1/w` and `attribute/w` linearly and divide once per pixel.

use glam::{Vec2, Vec3, Vec4};

/// A set of per-vertex attributes interpolated across a triangle.
pub trait Varying: Copy {
    /// The interpolated value for weights `w` (summing to 1), computed relative to `a`
    /// as `a + (b − a)·w[1] + (c − a)·w[2]`: a constant attribute stays exactly
    /// constant and a pixel at vertex A gets exactly A's value, which the sum
    /// `a·w[0] + b·w[1] + c·w[2]` does not guarantee in floating point.
    fn weighted(a: &Self, b: &Self, c: &Self, w: [f32; 3]) -> Self;

    /// `a + (b − a)·t`, used by clipping (linear in clip space).
    fn lerp(a: &Self, b: &Self, t: f32) -> Self;
}

macro_rules! vector_varying {
    ($($t:ty),*) => {$(
        impl Varying for $t {
            #[inline(always)]
            fn weighted(a: &Self, b: &Self, c: &Self, w: [f32; 3]) -> Self {
                *a + (*b - *a) * w[1] + (*c - *a) * w[2]
            }
            #[inline(always)]
            fn lerp(a: &Self, b: &Self, t: f32) -> Self {
                *a + (*b - *a) * t
            }
        }
    )*};
}
vector_varying!(f32, Vec2, Vec3, Vec4);

impl Varying for () {
    #[inline(always)]
    fn weighted(_: &Self, _: &Self, _: &Self, _: [f32; 3]) -> Self {}
    #[inline(always)]
    fn lerp(_: &Self, _: &Self, _: f32) -> Self {}
}

impl<A: Varying, B: Varying> Varying for (A, B) {
    #[inline(always)]
    fn weighted(a: &Self, b: &Self, c: &Self, w: [f32; 3]) -> Self {
        (
            A::weighted(&a.0, &b.0, &c.0, w),
            B::weighted(&a.1, &b.1, &c.1, w),
        )
    }
    #[inline(always)]
    fn lerp(a: &Self, b: &Self, t: f32) -> Self {
        (A::lerp(&a.0, &b.0, t), B::lerp(&a.1, &b.1, t))
    }
}

/// How attributes are interpolated across the screen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Interpolation {
    /// Weights `b_i/w_i / Σ b_j/w_j` (eq. 23): correct under perspective.
    Perspective,
    /// Screen-space weights: cheaper, wrong under perspective (kept for comparison).
    Affine,
}

/// Perspective-correct weights from screen-space barycentrics `b` and each vertex's
/// `1/w`, plus the interpolated `1/w` itself.
#[must_use]
#[inline(always)]
pub fn perspective_weights(b: [f32; 3], inv_w: [f32; 3]) -> ([f32; 3], f32) {
    // Same operations, same order, as the renderer's 8-lane path.
    let p = [b[0] * inv_w[0], b[1] * inv_w[1], b[2] * inv_w[2]];
    let s = p[0] + p[1] + p[2];
    let r = 1.0 / s;
    ([p[0] * r, p[1] * r, p[2] * r], s)
}

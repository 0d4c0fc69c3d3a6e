//! Varyings and their interpolation (barycentric and perspective-correct weights as
//! `docs/rasterization.md` defines them).
//!
//! A draw's varyings are one concrete type chosen at compile time, so the per-pixel
//! weighted sum is inlined for exactly the attributes the shader uses: a shader with
//! `()` varyings interpolates nothing.
//!
//! Screen-space barycentrics `(u, v, w)` come from the exact integer edge values
//! divided by the doubled area (so they are exact up to one rounding and do not lose
//! precision far from the origin). Perspective-correct weights
//! interpolate `1/w` and `attribute/w` linearly and divide once per pixel. A varying
//! whose shader needs only its direction ([`Direction`], Lambert's normal) skips the
//! division: `attribute/w` is a positive multiple of the attribute, which the
//! shader's normalisation removes.

use glam::{Vec2, Vec3, Vec4};

use crate::simd::each3;

/// A set of per-vertex attributes interpolated across a triangle. `Send + Sync`
/// and `'static`: a threaded draw's threads share and keep the per-triangle records.
pub trait Varying: Copy + Send + Sync + 'static {
    /// Whether the shader that reads the value divides it itself: it needs only its
    /// direction (a normal it normalises per pixel), or it carries its own weight
    /// ([`Homogeneous`]). Under perspective such a varying is interpolated as
    /// `attribute/w` itself, the numerator `Σ vᵢ·bᵢ/wᵢ` of the perspective-correct
    /// form, without the division by the interpolated `1/w`: as `Σ (vᵢ·cᵢ)·Fᵢ` for the
    /// exact edge values `Fᵢ`, with `cᵢ = (1/wᵢ)/area2` folded into the vertex values
    /// once per triangle ([`Varying::projective_form`]). That saves a division and a
    /// multiply per vertex per pixel. In the other modes it is a weighted sum of the
    /// vertex values (its relative form is `[a, b, c]`: see [`Direction`]).
    const PROJECTIVE: bool = false;

    /// The interpolated value for weights `w` (summing to 1), computed relative to `a`
    /// as `a + (b − a)·w[1] + (c − a)·w[2]`: a constant attribute stays exactly
    /// constant and a pixel at vertex A gets exactly A's value, which the sum
    /// `a·w[0] + b·w[1] + c·w[2]` does not guarantee in floating point.
    fn weighted(a: &Self, b: &Self, c: &Self, w: [f32; 3]) -> Self {
        Self::from_relative(&Self::relative(a, b, c), w)
    }

    /// `[a, b − a, c − a]`, what [`Varying::from_relative`] interpolates: computed once
    /// per triangle instead of once per pixel. ([`Varying::PROJECTIVE`] varyings keep
    /// `[a, b, c]`.)
    fn relative(a: &Self, b: &Self, c: &Self) -> [Self; 3];

    /// The per-triangle form of a [`Varying::PROJECTIVE`] varying under perspective,
    /// in place of [`Varying::relative`]: the vertex values `v` times `c` (see there).
    /// Other varyings are never asked for it.
    #[must_use]
    fn projective_form(v: &[Self; 3], c: [f32; 3]) -> [Self; 3] {
        let _ = c;
        *v
    }

    /// `r[0] + r[1]·w[1] + r[2]·w[2]` (as two fused multiply-adds, inner first) for `r`
    /// from [`Varying::relative`]: exactly [`Varying::weighted`] of the vertices `r`
    /// came from. ([`Varying::PROJECTIVE`] varyings: `r[0]·w[0] + r[1]·w[1] +
    /// r[2]·w[2]`, the same way.)
    fn from_relative(r: &[Self; 3], w: [f32; 3]) -> Self;

    /// `a + (b − a)·t`, used by clipping (linear in clip space).
    fn lerp(a: &Self, b: &Self, t: f32) -> Self;
}

/// A weight as the multiplier of a varying type: itself for `f32`, splatted for vectors.
trait Weight {
    fn weight(w: f32) -> Self;
}

impl Weight for f32 {
    #[inline(always)]
    fn weight(w: f32) -> Self {
        w
    }
}

macro_rules! vector_weight {
    ($($t:ty),*) => {$(
        impl Weight for $t {
            #[inline(always)]
            fn weight(w: f32) -> Self {
                <$t>::splat(w)
            }
        }
    )*};
}
vector_weight!(Vec2, Vec3, Vec4);

macro_rules! vector_varying {
    ($($t:ty),*) => {$(
        impl Varying for $t {
            #[inline(always)]
            fn relative(a: &Self, b: &Self, c: &Self) -> [Self; 3] {
                [*a, *b - *a, *c - *a]
            }
            #[inline(always)]
            fn from_relative(r: &[Self; 3], w: [f32; 3]) -> Self {
                // Fused: one rounding per term (a shader's `fragment_lanes` repeats this).
                r[2].mul_add(Self::weight(w[2]), r[1].mul_add(Self::weight(w[1]), r[0]))
            }
            #[inline(always)]
            fn lerp(a: &Self, b: &Self, t: f32) -> Self {
                *a + (*b - *a) * t
            }
        }
    )*};
}
vector_varying!(f32, Vec2, Vec3, Vec4);

/// A direction that its shader normalises per pixel (Lambert's normal): a
/// [`Varying::PROJECTIVE`] varying, interpolated as `Σ vᵢ·bᵢ/wᵢ` (a positive multiple
/// of the perspective-correct value) in the default perspective mode, and as an
/// ordinary weighted sum of the vertex values in the others.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Direction(pub Vec3);

impl Varying for Direction {
    const PROJECTIVE: bool = true;
    #[inline(always)]
    fn relative(a: &Self, b: &Self, c: &Self) -> [Self; 3] {
        // Weights that need not sum to 1 leave nothing to take relative to a vertex.
        [*a, *b, *c]
    }
    #[inline(always)]
    fn projective_form(v: &[Self; 3], c: [f32; 3]) -> [Self; 3] {
        each3!(|i| Self(v[i].0 * c[i]))
    }
    #[inline(always)]
    fn from_relative(r: &[Self; 3], w: [f32; 3]) -> Self {
        // Fused, inner first, from `a·w[0]` (Lambert's lane code repeats this).
        let [a, b, c] = each3!(|i| r[i].0);
        Self(c.mul_add(Vec3::splat(w[2]), b.mul_add(Vec3::splat(w[1]), a * w[0])))
    }
    #[inline(always)]
    fn lerp(a: &Self, b: &Self, t: f32) -> Self {
        Self(<Vec3 as Varying>::lerp(&a.0, &b.0, t))
    }
}

/// A value carried with its own weight, `(value, 1)` at the vertices, for a shader
/// that divides by the weight itself and can share that division with one of its
/// own (the coloured Lambert's normalisation): a [`Varying::PROJECTIVE`] varying.
/// Under perspective a pixel gets `Σ (vᵢ, 1)·bᵢ/wᵢ`, a positive multiple of the
/// perspective-correct `(value, 1)`; in the other modes the weights sum to 1, and so
/// does the weight up to rounding. The value is `scaled / weight`. (Four floats of
/// 4-byte alignment, not a `Vec4`, so a record holding three is not padded.)
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Homogeneous {
    /// The value times the weight.
    pub scaled: Vec3,
    pub weight: f32,
}

impl Homogeneous {
    /// `(v, 1)`: a vertex's value.
    #[must_use]
    pub fn new(v: Vec3) -> Self {
        Self {
            scaled: v,
            weight: 1.0,
        }
    }
}

impl Varying for Homogeneous {
    const PROJECTIVE: bool = true;
    #[inline(always)]
    fn relative(a: &Self, b: &Self, c: &Self) -> [Self; 3] {
        [*a, *b, *c]
    }
    #[inline(always)]
    fn projective_form(v: &[Self; 3], c: [f32; 3]) -> [Self; 3] {
        each3!(|i| Self {
            scaled: v[i].scaled * c[i],
            weight: v[i].weight * c[i],
        })
    }
    #[inline(always)]
    fn from_relative(r: &[Self; 3], w: [f32; 3]) -> Self {
        // As `Direction`'s, per component (the coloured Lambert's lane code repeats it).
        let [a, b, c] = *r;
        Self {
            scaled: Direction::from_relative(&each3!(|i| Direction(r[i].scaled)), w).0,
            weight: c
                .weight
                .mul_add(w[2], b.weight.mul_add(w[1], a.weight * w[0])),
        }
    }
    #[inline(always)]
    fn lerp(a: &Self, b: &Self, t: f32) -> Self {
        Self {
            scaled: <Vec3 as Varying>::lerp(&a.scaled, &b.scaled, t),
            weight: <f32 as Varying>::lerp(&a.weight, &b.weight, t),
        }
    }
}

impl Varying for () {
    #[inline(always)]
    fn relative(_: &Self, _: &Self, _: &Self) -> [Self; 3] {
        [(); 3]
    }
    #[inline(always)]
    fn from_relative(_: &[Self; 3], _: [f32; 3]) -> Self {}
    #[inline(always)]
    fn lerp(_: &Self, _: &Self, _: f32) -> Self {}
}

/// Packed attributes (a scene object's, laid out at run time): each float is
/// interpolated as an `f32` varying is, so a packed `Vec3` gets the same bits as a
/// `Vec3` varying.
impl<const K: usize> Varying for [f32; K] {
    #[inline(always)]
    fn relative(a: &Self, b: &Self, c: &Self) -> [Self; 3] {
        [
            *a,
            std::array::from_fn(|i| b[i] - a[i]),
            std::array::from_fn(|i| c[i] - a[i]),
        ]
    }
    #[inline(always)]
    fn from_relative(r: &[Self; 3], w: [f32; 3]) -> Self {
        std::array::from_fn(|i| r[2][i].mul_add(w[2], r[1][i].mul_add(w[1], r[0][i])))
    }
    #[inline(always)]
    fn lerp(a: &Self, b: &Self, t: f32) -> Self {
        std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t)
    }
}

/// Projective when both parts are; otherwise both take weights that sum to 1, which
/// a projective part shades the same with.
impl<A: Varying, B: Varying> Varying for (A, B) {
    const PROJECTIVE: bool = A::PROJECTIVE && B::PROJECTIVE;
    #[inline(always)]
    fn projective_form(v: &[Self; 3], c: [f32; 3]) -> [Self; 3] {
        let a = A::projective_form(&each3!(|i| v[i].0), c);
        let b = B::projective_form(&each3!(|i| v[i].1), c);
        each3!(|i| (a[i], b[i]))
    }
    #[inline(always)]
    fn relative(a: &Self, b: &Self, c: &Self) -> [Self; 3] {
        let [a0, a1, a2] = A::relative(&a.0, &b.0, &c.0);
        let [b0, b1, b2] = B::relative(&a.1, &b.1, &c.1);
        [(a0, b0), (a1, b1), (a2, b2)]
    }
    #[inline(always)]
    fn from_relative(r: &[Self; 3], w: [f32; 3]) -> Self {
        (
            A::from_relative(&[r[0].0, r[1].0, r[2].0], w),
            B::from_relative(&[r[0].1, r[1].1, r[2].1], w),
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
    /// Weights `b_i/w_i / Σ b_j/w_j` at every pixel: correct under perspective.
    Perspective,
    /// Perspective-correct at every 4th pixel of a row (x a multiple of 4), linear in
    /// between: the classic subdivided span of software renderers.
    #[value(name = "perspective-4")]
    Perspective4,
    /// As `perspective-4`, every 8th pixel.
    #[value(name = "perspective-8")]
    Perspective8,
    /// As `perspective-4`, every 16th pixel.
    #[value(name = "perspective-16")]
    Perspective16,
    /// Screen-space weights: cheaper, wrong under perspective (kept for comparison).
    Affine,
}

impl Interpolation {
    /// Every mode, in table order.
    pub const ALL: [Interpolation; 5] = [
        Interpolation::Affine,
        Interpolation::Perspective,
        Interpolation::Perspective4,
        Interpolation::Perspective8,
        Interpolation::Perspective16,
    ];

    /// The name used on the command line and in tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Interpolation::Perspective => "perspective",
            Interpolation::Perspective4 => "perspective-4",
            Interpolation::Perspective8 => "perspective-8",
            Interpolation::Perspective16 => "perspective-16",
            Interpolation::Affine => "affine",
        }
    }

    /// The span length of the subdivided modes: exact weights at pixels whose x is a
    /// multiple of it, linear in between.
    #[must_use]
    pub fn span(self) -> Option<u32> {
        match self {
            Interpolation::Perspective4 => Some(4),
            Interpolation::Perspective8 => Some(8),
            Interpolation::Perspective16 => Some(16),
            Interpolation::Perspective | Interpolation::Affine => None,
        }
    }
}

/// Where pixel `x` lies in its span of length `n`: the span's first pixel and the
/// fraction `t` of the way to the next span's first pixel. The renderer's lanes and
/// the probe both use this, so their weights agree bit for bit.
#[must_use]
#[inline(always)]
pub fn span_position(x: u32, n: u32) -> (u32, f32) {
    let a = x & !(n - 1);
    (a, (x - a) as f32 / n as f32)
}

/// Linear interpolation of span-end weights: `wa + (wb − wa)·t` per vertex.
#[must_use]
#[inline(always)]
pub fn span_lerp(wa: [f32; 3], wb: [f32; 3], t: f32) -> [f32; 3] {
    [
        wa[0] + (wb[0] - wa[0]) * t,
        wa[1] + (wb[1] - wa[1]) * t,
        wa[2] + (wb[2] - wa[2]) * t,
    ]
}

//! Ready-made shaders over a [`Mesh`].

use glam::{Mat3, Mat4, Vec3, Vec4};

use super::{ShadeLanes, Shader};
use crate::mesh::Mesh;
use crate::raster::interp::{Direction, Homogeneous};
use crate::simd::{F32s, each3};

/// The standard light direction (towards the light, world space), normalised.
#[must_use]
pub fn standard_light() -> Vec3 {
    Vec3::new(0.4, 0.6, 1.0).normalize()
}

/// Per-pixel Lambert shading from interpolated normals (the benchmark scene).
/// Varying: the world-space normal, as a [`Direction`]: the shading normalises it, so
/// it is interpolated without the perspective division (see
/// [`Varying::PROJECTIVE`](crate::raster::interp::Varying::PROJECTIVE)).
#[derive(Clone, Debug)]
pub struct Lambert<'a> {
    pub mesh: &'a Mesh,
    /// Model-view-projection.
    pub mvp: Mat4,
    /// Model rotation for normals.
    pub normal_matrix: Mat3,
    /// Towards the light, normalised, world space.
    pub light: Vec3,
    /// Surface colour times `1 − ambient`: the colour is `l·lit + unlit` for the
    /// cosine `l`, one fused multiply-add per channel. Set with the ambient term by
    /// [`Lambert::with_material`], once per draw rather than per fragment.
    lit: Vec3,
    /// Surface colour times the ambient term.
    unlit: Vec3,
    /// The surface colour and the ambient term themselves ([`ColoredLambert`]).
    base: Vec3,
    ambient: f32,
    /// Whether the three channels of the surface colour are equal (see
    /// [`ShadeLanes::Grey`]).
    grey: bool,
}

impl<'a> Lambert<'a> {
    /// A white Lambert shader; `mesh` must have normals ([`Mesh::ensure_normals`]).
    #[must_use]
    pub fn new(mesh: &'a Mesh, model: Mat4, view_proj: Mat4) -> Self {
        Self {
            mesh,
            mvp: view_proj * model,
            normal_matrix: Mat3::from_mat4(model).inverse().transpose(),
            light: standard_light(),
            lit: Vec3::ONE,
            unlit: Vec3::ZERO,
            base: Vec3::ONE,
            ambient: 0.0,
            grey: true,
        }
        .with_material(Vec3::ONE, 0.08)
    }

    /// The same shader with surface colour `base` and ambient term `ambient`.
    #[must_use]
    pub fn with_material(self, base: Vec3, ambient: f32) -> Self {
        Self {
            lit: base * (1.0 - ambient),
            unlit: base * ambient,
            base,
            ambient,
            grey: base.x == base.y && base.y == base.z,
            ..self
        }
    }
}

impl Lambert<'_> {
    /// The lit cosine `max(n·L / |n|, 0)` of an interpolated normal (shorter than 1:
    /// it is normalised here). Written out, with fused multiply-adds, so
    /// [`Lambert::cosine_lanes`] repeats it bit for bit.
    #[inline(always)]
    fn cosine(&self, n: Vec3) -> f32 {
        let lt = self.light;
        let len = n.z.mul_add(n.z, n.y.mul_add(n.y, n.x * n.x)).sqrt();
        let d = n.z.mul_add(lt.z, n.y.mul_add(lt.y, n.x * lt.x));
        let l = d / len;
        if l > 0.0 { l } else { 0.0 }
    }

    /// [`Lambert::cosine`] on lanes of the normal's components.
    #[inline(always)]
    fn cosine_lanes<F: F32s>(&self, [x, y, z]: [F; 3]) -> F {
        let len = z.mul_add(z, y.mul_add(y, x * x)).sqrt();
        let lt = self.light;
        let d = z.mul_add(
            F::splat(lt.z),
            y.mul_add(F::splat(lt.y), x * F::splat(lt.x)),
        );
        // NaN (zero-length normal) compares false and becomes 0, as in `cosine`.
        (d / len).max(F::splat(0.0))
    }
}

impl Shader for Lambert<'_> {
    type Varying = Direction;
    const LANE_CODE: bool = true;

    #[inline(always)]
    fn vertex(&self, index: u32) -> (Vec4, Direction) {
        let i = index as usize;
        let p = self.mesh.positions[i];
        let n = self.mesh.normals.get(i).copied().unwrap_or(Vec3::Z);
        (self.mvp * p.extend(1.0), Direction(self.normal_matrix * n))
    }

    #[inline(always)]
    fn fragment(&self, &Direction(n): &Direction) -> Vec3 {
        Vec3::splat(self.cosine(n)).mul_add(self.lit, self.unlit)
    }

    #[inline(always)]
    fn fragment_lanes<F: F32s>(
        &self,
        rel: &[Direction; 3],
        w: &[F; 3],
        _mask: u32,
    ) -> ShadeLanes<F> {
        let [Direction(a), Direction(b), Direction(c)] = *rel;
        let n = each3!(|i| weigh_lanes([a[i], b[i], c[i]], w));
        let l = self.cosine_lanes(n);
        let (lit, unlit) = (self.lit, self.unlit);
        // A grey base (the standard scene's white) gives three equal channels: one
        // multiply-add and, in the target, one conversion.
        if self.grey {
            ShadeLanes::Grey(l.mul_add(F::splat(lit.x), F::splat(unlit.x)))
        } else {
            ShadeLanes::Rgb(each3!(|i| l.mul_add(F::splat(lit[i]), F::splat(unlit[i]))))
        }
    }
}

/// [`Lambert`] times the mesh's vertex colours (a scan's, a painted asset's):
/// `colour·base·((1 − ambient)·l + ambient)` for the cosine `l`, with lane code of
/// its own. Varying: the world-space normal as a [`Direction`] and the vertex colour
/// times the surface colour as a [`Homogeneous`] value, both
/// [`Varying::PROJECTIVE`](crate::raster::interp::Varying::PROJECTIVE): under
/// perspective neither is divided by the interpolated `1/w` before the shader, which
/// divides once, for the normal's length and the colour's weight together.
#[derive(Clone, Debug)]
pub struct ColoredLambert<'a> {
    lambert: Lambert<'a>,
    /// Towards the light, times `1 − ambient`.
    light: Vec3,
}

/// The least normal length [`ColoredLambert`] divides by: a zero normal (cosine 0)
/// shades `colour·base·ambient`, as [`Lambert`]'s does, instead of `0/0`.
const MIN_NORMAL_LENGTH: f32 = 1e-20;

/// `x > y ? x : y`, the lanes' `max` (which returns `y` when either is NaN).
#[inline(always)]
fn max(x: f32, y: f32) -> f32 {
    if x > y { x } else { y }
}

impl<'a> ColoredLambert<'a> {
    /// `lambert` times the mesh's vertex colours (white where it has none).
    #[must_use]
    pub fn new(lambert: Lambert<'a>) -> Self {
        let light = lambert.light * (1.0 - lambert.ambient);
        Self { lambert, light }
    }

    /// The colour for an interpolated normal `n` and colour `h = (s·c, s)`, with one
    /// division: `c·((1 − ambient)·max(n·L, 0)/|n| + ambient)` is `h·m` for
    /// `m = (max(n·L′, 0) + ambient·|n|) / (|n|·s)`, `L′ = (1 − ambient)·L`.
    /// Written out, with fused multiply-adds, so [`ColoredLambert::shade_lanes`]
    /// repeats it bit for bit.
    #[inline(always)]
    fn shade(&self, n: Vec3, h: Homogeneous) -> Vec3 {
        let lt = self.light;
        let len2 = n.z.mul_add(n.z, n.y.mul_add(n.y, n.x * n.x));
        let len = max(len2.sqrt(), MIN_NORMAL_LENGTH);
        let d = n.z.mul_add(lt.z, n.y.mul_add(lt.y, n.x * lt.x));
        let m = len.mul_add(self.lambert.ambient, max(d, 0.0)) * (1.0 / (len * h.weight));
        h.scaled * m
    }

    /// [`ColoredLambert::shade`] on lanes.
    #[inline(always)]
    fn shade_lanes<F: F32s>(&self, [x, y, z]: [F; 3], h: [F; 3], weight: F) -> [F; 3] {
        let lt = self.light;
        let len = z
            .mul_add(z, y.mul_add(y, x * x))
            .sqrt()
            .max(F::splat(MIN_NORMAL_LENGTH));
        let d = z.mul_add(
            F::splat(lt.z),
            y.mul_add(F::splat(lt.y), x * F::splat(lt.x)),
        );
        let ambient = F::splat(self.lambert.ambient);
        let m = len.mul_add(ambient, d.max(F::splat(0.0))) * (F::splat(1.0) / (len * weight));
        each3!(|i| h[i] * m)
    }
}

impl Shader for ColoredLambert<'_> {
    type Varying = (Direction, Homogeneous);
    const LANE_CODE: bool = true;

    #[inline(always)]
    fn vertex(&self, index: u32) -> (Vec4, (Direction, Homogeneous)) {
        let l = &self.lambert;
        let (pos, n) = l.vertex(index);
        let c = l.mesh.colors.get(index as usize).copied();
        (pos, (n, Homogeneous::new(c.unwrap_or(Vec3::ONE) * l.base)))
    }

    #[inline(always)]
    fn fragment(&self, &(Direction(n), h): &(Direction, Homogeneous)) -> Vec3 {
        self.shade(n, h)
    }

    #[inline(always)]
    fn fragment_lanes<F: F32s>(
        &self,
        rel: &[(Direction, Homogeneous); 3],
        w: &[F; 3],
        _mask: u32,
    ) -> ShadeLanes<F> {
        // Through `black_box`, the 21 vertex terms are loaded and broadcast for each
        // group: otherwise the compiler hoists their broadcasts out of the group loop,
        // has too few vector registers for them, and spills each as a 64-byte vector
        // per triangle (see docs/performance.md, "The coloured Lambert's terms").
        let [
            (Direction(na), ha),
            (Direction(nb), hb),
            (Direction(nc), hc),
        ] = *std::hint::black_box(rel);
        let n = each3!(|i| weigh_lanes([na[i], nb[i], nc[i]], w));
        let h = each3!(|i| weigh_lanes([ha.scaled[i], hb.scaled[i], hc.scaled[i]], w));
        let weight = weigh_lanes([ha.weight, hb.weight, hc.weight], w);
        ShadeLanes::Rgb(self.shade_lanes(n, h, weight))
    }
}

/// One component of a [`Varying::PROJECTIVE`](crate::raster::interp::Varying::PROJECTIVE)
/// varying's weighted sum on lanes, from its vertex values `r`: `r[0]·w[0] + r[1]·w[1]
/// + r[2]·w[2]`, fused, inner first, as its `from_relative` computes it. (A plain
/// function: closures, as `array::from_fn` takes, stay outside the lane copies.)
#[inline(always)]
fn weigh_lanes<F: F32s>(r: [f32; 3], w: &[F; 3]) -> F {
    F::splat(r[2]).mul_add(w[2], F::splat(r[1]).mul_add(w[1], F::splat(r[0]) * w[0]))
}

#[cfg(test)]
mod tests {
    use glam::{Mat4, Vec3};
    use proptest::prelude::*;
    use wide::f32x8;

    use super::{ColoredLambert, Lambert};
    use crate::mesh::Mesh;
    use crate::raster::interp::{Direction, Homogeneous, Varying};
    use crate::render::perspective_weights;
    use crate::render::{ShadeLanes, Shader};
    use crate::simd::F32s;

    fn vec3() -> impl Strategy<Value = Vec3> {
        prop::array::uniform3(-2.0f32..2.0).prop_map(Vec3::from)
    }

    /// A unit normal within 60° of +z, so that interpolating three of them never comes
    /// near the zero vector, where the normalisation is ill-conditioned.
    fn normal() -> impl Strategy<Value = Vec3> {
        (-1.0f32..1.0, -1.0f32..1.0).prop_map(|(x, y)| Vec3::new(x, y, 2.0).normalize())
    }

    proptest! {
        /// Interpolating Lambert's normal without the perspective division shades as
        /// the perspective-correct normal does, up to rounding: the two differ by the
        /// positive factor `Σ pᵢ`, which the normalisation removes.
        #[test]
        fn projective_normals_shade_as_perspective_correct_ones(
            n in prop::array::uniform3(normal()),
            q in (1.0f32..1e6, 0.0f32..1e6, 0.0f32..1e6),
            c in prop::array::uniform3(1e-9f32..1e-3),
            ambient in 0.0f32..0.5,
        ) {
            let mesh = Mesh::teapot();
            let shader = Lambert::new(&mesh, Mat4::IDENTITY, Mat4::IDENTITY)
                .with_material(Vec3::ONE, ambient);
            let q = [q.0, q.1, q.2];
            let (persp, _) = perspective_weights(q, c);
            let exact = shader.fragment(&Direction(Vec3::weighted(&n[0], &n[1], &n[2], persp)));
            let proj = Direction::projective_form(&n.map(Direction), c);
            let fast = shader.fragment(&Direction::from_relative(&proj, q));
            let err = (exact - fast).abs().max_element();
            prop_assert!(err <= 2e-6, "{exact} against {fast}");
        }

        /// Lambert's 8-lane fragments equal its per-pixel ones bit for bit, for grey
        /// bases (one channel) and coloured ones (three), on every lane of the mask.
        #[test]
        fn lambert_lanes_equal_single_fragments(
            verts in prop::array::uniform3(vec3().prop_map(Direction)),
            w in prop::array::uniform3(prop::array::uniform8(0.0f32..1.0)),
            base in vec3(),
            grey in any::<bool>(),
            ambient in 0.0f32..0.5,
            mask in 1..=255u8,
        ) {
            let mesh = Mesh::teapot();
            let base = if grey { Vec3::splat(base.x.abs()) } else { base.abs() };
            let shader = Lambert::new(&mesh, Mat4::IDENTITY, Mat4::IDENTITY)
                .with_material(base, ambient);
            let rel = Direction::relative(&verts[0], &verts[1], &verts[2]);
            let lanes = w.map(f32x8::from);
            let shade = shader.fragment_lanes(&rel, &lanes, mask.into());
            prop_assert_eq!(matches!(shade, ShadeLanes::Grey(_)), grey);
            let rgb = match shade {
                ShadeLanes::Grey(g) => [g, g, g],
                ShadeLanes::Rgb(c) => c,
            }
            .map(F32s::to_array);
            for k in (0..8).filter(|k| mask >> k & 1 == 1) {
                let v = Direction::from_relative(&rel, [w[0][k], w[1][k], w[2][k]]);
                let one = shader.fragment(&v);
                for (c, lane) in one.to_array().iter().zip(rgb) {
                    prop_assert_eq!(c.to_bits(), lane[k].to_bits(), "lane {}", k);
                }
            }
        }

        /// The coloured Lambert's 8-lane fragments equal its per-pixel ones bit for
        /// bit, zero normals included.
        #[test]
        fn colored_lambert_lanes_equal_single_fragments(
            normals in prop::array::uniform3(prop_oneof![vec3(), Just(Vec3::ZERO)]),
            colors in prop::array::uniform3(prop::array::uniform3(0.0f32..1.0)),
            w in prop::array::uniform3(prop::array::uniform8(0.0f32..1.0)),
            base in vec3(),
            ambient in 0.0f32..0.5,
            mask in 1..=255u8,
        ) {
            let mesh = Mesh::teapot();
            let shader = ColoredLambert::new(
                Lambert::new(&mesh, Mat4::IDENTITY, Mat4::IDENTITY)
                    .with_material(base.abs(), ambient),
            );
            let v = |i: usize| (Direction(normals[i]), Homogeneous::new(Vec3::from(colors[i])));
            let rel = <(Direction, Homogeneous)>::relative(&v(0), &v(1), &v(2));
            let lanes = w.map(f32x8::from);
            let ShadeLanes::Rgb(rgb) = shader.fragment_lanes(&rel, &lanes, mask.into()) else {
                panic!("a coloured shader shades three channels");
            };
            let rgb = rgb.map(F32s::to_array);
            for k in (0..8).filter(|k| mask >> k & 1 == 1) {
                let one = shader.fragment(&<(Direction, Homogeneous)>::from_relative(
                    &rel,
                    [w[0][k], w[1][k], w[2][k]],
                ));
                prop_assert!(one.is_finite(), "{one}");
                for (c, lane) in one.to_array().iter().zip(rgb) {
                    prop_assert_eq!(c.to_bits(), lane[k].to_bits(), "lane {}", k);
                }
            }
        }

        /// The coloured Lambert, given its normal and colour without the perspective
        /// division, shades as the perspective-correct formula does (in f64), to
        /// within a few units of rounding: `colour·base·((1 − a)·max(n·L/|n|, 0) + a)`.
        #[test]
        fn colored_lambert_shades_the_perspective_correct_colour(
            n in prop::array::uniform3(normal()),
            colors in prop::array::uniform3(prop::array::uniform3(0.0f32..1.0)),
            q in (1.0f32..1e6, 0.0f32..1e6, 0.0f32..1e6),
            c in prop::array::uniform3(1e-9f32..1e-3),
            base in prop::array::uniform3(0.0f32..1.0),
            ambient in 0.0f32..0.5,
        ) {
            let mesh = Mesh::teapot();
            let base = Vec3::from(base);
            let shader = ColoredLambert::new(
                Lambert::new(&mesh, Mat4::IDENTITY, Mat4::IDENTITY)
                    .with_material(base, ambient),
            );
            let q = [q.0, q.1, q.2];
            let verts = [0, 1, 2].map(|i| (Direction(n[i]), Homogeneous::new(Vec3::from(colors[i]) * base)));
            let proj = <(Direction, Homogeneous)>::projective_form(&verts, c);
            let fast = shader.fragment(&<(Direction, Homogeneous)>::from_relative(&proj, q));
            // The oracle: perspective weights and the formula, in f64.
            let p: [f64; 3] = std::array::from_fn(|i| f64::from(q[i]) * f64::from(c[i]));
            let sum: f64 = p.iter().sum();
            let mix = |v: [[f32; 3]; 3], k: usize| (0..3).map(|i| f64::from(v[i][k]) * p[i] / sum).sum::<f64>();
            let nn: [f64; 3] = std::array::from_fn(|k| mix(n.map(|v| v.to_array()), k));
            let len = nn.iter().map(|x| x * x).sum::<f64>().sqrt();
            let light = super::standard_light();
            let d = nn[0] * f64::from(light.x) + nn[1] * f64::from(light.y) + nn[2] * f64::from(light.z);
            let lit = (1.0 - f64::from(ambient)) * (d / len).max(0.0) + f64::from(ambient);
            for k in 0..3 {
                let exact = mix(colors, k) * f64::from(base[k]) * lit;
                let err = (exact - f64::from(fast[k])).abs();
                prop_assert!(err <= 4e-6, "channel {k}: {exact} against {}", fast[k]);
            }
        }
    }

    /// A zero normal (a degenerate mesh's) shades the ambient part of the colour, as
    /// [`Lambert`] does, rather than NaN.
    #[test]
    fn colored_lambert_shades_a_zero_normal_with_the_ambient_term() {
        let mesh = Mesh::teapot();
        let base = Vec3::new(0.5, 1.0, 0.25);
        let shader = ColoredLambert::new(
            Lambert::new(&mesh, Mat4::IDENTITY, Mat4::IDENTITY).with_material(base, 0.2),
        );
        let colour = Vec3::new(0.8, 0.4, 1.0);
        for s in [1e-3, 0.4, 1.0, 7.0] {
            let h = Homogeneous {
                scaled: colour * base * s,
                weight: s,
            };
            let got = shader.fragment(&(Direction(Vec3::ZERO), h));
            let want = colour * base * 0.2;
            assert!(
                (got - want).abs().max_element() <= 1e-6,
                "{got} against {want} (s = {s})"
            );
        }
    }
}

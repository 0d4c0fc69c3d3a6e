//! Ready-made shaders over a [`Mesh`].

use glam::{Mat3, Mat4, Vec3, Vec4};

use super::{ShadeLanes, Shader};
use crate::mesh::Mesh;
use crate::raster::interp::Direction;
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
        // `Direction::from_relative` lane by lane: a·w0 + b·w1 + c·w2, fused.
        let [a, b, c] = [rel[0].0, rel[1].0, rel[2].0];
        let n =
            each3!(|i| F::splat(c[i])
                .mul_add(w[2], F::splat(b[i]).mul_add(w[1], F::splat(a[i]) * w[0])));
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
/// `colour·(l·lit + unlit)`, with lane code of its own. Varying: the world-space
/// normal and the vertex colour, both perspective-correct (the colour needs the
/// division, so the normal takes the same weights rather than its projective form).
#[derive(Clone, Debug)]
pub struct ColoredLambert<'a>(pub Lambert<'a>);

impl Shader for ColoredLambert<'_> {
    type Varying = (Vec3, Vec3);
    const LANE_CODE: bool = true;

    #[inline(always)]
    fn vertex(&self, index: u32) -> (Vec4, (Vec3, Vec3)) {
        let (pos, Direction(n)) = self.0.vertex(index);
        let c = self.0.mesh.colors.get(index as usize).copied();
        (pos, (n, c.unwrap_or(Vec3::ONE)))
    }

    #[inline(always)]
    fn fragment(&self, &(n, c): &(Vec3, Vec3)) -> Vec3 {
        let s = &self.0;
        Vec3::splat(s.cosine(n)).mul_add(s.lit, s.unlit) * c
    }

    #[inline(always)]
    fn fragment_lanes<F: F32s>(
        &self,
        rel: &[(Vec3, Vec3); 3],
        w: &[F; 3],
        _mask: u32,
    ) -> ShadeLanes<F> {
        let n = relative_lanes([rel[0].0, rel[1].0, rel[2].0], w);
        let c = relative_lanes([rel[0].1, rel[1].1, rel[2].1], w);
        let s = &self.0;
        let l = s.cosine_lanes(n);
        ShadeLanes::Rgb(each3!(|i| l
            .mul_add(F::splat(s.lit[i]), F::splat(s.unlit[i]))
            * c[i]))
    }
}

/// `Vec3::from_relative` on lanes: `r0 + r1·w1 + r2·w2`, fused, inner first.
#[inline(always)]
fn relative_lanes<F: F32s>(r: [Vec3; 3], w: &[F; 3]) -> [F; 3] {
    each3!(|i| F::splat(r[2][i]).mul_add(w[2], F::splat(r[1][i]).mul_add(w[1], F::splat(r[0][i]))))
}

#[cfg(test)]
mod tests {
    use glam::{Mat4, Vec3};
    use proptest::prelude::*;
    use wide::f32x8;

    use super::{ColoredLambert, Lambert};
    use crate::mesh::Mesh;
    use crate::raster::interp::{Direction, Varying};
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
        /// bit: the normal and the colour interpolated as `Vec3` varyings are, then lit.
        #[test]
        fn colored_lambert_lanes_equal_single_fragments(
            normals in prop::array::uniform3(vec3()),
            colors in prop::array::uniform3(prop::array::uniform3(0.0f32..1.0)),
            w in prop::array::uniform3(prop::array::uniform8(0.0f32..1.0)),
            base in vec3(),
            ambient in 0.0f32..0.5,
            mask in 1..=255u8,
        ) {
            let mesh = Mesh::teapot();
            let shader = ColoredLambert(
                Lambert::new(&mesh, Mat4::IDENTITY, Mat4::IDENTITY)
                    .with_material(base.abs(), ambient),
            );
            let v = |i: usize| (normals[i], Vec3::from(colors[i]));
            let rel = <(Vec3, Vec3)>::relative(&v(0), &v(1), &v(2));
            let lanes = w.map(f32x8::from);
            let ShadeLanes::Rgb(rgb) = shader.fragment_lanes(&rel, &lanes, mask.into()) else {
                panic!("a coloured shader shades three channels");
            };
            let rgb = rgb.map(F32s::to_array);
            for k in (0..8).filter(|k| mask >> k & 1 == 1) {
                let one = shader.fragment(&<(Vec3, Vec3)>::from_relative(
                    &rel,
                    [w[0][k], w[1][k], w[2][k]],
                ));
                for (c, lane) in one.to_array().iter().zip(rgb) {
                    prop_assert_eq!(c.to_bits(), lane[k].to_bits(), "lane {}", k);
                }
            }
        }
    }
}

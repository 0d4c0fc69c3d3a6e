//! The pipelines of plain colour, whose fragment stages are lane code: an object
//! whose every fragment has its material's colour (the minimal scene) is drawn by
//! [`FlatColor`], one splat per group of pixels; one whose fragments are the material's
//! colour times a colour interpolated from its vertices (Gouraud or flat lighting,
//! vertex colours) by [`VertexColor`]. The packed shader would call its fragment stage
//! once per pixel for either.

use glam::{Mat4, Vec3, Vec4};

use super::{FrameCtx, ObjectShader, Shading};
use crate::render::shader::{ShadeLanes, Shader};
use crate::scene::SceneObject;
use crate::scene::file::TextureMode;
use crate::scene::plan::{ObjectPlan, VaryingSet};
use crate::simd::{F32s, each3};

/// Whether every fragment of an object with this plan has its material's colour: it
/// interpolates nothing, so it has no lighting, vertex colours, texture, fog or depth
/// shading (each needs a varying), and transforms no normal or world position (so the
/// packed shader would count no work either).
#[must_use]
pub fn is_flat_colour(plan: &ObjectPlan) -> bool {
    plan.varyings == VaryingSet::default()
        && !plan.normals
        && !plan.world_positions
        && plain_surface(plan)
}

/// No texture, fog or depth shading: nothing on the surface but the material colour
/// and what the varyings carry.
fn plain_surface(plan: &ObjectPlan) -> bool {
    plan.texture == TextureMode::Off && !plan.fog && !plan.depth_shading
}

/// A shader of one colour.
pub struct FlatColor<'a> {
    positions: &'a [Vec3],
    mvp: Mat4,
    color: Vec3,
    /// Whether the three channels are equal ([`ShadeLanes::Grey`]).
    grey: bool,
}

impl Shader for FlatColor<'_> {
    type Varying = ();
    const LANE_CODE: bool = true;

    #[inline(always)]
    fn vertex(&self, index: u32) -> (Vec4, ()) {
        let p = self
            .positions
            .get(index as usize)
            .copied()
            .unwrap_or(Vec3::ZERO);
        (self.mvp * p.extend(1.0), ())
    }

    #[inline(always)]
    fn fragment(&self, (): &()) -> Vec3 {
        self.color
    }

    #[inline(always)]
    fn fragment_lanes<F: F32s>(&self, _: &[(); 3], _: &[F; 3], _: u32) -> ShadeLanes<F> {
        let c = self.color;
        if self.grey {
            ShadeLanes::Grey(F::splat(c.x))
        } else {
            ShadeLanes::Rgb([F::splat(c.x), F::splat(c.y), F::splat(c.z)])
        }
    }
}

/// The pipeline of [`FlatColor`] in the object's material colour.
pub struct Flat;

impl Shading for Flat {
    const NAME: &'static str = "flat";
    type Varying = ();
    type Instance<'a> = FlatColor<'a>;

    fn shader<'a>(obj: &'a SceneObject, _plan: &'a ObjectPlan, ctx: FrameCtx<'a>) -> FlatColor<'a> {
        let color = obj.desc.material.color;
        FlatColor {
            positions: &obj.mesh.positions,
            mvp: ctx.view_proj * ctx.model(obj),
            color,
            grey: color.x == color.y && color.y == color.z,
        }
    }
}

/// Whether every fragment of an object with this plan is its material's colour times
/// one interpolated colour, and nothing else: the colour is its only varying (lit per
/// vertex or per face, or the vertex colours), with no texture, fog or depth shading.
#[must_use]
pub fn is_vertex_colour(plan: &ObjectPlan) -> bool {
    let color_only = VaryingSet {
        color: true,
        ..VaryingSet::default()
    };
    plan.varyings == color_only && plain_surface(plan)
}

/// The packed shader of a colour-only plan ([`is_vertex_colour`]), whose vertex stage
/// it keeps (lighting per vertex, and the work counters), with lane code for its
/// fragment stage: the material colour times the interpolated colour.
pub struct VertexColor<'a> {
    packed: ObjectShader<'a, 4>,
    base: Vec3,
}

impl Shader for VertexColor<'_> {
    type Varying = [f32; 4];
    const LANE_CODE: bool = true;

    #[inline(always)]
    fn vertex(&self, index: u32) -> (Vec4, [f32; 4]) {
        self.packed.vertex(index)
    }

    #[inline(always)]
    fn fragment(&self, v: &[f32; 4]) -> Vec3 {
        self.packed.fragment(v)
    }

    /// The colour is the layout's first three floats, interpolated as
    /// [`Varying::from_relative`](crate::raster::interp::Varying::from_relative) does
    /// and multiplied by the material colour as [`ObjectShader::fragment`] does.
    #[inline(always)]
    fn fragment_lanes<F: F32s>(&self, rel: &[[f32; 4]; 3], w: &[F; 3], _: u32) -> ShadeLanes<F> {
        // Through `black_box`, the vertex terms are broadcast in each group rather than
        // hoisted out of the group loop and spilled once per triangle (as in
        // `ColoredLambert`); `each3!` rather than a closure, which would stay a call
        // outside the lane copies.
        let [a, b, c] = *std::hint::black_box(rel);
        let base = self.base;
        ShadeLanes::Rgb(each3!(|i| {
            let v = F::splat(c[i]).mul_add(w[2], F::splat(b[i]).mul_add(w[1], F::splat(a[i])));
            F::splat(base[i]) * v
        }))
    }
}

/// The pipeline of [`VertexColor`].
pub struct Interpolated;

impl Shading for Interpolated {
    const NAME: &'static str = "vertex-color";
    type Varying = [f32; 4];
    type Instance<'a> = VertexColor<'a>;

    fn shader<'a>(
        obj: &'a SceneObject,
        plan: &'a ObjectPlan,
        ctx: FrameCtx<'a>,
    ) -> VertexColor<'a> {
        let packed = ObjectShader::new(obj, plan, ctx);
        debug_assert_eq!(packed.layout.color, Some(0));
        VertexColor {
            packed,
            base: obj.desc.material.color,
        }
    }
}

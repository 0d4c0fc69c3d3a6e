//! The flat-colour pipeline: an object whose every fragment has its material's colour
//! (no varying, no fog, no depth shading: the minimal scene) is drawn by [`FlatColor`],
//! whose fragment stage is one splat per group of pixels, instead of the packed shader,
//! which would call its fragment stage once per pixel for the same colour.

use glam::{Mat4, Vec3, Vec4};

use super::{FrameCtx, Shading};
use crate::render::shader::{ShadeLanes, Shader};
use crate::scene::SceneObject;
use crate::scene::file::TextureMode;
use crate::scene::plan::{ObjectPlan, VaryingSet};
use crate::simd::F32s;

/// Whether every fragment of an object with this plan has its material's colour: it
/// interpolates nothing, transforms no normal or world position (so the packed shader
/// would count no work either), and has no fog or depth shading.
#[must_use]
pub fn is_flat_colour(obj: &SceneObject, plan: &ObjectPlan) -> bool {
    plan.varyings == VaryingSet::default()
        && !plan.normals
        && !plan.world_positions
        && !plan.vertex_colors
        && plan.texture == TextureMode::Off
        && !plan.fog
        && obj.desc.effects.fog.is_none()
        && !plan.depth_shading
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

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::camera::Camera;
    use crate::raster::Target;
    use crate::render::{DrawOptions, Renderer, Rgba8, VertexCache};
    use crate::scene::Scene;
    use crate::scene::render::{Packed, draw_options};

    /// The colour and depth bits of one frame of `scene`'s object drawn by shading `S`.
    fn frame<S: Shading>(scene: &Scene, target: Target) -> (Vec<[u8; 4]>, Vec<u32>) {
        let (obj, plan) = (&scene.objects[0], &scene.plan.objects[0]);
        let cam = Camera::default();
        let ctx = FrameCtx {
            view_proj: cam.projection(target.width, target.height, 1.0) * cam.view(),
            eye: cam.eye,
            forward: (cam.target - cam.eye).normalize(),
            lights: &[],
            depth_range: (1.0, 4.0),
            time: 0.7,
            turn: None,
        };
        let shader = S::shader(obj, plan, ctx);
        let mut r = Renderer::new(target);
        let mut color = Rgba8::default();
        r.begin_frame(target, &mut color, Vec3::ZERO);
        let mut cache = VertexCache::default();
        r.transform(&shader, obj.mesh.positions.len(), &mut cache);
        let opts = draw_options(plan, DrawOptions::default());
        r.draw(&shader, &cache, &obj.mesh.indices, &opts, &mut color);
        let depth = r.depth.to_vec().iter().map(|d| d.to_bits()).collect();
        (color.0, depth)
    }

    /// Pass: an object of one flat colour takes this pipeline, and it draws the bits
    /// the packed shader draws for it, in grey and in colour, with and without a depth
    /// test, culled or not.
    #[test]
    fn flat_colour_draws_the_packed_shaders_bits() {
        let target = Target::new(96, 64);
        for (color, effects) in [
            ("", "depth_test = true"),
            (
                "color = [0.9, 0.4, 0.1]\n",
                "depth_test = true\ncull = true",
            ),
            ("color = [0.2, 0.7, 0.5]\n", ""),
        ] {
            let text = format!(
                "[[object]]\nmodel = \"teapot\"\nrotation = [30, 20, 0]\n\
                 [object.material]\n{color}[object.effects]\n{effects}\n"
            );
            let scene = Scene::from_text(&text, Path::new("flat.toml")).unwrap();
            assert!(
                is_flat_colour(&scene.objects[0], &scene.plan.objects[0]),
                "{text}"
            );
            let flat = frame::<Flat>(&scene, target);
            let packed = frame::<Packed<0>>(&scene, target);
            assert!(
                flat.0.iter().filter(|p| p[3] == 255).count() > 500,
                "{text}"
            );
            assert_eq!(flat, packed, "{text}");
        }
    }
}

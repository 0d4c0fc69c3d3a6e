//! The standard plan's pipelines: an object lit per pixel by Lambert under the standard
//! lights, depth-tested, with nothing else on its surface but perhaps its vertex
//! colours, is what a model is ([`Scene::for_model`](crate::scene::Scene::for_model))
//! and what the benchmark draws. Such an object is drawn with [`Lambert`] (or
//! [`ColoredLambert`]), whose fragment stage is lane code of its own (and gets the
//! 16-lane AVX-512 copy of the draw loop), instead of the packed shader, which shades
//! one fragment at a time.

use super::{FrameCtx, Shading};
use crate::counters::{self, Stage};
use crate::raster::interp::{Direction, Homogeneous};
use crate::render::shaders::{ColoredLambert, Lambert};
use crate::scene::file::{Lighting, TextureMode};
use crate::scene::plan::{ObjectPlan, VaryingSet};
use crate::scene::{LightDesc, STANDARD_AMBIENT, SceneObject, standard_lights};

/// Whether an object's plan is exactly the standard one: per-pixel Lambert from
/// smooth normals under [`standard_lights`], a depth test, and no vertex colours,
/// texture, fog or depth shading. Culling, wireframes and silhouettes are drawn
/// outside the shader, so they do not matter.
#[must_use]
pub fn is_standard_lambert(obj: &SceneObject, plan: &ObjectPlan, lights: &[LightDesc]) -> bool {
    standard_surface(obj, plan, lights) && !plan.vertex_colors
}

/// Whether an object's plan is the standard one ([`is_standard_lambert`]) but for the
/// mesh's vertex colours, which it multiplies.
#[must_use]
pub fn is_colored_lambert(obj: &SceneObject, plan: &ObjectPlan, lights: &[LightDesc]) -> bool {
    standard_surface(obj, plan, lights) && plan.vertex_colors
}

/// Per-pixel Lambert from smooth normals under the standard lights, depth-tested,
/// interpolating the normal and at most the vertex colours.
fn standard_surface(obj: &SceneObject, plan: &ObjectPlan, lights: &[LightDesc]) -> bool {
    let varyings = VaryingSet {
        normal: true,
        color: plan.vertex_colors,
        ..VaryingSet::default()
    };
    obj.desc.material.lighting == Lighting::Lambert
        && plan.varyings == varyings
        && plan.normals
        && !plan.unweld
        && !plan.world_positions
        && plan.texture == TextureMode::Off
        && plan.depth_test
        && !plan.fog
        && !plan.depth_shading
        && lights == standard_lights().as_slice()
}

/// [`Lambert`] in the material's colour, under the standard lights.
pub struct StandardLambert;

impl Shading for StandardLambert {
    const NAME: &'static str = "lambert";
    type Varying = Direction;
    type Instance<'a> = Lambert<'a>;

    fn shader<'a>(obj: &'a SceneObject, _plan: &'a ObjectPlan, ctx: FrameCtx<'a>) -> Lambert<'a> {
        let model = ctx.model(obj);
        Lambert::new(&obj.mesh, model, ctx.view_proj)
            .with_material(obj.desc.material.color, STANDARD_AMBIENT)
    }

    fn count_work(obj: &SceneObject, shaded: u64) {
        // Lambert transforms every normal and lights every shaded fragment; it is a
        // render shader and counts nothing itself.
        counters::add(Stage::NormalsTransformed, obj.mesh.positions.len() as u64);
        counters::add(Stage::Lighting, shaded);
    }
}

/// [`ColoredLambert`]: [`StandardLambert`] times the vertex colours.
pub struct StandardColoredLambert;

impl Shading for StandardColoredLambert {
    const NAME: &'static str = "lambert-colors";
    type Varying = (Direction, Homogeneous);
    type Instance<'a> = ColoredLambert<'a>;

    fn shader<'a>(
        obj: &'a SceneObject,
        plan: &'a ObjectPlan,
        ctx: FrameCtx<'a>,
    ) -> ColoredLambert<'a> {
        ColoredLambert::new(StandardLambert::shader(obj, plan, ctx))
    }

    fn count_work(obj: &SceneObject, shaded: u64) {
        StandardLambert::count_work(obj, shaded);
        counters::add(Stage::VertexColors, obj.mesh.positions.len() as u64);
    }
}

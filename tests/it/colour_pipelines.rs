//! The plain-colour pipelines (`scene/render/color.rs`): each draws the bits the
//! packed shader draws for the plans it takes. Here rather than beside the pipelines,
//! so that the library's unit-test build compiles no copy of the draw loop.

use std::path::Path;

use glam::Vec3;
use termrast::camera::Camera;
use termrast::raster::Target;
use termrast::raster::interp::Interpolation;
use termrast::render::{DrawOptions, Renderer, Rgba8, VertexCache};
use termrast::scene::Scene;
use termrast::scene::render::{
    Flat, FrameCtx, Interpolated, Packed, Shading, draw_options, is_flat_colour, is_vertex_colour,
};

/// The colour and depth bits of one frame of `scene`'s object drawn by shading `S`
/// with the interpolation and traversal of `base`.
fn frame<S: Shading>(scene: &Scene, target: Target, base: DrawOptions) -> (Vec<[u8; 4]>, Vec<u32>) {
    let (obj, plan) = (&scene.objects[0], &scene.plan.objects[0]);
    let cam = Camera::default();
    let ctx = FrameCtx {
        view_proj: cam.projection(target.width, target.height, 1.0) * cam.view(),
        eye: cam.eye,
        forward: (cam.target - cam.eye).normalize(),
        lights: &scene.lights,
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
    let opts = draw_options(plan, base);
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
        assert!(is_flat_colour(&scene.plan.objects[0]), "{text}");
        let base = DrawOptions::default();
        let flat = frame::<Flat>(&scene, target, base);
        let packed = frame::<Packed<0>>(&scene, target, base);
        assert!(
            flat.0.iter().filter(|p| p[3] == 255).count() > 500,
            "{text}"
        );
        assert_eq!(flat, packed, "{text}");
    }
}

/// Pass: an object whose only varying is a colour (lit per vertex or per face, or
/// its vertex colours) takes the interpolated-colour pipeline, and it draws the
/// bits the packed shader draws for it, in every interpolation mode, culled or not.
#[test]
fn vertex_colour_draws_the_packed_shaders_bits() {
    let target = Target::new(96, 64);
    for (model, material, effects) in [
        (
            "sphere:2000",
            "lighting = \"gouraud\"\n",
            "depth_test = true",
        ),
        (
            "teapot",
            "lighting = \"flat\"\ncolor = [0.9, 0.4, 0.1]\n",
            "depth_test = true\ncull = true",
        ),
        ("sphere:2000", "vertex_colors = true\n", "depth_test = true"),
        (
            "sphere:2000",
            "lighting = \"gouraud\"\nvertex_colors = true\n",
            "",
        ),
    ] {
        let text = format!(
            "[[object]]\nmodel = \"{model}\"\nrotation = [30, 20, 0]\n\
             [object.material]\n{material}[object.effects]\n{effects}\n"
        );
        let scene = Scene::from_text(&text, Path::new("colour.toml")).unwrap();
        assert!(is_vertex_colour(&scene.plan.objects[0]), "{text}");
        for interpolation in [
            Interpolation::Perspective,
            Interpolation::Perspective4,
            Interpolation::Affine,
        ] {
            let base = DrawOptions {
                interpolation,
                ..DrawOptions::default()
            };
            let lanes = frame::<Interpolated>(&scene, target, base);
            let packed = frame::<Packed<4>>(&scene, target, base);
            let covered: Vec<_> = lanes.0.iter().filter(|p| p[3] == 255).collect();
            assert!(covered.len() > 500, "{text}");
            let mut colours = covered.clone();
            colours.sort_unstable();
            colours.dedup();
            assert!(colours.len() > 20, "{text}: {} colours", colours.len());
            assert_eq!(lanes, packed, "{text} {interpolation:?}");
        }
    }
}

//! The 3D pipeline: perspective-correct interpolation, depth, near-plane clipping,
//! the probe against the framebuffer, and a snapshot. Near-plane, behind-the-eye and
//! close-plane cases are in `hard_cases.rs`.

use crate::common::{Direct, draw};

use glam::{Mat4, Vec3, Vec4};
use termrast::camera::Camera;
use termrast::raster::depth::DEPTH_CLEAR;
use termrast::raster::interp::{Interpolation, Varying};
use termrast::raster::{Target, Traversal};
use termrast::render::probe::{DepthOutcome, probe};
use termrast::render::shaders::Lambert;
use termrast::render::target::to_u8;
use termrast::render::{DrawOptions, Isa, Renderer, Shader, VertexCache, transform};
use termrast::scene::Scene;
use termrast::scene::render::{SceneFrame, SceneView};

/// A quad tilted in depth whose attribute is its texture coordinate (u across, v along
/// the slope), checked against the analytic ray–plane intersection in f64.
///
/// Error budget: snapping moves a vertex by at most 1/512 px, which shifts an attribute
/// by its screen gradient / 512; the quad is tilted (not grazing) so that stays below
/// 1e-4 and the remaining error is f32 rounding.
#[test]
fn perspective_correct_matches_ray_plane_reference() {
    let target = Target::new(256, 192);
    let camera = Camera::default();
    let vp = camera.projection(target.width, target.height, 1.0) * camera.view();
    // A slope rising from y = −1 at z = 1 (near the eye) to y = 1 at z = −2, its texture
    // coordinates u across and v along it. It is turned about y so depth also varies
    // along screen rows, which is what the subdivided modes approximate.
    let slope = [
        Vec3::new(-1.5, -1.0, 1.0),
        Vec3::new(1.5, -1.0, 1.0),
        Vec3::new(1.5, 1.0, -2.0),
        Vec3::new(-1.5, 1.0, -2.0),
    ];
    let turn = glam::DQuat::from_rotation_y(0.6);
    let uv_of_slope = |p: glam::DVec3| glam::DVec3::new((p.x + 1.5) / 3.0, (1.0 - p.z) / 3.0, 0.0);
    let uv = |world: glam::DVec3| uv_of_slope(turn.inverse() * world);
    let world = slope.map(|p| (turn * p.as_dvec3()).as_vec3());
    let [a, b, _, d] = world.map(Vec3::as_dvec3);
    let normal = (b - a).cross(d - a);
    let shader = Direct {
        clip: world.iter().map(|p| vp * p.extend(1.0)).collect(),
        attr: slope
            .iter()
            .map(|p| uv_of_slope(p.as_dvec3()).as_vec3())
            .collect(),
    };
    let inv_vp = vp.as_dmat4().inverse();
    // Per mode: the largest error anywhere, and the largest at pixels whose x is a
    // multiple of 16 (span ends for every subdivided mode).
    let mut errors = [[0f32; 2]; 5];
    for (k, mode) in Interpolation::ALL.into_iter().enumerate() {
        let opts = DrawOptions {
            interpolation: mode,
            ..DrawOptions::default()
        };
        let (img, _) = draw(&shader, &[0, 1, 2, 0, 2, 3], target, &opts);
        let mut n = 0;
        for y in 0..target.height {
            for x in 0..target.width {
                let Some(got) = img.colors[(y * target.width + x) as usize] else {
                    continue;
                };
                // Ray through the pixel centre, intersected with the slope in f64.
                let ndc_x = (f64::from(x) + 0.5) / f64::from(target.width) * 2.0 - 1.0;
                let ndc_y = 1.0 - (f64::from(y) + 0.5) / f64::from(target.height) * 2.0;
                let far = inv_vp * glam::DVec4::new(ndc_x, ndc_y, 1.0, 1.0);
                let far = (far / far.w).truncate();
                let eye = camera.eye.as_dvec3();
                let t = normal.dot(a - eye) / normal.dot(far - eye);
                let want = uv(eye + (far - eye) * t);
                let err = (got.as_dvec3() - want).abs().max_element() as f32;
                errors[k][0] = errors[k][0].max(err);
                if x % 16 == 0 {
                    errors[k][1] = errors[k][1].max(err);
                }
                n += 1;
            }
        }
        assert!(n > 1000, "quad covers the view");
    }
    let [affine, perspective, p4, p8, p16] = errors;
    assert!(
        perspective[0] < 1e-4,
        "perspective error {}",
        perspective[0]
    );
    assert!(
        affine[0] > 0.01,
        "affine should be visibly wrong: {}",
        affine[0]
    );
    // Subdivided spans are exact at their ends and err in between, more for longer
    // spans, but far less than affine.
    for (name, e) in [("4", p4), ("8", p8), ("16", p16)] {
        assert!(e[1] < 1e-4, "perspective-{name} at span ends: {}", e[1]);
        assert!(
            e[0] > perspective[0],
            "perspective-{name} errs between ends"
        );
        assert!(e[0] < affine[0] / 4.0, "perspective-{name}: {}", e[0]);
    }
    assert!(p4[0] < p8[0] && p8[0] < p16[0], "{p4:?} {p8:?} {p16:?}");
    eprintln!(
        "max error: affine {affine:?} perspective {perspective:?} 4 {p4:?} 8 {p8:?} 16 {p16:?}"
    );
}

#[test]
fn interpolation_properties() {
    let target = Target::new(400, 300);
    // A small triangle far from the origin of a large target, tilted in depth.
    let clip = vec![
        Vec4::new(0.5, 0.5, 0.3, 1.0),
        Vec4::new(1.9, 1.2, 0.8, 2.0),
        Vec4::new(0.3, 0.475, 0.2, 0.5),
    ];
    let attr = vec![
        Vec3::new(1.0, 5.0, -2.0),
        Vec3::new(3.0, 5.0, 7.0),
        Vec3::new(-4.0, 5.0, 0.5),
    ];
    let shader = Direct {
        clip,
        attr: attr.clone(),
    };
    let (img, r) = draw(&shader, &[0, 1, 2], target, &DrawOptions::default());
    let lo = attr.iter().fold(Vec3::INFINITY, |m, a| m.min(*a));
    let hi = attr.iter().fold(Vec3::NEG_INFINITY, |m, a| m.max(*a));
    let mut n = 0;
    for c in img.colors.iter().flatten() {
        assert_eq!(c.y, 5.0, "a constant attribute stays exactly constant");
        let tol = Vec3::splat(1e-5) * (hi - lo).abs().max(Vec3::ONE);
        assert!(
            c.cmpge(lo - tol).all() && c.cmple(hi + tol).all(),
            "{c} outside {lo}..{hi}"
        );
        n += 1;
    }
    assert!(n > 50 && r.stats.shaded == n);
    // At a vertex, weights are exactly (1, 0, 0): the value is the vertex's own.
    let v = Vec3::weighted(&attr[0], &attr[1], &attr[2], [1.0, 0.0, 0.0]);
    assert_eq!(v, attr[0]);
}

#[test]
fn interpenetrating_triangles_split_along_their_intersection() {
    // Two triangles crossing at view depth z = −2: the left half of one is in front.
    let target = Target::new(64, 64);
    let camera = Camera::default();
    let vp = camera.projection(64, 64, 1.0) * camera.view();
    let a = [
        Vec3::new(-1.0, -1.0, 0.5),
        Vec3::new(1.0, -1.0, -0.5),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let b = [
        Vec3::new(-1.0, -1.0, -0.5),
        Vec3::new(1.0, -1.0, 0.5),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let clip = a.iter().chain(&b).map(|p| vp * p.extend(1.0)).collect();
    let attr = vec![Vec3::X, Vec3::X, Vec3::X, Vec3::Y, Vec3::Y, Vec3::Y];
    let (img, _) = draw(
        &Direct { clip, attr },
        &[0, 1, 2, 3, 4, 5],
        target,
        &DrawOptions::default(),
    );
    let mut seen = [0; 2];
    for y in 0..64 {
        for x in 0..64 {
            let Some(c) = img.colors[y * 64 + x] else {
                continue;
            };
            // World x of the pixel centre on either triangle has the same sign as the
            // screen x offset from the centre line; a is nearer where x < 0.
            let sx = x as f32 + 0.5 - 32.0;
            if sx.abs() < 1.0 {
                continue;
            }
            let want = if sx < 0.0 { Vec3::X } else { Vec3::Y };
            assert_eq!(c, want, "pixel ({x},{y})");
            seen[usize::from(sx > 0.0)] += 1;
        }
    }
    assert!(seen[0] > 100 && seen[1] > 100);
}

/// The benchmark's scene of the bunny (the fixed camera, the model turning).
fn bunny() -> Scene {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/src/mesh/bunny.obj");
    Scene::standard(path).expect("bunny loads")
}

/// The view of the benchmark's frame turned by `angle`, with square pixels.
fn turned(angle: f32) -> SceneView {
    SceneView {
        yaw: angle,
        ..SceneView::default()
    }
}

/// The probe equals the framebuffer at every pixel, for the lane-code Lambert and
/// for its form with vertex colours (the sphere's).
#[test]
fn probe_equals_the_framebuffer_for_every_pixel() {
    let bunny = bunny();
    assert_eq!(bunny.objects[0].mesh.triangle_count(), 3674);
    let sphere = Scene::standard("sphere:3000").expect("the sphere");
    let target = Target::new(120, 90);
    for ((mut scene, pipeline), (angle, cull)) in [
        (bunny.clone(), "lambert"),
        (bunny, "lambert"),
        (sphere.clone(), "lambert-colors"),
        (sphere, "lambert-colors"),
    ]
    .into_iter()
    .zip([(0.7f32, false), (2.1, true)].into_iter().cycle())
    {
        scene.set_cull(cull);
        let mut frame = SceneFrame::new(&scene);
        frame.draw(&scene, target, &turned(angle));
        assert_eq!(frame.pipelines(), [pipeline]);
        let color = &frame.color;
        let mut winners = 0;
        for y in 0..target.height {
            for x in 0..target.width {
                let probes = frame.probe(&scene, x, y);
                let p = &probes[0];
                let i = (y * target.width + x) as usize;
                assert_eq!(
                    p.final_depth.to_bits(),
                    frame.renderer.depth.at(i).to_bits(),
                    "depth at ({x},{y})"
                );
                match p.winner {
                    Some(w) => {
                        let rec = &p.records[w];
                        assert!(rec.eval.covered);
                        assert!(matches!(rec.depth, DepthOutcome::Passed { .. }));
                        // The colour the probe's record was shaded: the shader's
                        // scalar fragment stage on the probe's varyings.
                        let c = rec.varying.expect("a passing fragment is shaded");
                        assert_eq!(
                            color.0[i],
                            [to_u8(c.x), to_u8(c.y), to_u8(c.z), 255],
                            "colour at ({x},{y})"
                        );
                        // The winner is the last passing record, and nothing after it passed.
                        assert!(
                            p.records[w + 1..]
                                .iter()
                                .all(|r| !matches!(r.depth, DepthOutcome::Passed { .. }))
                        );
                        winners += 1;
                    }
                    None => {
                        assert_eq!(color.0[i], [0, 0, 0, 0]);
                        assert_eq!(p.final_depth, DEPTH_CLEAR);
                    }
                }
            }
        }
        assert!(winners > 2000, "the model covers the frame ({winners})");
    }
}

/// The colour and depth bits of one frame of the benchmark's scene.
fn frame_bits(
    scene: &Scene,
    target: Target,
    view: &SceneView,
    (interpolation, traversal): (Interpolation, Traversal),
    isa: Isa,
) -> (Vec<[u8; 4]>, Vec<u32>) {
    let mut frame = SceneFrame::new(scene);
    frame.renderer.isa = isa;
    frame.interpolation = interpolation;
    frame.traversal = traversal;
    frame.draw(scene, target, view);
    let depth = frame
        .renderer
        .depth
        .to_vec()
        .iter()
        .map(|d| d.to_bits())
        .collect();
    (frame.color.0, depth)
}

/// Every traversal, on every instruction set the CPU has, gives the same framebuffer bit for bit:
/// coverage is exact, and the fragment paths (`wide`'s `i32x8` edge lanes, the `i64`
/// fallback, the per-pixel path of the others) perform the same f32 operations.
#[test]
fn traversals_and_instruction_sets_draw_identical_frames() {
    let scene = bunny();
    let target = Target::new(160, 120);
    let view = turned(0.9);
    for interpolation in Interpolation::ALL {
        let frame_of = |traversal: Traversal, isa: Isa| {
            frame_bits(&scene, target, &view, (interpolation, traversal), isa)
        };
        let reference = frame_of(Traversal::Scalar, Isa::Baseline);
        assert!(reference.0.iter().filter(|p| p[3] == 255).count() > 3000);
        for traversal in Traversal::ALL {
            for isa in Isa::supported() {
                assert!(
                    frame_of(traversal, isa) == reference,
                    "{} on {isa:?} ({interpolation:?}) differs from scalar",
                    traversal.name()
                );
            }
        }
    }
}

/// The AVX-512 copy's two-row groups have no per-pixel fallback for groups past the
/// target's edge, so it is chosen only for targets at least a group (8 pixels) wide;
/// narrower ones run the AVX2 copy (or the baseline). It is built only for shaders with
/// lane code of their own (Lambert), so others run the AVX2 copy at any width.
#[test]
fn avx512_copy_runs_only_on_targets_a_group_wide_with_lane_shaders() {
    let next_down = if Isa::Avx2.is_supported() {
        Isa::Avx2
    } else {
        Isa::Baseline
    };
    for (width, wide_enough) in [(1, false), (7, false), (8, true), (1920, true)] {
        let mut renderer = Renderer::new(Target::new(width, 4));
        renderer.isa = Isa::Avx512;
        let opts = DrawOptions::default();
        let want = if wide_enough && Isa::Avx512.is_supported() {
            Isa::Avx512
        } else {
            next_down
        };
        assert_eq!(
            renderer.copy_for::<Lambert>(&opts).isa,
            want,
            "{width} wide"
        );
        assert_eq!(
            renderer.copy_for::<Direct>(&opts).isa,
            next_down,
            "{width} wide"
        );
    }
}

/// Targets narrower than a group (and just wider): `wide` then has groups that reach
/// past the right edge or start left of a box, and the fragment stage falls back to
/// single pixels; every traversal on every instruction set the CPU has still draws the scalar
/// reference's frame.
#[test]
fn narrow_targets_draw_the_same_frame_with_every_traversal() {
    let mut scene = bunny();
    // Close up, so the model reaches past every side of the target.
    let view = turned(0.4);
    scene.camera.eye = Vec3::new(0.0, 0.0, 1.3);
    for (w, h) in [(1, 1), (3, 5), (7, 6), (8, 4), (9, 9), (15, 12), (17, 10)] {
        let target = Target::new(w, h);
        let frame_of = |traversal: Traversal, isa: Isa| {
            let options = (Interpolation::Perspective, traversal);
            frame_bits(&scene, target, &view, options, isa)
        };
        let reference = frame_of(Traversal::Scalar, Isa::Baseline);
        let covered = reference.0.iter().filter(|p| p[3] == 255).count();
        assert!(covered * 2 > reference.0.len(), "{w}x{h} is mostly covered");
        for traversal in Traversal::ALL {
            for isa in Isa::supported() {
                assert!(
                    frame_of(traversal, isa) == reference,
                    "{} on {isa:?} at {w}x{h} differs from scalar",
                    traversal.name()
                );
            }
        }
    }
}

/// A triangle far larger than the target takes `wide`'s `i64` fallback (its edge
/// values do not fit `i32` lanes); it still equals the scalar traversal and the probe.
#[test]
fn huge_triangles_take_the_i64_lanes_and_agree() {
    let target = Target::new(64, 48);
    let shader = Direct {
        clip: vec![
            Vec4::new(-4000.0, -3000.0, 0.5, 1.0),
            Vec4::new(5000.0, -2500.0, 0.5, 1.0),
            Vec4::new(300.0, 6000.0, 0.2, 1.0),
        ],
        attr: vec![Vec3::X, Vec3::Y, Vec3::Z],
    };
    let mut cache = VertexCache::default();
    transform(&shader, 3, &mut cache);
    let mut seen = None;
    termrast::render::prepare(
        &cache,
        &[0, 1, 2],
        0,
        target,
        &DrawOptions::default(),
        &mut |p: &termrast::render::Prepared<Vec3>| {
            seen = Some(termrast::raster::traverse::fits_i32(&p.setup));
        },
    );
    assert_eq!(seen, Some(false), "the triangle must need i64 lanes");
    let frames: Vec<Vec<Option<[u32; 3]>>> = [Traversal::Scalar, Traversal::Wide]
        .into_iter()
        .map(|traversal| {
            let opts = DrawOptions {
                traversal,
                ..DrawOptions::default()
            };
            let (out, _) = draw(&shader, &[0, 1, 2], target, &opts);
            out.colors
                .iter()
                .map(|c| c.map(|c| c.to_array().map(f32::to_bits)))
                .collect()
        })
        .collect();
    assert_eq!(frames[0], frames[1]);
    assert!(
        frames[1].iter().all(Option::is_some),
        "covers the whole target"
    );
    let opts = DrawOptions::default();
    for (x, y) in [(0, 0), (63, 47), (31, 20)] {
        let p = probe(&cache, &[0, 1, 2], target, &opts, x, y);
        let w = p.winner.expect("covered");
        let c = shader
            .fragment(&p.records[w].varying)
            .to_array()
            .map(f32::to_bits);
        assert_eq!(frames[1][(y * 64 + x) as usize], Some(c));
    }
}

#[test]
fn teapot_luminance_snapshot() {
    let scene = Scene::standard("teapot").unwrap();
    let target = Target::new(64, 32);
    let mut frame = SceneFrame::new(&scene);
    // Pixels twice as tall as wide, like terminal cells.
    let view = SceneView {
        pixel_aspect: 0.5,
        ..turned(0.6)
    };
    frame.draw(&scene, target, &view);
    // The teapot is grey, so any channel is its luminance.
    let ramp = b" .:-=+*#%@";
    let mut text = String::new();
    for row in frame.color.0.chunks(64) {
        for p in row {
            let l = f32::from(p[1]) / 255.0;
            text.push(ramp[((l * 9.0).round() as usize).min(9)] as char);
        }
        text.push('\n');
    }
    insta::assert_snapshot!(text);
}

#[test]
fn transform_and_cull_counts() {
    let mut scene = bunny();
    scene.set_cull(true);
    let target = Target::new(160, 120);
    let mut frame = SceneFrame::new(&scene);
    frame.draw(&scene, target, &turned(0.0));
    let s = frame.stats;
    assert_eq!(s.triangles, 3674);
    assert_eq!(s.drawn + s.culled + s.rejected, s.triangles);
    // A closed mesh shows roughly half its faces.
    assert!(s.culled > 1200 && s.drawn > 1200, "{s:?}");
    let _ = Mat4::IDENTITY;
}

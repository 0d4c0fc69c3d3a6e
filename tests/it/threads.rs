//! Drawing on several threads, binned by bands or in strips: the frame (colour and
//! depth bits) and the counters equal one thread's for every model and scene,
//! traversal, interpolation mode and instruction set, on targets smaller than a band
//! and across bands and strips; the probe still equals the framebuffer; triangles
//! crossing a band's or a strip's border at every subpixel offset, and random ones,
//! draw the same fragments in the same order.

use glam::{Vec3, Vec4};
use proptest::prelude::*;
use termrast::raster::depth::{DepthFunc, DepthState};
use termrast::raster::interp::Interpolation;
use termrast::raster::{Target, Traversal};
use termrast::render::probe::DepthOutcome;
use termrast::render::target::to_u8;
use termrast::render::{
    BAND_ROWS, DENSE_BAND_ROWS, DrawOptions, DrawStats, Isa, MIN_THREADED_WORK, Renderer,
    STRIP_DENSITY, Spread, TRIANGLE_WORK, VertexCache, band_rows, project_vertices, strip_ends,
    vertex_spans,
};
use termrast::scene::Scene;
use termrast::scene::render::{SceneFrame, SceneView};

use crate::common::{Direct, Exact};

/// A frame's colour, depth bits and counters.
type Bits = (Vec<[u8; 4]>, Vec<u32>, DrawStats);

/// The ways draws are shared among threads.
const WAYS: [Spread; 2] = [Spread::Bins, Spread::Strips];

/// Sets the thresholds so that every draw of `r` with threads is shared `way`, its
/// vertex stage on the threads too (`parallel_vertices`) or on the calling thread
/// (the draw then projects the vertices itself).
fn share(r: &mut Renderer, way: Spread, parallel_vertices: bool) {
    match way {
        Spread::Bins => {
            r.min_threaded_work = 0;
            r.strip_density = 0;
        }
        _ => {
            r.min_threaded_work = u64::MAX;
            r.min_strip_work = 0;
        }
    }
    r.min_parallel_vertices = if parallel_vertices { 0 } else { usize::MAX };
}

/// One frame of `scene` drawn on `threads` threads, shared `way`; the frame runs on
/// the pool's threads, as the viewer's does (which strips need).
fn frame_bits(
    scene: &Scene,
    target: Target,
    view: &SceneView,
    (interpolation, traversal, isa): (Interpolation, Traversal, Isa),
    threads: usize,
    way: Spread,
) -> Bits {
    let mut frame = SceneFrame::new(scene);
    frame.renderer.isa = isa;
    frame.renderer.set_threads(threads);
    share(&mut frame.renderer, way, true);
    assert_eq!(frame.renderer.threads(), threads);
    frame.interpolation = interpolation;
    frame.traversal = traversal;
    match frame.renderer.thread_pool().cloned() {
        Some(pool) => pool.install(|| frame.draw(scene, target, view)),
        None => frame.draw(scene, target, view),
    }
    if threads > 1 {
        assert_eq!(frame.renderer.spread(), way, "{target:?}");
    }
    bits(&frame)
}

/// The colour, depth bits and counters of `frame`'s last frame.
fn bits(frame: &SceneFrame) -> Bits {
    let depth = frame.renderer.depth.to_vec();
    let depth = depth.iter().map(|d| d.to_bits()).collect();
    (frame.color.0.clone(), depth, frame.stats)
}

fn turned(yaw: f32) -> SceneView {
    SceneView {
        yaw,
        ..SceneView::default()
    }
}

fn model(spec: &str) -> Scene {
    Scene::standard(spec).expect("the model loads")
}

fn scene_file(name: &str) -> Scene {
    let path = format!("{}/examples/scenes/{name}", env!("CARGO_MANIFEST_DIR"));
    Scene::load(std::path::Path::new(&path)).expect("the scene loads")
}

/// Every way to draw: each interpolation mode with each traversal, on each
/// instruction set this CPU has.
fn every_option() -> Vec<(Interpolation, Traversal, Isa)> {
    let mut out = Vec::new();
    for interpolation in Interpolation::ALL {
        for traversal in Traversal::ALL {
            for isa in Isa::supported() {
                out.push((interpolation, traversal, isa));
            }
        }
    }
    out
}

/// Models (the lane-code Lambert pipeline) and scene files (the packed pipelines,
/// textures, depth shading, several objects, culling; the flat colour without a depth
/// buffer; the interpolated colour of flat lighting) at a size of several bands
/// whose height is not a multiple of one: every option on 2 and 3 threads gives the
/// frame and counters of 1 thread.
#[test]
fn threaded_frames_equal_one_thread_for_every_model_option_and_isa() {
    let target = Target::new(97, 2 * BAND_ROWS + 11);
    let scenes = [
        ("teapot", model("teapot")),
        ("bunny", model("bunny")),
        ("sphere:3000", model("sphere:3000")),
        ("textured-cube", scene_file("textured-cube.toml")),
        ("depth-map", scene_file("depth-map.toml")),
        ("silhouettes", scene_file("silhouettes.toml")),
        ("minimal", scene_file("minimal.toml")),
    ];
    for (name, scene) in &scenes {
        let view = turned(0.9);
        for options in every_option() {
            let one = frame_bits(scene, target, &view, options, 1, Spread::One);
            assert!(one.2.shaded > 500, "{name} covers the frame");
            for threads in [2, 3] {
                for way in WAYS {
                    let many = frame_bits(scene, target, &view, options, threads, way);
                    assert!(
                        one == many,
                        "{name} {options:?} on {threads} threads, {way:?}"
                    );
                }
            }
        }
    }
}

/// Targets smaller than a band, a group or a pixel row of a band, one band exactly and
/// just over one (for the shortest bands and the tallest, which the bunny's 3 674
/// triangles get as a dense draw on the narrow tall targets), the model reaching past
/// every side.
#[test]
fn targets_smaller_than_a_band_draw_the_same_frame() {
    let mut scene = model("bunny");
    scene.camera.eye = Vec3::new(0.0, 0.0, 1.3);
    let view = turned(0.4);
    let b = BAND_ROWS;
    let tall = 12 * DENSE_BAND_ROWS;
    assert_eq!(band_rows(Target::new(16, tall), 2, 3674), DENSE_BAND_ROWS);
    for (w, h) in [
        (1, 1),
        (3, 5),
        (7, 6),
        (8, 4),
        (9, 9),
        (17, 10),
        (40, b - 1),
        (40, b),
        (40, b + 1),
        (33, 2 * b + 3),
        (12, 7),
        (12, 8),
        (12, 17),
        (16, tall - 1),
        (16, tall),
        (16, tall + 1),
    ] {
        let target = Target::new(w, h);
        for options in every_option() {
            let one = frame_bits(&scene, target, &view, options, 1, Spread::One);
            for way in WAYS {
                let two = frame_bits(&scene, target, &view, options, 2, way);
                assert!(one == two, "{w}x{h} {options:?} {way:?}");
            }
        }
    }
}

/// More threads than the bands hand-out serves (17), and a thread count that leaves
/// some threads without a band of their own (5 on 8-row bands of a short target): one
/// thread's frame.
#[test]
fn many_threads_draw_the_same_frame() {
    let scene = model("bunny");
    let view = turned(1.3);
    for target in [Target::new(64, 30), Target::new(200, 300)] {
        for isa in Isa::supported() {
            let options = (Interpolation::Perspective, Traversal::Wide, isa);
            let one = frame_bits(&scene, target, &view, options, 1, Spread::One);
            for threads in [5, 17] {
                for way in WAYS {
                    let many = frame_bits(&scene, target, &view, options, threads, way);
                    assert!(
                        one == many,
                        "{target:?} {isa:?} on {threads} threads {way:?}"
                    );
                }
            }
        }
    }
}

/// Frame after frame through one renderer drawing in strips, whose borders move with
/// the strips' times and with uneven shares set before some frames: each frame is
/// one thread's.
#[test]
fn strips_frame_after_frame_equal_one_thread() {
    let scene = model("bunny");
    let target = Target::new(150, 4 * BAND_ROWS + 3);
    let options = (Interpolation::Perspective, Traversal::Wide, Isa::detect());
    let mut frame = SceneFrame::new(&scene);
    (frame.interpolation, frame.traversal, frame.renderer.isa) = options;
    frame.renderer.set_threads(2);
    share(&mut frame.renderer, Spread::Strips, true);
    let pool = frame.renderer.thread_pool().cloned().expect("two threads");
    for n in 0..24 {
        match n % 6 {
            2 => frame.renderer.set_strip_shares(0, &[0.2, 0.8]),
            5 => frame.renderer.set_strip_shares(0, &[0.9, 0.1]),
            _ => {}
        }
        strips_frame_is_one_threads(&mut frame, &pool, &scene, target, n, options);
    }
}

/// Draws frame `n` of `scene` turning, on `pool` in strips, and checks that it is one
/// thread's.
fn strips_frame_is_one_threads(
    frame: &mut SceneFrame,
    pool: &rayon::ThreadPool,
    scene: &Scene,
    target: Target,
    n: u32,
    options: (Interpolation, Traversal, Isa),
) {
    let view = turned(0.3 * n as f32);
    pool.install(|| frame.draw(scene, target, &view));
    assert_eq!(frame.renderer.spread(), Spread::Strips);
    let many = bits(frame);
    let one = frame_bits(scene, target, &view, options, 1, Spread::One);
    let threads = frame.renderer.threads();
    assert!(one == many, "{options:?} on {threads} threads, frame {n}");
}

/// A thread done with its strip takes rows from one still drawing, mid-draw: with
/// shares that leave the other strips nearly empty, rows are handed over, on two and
/// on four threads, for each instruction set and interpolation mode, and each frame
/// (colour, depth bits, counters) is one thread's.
#[test]
fn rows_handed_over_mid_draw_keep_one_threads_frame() {
    let scene = model("sphere:4096");
    let target = Target::new(320, 200);
    for isa in Isa::supported() {
        for interpolation in [Interpolation::Perspective, Interpolation::Affine] {
            let options = (interpolation, Traversal::Wide, isa);
            for threads in [2, 4] {
                let mut frame = SceneFrame::new(&scene);
                (frame.interpolation, frame.traversal, frame.renderer.isa) = options;
                frame.renderer.set_threads(threads);
                share(&mut frame.renderer, Spread::Strips, true);
                let pool = frame.renderer.thread_pool().cloned().expect("threads");
                // The calling thread draws the first strip, the others start later.
                let mut shares = vec![0.2; threads];
                shares[0] = 1.0;
                // Whether rows change hands depends on when the other threads run: on
                // a loaded machine they may start only after the first strip is done.
                // So frames are drawn (and checked) until some rows have changed hands.
                let mut n = 0;
                while n < 8 || frame.renderer.handovers() == 0 {
                    assert!(
                        n < 400,
                        "{options:?} {threads} threads: no rows handed over in {n} frames"
                    );
                    frame.renderer.set_strip_shares(0, &shares);
                    strips_frame_is_one_threads(&mut frame, &pool, &scene, target, n, options);
                    n += 1;
                }
            }
        }
    }
}

/// With the default thresholds, a large draw goes in strips unless it has more than
/// `STRIP_DENSITY` triangles per pixel and thread: then it is binned. Whether the
/// caller runs on the pool or not, and each frame is one thread's.
#[test]
fn large_draws_go_in_strips_unless_dense() {
    let options = (Interpolation::Perspective, Traversal::Wide, Isa::detect());
    for (spec, target, way) in [
        ("sphere:16384", Target::new(1280, 720), Spread::Strips),
        ("sphere:16384", Target::new(160, 120), Spread::Strips),
        ("sphere:32768", Target::new(96, 64), Spread::Bins),
    ] {
        let scene = model(spec);
        let triangles = scene.objects[0].mesh.triangle_count() as u64;
        let work = target.len() as u64 + TRIANGLE_WORK * triangles;
        assert!(
            work >= MIN_THREADED_WORK,
            "{spec} {target:?} is a large draw"
        );
        let dense = 2 * triangles > STRIP_DENSITY * target.len() as u64;
        assert_eq!(dense, way == Spread::Bins, "{spec} {target:?}");
        let mut frame = SceneFrame::new(&scene);
        (frame.interpolation, frame.traversal, frame.renderer.isa) = options;
        frame.renderer.set_threads(2);
        let pool = frame.renderer.thread_pool().cloned().expect("two threads");
        let view = turned(0.4);
        for on_pool in [true, false] {
            if on_pool {
                pool.install(|| frame.draw(&scene, target, &view));
            } else {
                frame.draw(&scene, target, &view);
            }
            let at = format!("{spec} {target:?}, on the pool: {on_pool}");
            assert_eq!(frame.renderer.spread(), way, "{at}");
            let many = bits(&frame);
            let one = frame_bits(&scene, target, &view, options, 1, Spread::One);
            assert!(one == many, "{at}");
        }
    }
}

/// With the measured choice (`Renderer::set_measured`, as in the viewer) a frame goes
/// to the pool or stays on the calling thread by how long earlier frames took each
/// way: both ways are taken within the first frames, and every frame is one thread's.
#[test]
fn measured_frames_take_both_ways_and_equal_one_thread() {
    let options = (Interpolation::Perspective, Traversal::Wide, Isa::detect());
    for way in WAYS {
        let scene = model("bunny");
        let target = Target::new(120, 2 * BAND_ROWS + 5);
        let mut frame = SceneFrame::new(&scene);
        (frame.interpolation, frame.traversal, frame.renderer.isa) = options;
        frame.renderer.set_threads(2);
        frame.renderer.set_measured(true);
        share(&mut frame.renderer, way, true);
        let pool = frame.renderer.thread_pool().cloned().expect("two threads");
        let mut pooled = [0; 2];
        for n in 0..12 {
            let view = turned(0.2 * n as f32);
            pool.install(|| frame.draw(&scene, target, &view));
            let on_pool = frame.renderer.frame_pooled();
            pooled[usize::from(on_pool)] += 1;
            let expected = if on_pool { way } else { Spread::One };
            assert_eq!(frame.renderer.spread(), expected, "frame {n}");
            let bits = bits(&frame);
            let one = frame_bits(&scene, target, &view, options, 1, Spread::One);
            assert!(one == bits, "{way:?} frame {n}");
        }
        assert!(pooled.iter().all(|&n| n >= 3), "{way:?}: {pooled:?}");
    }
}

/// The probe, which recomputes a pixel from scratch on one thread, equals the frame
/// drawn on two at every pixel.
#[test]
fn probe_equals_the_threaded_framebuffer() {
    let mut scene = model("bunny");
    let target = Target::new(120, 90);
    for (angle, cull, way) in [
        (0.7f32, false, Spread::Bins),
        (2.1, true, Spread::Bins),
        (0.7, false, Spread::Strips),
        (2.1, true, Spread::Strips),
    ] {
        scene.set_cull(cull);
        let mut frame = SceneFrame::new(&scene);
        frame.renderer.set_threads(2);
        share(&mut frame.renderer, way, true);
        let pool = frame.renderer.thread_pool().cloned().expect("two threads");
        pool.install(|| frame.draw(&scene, target, &turned(angle)));
        assert_eq!(frame.renderer.spread(), way);
        let mut winners = 0;
        for y in 0..target.height {
            for x in 0..target.width {
                let p = &frame.probe(&scene, x, y)[0];
                let i = (y * target.width + x) as usize;
                let depth = frame.renderer.depth.at(i);
                assert_eq!(p.final_depth.to_bits(), depth.to_bits(), "({x},{y})");
                let want = p.winner.map_or([0; 4], |w| {
                    assert!(matches!(p.records[w].depth, DepthOutcome::Passed { .. }));
                    let c = p.records[w].varying.expect("a passing fragment is shaded");
                    winners += 1;
                    [to_u8(c.x), to_u8(c.y), to_u8(c.z), 255]
                });
                assert_eq!(frame.color.0[i], want, "({x},{y})");
            }
        }
        assert!(winners > 2000, "the bunny covers the frame ({winners})");
    }
}

/// What a draw of `shader` leaves: the exact colours, the writes per pixel, the depth
/// bits and the counters.
type Drawn = (Vec<Option<Vec3>>, Vec<u32>, Vec<u32>, DrawStats);

/// Draws `shader`'s triangles on `threads` threads, shared `way`, into an [`Exact`]
/// target, which fails the test on a write outside the band or strip being drawn. The
/// vertex stage runs on the calling thread, so the draw projects the vertices (the
/// scene frames of [`frame_bits`] project them on the threads).
fn draw_direct(
    shader: &Direct,
    indices: &[u32],
    target: Target,
    opts: &DrawOptions,
    (threads, way): (usize, Spread),
) -> Drawn {
    draw_direct_shared(shader, indices, target, opts, (threads, way), &[])
}

/// [`draw_direct`], the strips starting from `shares` of the vertices if given.
fn draw_direct_shared(
    shader: &Direct,
    indices: &[u32],
    target: Target,
    opts: &DrawOptions,
    (threads, way): (usize, Spread),
    shares: &[f32],
) -> Drawn {
    let mut r = Renderer::new(target);
    r.set_threads(threads);
    share(&mut r, way, false);
    if !shares.is_empty() {
        r.set_strip_shares(0, shares);
    }
    let mut out = Exact::default();
    let mut cache = VertexCache::default();
    r.begin_frame(target, &mut out, Vec3::ZERO);
    r.transform(shader, shader.clip.len(), &mut cache);
    r.draw(shader, &cache, indices, opts, &mut out);
    if threads > 1 && !target.is_empty() {
        assert_eq!(r.spread(), way);
    }
    let depth = r.depth.to_vec().iter().map(|d| d.to_bits()).collect();
    (out.colors, out.writes, depth, r.stats)
}

/// Clip-space position (w = 1) of a point given in pixels of `target`, at depth `z`.
fn at_pixel(target: Target, x: f32, y: f32, z: f32) -> Vec4 {
    let (w, h) = (target.width as f32, target.height as f32);
    Vec4::new(x / w * 2.0 - 1.0, 1.0 - y / h * 2.0, z, 1.0)
}

/// The options a property test draws with: any traversal and interpolation, and
/// depth tests where the order of equal depths decides.
fn options(traversal: Traversal, interpolation: Interpolation, func: DepthFunc) -> DrawOptions {
    DrawOptions {
        traversal,
        interpolation,
        depth: DepthState { func, write: true },
        ..DrawOptions::default()
    }
}

/// Triangles with a vertex on each side of the first band border, the border crossed
/// at every one of the 256 subpixel offsets (and vertices exactly on it), overlapping
/// at equal and unequal depths so the order of the writes shows: the same exact
/// colours, writes per pixel, depth and counters on 1 and 2 threads, binned or in
/// strips (whose border unused vertices put on the same row), for every traversal;
/// on a short target (the shortest bands) and a tall one (the tallest).
#[test]
fn triangles_crossing_a_band_border_at_every_subpixel_draw_the_same() {
    let short = Target::new(48, 45);
    let tall = Target::new(48, 12 * BAND_ROWS + 5);
    // The seven triangles drawn below.
    let drawn = 7;
    assert_eq!(band_rows(short, 2, drawn), 8);
    assert_eq!(band_rows(tall, 2, drawn), BAND_ROWS);
    for (target, sub) in (0..256u32)
        .map(|s| (short, s))
        .chain((0..256).map(|s| (tall, s)))
    {
        let border = band_rows(target, 2, drawn) as f32;
        let off = sub as f32 / 256.0;
        let y = border - 0.5 + off;
        let p = |x: f32, y: f32, z: f32| at_pixel(target, x, y, z);
        let clip = vec![
            // A fan around a vertex near the border.
            p(20.0 + off, y, 0.5),
            p(3.0, y - 9.0 - off, 0.2),
            p(41.0, y - 1.0 + off, 0.7),
            p(37.0 - off, y + 12.0, 0.3),
            p(2.0 + off, y + 3.0 - off, 0.6),
            // A thin sliver along the border and a triangle with an edge on it.
            p(0.5, y, 0.5),
            p(47.5, y + off, 0.5),
            p(24.0, y + 0.75, 0.5),
            p(5.0, border, 0.4),
            p(30.0 + off, border, 0.4),
            p(17.0, border + 6.0 * off, 0.4),
        ];
        // Unused vertices that end the first of two strips at the border: as many
        // in the 8 rows above it as in the last 8 rows and the fan together.
        let fan = clip.len();
        let mut clip = clip;
        clip.extend((0..1000).map(|_| p(1.0, border - 4.0, 0.5)));
        let last = target.height as f32 - 2.0;
        clip.extend((0..1000 - fan + 1).map(|_| p(1.0, last, 0.5)));
        let attr = (0..clip.len())
            .map(|i| Vec3::new(i as f32, off, 1.0 - off))
            .collect();
        let shader = Direct { clip, attr };
        let mut cache = VertexCache::default();
        termrast::render::transform(&shader, shader.clip.len(), &mut cache);
        let mut pv = Vec::new();
        project_vertices(&cache, target, &mut pv);
        let mut spans = Vec::new();
        vertex_spans(&pv, target.height, &mut spans);
        let ends = strip_ends(&spans, target.height, &[1.0; 2], &mut Vec::new()).0;
        assert_eq!(
            ends[0], border as u32,
            "{target:?} {sub}: the strips' border"
        );
        let indices = [
            0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1, 5, 6, 7, 8, 9, 10, 1, 3, 2,
        ];
        assert_eq!(indices.len() / 3, drawn);
        for traversal in Traversal::ALL {
            for func in [DepthFunc::Less, DepthFunc::LessEqual, DepthFunc::Always] {
                let o = options(traversal, Interpolation::Perspective, func);
                let one = draw_direct(&shader, &indices, target, &o, (1, Spread::One));
                assert!(one.3.fragments > 100, "{sub}: the fan covers pixels");
                for way in WAYS {
                    let two = draw_direct(&shader, &indices, target, &o, (2, way));
                    assert!(
                        one == two,
                        "{target:?} subpixel {sub}, {traversal:?}, {func:?}, {way:?}"
                    );
                }
            }
        }
    }
}

fn vertex() -> impl Strategy<Value = Vec4> {
    // Mostly on the target, some past its sides (clipped) or behind the eye.
    (-1.4f32..1.4, -1.4f32..1.4, -0.2f32..1.1, 0.3f32..2.0)
        .prop_map(|(x, y, z, w)| Vec4::new(x * w, y * w, z * w, w))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random triangles, any traversal, interpolation and depth test, on targets
    /// from one band to several: 1, 2 and 3 threads, binned or in strips (from
    /// random shares of the vertices), draw the same.
    #[test]
    fn random_triangles_draw_the_same_on_every_thread_count(
        shares in prop::collection::vec(0.0f32..4.0, 3),
        clip in prop::collection::vec(vertex(), 3..40),
        tris in prop::collection::vec(any::<[prop::sample::Index; 3]>(), 1..30),
        (w, h) in (1u32..90, 1u32..(3 * BAND_ROWS + 7)),
        traversal in prop::sample::select(Traversal::ALL.to_vec()),
        interpolation in prop::sample::select(Interpolation::ALL.to_vec()),
        func in prop::sample::select(vec![DepthFunc::Less, DepthFunc::LessEqual, DepthFunc::Always]),
    ) {
        let target = Target::new(w, h);
        let indices: Vec<u32> = tris
            .iter()
            .flat_map(|t| t.map(|i| i.index(clip.len()) as u32))
            .collect();
        let attr = clip.iter().map(|p| p.truncate().abs()).collect();
        let shader = Direct { clip, attr };
        let o = options(traversal, interpolation, func);
        let one = draw_direct(&shader, &indices, target, &o, (1, Spread::One));
        for threads in [2, 3] {
            for way in WAYS {
                let shares = &shares[..threads];
                let many = draw_direct_shared(&shader, &indices, target, &o, (threads, way), shares);
                prop_assert!(one == many, "{} threads, {:?}", threads, way);
            }
        }
    }
}

/// `termrast render`'s text frames, its loop on the pool (frames of the bunny at
/// 200×60 cells are drawn in strips there), are the same bytes on 1, 2 and 3 threads.
#[test]
fn render_command_frames_are_the_same_on_every_thread_count() {
    let frames = |threads: &str| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_termrast"))
            .args([
                "render", "bunny", "--frames", "3", "--cols", "200", "--rows", "60",
            ])
            .args(["--threads", threads])
            .env("TERM", "xterm-256color")
            .output()
            .expect("the binary runs");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        out.stdout
    };
    let one = frames("1");
    assert!(one.len() > 10_000, "three frames of text");
    assert!(one == frames("2"), "2 threads");
    assert!(one == frames("3"), "3 threads");
}

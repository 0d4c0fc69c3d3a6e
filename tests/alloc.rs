//! A steady frame allocates nothing: after a few frames at a size, drawing more of
//! them (the model turning, as in the viewer) makes no heap allocation on any thread,
//! on one thread and on several, binned and in strips, for models and for a scene
//! whose draws differ in size.
//!
//! Its own test binary: the allocator counts every thread's allocations, which other
//! tests running at the same time would add to.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering::Relaxed};

use termrast::raster::Target;
use termrast::render::{MIN_STRIP_WORK, MIN_THREADED_WORK, Renderer, STRIP_DENSITY, Spread};
use termrast::scene::Scene;
use termrast::scene::render::{SceneFrame, SceneView};

/// The system allocator, counting the allocations made while [`ARMED`].
struct Counting;

static ARMED: AtomicBool = AtomicBool::new(false);
static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

impl Counting {
    fn count(&self) {
        if ARMED.load(Relaxed) {
            ALLOCATIONS.fetch_add(1, Relaxed);
        }
    }
}

// SAFETY: every call is passed on to `System` unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        self.count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        self.count();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        self.count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations while drawing six frames of `scene` with `frame` once it is steady:
/// after two frames in a row that allocated nothing (within 40). Buffers whose size
/// follows the view (a bin's entries as the model turns) may still grow in the first
/// frames, by doubling; a frame that allocates every time never becomes steady. With
/// threads, the whole loop runs on the pool, as the viewer's does (handing each
/// frame to the pool from outside would allocate in rayon's queue now and then).
fn allocations(frame: &mut SceneFrame, scene: &Scene, target: Target) -> u64 {
    let pool = frame.renderer.thread_pool().cloned();
    let mut measure = || {
        let mut k = 0;
        let mut draw = || {
            let view = SceneView {
                yaw: 0.05 * k as f32,
                ..SceneView::default()
            };
            k += 1;
            ALLOCATIONS.store(0, Relaxed);
            ARMED.store(true, Relaxed);
            frame.draw(scene, target, &view);
            ARMED.store(false, Relaxed);
            ALLOCATIONS.load(Relaxed)
        };
        let mut quiet = 0;
        for _ in 0..40 {
            quiet = if draw() == 0 { quiet + 1 } else { 0 };
            if quiet == 2 {
                break;
            }
        }
        (0..6).map(|_| draw()).sum()
    };
    match pool {
        Some(pool) => pool.install(measure),
        None => measure(),
    }
}

/// A scene of the teapot and a quad of two triangles: draws of the same varyings with
/// fewer triangles than a large pool's chunks and with more.
fn teapot_and_quad(dir: &std::path::Path) -> Scene {
    let quad = dir.join("quad.obj");
    std::fs::write(
        &quad,
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n",
    )
    .expect("the quad is written");
    let toml = dir.join("two.toml");
    std::fs::write(
        &toml,
        "[[object]]\nmodel = \"teapot\"\n[object.effects]\ndepth_test = true\n\n\
         [[object]]\nmodel = \"quad.obj\"\nscale = 0.4\n[object.effects]\ndepth_test = true\n",
    )
    .expect("the scene is written");
    Scene::load(&toml).expect("the scene loads")
}

#[test]
fn steady_frames_allocate_nothing() {
    let dir = std::env::temp_dir().join(format!("termrast-alloc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    let scenes = [
        ("teapot", Scene::standard("teapot").expect("built in")),
        ("bunny", Scene::standard("bunny").expect("built in")),
        (
            "sphere:20000",
            Scene::standard("sphere:20000").expect("built in"),
        ),
        ("teapot and quad", teapot_and_quad(&dir)),
    ];
    // One renderer per thread count for the whole test, lent to each frame: a dropped
    // pool's threads allocate as they exit, which could land in another setting's
    // measured frames.
    let mut renderers = [1, 2, 4].map(|n| {
        let mut r = Renderer::new(Target::new(1, 1));
        r.set_threads(n);
        // Every thread started and taking jobs before anything is counted.
        if let Some(pool) = r.thread_pool() {
            pool.broadcast(|_| ());
        }
        (n, r)
    });
    for (name, scene) in &scenes {
        for target in [Target::new(400, 240), Target::new(1280, 720)] {
            for (threads, renderer) in &mut renderers {
                let ways: &[Option<Spread>] = if *threads == 1 {
                    &[None]
                } else {
                    &[None, Some(Spread::Bins), Some(Spread::Strips)]
                };
                for &way in ways {
                    let mut frame = SceneFrame::new(scene);
                    std::mem::swap(&mut frame.renderer, renderer);
                    let r = &mut frame.renderer;
                    (r.min_threaded_work, r.min_strip_work, r.strip_density) = match way {
                        Some(Spread::Bins) => (0, MIN_STRIP_WORK, 0),
                        Some(_) => (u64::MAX, 0, STRIP_DENSITY),
                        None => (MIN_THREADED_WORK, MIN_STRIP_WORK, STRIP_DENSITY),
                    };
                    let n = allocations(&mut frame, scene, target);
                    assert_eq!(n, 0, "{name}, {target:?}, {threads} threads, {way:?}");
                    if let Some(way) = way {
                        assert_eq!(frame.renderer.spread(), way, "{name} {target:?}");
                    }
                    std::mem::swap(&mut frame.renderer, renderer);
                }
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

//! What accuracy costs in time: the variants of `termrast bench accuracy`, the
//! workloads they run on, and the exact references their errors are measured against.
//!
//! Every variant is a real code path:
//!
//! | family | variants | reference |
//! |---|---|---|
//! | edge arithmetic ([`edge`]) | `f32-direct`, `f32-incremental`, `f64`, `fixed4`, `fixed8`, `i64` | the i128 oracle on the 1/256 px grid |
//! | traversal | `scalar`, `planes`, `block`, `wide` | the oracle |
//! | interpolation | `affine`, `perspective`, `perspective-4/8/16` (the renderer's modes) | ray–plane intersection in f64 |
//! | anti-aliasing ([`area`]) | `1x`, `4x`, `16x` samples per pixel | exact area of triangle ∩ pixel |
//! | depth ([`depth`]) | `depth-f32`, `depth-unorm24`, `depth-unorm16`, `depth-f32-reversed` | the known nearer of two close planes |
//!
//! Times are the median of rounds of a whole workload, with the 95 % interval of that
//! median ([`timing`]): the variants of a family on a workload are timed in
//! interleaved rounds until each interval is narrow enough or its time budget is
//! spent. Errors come from one more run recorded in full. [`cases`] holds the hard
//! cases the stability suite and the table share.

pub mod area;
pub mod cases;
pub mod depth;
pub mod edge;
mod interpolation;
pub mod timing;
pub mod workloads;

use std::time::Duration;

use glam::{Mat4, Vec3};

use self::area::{SAMPLE_COUNTS, Supersampled, aa_name, pixel_areas, snapped, supersample};
use self::depth::{DepthFormat, DepthPass};
use self::edge::EdgeArith;
use self::interpolation::interpolation_rows;
use self::timing::{Policy, Timing, measure_each};
use self::workloads::WORKLOADS;
use crate::raster::{BitMask, CountGrid, CoverageSink, Setup, Target, Traversal};
use crate::workload::Tri2;

/// A family of variants: one accuracy choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Family {
    Edge,
    Traversal,
    Interpolation,
    AntiAliasing,
    Depth,
}

impl Family {
    /// Every family, in table order.
    pub const ALL: [Family; 5] = [
        Family::Edge,
        Family::Traversal,
        Family::Interpolation,
        Family::AntiAliasing,
        Family::Depth,
    ];

    /// The name in tables and CSV.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Family::Edge => "edge",
            Family::Traversal => "traversal",
            Family::Interpolation => "interpolation",
            Family::AntiAliasing => "anti-aliasing",
            Family::Depth => "depth",
        }
    }

    /// What the family's error column measures.
    #[must_use]
    pub fn error_name(self) -> &'static str {
        match self {
            Family::Edge | Family::Traversal => "coverage mismatches vs oracle (px)",
            Family::Interpolation => "max attribute error (px)",
            Family::AntiAliasing => "mean |coverage − area| per pixel",
            Family::Depth => "z-fighting rate",
        }
    }

    /// The variant the others are timed against: what the renderer uses.
    #[must_use]
    pub fn baseline(self) -> &'static str {
        match self {
            Family::Edge => "fixed8",
            Family::Traversal => "wide",
            Family::Interpolation => "perspective",
            Family::AntiAliasing => "1x",
            Family::Depth => "depth-f32",
        }
    }
}

/// Which sizes and how much work.
#[derive(Clone, Debug)]
pub struct Config {
    pub sizes: Vec<Target>,
    /// Scales the triangle counts of the tiny and sliver workloads.
    pub scale: f64,
    /// How long each measurement is timed (the median of its rounds is reported).
    pub timing: Policy,
}

impl Config {
    /// Every workload at 80×24, 200×60 and 1920×1080.
    #[must_use]
    pub fn full() -> Self {
        Self {
            sizes: vec![
                Target::new(80, 24),
                Target::new(200, 60),
                Target::new(1920, 1080),
            ],
            scale: 1.0,
            timing: Policy::new(5, 0.02, Duration::from_millis(300)),
        }
    }

    /// Terminal sizes only, thinner workloads, a smaller time budget per
    /// measurement: every variant, in seconds.
    #[must_use]
    pub fn quick() -> Self {
        Self {
            sizes: vec![Target::new(80, 24), Target::new(200, 60)],
            scale: 0.5,
            timing: Policy::new(5, 0.03, Duration::from_millis(30)),
        }
    }
}

/// Errors of one measurement; `None` where a measure does not apply.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Errors {
    /// Pixels where coverage differs from the oracle, summed over triangles.
    pub mismatches: Option<u64>,
    /// Pixels covered by no triangle / by several, for workloads that tile the target.
    pub holes: Option<u64>,
    pub double_hits: Option<u64>,
    /// Largest and mean absolute attribute error (uv units).
    pub attr_max: Option<f64>,
    pub attr_mean: Option<f64>,
    /// The same in pixels: the error divided by how far the exact attribute moves
    /// between neighbouring pixels (so the far end of a grazing floor, where one pixel
    /// spans many texels, does not drown everything else).
    pub attr_max_px: Option<f64>,
    pub attr_mean_px: Option<f64>,
    /// Mean and largest |coverage − exact area| per touched pixel.
    pub aa_mean: Option<f64>,
    pub aa_max: Option<f64>,
    /// Fraction of pixels where the farther of two close planes won.
    pub zfight: Option<f64>,
}

/// One variant on one workload at one size.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub family: Family,
    pub variant: &'static str,
    pub workload: &'static str,
    pub target: Target,
    /// Triangles (or clipped pieces) per run.
    pub triangles: u64,
    /// Pixels (fragments, samples resolved to pixels) produced per run.
    pub pixels: u64,
    /// Time of one run in nanoseconds: the median of the rounds and its interval.
    pub time: Timing,
    pub errors: Errors,
}

impl Row {
    /// Median nanoseconds of one run.
    #[must_use]
    pub fn median_ns(&self) -> f64 {
        self.time.median
    }

    /// Nanoseconds per triangle.
    #[must_use]
    pub fn ns_per_triangle(&self) -> f64 {
        self.time.median / self.triangles.max(1) as f64
    }

    /// Million pixels per second.
    #[must_use]
    pub fn mpx_per_s(&self) -> f64 {
        self.pixels as f64 / self.time.median.max(1.0) * 1e3
    }
}

/// A bit mask that also counts what it is sent (the timing sink).
struct Counted {
    mask: BitMask,
    n: u64,
}

impl CoverageSink for Counted {
    #[inline]
    fn pixel(&mut self, x: u32, y: u32) {
        self.mask.pixel(x, y);
        self.n += 1;
    }
    #[inline]
    fn span(&mut self, y: u32, x0: u32, x1: u32) {
        self.mask.span(y, x0, x1);
        self.n += u64::from(x1 - x0);
    }
    #[inline]
    fn mask8(&mut self, y: u32, x0: u32, mask: u8) {
        self.mask.mask8(y, x0, mask);
        self.n += u64::from(mask.count_ones());
    }
}

/// Coverage errors of a rasterizer (`raster(tri, sink)`) against the oracle's pixels.
fn coverage_errors(
    tris: &[Tri2],
    oracle: &[Vec<(u32, u32)>],
    target: Target,
    watertight: bool,
    mut raster: impl FnMut(Tri2, &mut Vec<(u32, u32)>),
) -> Errors {
    let mut grid = watertight.then(|| CountGrid::new(target.width, target.height));
    let mut got = Vec::new();
    let mut mismatches = 0;
    for (tri, want) in tris.iter().zip(oracle) {
        got.clear();
        raster(*tri, &mut got);
        if let Some(g) = grid.as_mut() {
            for &(x, y) in &got {
                g.counts[y as usize * target.width as usize + x as usize] += 1;
            }
        }
        got.sort_unstable_by_key(|&(x, y)| (y, x));
        mismatches += cases::symmetric_difference(&got, want);
    }
    Errors {
        mismatches: Some(mismatches),
        holes: grid
            .as_ref()
            .map(|g| g.counts.iter().filter(|&&c| c == 0).count() as u64),
        double_hits: grid.map(|g| g.counts.iter().filter(|&&c| c > 1).count() as u64),
        ..Errors::default()
    }
}

/// Rasterizes every triangle with `f` into `sink` (cleared first). Generic so the
/// rasterizer inlines into the sink.
fn cover_all<F: Fn(Tri2, &mut Counted)>(tris: &[Tri2], sink: &mut Counted, f: F) {
    sink.mask.clear();
    sink.n = 0;
    for &t in tris {
        f(t, sink);
    }
}

/// The edge-arithmetic and traversal rows of one 2D workload. Each family's variants
/// are timed in interleaved rounds.
fn coverage_rows(
    workload: &'static str,
    tris: &[Tri2],
    target: Target,
    config: &Config,
    rows: &mut Vec<Row>,
) {
    let oracle: Vec<Vec<(u32, u32)>> = tris
        .iter()
        .map(|&t| cases::oracle_pixels(t, target))
        .collect();
    let watertight = matches!(workload, "large" | "slivers");
    let mut sink = Counted {
        mask: BitMask::new(target.width, target.height),
        n: 0,
    };
    let edge = |v: EdgeArith, sink: &mut Counted| {
        cover_all(tris, sink, |t, s| v.rasterize(t, target, s));
    };
    let times = measure_each(&config.timing, EdgeArith::ALL.len(), |i| {
        edge(EdgeArith::ALL[i], &mut sink);
    });
    for (v, time) in EdgeArith::ALL.into_iter().zip(times) {
        edge(v, &mut sink);
        let errors = coverage_errors(tris, &oracle, target, watertight, |t, out| {
            v.rasterize(t, target, out);
        });
        rows.push(Row {
            family: Family::Edge,
            variant: v.name(),
            workload,
            target,
            triangles: tris.len() as u64,
            pixels: sink.n,
            time,
            errors,
        });
    }
    let traverse = |tr: Traversal, sink: &mut Counted| {
        cover_all(tris, sink, |t, s| {
            if let Ok(setup) = Setup::new(t, target) {
                tr.run(&setup, s);
            }
        });
    };
    let times = measure_each(&config.timing, Traversal::ALL.len(), |i| {
        traverse(Traversal::ALL[i], &mut sink);
    });
    for (tr, time) in Traversal::ALL.into_iter().zip(times) {
        traverse(tr, &mut sink);
        let errors = coverage_errors(tris, &oracle, target, watertight, |t, out| {
            if let Ok(setup) = Setup::new(t, target) {
                tr.run(&setup, out);
            }
        });
        rows.push(Row {
            family: Family::Traversal,
            variant: tr.name(),
            workload,
            target,
            triangles: tris.len() as u64,
            pixels: sink.n,
            time,
            errors,
        });
    }
}

/// The anti-aliasing rows of one 2D workload.
fn aa_rows(
    workload: &'static str,
    tris: &[Tri2],
    target: Target,
    config: &Config,
    rows: &mut Vec<Row>,
) {
    let mut ss = Supersampled::default();
    let mut pixels = [0u64; SAMPLE_COUNTS.len()];
    let times = measure_each(&config.timing, SAMPLE_COUNTS.len(), |i| {
        let mut n = 0;
        for &t in tris {
            supersample(t, target, SAMPLE_COUNTS[i], &mut ss);
            n += ss.counts.iter().filter(|&&c| c > 0).count() as u64;
        }
        pixels[i] = n;
    });
    for ((samples, time), pixels) in SAMPLE_COUNTS.into_iter().zip(times).zip(pixels) {
        let (mut sum, mut n, mut max) = (0.0, 0u64, 0.0f64);
        for &t in tris {
            let Some(exact) = snapped(t) else { continue };
            supersample(t, target, samples, &mut ss);
            pixel_areas(exact, target, |x, y, a| {
                let e = (ss.coverage(x, y) - a.min(1.0)).abs();
                sum += e;
                max = max.max(e);
                n += 1;
            });
        }
        rows.push(Row {
            family: Family::AntiAliasing,
            variant: aa_name(samples),
            workload,
            target,
            triangles: tris.len() as u64,
            pixels,
            time,
            errors: Errors {
                aa_mean: Some(if n == 0 { 0.0 } else { sum / n as f64 }),
                aa_max: Some(max),
                ..Errors::default()
            },
        });
    }
}

/// Two parallel planes tilted in depth, `gap` apart at view distance `distance`,
/// filling the view: (farther, nearer) as positions with two triangles each.
fn close_planes(distance: f32, gap: f32) -> [Vec<Vec3>; 2] {
    let cam = crate::camera::Camera::default();
    let half = distance * (cam.fov_y * 0.5).tan() * 2.0;
    let tilt = Mat4::from_rotation_x(-0.9);
    let centre = cam.eye - Vec3::Z * distance;
    let quad = |offset: f32| {
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(x, y)| {
                centre
                    + tilt.transform_vector3(Vec3::new(x * half, y * half, 0.0))
                    + tilt.transform_vector3(Vec3::Z) * offset
            })
            .to_vec()
    };
    [quad(0.0), quad(gap)]
}

/// View distances and relative gaps of the close-planes workload.
pub const CLOSE_PLANE_DISTANCES: [f32; 4] = [0.3, 1.0, 3.0, 9.0];
/// Gaps between the planes as fractions of their distance.
pub const CLOSE_PLANE_GAPS: [f32; 3] = [1e-3, 1e-4, 1e-5];

/// The depth rows: z-fighting on close planes, and the bunny for speed. The close
/// planes are timed as one run through every distance, gap and draw order.
fn depth_rows(target: Target, config: &Config, rows: &mut Vec<Row>) {
    const QUAD: [u32; 6] = [0, 1, 2, 0, 2, 3];
    let cam = crate::camera::Camera::default();
    let vp = cam.projection(target.width, target.height, 1.0) * cam.view();
    let bunny = workloads::bunny_scene();
    // (first drawn, its id, second drawn, its id): the farther plane has id 0.
    let mut pairs: Vec<[(Vec<Vec3>, u32); 2]> = Vec::new();
    for d in CLOSE_PLANE_DISTANCES {
        for g in CLOSE_PLANE_GAPS {
            let [far, near] = close_planes(d, d * g);
            pairs.push([(far.clone(), 0), (near.clone(), 1)]);
            pairs.push([(near, 1), (far, 0)]);
        }
    }
    let mut passes: Vec<DepthPass> = DepthFormat::ALL
        .iter()
        .map(|&f| DepthPass::new(target, f))
        .collect();
    let matrices = DepthFormat::ALL.map(|f| f.projection(vp));
    let bunny_matrices = DepthFormat::ALL.map(|f| f.projection(bunny.view_proj(target)));
    let planes = |pass: &mut DepthPass, matrix: Mat4, pair: &[(Vec<Vec3>, u32); 2]| {
        pass.clear();
        for (p, id) in pair {
            pass.draw(p, &QUAD, matrix, *id);
        }
    };
    let times = measure_each(&config.timing, passes.len(), |i| {
        for pair in &pairs {
            planes(&mut passes[i], matrices[i], pair);
        }
    });
    let bunny_times = measure_each(&config.timing, passes.len(), |i| {
        let pass = &mut passes[i];
        pass.clear();
        pass.draw(&bunny.positions, &bunny.indices, bunny_matrices[i], 0);
    });
    for (i, pass) in passes.iter_mut().enumerate() {
        let format = DepthFormat::ALL[i];
        let (mut wrong, mut total, mut fragments) = (0u64, 0u64, 0u64);
        for pair in &pairs {
            planes(pass, matrices[i], pair);
            fragments += pass.fragments;
            // Pixels both planes cover: the ids show which won.
            total += pass.ids.iter().filter(|&&i| i != u32::MAX).count() as u64;
            wrong += pass.ids.iter().filter(|&&i| i == 0).count() as u64;
        }
        rows.push(Row {
            family: Family::Depth,
            variant: format.name(),
            workload: "close-planes",
            target,
            triangles: 2 * QUAD.len() as u64 / 3 * pairs.len() as u64,
            pixels: fragments,
            time: times[i],
            errors: Errors {
                zfight: Some(if total == 0 {
                    0.0
                } else {
                    wrong as f64 / total as f64
                }),
                ..Errors::default()
            },
        });
        pass.clear();
        pass.draw(&bunny.positions, &bunny.indices, bunny_matrices[i], 0);
        rows.push(Row {
            family: Family::Depth,
            variant: format.name(),
            workload: "bunny",
            target,
            triangles: (bunny.indices.len() / 3) as u64,
            pixels: pass.fragments,
            time: bunny_times[i],
            errors: Errors::default(),
        });
    }
}

/// Runs every variant on every workload at every size. `progress` is told what is
/// being measured.
pub fn run(config: &Config, mut progress: impl FnMut(&str)) -> Vec<Row> {
    let mut rows = Vec::new();
    for &target in &config.sizes {
        for &name in &WORKLOADS {
            progress(&format!("{}x{} {name}", target.width, target.height));
            let tris = workloads::triangles(name, target, config.scale);
            coverage_rows(name, &tris, target, config, &mut rows);
            aa_rows(name, &tris, target, config, &mut rows);
            if let Some(scene) = workloads::scene(name) {
                interpolation_rows(&scene, target, config, &mut rows);
            }
        }
        progress(&format!("{}x{} depth", target.width, target.height));
        depth_rows(target, config, &mut rows);
    }
    rows
}

//! The interpolation family of the accuracy table: each interpolation mode draws a
//! scene's texture coordinates, timed, and is scored against the ray-cast uv at every
//! pixel centre (in uv units and in pixels of the attribute's footprint).

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::timing::measure_each;
use super::workloads::{Scene3, UvShader};
use super::{Config, Errors, Family, Row};
use crate::raster::Target;
use crate::raster::interp::Interpolation;
use crate::render::target::{SplitOff, split_off_slice, split_slice};
use crate::render::{ColorTarget, DrawOptions, Renderer, VertexCache, transform};

/// Texture coordinates per pixel (NaN where nothing was drawn).
#[derive(Default)]
struct UvTarget(Vec<[f32; 2]>);

impl ColorTarget for UvTarget {
    #[inline(always)]
    fn put(&mut self, i: usize, c: Vec3) {
        self.0[i] = [c.x, c.y];
    }
    fn reset(&mut self, len: usize, _: Vec3) {
        self.0.clear();
        self.0.resize(len, [f32::NAN; 2]);
    }
    fn len(&self) -> usize {
        self.0.len()
    }

    type Rows<'a> = UvRows<'a>;

    fn all_rows(&mut self) -> UvRows<'_> {
        UvRows(&mut self.0[..])
    }

    fn bands(&mut self, pixels: usize) -> impl IndexedParallelIterator<Item = UvRows<'_>> {
        self.0.par_chunks_mut(pixels).map(UvRows)
    }

    fn split_rows<'s>(&'s mut self, ends: &[usize], mut f: impl FnMut(UvRows<'s>)) {
        split_slice(&mut self.0[..], ends, |p| f(UvRows(p)));
    }
}

/// A band of rows of a [`UvTarget`].
struct UvRows<'a>(&'a mut [[f32; 2]]);

impl SplitOff for UvRows<'_> {
    fn split_off(&mut self, pixels: usize) -> Self {
        UvRows(split_off_slice(&mut self.0, pixels))
    }
}

impl ColorTarget for UvRows<'_> {
    #[inline(always)]
    fn put(&mut self, i: usize, c: Vec3) {
        self.0[i] = [c.x, c.y];
    }
    fn reset(&mut self, _: usize, _: Vec3) {
        self.0.fill([f32::NAN; 2]);
    }
    fn len(&self) -> usize {
        self.0.len()
    }

    type Rows<'a>
        = UvRows<'a>
    where
        Self: 'a;

    fn all_rows(&mut self) -> UvRows<'_> {
        UvRows(&mut self.0[..])
    }

    fn bands(&mut self, pixels: usize) -> impl IndexedParallelIterator<Item = UvRows<'_>> {
        self.0.par_chunks_mut(pixels).map(UvRows)
    }

    fn split_rows<'s>(&'s mut self, ends: &[usize], mut f: impl FnMut(UvRows<'s>)) {
        split_slice(&mut self.0[..], ends, |p| f(UvRows(p)));
    }
}

/// The exact uv at a pixel centre and its step to the neighbouring pixels.
type ExactUv = ([f64; 2], f64);

/// The interpolation rows of one 3D scene.
pub(super) fn interpolation_rows(
    scene: &Scene3,
    target: Target,
    config: &Config,
    rows: &mut Vec<Row>,
) {
    let shader = UvShader {
        scene,
        mvp: scene.view_proj(target),
    };
    let mut renderer = Renderer::new(target);
    let mut cache = VertexCache::<Vec2>::default();
    let mut out = UvTarget::default();
    // The exact uv at every pixel centre, and how far the uv moves to the next pixel
    // (the attribute's screen footprint), for errors in pixels.
    let exact: Option<Vec<Option<ExactUv>>> = scene.plane.map(|_| {
        let cast = scene.ray_caster(target);
        let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs().max((a[1] - b[1]).abs());
        (0..target.height)
            .flat_map(|y| (0..target.width).map(move |x| (x, y)))
            .map(|(x, y)| {
                let uv = cast(x, y)?;
                let step = [cast(x + 1, y), cast(x, y + 1)]
                    .into_iter()
                    .flatten()
                    .map(|n| dist(uv, n))
                    .fold(0.0, f64::max);
                Some((uv, step))
            })
            .collect()
    });
    let mut draw = |mode: Interpolation, out: &mut UvTarget| {
        let opts = DrawOptions {
            interpolation: mode,
            ..DrawOptions::default()
        };
        renderer.begin_frame(target, out, Vec3::ZERO);
        transform(&shader, scene.positions.len(), &mut cache);
        renderer.draw(&shader, &cache, &scene.indices, &opts, out);
        renderer.stats
    };
    let times = measure_each(&config.timing, Interpolation::ALL.len(), |i| {
        draw(Interpolation::ALL[i], &mut out);
    });
    for (mode, time) in Interpolation::ALL.into_iter().zip(times) {
        let stats = draw(mode, &mut out);
        let errors = exact.as_ref().map_or(Errors::default(), |exact| {
            let mut e = [(0.0, 0.0f64); 2];
            let mut n = 0u64;
            for (got, want) in out.0.iter().zip(exact) {
                let (Some((want, step)), false) = (want, got[0].is_nan()) else {
                    continue;
                };
                let err = (f64::from(got[0]) - want[0])
                    .abs()
                    .max((f64::from(got[1]) - want[1]).abs());
                let px = err / step.max(f64::MIN_POSITIVE);
                for (acc, v) in e.iter_mut().zip([err, px]) {
                    acc.0 += v;
                    acc.1 = acc.1.max(v);
                }
                n += 1;
            }
            let mean = |s: f64| if n == 0 { 0.0 } else { s / n as f64 };
            Errors {
                attr_max: Some(e[0].1),
                attr_mean: Some(mean(e[0].0)),
                attr_max_px: Some(e[1].1),
                attr_mean_px: Some(mean(e[1].0)),
                ..Errors::default()
            }
        });
        rows.push(Row {
            family: Family::Interpolation,
            variant: mode.name(),
            workload: scene.name,
            target,
            triangles: stats.drawn,
            pixels: stats.shaded,
            time,
            errors,
        });
    }
}

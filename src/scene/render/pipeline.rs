//! One object's pipeline: its shader (the lane-code Lambert for the standard plan,
//! else the packed shader at the narrowest width that holds its varyings), its vertex
//! cache, and what it draws (fill, wireframe, silhouettes, the probe).

use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

use glam::{Vec2, Vec3, Vec4};

use super::*;
use crate::counters::{self, Stage};
use crate::raster::Target;
use crate::raster::depth::{DepthBuffer, DepthState};
use crate::raster::interp::Varying;
use crate::render::probe::{DepthOutcome, Probe, probe_projected};

use crate::render::wire::{
    LineHit, ScreenLine, WIRE_COLOR, WIRE_DEPTH_BIAS, WireCount, draw_wireframe, line_under,
    probe_lines, project_edge,
};
use crate::render::{
    Cull, DrawOptions, Projected, Renderer, Rgba8, Shader, VertexCache, ndc_to_screen,
    project_vertices,
};
use crate::scene::plan::{ObjectPlan, VaryingSet};
use crate::scene::{LightDesc, SceneObject};

/// A silhouette edge on screen, in sample coordinates (pixel centres at +0.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Silhouette {
    pub a: Vec2,
    pub b: Vec2,
}

/// One object's pipeline: its monomorphized shader and its vertex cache.
pub trait ObjectPipeline {
    /// Transforms the object and draws its triangles (if its plan fills them) with
    /// `opts`; returns the time the vertex stage took.
    fn draw(
        &mut self,
        obj: &SceneObject,
        plan: &ObjectPlan,
        ctx: FrameCtx<'_>,
        opts: &DrawOptions,
        r: &mut Renderer,
        color: &mut Rgba8,
    ) -> Duration;
    /// Draws the object's edges.
    fn wireframe(
        &self,
        obj: &SceneObject,
        target: Target,
        depth: Option<&DepthBuffer>,
        color: &mut Rgba8,
    ) -> WireCount;
    /// Appends the object's silhouette edges, in the coordinates of `target`.
    fn silhouettes(
        &self,
        obj: &SceneObject,
        target: Target,
        depth: Option<(&DepthBuffer, u32)>,
        out: &mut Vec<Silhouette>,
    );
    /// The raster state of a pixel for this object as drawn with `opts` in the frame
    /// of `ctx`, continuing from `stored` depth; each record carries the colour its
    /// fragment was shaded (if it passed the depth test).
    #[allow(clippy::too_many_arguments)]
    fn probe(
        &self,
        obj: &SceneObject,
        plan: &ObjectPlan,
        ctx: FrameCtx<'_>,
        opts: &DrawOptions,
        target: Target,
        pixel: (u32, u32),
        stored: f32,
    ) -> Probe<Option<Vec3>>;
    /// Every one of the object's edges whose line draws pixel `(x, y)`.
    fn probe_lines(
        &self,
        obj: &SceneObject,
        target: Target,
        depth: Option<&DepthBuffer>,
        x: u32,
        y: u32,
    ) -> Vec<LineHit>;
    /// The varying set this pipeline was compiled for.
    fn varyings(&self) -> VaryingSet;
    /// Which shading it draws with ([`Shading::NAME`]).
    fn name(&self) -> &'static str;
    /// The line under a pixel (see [`line_under`]), from this frame's vertices.
    fn line_under(
        &self,
        obj: &SceneObject,
        wires: Option<Option<&DepthBuffer>>,
        triangle: Option<u32>,
        target: Target,
        x: u32,
        y: u32,
    ) -> Option<([u32; 2], ScreenLine, i64)>;
    /// One of the object's edges projected to `target`, from this frame's vertices.
    fn project_edge(&self, edge: [u32; 2], target: Target) -> Option<ScreenLine>;
}

/// The draw options an object's plan asks for (its depth test and culling), over
/// `base` (the frame's interpolation and traversal).
#[must_use]
pub fn draw_options(plan: &ObjectPlan, base: DrawOptions) -> DrawOptions {
    DrawOptions {
        depth: if plan.depth_test {
            DepthState::default()
        } else {
            DepthState::OFF
        },
        cull: if plan.cull { Cull::Back } else { Cull::None },
        ..base
    }
}

/// How a pipeline makes its object's shader for a frame: the packed shader of any
/// plan ([`Packed`]), or the lane-code Lambert of the standard plan ([`StandardLambert`]).
pub trait Shading: 'static {
    /// What the pipeline is called (tests and diagnostics).
    const NAME: &'static str;
    type Varying: Varying;
    type Instance<'a>: Shader<Varying = Self::Varying>;
    /// The object's shader at this frame.
    fn shader<'a>(
        obj: &'a SceneObject,
        plan: &'a ObjectPlan,
        ctx: FrameCtx<'a>,
    ) -> Self::Instance<'a>;
    /// Adds to the work counters what the shader does not count itself, after a draw
    /// that shaded `shaded` fragments.
    fn count_work(_obj: &SceneObject, _shaded: u64) {}
}

/// [`ObjectShader`] with its varyings packed in `K` floats.
pub struct Packed<const K: usize>;

impl<const K: usize> Shading for Packed<K> {
    const NAME: &'static str = "packed";
    type Varying = [f32; K];
    type Instance<'a> = ObjectShader<'a, K>;

    fn shader<'a>(
        obj: &'a SceneObject,
        plan: &'a ObjectPlan,
        ctx: FrameCtx<'a>,
    ) -> ObjectShader<'a, K> {
        ObjectShader::new(obj, plan, ctx)
    }
}

/// An object's pipeline: the shading it was chosen for, its vertex cache.
struct Pipeline<S: Shading> {
    cache: VertexCache<S::Varying>,
    varyings: VaryingSet,
    /// The cache's vertices projected for the probe, and the target they are for:
    /// made by the first probe after a draw, kept for the frame's other probes.
    projected: Mutex<(Option<Target>, Vec<Projected>)>,
}

impl<S: Shading> ObjectPipeline for Pipeline<S> {
    fn draw(
        &mut self,
        obj: &SceneObject,
        plan: &ObjectPlan,
        ctx: FrameCtx<'_>,
        opts: &DrawOptions,
        r: &mut Renderer,
        color: &mut Rgba8,
    ) -> Duration {
        let start = Instant::now();
        let shader = S::shader(obj, plan, ctx);
        r.transform(&shader, obj.mesh.positions.len(), &mut self.cache);
        self.projected
            .get_mut()
            .unwrap_or_else(PoisonError::into_inner)
            .0 = None;
        let vertex = start.elapsed();
        if plan.fill {
            let shaded = r.stats.shaded;
            r.draw(&shader, &self.cache, &obj.mesh.indices, opts, color);
            S::count_work(obj, r.stats.shaded - shaded);
        }
        vertex
    }

    fn wireframe(
        &self,
        obj: &SceneObject,
        target: Target,
        depth: Option<&DepthBuffer>,
        color: &mut Rgba8,
    ) -> WireCount {
        counters::add(Stage::WireEdges, obj.edges.len() as u64);
        draw_wireframe(&self.cache, &obj.edges, target, depth, WIRE_COLOR, color)
    }

    fn silhouettes(
        &self,
        obj: &SceneObject,
        target: Target,
        depth: Option<(&DepthBuffer, u32)>,
        out: &mut Vec<Silhouette>,
    ) {
        let verts = &self.cache.verts;
        let idx = &obj.mesh.indices;
        // Facing of a triangle: the sign of its doubled area in NDC (w > 0 only).
        let facing = |t: u32| -> Option<bool> {
            let tri = idx.get(t as usize * 3..t as usize * 3 + 3)?;
            let p = [tri[0], tri[1], tri[2]].map(|i| verts.get(i as usize).map(|v| v.pos));
            let [Some(a), Some(b), Some(c)] = p else {
                return None;
            };
            if a.w <= 0.0 || b.w <= 0.0 || c.w <= 0.0 {
                return None;
            }
            let (a, b, c) = (a.truncate() / a.w, b.truncate() / b.w, c.truncate() / c.w);
            Some((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) > 0.0)
        };
        let (w, h) = (target.width as f32, target.height as f32);
        for (e, faces) in obj.edges.iter().zip(&obj.edge_faces) {
            let front = facing(faces[0]);
            let other = if faces[1] == u32::MAX {
                None
            } else {
                facing(faces[1])
            };
            let silhouette = match (front, other) {
                (Some(a), Some(b)) => a != b,
                (Some(a), None) => a, // a boundary edge of a front face
                _ => false,
            };
            if !silhouette {
                continue;
            }
            let (Some(a), Some(b)) = (verts.get(e[0] as usize), verts.get(e[1] as usize)) else {
                continue;
            };
            let (a, b) = (a.pos, b.pos);
            if a.w <= 0.0 || b.w <= 0.0 {
                continue;
            }
            let screen = |p: Vec4| Vec2::from(ndc_to_screen([p.x / p.w, p.y / p.w], [w, h]));
            // Hidden silhouettes (behind other surfaces) are left out when depth exists:
            // the midpoint is tested like a wireframe pixel.
            if let Some((d, side)) = depth {
                let m = (a + b) * 0.5;
                let s = screen(m);
                let (x, y) = ((s.x * side as f32) as u32, (s.y * side as f32) as u32);
                if x < d.width() && y < d.height() {
                    let z = m.z / m.w;
                    if z - WIRE_DEPTH_BIAS * 10.0 > d.get(x, y) {
                        continue;
                    }
                }
            }
            counters::add(Stage::SilhouetteEdges, 1);
            out.push(Silhouette {
                a: screen(a),
                b: screen(b),
            });
        }
    }

    fn probe(
        &self,
        obj: &SceneObject,
        plan: &ObjectPlan,
        ctx: FrameCtx<'_>,
        opts: &DrawOptions,
        target: Target,
        (x, y): (u32, u32),
        stored: f32,
    ) -> Probe<Option<Vec3>> {
        if !plan.fill {
            // Nothing of it was rasterized.
            return Probe {
                x,
                y,
                records: Vec::new(),
                winner: None,
                final_depth: stored,
            };
        }
        let mut projected = self
            .projected
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        if projected.0 != Some(target) {
            project_vertices(&self.cache, target, &mut projected.1);
            projected.0 = Some(target);
        }
        let indices = &obj.mesh.indices;
        let p = probe_projected(
            &self.cache,
            &projected.1,
            indices,
            target,
            opts,
            (x, y),
            stored,
        );
        drop(projected);
        // The trait object cannot return this pipeline's varying type: each record
        // keeps the colour shaded from it instead.
        let shader = S::shader(obj, plan, ctx);
        Probe {
            x: p.x,
            y: p.y,
            records: p
                .records
                .into_iter()
                .map(|r| {
                    let passed = matches!(r.depth, DepthOutcome::Passed { .. });
                    r.map(|v| passed.then(|| shader.fragment(&v)))
                })
                .collect(),
            winner: p.winner,
            final_depth: p.final_depth,
        }
    }

    fn probe_lines(
        &self,
        obj: &SceneObject,
        target: Target,
        depth: Option<&DepthBuffer>,
        x: u32,
        y: u32,
    ) -> Vec<LineHit> {
        probe_lines(&self.cache, &obj.edges, target, depth, x, y)
    }

    fn varyings(&self) -> VaryingSet {
        self.varyings
    }

    fn name(&self) -> &'static str {
        S::NAME
    }

    fn line_under(
        &self,
        obj: &SceneObject,
        wires: Option<Option<&DepthBuffer>>,
        triangle: Option<u32>,
        target: Target,
        x: u32,
        y: u32,
    ) -> Option<([u32; 2], ScreenLine, i64)> {
        let wires = wires.map(|d| (obj.edges.as_slice(), d));
        line_under(
            &self.cache,
            &obj.mesh.indices,
            wires,
            triangle,
            target,
            x,
            y,
        )
    }

    fn project_edge(&self, edge: [u32; 2], target: Target) -> Option<ScreenLine> {
        project_edge(&self.cache, edge, target)
    }
}

/// The pipeline for an object of a scene lit by `lights`: the lane-code Lambert when
/// its plan is exactly the standard one ([`is_standard_lambert`]) or that with vertex
/// colours ([`is_colored_lambert`]), the flat colour when nothing varies over its
/// surface ([`is_flat_colour`]), the interpolated colour when only a colour does
/// ([`is_vertex_colour`]), else the packed
/// shader at the narrowest of [`PACKED_WIDTHS`] that holds its varyings.
#[must_use]
pub fn pipeline_for(
    obj: &SceneObject,
    plan: &ObjectPlan,
    lights: &[LightDesc],
) -> Box<dyn ObjectPipeline + Send> {
    fn new<S: Shading>(varyings: VaryingSet) -> Box<dyn ObjectPipeline + Send> {
        Box::new(Pipeline::<S> {
            cache: VertexCache::default(),
            varyings,
            projected: Mutex::default(),
        })
    }
    let varyings = plan.varyings;
    if is_standard_lambert(obj, plan, lights) {
        return new::<StandardLambert>(varyings);
    }
    if is_colored_lambert(obj, plan, lights) {
        return new::<StandardColoredLambert>(varyings);
    }
    if is_flat_colour(plan) {
        return new::<Flat>(varyings);
    }
    if is_vertex_colour(plan) {
        return new::<Interpolated>(varyings);
    }
    match Layout::new(varyings).len {
        0 => new::<Packed<0>>(varyings),
        1..=4 => new::<Packed<4>>(varyings),
        5..=8 => new::<Packed<8>>(varyings),
        _ => new::<Packed<12>>(varyings),
    }
}

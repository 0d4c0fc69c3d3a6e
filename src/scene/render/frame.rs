//! A scene's frame: the camera, the buffers the plan asks for, every object drawn in
//! order, supersampling resolved.

use std::hash::{DefaultHasher, Hash, Hasher};
use std::time::{Duration, Instant};

use glam::{Mat3, Mat4, Vec3};

use super::*;
use crate::camera::Camera;
use crate::counters::{self, Stage};
use crate::raster::interp::Interpolation;
use crate::raster::samples::grid_side;
use crate::raster::{Target, Traversal};
use crate::render::probe::Probe;
use crate::render::wire::{LineHit, ScreenLine, WireCount};
use crate::render::{DrawOptions, DrawStats, Renderer, Rgba8};
use crate::scene::plan::{ObjectPlan, VaryingSet};
use crate::scene::{Rig, Scene, SceneObject};

/// A probe of one object at a pixel, each record carrying the colour its fragment
/// was shaded (if it passed the depth test).
pub type ShadedProbe = Probe<Option<Vec3>>;

/// Where a scene is seen from in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneView {
    /// Seconds since the start (spins).
    pub time: f32,
    /// Radians about y, then about x: of the camera about its target
    /// ([`Rig::Orbit`]), or of the objects about the origin ([`Rig::Turntable`]).
    pub yaw: f32,
    pub pitch: f32,
    /// Camera distance divisor (1 = as loaded): see [`Rig`].
    pub zoom: f32,
    /// Pixel width over height of the target's samples.
    pub pixel_aspect: f32,
}

impl Default for SceneView {
    fn default() -> Self {
        Self {
            time: 0.0,
            yaw: 0.0,
            pitch: 0.0,
            zoom: 1.0,
            pixel_aspect: 1.0,
        }
    }
}

/// Buffers and pipelines for drawing a scene; reused from frame to frame.
pub struct SceneFrame {
    pub renderer: Renderer,
    /// The frame at the requested size (alpha 255 where covered).
    pub color: Rgba8,
    /// The supersampled frame (empty when the plan has no supersampling).
    fine: Rgba8,
    pipelines: Vec<Box<dyn ObjectPipeline + Send>>,
    pub silhouettes: Vec<Silhouette>,
    /// Counters of the last frame, all objects.
    pub stats: DrawStats,
    pub wire: WireCount,
    /// How every object's attributes are interpolated, and the traversal that walks
    /// its triangles (all give the same coverage): the rest of the draw options
    /// come from each object's plan.
    pub interpolation: Interpolation,
    pub traversal: Traversal,
    /// Time of the last frame's vertex stage, and of the rest of its drawing
    /// (coverage, depth and shading are one fused loop, so they are timed together).
    pub timing: [Duration; 2],
    /// The last frame's context, for the probe (its lights are the scene's).
    ctx: Option<FrameCtx<'static>>,
}

impl std::fmt::Debug for SceneFrame {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneFrame")
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

impl SceneFrame {
    /// Pipelines for a scene's objects, by its plan.
    #[must_use]
    pub fn new(scene: &Scene) -> Self {
        Self {
            renderer: Renderer::new(Target::new(1, 1)),
            color: Rgba8::default(),
            fine: Rgba8::default(),
            pipelines: scene
                .objects
                .iter()
                .zip(&scene.plan.objects)
                .map(|(o, op)| pipeline_for(o, op, &scene.lights))
                .collect(),
            silhouettes: Vec::new(),
            stats: DrawStats::default(),
            wire: WireCount::default(),
            interpolation: Interpolation::Perspective,
            traversal: Traversal::Wide,
            timing: Default::default(),
            ctx: None,
        }
    }

    /// The draw options of an object: its plan's depth test and culling, this
    /// frame's interpolation and traversal.
    #[must_use]
    pub fn draw_options(&self, plan: &ObjectPlan) -> DrawOptions {
        draw_options(plan, self.base_options())
    }

    fn base_options(&self) -> DrawOptions {
        DrawOptions {
            interpolation: self.interpolation,
            traversal: self.traversal,
            ..DrawOptions::default()
        }
    }

    /// The varying sets the pipelines were compiled for, per object.
    #[must_use]
    pub fn varyings(&self) -> Vec<VaryingSet> {
        self.pipelines.iter().map(|p| p.varyings()).collect()
    }

    /// The shading each object's pipeline draws with: `"lambert"` for the standard
    /// plan's lane-code Lambert, `"lambert-colors"` for it with vertex colours,
    /// `"flat"` for one flat colour, `"vertex-color"` for a colour interpolated from
    /// the vertices, else `"packed"`.
    #[must_use]
    pub fn pipelines(&self) -> Vec<&'static str> {
        self.pipelines.iter().map(|p| p.name()).collect()
    }

    /// Draws a frame of `target` samples.
    pub fn draw(&mut self, scene: &Scene, target: Target, view: &SceneView) {
        let side = u64::from(grid_side(scene.plan.samples)).pow(2);
        let triangles: usize = scene.objects.iter().map(|o| o.mesh.triangle_count()).sum();
        self.renderer.plan_frame(
            target.len() as u64 * side + crate::render::TRIANGLE_WORK * triangles as u64,
            draw_kind(scene, self.interpolation, self.traversal),
        );
        let start = Instant::now();
        match self.renderer.pool().cloned() {
            // The whole frame on the pool: its steps then start their parallel work
            // from one of its threads, without waking the pool for each.
            Some(pool) => pool.install(|| self.draw_here(scene, target, view)),
            None => self.draw_here(scene, target, view),
        }
        self.renderer.frame_took(start.elapsed());
    }

    /// [`SceneFrame::draw`] on the calling thread.
    fn draw_here(&mut self, scene: &Scene, target: Target, view: &SceneView) {
        let start = Instant::now();
        let plan = &scene.plan;
        let side = grid_side(plan.samples);
        let fine = Target::new(target.width * side, target.height * side);
        let (cam, turn) = view_of(scene, view);
        let cam = &cam;
        let eye = cam.eye;
        let view_proj = cam.projection(fine.width, fine.height, view.pixel_aspect) * cam.view();
        let forward = (cam.target - eye).normalize_or_zero();
        let model = |o: &SceneObject| {
            let m = o.desc.model_matrix(view.time);
            turn.map_or(m, |t| t * m)
        };
        // Depth shading spans the objects' bounding spheres along the view.
        let depth_range = scene
            .objects
            .iter()
            .map(|o| {
                let c = model(o).transform_point3(Vec3::ZERO);
                let r = o.desc.scale * 3f32.sqrt();
                let d = (c - eye).dot(forward);
                (d - r, d + r)
            })
            .fold((f32::INFINITY, f32::NEG_INFINITY), |a, b| {
                (a.0.min(b.0), a.1.max(b.1))
            });
        let depth_range = if depth_range.0.is_finite() {
            (
                depth_range.0.max(cam.near),
                depth_range.1.max(cam.near + 1e-3),
            )
        } else {
            (cam.near, cam.far)
        };
        let base = self.base_options();
        let ctx = FrameCtx {
            view_proj,
            eye,
            forward,
            lights: &scene.lights,
            depth_range,
            time: view.time,
            turn,
        };
        self.ctx = Some(ctx.without_lights());
        let color = if side > 1 {
            &mut self.fine
        } else {
            &mut self.color
        };
        self.renderer
            .begin_frame_deferred(fine, color, scene.background, plan.depth_buffer);
        let mut stats = DrawStats::default();
        let mut vertex = Duration::ZERO;
        for ((obj, op), pipe) in scene
            .objects
            .iter()
            .zip(&plan.objects)
            .zip(&mut self.pipelines)
        {
            let opts = draw_options(op, base);
            vertex += pipe.draw(obj, op, ctx, &opts, &mut self.renderer, color);
            stats += self.renderer.stats;
            self.renderer.stats = DrawStats::default();
        }
        self.renderer.finish_clear(color);
        self.wire = WireCount::default();
        for ((obj, op), pipe) in scene.objects.iter().zip(&plan.objects).zip(&self.pipelines) {
            if op.wireframe {
                let depth = op.hidden_lines.then_some(&self.renderer.depth);
                self.wire += pipe.wireframe(obj, fine, depth, color);
            }
        }
        self.silhouettes.clear();
        for ((obj, op), pipe) in scene.objects.iter().zip(&plan.objects).zip(&self.pipelines) {
            if op.silhouette {
                let depth = op.writes_depth().then_some((&self.renderer.depth, side));
                pipe.silhouettes(obj, target, depth, &mut self.silhouettes);
            }
        }
        if side > 1 {
            resolve(
                &self.fine,
                fine,
                side,
                &mut self.color,
                target,
                scene.background,
            );
        }
        self.stats = stats;
        self.timing = [vertex, start.elapsed().saturating_sub(vertex)];
    }

    /// Probes pixel `(x, y)` of the last frame's (supersampled) target for every
    /// object in draw order, the depth carried from one object to the next; each
    /// record carries the colour its fragment was shaded, if it passed. Empty before
    /// the first frame.
    #[must_use]
    pub fn probe(&self, scene: &Scene, x: u32, y: u32) -> Vec<ShadedProbe> {
        let Some(ctx) = self.ctx else {
            return Vec::new();
        };
        let ctx = FrameCtx {
            lights: &scene.lights,
            ..ctx
        };
        let mut stored = crate::raster::depth::DEPTH_CLEAR;
        let mut out = Vec::new();
        for ((obj, op), pipe) in scene
            .objects
            .iter()
            .zip(&scene.plan.objects)
            .zip(&self.pipelines)
        {
            let opts = self.draw_options(op);
            let p = pipe.probe(obj, op, ctx, &opts, self.renderer.target, (x, y), stored);
            stored = p.final_depth;
            out.push(p);
        }
        out
    }

    /// Every drawn wireframe line through pixel `(x, y)` of the last frame's
    /// (supersampled) target, by object, tested as it was drawn.
    #[must_use]
    pub fn probe_lines(&self, scene: &Scene, x: u32, y: u32) -> Vec<(usize, LineHit)> {
        let depth = self.renderer.has_depth().then_some(&self.renderer.depth);
        let mut out = Vec::new();
        for (i, ((obj, op), pipe)) in scene
            .objects
            .iter()
            .zip(&scene.plan.objects)
            .zip(&self.pipelines)
            .enumerate()
        {
            if op.wireframe {
                let depth = depth.filter(|_| op.hidden_lines);
                let hits = pipe.probe_lines(obj, self.renderer.target, depth, x, y);
                out.extend(hits.into_iter().map(|h| (i, h)));
            }
        }
        out
    }

    /// The line under pixel `(x, y)` of the frame's (supersampled) target: of the
    /// object seen there, a drawn wireframe line through the pixel or the nearest edge
    /// of its triangle. Returns the object's index, the edge, its screen line and step.
    #[must_use]
    pub fn line_under(
        &self,
        scene: &Scene,
        x: u32,
        y: u32,
    ) -> Option<(usize, [u32; 2], ScreenLine, i64)> {
        let probes = self.probe(scene, x, y);
        let seen = probes.iter().rposition(|p| p.winner.is_some());
        let depth = self.renderer.has_depth().then_some(&self.renderer.depth);
        // The object seen there first; else any drawn wireframe through the pixel.
        let order = seen.into_iter().chain(
            (0..scene.objects.len())
                .filter(|&i| Some(i) != seen && scene.plan.objects[i].wireframe),
        );
        for i in order {
            let op = &scene.plan.objects[i];
            // No probes before the first frame.
            let triangle = probes
                .get(i)
                .and_then(|p| p.winner.map(|w| p.records[w].triangle));
            let wires = op.wireframe.then(|| depth.filter(|_| op.hidden_lines));
            let found = self.pipelines[i].line_under(
                &scene.objects[i],
                wires,
                triangle,
                self.renderer.target,
                x,
                y,
            );
            if let Some((e, sl, k)) = found {
                return Some((i, e, sl, k));
            }
        }
        None
    }

    /// Edge `edge` of object `object` projected to the frame's (supersampled) target.
    #[must_use]
    pub fn project_edge(&self, object: usize, edge: [u32; 2]) -> Option<ScreenLine> {
        self.pipelines
            .get(object)?
            .project_edge(edge, self.renderer.target)
    }
}

/// The camera of a frame, and the turntable's rotation of the objects if the scene
/// is on one.
fn view_of(scene: &Scene, view: &SceneView) -> (Camera, Option<Mat4>) {
    let cam = &scene.camera;
    match scene.rig {
        Rig::Orbit => {
            let orbit = Mat3::from_rotation_y(view.yaw) * Mat3::from_rotation_x(view.pitch);
            let eye = cam.target + orbit * (cam.eye - cam.target) / view.zoom.max(0.05);
            let camera = Camera {
                eye,
                up: orbit * cam.up,
                ..*cam
            };
            (camera, None)
        }
        Rig::Turntable { framing } => {
            let camera = framing.map_or(*cam, |r| Camera::framing(r, view.zoom));
            let turn = Mat4::from_rotation_x(view.pitch) * Mat4::from_rotation_y(view.yaw);
            (camera, Some(turn))
        }
    }
}

/// Averages `side × side` blocks of `fine` into `out`: colour is the mean of the
/// covered samples blended with the background by coverage, alpha is the coverage.
fn resolve(fine: &Rgba8, ft: Target, side: u32, out: &mut Rgba8, target: Target, background: Vec3) {
    let n = side * side;
    let bg = background
        .to_array()
        .map(|c| (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u32);
    crate::memory::refill(&mut out.0, target.len(), [0; 4]);
    counters::add(Stage::Resolves, target.len() as u64);
    for y in 0..target.height {
        for x in 0..target.width {
            let mut sum = [0u32; 3];
            let mut covered = 0u32;
            for j in 0..side {
                let row = ((y * side + j) * ft.width + x * side) as usize;
                for p in &fine.0[row..row + side as usize] {
                    if p[3] == 255 {
                        covered += 1;
                        for c in 0..3 {
                            sum[c] += u32::from(p[c]);
                        }
                    }
                }
            }
            let px = &mut out.0[(y * target.width + x) as usize];
            for c in 0..3 {
                // Covered samples carry their colour, the others the background.
                px[c] = ((sum[c] + bg[c] * (n - covered) + n / 2) / n) as u8;
            }
            px[3] = ((covered * 255 + n / 2) / n) as u8;
        }
    }
}

/// What tells frames of one amount of work apart for the renderer's measured choice
/// ([`Renderer::plan_frame`]): the interpolation and traversal, and what each object
/// draws (triangles, edges) and culls (the viewer's `w` and `b`).
fn draw_kind(scene: &Scene, interpolation: Interpolation, traversal: Traversal) -> u64 {
    let mut h = DefaultHasher::new();
    (interpolation, traversal).hash(&mut h);
    for o in &scene.objects {
        let e = &o.desc.effects;
        (e.fill, e.wireframe, e.cull).hash(&mut h);
    }
    h.finish()
}

#[cfg(test)]
mod tests {
    use super::draw_kind;
    use crate::raster::Traversal;
    use crate::raster::interp::Interpolation;
    use crate::scene::{Mode, Scene};

    /// Frames drawn differently have different kinds, so the measured choice starts
    /// over when the viewer's `w` or `b` changes them; the same drawing keeps its kind.
    #[test]
    fn a_change_in_drawing_changes_the_kind() {
        let mut scene = Scene::standard("teapot").expect("the built-in teapot");
        let wide = |scene: &Scene| draw_kind(scene, Interpolation::Perspective, Traversal::Wide);
        let fill = wide(&scene);
        assert_eq!(wide(&scene), fill);
        let mut kinds = vec![fill];
        for mode in [Mode::Wire, Mode::FillWire] {
            scene.set_mode(mode);
            kinds.push(wide(&scene));
        }
        scene.set_mode(Mode::Fill);
        assert_eq!(wide(&scene), fill, "back to triangles");
        scene.set_cull(true);
        kinds.push(wide(&scene));
        scene.set_cull(false);
        kinds.push(draw_kind(
            &scene,
            Interpolation::Perspective,
            Traversal::Scalar,
        ));
        kinds.push(draw_kind(&scene, Interpolation::Affine, Traversal::Wide));
        let mut distinct = kinds.clone();
        distinct.sort_unstable();
        distinct.dedup();
        assert_eq!(distinct.len(), kinds.len(), "{kinds:?}");
    }
}

//! Rendering a scene by its plan.
//!
//! An object's varyings are the attributes its plan needs ([`VaryingSet`]: normal,
//! world position, colour, uv), packed into an array of floats by a [`Layout`]
//! chosen when the scene is loaded. An attribute the plan leaves out is neither
//! computed in the vertex stage nor read by the fragment stage. The draw loop is
//! compiled for a few array widths ([`PACKED_WIDTHS`]), not for every attribute set,
//! which keeps the build small. The choice is made once per object (a trait object
//! per object, called once per frame); nothing is dispatched per vertex or pixel.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

use super::file::{LightKind, Lighting};
use super::plan::{ObjectPlan, VaryingSet};
use super::{LightDesc, Scene, SceneObject};
use crate::counters::{self, Stage};
use crate::raster::Target;
use crate::raster::depth::{DepthBuffer, DepthState};
use crate::raster::samples::grid_side;
use crate::render::probe::{Probe, probe_from};
use crate::render::standard::WIRE_COLOR;
use crate::render::wire::{
    ScreenLine, WIRE_DEPTH_BIAS, WireCount, draw_wireframe, line_under, project_edge,
};
use crate::render::{
    Cull, DrawOptions, DrawStats, Renderer, Rgba8, Shader, VertexCache, ndc_to_screen, transform,
};

/// Where an object's attributes sit in its packed varyings: the offset of each one
/// its plan interpolates ([`VaryingSet`]), in floats.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Layout {
    pub normal: Option<usize>,
    pub position: Option<usize>,
    pub color: Option<usize>,
    pub uv: Option<usize>,
    /// Floats in use.
    pub len: usize,
}

impl Layout {
    /// The attributes of `v`, packed in the order normal, position, colour, uv.
    #[must_use]
    pub fn new(v: VaryingSet) -> Self {
        let mut len = 0;
        let mut place = |on: bool, floats: usize| {
            on.then(|| {
                len += floats;
                len - floats
            })
        };
        let normal = place(v.normal, 3);
        let position = place(v.position, 3);
        let color = place(v.color, 3);
        let uv = place(v.uv, 2);
        Self {
            normal,
            position,
            color,
            uv,
            len,
        }
    }
}

/// The widths (floats) the pipelines are compiled for; an object takes the narrowest
/// that holds its layout. Four widths instead of one pipeline per attribute set keep
/// the build small, at the cost of at most three unused floats interpolated.
pub const PACKED_WIDTHS: [usize; 4] = [0, 4, 8, 12];

#[inline(always)]
fn get3<const K: usize>(v: &[f32; K], at: Option<usize>) -> Option<Vec3> {
    let s = v.get(at?..at? + 3)?;
    Some(Vec3::new(s[0], s[1], s[2]))
}

#[inline(always)]
fn get2<const K: usize>(v: &[f32; K], at: Option<usize>) -> Option<Vec2> {
    let s = v.get(at?..at? + 2)?;
    Some(Vec2::new(s[0], s[1]))
}

#[inline(always)]
fn put<const K: usize>(v: &mut [f32; K], at: Option<usize>, x: &[f32]) {
    if let Some(s) = at.and_then(|o| v.get_mut(o..o + x.len())) {
        s.copy_from_slice(x);
    }
}

/// What every object of a frame shares.
#[derive(Clone, Copy, Debug)]
pub struct FrameCtx<'a> {
    pub view_proj: Mat4,
    pub eye: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    pub lights: &'a [LightDesc],
    /// View depths mapped to bright and dark by depth shading.
    pub depth_range: (f32, f32),
    pub time: f32,
}

/// The shader of one object, its varyings packed in `K` floats by [`Layout`].
pub struct ObjectShader<'a, const K: usize> {
    pub obj: &'a SceneObject,
    pub plan: &'a ObjectPlan,
    pub ctx: FrameCtx<'a>,
    pub model: Mat4,
    pub normal_matrix: Mat3,
    pub mvp: Mat4,
    pub layout: Layout,
}

impl<'a, const K: usize> ObjectShader<'a, K> {
    /// The shader for an object at this frame.
    #[must_use]
    pub fn new(obj: &'a SceneObject, plan: &'a ObjectPlan, ctx: FrameCtx<'a>) -> Self {
        let model = obj.desc.model_matrix(ctx.time);
        let layout = Layout::new(plan.varyings);
        debug_assert!(layout.len <= K);
        Self {
            obj,
            plan,
            ctx,
            model,
            normal_matrix: Mat3::from_mat4(model).inverse().transpose(),
            mvp: ctx.view_proj * model,
            layout,
        }
    }

    /// Diffuse (and, with `specular`, Blinn–Phong) light at a point, times `base`.
    fn light(&self, normal: Vec3, at: Vec3, specular: bool, base: Vec3) -> Vec3 {
        counters::add(Stage::Lighting, 1);
        let m = &self.obj.desc.material;
        let n = normal.normalize_or_zero();
        let view = (self.ctx.eye - at).normalize_or_zero();
        let (mut diffuse, mut spec) = (Vec3::ZERO, Vec3::ZERO);
        for l in self.ctx.lights {
            let (dir, power) = match l.kind {
                LightKind::Ambient => {
                    diffuse += l.color;
                    continue;
                }
                LightKind::Directional => (l.vector, l.color),
                LightKind::Point => {
                    let d = l.vector - at;
                    (d.normalize_or_zero(), l.color / (1.0 + d.length_squared()))
                }
            };
            let ndl = n.dot(dir);
            if ndl > 0.0 {
                diffuse += power * ndl;
                if specular {
                    let h = (dir + view).normalize_or_zero();
                    spec += power * m.specular * n.dot(h).max(0.0).powf(m.shininess);
                }
            }
        }
        base * diffuse + spec
    }

    fn view_depth(&self, world: Vec3) -> f32 {
        (world - self.ctx.eye).dot(self.ctx.forward)
    }
}

impl<const K: usize> Shader for ObjectShader<'_, K> {
    type Varying = [f32; K];

    fn vertex(&self, index: u32) -> (Vec4, Self::Varying) {
        let i = index as usize;
        let mesh = &self.obj.mesh;
        let p = mesh.positions.get(i).copied().unwrap_or(Vec3::ZERO);
        let plan = self.plan;
        let layout = self.layout;
        let mut out = [0.0; K];
        let world = if plan.world_positions {
            counters::add(Stage::PositionsToWorld, 1);
            self.model.transform_point3(p)
        } else {
            Vec3::ZERO
        };
        let normal = if plan.normals {
            counters::add(Stage::NormalsTransformed, 1);
            let n = mesh.normals.get(i).copied().unwrap_or(Vec3::Z);
            (self.normal_matrix * n).normalize_or_zero()
        } else {
            Vec3::ZERO
        };
        put(&mut out, layout.normal, &normal.to_array());
        put(&mut out, layout.position, &world.to_array());
        if layout.color.is_some() {
            let mut c = Vec3::ONE;
            if plan.vertex_colors {
                counters::add(Stage::VertexColors, 1);
                c *= mesh.colors.get(i).copied().unwrap_or(Vec3::ONE);
            }
            if self.obj.desc.material.lighting.per_vertex() && !plan.depth_shading {
                // Flat: lit at the face centre, so all three corners agree.
                let at = match self.obj.face_centres.get(i) {
                    Some(c) if plan.unweld => self.model.transform_point3(*c),
                    _ => world,
                };
                c = self.light(normal, at, false, c);
            }
            put(&mut out, layout.color, &c.to_array());
        }
        if layout.uv.is_some() {
            counters::add(Stage::Uvs, 1);
            let uv = mesh.uvs.get(i).copied().unwrap_or(Vec2::ZERO);
            put(&mut out, layout.uv, &uv.to_array());
        }
        (self.mvp * p.extend(1.0), out)
    }

    fn fragment(&self, v: &Self::Varying) -> Vec3 {
        let plan = self.plan;
        let layout = self.layout;
        let world = get3(v, layout.position).unwrap_or(Vec3::ZERO);
        if plan.depth_shading {
            counters::add(Stage::DepthShading, 1);
            let (near, far) = self.ctx.depth_range;
            let t = ((self.view_depth(world) - near) / (far - near).max(1e-6)).clamp(0.0, 1.0);
            return Vec3::splat(1.0 - 0.85 * t);
        }
        let m = &self.obj.desc.material;
        let mut color = m.color;
        if let Some(c) = get3(v, layout.color) {
            color *= c;
        }
        if let (Some(uv), Some(t)) = (get2(v, layout.uv), &self.obj.texture) {
            color *= t.sample(uv, plan.texture);
        }
        if let Some(n) = get3(v, layout.normal) {
            color = self.light(n, world, m.lighting == Lighting::BlinnPhong, color);
        }
        if let Some(fog) = self.obj.desc.effects.fog {
            counters::add(Stage::Fog, 1);
            let d = self.view_depth(world);
            let t = ((fog.end - d) / (fog.end - fog.start)).clamp(0.0, 1.0);
            color = Vec3::from(fog.color).lerp(color, t);
        }
        color
    }
}

/// A silhouette edge on screen, in sample coordinates (pixel centres at +0.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Silhouette {
    pub a: Vec2,
    pub b: Vec2,
}

/// One object's pipeline: its monomorphized shader and its vertex cache.
pub trait ObjectPipeline {
    /// Transforms and draws the object.
    fn draw(
        &mut self,
        obj: &SceneObject,
        plan: &ObjectPlan,
        ctx: FrameCtx<'_>,
        r: &mut Renderer,
        color: &mut Rgba8,
    );
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
    /// The raster state of a pixel for this object, continuing from `stored` depth.
    fn probe(
        &self,
        obj: &SceneObject,
        plan: &ObjectPlan,
        target: Target,
        x: u32,
        y: u32,
        stored: f32,
    ) -> Probe<()>;
    /// The varying set this pipeline was compiled for.
    fn varyings(&self) -> VaryingSet;
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

/// The draw options an object's plan asks for.
#[must_use]
pub fn draw_options(plan: &ObjectPlan) -> DrawOptions {
    DrawOptions {
        depth: if plan.depth_test {
            DepthState::default()
        } else {
            DepthState::OFF
        },
        cull: if plan.cull { Cull::Back } else { Cull::None },
        ..DrawOptions::default()
    }
}

/// The pipeline of objects whose varyings fit `K` floats.
struct Pipeline<const K: usize> {
    cache: VertexCache<[f32; K]>,
    varyings: VaryingSet,
}

impl<const K: usize> ObjectPipeline for Pipeline<K> {
    fn draw(
        &mut self,
        obj: &SceneObject,
        plan: &ObjectPlan,
        ctx: FrameCtx<'_>,
        r: &mut Renderer,
        color: &mut Rgba8,
    ) {
        let shader = ObjectShader::<K>::new(obj, plan, ctx);
        transform(&shader, obj.mesh.positions.len(), &mut self.cache);
        r.draw(
            &shader,
            &self.cache,
            &obj.mesh.indices,
            &draw_options(plan),
            color,
        );
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
        target: Target,
        x: u32,
        y: u32,
        stored: f32,
    ) -> Probe<()> {
        // The trait object cannot return this pipeline's varying type: the records keep
        // everything else.
        let p = probe_from(
            &self.cache,
            &obj.mesh.indices,
            target,
            &draw_options(plan),
            x,
            y,
            stored,
        );
        Probe {
            x: p.x,
            y: p.y,
            records: p.records.into_iter().map(|r| r.map(|_| ())).collect(),
            winner: p.winner,
            final_depth: p.final_depth,
        }
    }

    fn varyings(&self) -> VaryingSet {
        self.varyings
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

/// The pipeline for a varying set: the narrowest of [`PACKED_WIDTHS`] that holds it.
#[must_use]
pub fn pipeline_for(varyings: VaryingSet) -> Box<dyn ObjectPipeline> {
    fn new<const K: usize>(varyings: VaryingSet) -> Box<dyn ObjectPipeline> {
        Box::new(Pipeline::<K> {
            cache: VertexCache::default(),
            varyings,
        })
    }
    match Layout::new(varyings).len {
        0 => new::<0>(varyings),
        1..=4 => new::<4>(varyings),
        5..=8 => new::<8>(varyings),
        _ => new::<12>(varyings),
    }
}

/// Where a scene is seen from in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneView {
    /// Seconds since the start (spins).
    pub time: f32,
    /// Orbit of the camera about its target: radians about y, then about x.
    pub yaw: f32,
    pub pitch: f32,
    /// Camera distance divisor (1 = as in the file).
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
    pipelines: Vec<Box<dyn ObjectPipeline>>,
    pub silhouettes: Vec<Silhouette>,
    /// Counters of the last frame, all objects.
    pub stats: DrawStats,
    pub wire: WireCount,
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
                .plan
                .objects
                .iter()
                .map(|o| pipeline_for(o.varyings))
                .collect(),
            silhouettes: Vec::new(),
            stats: DrawStats::default(),
            wire: WireCount::default(),
        }
    }

    /// The varying sets the pipelines were compiled for, per object.
    #[must_use]
    pub fn varyings(&self) -> Vec<VaryingSet> {
        self.pipelines.iter().map(|p| p.varyings()).collect()
    }

    /// Draws a frame of `target` samples.
    pub fn draw(&mut self, scene: &Scene, target: Target, view: &SceneView) {
        let plan = &scene.plan;
        let side = grid_side(plan.samples);
        let fine = Target::new(target.width * side, target.height * side);
        let cam = &scene.camera;
        let orbit = Mat3::from_rotation_y(view.yaw) * Mat3::from_rotation_x(view.pitch);
        let eye = cam.target + orbit * (cam.eye - cam.target) / view.zoom.max(0.05);
        let camera = crate::camera::Camera {
            eye,
            up: orbit * cam.up,
            ..*cam
        };
        let view_proj =
            camera.projection(fine.width, fine.height, view.pixel_aspect) * camera.view();
        let forward = (cam.target - eye).normalize_or_zero();
        // Depth shading spans the objects' bounding spheres along the view.
        let depth_range = scene
            .objects
            .iter()
            .map(|o| {
                let c = o.desc.model_matrix(view.time).transform_point3(Vec3::ZERO);
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
        let ctx = FrameCtx {
            view_proj,
            eye,
            forward,
            lights: &scene.lights,
            depth_range,
            time: view.time,
        };
        let color = if side > 1 {
            &mut self.fine
        } else {
            &mut self.color
        };
        self.renderer
            .begin_frame_with(fine, color, scene.background, plan.depth_buffer);
        let mut stats = DrawStats::default();
        for ((obj, op), pipe) in scene
            .objects
            .iter()
            .zip(&plan.objects)
            .zip(&mut self.pipelines)
        {
            pipe.draw(obj, op, ctx, &mut self.renderer, color);
            stats += self.renderer.stats;
            self.renderer.stats = DrawStats::default();
        }
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
                let depth = op.depth_test.then_some((&self.renderer.depth, side));
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
    }

    /// Probes sample `(x, y)` of the last frame (without supersampling) for every
    /// object in draw order, the depth carried from one object to the next.
    #[must_use]
    pub fn probe(&self, scene: &Scene, x: u32, y: u32) -> Vec<Probe<()>> {
        let mut stored = crate::raster::depth::DEPTH_CLEAR;
        let mut out = Vec::new();
        for ((obj, op), pipe) in scene
            .objects
            .iter()
            .zip(&scene.plan.objects)
            .zip(&self.pipelines)
        {
            let p = pipe.probe(obj, op, self.renderer.target, x, y, stored);
            stored = p.final_depth;
            out.push(p);
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
            let triangle = probes[i].winner.map(|w| probes[i].records[w].triangle);
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

/// Averages `side × side` blocks of `fine` into `out`: colour is the mean of the
/// covered samples blended with the background by coverage, alpha is the coverage.
fn resolve(fine: &Rgba8, ft: Target, side: u32, out: &mut Rgba8, target: Target, background: Vec3) {
    let n = side * side;
    let bg = background
        .to_array()
        .map(|c| (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u32);
    out.0.clear();
    out.0.resize(target.len(), [0; 4]);
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

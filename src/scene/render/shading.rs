//! An object's packed varyings ([`Layout`]) and its shader: the vertex stage fills
//! only the attributes the plan interpolates, the fragment stage lights, textures and
//! fogs them as the plan says.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

use crate::counters::{self, Stage};
use crate::render::Shader;
use crate::scene::file::{LightKind, Lighting};
use crate::scene::plan::{ObjectPlan, VaryingSet};
use crate::scene::{LightDesc, SceneObject};

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
    /// The turntable's rotation of every object ([`Rig::Turntable`](crate::scene::Rig::Turntable)), if any.
    pub turn: Option<Mat4>,
}

impl FrameCtx<'_> {
    /// An object's model matrix in this frame: its own at the frame's time, turned on
    /// the turntable.
    #[must_use]
    pub fn model(&self, obj: &SceneObject) -> Mat4 {
        let m = obj.desc.model_matrix(self.time);
        self.turn.map_or(m, |t| t * m)
    }

    /// The same context without its lights, to keep past the frame (the probe gives
    /// them back).
    #[must_use]
    pub fn without_lights(&self) -> FrameCtx<'static> {
        FrameCtx {
            view_proj: self.view_proj,
            eye: self.eye,
            forward: self.forward,
            lights: &[],
            depth_range: self.depth_range,
            time: self.time,
            turn: self.turn,
        }
    }
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
        let model = ctx.model(obj);
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

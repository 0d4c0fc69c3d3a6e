//! Scenes: TOML files that declare objects, their materials and effects, lights and
//! a camera; and a renderer that does only the work those effects call for.
//!
//! # The file
//!
//! The minimal scene is one `[[object]]` with `model = "teapot"` (or `bunny`,
//! `sphere:N`, or a model file relative to the scene file). Every other key has a
//! default and every effect is off: such a scene is the model's silhouette in flat
//! white, drawn in order without a depth buffer. See `examples/scenes/` for the rest:
//!
//! ```toml
//! [render]                 # antialias = 1 | 4 | 16, background = [r, g, b]
//! [camera]                 # eye, target, up, fov (degrees), near, far
//! [[light]]                # kind = "ambient" | "directional" | "point",
//!                          # color, intensity, direction (towards the light), position
//! [[object]]
//! model = "teapot"
//! position = [0, 0, 0]     # and rotation (degrees about x, y, z), scale
//! spin = { axis = [0, 1, 0], speed = 0.5 }          # radians per second
//! [object.material]        # color, lighting = "none" | "flat" | "gouraud" |
//!                          # "lambert" | "blinn-phong", specular, shininess,
//!                          # vertex_colors, texture = "off" | "nearest" | "bilinear",
//!                          # image (a PNG instead of the OBJ material's map_Kd),
//!                          # from_model (the model file's materials, too)
//! [object.effects]         # depth_test, cull, fog = { start, end, color },
//!                          # depth_shading, wireframe, silhouette
//! ```
//!
//! A lit object in a scene without `[[light]]` gets the standard lights: ambient 0.08
//! and a directional light towards (0.4, 0.6, 1.0). Point lights fall off as
//! `1 / (1 + d²)`.
//!
//! # The plan
//!
//! [`plan::Plan`] decides from the scene alone which attributes are kept and
//! transformed, which varyings each object interpolates, which buffers exist and
//! which per-pixel stages run; [`render::SceneFrame`] follows it. Loading already
//! applies it: attributes no stage reads are dropped from the mesh, normals are only
//! generated when lighting needs them, edges only computed for wireframes and
//! silhouettes.

pub mod file;
mod load;
pub use load::MAX_SCENE_TRIANGLES;
pub mod plan;
pub mod render;
pub mod texture;
mod topology;

use std::path::{Path, PathBuf};

use glam::{EulerRot, Mat4, Quat, Vec3};

use self::file::{EffectsFile, LightKind, Lighting, MaterialFile, TextureMode};
use self::plan::Plan;
use self::texture::Texture;
use self::topology::Topology;
use crate::camera::Camera;
use crate::mesh::{Mesh, MeshError};
use crate::render::wire::Mode;

/// `image = "checker"`: a built-in checkerboard texture instead of a file.
pub const BUILTIN_CHECKER: &str = "checker";

/// Why a scene could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}{}: {problem}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Invalid {
        path: PathBuf,
        line: Option<usize>,
        problem: String,
    },
    /// A model's own error, for its default scene (which adds nothing to say).
    #[error(transparent)]
    Mesh(#[from] MeshError),
    #[error("{scene}: object {object}: {source}")]
    Model {
        scene: PathBuf,
        object: usize,
        source: MeshError,
    },
    #[error("{scene}: object {object} ({model}): {problem}")]
    Unsupported {
        scene: PathBuf,
        object: usize,
        model: String,
        problem: String,
    },
    #[error("texture {path}: {problem}")]
    Texture { path: PathBuf, problem: String },
}

/// A light, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightDesc {
    pub kind: LightKind,
    /// Colour times intensity.
    pub color: Vec3,
    /// Directional: unit vector towards the light. Point: its position.
    pub vector: Vec3,
}

/// An object as the scene file describes it.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectDesc {
    /// The model as the scene file names it.
    pub name: String,
    /// The model spec as resolved (built-in name or path).
    pub model: String,
    pub position: Vec3,
    pub rotation: Quat,
    pub scale: f32,
    /// Unit axis and radians per second.
    pub spin: Option<(Vec3, f32)>,
    pub material: Material,
    pub effects: EffectsFile,
}

impl ObjectDesc {
    /// Model matrix at time `t` seconds: scale, rotate, spin, translate.
    #[must_use]
    pub fn model_matrix(&self, t: f32) -> Mat4 {
        let spin = self.spin.map_or(Quat::IDENTITY, |(axis, speed)| {
            Quat::from_axis_angle(axis, speed * t)
        });
        Mat4::from_scale_rotation_translation(
            Vec3::splat(self.scale),
            spin * self.rotation,
            self.position,
        )
    }
}

/// An object's material.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub color: Vec3,
    pub lighting: Lighting,
    pub specular: f32,
    pub shininess: f32,
    pub vertex_colors: bool,
    pub texture: TextureMode,
    /// A texture image given in the scene (else the model's map_Kd); a path ending
    /// in [`BUILTIN_CHECKER`] with no extension is the built-in checkerboard.
    pub image: Option<PathBuf>,
    /// Take the model file's own materials too: its diffuse colours (one object per
    /// material), textures and vertex colours (a model's default scene does).
    pub from_model: bool,
}

impl From<(&MaterialFile, &Path)> for Material {
    fn from((m, scene): (&MaterialFile, &Path)) -> Self {
        Self {
            color: Vec3::from(m.color),
            lighting: m.lighting,
            specular: m.specular,
            shininess: m.shininess,
            vertex_colors: m.vertex_colors,
            texture: m.texture,
            image: m.image.as_deref().map(|i| file::relative(i, scene)),
            from_model: m.from_model,
        }
    }
}

/// An object ready to draw: its mesh holds only what the plan uses.
#[derive(Clone, Debug)]
pub struct SceneObject {
    pub desc: ObjectDesc,
    /// Shared by the scene's clones (each viewer of `termrast serve` has one).
    pub mesh: std::sync::Arc<Mesh>,
    /// Unique edges (wireframe and silhouettes), else empty.
    pub edges: Vec<[u32; 2]>,
    /// For each edge, the one or two triangles that share it (silhouettes), else empty.
    pub edge_faces: Vec<[u32; 2]>,
    /// Flat lighting: each vertex's face centre, else empty.
    pub face_centres: Vec<Vec3>,
    pub texture: Option<Texture>,
}

/// How a view's turn and zoom ([`render::SceneView`]) move a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rig {
    /// The camera orbits its target (yaw about y, then pitch about x) and zoom divides
    /// its distance: a scene file's lights stay put in its world.
    Orbit,
    /// The objects turn about the origin (yaw about y, then pitch about x) under the
    /// camera and the lights, as on a turntable: a model's lit side stays towards the
    /// light as it turns.
    Turntable {
        /// Zoom re-frames a sphere of this radius about the origin
        /// ([`Camera::framing`]: the distance and the near and far planes follow it);
        /// `None` keeps the scene's camera at every zoom (the benchmark's fixed view).
        framing: Option<f32>,
    },
}

/// A loaded scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Where it came from (for messages and the status line).
    pub source: String,
    pub camera: Camera,
    pub rig: Rig,
    pub background: Vec3,
    pub lights: Vec<LightDesc>,
    pub objects: Vec<SceneObject>,
    pub plan: Plan,
    /// What the model loaders went past (file and line each), for the user.
    pub warnings: Vec<String>,
}

/// The ambient term of [`standard_lights`] (the lane-code Lambert of the standard
/// plan takes it as its material's).
pub const STANDARD_AMBIENT: f32 = 0.08;

/// The lights a lit object gets when the scene declares none.
#[must_use]
pub fn standard_lights() -> Vec<LightDesc> {
    vec![
        LightDesc {
            kind: LightKind::Ambient,
            color: Vec3::splat(STANDARD_AMBIENT),
            vector: Vec3::ZERO,
        },
        LightDesc {
            kind: LightKind::Directional,
            color: Vec3::splat(0.92),
            vector: crate::render::shaders::standard_light(),
        },
    ]
}

/// Whether a model argument names a scene file rather than a model.
#[must_use]
pub fn is_scene_path(spec: &str) -> bool {
    Path::new(spec)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}

impl Scene {
    /// The default scene of a model (what a model path is shorthand for): the model
    /// with depth test and per-pixel Lambert under the standard lights, its bounding
    /// sphere framed, turning on a turntable, as the viewer and `render` show it.
    pub fn for_model(spec: &str) -> Result<Self, SceneError> {
        let text = format!(
            "[[object]]\nmodel = {}\n[object.material]\nlighting = \"lambert\"\nfrom_model = true\n[object.effects]\ndepth_test = true\n",
            toml::Value::String(spec.to_string())
        );
        let mut scene =
            Self::from_text(&text, Path::new("default scene")).map_err(|e| match e {
                SceneError::Model { source, .. } => SceneError::Mesh(source),
                e => e,
            })?;
        scene.source = format!("{spec} (default scene)");
        let radius = scene
            .objects
            .iter()
            .map(|o| o.mesh.bounding_radius())
            .fold(0.0, f32::max);
        scene.rig = Rig::Turntable {
            framing: Some(radius),
        };
        Ok(scene)
    }

    /// The benchmark's scene: a model's default scene seen from the standard camera
    /// ([`Camera::default`]) whatever the model's size, so that figures of one model
    /// stay comparable from run to run.
    pub fn standard(spec: &str) -> Result<Self, SceneError> {
        let mut scene = Self::for_model(spec)?;
        scene.camera = Camera::default();
        scene.rig = Rig::Turntable { framing: None };
        Ok(scene)
    }

    /// Whether this is a model's default scene rather than a scene file's.
    #[must_use]
    pub fn is_model(&self) -> bool {
        matches!(self.rig, Rig::Turntable { .. })
    }

    /// How every object is drawn, if they agree: filled, as edges, or both.
    #[must_use]
    pub fn mode(&self) -> Option<Mode> {
        let mode = |e: &EffectsFile| match (e.fill, e.wireframe) {
            (true, false) => Some(Mode::Fill),
            (false, true) => Some(Mode::Wire),
            (true, true) => Some(Mode::FillWire),
            (false, false) => None,
        };
        let first = mode(&self.objects.first()?.desc.effects)?;
        self.objects
            .iter()
            .all(|o| mode(&o.desc.effects) == Some(first))
            .then_some(first)
    }

    /// Draws every object in `mode` (the viewer's `w`, `--mode`): its triangles, its
    /// edges (hidden lines removed where it tests depth), or both; and plans again.
    pub fn set_mode(&mut self, mode: Mode) {
        for o in &mut self.objects {
            o.desc.effects.fill = mode.fills();
            o.desc.effects.wireframe = mode.wires();
        }
        self.replan();
    }

    /// Whether every object culls back faces (`Some(false)`: none does).
    #[must_use]
    pub fn cull(&self) -> Option<bool> {
        let first = self.objects.first()?.desc.effects.cull;
        self.objects
            .iter()
            .all(|o| o.desc.effects.cull == first)
            .then_some(first)
    }

    /// Culls back faces of every object or of none (the viewer's `b`, `--cull`), and
    /// plans again.
    pub fn set_cull(&mut self, cull: bool) {
        for o in &mut self.objects {
            o.desc.effects.cull = cull;
        }
        self.replan();
    }

    /// Draws every object in its material's colour alone, without its model's vertex
    /// colours (`bench render --no-vertex-colors`), and plans again. The colours are
    /// dropped from the mesh too, as loading drops them for a material without them:
    /// a mesh holds exactly the attributes its plan transforms. Before any frame is
    /// made for the scene: its pipelines change.
    pub fn drop_vertex_colors(&mut self) {
        for o in &mut self.objects {
            o.desc.material.vertex_colors = false;
            std::sync::Arc::make_mut(&mut o.mesh).colors = Vec::new();
        }
        self.replan();
    }

    /// The plan again after an effect changed, and the edges of objects that now draw
    /// them. Once frames are made for the scene, only effects drawn outside the shader
    /// may change (fill, wireframe, culling), so the pipelines chosen by the old plan
    /// still fit ([`render::is_standard_lambert`] ignores them) and nothing loaded is
    /// missing but edges.
    fn replan(&mut self) {
        let descs: Vec<ObjectDesc> = self.objects.iter().map(|o| o.desc.clone()).collect();
        self.plan = Plan::new(&descs, &self.lights, self.plan.samples);
        for (o, op) in self.objects.iter_mut().zip(&self.plan.objects) {
            if op.edges && o.edges.is_empty() {
                // From the mesh as drawn: identified by position, its edges are the
                // loaded mesh's (the per-face split moves no vertex).
                o.edges = Topology::of(&o.mesh).drawn_edges(&o.mesh.indices);
            }
        }
    }

    /// Reads and loads a scene file.
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        // Only a regular file, and not without end: a FIFO or a device would hang.
        let bytes = crate::mesh::read::read_regular(path, 16 << 20).map_err(|e| match e {
            MeshError::Io { path, source } => SceneError::Io { path, source },
            e => SceneError::Mesh(e),
        })?;
        let text = String::from_utf8(bytes).map_err(|e| SceneError::Invalid {
            path: path.into(),
            line: None,
            problem: format!(
                "not text (byte {} is not UTF-8)",
                e.utf8_error().valid_up_to()
            ),
        })?;
        Self::from_text(&text, path)
    }

    /// Loads a scene from its text; `path` names it and anchors relative paths.
    pub fn from_text(text: &str, path: &Path) -> Result<Self, SceneError> {
        let f = file::parse(text, path)?;
        let camera = f.camera.as_ref().map(|c| Camera {
            eye: Vec3::from(c.eye),
            target: Vec3::from(c.target),
            up: Vec3::from(c.up),
            fov_y: c.fov.to_radians(),
            near: c.near,
            far: c.far,
        });
        let mut lights: Vec<LightDesc> = f
            .lights
            .iter()
            .map(|l| LightDesc {
                kind: l.kind,
                color: Vec3::from(l.color.unwrap_or([1.0; 3])) * l.intensity.unwrap_or(1.0),
                vector: match l.kind {
                    LightKind::Ambient => Vec3::ZERO,
                    LightKind::Directional => {
                        Vec3::from(l.direction.unwrap_or([0.4, 0.6, 1.0])).normalize()
                    }
                    LightKind::Point => Vec3::from(l.position.unwrap_or([2.0, 2.0, 2.0])),
                },
            })
            .collect();
        let lit = f
            .objects
            .iter()
            .any(|o| o.material.lighting != Lighting::None);
        if lights.is_empty() && lit {
            lights = standard_lights();
        }
        let descs: Vec<ObjectDesc> = f
            .objects
            .iter()
            .map(|o| ObjectDesc {
                name: o.model.clone(),
                model: file::resolve(&o.model, path),
                position: Vec3::from(o.position),
                rotation: {
                    let r = o.rotation.map(f32::to_radians);
                    Quat::from_euler(EulerRot::ZYX, r[2], r[1], r[0])
                },
                scale: o.scale,
                spin: o
                    .spin
                    .as_ref()
                    .map(|s| (Vec3::from(s.axis).normalize(), s.speed)),
                material: Material::from((&o.material, path)),
                effects: o.effects,
            })
            .collect();
        let (parts, warnings) = load::read_models(descs, path)?;
        let part_descs: Vec<ObjectDesc> = parts.iter().map(|p| p.desc.clone()).collect();
        let plan = Plan::new(&part_descs, &lights, f.render.antialias);
        let objects = parts
            .into_iter()
            .zip(&plan.objects)
            .map(|(part, op)| load::load_object(part, op, path))
            .collect::<Result<Vec<_>, _>>()?;
        let camera = camera.unwrap_or_else(|| framing(&objects));
        Ok(Self {
            source: path.display().to_string(),
            camera,
            rig: Rig::Orbit,
            background: Vec3::from(f.render.background),
            lights,
            objects,
            plan,
            warnings,
        })
    }
}

/// The camera for a scene without one: looking down −z at the centre of a sphere that
/// holds every object however it spins, framed by [`Camera::framing`].
fn framing(objects: &[SceneObject]) -> Camera {
    let spheres: Vec<(Vec3, f32)> = objects
        .iter()
        .map(|o| (o.desc.position, o.mesh.bounding_radius() * o.desc.scale))
        .collect();
    let (lo, hi) = spheres.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &(c, r)| (lo.min(c - r), hi.max(c + r)),
    );
    let centre = if lo.is_finite() && hi.is_finite() {
        (lo + hi) * 0.5
    } else {
        Vec3::ZERO
    };
    let radius = spheres
        .iter()
        .map(|&(c, r)| (c - centre).length() + r)
        .fold(0.0, f32::max);
    let mut camera = Camera::framing(radius, 1.0);
    camera.target += centre;
    camera.eye += centre;
    camera
}

//! The standard scene: one model, centred and scaled to max |coordinate| = 1, camera at
//! distance 2.6 on +z, 45°, near 0.1, far 10, turning about y, per-pixel Lambert
//! shading with the light towards (0.4, 0.6, 1.0). The benchmark, `render --out` and
//! the tests all draw it through this one function.

use std::time::Instant;

use glam::{Mat4, Vec3};

use super::shaders::Lambert;
use super::wire::{Mode, WireCount, draw_wireframe, unique_edges};
use super::{ColorTarget, DrawOptions, Renderer, VertexCache, transform};
use crate::camera::Camera;
use crate::mesh::Mesh;
use crate::raster::Target;
use crate::raster::interp::Direction;

/// Rotation per frame of the benchmark, radians about y.
pub const RADIANS_PER_FRAME: f32 = 0.05;

/// Background colour (black).
pub const BACKGROUND: Vec3 = Vec3::ZERO;

/// Where the standard scene is seen from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StandardView {
    pub camera: Camera,
    /// Rotation of the model about y, radians.
    pub angle: f32,
    /// Rotation of the model about x (applied after `angle`), radians.
    pub tilt: f32,
    /// Pixel width over pixel height (1 for images, about 0.5 for terminal cells).
    pub pixel_aspect: f32,
}

impl StandardView {
    /// The standard camera, model turned by `angle`, square pixels: the benchmark's
    /// fixed view, whatever the model's size or the target's aspect.
    #[must_use]
    pub fn at(angle: f32) -> Self {
        Self {
            camera: Camera::default(),
            angle,
            tilt: 0.0,
            pixel_aspect: 1.0,
        }
    }

    /// The view of `model` that frames its bounding sphere (see [`Camera::framing`]),
    /// moved closer by `zoom`.
    #[must_use]
    pub fn framed(model: &Model, zoom: f32, angle: f32) -> Self {
        Self {
            camera: Camera::framing(model.radius, zoom),
            ..Self::at(angle)
        }
    }
}

/// A mesh with its unique edges (for wireframes), computed once.
#[derive(Clone, Debug)]
pub struct Model {
    pub mesh: Mesh,
    pub edges: Vec<[u32; 2]>,
    /// [`Mesh::bounding_radius`], for framing.
    pub radius: f32,
}

impl Model {
    /// Computes the edges and bounding radius of a mesh.
    #[must_use]
    pub fn new(mesh: Mesh) -> Self {
        let edges = unique_edges(&mesh.indices);
        let radius = mesh.bounding_radius();
        Self {
            mesh,
            edges,
            radius,
        }
    }
}

/// Colour of wireframe lines.
pub const WIRE_COLOR: Vec3 = Vec3::new(1.0, 0.75, 0.2);

/// Reusable buffers for drawing the standard scene.
#[derive(Debug)]
pub struct StandardFrame {
    pub renderer: Renderer,
    pub cache: VertexCache<Direction>,
    /// Time of the last frame's vertex stage and of its raster stage (coverage, depth
    /// and shading are one fused loop, so they are timed together).
    pub timing: [std::time::Duration; 2],
}

impl StandardFrame {
    /// Buffers for a target.
    #[must_use]
    pub fn new(target: Target) -> Self {
        Self {
            renderer: Renderer::new(target),
            cache: VertexCache::default(),
            timing: Default::default(),
        }
    }

    /// The shader for the model as seen from `view`.
    #[must_use]
    pub fn shader<'m>(mesh: &'m Mesh, view: &StandardView, target: Target) -> Lambert<'m> {
        let c = &view.camera;
        let view_proj = c.projection(target.width, target.height, view.pixel_aspect) * c.view();
        let model = Mat4::from_rotation_x(view.tilt) * Mat4::from_rotation_y(view.angle);
        Lambert::new(mesh, model, view_proj)
    }

    /// Clears and draws one frame in `mode`. The mesh must have normals. Returns the
    /// wireframe lines and pixels drawn.
    pub fn draw<C: ColorTarget>(
        &mut self,
        model: &Model,
        view: &StandardView,
        target: Target,
        opts: &DrawOptions,
        mode: Mode,
        color: &mut C,
    ) -> WireCount {
        let mesh = &model.mesh;
        let shader = Self::shader(mesh, view, target);
        let start = Instant::now();
        self.renderer.begin_frame(target, color, BACKGROUND);
        transform(&shader, mesh.positions.len(), &mut self.cache);
        let transformed = Instant::now();
        if mode.fills() {
            self.renderer
                .draw(&shader, &self.cache, &mesh.indices, opts, color);
        }
        let wire = if mode.wires() {
            let depth = mode.fills().then_some(&self.renderer.depth);
            draw_wireframe(&self.cache, &model.edges, target, depth, WIRE_COLOR, color)
        } else {
            WireCount::default()
        };
        self.timing = [transformed - start, transformed.elapsed()];
        wire
    }
}

//! The accuracy table's workloads: 2D triangle sets for coverage, and 3D scenes for
//! interpolation and depth, each with an exact reference where one exists.
//!
//! 3D scenes reach the 2D variants through the pipeline itself: a scene is projected
//! and clipped by [`prepare()`], and the unsnapped screen positions of every piece become
//! the 2D workload. Planar scenes carry their plane and texture mapping, so the
//! attribute at any pixel has an analytic value (the ray through the pixel centre,
//! intersected with the plane, in f64).

use glam::{DMat4, DVec3, DVec4, Mat4, Vec2, Vec3, Vec4};

use crate::camera::Camera;
use crate::mesh::Mesh;
use crate::raster::Target;
use crate::render::{DrawOptions, EmitPiece, Prepared, Shader, VertexCache, prepare, transform};
use crate::workload::{Tri2, sliver_fan, tiling, tiny_triangles};

/// Names of the workloads, in table order.
pub const WORKLOADS: [&str; 6] = ["tiny", "large", "slivers", "near-plane", "floor", "bunny"];

/// A 3D scene: a mesh with texture coordinates and a camera.
#[derive(Clone, Debug)]
pub struct Scene3 {
    pub name: &'static str,
    pub positions: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub indices: Vec<u32>,
    pub camera: Camera,
    /// For planar scenes: a point on the plane, its normal, and the world-to-uv map
    /// (`uv = (m · p).xy`), in f64.
    pub plane: Option<(DVec3, DVec3, DMat4)>,
}

impl Scene3 {
    /// View-projection for a target (square pixels).
    #[must_use]
    pub fn view_proj(&self, target: Target) -> Mat4 {
        self.camera.projection(target.width, target.height, 1.0) * self.camera.view()
    }

    /// Where the ray through the centre of pixel `(x, y)` meets the plane, in f64.
    #[must_use]
    pub fn exact_hit(&self, target: Target, x: u32, y: u32) -> Option<DVec3> {
        let inv = self.view_proj(target).as_dmat4().inverse();
        self.hit_with(&inv, target, x, y)
    }

    fn hit_with(&self, inv: &DMat4, target: Target, x: u32, y: u32) -> Option<DVec3> {
        let (point, normal, _) = self.plane?;
        let ndc_x = (f64::from(x) + 0.5) / f64::from(target.width) * 2.0 - 1.0;
        let ndc_y = 1.0 - (f64::from(y) + 0.5) / f64::from(target.height) * 2.0;
        let far = *inv * DVec4::new(ndc_x, ndc_y, 1.0, 1.0);
        let far = (far / far.w).truncate();
        let eye = self.camera.eye.as_dvec3();
        let t = normal.dot(point - eye) / normal.dot(far - eye);
        Some(eye + (far - eye) * t)
    }

    /// [`Scene3::exact_uv`] for many pixels of one target (the inverse projection is
    /// computed once).
    pub fn ray_caster(&self, target: Target) -> impl Fn(u32, u32) -> Option<[f64; 2]> + '_ {
        let inv = self.view_proj(target).as_dmat4().inverse();
        move |x, y| self.uv_at(self.hit_with(&inv, target, x, y)?)
    }

    /// Texture coordinates of a point of the plane.
    #[must_use]
    pub fn uv_at(&self, p: DVec3) -> Option<[f64; 2]> {
        let (_, _, to_uv) = self.plane?;
        let uv = to_uv * p.extend(1.0);
        Some([uv.x, uv.y])
    }

    /// The exact texture coordinates at the centre of pixel `(x, y)`, for planar
    /// scenes.
    #[must_use]
    pub fn exact_uv(&self, target: Target, x: u32, y: u32) -> Option<[f64; 2]> {
        self.uv_at(self.exact_hit(target, x, y)?)
    }
}

/// A plane `y = height` between two corners, as a grid of `nx × nz` quads, with uv =
/// (x, z) / `uv_scale`, banked by `roll` radians about z, then turned by `turn` about
/// y. (A level plane seen by a level camera has constant depth along each screen row,
/// so only a banked one makes depth vary along rows.)
#[allow(clippy::too_many_arguments)]
fn plane_grid(
    name: &'static str,
    (x0, x1): (f32, f32),
    (z0, z1): (f32, f32),
    height: f32,
    (nx, nz): (u32, u32),
    uv_scale: f32,
    roll: f32,
    turn: f32,
) -> Scene3 {
    let rot = Mat4::from_rotation_y(turn) * Mat4::from_rotation_z(roll);
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..=nz {
        for i in 0..=nx {
            let x = x0 + (x1 - x0) * i as f32 / nx as f32;
            let z = z0 + (z1 - z0) * j as f32 / nz as f32;
            positions.push(rot.transform_point3(Vec3::new(x, height, z)));
            uvs.push(Vec2::new(x, z) / uv_scale);
        }
    }
    let mut indices = Vec::new();
    for j in 0..nz {
        for i in 0..nx {
            let at = |i: u32, j: u32| j * (nx + 1) + i;
            indices.extend([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            indices.extend([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    let rot_d = DMat4::from_rotation_y(f64::from(turn)) * DMat4::from_rotation_z(f64::from(roll));
    let to_uv = DMat4::from_cols(
        DVec4::new(1.0, 0.0, 0.0, 0.0),
        DVec4::ZERO,
        DVec4::new(0.0, 1.0, 0.0, 0.0),
        DVec4::ZERO,
    ) * DMat4::from_scale(DVec3::splat(1.0 / f64::from(uv_scale)))
        * rot_d.inverse();
    Scene3 {
        name,
        positions,
        uvs,
        indices,
        camera: Camera::default(),
        plane: Some((
            rot_d.transform_point3(DVec3::new(0.0, f64::from(height), 0.0)),
            rot_d.transform_vector3(DVec3::Y),
            to_uv,
        )),
    }
}

/// A ground plane from behind the eye (z = 6) to z = −20: the triangles under the
/// camera cross the near plane and are clipped.
#[must_use]
pub fn near_plane_scene() -> Scene3 {
    plane_grid(
        "near-plane",
        (-8.0, 8.0),
        (6.0, -20.0),
        -0.5,
        (8, 12),
        2.0,
        0.0,
        0.3,
    )
}

/// A long floor (4 wide, 80 deep, 64 long thin quads) seen at a grazing angle,
/// banked 0.5 rad and turned 0.4 rad so depth changes fast along screen rows: where
/// interpolation shortcuts show.
#[must_use]
pub fn floor_scene() -> Scene3 {
    plane_grid(
        "floor",
        (-2.0, 2.0),
        (2.0, -78.0),
        -0.6,
        (1, 64),
        0.25,
        0.5,
        0.4,
    )
}

/// The bunny with the standard camera (no texture coordinates: uv = (x, y)).
#[must_use]
pub fn bunny_scene() -> Scene3 {
    let mesh = Mesh::bunny();
    Scene3 {
        name: "bunny",
        uvs: mesh.positions.iter().map(|p| Vec2::new(p.x, p.y)).collect(),
        positions: mesh.positions,
        indices: mesh.indices,
        camera: Camera::default(),
        plane: None,
    }
}

/// Positions projected by a matrix, uv as the varying.
pub struct UvShader<'a> {
    pub scene: &'a Scene3,
    pub mvp: Mat4,
}

impl Shader for UvShader<'_> {
    /// The accuracy table measures one thread.
    const THREADED: bool = false;

    type Varying = Vec2;
    #[inline(always)]
    fn vertex(&self, i: u32) -> (Vec4, Vec2) {
        let i = i as usize;
        let p = self.scene.positions.get(i).copied().unwrap_or(Vec3::ZERO);
        let uv = self.scene.uvs.get(i).copied().unwrap_or(Vec2::ZERO);
        (self.mvp * p.extend(1.0), uv)
    }
    #[inline(always)]
    fn fragment(&self, uv: &Vec2) -> Vec3 {
        Vec3::new(uv.x, uv.y, 0.0)
    }
}

/// The screen-space triangles a 3D scene becomes after projection and clipping
/// (unsnapped pixel coordinates, one per piece).
#[must_use]
pub fn projected(scene: &Scene3, target: Target) -> Vec<Tri2> {
    let shader = UvShader {
        scene,
        mvp: scene.view_proj(target),
    };
    let mut cache = VertexCache::default();
    transform(&shader, scene.positions.len(), &mut cache);
    let mut pieces = Pieces(Vec::new());
    for t in 0..(scene.indices.len() / 3) as u32 {
        prepare(
            &cache,
            &scene.indices,
            t,
            target,
            &DrawOptions::default(),
            &mut pieces,
        );
    }
    pieces.0
}

/// Collects each piece's unsnapped screen positions.
struct Pieces(Vec<Tri2>);

impl EmitPiece<Vec2> for Pieces {
    fn piece(&mut self, _: &Prepared<Vec2>) {}

    fn piece_on_screen(&mut self, _: &Prepared<Vec2>, screen: &[[f32; 2]; 3]) {
        self.0
            .push(screen.map(|v| [f64::from(v[0]), f64::from(v[1])]));
    }
}

/// The 2D triangles of a workload at a target size (`scale` < 1 thins the
/// triangle-count-heavy ones for quick runs).
#[must_use]
pub fn triangles(name: &str, target: Target, scale: f64) -> Vec<Tri2> {
    let (w, h) = (target.width, target.height);
    let count = |n: f64| ((n * scale).round() as usize).max(4);
    match name {
        // About one tiny triangle per 40 pixels, at least a few hundred.
        "tiny" => tiny_triangles(
            count((f64::from(w) * f64::from(h) / 40.0).clamp(400.0, 20_000.0)),
            w,
            h,
            1,
        ),
        "large" => tiling(10, 5, w, h, 2),
        "slivers" => sliver_fan(count(f64::from(w + h).min(2000.0)), w, h, 3),
        "near-plane" => projected(&near_plane_scene(), target),
        "floor" => projected(&floor_scene(), target),
        "bunny" => projected(&bunny_scene(), target),
        _ => Vec::new(),
    }
}

/// The 3D scene of a workload, if it has one.
#[must_use]
pub fn scene(name: &str) -> Option<Scene3> {
    match name {
        "near-plane" => Some(near_plane_scene()),
        "floor" => Some(floor_scene()),
        "bunny" => Some(bunny_scene()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::ndc_to_screen;

    #[test]
    fn near_plane_scene_is_clipped_and_floor_is_visible() {
        let target = Target::new(200, 60);
        let near = near_plane_scene();
        let pieces = projected(&near, target);
        assert!(pieces.len() > 20, "{}", pieces.len());
        // Some triangle straddles the near plane: the eye is above the plane at z = 2.6
        // and the grid runs from z = 6 to −20.
        let shader = UvShader {
            scene: &near,
            mvp: near.view_proj(target),
        };
        let mut cache = VertexCache::default();
        transform(&shader, near.positions.len(), &mut cache);
        let clipped = (0..(near.indices.len() / 3) as u32)
            .filter(|&t| {
                matches!(
                    prepare(
                        &cache,
                        &near.indices,
                        t,
                        target,
                        &DrawOptions::default(),
                        &mut |_: &Prepared<Vec2>| {}
                    ),
                    crate::render::PrepareOutcome::Drawn { clipped: true }
                )
            })
            .count();
        assert!(clipped > 0);
        assert!(!projected(&floor_scene(), target).is_empty());
    }

    #[test]
    fn exact_uv_is_the_plane_mapping_at_the_pixel_ray() {
        for s in [floor_scene(), near_plane_scene()] {
            // The uv map reproduces every vertex's texture coordinates, up to the
            // rounding of the turned positions to f32.
            for (p, uv) in s.positions.iter().zip(&s.uvs) {
                let got = s.uv_at(p.as_dvec3()).unwrap();
                // Rotation mixes the components, so the error scales with the larger.
                let tol = 4e-6 * f64::from(uv.abs().max_element().max(1.0));
                for (g, w) in got.into_iter().zip([uv.x, uv.y]) {
                    assert!((g - f64::from(w)).abs() < tol, "{got:?} {uv:?}");
                }
            }
            // The hit lies on the plane and projects back to the pixel centre.
            let target = Target::new(160, 120);
            let (point, normal, _) = s.plane.unwrap();
            let vp = s.view_proj(target).as_dmat4();
            for (x, y) in [(3, 100), (80, 90), (150, 70)] {
                let hit = s.exact_hit(target, x, y).unwrap();
                assert!(normal.dot(hit - point).abs() < 1e-9);
                let c = vp * hit.extend(1.0);
                let [sx, sy] = ndc_to_screen([c.x / c.w, c.y / c.w], [160.0, 120.0]);
                assert!((sx - f64::from(x) - 0.5).abs() < 1e-6, "{sx}");
                assert!((sy - f64::from(y) - 0.5).abs() < 1e-6, "{sy}");
            }
        }
    }
}

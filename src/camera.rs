//! The camera: right-handed view space looking down −z, depth 0 (near) .. 1 (far).
//!
//! The projection is glam's `camera::rh::proj::directx::perspective` (NDC z in [0, 1]).
//! It takes the target's pixel aspect ratio so a terminal cell (about twice as tall as
//! wide) can be corrected: the aspect passed to the projection is the target's width in
//! the same units as its height.

use glam::{Mat4, Vec3};

/// A perspective camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view in radians.
    pub fov_y: f32,
    pub near: f32,
    pub far: f32,
}

impl Default for Camera {
    /// The standard camera: distance 2.6 on +z looking at the origin, 45°, near 0.1,
    /// far 10.
    fn default() -> Self {
        Self {
            eye: Vec3::new(0.0, 0.0, 2.6),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y: 45f32.to_radians(),
            near: 0.1,
            far: 10.0,
        }
    }
}

/// How much of the narrower half of the view a framed model's bounding sphere spans.
pub const FRAME_FILL: f32 = 0.88;

impl Camera {
    /// The standard camera moved along +z until a sphere of `radius` about the origin
    /// spans [`FRAME_FILL`] of the view's narrower half (whose field of view is `fov_y`,
    /// see [`Camera::projection`]), moved closer by `zoom`: seen from distance `d` the
    /// sphere's outline is a circle of tangent `r / √(d² − r²)`. Near and far planes
    /// follow the distance so zooming out never clips.
    #[must_use]
    pub fn framing(radius: f32, zoom: f32) -> Self {
        let mut c = Self::default();
        let r = if radius.is_finite() && radius > 0.0 {
            radius
        } else {
            1.0
        };
        let t = FRAME_FILL * (c.fov_y * 0.5).tan();
        let d = r * (1.0 + 1.0 / (t * t)).sqrt() / zoom.max(0.05);
        c.eye = Vec3::new(0.0, 0.0, d);
        c.near = (d - 2.0 * r).max(0.01 * d).min(c.near);
        c.far = c.far.max(d + 2.0 * r);
        c
    }

    /// World to view space.
    #[must_use]
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up)
    }

    /// View to clip space for a `width × height` pixel target whose pixels are
    /// `pixel_aspect` times as wide as they are tall (1 for square pixels, 0.5 for a
    /// terminal cell sampled once). `fov_y` spans the narrower side: the height of a
    /// wide view, the width of a tall one, so what fits one aspect fits every other.
    #[must_use]
    pub fn projection(&self, width: u32, height: u32, pixel_aspect: f32) -> Mat4 {
        let aspect = (width.max(1) as f32 * pixel_aspect) / height.max(1) as f32;
        let fov = if aspect < 1.0 {
            2.0 * ((self.fov_y * 0.5).tan() / aspect).atan()
        } else {
            self.fov_y
        };
        glam::camera::rh::proj::directx::perspective(fov, aspect, self.near, self.far)
    }
}

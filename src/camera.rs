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

impl Camera {
    /// World to view space.
    #[must_use]
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up)
    }

    /// View to clip space for a `width × height` pixel target whose pixels are
    /// `pixel_aspect` times as wide as they are tall (1 for square pixels, 0.5 for a
    /// terminal cell sampled once).
    #[must_use]
    pub fn projection(&self, width: u32, height: u32, pixel_aspect: f32) -> Mat4 {
        let aspect = (width.max(1) as f32 * pixel_aspect) / height.max(1) as f32;
        glam::camera::rh::proj::directx::perspective(self.fov_y, aspect, self.near, self.far)
    }
}

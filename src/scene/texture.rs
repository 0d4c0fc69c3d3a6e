//! Textures: images (PNG, JPEG, BMP, TGA, GIF) sampled by texture coordinates, nearest or bilinear.
//!
//! Coordinates follow OBJ: (0, 0) is the bottom-left of the image, (1, 1) the top
//! right, and the texture repeats outside [0, 1]. Texel centres are at
//! `(i + ½) / width`. Colours are the image's 8-bit values scaled to 0..1 (no
//! gamma, like the rest of the shading).

use std::path::Path;

use glam::{Vec2, Vec3};

use super::SceneError;
use super::file::TextureMode;
use crate::counters::{self, Stage};
use crate::mesh::read::read_regular;
use crate::mesh::{MAX_MODEL_BYTES, MeshError, TextureSource};

/// The most pixels a texture may have (8192 × 8192): its texels take 12 bytes each.
pub const MAX_TEXTURE_PIXELS: u64 = 1 << 26;

/// An RGB image for sampling.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub width: u32,
    pub height: u32,
    /// Row-major from the top row, as 0..1 colours.
    pub texels: Vec<Vec3>,
}

impl Texture {
    /// Reads an image file: PNG, JPEG, BMP, TGA or GIF. Only a regular file is read,
    /// and an image of more than [`MAX_TEXTURE_PIXELS`] is refused from its header,
    /// before it is decoded.
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let bytes = read_regular(path, MAX_MODEL_BYTES).map_err(|e| SceneError::Texture {
            path: path.into(),
            problem: match e {
                MeshError::Io { source, .. } => source.to_string(),
                MeshError::NotRegular { what, .. } => format!("{what}, not an image file"),
                e => e.to_string().replace(&format!("{}: ", path.display()), ""),
            },
        })?;
        Self::decode(&bytes, path)
    }

    /// Reads a model's texture, from its file or from the bytes inside the model.
    pub fn from_source(source: &TextureSource) -> Result<Self, SceneError> {
        match source {
            TextureSource::File(path) => Self::load(path),
            TextureSource::Embedded { name, bytes } => Self::decode(bytes, Path::new(name)),
        }
    }

    fn decode(bytes: &[u8], path: &Path) -> Result<Self, SceneError> {
        let problem = |problem: String| SceneError::Texture {
            path: path.into(),
            problem,
        };
        let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| problem(e.to_string()))?;
        let (width, height) = reader
            .into_dimensions()
            .map_err(|e| problem(e.to_string()))?;
        if u64::from(width) * u64::from(height) > MAX_TEXTURE_PIXELS {
            return Err(problem(format!(
                "{width}×{height} is more than the {MAX_TEXTURE_PIXELS} pixels a texture may have"
            )));
        }
        let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| problem(e.to_string()))?;
        let mut limits = image::Limits::default();
        limits.max_alloc = Some(MAX_TEXTURE_PIXELS * 16);
        reader.limits(limits);
        let img = reader.decode().map_err(|e| problem(e.to_string()))?;
        let rgb = img.to_rgb8();
        let (width, height) = rgb.dimensions();
        if width == 0 || height == 0 {
            return Err(problem("the image is empty".into()));
        }
        Ok(Self {
            width,
            height,
            texels: rgb
                .pixels()
                .map(|p| Vec3::new(f32::from(p[0]), f32::from(p[1]), f32::from(p[2])) / 255.0)
                .collect(),
        })
    }

    /// A `w × h` checkerboard of two colours with `n × n` squares (for tests).
    #[must_use]
    pub fn checker(w: u32, h: u32, n: u32, a: Vec3, b: Vec3) -> Self {
        let texels = (0..h)
            .flat_map(|y| {
                (0..w).map(move |x| {
                    if (x * n / w + y * n / h).is_multiple_of(2) {
                        a
                    } else {
                        b
                    }
                })
            })
            .collect();
        Self {
            width: w,
            height: h,
            texels,
        }
    }

    #[inline]
    fn texel(&self, x: i64, y: i64) -> Vec3 {
        let (w, h) = (i64::from(self.width), i64::from(self.height));
        self.texels[(y.rem_euclid(h) * w + x.rem_euclid(w)) as usize]
    }

    /// The colour at texture coordinates `uv` (non-finite coordinates read texel 0).
    #[inline]
    #[must_use]
    pub fn sample(&self, uv: Vec2, mode: TextureMode) -> Vec3 {
        counters::add(Stage::TextureSamples, 1);
        let uv = if uv.is_finite() { uv } else { Vec2::ZERO };
        // Texel space with row 0 at the top; repeat keeps it in range.
        let u = f64::from(uv.x.fract()).rem_euclid(1.0) * f64::from(self.width);
        let v = (1.0 - f64::from(uv.y.fract()).rem_euclid(1.0)) * f64::from(self.height);
        match mode {
            TextureMode::Off => Vec3::ONE,
            TextureMode::Nearest => self.texel(u.floor() as i64, v.floor() as i64),
            TextureMode::Bilinear => {
                let (x, y) = (u - 0.5, v - 0.5);
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
                let (x0, y0) = (x0 as i64, y0 as i64);
                let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), fx);
                let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), fx);
                top.lerp(bottom, fy)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_and_bilinear_follow_obj_orientation_and_repeat() {
        // 2×2: top row red, green; bottom row blue, white.
        let t = Texture {
            width: 2,
            height: 2,
            texels: vec![Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE],
        };
        let n = |u, v| t.sample(Vec2::new(u, v), TextureMode::Nearest);
        assert_eq!(n(0.25, 0.75), Vec3::X, "top left");
        assert_eq!(n(0.75, 0.75), Vec3::Y);
        assert_eq!(n(0.25, 0.25), Vec3::Z, "bottom left (v = 0 is the bottom)");
        assert_eq!(n(1.25, -0.75), Vec3::Z, "repeats");
        // At a texel centre bilinear equals the texel; midway it averages.
        let b = |u, v| t.sample(Vec2::new(u, v), TextureMode::Bilinear);
        assert!((b(0.25, 0.75) - Vec3::X).length() < 1e-6);
        assert!((b(0.5, 0.75) - (Vec3::X + Vec3::Y) * 0.5).length() < 1e-6);
        assert_eq!(n(f32::NAN, 0.3), n(0.0, 0.0));
    }
}

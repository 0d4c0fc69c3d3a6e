//! The reference a terminal frame is scored against: the same view rendered as an
//! image, supersampled.

use image::RgbImage;

use crate::raster::Target;
use crate::scene::Scene;
use crate::scene::render::{SceneFrame, SceneView};
use crate::terminal::color::{to_linear, to_srgb};

/// Samples per reference pixel along each axis: the view is rendered at this multiple
/// of the painted screen's size and box-filtered down.
pub const SUPERSAMPLE: u32 = 2;

/// A reference image at full (supersampled) size and at the painted screen's size.
#[derive(Clone, Debug)]
pub struct ReferenceImages {
    /// `SUPERSAMPLE` times the screen's pixel size (what chafa is given: it does its
    /// own downscale).
    pub full: RgbImage,
    /// Box-filtered in linear light to the screen's pixel size (what is scored).
    pub image: RgbImage,
}

/// Renders `scene` as the viewport saw it (`view`, with square pixels) at
/// `SUPERSAMPLE·width × SUPERSAMPLE·height` and box-filters it to `width × height`.
/// Uncovered pixels are the scene's background (black for a model).
#[must_use]
pub fn render(scene: &Scene, view: &SceneView, width: u32, height: u32) -> ReferenceImages {
    let target = Target::new(width * SUPERSAMPLE, height * SUPERSAMPLE);
    let mut frame = SceneFrame::new(scene);
    let view = SceneView {
        pixel_aspect: 1.0,
        ..*view
    };
    frame.draw(scene, target, &view);
    // The frame is cleared to the background, so uncovered pixels (alpha 0) already
    // hold it.
    let raw: Vec<u8> = frame
        .color
        .0
        .iter()
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    let full = RgbImage::from_raw(target.width, target.height, raw)
        .unwrap_or_else(|| RgbImage::new(target.width, target.height));
    let image = box_filter(&full, SUPERSAMPLE);
    ReferenceImages { full, image }
}

/// Averages each `factor × factor` block in linear light (the last partial blocks
/// are dropped).
#[must_use]
pub fn box_filter(img: &RgbImage, factor: u32) -> RgbImage {
    let f = factor.max(1);
    let (w, h) = (img.width() / f, img.height() / f);
    let n = (f * f) as f32;
    RgbImage::from_fn(w, h, |x, y| {
        let mut sum = [0.0f32; 3];
        for j in 0..f {
            for i in 0..f {
                let p = img.get_pixel(x * f + i, y * f + j).0;
                for (s, v) in sum.iter_mut().zip(p) {
                    *s += to_linear(v);
                }
            }
        }
        image::Rgb(sum.map(|s| to_srgb(s / n)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_filter_averages_light() {
        // A white and a black pixel side by side, twice: half the light, sRGB 188.
        let img = RgbImage::from_fn(2, 2, |x, _| image::Rgb([255 * (1 - x as u8); 3]));
        let out = box_filter(&img, 2);
        assert_eq!(out.dimensions(), (1, 1));
        assert_eq!(out.get_pixel(0, 0).0, [188; 3]);
    }
}

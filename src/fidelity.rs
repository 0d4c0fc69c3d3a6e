//! The fidelity benchmark: how close what a terminal shows comes to the image it
//! stands for (`termrast bench fidelity`).
//!
//! Per view, a reference is rendered with the viewport's own camera at twice the
//! painted screen's pixel size and box-filtered in linear light ([`mod@reference`]). Each
//! glyph mode × colour depth is rendered by the viewport, encoded to ANSI bytes, fed
//! through a terminal emulator and painted back to pixels at 8×16 per cell
//! ([`crate::terminal::paint`]); chafa's output, when chafa is installed, goes the
//! same way ([`chafa`]). The painted screen is scored against the reference by SSIM
//! and PSNR on blurred luminance ([`metrics`]), and the table ([`report`]) averages
//! the views. Scoring through the emulator is deliberate: it measures what a
//! terminal shows, not the viewer's internal cells.

pub mod bench;
pub mod chafa;
pub mod config;
pub mod metrics;
pub mod reference;
pub mod report;
pub mod spin;

use std::io::Write;
use std::path::{Path, PathBuf};

use image::RgbImage;

pub use bench::{Measurement, Outcome, Source, run};
pub use config::{Config, View, standard_views};

/// Why the benchmark could not run.
#[derive(Debug, thiserror::Error)]
pub enum FidelityError {
    #[error("a grid of {0}×{1} cells cannot be measured: {2}")]
    Size(u16, u16, String),
    #[error("there are no views to measure")]
    NoViews,
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    #[error(transparent)]
    Paint(#[from] crate::terminal::paint::PaintError),
    #[error(transparent)]
    Metric(#[from] metrics::MetricError),
    #[error("encoding a frame: {0}")]
    Encode(std::io::Error),
    #[error("{0}: {1}")]
    Io(PathBuf, std::io::Error),
    #[error("{0}: {1}")]
    Image(PathBuf, image::ImageError),
    #[error("a benchmark worker panicked")]
    Worker,
}

/// Writes an RGB PNG, compressed fast: the benchmark writes many large ones.
pub fn save_png(path: &Path, img: &RgbImage) -> Result<(), FidelityError> {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let io_err = |e| FidelityError::Io(path.into(), e);
    let file = std::fs::File::create(path).map_err(io_err)?;
    let mut w = std::io::BufWriter::new(file);
    PngEncoder::new_with_quality(&mut w, CompressionType::Fast, FilterType::Adaptive)
        .write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| FidelityError::Image(path.into(), e))?;
    w.flush().map_err(io_err)
}

//! Image comparison as a viewer sees it: luminance, blurred, then SSIM and PSNR.
//!
//! Both images go to linear light, to relative luminance `Y = 0.2126 R + 0.7152 G +
//! 0.0722 B`, through a Gaussian blur of σ = [`VIEW_BLUR_SIGMA`] pixels (cells are
//! seen from a distance, so a glyph's inner pattern should count only as far as it
//! changes the light of its neighbourhood), and back through the sRGB transfer curve
//! to 0..255, a perceptually even scale on which the usual SSIM constants apply.
//!
//! SSIM is Wang, Bovik, Sheikh and Simoncelli, "Image quality assessment: from error
//! visibility to structural similarity" (IEEE TIP 13(4), 2004): local means, variances
//! and covariance under an 11×11 Gaussian window of σ = 1.5, combined as
//! `(2μxμy + C1)(2σxy + C2) / ((μx² + μy² + C1)(σx² + σy² + C2))` with
//! `C1 = (0.01·255)²`, `C2 = (0.03·255)²`, averaged over every window that lies wholly
//! inside the image (the paper's own implementation does the same).

use image::RgbImage;

use crate::terminal::color::{linear_to_srgb, to_linear};

/// The blur standing in for viewing distance, in pixels.
pub const VIEW_BLUR_SIGMA: f32 = 2.0;
/// The SSIM window's Gaussian σ, in pixels.
pub const SSIM_SIGMA: f32 = 1.5;
/// The SSIM window's side, in pixels.
pub const SSIM_WINDOW: usize = 11;
/// SSIM's luminance constant, `(K1·L)²` with K1 = 0.01 and L = 255.
pub const SSIM_C1: f64 = (0.01 * 255.0) * (0.01 * 255.0);
/// SSIM's contrast constant, `(K2·L)²` with K2 = 0.03 and L = 255.
pub const SSIM_C2: f64 = (0.03 * 255.0) * (0.03 * 255.0);

/// A plane of values, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    pub width: usize,
    pub height: usize,
    pub data: Vec<f32>,
}

/// Why two images cannot be compared.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum MetricError {
    #[error("an image of {0}×{1} pixels has nothing to compare")]
    Empty(usize, usize),
    #[error("images of {0}×{1} and {2}×{3} pixels cannot be compared")]
    SizeMismatch(usize, usize, usize, usize),
    #[error(
        "an image of {0}×{1} pixels is smaller than the {SSIM_WINDOW}×{SSIM_WINDOW} SSIM window"
    )]
    TooSmall(usize, usize),
}

/// SSIM and PSNR of one image against a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Score {
    /// Mean SSIM, at most 1 (identical).
    pub ssim: f64,
    /// Peak signal-to-noise ratio in dB; infinite for identical images.
    pub psnr: f64,
}

/// A normalised Gaussian of `2·radius + 1` taps.
#[must_use]
pub fn gaussian_kernel(sigma: f32, radius: usize) -> Vec<f32> {
    let r = radius as f32;
    let w: Vec<f32> = (0..=2 * radius)
        .map(|i| {
            let d = i as f32 - r;
            (-d * d / (2.0 * sigma * sigma)).exp()
        })
        .collect();
    let sum: f32 = w.iter().sum();
    w.into_iter().map(|v| v / sum).collect()
}

/// Correlates each row with `k` where the kernel fits wholly: `(w − n + 1) × h`.
fn rows_valid(src: &[f32], w: usize, h: usize, k: &[f32]) -> Vec<f32> {
    let ow = w + 1 - k.len();
    let mut out = vec![0.0; ow * h];
    for (o, row) in out.chunks_exact_mut(ow).zip(src.chunks_exact(w)) {
        // Tap by tap over the whole row, so the inner loop is a vector multiply-add.
        for (j, &kj) in k.iter().enumerate() {
            for (ov, &s) in o.iter_mut().zip(&row[j..j + ow]) {
                *ov += kj * s;
            }
        }
    }
    out
}

/// Correlates each column with `k` where the kernel fits wholly: `w × (h − n + 1)`.
fn cols_valid(src: &[f32], w: usize, h: usize, k: &[f32]) -> Vec<f32> {
    let oh = h + 1 - k.len();
    let mut out = vec![0.0; w * oh];
    for (y, o) in out.chunks_exact_mut(w).enumerate() {
        for (j, &kj) in k.iter().enumerate() {
            for (ov, &s) in o.iter_mut().zip(&src[(y + j) * w..(y + j + 1) * w]) {
                *ov += kj * s;
            }
        }
    }
    out
}

/// Gaussian blur, separable, radius ⌈3σ⌉, edges clamped (the border pixel repeats).
#[must_use]
pub fn blur(p: &Plane, sigma: f32) -> Plane {
    let r = (3.0 * sigma).ceil() as usize;
    if p.width == 0 || p.height == 0 || r == 0 {
        return p.clone();
    }
    let k = gaussian_kernel(sigma, r);
    let (w, h) = (p.width, p.height);
    let (pw, ph) = (w + 2 * r, h + 2 * r);
    let mut padded = vec![0.0; pw * ph];
    for (y, out) in padded.chunks_exact_mut(pw).enumerate() {
        let row = &p.data[y.saturating_sub(r).min(h - 1) * w..][..w];
        for (x, v) in out.iter_mut().enumerate() {
            *v = row[x.saturating_sub(r).min(w - 1)];
        }
    }
    let across = rows_valid(&padded, pw, ph, &k);
    Plane {
        width: w,
        height: h,
        data: cols_valid(&across, w, ph, &k),
    }
}

/// Relative luminance in linear light, 0..1.
#[must_use]
pub fn luminance(img: &RgbImage) -> Plane {
    let data = img
        .pixels()
        .map(|p| {
            let [r, g, b] = p.0.map(to_linear);
            0.2126 * r + 0.7152 * g + 0.0722 * b
        })
        .collect();
    Plane {
        width: img.width() as usize,
        height: img.height() as usize,
        data,
    }
}

/// The image as a viewer sees it: luminance, blurred by [`VIEW_BLUR_SIGMA`], encoded
/// with the sRGB curve to 0..255 (unrounded).
pub fn viewed(img: &RgbImage) -> Result<Plane, MetricError> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    if w == 0 || h == 0 {
        return Err(MetricError::Empty(w, h));
    }
    let mut p = blur(&luminance(img), VIEW_BLUR_SIGMA);
    for v in &mut p.data {
        *v = linear_to_srgb(*v) * 255.0;
    }
    Ok(p)
}

fn check(a: &Plane, b: &Plane) -> Result<(), MetricError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(MetricError::SizeMismatch(
            a.width, a.height, b.width, b.height,
        ));
    }
    if a.width == 0 || a.height == 0 {
        return Err(MetricError::Empty(a.width, a.height));
    }
    if a.width < SSIM_WINDOW || a.height < SSIM_WINDOW {
        return Err(MetricError::TooSmall(a.width, a.height));
    }
    Ok(())
}

/// The mean of `p` under the SSIM window at every position where it fits.
fn window_mean(data: &[f32], w: usize, h: usize) -> Vec<f32> {
    let k = gaussian_kernel(SSIM_SIGMA, SSIM_WINDOW / 2);
    cols_valid(&rows_valid(data, w, h, &k), w + 1 - k.len(), h, &k)
}

/// A reference's windowed statistics, computed once for many comparisons.
#[derive(Clone, Debug)]
pub struct Reference {
    pub viewed: Plane,
    mean: Vec<f32>,
    mean_sq: Vec<f32>,
}

impl Reference {
    /// Prepares an image to be compared against.
    pub fn new(img: &RgbImage) -> Result<Self, MetricError> {
        Self::from_plane(viewed(img)?)
    }

    /// Prepares a viewed plane ([`viewed`]) to be compared against.
    pub fn from_plane(p: Plane) -> Result<Self, MetricError> {
        check(&p, &p)?;
        let (w, h) = (p.width, p.height);
        let sq: Vec<f32> = p.data.iter().map(|v| v * v).collect();
        Ok(Self {
            mean: window_mean(&p.data, w, h),
            mean_sq: window_mean(&sq, w, h),
            viewed: p,
        })
    }

    /// SSIM and PSNR of `img` against this reference.
    pub fn score(&self, img: &RgbImage) -> Result<Score, MetricError> {
        self.score_plane(&viewed(img)?)
    }

    /// SSIM and PSNR of a viewed plane against this reference.
    pub fn score_plane(&self, x: &Plane) -> Result<Score, MetricError> {
        let y = &self.viewed;
        check(x, y)?;
        let (w, h) = (x.width, x.height);
        let sq: Vec<f32> = x.data.iter().map(|v| v * v).collect();
        let cross: Vec<f32> = x.data.iter().zip(&y.data).map(|(a, b)| a * b).collect();
        let (mx, mxx, mxy) = (
            window_mean(&x.data, w, h),
            window_mean(&sq, w, h),
            window_mean(&cross, w, h),
        );
        let mut sum = 0.0f64;
        for i in 0..mx.len() {
            let (ux, uy) = (f64::from(mx[i]), f64::from(self.mean[i]));
            let vx = f64::from(mxx[i]) - ux * ux;
            let vy = f64::from(self.mean_sq[i]) - uy * uy;
            let cxy = f64::from(mxy[i]) - ux * uy;
            sum += ((2.0 * ux * uy + SSIM_C1) * (2.0 * cxy + SSIM_C2))
                / ((ux * ux + uy * uy + SSIM_C1) * (vx + vy + SSIM_C2));
        }
        Ok(Score {
            ssim: sum / mx.len() as f64,
            psnr: psnr(x, y)?,
        })
    }
}

/// Mean SSIM of two planes on a 0..255 scale (see the module documentation).
pub fn ssim(a: &Plane, b: &Plane) -> Result<f64, MetricError> {
    check(a, b)?;
    Ok(Reference::from_plane(b.clone())?.score_plane(a)?.ssim)
}

/// PSNR in dB of two planes on a 0..255 scale: `10·log10(255² / MSE)`, infinite when
/// they are equal.
pub fn psnr(a: &Plane, b: &Plane) -> Result<f64, MetricError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(MetricError::SizeMismatch(
            a.width, a.height, b.width, b.height,
        ));
    }
    if a.data.is_empty() {
        return Err(MetricError::Empty(a.width, a.height));
    }
    let se: f64 = a
        .data
        .iter()
        .zip(&b.data)
        .map(|(x, y)| f64::from(x - y).powi(2))
        .sum();
    let mse = se / a.data.len() as f64;
    Ok(if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0 * 255.0 / mse).log10()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(w: usize, h: usize, mut f: impl FnMut(usize, usize) -> f32) -> Plane {
        let data = (0..w * h).map(|i| f(i % w, i / w)).collect();
        Plane {
            width: w,
            height: h,
            data,
        }
    }

    /// A gradient with some structure, plus deterministic noise of `amp` levels.
    fn scene(amp: f32) -> Plane {
        let mut seed = 12345u32;
        plane(48, 40, |x, y| {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let noise = (seed >> 8) as f32 / (1u32 << 24) as f32 - 0.5;
            let base = if (x / 8 + y / 8) % 2 == 0 {
                60.0
            } else {
                180.0
            };
            (base + x as f32 + amp * noise).clamp(0.0, 255.0)
        })
    }

    #[test]
    fn an_image_matches_itself() {
        let a = scene(0.0);
        let s = ssim(&a, &a).unwrap();
        assert!((s - 1.0).abs() < 1e-12, "{s}");
        assert_eq!(psnr(&a, &a).unwrap(), f64::INFINITY);
        let img = RgbImage::from_fn(20, 16, |x, y| image::Rgb([x as u8 * 9, y as u8 * 13, 77]));
        let r = Reference::new(&img).unwrap().score(&img).unwrap();
        assert!(
            (r.ssim - 1.0).abs() < 1e-12 && r.psnr.is_infinite(),
            "{r:?}"
        );
    }

    #[test]
    fn noise_lowers_ssim() {
        let clean = scene(0.0);
        let (s1, s2, s3) = (
            ssim(&scene(10.0), &clean).unwrap(),
            ssim(&scene(40.0), &clean).unwrap(),
            ssim(&scene(120.0), &clean).unwrap(),
        );
        assert!(1.0 > s1 && s1 > s2 && s2 > s3 && s3 > 0.0, "{s1} {s2} {s3}");
        let (p1, p2) = (
            psnr(&scene(10.0), &clean).unwrap(),
            psnr(&scene(40.0), &clean).unwrap(),
        );
        assert!(p1 > p2, "{p1} {p2}");
    }

    #[test]
    fn constant_images_by_hand() {
        // One window (11×11); no variance, so SSIM is the luminance term alone:
        // (2·10·5 + C1) / (10² + 5² + C1) with C1 = 6.5025, 0.80989 (0.8 without C1).
        let (a, b) = (plane(11, 11, |_, _| 10.0), plane(11, 11, |_, _| 5.0));
        let want = (100.0 + 6.5025) / (125.0 + 6.5025);
        let got = ssim(&a, &b).unwrap();
        assert!((got - want).abs() < 1e-5, "{got} vs {want}");
        // A 12-wide image has two window positions: a bright last column is seen by
        // the second only, whose structure term then falls.
        let c = plane(12, 11, |x, _| if x == 11 { 200.0 } else { 10.0 });
        let d = plane(12, 11, |_, _| 10.0);
        let s = ssim(&c, &d).unwrap();
        assert!(s < 1.0 && s > 0.5, "{s}");
        // Every pixel 10 apart: MSE 100, PSNR 10·log10(65025 / 100) = 28.1308 dB.
        let (p, q) = (plane(11, 11, |_, _| 100.0), plane(11, 11, |_, _| 90.0));
        assert!((psnr(&p, &q).unwrap() - 28.130_803_6).abs() < 1e-6);
    }

    #[test]
    fn blur_keeps_constants_and_energy() {
        let c = plane(30, 20, |_, _| 0.4);
        let b = blur(&c, VIEW_BLUR_SIGMA);
        assert!(b.data.iter().all(|v| (v - 0.4).abs() < 1e-6));
        // An impulse far from the edges spreads out but keeps its sum.
        let imp = plane(31, 31, |x, y| f32::from(u8::from(x == 15 && y == 15)));
        let b = blur(&imp, VIEW_BLUR_SIGMA);
        let sum: f32 = b.data.iter().sum();
        assert!(
            (sum - 1.0).abs() < 1e-5 && b.data[15 * 31 + 15] < 0.1,
            "{sum}"
        );
        let k = gaussian_kernel(SSIM_SIGMA, SSIM_WINDOW / 2);
        assert_eq!(k.len(), SSIM_WINDOW);
        assert!((k.iter().sum::<f32>() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn bad_sizes_are_errors() {
        let a = plane(11, 11, |_, _| 0.0);
        let small = plane(10, 30, |_, _| 0.0);
        assert_eq!(ssim(&small, &small), Err(MetricError::TooSmall(10, 30)));
        assert!(matches!(
            ssim(&a, &small),
            Err(MetricError::SizeMismatch(..))
        ));
        assert!(matches!(
            viewed(&RgbImage::new(0, 5)),
            Err(MetricError::Empty(0, 5))
        ));
    }
}

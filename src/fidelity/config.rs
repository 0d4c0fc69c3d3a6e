//! What the benchmark measures: the views and the cell grid.

use std::path::PathBuf;

use super::{FidelityError, metrics, reference};
use crate::terminal::paint::{CELL_HEIGHT, CELL_WIDTH};
use crate::tui::viewport::ViewSettings;

/// The built-in models the benchmark views.
pub const MODELS: [&str; 2] = ["teapot", "bunny"];
/// Model rotations about y, radians, of the full run (`--quick` takes the first).
pub const ANGLES: [f32; 3] = [0.6, 2.2, 4.0];

/// One view: a model turned by `angle`, tilted by `tilt` (radians).
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    pub model: String,
    pub angle: f32,
    pub tilt: f32,
}

impl View {
    /// A name for tables and file names, e.g. `teapot-0.6`.
    #[must_use]
    pub fn name(&self) -> String {
        format!("{}-{:.1}", self.model, self.angle)
    }
}

/// The benchmark's views: both models at every angle (or only the first angle),
/// with the viewer's default tilt.
#[must_use]
pub fn standard_views(quick: bool) -> Vec<View> {
    let angles = if quick { &ANGLES[..1] } else { &ANGLES[..] };
    let tilt = ViewSettings::default().tilt;
    MODELS
        .iter()
        .flat_map(|m| {
            angles.iter().map(move |&angle| View {
                model: (*m).to_owned(),
                angle,
                tilt,
            })
        })
        .collect()
}

/// What to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    pub cols: u16,
    pub rows: u16,
    pub views: Vec<View>,
    /// Compare with chafa when it is installed.
    pub chafa: bool,
    /// Write the reference and every painted screen as PNGs into this directory.
    pub keep: Option<PathBuf>,
}

impl Config {
    /// A configuration for a `cols × rows` cell grid, checked: the reference (twice
    /// the grid's pixel size) must fit a render target, and the painted screen the
    /// SSIM window.
    pub fn new(cols: u16, rows: u16, views: Vec<View>) -> Result<Self, FidelityError> {
        let c = Self {
            cols,
            rows,
            views,
            chafa: true,
            keep: None,
        };
        c.check()?;
        Ok(c)
    }

    /// Checks the grid and views (see [`Config::new`]).
    pub fn check(&self) -> Result<(), FidelityError> {
        let bad = |why: String| Err(FidelityError::Size(self.cols, self.rows, why));
        let (w, h) = self.pixels();
        let s = reference::SUPERSAMPLE;
        if self.cols == 0 || self.rows == 0 {
            return bad("the grid is empty".into());
        }
        if (w as usize) < metrics::SSIM_WINDOW || (h as usize) < metrics::SSIM_WINDOW {
            return bad(format!(
                "{w}×{h} pixels is smaller than the {0}×{0} SSIM window",
                metrics::SSIM_WINDOW
            ));
        }
        let (rw, rh) = (u64::from(w * s), u64::from(h * s));
        let side = u64::from(crate::raster::setup::MAX_TARGET_SIDE);
        if rw > side || rh > side || rw * rh > crate::cli::MAX_PIXELS {
            return bad(format!("the {rw}×{rh} reference is too large to render"));
        }
        if self.views.is_empty() {
            return Err(FidelityError::NoViews);
        }
        Ok(())
    }

    /// The painted screen's size in pixels.
    #[must_use]
    pub fn pixels(&self) -> (u32, u32) {
        (
            u32::from(self.cols) * CELL_WIDTH,
            u32::from(self.rows) * CELL_HEIGHT,
        )
    }
}

/// A PNG file name from a row's name, `+` and other punctuation made `_`.
pub(super) fn file_name(name: &str) -> String {
    let safe: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{safe}.png")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_configurations_are_errors() {
        assert!(Config::new(0, 10, standard_views(true)).is_err());
        assert!(Config::new(1, 1, standard_views(true)).is_err());
        assert!(Config::new(5000, 100, standard_views(true)).is_err());
        assert!(matches!(
            Config::new(20, 8, Vec::new()),
            Err(FidelityError::NoViews)
        ));
        assert_eq!(standard_views(false).len(), MODELS.len() * ANGLES.len());
        assert_eq!(file_name("a-0.6-chafa-x+y"), "a-0.6-chafa-x_y.png");
    }
}

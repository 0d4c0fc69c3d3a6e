//! The terminal as a framebuffer: sub-sample layouts, glyph and colour selection.
//!
//! A cell is covered by `sx × sy` sub-samples (the glyph mode); the rasterizer runs at
//! sub-sample resolution and each cell's glyph and two colours are fitted to its
//! samples. Cells are about twice as tall as wide (`cell_aspect` = width / height ≈
//! 0.5), so a sample's aspect is `cell_aspect · sy / sx`.

pub mod ansi;
pub mod color;
pub mod fit;
pub mod glyphs;
pub mod input;
pub mod locale;
pub mod paint;
pub mod palette;
mod shaped;
pub mod shapes;
mod split;

pub use color::{ColorMode, Rgb};
pub use glyphs::{CellGlyph, GlyphMode};
pub use palette::Palette;

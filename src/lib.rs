//! termrast: a terminal 3D rasterizer with an exact, SIMD edge-function core.
//!
//! The library holds all of the logic; the `termrast` binary only parses arguments.
//! Start with [`raster`] for the coverage rules and conventions.

pub mod accuracy;
pub mod camera;
pub mod cli;
pub mod counters;
pub mod fidelity;
pub mod memory;
pub mod mesh;
pub mod raster;
pub mod render;
pub mod scene;
pub mod serve;
pub mod simd;
pub mod slowlink;
pub mod terminal;
pub mod tui;
pub mod workload;

//! The hard-case stability suite: the cases where rasterizers crack, leak, drift or
//! panic, in one place. Each test's pass criterion is in its doc comment.
//!
//! "Exact" means equal to the independent i128 oracle on the 1/256 px grid, pixel for
//! pixel. The float edge variants of `termrast bench accuracy` run through the same
//! 2D cases (`termrast::accuracy::cases`); their errors are benchmark output (the
//! hard-case table of `termrast bench accuracy`), not test results.
//!
//! One file per topic; the imports and the target size here are shared by all.

use crate::common::{Direct, Exact, accumulate, assert_all_match_oracle, coverage, draw};
use glam::{Vec3, Vec4};
use proptest::prelude::*;
use termrast::accuracy::cases;
use termrast::accuracy::depth::{DepthFormat, DepthPass};
use termrast::accuracy::edge::EdgeArith;
use termrast::camera::Camera;
use termrast::raster::clip::{
    ClipOutcome, ClipVertex, MAX_CLIPPED, classify_codes, clip_straddling, guard_band_ndc, outcode,
};
use termrast::raster::depth::{DepthFunc, DepthState};
use termrast::raster::interp::Interpolation;
use termrast::raster::line::{Line, NoTrace};

use termrast::raster::traverse::planes_lanes;
use termrast::raster::{CountGrid, Reject, Setup, Target, Traversal};
use termrast::render::probe::probe;
use termrast::render::{DrawOptions, Prepared, Renderer, VertexCache, prepare, transform};

const T: Target = Target {
    width: 96,
    height: 64,
};

mod clipping;
mod degenerate;
mod fans;
mod fuzz;
mod lines;
mod precision;

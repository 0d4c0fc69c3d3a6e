//! The four traversals of one [`Setup`]. They differ only in how they walk the bounding
//! box; the tests hold them to bit-identical coverage against each other and the oracle.
//!
//! The terms are defined in `docs/rasterization.md`.
//!
//! | traversal | walks                                                        | edge arithmetic |
//! |-----------|--------------------------------------------------------------|-----------------|
//! | `scalar`  | every pixel, `F += I` per x, `+= J` per row                  | `i64`           |
//! | `planes`  | every pixel, one 4-lane vector `(F00, F01, F02, F03)`: the 1/z plane and the three edges, which divided by `area2` are `(1/z, w, u, v)` | `i64x4` |
//! | `block`   | q×q blocks classified by their corners (outside / inside / partial) | `i64`    |
//! | `wide`    | 8 pixels per step                                            | `i32x8` when the box allows, else `i64` |

mod block;
mod planes;
mod scalar;
mod wide;

pub use block::{BlockClass, DEFAULT_BLOCK, block, block_containing, classify_block};
pub use planes::{PlaneLanes, planes, planes_lanes};
pub use scalar::scalar;
pub use wide::{fits_i32, wide, wide_lanes};

use super::{CoverageSink, Setup};
use crate::simd::I32s;

/// Which traversal to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Traversal {
    /// Per-pixel incremental loop, the reference.
    Scalar,
    /// One 4-lane vector of planes per pixel: 1/z and the three edge functions.
    #[value(alias = "seed-simd")]
    Planes,
    /// q×q blocks with trivial accept and reject (q = 8).
    Block,
    /// 8 pixels per step in `i32x8`, the fast path.
    Wide,
}

impl Traversal {
    /// Every traversal, in table order.
    pub const ALL: [Traversal; 4] = [
        Traversal::Scalar,
        Traversal::Planes,
        Traversal::Block,
        Traversal::Wide,
    ];

    /// The name used on the command line and in tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Traversal::Scalar => "scalar",
            Traversal::Planes => "planes",
            Traversal::Block => "block",
            Traversal::Wide => "wide",
        }
    }

    /// Runs this traversal over one triangle. The match happens once per triangle.
    #[inline(always)]
    pub fn run<S: CoverageSink>(self, setup: &Setup, sink: &mut S) {
        self.run_lanes::<::wide::i32x8, S>(setup, sink);
    }

    /// [`Traversal::run`] with `wide`'s lanes of backend `L` (see [`crate::simd`]).
    #[inline(always)]
    pub fn run_lanes<L: I32s, S: CoverageSink>(self, setup: &Setup, sink: &mut S) {
        match self {
            Traversal::Scalar => scalar(setup, sink),
            Traversal::Planes => planes(setup, sink),
            Traversal::Block => block(setup, DEFAULT_BLOCK, sink),
            Traversal::Wide => wide_lanes::<L, S>(setup, sink),
        }
    }
}

//! The four traversals of one [`Setup`]. They differ only in how they walk the bounding
//! box; the tests hold them to bit-identical coverage against each other and the oracle.
//!
//! | traversal   | walks                                   | edge arithmetic            |
//! |-------------|-----------------------------------------|----------------------------|
//! | `scalar`    | every pixel, `F += I` per x, `+= J` per row (seed 000 §2) | `i64` |
//! | `seed-simd` | every pixel, one 4-lane vector (F00, F01, F02, F03) (seed 000 §4) | `i64x4` |
//! | `block`     | q×q blocks classified by their corners (seed 002) | `i64`          |
//! | `wide`      | 8 pixels per step                        | `i32x8` when the box allows, else `i64` |

mod block;
mod scalar;
mod seed_simd;
mod wide;

pub use block::{BlockClass, DEFAULT_BLOCK, block, block_containing, classify_block};
pub use scalar::scalar;
pub use seed_simd::{SeedLanes, seed_simd, seed_simd_lanes};
pub use wide::{fits_i32, wide, wide_lanes};

use super::{CoverageSink, Setup};
use crate::simd::I32s;

/// Which traversal to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Traversal {
    /// Per-pixel incremental loop, the reference.
    Scalar,
    /// Seed 000's 4-lane vector per pixel.
    SeedSimd,
    /// Seed 002's q×q blocks with trivial accept and reject (q = 8).
    Block,
    /// 8 pixels per step in `i32x8`, the fast path.
    Wide,
}

impl Traversal {
    /// Every traversal, in table order.
    pub const ALL: [Traversal; 4] = [
        Traversal::Scalar,
        Traversal::SeedSimd,
        Traversal::Block,
        Traversal::Wide,
    ];

    /// The name used on the command line and in tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Traversal::Scalar => "scalar",
            Traversal::SeedSimd => "seed-simd",
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
            Traversal::SeedSimd => seed_simd(setup, sink),
            Traversal::Block => block(setup, DEFAULT_BLOCK, sink),
            Traversal::Wide => wide_lanes::<L, S>(setup, sink),
        }
    }
}

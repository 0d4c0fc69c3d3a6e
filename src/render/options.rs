//! What a draw is asked to do ([`DrawOptions`], [`Cull`]) and what it did ([`DrawStats`]).

use crate::raster::Traversal;
use crate::raster::depth::DepthState;
use crate::raster::interp::Interpolation;

/// Which faces to skip.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Cull {
    /// Draw both sides.
    #[default]
    None,
    /// Skip faces that are clockwise in NDC (facing away).
    Back,
}

/// Per-draw state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawOptions {
    pub depth: DepthState,
    pub cull: Cull,
    pub interpolation: Interpolation,
    /// Traversal that walks each triangle (all give identical coverage).
    pub traversal: Traversal,
}

impl Default for DrawOptions {
    fn default() -> Self {
        Self {
            depth: DepthState::default(),
            cull: Cull::None,
            interpolation: Interpolation::Perspective,
            traversal: Traversal::Wide,
        }
    }
}

/// Counters of one frame, for the status line and the benchmark.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrawStats {
    /// Triangles submitted.
    pub triangles: u64,
    /// Triangles that reached the traversal (after clipping, setup and culling).
    pub drawn: u64,
    /// Back faces skipped: told by the sign of their area before the rest of the
    /// set-up, so one that would cover no pixel centre counts here, not as rejected.
    pub culled: u64,
    /// Triangles cut by a clip plane (drawn in part).
    pub clipped: u64,
    /// Triangles with nothing left: behind the eye, beyond far, off screen, zero
    /// area after snapping, or non-finite.
    pub rejected: u64,
    /// Covered pixels that went through the depth test.
    pub fragments: u64,
    /// Fragments that passed the depth test and were shaded.
    pub shaded: u64,
}

impl std::ops::AddAssign for DrawStats {
    fn add_assign(&mut self, o: Self) {
        self.triangles += o.triangles;
        self.drawn += o.drawn;
        self.culled += o.culled;
        self.clipped += o.clipped;
        self.rejected += o.rejected;
        self.fragments += o.fragments;
        self.shaded += o.shaded;
    }
}

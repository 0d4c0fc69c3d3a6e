//! Work counters: how much each optional stage actually did.
//!
//! They exist to prove that a scene's skipped stages really do no work (the scene
//! tests read them). They count only in builds with debug assertions (`cargo test`);
//! in release builds every call compiles to nothing, so the viewer and the
//! benchmarks pay nothing for them. Counts are per thread.

/// A stage that does optional work.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Vertices whose smooth normals were generated (mesh load).
    NormalsGenerated,
    /// Vertex normals transformed to world space.
    NormalsTransformed,
    /// Vertex positions transformed to world space for a varying.
    PositionsToWorld,
    /// Vertex colours read.
    VertexColors,
    /// Texture coordinates read.
    Uvs,
    /// Lighting evaluated (per vertex or per pixel).
    Lighting,
    /// Texture samples taken.
    TextureSamples,
    /// Fog applied to a fragment.
    Fog,
    /// Depth-shaded fragments.
    DepthShading,
    /// Depth-buffer pixels cleared.
    DepthClears,
    /// Fragments depth-tested.
    DepthTests,
    /// Wireframe edges projected.
    WireEdges,
    /// Silhouette edges found.
    SilhouetteEdges,
    /// Supersampled pixels resolved.
    Resolves,
}

impl Stage {
    /// Every stage, in report order.
    pub const ALL: [Stage; 14] = [
        Stage::NormalsGenerated,
        Stage::NormalsTransformed,
        Stage::PositionsToWorld,
        Stage::VertexColors,
        Stage::Uvs,
        Stage::Lighting,
        Stage::TextureSamples,
        Stage::Fog,
        Stage::DepthShading,
        Stage::DepthClears,
        Stage::DepthTests,
        Stage::WireEdges,
        Stage::SilhouetteEdges,
        Stage::Resolves,
    ];
}

#[cfg(debug_assertions)]
thread_local! {
    static COUNTS: std::cell::Cell<[u64; Stage::ALL.len()]> =
        const { std::cell::Cell::new([0; Stage::ALL.len()]) };
}

/// Adds `n` units of work to a stage (debug builds only).
#[inline(always)]
pub fn add(stage: Stage, n: u64) {
    #[cfg(debug_assertions)]
    COUNTS.with(|c| {
        let mut v = c.get();
        v[stage as usize] += n;
        c.set(v);
    });
    #[cfg(not(debug_assertions))]
    let _ = (stage, n);
}

/// The counts so far on this thread (all zero in release builds).
#[must_use]
pub fn snapshot() -> Counts {
    #[cfg(debug_assertions)]
    return Counts(COUNTS.with(std::cell::Cell::get));
    #[cfg(not(debug_assertions))]
    Counts([0; Stage::ALL.len()])
}

/// Resets this thread's counts.
pub fn reset() {
    #[cfg(debug_assertions)]
    COUNTS.with(|c| c.set([0; Stage::ALL.len()]));
}

/// Whether counting is compiled in.
#[must_use]
pub const fn enabled() -> bool {
    cfg!(debug_assertions)
}

/// A snapshot of the counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts(pub [u64; Stage::ALL.len()]);

impl Counts {
    /// Work done in a stage.
    #[must_use]
    pub fn get(&self, stage: Stage) -> u64 {
        self.0[stage as usize]
    }
}

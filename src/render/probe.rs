//! The probe: the raster state of one pixel, recomputed on demand.
//!
//! Nothing is recorded while rendering. Asked about a pixel, the probe re-runs the
//! per-triangle preparation for every triangle in draw order, keeps those whose
//! bounding box holds the pixel, evaluates them with the renderer's own per-pixel code
//! and replays the depth test. Its answers therefore equal what the renderer did
//! (the tests check every pixel of a frame). A triangle drawn unclipped whose box
//! misses the pixel is passed over after a box test of its snapped vertices, which is
//! the test set-up makes, so probing a large mesh stays fast.

use super::prepare::{Projected, prepare_projected, project_vertices};
use super::{DrawOptions, PixelEval, Prepared, VertexCache};
use crate::raster::depth::DEPTH_CLEAR;
use crate::raster::interp::Varying;
use crate::raster::traverse::{BlockClass, DEFAULT_BLOCK, block_containing, classify_block};
use crate::raster::{Setup, Target};

/// Depth-test outcome of one covered fragment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DepthOutcome {
    /// Not covered: no test.
    NotCovered,
    /// Passed against the stored value.
    Passed { against: f32 },
    /// Failed against the stored value.
    Failed { against: f32 },
}

/// One triangle's state at the probed pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeRecord<V> {
    /// Mesh triangle index and clipped piece.
    pub triangle: u32,
    pub piece: u8,
    pub clipped: bool,
    /// The triangle's setup: I/J, bias, doubled area, winding, box and the edge
    /// values at its first pixel.
    pub setup: Setup,
    pub eval: PixelEval,
    pub depth: DepthOutcome,
    /// Classification of the pixel's block by the `block` traversal (q = 8).
    pub block: BlockClass,
    /// Interpolated varyings as the shader receives them (for the shading value): for
    /// a [`Varying::PROJECTIVE`] varying under perspective, `attribute/w`.
    pub varying: V,
}

impl<V> ProbeRecord<V> {
    /// The same record with its varyings replaced by `f(varying)`.
    #[must_use]
    pub fn map<U>(self, f: impl FnOnce(V) -> U) -> ProbeRecord<U> {
        ProbeRecord {
            triangle: self.triangle,
            piece: self.piece,
            clipped: self.clipped,
            setup: self.setup,
            eval: self.eval,
            depth: self.depth,
            block: self.block,
            varying: f(self.varying),
        }
    }
}

/// Everything the probe found at a pixel, in draw order.
#[derive(Clone, Debug, PartialEq)]
pub struct Probe<V> {
    pub x: u32,
    pub y: u32,
    pub records: Vec<ProbeRecord<V>>,
    /// Index into `records` of the fragment that is in the framebuffer, if any.
    pub winner: Option<usize>,
    /// The depth buffer value after the frame.
    pub final_depth: f32,
}

/// Probes pixel `(x, y)` of a frame drawn from `cache`/`indices` with these options.
#[must_use]
pub fn probe<V: Varying>(
    cache: &VertexCache<V>,
    indices: &[u32],
    target: Target,
    opts: &DrawOptions,
    x: u32,
    y: u32,
) -> Probe<V> {
    probe_from(cache, indices, target, opts, x, y, DEPTH_CLEAR)
}

/// [`probe`] for a draw that starts with `stored` in the depth buffer at the pixel
/// (the depth left by earlier draws of the frame).
#[must_use]
pub fn probe_from<V: Varying>(
    cache: &VertexCache<V>,
    indices: &[u32],
    target: Target,
    opts: &DrawOptions,
    x: u32,
    y: u32,
    stored: f32,
) -> Probe<V> {
    let mut projected = Vec::new();
    project_vertices(cache, target, &mut projected);
    probe_projected(cache, &projected, indices, target, opts, (x, y), stored)
}

/// [`probe_from`] with the vertices of `cache` already projected for `target`
/// ([`project_vertices`]), as a caller probing many pixels of one frame keeps them.
/// Each vertex projected once gives the set-ups the threaded renderer makes, and lets
/// the many triangles whose box misses the pixel cost a box test.
#[must_use]
pub fn probe_projected<V: Varying>(
    cache: &VertexCache<V>,
    projected: &[Projected],
    indices: &[u32],
    target: Target,
    opts: &DrawOptions,
    (x, y): (u32, u32),
    stored: f32,
) -> Probe<V> {
    let (depth_state, interpolation) = (opts.depth, opts.interpolation);
    let mut out = Probe {
        x,
        y,
        records: Vec::new(),
        winner: None,
        final_depth: stored,
    };
    if x >= target.width || y >= target.height {
        return out;
    }
    let mut stored = stored;
    for (t, idx) in indices.chunks_exact(3).enumerate() {
        let get = |i: u32| projected.get(i as usize).copied();
        if let (Some(a), Some(b), Some(c)) = (get(idx[0]), get(idx[1]), get(idx[2]))
            && Projected::box_misses([a, b, c], x, y)
        {
            continue;
        }
        let t = t as u32;
        let _ = prepare_projected(
            cache,
            Some(projected),
            indices,
            t,
            target,
            opts,
            &mut |p: &Prepared<V>| {
                let s = &p.setup;
                if !s.bbox.contains(x, y) {
                    return;
                }
                let eval = p.eval(x, y);
                let depth = if !eval.covered {
                    DepthOutcome::NotCovered
                } else if depth_state.func.passes(eval.depth, stored) {
                    let against = stored;
                    if depth_state.write {
                        stored = eval.depth;
                    }
                    out.winner = Some(out.records.len());
                    DepthOutcome::Passed { against }
                } else {
                    DepthOutcome::Failed { against: stored }
                };
                let block = block_containing(s, DEFAULT_BLOCK, x, y)
                    .map_or(BlockClass::Outside, |r| classify_block(s, r));
                out.records.push(ProbeRecord {
                    triangle: p.triangle,
                    piece: p.piece,
                    clipped: p.clipped,
                    setup: *s,
                    eval,
                    depth,
                    block,
                    varying: p.varyings(&eval, interpolation),
                });
            },
        );
    }
    out.final_depth = stored;
    out
}

//! Per-vertex and per-triangle work: the vertex cache and transform, each vertex's
//! projection ([`Projected`]), the hand-off to clipping, and the set-up of each piece
//! into a [`Prepared`] triangle. The renderer and the probe share all of it, so the
//! probe sees the triangles the renderer drew.

use std::ops::{Add, Mul, Sub};

use glam::Vec4;

use super::options::{Cull, DrawOptions, DrawStats};
use super::shader::Shader;
use crate::raster::clip::{
    ClipOutcome, ClipVertex, classify_codes, clip_straddling, guard_band_ndc, outcode,
};
use crate::raster::interp::{Interpolation, Varying};
use crate::raster::setup::{box_holds, box_rows, signed_area2, snap};
use crate::raster::{SUBPIXEL_BITS, Setup, Target};
use crate::simd::each3;

mod lanes;
pub(crate) use lanes::{one_per_vertex, project_into};

/// A triangle after clipping and projection, ready to rasterize. Vertex arrays are in
/// setup order (A, B, C after any winding flip).
#[derive(Clone, Copy, Debug)]
pub struct Prepared<V> {
    /// Index of the mesh triangle it came from.
    pub triangle: u32,
    /// Which piece of the clipped polygon (0 when unclipped).
    pub piece: u8,
    /// Whether clipping cut the original triangle.
    pub clipped: bool,
    pub setup: Setup,
    /// NDC depth of vertex A (see [`Prepared::zc`]).
    pub z: f32,
    /// The varyings in the form the draw's interpolation mode reads: relative (see
    /// [`Varying::relative`]), or for a [`Varying::PROJECTIVE`] varying under
    /// perspective the vertex values times `pc` ([`Varying::projective_form`]),
    /// weighted by the edge values. So a record is read in the mode it was prepared
    /// for.
    pub rel: [V; 3],
    /// `1 / area2`, rounded once to f32: barycentrics are `F · inv_area2`.
    pub inv_area2: f32,
    /// Depth per unit of B's and C's edge value: `(z_B − z_A) / area2` and
    /// `(z_C − z_A) / area2`, so depth is `z_A + F_B·zc[0] + F_C·zc[1]` (two fused
    /// multiply-adds, exactly `z_A` at A).
    pub zc: [f32; 2],
    /// `(1/w_i) / area2` per vertex: the perspective numerators are `F_i · pc[i]`.
    pub pc: [f32; 3],
    /// `F0e − 256·G0e` per edge (see [`Setup::reduced_edge`]): the same at every pixel,
    /// so `F0e = 256·G0e + edge_rem[e]` rebuilds the exact edge value from the lanes of
    /// the `wide` traversal.
    pub edge_rem: [f32; 3],
}

/// Reusable per-draw storage: transformed vertices, and their projections when the
/// vertex stage made them too. Kept by the caller so a steady viewer allocates nothing
/// per frame.
#[derive(Debug)]
pub struct VertexCache<V> {
    pub(crate) verts: Vec<ClipVertex<V>>,
    /// The vertices projected for `projected_for` ([`transform_projected`]).
    pub(crate) projected: Vec<Projected>,
    /// The target `projected` is for; `None` when the vertices were transformed alone.
    pub(crate) projected_for: Option<Target>,
}

impl<V> Default for VertexCache<V> {
    fn default() -> Self {
        Self {
            verts: Vec::new(),
            projected: Vec::new(),
            projected_for: None,
        }
    }
}

impl<V> VertexCache<V> {
    /// The vertices' projections for `target`, if the vertex stage made them.
    #[must_use]
    pub fn projections(&self, target: Target) -> Option<&[Projected]> {
        (self.projected_for == Some(target)).then_some(&self.projected[..])
    }
}

/// Result of preparing one mesh triangle.
pub enum PrepareOutcome {
    Rejected,
    Culled,
    Drawn { clipped: bool },
}

impl PrepareOutcome {
    /// Counts the triangle in `stats`, `n` times: 1, or 0 or 1 for the strips, which
    /// count a triangle only in the strip that owns it, without a branch (see
    /// `tiles::strips`).
    #[inline(always)]
    pub fn count(self, stats: &mut DrawStats, n: u64) {
        stats.triangles += n;
        match self {
            PrepareOutcome::Rejected => stats.rejected += n,
            PrepareOutcome::Culled => stats.culled += n,
            PrepareOutcome::Drawn { clipped } => {
                stats.drawn += n;
                stats.clipped += n * u64::from(clipped);
            }
        }
    }
}

/// Transforms every vertex once into the cache.
pub fn transform<S: Shader>(shader: &S, vertex_count: usize, cache: &mut VertexCache<S::Varying>) {
    cache.projected_for = None;
    cache.verts.clear();
    cache
        .verts
        .extend((0..vertex_count).map(|i| clip_vertex(shader, i)));
}

/// Vertex `i` through `shader`'s vertex stage: what every form of [`transform`] stores.
#[inline(always)]
pub(crate) fn clip_vertex<S: Shader>(shader: &S, i: usize) -> ClipVertex<S::Varying> {
    let (pos, var) = shader.vertex(i as u32);
    ClipVertex { pos, var }
}

/// Vertices `first..first + verts.len()` through `shader`'s vertex stage, into the
/// last frame's `verts` in place: a piece of a steady frame's parallel vertex stage.
#[inline(always)]
pub(crate) fn transform_in_place<S: Shader>(
    shader: &S,
    first: usize,
    verts: &mut [ClipVertex<S::Varying>],
) {
    for (j, v) in verts.iter_mut().enumerate() {
        *v = clip_vertex(shader, first + j);
    }
}

/// [`transform`] and [`project_vertices`] for `target` in one pass: each block of
/// vertices is projected while it is in the L1 cache, instead of being read back from
/// memory once a large mesh has pushed it out of the processor's caches (a
/// million-triangle mesh's vertices are some 25 MB).
pub fn transform_projected<S: Shader>(
    shader: &S,
    vertex_count: usize,
    cache: &mut VertexCache<S::Varying>,
    target: Target,
) {
    cache.verts.clear();
    cache.verts.reserve(vertex_count);
    // Blocks small enough that their vertices are still in the L1 cache when projected.
    const BLOCK: usize = 64;
    for (b, out) in one_per_vertex(&mut cache.projected, vertex_count)
        .chunks_mut(BLOCK)
        .enumerate()
    {
        let first = b * BLOCK;
        cache
            .verts
            .extend((first..first + out.len()).map(|i| clip_vertex(shader, i)));
        project_into(&cache.verts[first..], target, out);
    }
    cache.projected_for = Some(target);
}

/// Receives the pieces [`prepare`] makes of a triangle. A trait rather than a closure
/// so the renderer's per-triangle work inlines into its caller (closures are compiled
/// on their own, without the caller's target features).
pub trait EmitPiece<V> {
    fn piece(&mut self, p: &Prepared<V>);

    /// [`EmitPiece::piece`] with the piece's screen positions (pixels, before
    /// snapping, setup order), which the record does not keep: for the few callers
    /// that want them.
    #[inline(always)]
    fn piece_on_screen(&mut self, p: &Prepared<V>, screen: &[[f32; 2]; 3]) {
        let _ = screen;
        self.piece(p);
    }
}

impl<V, F: FnMut(&Prepared<V>)> EmitPiece<V> for F {
    #[inline(always)]
    fn piece(&mut self, p: &Prepared<V>) {
        self(p);
    }
}

/// A vertex's clip outcode and projection, computed once per vertex per draw (most
/// vertices are shared by about six triangles) and identically for clipped vertices,
/// so a triangle set up from these is bit for bit the triangle set up from scratch.
#[derive(Clone, Copy, Debug, Default)]
pub struct Projected {
    /// See [`outcode`].
    out: u8,
    /// Whether both screen coordinates snapped (finite and within the guard band).
    snapped: bool,
    inv_w: f32,
    /// Screen position in pixels, before snapping.
    screen: [f32; 2],
    /// NDC depth.
    z: f32,
    /// Snapped screen position in subpixels.
    fixed: [i64; 2],
}

impl Projected {
    /// Classifies and projects a clip-space position for a target.
    #[inline(always)]
    #[must_use]
    pub fn of(pos: Vec4, target: Target, guard: [f32; 2]) -> Self {
        let (fw, fh) = (target.width as f32, target.height as f32);
        let inv_w = 1.0 / pos.w;
        let p = pos * inv_w;
        let screen = ndc_to_screen([p.x, p.y], [fw, fh]);
        let (sx, sy) = (snap(f64::from(screen[0])), snap(f64::from(screen[1])));
        Self {
            out: outcode(pos, guard),
            snapped: sx.is_some() && sy.is_some(),
            inv_w,
            screen,
            z: pos.z * inv_w,
            fixed: [sx.unwrap_or(0), sy.unwrap_or(0)],
        }
    }

    /// The first and last row of the box of a triangle with this vertex alone
    /// ([`box_rows`], unclamped to the target), if the vertex is inside every plane
    /// and snapped; `None` if a triangle with it needs clipping or is rejected. A box
    /// is monotone in its vertices, so a triangle drawn unclipped has the rows from
    /// the least first row to the greatest last row of its three vertices.
    #[inline(always)]
    #[must_use]
    pub(crate) fn rows(&self) -> Option<[i64; 2]> {
        let inside = classify_codes([self.out; 3]) == ClipOutcome::Inside;
        (inside && self.snapped).then(|| box_rows(&[self.fixed; 3]))
    }

    /// Whether a triangle of these vertices surely leaves pixel `(x, y)` alone: it is
    /// drawn unclipped (inside every plane, every vertex snapped) and its box misses
    /// the pixel. Exact, as set-up boxes the same snapped vertices; a triangle that
    /// needs clipping answers `false` and is left to [`prepare_projected`].
    #[inline]
    #[must_use]
    pub fn box_misses(pv: [Self; 3], x: u32, y: u32) -> bool {
        classify_codes(each3!(|i| pv[i].out)) == ClipOutcome::Inside
            && pv.iter().all(|p| p.snapped)
            && !box_holds(&each3!(|i| pv[i].fixed), x, y)
    }
}

/// Maps NDC `x, y` ∈ [−1, 1] to screen pixels in a target of `size` pixels: x to
/// `[0, width]` left to right, y to `[height, 0]` (screen space is y-down). The
/// renderer, the wireframes, the scene outlines and the accuracy references all map
/// through this, so they agree to the bit (generic so the f64 references use the same
/// operations).
#[inline(always)]
#[must_use]
pub fn ndc_to_screen<T>(ndc: [T; 2], size: [T; 2]) -> [T; 2]
where
    T: Copy + From<f32> + Add<Output = T> + Sub<Output = T> + Mul<Output = T>,
{
    let half = T::from(0.5);
    [
        (ndc[0] * half + half) * size[0],
        (half - ndc[1] * half) * size[1],
    ]
}

/// Projects every vertex of `cache` for `target` into `out` (reusing its storage).
pub fn project_vertices<V>(cache: &VertexCache<V>, target: Target, out: &mut Vec<Projected>) {
    project_into(&cache.verts, target, one_per_vertex(out, cache.verts.len()));
}

/// Clips, projects and sets up mesh triangle `t`, calling `emit` for each piece that
/// reaches the rasterizer. Shared by the renderer and the probe.
#[inline(always)]
pub fn prepare<V: Varying>(
    cache: &VertexCache<V>,
    indices: &[u32],
    t: u32,
    target: Target,
    opts: &DrawOptions,
    emit: &mut impl EmitPiece<V>,
) -> PrepareOutcome {
    prepare_projected(cache, None, indices, t, target, opts, emit)
}

/// [`prepare`] with the vertices' projections from [`project_vertices`] (for this
/// cache and target) when given, else computed here: the result is the same.
#[inline(always)]
pub fn prepare_projected<V: Varying>(
    cache: &VertexCache<V>,
    projected: Option<&[Projected]>,
    indices: &[u32],
    t: u32,
    target: Target,
    opts: &DrawOptions,
    emit: &mut impl EmitPiece<V>,
) -> PrepareOutcome {
    let base = t as usize * 3;
    let Some(idx) = indices.get(base..base + 3) else {
        return PrepareOutcome::Rejected;
    };
    // By reference: a triangle inside every plane reads only the varyings, once it
    // knows their order (`setup_piece`).
    let fetch = |i: u32| cache.verts.get(i as usize);
    let (Some(a), Some(b), Some(c)) = (fetch(idx[0]), fetch(idx[1]), fetch(idx[2])) else {
        return PrepareOutcome::Rejected;
    };
    let tri = [a, b, c];
    let guard = guard_band_ndc(target.width, target.height);
    let pv = match projected {
        Some(p) => match (
            p.get(idx[0] as usize),
            p.get(idx[1] as usize),
            p.get(idx[2] as usize),
        ) {
            (Some(&pa), Some(&pb), Some(&pc)) => [pa, pb, pc],
            _ => return PrepareOutcome::Rejected,
        },
        None => each3!(|i| Projected::of(tri[i].pos, target, guard)),
    };
    let outcome = classify_codes(each3!(|i| pv[i].out));
    let clipped = outcome == ClipOutcome::Clipped;
    let mut seen = Seen::default();
    match outcome {
        ClipOutcome::Rejected => return PrepareOutcome::Rejected,
        ClipOutcome::Inside => {
            let var = each3!(|i| &tri[i].var);
            seen.add(setup_piece((t, 0, clipped), pv, var, target, opts, emit));
        }
        ClipOutcome::Clipped => {
            let Some(poly) = clip_straddling([*a, *b, *c], guard) else {
                return PrepareOutcome::Rejected;
            };
            for (i, tri) in poly.triangles().enumerate() {
                let pv = each3!(|i| Projected::of(tri[i].pos, target, guard));
                let var = each3!(|i| &tri[i].var);
                seen.add(setup_piece((t, i, clipped), pv, var, target, opts, emit));
            }
        }
    }
    match (seen.drawn, seen.culled) {
        (true, _) => PrepareOutcome::Drawn { clipped },
        (false, true) => PrepareOutcome::Culled,
        (false, false) => PrepareOutcome::Rejected,
    }
}

/// What became of a triangle's pieces.
#[derive(Default)]
struct Seen {
    drawn: bool,
    culled: bool,
}

impl Seen {
    /// Notes what became of a piece.
    #[inline(always)]
    fn add(&mut self, piece: Piece) {
        match piece {
            Piece::Drawn => self.drawn = true,
            Piece::Culled => self.culled = true,
            Piece::Rejected => {}
        }
    }
}

/// What became of one piece of a triangle.
enum Piece {
    /// Set up and handed to the [`EmitPiece`].
    Drawn,
    Culled,
    Rejected,
}

/// Sets up one (possibly clipped) triangle whose vertices all have w > 0, from their
/// projections, and hands it to `emit`. The record is built where `emit` reads it:
/// returned in an enum and then passed on, it would be partly copied once more.
#[inline(always)]
fn setup_piece<V: Varying>(
    (t, piece, clipped): (u32, usize, bool),
    pv: [Projected; 3],
    var: [&V; 3],
    target: Target,
    opts: &DrawOptions,
    emit: &mut impl EmitPiece<V>,
) -> Piece {
    // Not `iter().all(..)`: it stays out of line in the AVX2 draw loop.
    if !(pv[0].snapped && pv[1].snapped && pv[2].snapped) {
        return Piece::Rejected;
    }
    let fixed = each3!(|i| pv[i].fixed);
    // Counter-clockwise in NDC (y-up) is negative area in y-down screen space. Culled
    // by the sign alone, before the rest of the set-up: a culled draw skips half of it.
    if opts.cull == Cull::Back && signed_area2(&fixed) > 0 {
        return Piece::Culled;
    }
    let Ok(setup) = Setup::from_snapped(fixed, target) else {
        return Piece::Rejected;
    };
    let order = |i: usize| if setup.flipped && i > 0 { 3 - i } else { i };
    let var = each3!(|i| *var[order(i)]);
    // The raw value at the box's origin less 256 times the reduced one.
    let g = setup.reduced_at_origin();
    let edge_rem = each3!(|e| (setup.origin[e] - setup.bias[e] - (g[e] << SUBPIXEL_BITS)) as f32);
    let z = each3!(|i| pv[order(i)].z);
    let inv_w = each3!(|i| pv[order(i)].inv_w);
    let screen = each3!(|i| pv[order(i)].screen);
    // In f64, rounded once: the per-pixel terms then carry one rounding each.
    let ia = 1.0 / setup.area2 as f64;
    let slope = |i: usize| ((f64::from(z[i]) - f64::from(z[0])) * ia) as f32;
    let zc = [slope(1), slope(2)];
    let pc = each3!(|i| (f64::from(inv_w[i]) * ia) as f32);
    // The one form of the varyings the draw's pixels read.
    let rel = if V::PROJECTIVE && opts.interpolation == Interpolation::Perspective {
        V::projective_form(&var, pc)
    } else {
        V::relative(&var[0], &var[1], &var[2])
    };
    let prepared = Prepared {
        triangle: t,
        piece: piece as u8,
        clipped,
        setup,
        z: z[0],
        zc,
        pc,
        rel,
        inv_area2: ia as f32,
        edge_rem,
    };
    emit.piece_on_screen(&prepared, &screen);
    Piece::Drawn
}

#[cfg(test)]
pub(crate) mod tests {
    use glam::{Mat4, Vec3};

    use super::*;
    use crate::camera::Camera;
    use crate::mesh::Mesh;
    use crate::render::shaders::Lambert;

    /// A Lambert shader for `mesh` seen from `eye` by the default camera into `target`.
    pub(crate) fn lambert_from(mesh: &Mesh, eye: Vec3, target: Target) -> Lambert<'_> {
        let cam = Camera {
            eye,
            ..Camera::default()
        };
        let view_proj = cam.projection(target.width, target.height, 1.0) * cam.view();
        Lambert::new(mesh, Mat4::IDENTITY, view_proj)
    }

    /// The vertex stage with its projections made in the same pass gives the vertices
    /// of [`transform`] and the projections of [`project_vertices`], bit for bit, and
    /// a later [`transform`] forgets them.
    #[test]
    fn projecting_in_the_vertex_pass_changes_nothing() {
        let mesh = Mesh::teapot();
        let target = Target::new(123, 77);
        // Far, and so near that vertices leave the frustum and the guard band.
        for eye in [Vec3::new(0.3, 0.5, 3.0), Vec3::new(0.0, 0.2, 0.4)] {
            let shader = lambert_from(&mesh, eye, target);
            let n = mesh.positions.len();
            let (mut apart, mut fused) = (VertexCache::default(), VertexCache::default());
            transform(&shader, n, &mut apart);
            let mut projected = Vec::new();
            project_vertices(&apart, target, &mut projected);
            transform_projected(&shader, n, &mut fused, target);
            assert_eq!(format!("{:?}", apart.verts), format!("{:?}", fused.verts));
            let pv = fused.projections(target).expect("made with the vertices");
            assert_eq!(format!("{projected:?}"), format!("{pv:?}"));
            assert!(apart.projections(target).is_none());
            assert!(fused.projections(Target::new(124, 77)).is_none());
            transform(&shader, n, &mut fused);
            assert!(fused.projections(target).is_none());
        }
    }
}

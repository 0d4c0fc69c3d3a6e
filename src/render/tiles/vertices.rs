//! The vertex stage of a small mesh on the calling thread and one other, each taking
//! pieces of the vertices until none is left (a mesh under
//! `Renderer::min_parallel_vertices`, which rayon's split would make wait for a
//! sleeping thread).

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use super::VERTEX_JOB;
use super::queue::lock;
use crate::raster::Target;
use crate::render::prepare::{
    Projected, VertexCache, one_per_vertex, project_into, transform_in_place,
};
use crate::render::shader::Shader;

/// The most pieces [`project_claimed`] cuts the vertices into.
const PIECES: usize = 64;

/// The projections of `cache`'s vertices for `target`: those its vertex stage made,
/// or else made now into `store` by [`project_claimed`]. What every threaded draw
/// walks from.
pub(in crate::render) fn projections<'a, V: Sync>(
    cache: &'a VertexCache<V>,
    target: Target,
    store: &'a mut Vec<Projected>,
) -> &'a [Projected] {
    match cache.projections(target) {
        Some(pv) => pv,
        None => {
            project_claimed(cache, target, store);
            store
        }
    }
}

/// Projects every vertex of `cache` for `target` into `out` (as
/// [`crate::render::project_vertices`] does), in pieces claimed by the calling thread
/// and one other of the current pool ([`claimed`]).
fn project_claimed<V: Sync>(cache: &VertexCache<V>, target: Target, out: &mut Vec<Projected>) {
    let verts = &cache.verts[..];
    let out = one_per_vertex(out, verts.len());
    let piece = piece_len(verts.len());
    claimed(out.chunks_mut(piece), |k, dst: &mut [Projected]| {
        let first = k * piece;
        project_into(&verts[first..first + dst.len()], target, dst);
    });
}

/// The vertex stage of a steady frame (`cache` holds `vertex_count` vertices from the
/// last) in pieces claimed by the calling thread and one other of the current pool
/// ([`claimed`]): each piece transformed by `shader` in place and projected for
/// `target` while it is in the cache, as [`crate::render::transform_projected`] does.
/// Returns false, doing nothing, for another vertex count.
pub(in crate::render) fn transform_claimed<S: Shader>(
    shader: &S,
    vertex_count: usize,
    cache: &mut VertexCache<S::Varying>,
    target: Target,
) -> bool {
    if cache.verts.len() != vertex_count {
        return false;
    }
    let piece = piece_len(vertex_count);
    let projected = one_per_vertex(&mut cache.projected, vertex_count);
    let pieces = cache
        .verts
        .chunks_mut(piece)
        .zip(projected.chunks_mut(piece));
    claimed(pieces, |k, (verts, out)| {
        transform_in_place(shader, k * piece, verts);
        project_into(verts, target, out);
    });
    cache.projected_for = Some(target);
    true
}

/// Vertices per piece for `n`: at least [`VERTEX_JOB`], at most [`PIECES`] pieces.
fn piece_len(n: usize) -> usize {
    VERTEX_JOB.max(n.div_ceil(PIECES))
}

/// Runs `f(k, piece)` for each of `pieces` (at most [`PIECES`]), the calling thread
/// and one other of the current pool taking the next until none is left.
///
/// Claimed rather than split in halves: the other thread, often woken from sleep by
/// the call, takes only what is left when it arrives, so the calling thread waits at
/// most for the piece in its hands (rayon's split made it wait for a stolen half);
/// and the other thread is then awake for the draw's next step.
fn claimed<T: Send>(pieces: impl Iterator<Item = T>, f: impl Fn(usize, T) + Sync) {
    let slots: [Mutex<Option<T>>; PIECES] = std::array::from_fn(|_| Mutex::new(None));
    let mut pieces = pieces;
    for (slot, p) in slots.iter().zip(&mut pieces) {
        *lock(slot) = Some(p);
    }
    debug_assert!(pieces.next().is_none(), "more than {PIECES} pieces");
    let next = AtomicUsize::new(0);
    let work = || {
        loop {
            let k = next.fetch_add(1, Ordering::Relaxed);
            let Some(p) = slots.get(k).and_then(|s| lock(s).take()) else {
                return;
            };
            f(k, p);
        }
    };
    rayon::join(work, work);
}

#[cfg(test)]
mod tests {
    use glam::Vec4;

    use super::project_claimed;
    use crate::raster::Target;
    use crate::raster::clip::ClipVertex;
    use crate::render::prepare::VertexCache;
    use crate::render::{Projected, project_vertices};

    /// The vertex stage on two threads (`Renderer::transform`), split by rayon (every
    /// mesh a parallel one) and in claimed pieces (the default for the bunny's 1 839
    /// vertices), on a first frame and on later ones that reuse its vertices in place,
    /// gives one thread's vertices and projections, for the bunny seen far and so near
    /// that vertices leave the frustum and the guard band.
    #[test]
    fn vertex_stage_on_threads_equals_one_threads_frame_after_frame() {
        use glam::Vec3;

        use crate::mesh::Mesh;
        use crate::render::prepare::tests::lambert_from;
        use crate::render::{MIN_PARALLEL_VERTICES, Renderer, transform};

        let mesh = Mesh::bunny();
        let target = Target::new(123, 77);
        let n = mesh.positions.len();
        assert!(n < MIN_PARALLEL_VERTICES);
        for min_parallel in [0, MIN_PARALLEL_VERTICES] {
            let mut r = Renderer::new(target);
            r.set_threads(2);
            r.min_parallel_vertices = min_parallel;
            let mut shared = VertexCache::default();
            let eyes = [
                Vec3::new(0.3, 0.5, 3.0),
                Vec3::new(0.0, 0.2, 0.4),
                Vec3::Z * 2.0,
            ];
            for (k, eye) in eyes.into_iter().enumerate() {
                let shader = lambert_from(&mesh, eye, target);
                let mut one = VertexCache::default();
                transform(&shader, n, &mut one);
                let mut projected = Vec::new();
                project_vertices(&one, target, &mut projected);
                r.transform(&shader, n, &mut shared);
                assert_eq!(format!("{:?}", one.verts), format!("{:?}", shared.verts));
                match shared.projections(target) {
                    Some(pv) => assert_eq!(format!("{projected:?}"), format!("{pv:?}"), "{eye}"),
                    // The claimed pieces start from the second frame (the vertices are
                    // made in place); the first is transformed alone.
                    None => assert!(min_parallel > 0 && k == 0, "{min_parallel} {k}"),
                }
            }
        }
    }

    /// Every vertex gets the projection one thread gives it, for meshes of no vertex,
    /// fewer than a piece, and pieces that do not divide the count, from a pool of
    /// two threads and from outside any pool.
    #[test]
    fn claimed_projections_equal_one_threads() {
        let target = Target::new(37, 23);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("a pool");
        for n in [0, 1, 5, 511, 512, 513, 4099, 40_000] {
            let verts = (0..n)
                .map(|i| {
                    let t = i as f32 * 0.37;
                    let w = 0.2 + (t * 0.11).sin().abs() * 3.0;
                    ClipVertex {
                        pos: Vec4::new(t.sin() * 1.3 * w, t.cos() * 1.2 * w, 0.5 * w, w),
                        var: (),
                    }
                })
                .collect();
            let cache = VertexCache::<()> {
                verts,
                ..VertexCache::default()
            };
            let mut one = Vec::new();
            project_vertices(&cache, target, &mut one);
            // Debug prints each float exactly: equal text, equal bits.
            let one = format!("{one:?}");
            let mut shared = vec![Projected::default(); 3];
            pool.install(|| project_claimed(&cache, target, &mut shared));
            assert_eq!(format!("{shared:?}"), one, "{n} vertices on the pool");
            project_claimed(&cache, target, &mut shared);
            assert_eq!(format!("{shared:?}"), one, "{n} vertices off any pool");
        }
    }
}

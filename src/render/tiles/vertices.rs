//! The projections of a threaded draw whose vertices were transformed on the calling
//! thread alone (a mesh under `Renderer::min_parallel_vertices`).

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use super::VERTEX_JOB;
use super::queue::lock;
use crate::raster::Target;
use crate::render::prepare::{Projected, VertexCache, one_per_vertex, project_into};

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
/// [`crate::render::project_vertices`] does), the calling thread and one other of the
/// current pool taking pieces of at least [`VERTEX_JOB`] vertices until none is left.
///
/// Claimed rather than split in halves: the other thread, often woken from sleep by
/// the call, takes only what is left when it arrives, so the calling thread waits at
/// most for the piece in its hands (rayon's split made it wait for a stolen half);
/// and the other thread is then awake for the draw's next step.
fn project_claimed<V: Sync>(cache: &VertexCache<V>, target: Target, out: &mut Vec<Projected>) {
    let verts = &cache.verts[..];
    if verts.is_empty() {
        out.clear();
        return;
    }
    let out = one_per_vertex(out, verts.len());
    let piece = VERTEX_JOB.max(verts.len().div_ceil(PIECES));
    let slots: [Mutex<Option<&mut [Projected]>>; PIECES] =
        std::array::from_fn(|_| Mutex::new(None));
    for (slot, p) in slots.iter().zip(out.chunks_mut(piece)) {
        *lock(slot) = Some(p);
    }
    let next = AtomicUsize::new(0);
    let work = || {
        loop {
            let k = next.fetch_add(1, Ordering::Relaxed);
            let Some(dst) = slots.get(k).and_then(|s| lock(s).take()) else {
                return;
            };
            let first = k * piece;
            project_into(&verts[first..first + dst.len()], target, dst);
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

    /// The vertex stage on two threads (`Renderer::transform`), on a first frame and
    /// on later ones that reuse its vertices in place, gives one thread's vertices and
    /// projections, for the bunny seen far and so near that vertices leave the
    /// frustum and the guard band.
    #[test]
    fn vertex_stage_on_threads_equals_one_threads_frame_after_frame() {
        use glam::Vec3;

        use crate::mesh::Mesh;
        use crate::render::prepare::tests::lambert_from;
        use crate::render::{Renderer, transform};

        let mesh = Mesh::bunny();
        let target = Target::new(123, 77);
        let mut r = Renderer::new(target);
        r.set_threads(2);
        r.min_parallel_vertices = 0;
        let mut shared = VertexCache::default();
        let n = mesh.positions.len();
        for eye in [
            Vec3::new(0.3, 0.5, 3.0),
            Vec3::new(0.0, 0.2, 0.4),
            Vec3::Z * 2.0,
        ] {
            let shader = lambert_from(&mesh, eye, target);
            let mut one = VertexCache::default();
            transform(&shader, n, &mut one);
            let mut projected = Vec::new();
            project_vertices(&one, target, &mut projected);
            r.transform(&shader, n, &mut shared);
            assert_eq!(format!("{:?}", one.verts), format!("{:?}", shared.verts));
            let pv = shared.projections(target).expect("made on the threads");
            assert_eq!(format!("{projected:?}"), format!("{pv:?}"), "{eye}");
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

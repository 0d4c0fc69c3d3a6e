//! Depth formats: the same depth test with different storage.
//!
//! `depth-f32` is the renderer's buffer (NDC z in [0, 1], `<`). `depth-unorm24` and
//! `depth-unorm16` store `round(z · (2^n − 1))` in integers and compare those.
//! `depth-f32-reversed` projects with reversed z (the projection's z row replaced by
//! `w − z`, so the near plane is 1 and the far plane 0), stores f32 and tests `>`:
//! floats are densest near 0, which is now the far distance, where the standard
//! mapping has the least precision. Each is a real depth pass: the pipeline's own
//! clipping, setup, `wide` traversal and per-pixel depth, then the format's store.

use glam::{Mat4, Vec3, Vec4};

use crate::raster::traverse::wide;
use crate::raster::{CoverageSink, Target};
use crate::render::{DrawOptions, EmitPiece, Prepared, Shader, VertexCache, prepare, transform};

/// One depth storage format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DepthFormat {
    F32,
    Unorm24,
    Unorm16,
    F32Reversed,
}

impl DepthFormat {
    /// Every format, in table order.
    pub const ALL: [DepthFormat; 4] = [
        DepthFormat::F32,
        DepthFormat::Unorm24,
        DepthFormat::Unorm16,
        DepthFormat::F32Reversed,
    ];

    /// The name in tables and CSV.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            DepthFormat::F32 => "depth-f32",
            DepthFormat::Unorm24 => "depth-unorm24",
            DepthFormat::Unorm16 => "depth-unorm16",
            DepthFormat::F32Reversed => "depth-f32-reversed",
        }
    }

    /// The projection this format draws with: reversed formats map near to 1.
    #[must_use]
    pub fn projection(self, view_proj: Mat4) -> Mat4 {
        match self {
            DepthFormat::F32Reversed => reverse_z() * view_proj,
            _ => view_proj,
        }
    }
}

/// `z' = w − z`: turns a [0, 1] depth projection into a reversed one.
#[must_use]
pub fn reverse_z() -> Mat4 {
    Mat4::from_cols(
        Vec4::new(1.0, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 1.0, 0.0, 0.0),
        Vec4::new(0.0, 0.0, -1.0, 0.0),
        Vec4::new(0.0, 0.0, 1.0, 1.0),
    )
}

/// Depth storage in a format, with its test. Buffers are reused across frames.
#[derive(Clone, Debug)]
pub enum DepthStorage {
    F32(Vec<f32>),
    Unorm(Vec<u32>, u32),
    Unorm16(Vec<u16>),
    Reversed(Vec<f32>),
}

impl DepthStorage {
    /// A cleared buffer of `len` pixels (far: 1.0, max, or 0.0 when reversed).
    #[must_use]
    pub fn new(format: DepthFormat, len: usize) -> Self {
        match format {
            DepthFormat::F32 => DepthStorage::F32(vec![1.0; len]),
            DepthFormat::Unorm24 => DepthStorage::Unorm(vec![(1 << 24) - 1; len], (1 << 24) - 1),
            DepthFormat::Unorm16 => DepthStorage::Unorm16(vec![u16::MAX; len]),
            DepthFormat::F32Reversed => DepthStorage::Reversed(vec![0.0; len]),
        }
    }

    /// Clears to the far value.
    pub fn clear(&mut self) {
        match self {
            DepthStorage::F32(d) => d.fill(1.0),
            DepthStorage::Unorm(d, max) => d.fill(*max),
            DepthStorage::Unorm16(d) => d.fill(u16::MAX),
            DepthStorage::Reversed(d) => d.fill(0.0),
        }
    }

    /// Tests depth `z` (this format's NDC depth) at pixel `i` and stores it if it
    /// passes.
    #[inline(always)]
    pub fn test_and_set(&mut self, i: usize, z: f32) -> bool {
        match self {
            DepthStorage::F32(d) => store_if(&mut d[i], z, |n, o| n < o),
            DepthStorage::Unorm(d, max) => store_if(&mut d[i], unorm(z, *max), |n, o| n < o),
            DepthStorage::Unorm16(d) => store_if(&mut d[i], unorm(z, 0xFFFF) as u16, |n, o| n < o),
            DepthStorage::Reversed(d) => store_if(&mut d[i], z, |n, o| n > o),
        }
    }
}

#[inline(always)]
fn store_if<T: Copy>(slot: &mut T, new: T, passes: impl Fn(T, T) -> bool) -> bool {
    let ok = passes(new, *slot);
    if ok {
        *slot = new;
    }
    ok
}

/// `round(z · max)` with z clamped to [0, 1] (NaN stores as far).
#[inline(always)]
fn unorm(z: f32, max: u32) -> u32 {
    let z = if z >= 0.0 {
        z.min(1.0)
    } else if z < 0.0 {
        0.0
    } else {
        1.0
    };
    (f64::from(z) * f64::from(max) + 0.5) as u32
}

/// Positions only, projected by a given matrix.
struct Positions<'a> {
    positions: &'a [Vec3],
    matrix: Mat4,
}

impl Shader for Positions<'_> {
    type Varying = ();
    #[inline(always)]
    fn vertex(&self, index: u32) -> (Vec4, ()) {
        let p = self
            .positions
            .get(index as usize)
            .copied()
            .unwrap_or(Vec3::ZERO);
        (self.matrix * p.extend(1.0), ())
    }
    fn fragment(&self, _: &()) -> Vec3 {
        Vec3::ONE
    }
}

/// A depth-only renderer: per pixel, the id of the object that last passed.
pub struct DepthPass {
    pub target: Target,
    pub storage: DepthStorage,
    /// Object id per pixel (`u32::MAX` where nothing passed).
    pub ids: Vec<u32>,
    cache: VertexCache<()>,
    /// Covered pixels tested in the last draws.
    pub fragments: u64,
}

impl DepthPass {
    /// A cleared pass for a target and format.
    #[must_use]
    pub fn new(target: Target, format: DepthFormat) -> Self {
        Self {
            target,
            storage: DepthStorage::new(format, target.len()),
            ids: vec![u32::MAX; target.len()],
            cache: VertexCache::default(),
            fragments: 0,
        }
    }

    /// Clears depth and ids.
    pub fn clear(&mut self) {
        self.storage.clear();
        self.ids.fill(u32::MAX);
        self.fragments = 0;
    }

    /// Draws a mesh (already projected by `matrix`, which must come from
    /// [`DepthFormat::projection`]) as object `id`.
    pub fn draw(&mut self, positions: &[Vec3], indices: &[u32], matrix: Mat4, id: u32) {
        let shader = Positions { positions, matrix };
        transform(&shader, positions.len(), &mut self.cache);
        let mut sink = Sink {
            storage: &mut self.storage,
            ids: &mut self.ids,
            width: self.target.width as usize,
            id,
            tri: None,
            fragments: 0,
        };
        let cache = std::mem::take(&mut self.cache);
        for t in 0..(indices.len() / 3) as u32 {
            prepare(
                &cache,
                indices,
                t,
                self.target,
                &DrawOptions::default(),
                &mut sink,
            );
        }
        self.fragments += sink.fragments;
        self.cache = cache;
    }
}

struct Sink<'a> {
    storage: &'a mut DepthStorage,
    ids: &'a mut [u32],
    width: usize,
    id: u32,
    tri: Option<Prepared<()>>,
    fragments: u64,
}

impl EmitPiece<()> for Sink<'_> {
    fn piece(&mut self, p: &Prepared<()>) {
        self.tri = Some(*p);
        let s = p.setup;
        wide(&s, self);
    }
}

impl CoverageSink for Sink<'_> {
    #[inline]
    fn pixel(&mut self, x: u32, y: u32) {
        let Some(t) = &self.tri else { return };
        let z = t.depth_at(x, y);
        let i = y as usize * self.width + x as usize;
        self.fragments += 1;
        if self.storage.test_and_set(i, z) {
            self.ids[i] = self.id;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unorm_rounds_and_clamps() {
        assert_eq!(unorm(0.0, 0xFFFF), 0);
        assert_eq!(unorm(1.0, 0xFFFF), 0xFFFF);
        assert_eq!(unorm(2.0, 0xFFFF), 0xFFFF);
        assert_eq!(unorm(-1.0, 0xFFFF), 0);
        assert_eq!(unorm(f32::NAN, 0xFFFF), 0xFFFF);
        assert_eq!(unorm(0.5, 0xFFFF), 32768);
    }

    #[test]
    fn reverse_z_maps_near_to_one_and_far_to_zero() {
        let c = crate::camera::Camera::default();
        let p = DepthFormat::F32Reversed.projection(c.projection(100, 100, 1.0));
        let at = |d: f32| {
            let v = p * Vec4::new(0.0, 0.0, -d, 1.0);
            v.z / v.w
        };
        assert!((at(c.near) - 1.0).abs() < 1e-6);
        assert!(at(c.far).abs() < 1e-6);
        assert!(at(1.0) > at(2.0));
    }
}

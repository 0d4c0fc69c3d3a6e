//! The shader interface: a vertex stage, a fragment stage, and the lane form of the
//! fragment stage that the draw loop calls per group of pixels.

use glam::{Vec3, Vec4};

use crate::raster::interp::Varying;
use crate::simd::{F32s, each3};

/// A shader: the vertex stage produces clip-space positions and varyings for vertex
/// indices, the fragment stage a linear RGB colour from interpolated varyings. The
/// varying type is fixed at compile time, so each shader gets its own pipeline.
///
/// `Sync`: a threaded draw's threads share the shader.
pub trait Shader: Sync {
    type Varying: Varying;
    /// Clip-space position and varyings of vertex `index`.
    fn vertex(&self, index: u32) -> (Vec4, Self::Varying);
    /// Colour of a fragment.
    fn fragment(&self, v: &Self::Varying) -> Vec3;

    /// Whether [`Shader::fragment_lanes`] is lane code of the shader's own rather than
    /// the default loop over single fragments. Only such shaders get the 16-lane
    /// AVX-512 copy of the draw loop (see [`super::DrawCopy::choose`]), and an inlined
    /// per-pixel fallback in the others: a loop over single fragments gains nothing
    /// from wider lanes, and only makes the build longer.
    const LANE_CODE: bool = false;

    /// Whether draws of this shader may run on the renderer's threads. A shader only
    /// ever drawn on one thread (the accuracy table's, which measures one thread's
    /// cost) says `false`, so the threaded copies of the draw loop are not compiled for
    /// it; a renderer with threads then draws it on the calling thread.
    const THREADED: bool = true;

    /// Colours of a group of fragments of one triangle at once (8 lanes per row of
    /// pixels, `F::ROWS` rows): lane `k` (for each set bit of `mask`) has weights
    /// `w[..][k]` for the triangle's varyings in relative form `rel` (see
    /// [`Varying::relative`]). The default interpolates and shades lane by lane;
    /// shaders override it with lane code that must give the same bits as
    /// [`Shader::fragment`] (the probe relies on it).
    #[inline(always)]
    fn fragment_lanes<F: F32s>(
        &self,
        rel: &[Self::Varying; 3],
        w: &[F; 3],
        mask: u32,
    ) -> ShadeLanes<F> {
        let w = each3!(|i| w[i].to_array());
        let mut out = [F::Arr::default(); 3];
        let mut m = mask;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            let lane = |a: &F::Arr| a.as_ref()[k];
            let v = Self::Varying::from_relative(rel, [lane(&w[0]), lane(&w[1]), lane(&w[2])]);
            let c = self.fragment(&v);
            for (o, c) in out.iter_mut().zip([c.x, c.y, c.z]) {
                o.as_mut()[k] = c;
            }
            m &= m - 1;
        }
        ShadeLanes::Rgb(each3!(|i| F::from_array(out[i])))
    }
}

/// The colours of a group of fragments from [`Shader::fragment_lanes`].
#[derive(Clone, Copy, Debug)]
pub enum ShadeLanes<F> {
    /// Red, green and blue lanes.
    Rgb([F; 3]),
    /// One value for all three channels: a grey shader says so, and the target
    /// converts one channel instead of three (the stored bits are the same as for
    /// `Rgb([g, g, g])`).
    Grey(F),
}

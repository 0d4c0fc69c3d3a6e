//! Exact triangle coverage: fixed-point edge functions and the traversals that walk them.
//!
//! # Conventions
//!
//! * **Screen space is y-down.** Pixel `(x, y)` covers `[x, x+1) × [y, y+1)` and is
//!   sampled at its centre `(x + 0.5, y + 0.5)`.
//! * **Fixed point.** Vertices are snapped to a grid of 1/256 px ([`SUBPIXEL_BITS`] = 8)
//!   by rounding to nearest (ties away from zero). Everything after snapping is
//!   integer arithmetic, so coverage is exact: it depends only on the snapped
//!   vertices, never on evaluation order or traversal.
//! * **Edge functions** (defined with the other terms in `docs/rasterization.md`): for
//!   the edge A→B,
//!   `I01 = Ay − By`, `J01 = Bx − Ax`, `K01 = Ax·By − Ay·Bx`, and
//!   `F01(P) = I01·Px + J01·Py + K01`; `F02` is B→C and `F03` is C→A. With the doubled
//!   signed area `area2 = (Bx−Ax)(Cy−Ay) − (By−Ay)(Cx−Ax)` made positive (B and C are
//!   swapped for the other winding) every `F` is ≥ 0 inside, and `F01 + F02 + F03 = area2`.
//!   The barycentric weights of A, B, C are `u = F02/area2`, `v = F03/area2`,
//!   `w = F01/area2`.
//! * **Fill rule: top-left** (Direct3D 10+). A centre exactly on an edge belongs to the
//!   triangle only if that edge is a *left* edge (it goes up, `b.y < a.y`) or a *top*
//!   edge (horizontal, going right). The other edges get a bias of −1, so the test is
//!   always `F ≥ 0`: two triangles sharing an edge never both cover, and never both miss,
//!   a centre on it.
//! * **Degenerate input.** Zero-area triangles cover nothing. A NaN or infinite
//!   coordinate discards the triangle.
//! * **Guard band.** Snapped coordinates are accepted up to ±[`GUARD_BAND_PX`] (2^20 px)
//!   from the origin, whatever the target size; all setup arithmetic is then provably
//!   within `i64`. A vertex beyond it discards the triangle (the 3D pipeline clips
//!   against the guard band before this point, so nothing visible is lost there).
//!   No pixel outside the target or the triangle's bounding box is ever visited.
//!
//! # Layout
//!
//! [`setup`] does everything that depends on the triangle alone; the traversals in
//! [`traverse`] (`scalar`, `planes`, `block`, `wide`) only walk its pixels and must
//! agree bit for bit. [`oracle`] is an independent i128 reference used by the tests and
//! the accuracy benchmark.

pub mod clip;
pub mod depth;
pub mod interp;
pub mod line;
pub mod oracle;
pub mod samples;
pub mod setup;
pub mod sink;
pub mod traverse;

pub use setup::{
    EDGE_NAMES, GUARD_BAND_PX, PixelRect, Reject, SUBPIXEL_BITS, SUBPIXEL_ONE, Setup, Target, snap,
};
pub use sink::{BitMask, CountGrid, CoverageSink};
pub use traverse::{BlockClass, Traversal};

//! Rendering a scene by its plan.
//!
//! An object's varyings are the attributes its plan needs
//! ([`VaryingSet`](crate::scene::plan::VaryingSet): normal, world position, colour,
//! uv), packed into an array of floats by a [`Layout`]
//! chosen when the scene is loaded. An attribute the plan leaves out is neither
//! computed in the vertex stage nor read by the fragment stage. The draw loop is
//! compiled for a few array widths ([`PACKED_WIDTHS`]), not for every attribute set,
//! which keeps the build small. An object whose plan is exactly the standard one
//! (per-pixel Lambert under the standard lights, depth-tested, nothing else: what a
//! model is) is drawn with the lane-code [`Lambert`](crate::render::shaders::Lambert)
//! instead ([`is_standard_lambert`]), one of a single flat colour with [`FlatColor`]
//! ([`is_flat_colour`]) and one of a colour interpolated from its vertices with
//! [`VertexColor`] ([`is_vertex_colour`]). The choice is made once per object (a
//! trait object per object, called once per frame); nothing is dispatched per vertex
//! or pixel.

mod color;
mod frame;
mod lambert;
mod pipeline;
mod shading;

pub use color::*;
pub use frame::*;
pub use lambert::*;
pub use pipeline::*;
pub use shading::*;

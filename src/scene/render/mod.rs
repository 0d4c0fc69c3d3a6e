//! Rendering a scene by its plan.
//!
//! An object's varyings are the attributes its plan needs ([`VaryingSet`]: normal,
//! world position, colour, uv), packed into an array of floats by a [`Layout`]
//! chosen when the scene is loaded. An attribute the plan leaves out is neither
//! computed in the vertex stage nor read by the fragment stage. The draw loop is
//! compiled for a few array widths ([`PACKED_WIDTHS`]), not for every attribute set,
//! which keeps the build small. The choice is made once per object (a trait object
//! per object, called once per frame); nothing is dispatched per vertex or pixel.

mod frame;
mod pipeline;
mod shading;

pub use frame::*;
pub use pipeline::*;
pub use shading::*;

//! Frequency-domain volume rendering core, after Totsuka & Levoy,
//! "Frequency Domain Volume Rendering", SIGGRAPH 1993.
//!
//! Once per volume: premultiply by the reciprocal of the interpolation
//! filter's spatial response, take the 3D Hartley transform and store the
//! real spectrum in 16-bit floats ([`spectrum`]). Per view: extract the 2D
//! slice through the origin perpendicular to the view ([`mod@slice`]) and
//! inverse-transform it ([`image`]); the result is the X-ray projection.
//! [`fn@render`] is the one entry point for a view, plain, progressive or
//! shaded ([`shading`]).
//!
//! Modules in the order data flows: [`num`] (number types) → [`dht`] →
//! [`filter`] → [`volume`] → [`spectrum`] → [`mod@slice`] → [`image`] →
//! [`shading`] → [`mod@render`]; each uses only modules before it (and
//! [`error`], [`geometry`]).
//!
//! `no_std`, no allocation: every buffer is provided by the caller, and every
//! fallible call returns [`Result`]. The crate never panics on data.
#![no_std]

pub mod dht;
pub mod error;
pub mod filter;
pub mod fvrs;
pub mod geometry;
pub mod image;
pub mod num;
pub mod render;
pub mod shading;
pub mod slice;
pub mod spectrum;
pub mod volume;

#[cfg(test)]
mod test_support;

pub use error::{Error, Result};
pub use half::f16;
pub use render::{render, Buffers, Request, Source};

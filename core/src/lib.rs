//! Frequency-domain volume rendering core, after Totsuka & Levoy,
//! "Frequency Domain Volume Rendering", SIGGRAPH 1993.
//!
//! Once per volume: premultiply by the reciprocal of the interpolation
//! filter's spatial response, take the 3D Hartley transform and store the
//! real spectrum in 16-bit floats ([`spectrum`]). Per view: extract the 2D
//! slice through the origin perpendicular to the view and inverse-transform
//! it; the result is the X-ray projection ([`render`]).
//!
//! `no_std`, no allocation: every buffer is provided by the caller, and every
//! fallible call returns [`Result`]. The crate never panics on data.
#![no_std]

pub mod adaptive;
pub mod dht;
pub mod error;
pub mod filter;
pub mod format;
pub mod geometry;
pub mod gradient;
pub mod progressive;
pub mod real;
pub mod render;
pub mod scene;
pub mod scene_render;
pub mod spectrum;

pub use error::{Error, Result};
pub use half::f16;

//! The `fvr-core` pipeline on the host: threads (rayon), lanes and real
//! FFTs over owned buffers, with no file formats and no command line.
//!
//! The stages, in the order data flows through them:
//!
//! - [`volume`]: the volume in memory, its spacing, analytic phantoms;
//! - [`dht`]: the 3D Hartley transform through real FFTs, in lanes, and
//!   the rounding to the storage format;
//! - [`spectrum`]: the stored spectrum: preparation, bricks, the exchanged
//!   copy;
//! - [`slice`]: the walks that interpolate a slice through the origin, and
//!   adaptive filtering's marks and walk;
//! - [`image`]: the 2D inverse that finishes a view, and the image type;
//! - [`render`]: views, shaded scenes, adaptive views, turntables;
//! - [`plan`]: the accuracy planner that chooses filter, grid and precision.
//!
//! [`Renderer`] is the one entry point over them: settings in, a plan, a
//! preparation, then views. [`memory`] is the one budget every allocation is
//! checked against.

mod clock;
pub mod dht;
mod error;
pub mod image;
pub mod memory;
pub mod plan;
pub mod render;
mod renderer;
pub mod slice;
pub mod spectrum;
pub mod volume;
pub use error::PipelineError;
pub use renderer::{
    describe, AdaptiveView, Plan, Renderer, Settings, Units, ViewReport, DEFAULT_ACCURACY_DB,
    PREDICTION_WARNING_DB, STORAGE_SNR_WARNING_DB,
};

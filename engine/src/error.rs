//! The engine's error.

/// Why a host pipeline could not run.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The core refused (bad view, bad size, non-finite voxel, ...).
    #[error(transparent)]
    Core(#[from] fvr_core::Error),
    /// The padded spectrum would need more memory than is available.
    #[error("a {n}^3 spectrum needs {needed} bytes, more than the {limit} bytes available")]
    OutOfMemory {
        /// Bytes the spectrum would need.
        needed: u64,
        /// Bytes available.
        limit: u64,
        /// Side of the padded cube.
        n: usize,
    },
    /// An image overflowed `f32` ([`crate::image::finite`]).
    #[error(
        "view {view} has non-finite pixels once stored as f32 (the first is {value}): {cause}"
    )]
    Overflow {
        /// The view's index in its batch.
        view: usize,
        /// The first non-finite value.
        value: f32,
        /// What to lower.
        cause: String,
    },
    /// Settings that no view can render, or a planner's refusal; one line.
    #[error("{0}")]
    Settings(String),
}

//! The core with owned buffers on the host: the stored spectrum and view
//! renderer, shaded renders, adaptive filtering, turntables and scene files.

pub mod adaptive;
pub mod adaptive_view;
pub mod fast_adaptive;
pub mod fast_bricks;
pub mod fast_column;
pub mod fast_dht;
pub mod fast_inverse;
pub mod fast_marks;
pub mod fast_mixed;
mod fast_prefetch;
pub mod fast_prepare;
mod fast_runs;
pub mod fast_slice;
pub mod fast_store;
pub mod fast_strip;
#[cfg(test)]
mod fast_tests;
pub mod fast_transpose;
pub mod filter;
pub mod marks_summary;
pub mod partial_spans;
pub mod plan;
pub mod scene_file;
pub mod shaded;
pub mod spectrum;
pub mod turntable;
pub mod view;

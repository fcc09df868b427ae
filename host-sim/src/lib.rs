//! Host simulator for `fvr-core`: volume I/O, analytic phantoms, f64
//! references, agreement in dB and the `fvr` command-line program.

pub mod accuracy;
pub mod adaptive;
pub mod datasets;
pub mod formats;
pub mod growth;
pub mod image;
pub mod nrrd;
pub mod output;
pub mod phantom;
pub mod pipeline;
pub mod plot;
pub mod precision;
pub mod precision_cli;
pub mod progress;
pub mod raycast;
pub mod reference;
pub mod scene;
pub mod scene_file;
pub mod scene_reference;
pub mod shaded;
pub mod teapot;
pub mod timing;
pub mod trade;
pub mod turntable;
pub mod volume;

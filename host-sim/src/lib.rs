//! Host simulator for `fvr-core`: volume I/O, analytic phantoms, f64
//! references, agreement in dB and the `fvr` command-line program.
//!
//! - [`io`]: volume and image files (NRRD, NIfTI, den, inv3, DICOM, raw);
//! - [`image`]: windowing, colormaps, PNG/APNG output and plots;
//! - [`sources`]: volumes by name: phantoms, the teapot, data sets;
//! - [`render`]: the core with owned buffers: spectra, views, shaded
//!   renders, adaptive filtering, turntables, scene files;
//! - [`reference`]: f64 references and the agreement metric;
//! - [`studies`]: the measuring commands (accuracy, adaptive table,
//!   precision, growth, trade) and their timing.

pub mod budget;
pub mod image;
pub mod io;
pub mod options;
pub mod parts;
pub mod progress;
pub mod reference;
pub mod scene_file;
pub mod sources;
pub mod studies;
pub mod text;

//! Checks the commands run before they allocate or write: the output path,
//! a resampled volume against the memory limit, an image's pixels.

use std::path::Path;

use fvr_host::volume::Volume;

use crate::Error;

/// Checks of the output path before any work: its directory exists, and it
/// is not the input file (compared by file identity).
pub(crate) fn check_output(
    out: &Path,
    allowed: &'static [&'static str],
    volume_spec: &str,
) -> Result<(), Error> {
    fvr_host::io::paths::check_output(out, allowed, &[Path::new(volume_spec)])?;
    Ok(())
}

/// Refuse an output that is any file the job has read so far (the volume,
/// a detached NRRD's data file, a data set, a DICOM series' files, a scene,
/// a depth profile), by file identity. Run once the inputs are read, before
/// the render.
pub(crate) fn check_not_input(out: &Path) -> Result<(), Error> {
    fvr_host::io::inputs::check_output(out)?;
    Ok(())
}

/// Refuse a resampled volume beyond the memory limit before allocating it.
pub(crate) fn check_resample(volume: &Volume, largest: usize) -> Result<(), Error> {
    let dims = volume.resampled_dims(largest)?;
    let mut budget = fvr_host::budget::Budget::new();
    budget.hold(
        "resampled volume",
        dims.iter().map(|&d| d as u64).product(),
        4,
    );
    budget.check(fvr_host::budget::limit(), "use a smaller --resample")?;
    Ok(())
}

/// Refuse to write an image with a NaN or infinite pixel.
pub(crate) fn check_finite(data: &[f64]) -> Result<(), Error> {
    match data.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(format!(
            "the image has non-finite pixels (the first is pixel {i}, value {:e}): a setting overflowed; \
             lower --ambient, the --light colours or the --depth-cue weights",
            data[i]
        )
        .into()),
    }
}

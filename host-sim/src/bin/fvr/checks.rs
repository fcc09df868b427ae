//! Checks the commands run before they allocate or write: the output path,
//! a resampled volume against the memory limit, an image's pixels.

use std::path::Path;

use fvr_engine::volume::Volume;

use crate::Error;

/// Checks of the output path before any work: its directory exists, and it
/// is none of the files the job will read that are known now (compared by
/// file identity): the volume, a detached NRRD's data file, a data set's
/// file, and `others` (a scene, a depth profile). [`check_not_input`]
/// checks again once the inputs are read.
pub(crate) fn check_output(
    out: &Path,
    allowed: &'static [&'static str],
    volume_spec: &str,
    others: &[&Path],
) -> Result<(), Error> {
    let files = fvr_host::sources::input_files(volume_spec);
    let mut inputs: Vec<&Path> = vec![Path::new(volume_spec)];
    inputs.extend(files.iter().map(|p| p.as_path()));
    inputs.extend(others);
    fvr_host::io::paths::check_output(out, allowed, &inputs)?;
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

/// Refuse a direction too short to normalise: all its components
/// subnormal (`1e-320,0,0`), which pass a test for zero but turn into NaN
/// on the way to a unit vector. Named by `what` (the option), before any
/// work. The zero vector is left to the view's own check; tiny normal
/// components (`1e-300`) and huge ones (`1e308`) are scaled by the
/// renderer and keep their direction.
pub(crate) fn check_direction(what: &str, v: [f64; 3]) -> Result<(), Error> {
    // The core's rule (`View::frame` and the scene's validation apply it
    // too, for every front end); here it names the option before any work.
    if !fvr_core::geometry::too_short(v) {
        return Ok(());
    }
    Err(format!(
        "{what} {:?},{:?},{:?}: this direction is too short to be normalised (its components \
         are subnormal numbers); give components of ordinary size, such as 1,0,0",
        v[0], v[1], v[2]
    )
    .into())
}

/// The samples `--resample` (or a scene's `volume.resample`) may ask for
/// along the longest side: the engine's one rule.
pub(crate) use fvr_engine::volume::RESAMPLE_RANGE;

/// Refuse a `--resample` outside [`RESAMPLE_RANGE`] before any work.
pub(crate) fn check_resample_count(resample: Option<usize>) -> Result<(), Error> {
    match resample {
        Some(n) if !RESAMPLE_RANGE.contains(&n) => Err(format!(
            "--resample {n}: give {} to {} samples along the volume's longest side",
            RESAMPLE_RANGE.start(),
            RESAMPLE_RANGE.end()
        )
        .into()),
        _ => Ok(()),
    }
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

/// Refuse to write an image with a NaN or infinite pixel, in f64 or once
/// narrowed to the f32 of a NRRD image (a `--precision f64` render can
/// exceed 3.4e38). `cause` says what overflowed, naming only settings the
/// job was given ([`overflow_cause`]).
pub(crate) fn check_finite(data: &[f64], cause: &str) -> Result<(), Error> {
    match data.iter().position(|&v| !(v as f32).is_finite()) {
        None => Ok(()),
        Some(i) => Err(format!(
            "the image has non-finite pixels once stored as f32 (the first is pixel {i}, \
             value {:e}): {cause}",
            data[i]
        )
        .into()),
    }
}

/// What to lower when an image overflows, by the command line's names
/// (the engine's rule, [`fvr_engine::image::finite::overflow_cause`]).
pub(crate) fn overflow_cause(ambient: bool, lights: bool, depth_cue: bool) -> String {
    fvr_engine::image::finite::overflow_cause(
        [ambient, lights, depth_cue],
        &fvr_engine::image::finite::SettingNames {
            ambient: "--ambient",
            lights: "the --light colours",
            depth_cue: "the --depth-cue weights",
            volume: "the volume's values (times its voxel size in mm) are too large; rescale the \
                     volume, or add --ignore-spacing",
        },
    )
}

//! Named real data sets: `brainsmall` (embedded), `ct-head` (installed) and
//! `mri-head` (fetched).
//!
//! - `brainsmall`: VolPack's 128 × 128 × 84 MRI head (BSD-3, see
//!   `host-sim/tests/data/README.md`), embedded in the binary as `.den.gz`.
//! - `ct-head`: InVesalius' `Cranium.inv3`, a 256 × 256 × 108 CT head with
//!   0.957 × 0.957 × 1.5 mm voxels (GPL-2, never committed). It is found at
//!   `$FVR_CT_HEAD` if set, else where Debian's `invesalius-examples`
//!   installs it; `scripts/fetch-ct-head.sh` installs it.
//! - `mri-head`: the MNI152 2009a symmetric T1 template, 197 × 233 × 189
//!   uint8 NIfTI at 1 mm, as nilearn's PyPI wheel ships it (never
//!   committed). It is read from `$FVR_MRI_HEAD`, which
//!   `scripts/fetch-mri-head.sh` prints after fetching it into `target/`.
//!
//! Other modules get either with [`crate::sources::load_volume`]`("ct-head", None)`,
//! or [`load_dataset`].

use std::path::{Path, PathBuf};

use indicatif::ProgressBar;

use crate::io::den::parse_den;
use crate::io::read_volume_with_progress;
use fvr_engine::volume::Volume;

/// Environment variable that points at the CT head's `.inv3` file.
pub const CT_HEAD_ENV: &str = "FVR_CT_HEAD";

/// Where Debian's `invesalius-examples` installs the CT head.
pub const CT_HEAD_DEBIAN_PATH: &str = "/usr/share/doc/invesalius-examples/examples/Cranium.inv3";

/// Environment variable that points at the MRI head's `.nii.gz` file.
pub const MRI_HEAD_ENV: &str = "FVR_MRI_HEAD";

/// Sizes `[x, y, z]` of the MRI head (MNI152 2009a, 1 mm).
pub const MRI_HEAD_DIMS: [usize; 3] = [197, 233, 189];

/// Sizes `[x, y, z]` of the CT head.
pub const CT_HEAD_DIMS: [usize; 3] = [256, 256, 108];

/// Voxel spacing of the CT head in mm, from its `main.plist`.
pub const CT_HEAD_SPACING: [f64; 3] = [0.957_031_2, 0.957_031_2, 1.5];

/// Sizes `[x, y, z]` of `brainsmall`.
pub const BRAINSMALL_DIMS: [usize; 3] = [128, 128, 84];

/// Where `brainsmall`'s axes point in the patient (RAS). The `.den` file
/// carries no orientation; these are read from its anatomy: `x` runs from
/// the face to the back of the head (posterior), `y` from the crown to the
/// neck (inferior), and `z`, across the sagittal slices, is taken to run to
/// the patient's right so that the frame is right-handed (a head's left
/// and right look alike, so the anatomy cannot tell).
pub const BRAINSMALL_ORIENTATION: fvr_engine::volume::Orientation =
    fvr_engine::volume::Orientation {
        direction: [[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]],
        origin: [0.0; 3],
    };

/// `brainsmall.den`, gzip-compressed.
pub const BRAINSMALL_DEN_GZ: &[u8] = include_bytes!("../../tests/data/brainsmall.den.gz");

/// The names [`load_dataset`] knows, with a description each.
pub const DATASETS: &[(&str, &str)] = &[
    (
        "brainsmall",
        "VolPack's 128x128x84 MRI head (embedded, BSD-3)",
    ),
    (
        "ct-head",
        "InVesalius' 256x256x108 CT head, 0.957x0.957x1.5 mm (installed by scripts/fetch-ct-head.sh)",
    ),
    (
        "mri-head",
        "the MNI152 197x233x189 T1 head, 1 mm (fetched by scripts/fetch-mri-head.sh, read from $FVR_MRI_HEAD)",
    ),
];

/// Help text listing the data sets.
pub const DATASETS_HELP: &str = "data sets: `brainsmall` (VolPack's 128x128x84 MRI head, embedded) and \
`ct-head` (InVesalius' 256x256x108 CT head, installed by scripts/fetch-ct-head.sh or found at $FVR_CT_HEAD) and \
`mri-head` (the MNI152 197x233x189 T1 head, fetched by scripts/fetch-mri-head.sh, read from $FVR_MRI_HEAD)";

/// The CT head's file: `$FVR_CT_HEAD` if set, else Debian's install path.
///
/// # Errors
/// `$FVR_CT_HEAD` names a missing file, or it is unset and the Debian
/// package is not installed; the message says how to install it.
pub fn ct_head_path() -> Result<PathBuf, String> {
    if let Some(p) = std::env::var_os(CT_HEAD_ENV) {
        let path = PathBuf::from(p);
        return if path.is_file() {
            Ok(path)
        } else {
            Err(format!(
                "{CT_HEAD_ENV} is set to `{}`, which is not a file",
                path.display()
            ))
        };
    }
    let debian = Path::new(CT_HEAD_DEBIAN_PATH);
    if debian.is_file() {
        return Ok(debian.to_path_buf());
    }
    Err(format!(
        "the CT head is not installed: run `bash scripts/fetch-ct-head.sh` (it installs Debian's \
         `invesalius-examples`, GPL-2, to {CT_HEAD_DEBIAN_PATH}), or set {CT_HEAD_ENV} to a copy of Cranium.inv3"
    ))
}

/// The MRI head's file, from `$FVR_MRI_HEAD`.
///
/// # Errors
/// `$FVR_MRI_HEAD` is unset or names a missing file; the message says how
/// to fetch it.
pub fn mri_head_path() -> Result<PathBuf, String> {
    let fetch = "run `export FVR_MRI_HEAD=\"$(bash scripts/fetch-mri-head.sh)\"` (it fetches the MNI152 T1 head from nilearn's PyPI wheel into target/)";
    let Some(p) = std::env::var_os(MRI_HEAD_ENV) else {
        return Err(format!(
            "the MRI head is not fetched: {MRI_HEAD_ENV} is unset; {fetch}"
        ));
    };
    let path = PathBuf::from(p);
    if path.is_file() {
        Ok(path)
    } else {
        Err(format!(
            "{MRI_HEAD_ENV} is set to `{}`, which is not a file; {fetch}",
            path.display()
        ))
    }
}

/// Load a named data set, or `None` if `name` is not one.
///
/// # Errors
/// The data set is not installed, or its file cannot be read.
pub fn load_dataset(name: &str) -> Option<Result<Volume, String>> {
    load_dataset_with_progress(name, &ProgressBar::hidden())
}

/// [`load_dataset`], advancing `progress` by the bytes read from disk.
///
/// # Errors
/// As [`load_dataset`].
pub fn load_dataset_with_progress(
    name: &str,
    progress: &ProgressBar,
) -> Option<Result<Volume, String>> {
    match name {
        "brainsmall" => Some(
            parse_den(BRAINSMALL_DEN_GZ)
                .map(|v| Volume {
                    orientation: Some(BRAINSMALL_ORIENTATION),
                    ..v
                })
                .map_err(|e| format!("brainsmall: {e}")),
        ),
        "ct-head" => Some(
            ct_head_path()
                .and_then(|p| read_volume_with_progress(&p, progress).map_err(|e| e.to_string())),
        ),
        "mri-head" => Some(
            mri_head_path()
                .and_then(|p| read_volume_with_progress(&p, progress).map_err(|e| e.to_string())),
        ),
        _ => None,
    }
}

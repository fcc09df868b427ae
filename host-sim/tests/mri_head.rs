//! The MRI head (`mri-head`): the MNI152 2009a T1 template that
//! `scripts/fetch-mri-head.sh` fetches from nilearn's PyPI wheel (never
//! committed). With `FVR_MRI_HEAD` set (as `scripts/test-all.sh` does) the
//! NIfTI reader must give its shape, spacing, orientation and values; unset,
//! the data set must fail with a one-line message saying how to fetch it.

use std::path::Path;

use fvr_host::io::read_volume;
use fvr_host::sources::datasets::{load_dataset, mri_head_path, MRI_HEAD_DIMS, MRI_HEAD_ENV};

#[test]
fn mri_head_reads_as_the_mni152_t1_or_says_how_to_fetch_it() {
    let Some(path) = std::env::var_os(MRI_HEAD_ENV) else {
        let msg = load_dataset("mri-head").unwrap().unwrap_err();
        assert!(
            msg.contains(MRI_HEAD_ENV) && msg.contains("scripts/fetch-mri-head.sh"),
            "{msg}"
        );
        assert!(!msg.contains('\n'), "one line: {msg}");
        return;
    };
    assert_eq!(mri_head_path().unwrap(), Path::new(&path));
    // gzip, uint8 (datatype 2), scl_slope 1, sform the identity at 1 mm.
    let vol = read_volume(Path::new(&path)).expect("MRI head");
    assert_eq!(vol.dims, MRI_HEAD_DIMS);
    assert_eq!(vol.spacing, [1.0, 1.0, 1.0]);
    let min = vol.data.iter().copied().fold(f32::INFINITY, f32::min);
    let max = vol.data.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    assert_eq!((min, max), (0.0, 255.0));
    // The sform puts world (0, 0, 0) mm at voxel (98, 134, 72): brain.
    assert_eq!(vol.get(98, 134, 72), 71.0);
    // Orientation kept (no flips): the neck leaves the box at z = 0, the
    // top of the head does not reach z = 188.
    let face = |k: usize| -> f64 {
        (0..vol.dims[1])
            .flat_map(|j| (0..vol.dims[0]).map(move |i| (i, j)))
            .map(|(i, j)| f64::from(vol.get(i, j, k)))
            .sum()
    };
    assert!(face(0) > 0.0 && face(188) == 0.0);
    let by_name = load_dataset("mri-head").unwrap().unwrap();
    assert_eq!(by_name.data, vol.data);
}

#[test]
fn mri_head_set_to_a_missing_file_is_one_clear_line() {
    // Through the script, so that this process's environment is untouched.
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/fetch-mri-head.sh");
    let out = std::process::Command::new("bash")
        .arg(script)
        .env(MRI_HEAD_ENV, "/nonexistent/head.nii.gz")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/nonexistent/head.nii.gz"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

#[test]
fn fvr_names_the_missing_mri_head_in_one_line() {
    let dir = std::env::temp_dir();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_fvr"))
        .args(["render", "mri-head", "--dir", "0,1,0", "--out"])
        .arg(dir.join("fvr-mri-head-missing.png"))
        .arg("--quiet")
        .env(MRI_HEAD_ENV, "/nonexistent/head.nii.gz")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("FVR_MRI_HEAD is set to `/nonexistent/head.nii.gz`, which is not a file"),
        "{err}"
    );
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

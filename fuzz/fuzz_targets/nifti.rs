//! Fuzz `fvr_host::io::nifti::parse_nifti`: any bytes give a volume or an error, never a
//! panic, a hang or an allocation beyond the input's claims.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(volume) = fvr_host::io::nifti::parse_nifti(data) {
        assert_eq!(volume.data.len(), volume.dims.iter().product::<usize>());
        assert!(volume.data.iter().all(|v| v.is_finite()));
        assert!(volume.spacing.iter().all(|s| s.is_finite() && *s > 0.0));
    }
});

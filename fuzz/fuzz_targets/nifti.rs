//! Fuzz `fvr_host::io::nifti::parse_nifti`: any bytes give a volume or an error, never a
//! panic, a hang or an allocation beyond the input's claims.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| fvr_fuzz::check_volume(
    fvr_host::io::nifti::parse_nifti(data)
));

//! Fuzz `fvr_host::io::inv3::parse_inv3`: any bytes give a volume or an error, never a
//! panic, a hang or an allocation beyond the input's claims.
#![no_main]

libfuzzer_sys::fuzz_target!(
    |data: &[u8]| fvr_fuzz::check_volume(fvr_host::io::inv3::parse_inv3(data))
);

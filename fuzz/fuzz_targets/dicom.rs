//! Fuzz the DICOM slice reader (`dicom-object` parsing and
//! `dicom-pixeldata` decoding behind `fvr_host::io::dicom`): any bytes
//! give a slice or an error, never a panic or a runaway allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(slice) = fvr_host::io::dicom::parse_slice(data) {
        assert_eq!(slice.pixels.len(), slice.size[0] * slice.size[1]);
        let _ = fvr_host::io::dicom::assemble(vec![slice]);
    }
});

//! Fuzz the property-list reading behind `.inv3` files (the `plist` crate
//! after the nesting check): any text gives a value or an error, never a
//! panic or a stack overflow.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = fvr_host::io::inv3::parse_plist(text);
        let _ = fvr_host::io::inv3::parse_main_plist(text);
    }
});

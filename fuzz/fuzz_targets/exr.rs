//! Fuzz target: the exr reader must return an image or an error for any bytes, never panic,
//! and never allocate beyond the limits (tight limits here so the fuzzer explores sizes cheaply).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = ibl_io::Limits { max_width: 4096, max_height: 4096, max_pixels: 1 << 22 };
    // The header-only reader (`ibl info --header`) must not panic either.
    let _ = ibl_io::exr::header_size(data);
    if let Ok(raw) = ibl_io::exr::decode(data, &limits) {
        assert!(raw.image.width() <= limits.max_width && raw.image.height() <= limits.max_height);
    }
});

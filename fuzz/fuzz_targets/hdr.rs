//! Fuzz target: the hdr reader must return an image or an error for any bytes, never panic,
//! and never allocate beyond the limits (tight limits here so the fuzzer explores sizes cheaply);
//! its header-only reader (`header_size`, for `ibl info --header`) must agree with a successful
//! decode and never panic either.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = ibl_io::Limits { max_width: 4096, max_height: 4096, max_pixels: 1 << 22 };
    let header = ibl_io::hdr::header_size(data);
    if let Ok(raw) = ibl_io::hdr::decode(data, &limits) {
        assert!(raw.image.width() <= limits.max_width && raw.image.height() <= limits.max_height);
        // `ibl info --header` reports what the full read decodes.
        assert_eq!(header.ok(), Some((raw.image.width(), raw.image.height())));
    }
});

//! Fuzz target: the dds reader must return a texture or an error for any bytes, never panic,
//! and never allocate beyond the limits (tight limits here so the fuzzer explores sizes cheaply).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = ibl_io::Limits { max_width: 4096, max_height: 4096, max_pixels: 1 << 22 };
    if let Ok(t) = ibl_io::dds::decode(data, &limits) {
        let (w, h) = t.texture.size();
        assert!(w * h * t.texture.kind.faces() <= limits.max_pixels);
        assert!(t.texture.validate().is_ok());
    }
});

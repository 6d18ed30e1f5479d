//! Fuzz target: exposure-time lists (`ibl capture merge --times`, a file of `name seconds` pairs
//! in OpenCV's or a two-column layout, or plain numbers) must give positive, finite times or an
//! error naming the file, for any bytes, never panic.
#![no_main]

use std::path::{Path, PathBuf};

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(times) = ibl_io::photo::parse_exposure_times(text) {
        assert!(times.iter().all(|t| t.is_finite() && *t > 0.0), "{times:?}");
    }
    let images: Vec<PathBuf> = ["a.jpg", "b.jpg", "IMG_0003.JPG"].iter().map(PathBuf::from).collect();
    let path = Path::new("fuzz/times.txt");
    for unit in [None, Some(ibl_pipeline::exposure_list::TimeUnit::InverseSeconds)] {
        match ibl_pipeline::exposure_list::parse_times_file(path, text, &images, unit) {
            Ok((times, _)) => {
                assert!(times.iter().all(|t| t.is_finite() && *t > 0.0), "{times:?}");
            }
            Err(e) => assert!(e.to_string().contains("times.txt"), "{e}"),
        }
    }
});

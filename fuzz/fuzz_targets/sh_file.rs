//! Fuzz target: an SH file's text (`ibl-io::sh_file`, read by `ibl sh --from FORMAT` and by the
//! hybrid lighting) must parse in each of the seven formats to coefficients or an error, never
//! panic; parsed coefficients are written back in the same format without panicking, and the
//! JSON form reads back to the same coefficients.
#![no_main]

use ibl_io::ShFileFormat;
use ibl_io::sh_file::{format_sh, parse_sh};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    for format in ShFileFormat::ALL {
        let Ok(file) = parse_sh(format, text) else { continue };
        let _ = format_sh(format, &file);
        if let Ok(json) = format_sh(ShFileFormat::Json, &file) {
            let back = parse_sh(ShFileFormat::Json, &json).expect("iblkit's own JSON reads back");
            assert_eq!(back.bands, file.bands, "{format:?}");
        }
    }
});

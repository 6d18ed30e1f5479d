//! Fuzz target: a marks file (`ibl-room`) must parse to a validated file or an error for any
//! bytes, and calibration, scale and reconstruction from a parsed file must return a result or an
//! error, never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(marks) = ibl_room::MarksFile::from_json(text) else { return };
    let lines = ibl_room::line_observations(&marks);
    let Ok(calibration) = ibl_room::calibrate(&lines) else { return };
    let Ok(scale) = ibl_room::probe_height(&marks, calibration.world_from_probe()) else { return };
    let _ = ibl_room::reconstruct(&marks, &calibration, &scale, "probe.exr");
});

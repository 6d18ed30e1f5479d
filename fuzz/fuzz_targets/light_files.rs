//! Fuzz target: a light file's bytes (`ibl-io`: an `iblkit.lights/1` light set, or an
//! `iblkit.area-lights/1` file of the room's patches, as a scene's `lighting.lights_file` and
//! `ibl render --lights` read them) must give a checked light set or an error naming the file,
//! for any bytes, never panic; every light read has a unit direction and finite, non-negative
//! irradiance and solid angle.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz/lights.json");
    let set = if ibl_io::area_light_file::is_area_lights_json(data) {
        match ibl_io::area_light_file::AreaLightsFile::from_json(path, data) {
            Ok(file) => file.distant_lights(),
            Err(e) => {
                assert!(e.is_bad_input() && e.to_string().contains("lights.json"), "{e}");
                return;
            }
        }
    } else {
        match ibl_io::light_file::light_set_from_json(path, data) {
            Ok(set) => set,
            Err(e) => {
                assert!(e.is_bad_input() && e.to_string().contains("lights.json"), "{e}");
                return;
            }
        }
    };
    for l in &set.lights {
        assert!(l.direction.is_finite() && (l.direction.length() - 1.0).abs() < 1e-6);
        assert!(l.irradiance.to_array().iter().all(|c| c.is_finite() && *c >= 0.0));
        assert!(l.solid_angle_sr.is_finite() && l.solid_angle_sr >= 0.0);
    }
});

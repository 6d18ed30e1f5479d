//! Fuzz target: a room edits file's text (`ibl-pipeline::room_render`, read by
//! `ibl room render --edit`) must parse to checked edits or an error naming the file, for any
//! bytes, never panic; parsed edits hold only reflectances in [0, 1], at most 64 lights with
//! finite placements, at most 64 objects and a bounded view. Parsing reads no file (the lights' files are read by
//! `RoomEdits::load_lights`, the photometry readers having their own targets).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let path = Path::new("fuzz/edits.toml");
    match ibl_pipeline::room_render::RoomEdits::parse(text, path) {
        Ok(edits) => {
            for (_, rho) in &edits.materials {
                assert!(rho.to_array().iter().all(|v| (0.0..=1.0).contains(v)));
            }
            assert!(edits.lights.len() <= ibl_pipeline::room_render::MAX_LIGHTS);
            assert!(edits.objects.len() <= ibl_pipeline::room_render::MAX_OBJECTS);
            assert!((1..=ibl_pipeline::room_render::MAX_IMPORTANT_PATCHES).contains(&edits.important_patches));
            for l in &edits.lights {
                assert!(l.position.is_finite() && l.rotation_deg.iter().all(|a| a.is_finite()));
                assert!(l.colour.luminance() > 0.0);
            }
            if let Some(v) = &edits.view {
                assert!(v.width > 0 && v.height > 0 && u64::from(v.width) * u64::from(v.height) <= 64 << 20);
            }
        }
        Err(e) => assert!(e.to_string().contains("edits.toml"), "{e}"),
    }
});

//! Fuzz target: a scene file's text (`ibl-scene`, every table: `[probe]`, `[camera]`,
//! `[[local]]`, `[[object]]`, `[render]`, `[lighting]`, `[outdoor]`, `[room]`) must parse to a
//! validated description or an error for any bytes, never panic; a parsed description must
//! validate again and survive the civil-time helpers of its `[outdoor]` table.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(scene) = ibl_scene::SceneDescription::from_toml(text) else { return };
    assert!(scene.validate().is_ok(), "a parsed scene validates");
    if let Some(outdoor) = &scene.outdoor {
        let _ = outdoor.probe_local_time();
        let _ = outdoor.frames.start_local_time();
        let _ = outdoor.frames.seconds_after_start(usize::MAX);
    }
});

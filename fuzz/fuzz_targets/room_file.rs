//! Fuzz target: a room file (`ibl-room`, the `[probe]` and `[room]` tables) must parse to a
//! validated file or an error for any bytes; a parsed file must build a room or refuse with an
//! error (the patch count is bounded before anything is allocated), never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(mut file) = ibl_room::RoomFile::from_toml(text) else { return };
    // Keep each run cheap: at most a few thousand patches.
    file.room.patch_area_m2 = file.room.patch_area_m2.max(0.5);
    let _ = ibl_room::Room::from_file(&file);
});

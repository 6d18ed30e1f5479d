//! Fuzz target: the EULUMDAT reader must return a candela table or an error for any bytes, never
//! panic, and never allocate beyond the limits (tight ones here, so sizes are explored cheaply); a
//! table read must integrate to a finite flux and resample into an equal-area map.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = ibl_io::PhotometryLimits { max_bytes: 1 << 16, max_angles: 400, max_values: 1 << 14 };
    if let Ok(file) = ibl_io::photometry::ldt::decode(data, &limits) {
        let t = &file.table;
        assert!(t.vertical_deg().len() <= limits.max_angles);
        assert!(t.values().len() <= 4 * limits.max_values + 2 * t.vertical_deg().len());
        assert!(t.flux().is_finite());
        let map = ibl_light::EqualAreaMap::from_table(t, 8, 1);
        assert!(map.flux().is_finite());
    }
});

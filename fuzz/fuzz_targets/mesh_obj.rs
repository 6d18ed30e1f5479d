//! Fuzz target: the Wavefront OBJ reader must return a mesh or an error for any bytes, never
//! panic, and stay within the triangle limit. The input is split at the first NUL byte into the
//! OBJ text and the content of its material library.
#![no_main]

use ibl_io::mesh_file::{MeshLimits, decode_obj};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = MeshLimits { max_triangles: 1 << 16, max_file_bytes: 1 << 20 };
    let (obj, mtl) = match data.iter().position(|&b| b == 0) {
        Some(nul) => (&data[..nul], Some(&data[nul + 1..])),
        None => (data, None),
    };
    if let Ok(loaded) = decode_obj(obj, mtl, &limits) {
        assert!(loaded.mesh.triangle_count() <= limits.max_triangles);
        assert_eq!(loaded.base_colors.len(), loaded.mesh.material_names.len());
    }
});

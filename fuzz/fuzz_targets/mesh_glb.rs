//! Fuzz target: the glTF reader (binary GLB or JSON with embedded buffers) must return a mesh or
//! an error for any bytes, never panic, and stay within the limits (tight here so the fuzzer
//! explores sizes cheaply).
#![no_main]

use ibl_io::mesh_file::{MeshLimits, decode_gltf};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = MeshLimits { max_triangles: 1 << 16, max_file_bytes: 1 << 20 };
    if let Ok(loaded) = decode_gltf(data, &limits) {
        let mesh = &loaded.mesh;
        assert!(mesh.triangle_count() <= limits.max_triangles);
        assert_eq!(loaded.base_colors.len(), mesh.material_names.len());
        assert!(mesh.normals.is_empty() || mesh.normals.len() == mesh.positions.len());
    }
});

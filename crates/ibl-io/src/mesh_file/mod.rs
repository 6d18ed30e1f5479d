//! Triangle meshes from files: glTF 2.0 (`.gltf`, `.glb`) and Wavefront OBJ (`.obj` with its
//! `.mtl`), read into an [`ibl_scene::TriangleMesh`] in the model's own frame (no placement; glTF
//! models are +Y up with metres as units, OBJ units are whatever the file used) plus one linear
//! base colour per material group.
//!
//! One module per format: `gltf` (glTF 2.0, JSON or binary) and `obj` (Wavefront OBJ with its
//! `.mtl`); this module holds what both share: the limits, the result, the dispatch by extension
//! and the final checks.
//!
//! Normals are kept only when every triangle's corners have one (and none is zero-length);
//! otherwise the mesh gets none and is shaded flat, with a note in [`LoadedMesh::details`]. No
//! normals are ever computed. Finally [`ibl_scene::mesh::TriangleMesh::validate`] refuses out-of-range indices and
//! non-finite data and drops zero-area triangles.
//!
//! Cost: one pass over the file, O(bytes + vertices + triangles) time (plus a hash map lookup per
//! OBJ face corner); memory is the file's bytes plus the output mesh.

mod gltf;
mod loaded;
mod obj;

use std::path::Path;

use crate::error::IoError;

pub use self::gltf::decode_gltf;
pub use self::loaded::{DEFAULT_BASE_COLOR, DEFAULT_MATERIAL_NAME, LoadedMesh, MeshLimits};
pub use self::obj::decode_obj;

/// Reads a mesh file, choosing the format by extension (case-insensitive): `.gltf`/`.glb`
/// (glTF 2.0, JSON or binary either way) or `.obj` (plus the `.mtl` files it names, looked up
/// next to it). Every error names the file (or the `.mtl` file at fault) and, for bad content,
/// is [`IoError::is_bad_input`].
pub fn read_mesh(path: &Path, limits: &MeshLimits) -> Result<LoadedMesh, IoError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let is_gltf = match ext.as_deref() {
        Some("gltf" | "glb") => true,
        Some("obj") => false,
        _ => {
            return Err(IoError::Unsupported {
                path: path.to_path_buf(),
                what: "mesh file extension (expected .gltf, .glb or .obj)".into(),
            });
        }
    };
    let bytes = crate::read_bounded(path, limits.max_file_bytes)?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if is_gltf {
        self::gltf::decode_gltf_in(&bytes, Some(dir), limits).map_err(|e| e.with_path(path))
    } else {
        obj::read_obj(path, dir, &bytes, limits)
    }
}

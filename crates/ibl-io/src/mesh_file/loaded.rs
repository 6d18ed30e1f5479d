//! What every mesh reader returns and the checks it ends with: the size limits, the loaded mesh
//! with its base colours and details line, and the final pass (normals kept only when usable,
//! validation, the details). A leaf module shared by the glTF and OBJ readers.

use ibl_core::Rgb;
use ibl_core::glam::Vec3;
use ibl_scene::TriangleMesh;

use crate::error::DecodeError;

/// Base colour (linear) of a material group the file gives no colour for: OBJ groups without a
/// `Kd`, glTF primitives without a material.
pub const DEFAULT_BASE_COLOR: Rgb = Rgb::splat(0.8);

/// Name of the material group of faces or primitives the file assigns no material to.
pub const DEFAULT_MATERIAL_NAME: &str = "default";

/// Size limits checked before allocating.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshLimits {
    /// Most triangles in the whole mesh, every glTF node instance counted (default 20 million).
    /// Vertices are bounded by three times this.
    pub max_triangles: usize,
    /// Largest file read, in bytes (default 1 GiB); a `.gltf` and its external buffer files
    /// together, an `.obj` and each `.mtl` on its own.
    pub max_file_bytes: u64,
}

impl Default for MeshLimits {
    fn default() -> Self {
        MeshLimits {
            max_triangles: 20_000_000,
            max_file_bytes: 1 << 30,
        }
    }
}

impl MeshLimits {
    pub(crate) fn max_vertices(&self) -> u64 {
        (self.max_triangles as u64)
            .saturating_mul(3)
            .min(u64::from(u32::MAX))
    }
}

/// A mesh read from a file, in the model's own frame, with its material groups' base colours.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedMesh {
    /// The validated mesh (zero-area triangles already dropped).
    pub mesh: TriangleMesh,
    /// Linear base colour (diffuse albedo) of each entry of `mesh.material_names`: glTF
    /// `baseColorFactor.rgb`, OBJ `Kd`, else [`DEFAULT_BASE_COLOR`].
    pub base_colors: Vec<Rgb>,
    /// Human-readable summary, e.g. `"glTF 2.0 binary, 2826 vertices, 5648 triangles, vertex
    /// normals, 1 material"`, followed by notes on anything dropped or skipped.
    pub details: String,
}

/// Drops unusable normals, validates, and writes the details line.
pub(crate) fn finish(
    mut mesh: TriangleMesh,
    base_colors: Vec<Rgb>,
    format: &str,
    mut notes: Vec<String>,
) -> Result<LoadedMesh, DecodeError> {
    if mesh.triangles.is_empty() {
        return Err(DecodeError::invalid("no triangles"));
    }
    if let Some(v) = mesh.normals.iter().position(|&n| n == Vec3::ZERO) {
        notes.push(format!(
            "normals dropped: vertex {v} has a zero-length normal"
        ));
        mesh.normals.clear();
    }
    let dropped = mesh
        .validate()
        .map_err(|e| DecodeError::invalid(e.to_string()))?;
    if dropped > 0 {
        notes.push(format!("{dropped} zero-area triangles dropped"));
    }
    let materials = mesh.material_names.len();
    let mut details = format!(
        "{format}, {} vertices, {} triangles, {}, {materials} material{}",
        mesh.positions.len(),
        mesh.triangles.len(),
        if mesh.normals.is_empty() {
            "flat shading (no normals)"
        } else {
            "vertex normals"
        },
        if materials == 1 { "" } else { "s" }
    );
    for note in notes {
        details.push_str("; ");
        details.push_str(&note);
    }
    Ok(LoadedMesh {
        mesh,
        base_colors,
        details,
    })
}

/// `v / |v|`, or `v` itself when it has no direction (zero, or not finite), for [`finish`] to
/// drop or [`TriangleMesh::validate`] to refuse.
pub(crate) fn normalize_or_keep(v: Vec3) -> Vec3 {
    let length = v.length();
    if length > 0.0 && length.is_finite() {
        v / length
    } else {
        v
    }
}

//! Triangle meshes from files: glTF 2.0 (`.gltf`, `.glb`) and Wavefront OBJ (`.obj` with its
//! `.mtl`), read into an [`ibl_scene::TriangleMesh`] in the model's own frame (no placement; glTF
//! models are +Y up with metres as units, OBJ units are whatever the file used) plus one linear
//! base colour per material group.
//!
//! **glTF 2.0** (Khronos glTF 2.0 specification: GLB container, buffers, accessors, meshes, node
//! hierarchy). The GLB container (12-byte header, a JSON chunk, an optional BIN chunk) is split
//! here; the JSON is deserialised with `gltf-json` but *not* run through its validation pass (that
//! pass indexes arrays without bounds checks on hostile files); every index, offset, stride and
//! length is instead checked here before use, in 64-bit arithmetic, and sizes are checked against
//! [`MeshLimits`] before anything is allocated. Buffers come from the GLB binary chunk, from base64
//! `data:` URIs, or from files next to the `.gltf`. The default scene's node tree (else
//! `scenes[0]`, else every node that is nobody's child) is walked depth first with each node's
//! local transform `matrix` or `T * R * S`, accumulated as `world = parent * local`. Each mesh
//! instance is emitted with positions `M p`, normals `normalize((M3^-1)^T n)` and, when
//! `det M3 < 0` (a mirror), reversed winding, as the specification requires. Only the triangle
//! modes are read (TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN, the latter two unrolled with the
//! specification's vertex order); points and lines have no area and are skipped. `POSITION`
//! must be float VEC3, `NORMAL` is optional float VEC3, indices are optional u8/u16/u32 scalars
//! (none means `0, 1, 2, ...`). Files that *require* a geometry extension (Draco or meshopt
//! compression, mesh quantisation, ...) are refused with a message saying what to do; required
//! material/texture/light extensions are ignored because only geometry and `baseColorFactor` are
//! read. Base colours are `baseColorFactor.rgb` (linear; the specification's default is 1), and
//! 0.8 grey ([`DEFAULT_BASE_COLOR`]) for primitives without a material.
//!
//! **OBJ** (Wavefront "Object Files (.obj)" appendix B1 of the Advanced Visualizer manual): read by
//! a line parser of our own rather than `tobj`, because `tobj` 4.0.5 panics on an overflowing
//! multiplication for a face such as `f 1//-9223372036854775807` (with overflow checks on) and
//! forgets `usemtl` names when the `.mtl` is missing. Lines `v`, `vn`, `f`, `usemtl` and
//! `mtllib` are read, everything else (`vt`, `o`, `g`, `s`, `l`, `p`, curves) is ignored. Face
//! corners `v`, `v/vt`, `v//vn`, `v/vt/vn` take 1-based or negative (relative) indices that must
//! refer to data defined earlier in the file; polygons are fan-triangulated
//! `(c0, c[i], c[i+1])`, which is exact for convex polygons. Each distinct (position, normal) pair
//! becomes one vertex. Each `usemtl` name is a material group (faces before the first `usemtl`
//! form `"default"`); its base colour is the `Kd` of the `.mtl` files named by `mtllib` and found
//! next to the `.obj`; a missing `.mtl` only leaves 0.8 grey.
//!
//! Normals are kept only when every triangle's corners have one (and none is zero-length);
//! otherwise the mesh gets none and is shaded flat, with a note in [`LoadedMesh::details`]. No
//! normals are ever computed. Finally [`TriangleMesh::validate`] refuses out-of-range indices and
//! non-finite data and drops zero-area triangles.
//!
//! Cost: one pass over the file, O(bytes + vertices + triangles) time (plus a hash map lookup per
//! OBJ face corner); memory is the file's bytes plus the output mesh.

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use gltf::json;
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::Checked;
use ibl_core::Rgb;
use ibl_core::glam::{Mat3, Mat4, Quat, Vec3};
use ibl_scene::TriangleMesh;

use crate::error::{DecodeError, IoError};

/// Base colour (linear) of a material group the file gives no colour for: OBJ groups without a
/// `Kd`, glTF primitives without a material.
pub const DEFAULT_BASE_COLOR: Rgb = Rgb::splat(0.8);

/// Name of the material group of faces or primitives the file assigns no material to.
pub const DEFAULT_MATERIAL_NAME: &str = "default";

/// The glTF extension for Draco-compressed geometry.
const DRACO: &str = "KHR_draco_mesh_compression";

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
    fn max_vertices(&self) -> u64 {
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
    let bytes = read_bounded(path, limits.max_file_bytes)?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if is_gltf {
        decode_gltf_in(&bytes, Some(dir), limits).map_err(|e| e.with_path(path))
    } else {
        read_obj(path, dir, &bytes, limits)
    }
}

/// Reads a whole file after checking its size against `max_bytes`.
fn read_bounded(path: &Path, max_bytes: u64) -> Result<Vec<u8>, IoError> {
    let len = std::fs::metadata(path)
        .map_err(|e| IoError::read(path, e))?
        .len();
    if len > max_bytes {
        return Err(IoError::Limits {
            path: path.to_path_buf(),
            what: format!("{len} bytes, over the limit of {max_bytes}"),
        });
    }
    std::fs::read(path).map_err(|e| IoError::read(path, e))
}

// ---------------------------------------------------------------------------------------------
// glTF
// ---------------------------------------------------------------------------------------------

/// Decodes glTF 2.0 bytes, binary (`.glb`) or JSON (`.gltf`), whose buffers are all embedded (the
/// GLB binary chunk or base64 `data:` URIs); a buffer in an external file is
/// [`DecodeError::Unsupported`] here ([`read_mesh`] resolves those next to the file). The mesh is
/// validated. Never panics; allocations are bounded by `limits` and the input size.
pub fn decode_gltf(bytes: &[u8], limits: &MeshLimits) -> Result<LoadedMesh, DecodeError> {
    decode_gltf_in(bytes, None, limits)
}

/// [`decode_gltf`] with external buffer files resolved in `base_dir` (none: refused).
fn decode_gltf_in(
    bytes: &[u8],
    base_dir: Option<&Path>,
    limits: &MeshLimits,
) -> Result<LoadedMesh, DecodeError> {
    let container = split_container(bytes)?;
    let root: json::Root = serde_json::from_slice(trim_json(container.json))
        .map_err(|e| DecodeError::invalid(format!("glTF JSON: {e}")))?;
    if !root.asset.version.starts_with("2.") {
        return Err(DecodeError::Unsupported(format!(
            "glTF version {:?} (only 2.x is read)",
            root.asset.version
        )));
    }
    check_required_extensions(&root)?;
    let mut buffers = Buffers {
        bin: container.bin,
        base_dir,
        loaded: (0..root.buffers.len()).map(|_| None).collect(),
        external_budget: limits.max_file_bytes.saturating_sub(bytes.len() as u64),
    };
    let mut builder = GltfBuilder::new(limits);
    walk_scene(&root, &mut buffers, &mut builder)?;
    let format = if container.binary {
        "glTF 2.0 binary"
    } else {
        "glTF 2.0 JSON"
    };
    builder.finish(format)
}

/// The JSON text and binary chunk of a glTF file.
struct Container<'a> {
    json: &'a [u8],
    bin: Option<&'a [u8]>,
    binary: bool,
}

fn u32_le(b: &[u8]) -> u32 {
    let mut word = [0u8; 4];
    for (w, &x) in word.iter_mut().zip(b) {
        *w = x;
    }
    u32::from_le_bytes(word)
}

/// Splits a GLB into its JSON and BIN chunks, or passes JSON text through.
fn split_container(bytes: &[u8]) -> Result<Container<'_>, DecodeError> {
    const JSON_CHUNK: u32 = 0x4E4F_534A;
    const BIN_CHUNK: u32 = 0x004E_4942;
    if !bytes.starts_with(b"glTF") {
        let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
        return match text.iter().find(|b| !b.is_ascii_whitespace()) {
            Some(b'{') => Ok(Container {
                json: text,
                bin: None,
                binary: false,
            }),
            None => Err(DecodeError::invalid("the file is empty")),
            Some(_) => Err(DecodeError::invalid(
                "neither binary glTF (magic \"glTF\") nor a JSON object",
            )),
        };
    }
    let Some(header) = bytes.get(..12) else {
        return Err(DecodeError::invalid(format!(
            "truncated GLB header ({} of 12 bytes)",
            bytes.len()
        )));
    };
    let version = u32_le(&header[4..8]);
    if version != 2 {
        return Err(DecodeError::Unsupported(format!(
            "GLB container version {version} (only glTF 2.0 is read)"
        )));
    }
    let length = u32_le(&header[8..12]) as usize;
    if length < 12 || length > bytes.len() {
        return Err(DecodeError::invalid(format!(
            "truncated or corrupt GLB: the header says {length} bytes, the file has {}",
            bytes.len()
        )));
    }
    let mut rest = &bytes[12..length];
    let mut json = None;
    let mut bin = None;
    let mut chunk = 0usize;
    while !rest.is_empty() {
        let offset = length - rest.len();
        if rest.len() < 8 {
            return Err(DecodeError::invalid(format!(
                "truncated GLB chunk header at byte {offset}"
            )));
        }
        let (head, tail) = rest.split_at(8);
        let chunk_length = u32_le(&head[0..4]) as usize;
        let chunk_type = u32_le(&head[4..8]);
        if chunk_length > tail.len() {
            return Err(DecodeError::invalid(format!(
                "GLB chunk at byte {offset} claims {chunk_length} bytes but only {} remain",
                tail.len()
            )));
        }
        let (data, after) = tail.split_at(chunk_length);
        match (chunk, chunk_type) {
            (0, JSON_CHUNK) => json = Some(data),
            (0, _) => {
                return Err(DecodeError::invalid("the first GLB chunk is not JSON"));
            }
            (1, BIN_CHUNK) => bin = Some(data),
            (_, JSON_CHUNK | BIN_CHUNK) => {
                return Err(DecodeError::invalid(format!(
                    "unexpected extra JSON or BIN chunk at byte {offset}"
                )));
            }
            _ => {} // Unknown chunk types are skipped, as the specification says.
        }
        chunk += 1;
        rest = after;
    }
    let json = json.ok_or_else(|| DecodeError::invalid("GLB without a JSON chunk"))?;
    Ok(Container {
        json,
        bin,
        binary: true,
    })
}

/// The JSON text without the trailing padding (spaces, or the NULs some writers use).
fn trim_json(json: &[u8]) -> &[u8] {
    let end = json
        .iter()
        .rposition(|&b| b != 0 && !b.is_ascii_whitespace())
        .map_or(0, |i| i + 1);
    &json[..end]
}

/// Refuses files that require an extension changing how geometry is stored.
fn check_required_extensions(root: &json::Root) -> Result<(), DecodeError> {
    let ignorable = |name: &str| {
        name.starts_with("KHR_materials_")
            || name.starts_with("KHR_texture_")
            || name.starts_with("EXT_texture_")
            || name == "KHR_lights_punctual"
    };
    for name in &root.extensions_required {
        if name == DRACO {
            return Err(draco_error());
        }
        if !ignorable(name) {
            return Err(DecodeError::Unsupported(format!(
                "the file requires the glTF extension {name}, which iblkit cannot read; \
                 use a copy exported without it"
            )));
        }
    }
    Ok(())
}

fn draco_error() -> DecodeError {
    DecodeError::Unsupported(format!(
        "Draco compression unsupported ({DRACO}); use an uncompressed copy of the model \
         (re-export it without Draco)"
    ))
}

/// The buffers of a glTF file, loaded on first use.
struct Buffers<'a> {
    bin: Option<&'a [u8]>,
    base_dir: Option<&'a Path>,
    loaded: Vec<Option<Cow<'a, [u8]>>>,
    /// Bytes that external buffer files may still add up to.
    external_budget: u64,
}

impl<'a> Buffers<'a> {
    /// The bytes of buffer `index`, exactly `byteLength` of them.
    fn get(&mut self, root: &json::Root, index: usize) -> Result<&[u8], DecodeError> {
        let Some(buffer) = root.buffers.get(index) else {
            return Err(DecodeError::invalid(format!(
                "buffer {index} does not exist ({} buffers)",
                root.buffers.len()
            )));
        };
        if self.loaded.get(index).is_some_and(Option::is_none) {
            let data = self.load(index, buffer)?;
            let declared = buffer.byte_length.0;
            if (data.len() as u64) < declared {
                return Err(DecodeError::invalid(format!(
                    "buffer {index}: byteLength is {declared} but only {} bytes are present",
                    data.len()
                )));
            }
            let declared = declared as usize; // <= data.len()
            let data = match data {
                Cow::Borrowed(b) => Cow::Borrowed(&b[..declared]),
                Cow::Owned(mut v) => {
                    v.truncate(declared);
                    Cow::Owned(v)
                }
            };
            self.loaded[index] = Some(data);
        }
        match self.loaded.get(index) {
            Some(Some(data)) => Ok(data),
            _ => Err(DecodeError::invalid(format!(
                "buffer {index} cannot be loaded"
            ))),
        }
    }

    fn load(&mut self, index: usize, buffer: &json::Buffer) -> Result<Cow<'a, [u8]>, DecodeError> {
        let Some(uri) = &buffer.uri else {
            return match self.bin {
                Some(bin) if index == 0 => Ok(Cow::Borrowed(bin)),
                _ => Err(DecodeError::invalid(format!(
                    "buffer {index} has no uri and is not the GLB binary chunk"
                ))),
            };
        };
        if let Some(data_uri) = uri.strip_prefix("data:") {
            let Some((media, payload)) = data_uri.split_once(',') else {
                return Err(DecodeError::invalid(format!(
                    "buffer {index}: data: URI without a comma"
                )));
            };
            if !media.ends_with(";base64") {
                return Err(DecodeError::Unsupported(format!(
                    "buffer {index}: data: URI that is not base64"
                )));
            }
            return decode_base64(payload)
                .map(Cow::Owned)
                .map_err(|e| DecodeError::invalid(format!("buffer {index}: data: URI: {e}")));
        }
        let Some(dir) = self.base_dir else {
            return Err(DecodeError::Unsupported(format!(
                "buffer {index} is in the external file {uri:?}; byte-level decoding reads \
                 embedded buffers only"
            )));
        };
        let has_scheme = uri
            .split_once(':')
            .is_some_and(|(scheme, _)| !scheme.contains('/'));
        if has_scheme || uri.starts_with('/') || uri.starts_with('\\') {
            return Err(DecodeError::Unsupported(format!(
                "buffer {index} uri {uri:?}: only relative file paths and base64 data: URIs \
                 are read"
            )));
        }
        let relative = percent_decode(uri)
            .ok_or_else(|| DecodeError::invalid(format!("buffer {index}: bad uri {uri:?}")))?;
        let file = dir.join(relative);
        let cannot = |e: std::io::Error| {
            DecodeError::invalid(format!(
                "buffer {index}: cannot read {}: {e}",
                file.display()
            ))
        };
        let len = std::fs::metadata(&file).map_err(cannot)?.len();
        if len > self.external_budget {
            return Err(DecodeError::Limits(format!(
                "buffer {index} ({}) has {len} bytes, over the {} bytes the file size limit \
                 leaves for external buffers",
                file.display(),
                self.external_budget
            )));
        }
        self.external_budget -= len;
        std::fs::read(&file).map(Cow::Owned).map_err(cannot)
    }
}

/// Decodes standard or URL-safe base64; padding ends the data, anything else that is not in
/// the alphabet is an error.
fn decode_base64(text: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 2);
    let mut acc = 0u32;
    let mut bits = 0u32;
    for (i, c) in text.bytes().enumerate() {
        let value = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => break,
            _ => return Err(format!("byte {i} ({:?}) is not base64", char::from(c))),
        };
        acc = (acc << 6) | u32::from(value);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Ok(out)
}

/// Undoes `%XX` escapes of a URI path; `None` for a bad escape or non-UTF-8 result.
fn percent_decode(uri: &str) -> Option<PathBuf> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok().map(PathBuf::from)
}

/// An accessor's elements, bounds-checked: element `i` is `bytes[i * stride..][..size]`.
struct Elements<'b> {
    bytes: &'b [u8],
    stride: usize,
    size: usize,
    count: usize,
}

impl Elements<'_> {
    fn iter(&self) -> impl Iterator<Item = &[u8]> {
        (0..self.count).filter_map(move |i| self.bytes.get(i * self.stride..)?.get(..self.size))
    }
}

/// An accessor whose type and component type have been checked, with what reading it needs.
#[derive(Clone, Copy)]
struct TypedAccessor<'r> {
    accessor: &'r json::Accessor,
    /// Its index in `root.accessors` (for messages).
    index: usize,
    /// Bytes of one element (components x component size).
    element_size: u64,
}

impl TypedAccessor<'_> {
    /// Number of elements, as the file states it (not yet checked against its buffer).
    fn count(&self) -> u64 {
        self.accessor.count.0
    }
}

/// The accessor `index`, checked to have the given type and one of the component types.
fn typed_accessor<'r>(
    root: &'r json::Root,
    index: usize,
    what: &str,
    ty: Type,
    components: &[ComponentType],
) -> Result<TypedAccessor<'r>, DecodeError> {
    let Some(accessor) = root.accessors.get(index) else {
        return Err(DecodeError::invalid(format!(
            "{what}: accessor {index} does not exist ({} accessors)",
            root.accessors.len()
        )));
    };
    let (Checked::Valid(actual_ty), Checked::Valid(actual_component)) =
        (&accessor.type_, &accessor.component_type)
    else {
        return Err(DecodeError::invalid(format!(
            "{what}: accessor {index} has an unknown type or componentType"
        )));
    };
    if *actual_ty != ty || !components.contains(&actual_component.0) || accessor.normalized {
        return Err(DecodeError::Unsupported(format!(
            "{what}: accessor {index} is {actual_ty:?} of {:?}{} (expected {ty:?} of {})",
            actual_component.0,
            if accessor.normalized {
                ", normalized"
            } else {
                ""
            },
            components
                .iter()
                .map(|c| format!("{c:?}"))
                .collect::<Vec<_>>()
                .join(" or ")
        )));
    }
    Ok(TypedAccessor {
        accessor,
        index,
        element_size: type_components(ty) * component_size(actual_component.0),
    })
}

fn component_size(c: ComponentType) -> u64 {
    match c {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

fn type_components(t: Type) -> u64 {
    match t {
        Type::Scalar => 1,
        Type::Vec2 => 2,
        Type::Vec3 => 3,
        Type::Vec4 | Type::Mat2 => 4,
        Type::Mat3 => 9,
        Type::Mat4 => 16,
    }
}

/// Locates a type-checked accessor's bytes, checking every offset and length.
fn elements<'b>(
    root: &json::Root,
    buffers: &'b mut Buffers<'_>,
    typed: TypedAccessor<'_>,
    what: &str,
) -> Result<Elements<'b>, DecodeError> {
    let TypedAccessor {
        accessor,
        index,
        element_size: size,
    } = typed;
    if accessor.sparse.is_some() {
        return Err(DecodeError::Unsupported(format!(
            "{what}: accessor {index} is sparse"
        )));
    }
    let Some(view_index) = accessor.buffer_view.map(|v| v.value()) else {
        if root.extensions_used.iter().any(|e| e == DRACO) {
            return Err(draco_error());
        }
        return Err(DecodeError::Unsupported(format!(
            "{what}: accessor {index} has no bufferView (zero-filled accessors are not read)"
        )));
    };
    let Some(view) = root.buffer_views.get(view_index) else {
        return Err(DecodeError::invalid(format!(
            "{what}: bufferView {view_index} does not exist ({} bufferViews)",
            root.buffer_views.len()
        )));
    };
    let stride = view.byte_stride.map_or(size, |s| s.0 as u64);
    if stride < size {
        return Err(DecodeError::invalid(format!(
            "{what}: bufferView {view_index} byteStride {stride} is shorter than the \
             {size}-byte elements of accessor {index}"
        )));
    }
    let count = accessor.count.0;
    let start = accessor.byte_offset.map_or(0, |o| o.0);
    let span = match count {
        0 => Some(0),
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|s| s.checked_add(size)),
    };
    let end = span.and_then(|s| s.checked_add(start));
    let view_length = view.byte_length.0;
    let Some(end) = end.filter(|&e| e <= view_length) else {
        return Err(DecodeError::invalid(format!(
            "{what}: accessor {index} out of bounds: {count} elements of {size} bytes, stride \
             {stride}, from byte {start} of bufferView {view_index}, which has {view_length} bytes"
        )));
    };
    let buffer_index = view.buffer.value();
    let view_start = view.byte_offset.map_or(0, |o| o.0);
    let data = buffers.get(root, buffer_index)?;
    let view_end = view_start.checked_add(view_length);
    if view_end.is_none_or(|e| e > data.len() as u64) {
        return Err(DecodeError::invalid(format!(
            "{what}: bufferView {view_index} out of bounds: {view_length} bytes from byte \
             {view_start} of buffer {buffer_index}, which has {} bytes",
            data.len()
        )));
    }
    // Every value below is now at most data.len(), so the conversions are exact.
    let bytes = &data[(view_start + start) as usize..(view_start + end) as usize];
    Ok(Elements {
        bytes,
        stride: stride as usize,
        size: size as usize,
        count: count as usize,
    })
}

fn read_vec3(elements: &Elements<'_>) -> Vec<Vec3> {
    elements
        .iter()
        .map(|e| {
            Vec3::new(
                f32::from_le_bytes([e[0], e[1], e[2], e[3]]),
                f32::from_le_bytes([e[4], e[5], e[6], e[7]]),
                f32::from_le_bytes([e[8], e[9], e[10], e[11]]),
            )
        })
        .collect()
}

fn read_indices(elements: &Elements<'_>) -> Vec<u32> {
    elements
        .iter()
        .map(|e| match *e {
            [a] => u32::from(a),
            [a, b] => u32::from(u16::from_le_bytes([a, b])),
            _ => u32_le(e),
        })
        .collect()
}

/// Collects the triangles of every mesh instance of a glTF scene.
struct GltfBuilder<'l> {
    limits: &'l MeshLimits,
    mesh: TriangleMesh,
    base_colors: Vec<Rgb>,
    /// Material slot of each glTF material index (`None`: no material).
    slot_of: HashMap<Option<usize>, u32>,
    instances: usize,
    without_normals: usize,
    skipped_non_triangle: usize,
    skipped_singular: usize,
}

impl<'l> GltfBuilder<'l> {
    fn new(limits: &'l MeshLimits) -> Self {
        GltfBuilder {
            limits,
            mesh: TriangleMesh::default(),
            base_colors: Vec::new(),
            slot_of: HashMap::new(),
            instances: 0,
            without_normals: 0,
            skipped_non_triangle: 0,
            skipped_singular: 0,
        }
    }

    /// The material slot of a glTF material (created on first use).
    fn slot(&mut self, root: &json::Root, material: Option<usize>) -> Result<u32, DecodeError> {
        if let Some(&slot) = self.slot_of.get(&material) {
            return Ok(slot);
        }
        let (mut name, base_color) = match material {
            None => (DEFAULT_MATERIAL_NAME.to_owned(), DEFAULT_BASE_COLOR),
            Some(m) => {
                let Some(mat) = root.materials.get(m) else {
                    return Err(DecodeError::invalid(format!(
                        "material {m} does not exist ({} materials)",
                        root.materials.len()
                    )));
                };
                let [r, g, b, _] = mat.pbr_metallic_roughness.base_color_factor.0;
                let name = mat.name.clone().unwrap_or_else(|| format!("material{m}"));
                (name, Rgb::new(r, g, b))
            }
        };
        if self.mesh.material_names.contains(&name) {
            name = format!("{name}#{}", self.mesh.material_names.len());
        }
        let slot = self.mesh.material_names.len() as u32;
        self.mesh.material_names.push(name);
        self.base_colors.push(base_color);
        self.slot_of.insert(material, slot);
        Ok(slot)
    }

    /// Adds one primitive of mesh `mesh_index` placed by `world_from_model`.
    fn add_primitive(
        &mut self,
        root: &json::Root,
        buffers: &mut Buffers<'_>,
        (mesh_index, primitive_index): (usize, usize),
        primitive: &json::mesh::Primitive,
        world_from_model: Mat4,
    ) -> Result<(), DecodeError> {
        let what = format!("mesh {mesh_index} primitive {primitive_index}");
        let Checked::Valid(mode) = primitive.mode else {
            return Err(DecodeError::invalid(format!("{what}: unknown mode")));
        };
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            self.skipped_non_triangle += 1;
            return Ok(());
        }
        let attribute = |s: Semantic| {
            primitive
                .attributes
                .get(&Checked::Valid(s))
                .map(|i| i.value())
        };
        let Some(position_index) = attribute(Semantic::Positions) else {
            return Err(DecodeError::invalid(format!("{what} has no POSITION")));
        };
        let f32_only = [ComponentType::F32];
        let index_types = [ComponentType::U8, ComponentType::U16, ComponentType::U32];
        let position_what = format!("{what} POSITION");
        let positions =
            typed_accessor(root, position_index, &position_what, Type::Vec3, &f32_only)?;
        let vertex_count = positions.count();
        let index_what = format!("{what} indices");
        let indices = match primitive.indices.map(|i| i.value()) {
            Some(i) => Some(typed_accessor(
                root,
                i,
                &index_what,
                Type::Scalar,
                &index_types,
            )?),
            None => None,
        };
        let corner_count = indices.map_or(vertex_count, |a| a.count());
        let triangle_count = match mode {
            Mode::Triangles if corner_count % 3 != 0 => {
                return Err(DecodeError::invalid(format!(
                    "{what}: {corner_count} indices is not a multiple of 3"
                )));
            }
            Mode::Triangles => corner_count / 3,
            _ => corner_count.saturating_sub(2),
        };

        // Limits, before anything is read or allocated.
        let total_triangles = (self.mesh.triangles.len() as u64).saturating_add(triangle_count);
        if total_triangles > self.limits.max_triangles as u64 {
            return Err(DecodeError::Limits(format!(
                "{what} brings the mesh to {total_triangles} triangles, over the limit of {}",
                self.limits.max_triangles
            )));
        }
        let total_vertices = (self.mesh.positions.len() as u64).saturating_add(vertex_count);
        if total_vertices > self.limits.max_vertices() {
            return Err(DecodeError::Limits(format!(
                "{what} brings the mesh to {total_vertices} vertices, over the limit of {}",
                self.limits.max_vertices()
            )));
        }

        let model_from_local = Mat3::from_mat4(world_from_model);
        let determinant = model_from_local.determinant();
        if determinant == 0.0 {
            // A singular transform (e.g. a zero scale) flattens every triangle to zero area.
            self.skipped_singular += 1;
            return Ok(());
        }

        let local_positions = read_vec3(&elements(root, buffers, positions, &position_what)?);
        let local_normals = match attribute(Semantic::Normals) {
            Some(normal_index) => {
                let normal_what = format!("{what} NORMAL");
                let normals =
                    typed_accessor(root, normal_index, &normal_what, Type::Vec3, &f32_only)?;
                if normals.count() != vertex_count {
                    return Err(DecodeError::invalid(format!(
                        "{what}: {} normals for {vertex_count} positions",
                        normals.count()
                    )));
                }
                Some(read_vec3(&elements(root, buffers, normals, &normal_what)?))
            }
            None => None,
        };
        let corners: Vec<u32> = match indices {
            Some(accessor) => {
                let corners = read_indices(&elements(root, buffers, accessor, &index_what)?);
                if let Some(bad) = corners.iter().find(|&&c| u64::from(c) >= vertex_count) {
                    return Err(DecodeError::invalid(format!(
                        "{what}: index {bad} out of range ({vertex_count} vertices)"
                    )));
                }
                corners
            }
            None => (0..vertex_count as u32).collect(), // vertex_count <= u32::MAX (limits)
        };
        let slot = self.slot(root, primitive.material.map(|m| m.value()))?;

        let base = self.mesh.positions.len() as u32; // total_vertices <= u32::MAX
        let mirrored = determinant < 0.0;
        let normal_from_local = model_from_local.inverse().transpose();
        self.mesh.positions.extend(
            local_positions
                .iter()
                .map(|&p| world_from_model.transform_point3(p)),
        );
        match local_normals {
            Some(normals) => self.mesh.normals.extend(
                normals
                    .iter()
                    .map(|&n| normalize_or_keep(normal_from_local * n)),
            ),
            None => {
                self.without_normals += 1;
                self.mesh
                    .normals
                    .resize(self.mesh.positions.len(), Vec3::ZERO);
            }
        }
        let triangle = |[a, b, c]: [u32; 3]| {
            let [a, b, c] = [a + base, b + base, c + base];
            if mirrored { [a, c, b] } else { [a, b, c] }
        };
        let new_triangles = self.mesh.triangles.len();
        match mode {
            Mode::Triangles => self.mesh.triangles.extend(
                corners
                    .chunks_exact(3)
                    .map(|c| triangle([c[0], c[1], c[2]])),
            ),
            Mode::TriangleStrip => self
                .mesh
                .triangles
                .extend(corners.windows(3).enumerate().map(|(i, c)| {
                    // p_i = (v_i, v_{i + 1 + i % 2}, v_{i + 2 - i % 2}).
                    if i % 2 == 0 {
                        triangle([c[0], c[1], c[2]])
                    } else {
                        triangle([c[0], c[2], c[1]])
                    }
                })),
            _ => {
                // TRIANGLE_FAN: p_i = (v_{i + 1}, v_{i + 2}, v_0).
                if let Some((&first, rest)) = corners.split_first() {
                    self.mesh
                        .triangles
                        .extend(rest.windows(2).map(|c| triangle([c[0], c[1], first])));
                }
            }
        }
        let added = self.mesh.triangles.len() - new_triangles;
        self.mesh
            .material_slots
            .extend(std::iter::repeat_n(slot, added));
        self.instances += 1;
        Ok(())
    }

    fn finish(mut self, format: &str) -> Result<LoadedMesh, DecodeError> {
        let mut notes = Vec::new();
        if self.without_normals > 0 {
            if self.without_normals < self.instances {
                notes.push(format!(
                    "normals dropped: {} of {} primitive instances have none",
                    self.without_normals, self.instances
                ));
            }
            self.mesh.normals.clear();
        }
        if self.skipped_non_triangle > 0 {
            notes.push(format!(
                "{} point or line primitive instances skipped",
                self.skipped_non_triangle
            ));
        }
        if self.skipped_singular > 0 {
            notes.push(format!(
                "{} primitive instances under a singular (zero-scale) transform skipped",
                self.skipped_singular
            ));
        }
        finish(self.mesh, self.base_colors, format, notes)
    }
}

/// `v / |v|`, or `v` itself when it has no direction (zero, or not finite), for [`finish`] to
/// drop or [`TriangleMesh::validate`] to refuse.
fn normalize_or_keep(v: Vec3) -> Vec3 {
    let length = v.length();
    if length > 0.0 && length.is_finite() {
        v / length
    } else {
        v
    }
}

/// The local transform of a node: its `matrix` (column-major) or `T * R * S`.
fn local_transform(node: &json::Node) -> Mat4 {
    if let Some(m) = &node.matrix {
        return Mat4::from_cols_array(m);
    }
    let translation = node.translation.map_or(Vec3::ZERO, Vec3::from_array);
    let rotation = node
        .rotation
        .as_ref()
        .map_or(Quat::IDENTITY, |q| Quat::from_array(q.0).normalize());
    let scale = node.scale.map_or(Vec3::ONE, Vec3::from_array);
    Mat4::from_scale_rotation_translation(scale, rotation, translation)
}

/// Walks the default scene's node trees depth first, adding every mesh instance.
fn walk_scene(
    root: &json::Root,
    buffers: &mut Buffers<'_>,
    builder: &mut GltfBuilder<'_>,
) -> Result<(), DecodeError> {
    let roots: Vec<usize> = match root.scene.map(|s| s.value()) {
        Some(s) => match root.scenes.get(s) {
            Some(scene) => scene.nodes.iter().map(|n| n.value()).collect(),
            None => {
                return Err(DecodeError::invalid(format!(
                    "scene {s} does not exist ({} scenes)",
                    root.scenes.len()
                )));
            }
        },
        None => match root.scenes.first() {
            Some(scene) => scene.nodes.iter().map(|n| n.value()).collect(),
            None => {
                let mut is_child = vec![false; root.nodes.len()];
                for child in root.nodes.iter().flat_map(|n| n.children.iter().flatten()) {
                    if let Some(flag) = is_child.get_mut(child.value()) {
                        *flag = true;
                    }
                }
                (0..root.nodes.len()).filter(|&n| !is_child[n]).collect()
            }
        },
    };
    let mut visited = vec![false; root.nodes.len()];
    let mut stack: Vec<(usize, Mat4)> = roots.iter().rev().map(|&n| (n, Mat4::IDENTITY)).collect();
    while let Some((node_index, parent)) = stack.pop() {
        let Some(node) = root.nodes.get(node_index) else {
            return Err(DecodeError::invalid(format!(
                "node {node_index} does not exist ({} nodes)",
                root.nodes.len()
            )));
        };
        if std::mem::replace(&mut visited[node_index], true) {
            return Err(DecodeError::invalid(format!(
                "node {node_index} is reached twice; the node hierarchy must be a tree"
            )));
        }
        let world = parent * local_transform(node);
        if let Some(mesh_index) = node.mesh.map(|m| m.value()) {
            let Some(mesh) = root.meshes.get(mesh_index) else {
                return Err(DecodeError::invalid(format!(
                    "node {node_index}: mesh {mesh_index} does not exist ({} meshes)",
                    root.meshes.len()
                )));
            };
            for (p, primitive) in mesh.primitives.iter().enumerate() {
                builder.add_primitive(root, buffers, (mesh_index, p), primitive, world)?;
            }
        }
        for child in node.children.iter().flatten().rev() {
            stack.push((child.value(), world));
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// OBJ
// ---------------------------------------------------------------------------------------------

/// An OBJ file parsed, before material colours and validation.
struct ParsedObj {
    mesh: TriangleMesh,
    /// File names from `mtllib` lines, in order.
    material_libraries: Vec<String>,
    /// Notes for the details line.
    notes: Vec<String>,
}

/// Decodes Wavefront OBJ bytes; `mtl` is the content of its material library, if any (the
/// `mtllib` lines themselves are not followed). The mesh is validated. Never panics.
pub fn decode_obj(
    obj: &[u8],
    mtl: Option<&[u8]>,
    limits: &MeshLimits,
) -> Result<LoadedMesh, DecodeError> {
    let parsed = parse_obj(obj, limits)?;
    let colors = match mtl {
        Some(m) => {
            parse_mtl(m).map_err(|e| DecodeError::invalid(format!("material library: {e}")))?
        }
        None => HashMap::new(),
    };
    let base_colors = base_colors_of(&parsed.mesh.material_names, &colors);
    finish(parsed.mesh, base_colors, "Wavefront OBJ", parsed.notes)
}

/// Reads an OBJ file and the `.mtl` files it names.
fn read_obj(
    path: &Path,
    dir: &Path,
    bytes: &[u8],
    limits: &MeshLimits,
) -> Result<LoadedMesh, IoError> {
    let mut parsed = parse_obj(bytes, limits).map_err(|e| e.with_path(path))?;
    let mut colors = HashMap::new();
    for library in std::mem::take(&mut parsed.material_libraries) {
        // `mtllib a.mtl b.mtl` names two files, but exporters also write unquoted names with
        // spaces: the whole argument is tried first.
        let whole = dir.join(&library);
        let files: Vec<PathBuf> = if whole.is_file() {
            vec![whole]
        } else {
            library.split_whitespace().map(|f| dir.join(f)).collect()
        };
        for file in files {
            if !file.is_file() {
                parsed.notes.push(format!(
                    "material library {} not found, default base colours",
                    file.display()
                ));
                continue;
            }
            let text = read_bounded(&file, limits.max_file_bytes)?;
            let found = parse_mtl(&text).map_err(|e| e.with_path(&file))?;
            colors.extend(found);
        }
    }
    let base_colors = base_colors_of(&parsed.mesh.material_names, &colors);
    finish(parsed.mesh, base_colors, "Wavefront OBJ", parsed.notes).map_err(|e| e.with_path(path))
}

fn base_colors_of(names: &[String], colors: &HashMap<String, Rgb>) -> Vec<Rgb> {
    names
        .iter()
        .map(|n| colors.get(n).copied().unwrap_or(DEFAULT_BASE_COLOR))
        .collect()
}

/// The text of a line without its comment, and its arguments after the keyword.
fn obj_line(raw: &[u8]) -> Cow<'_, str> {
    let line = String::from_utf8_lossy(raw);
    match line.find('#') {
        Some(hash) => Cow::Owned(line[..hash].to_owned()),
        None => line,
    }
}

fn parse_floats<const N: usize>(
    mut words: std::str::SplitWhitespace<'_>,
    line: usize,
    keyword: &str,
) -> Result<[f32; N], DecodeError> {
    let mut out = [0.0f32; N];
    for value in &mut out {
        let word = words.next().ok_or_else(|| {
            DecodeError::invalid(format!("line {line}: {keyword} needs {N} numbers"))
        })?;
        *value = word.parse().map_err(|_| {
            DecodeError::invalid(format!("line {line}: {keyword}: {word:?} is not a number"))
        })?;
    }
    Ok(out)
}

/// Resolves a 1-based or negative OBJ index against the `defined` elements so far.
fn resolve_index(word: &str, defined: usize, line: usize, what: &str) -> Result<u32, DecodeError> {
    let raw: i64 = word
        .parse()
        .map_err(|_| DecodeError::invalid(format!("line {line}: bad {what} index {word:?}")))?;
    let defined = defined as i64;
    let resolved = if raw < 0 {
        defined.checked_add(raw)
    } else {
        Some(raw - 1)
    };
    match resolved {
        Some(i) if raw != 0 && (0..defined).contains(&i) => Ok(i as u32),
        _ => Err(DecodeError::invalid(format!(
            "line {line}: {what} index {raw} out of range ({defined} defined so far)"
        ))),
    }
}

fn parse_obj(bytes: &[u8], limits: &MeshLimits) -> Result<ParsedObj, DecodeError> {
    const NO_NORMAL: u32 = u32::MAX;
    let mut positions: Vec<Vec3> = Vec::new();
    let mut normals: Vec<Vec3> = Vec::new();
    let mut mesh = TriangleMesh::default();
    // (position index, normal index or NO_NORMAL) of each output vertex.
    let mut vertex_of: HashMap<(u32, u32), u32> = HashMap::new();
    let mut vertex_keys: Vec<(u32, u32)> = Vec::new();
    let mut slot_of: HashMap<String, u32> = HashMap::new();
    let mut slot: Option<u32> = None;
    let mut material_libraries = Vec::new();
    let mut corners_without_normal = 0usize;
    let mut corners: Vec<u32> = Vec::new();
    let mut slot_for = |name: &str, mesh: &mut TriangleMesh| -> u32 {
        *slot_of.entry(name.to_owned()).or_insert_with(|| {
            mesh.material_names.push(name.to_owned());
            (mesh.material_names.len() - 1) as u32
        })
    };

    for (number, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = number + 1;
        let text = obj_line(raw);
        let mut words = text.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let argument = || text.trim()[keyword.len()..].trim();
        match keyword {
            "v" => positions.push(Vec3::from_array(parse_floats::<3>(words, line, "v")?)),
            "vn" => normals.push(Vec3::from_array(parse_floats::<3>(words, line, "vn")?)),
            "f" => {
                corners.clear();
                for word in words {
                    let mut parts = word.split('/');
                    let v = parts.next().unwrap_or_default();
                    let _texture = parts.next();
                    let n = parts.next().filter(|n| !n.is_empty());
                    if parts.next().is_some() {
                        return Err(DecodeError::invalid(format!(
                            "line {line}: bad face corner {word:?}"
                        )));
                    }
                    let v = resolve_index(v, positions.len(), line, "vertex")?;
                    let n = match n {
                        Some(n) => resolve_index(n, normals.len(), line, "normal")?,
                        None => {
                            corners_without_normal += 1;
                            NO_NORMAL
                        }
                    };
                    let Ok(next) = u32::try_from(vertex_keys.len()) else {
                        return Err(DecodeError::Limits(format!(
                            "line {line}: more than {} vertices",
                            u32::MAX
                        )));
                    };
                    let vertex = *vertex_of.entry((v, n)).or_insert(next);
                    if vertex == next {
                        vertex_keys.push((v, n));
                    }
                    corners.push(vertex);
                }
                if corners.len() < 3 {
                    return Err(DecodeError::invalid(format!(
                        "line {line}: a face needs at least 3 corners, this one has {}",
                        corners.len()
                    )));
                }
                let total = mesh.triangles.len() + corners.len() - 2;
                if total > limits.max_triangles {
                    return Err(DecodeError::Limits(format!(
                        "line {line}: more than {} triangles",
                        limits.max_triangles
                    )));
                }
                let s = match slot {
                    Some(s) => s,
                    None => *slot.insert(slot_for(DEFAULT_MATERIAL_NAME, &mut mesh)),
                };
                for i in 1..corners.len() - 1 {
                    mesh.triangles
                        .push([corners[0], corners[i], corners[i + 1]]);
                    mesh.material_slots.push(s);
                }
            }
            "usemtl" => {
                let name = argument();
                if name.is_empty() {
                    return Err(DecodeError::invalid(format!(
                        "line {line}: usemtl without a name"
                    )));
                }
                slot = Some(slot_for(name, &mut mesh));
            }
            "mtllib" => {
                let name = argument();
                if !name.is_empty() {
                    material_libraries.push(name.to_owned());
                }
            }
            _ => {}
        }
    }

    let mut notes = Vec::new();
    mesh.positions = vertex_keys
        .iter()
        .map(|&(v, _)| positions[v as usize])
        .collect();
    if corners_without_normal == 0 {
        mesh.normals = vertex_keys
            .iter()
            .map(|&(_, n)| normalize_or_keep(normals[n as usize]))
            .collect();
    } else if !normals.is_empty() {
        notes.push(format!(
            "normals dropped: {corners_without_normal} face corners have none"
        ));
    }
    Ok(ParsedObj {
        mesh,
        material_libraries,
        notes,
    })
}

/// `Kd` of every `newmtl` of a material library.
fn parse_mtl(bytes: &[u8]) -> Result<HashMap<String, Rgb>, DecodeError> {
    let mut colors = HashMap::new();
    let mut current: Option<String> = None;
    for (number, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = number + 1;
        let text = obj_line(raw);
        let mut words = text.split_whitespace();
        match words.next() {
            Some("newmtl") => {
                let name = text.trim()["newmtl".len()..].trim();
                if name.is_empty() {
                    return Err(DecodeError::invalid(format!(
                        "line {line}: newmtl without a name"
                    )));
                }
                current = Some(name.to_owned());
            }
            Some("Kd") => {
                let values: Vec<&str> = words.collect();
                let parsed: Result<Vec<f32>, _> = values.iter().map(|w| w.parse()).collect();
                let kd = match parsed.as_deref() {
                    Ok([v]) => Rgb::splat(*v),
                    Ok([r, g, b]) => Rgb::new(*r, *g, *b),
                    _ => {
                        return Err(DecodeError::Unsupported(format!(
                            "line {line}: Kd {} (only one or three numbers are read)",
                            values.join(" ")
                        )));
                    }
                };
                if ![kd.r, kd.g, kd.b]
                    .iter()
                    .all(|c| c.is_finite() && *c >= 0.0)
                {
                    return Err(DecodeError::invalid(format!(
                        "line {line}: Kd must be finite and non-negative"
                    )));
                }
                if let Some(name) = &current {
                    colors.insert(name.clone(), kd);
                }
            }
            _ => {}
        }
    }
    Ok(colors)
}

// ---------------------------------------------------------------------------------------------
// Common
// ---------------------------------------------------------------------------------------------

/// Drops unusable normals, validates, and writes the details line.
fn finish(
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

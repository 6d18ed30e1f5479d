//! glTF 2.0 meshes (Khronos glTF 2.0 specification: GLB container, buffers, accessors, meshes, node
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
//! Normals, validation and the details line: see [`super::loaded`].

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

use super::loaded::{
    DEFAULT_BASE_COLOR, DEFAULT_MATERIAL_NAME, LoadedMesh, MeshLimits, finish, normalize_or_keep,
};
use crate::error::DecodeError;

/// The glTF extension for Draco-compressed geometry.
const DRACO: &str = "KHR_draco_mesh_compression";

/// Decodes glTF 2.0 bytes, binary (`.glb`) or JSON (`.gltf`), whose buffers are all embedded (the
/// GLB binary chunk or base64 `data:` URIs); a buffer in an external file is
/// [`DecodeError::Unsupported`] here ([`super::read_mesh`] resolves those next to the file). The mesh is
/// validated. Never panics; allocations are bounded by `limits` and the input size.
pub fn decode_gltf(bytes: &[u8], limits: &MeshLimits) -> Result<LoadedMesh, DecodeError> {
    decode_gltf_in(bytes, None, limits)
}

/// [`decode_gltf`] with external buffer files resolved in `base_dir` (none: refused).
pub(super) fn decode_gltf_in(
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
            return decode_base64(payload).map(Cow::Owned).map_err(|e| {
                DecodeError::invalid(format!("buffer {index}: data: URI is not base64: {e}"))
            });
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
        // Bounded by what the file size limit leaves, whatever the file is (a device, a FIFO
        // and a directory are refused by type).
        let bytes = crate::read_bounded(&file, self.external_budget).map_err(|e| match e {
            crate::IoError::Limits { .. } => DecodeError::Limits(format!(
                "buffer {index} ({}) is over the {} bytes the file size limit leaves for \
                 external buffers",
                file.display(),
                self.external_budget
            )),
            other => DecodeError::invalid(format!("buffer {index}: cannot read {other}")),
        })?;
        self.external_budget -= bytes.len() as u64;
        Ok(Cow::Owned(bytes))
    }
}

/// Decodes the base64 payload of a `data:` URI: the standard alphabet (RFC 4648 section 4, as
/// RFC 2397 uses), or the URL-safe one (section 5) that some exporters write; padding optional.
fn decode_base64(text: &str) -> Result<Vec<u8>, base64::DecodeError> {
    use base64::Engine as _;
    use base64::alphabet::{STANDARD, URL_SAFE};
    use base64::engine::{DecodePaddingMode, GeneralPurpose, GeneralPurposeConfig};
    let config = GeneralPurposeConfig::new()
        .with_decode_padding_mode(DecodePaddingMode::Indifferent)
        .with_decode_allow_trailing_bits(true);
    GeneralPurpose::new(&STANDARD, config)
        .decode(text)
        .or_else(|e| {
            GeneralPurpose::new(&URL_SAFE, config)
                .decode(text)
                .map_err(|_| e)
        })
}

/// Undoes `%XX` escapes of a URI path; `None` for a non-UTF-8 result.
fn percent_decode(uri: &str) -> Option<PathBuf> {
    percent_encoding::percent_decode_str(uri)
        .decode_utf8()
        .ok()
        .map(|path| PathBuf::from(path.as_ref()))
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

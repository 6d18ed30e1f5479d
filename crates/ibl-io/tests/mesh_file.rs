//! Mesh files: the bundled glTF models, hand-made glTF and OBJ fixtures with values computed by
//! hand (`tests/data/meshes/README.md`), and hostile input that must fail with a bad-input error
//! naming the file, never a panic.

use std::path::{Path, PathBuf};

use ibl_core::Rgb;
use ibl_core::glam::Vec3;
use ibl_io::mesh_file::{DEFAULT_BASE_COLOR, decode_gltf, decode_obj};
use ibl_io::{IoError, LoadedMesh, MeshLimits, read_mesh};
use ibl_scene::TriangleMesh;
use ibl_scene::mesh::triangle_area;
use serde_json::{Value, json};

fn models_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/models")
}

fn fixtures_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes")
}

fn load(path: &Path) -> LoadedMesh {
    read_mesh(path, &MeshLimits::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn close(a: Vec3, b: Vec3, tolerance: f32) -> bool {
    (a - b).abs().max_element() <= tolerance
}

/// Geometric (right-hand, counter-clockwise) unit normal of triangle `i`.
fn face_normal(mesh: &TriangleMesh, i: usize) -> Vec3 {
    let [a, b, c] = mesh.corners(i);
    (b - a).cross(c - a).normalize()
}

/// Splits a GLB into its JSON (parsed) and binary chunk.
fn split_glb(bytes: &[u8]) -> (Value, Vec<u8>) {
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().expect("4 bytes")) as usize;
    let json = serde_json::from_slice(&bytes[20..20 + json_len]).expect("GLB JSON chunk");
    let bin_start = 20 + json_len;
    let bin_len =
        u32::from_le_bytes(bytes[bin_start..bin_start + 4].try_into().expect("4 bytes")) as usize;
    (json, bytes[bin_start + 8..bin_start + 8 + bin_len].to_vec())
}

/// Builds a GLB from a JSON value and a binary chunk (both padded to 4 bytes).
fn make_glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut text = serde_json::to_vec(json).expect("JSON serialises");
    text.resize(text.len().next_multiple_of(4), b' ');
    let mut bin = bin.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let word = chunk
            .iter()
            .enumerate()
            .fold(0u32, |w, (i, &b)| w | u32::from(b) << (16 - 8 * i));
        for i in 0..=chunk.len() {
            out.push(char::from(ALPHABET[(word >> (18 - 6 * i) & 63) as usize]));
        }
        for _ in chunk.len()..3 {
            out.push('=');
        }
    }
    out
}

/// A glTF document with one node, one mesh and one primitive: float VEC3 `positions` then u32
/// `indices` (if any) in a base64 `data:` buffer.
fn gltf_doc(positions: &[[f32; 3]], indices: Option<&[u32]>) -> Value {
    let mut data: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let position_bytes = data.len();
    let mut primitive = json!({"attributes": {"POSITION": 0}});
    let mut accessors = vec![json!(
        {"bufferView": 0, "componentType": 5126, "count": positions.len(), "type": "VEC3"}
    )];
    let mut views = vec![json!({"buffer": 0, "byteLength": position_bytes})];
    if let Some(indices) = indices {
        data.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
        primitive["indices"] = json!(1);
        accessors.push(
            json!({"bufferView": 1, "componentType": 5125, "count": indices.len(), "type": "SCALAR"}),
        );
        views.push(json!({"buffer": 0, "byteOffset": position_bytes,
                          "byteLength": data.len() - position_bytes}));
    }
    json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [primitive]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": data.len(),
                     "uri": format!("data:application/octet-stream;base64,{}", base64(&data))}],
    })
}

const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// Writes `bytes` as `name` in a fresh directory and reads it: the error must be bad input,
/// name the file and contain `expected`.
fn expect_bad(name: &str, bytes: &[u8], expected: &str) -> IoError {
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).expect("writes the test file");
    let error = match read_mesh(&path, &MeshLimits::default()) {
        Ok(m) => panic!("{name}: loaded ({}), expected an error", m.details),
        Err(e) => e,
    };
    let message = error.to_string();
    assert!(error.is_bad_input(), "{name}: not bad input: {message}");
    assert!(
        message.contains(name),
        "{name}: message does not name the file: {message}"
    );
    assert!(
        message.contains(expected),
        "{name}: expected {expected:?} in: {message}"
    );
    error
}

// ---------------------------------------------------------------------------------------------
// Bundled models
// ---------------------------------------------------------------------------------------------

#[test]
fn bunny_glb_loads_with_its_counts_bounds_and_normals() {
    let path = models_dir().join("bunny.glb");
    let loaded = load(&path);
    let mesh = &loaded.mesh;
    assert_eq!(mesh.positions.len(), 2826);
    assert_eq!(mesh.triangle_count(), 5648, "{}", loaded.details);
    assert_eq!(mesh.normals.len(), 2826);
    assert_eq!(mesh.material_names, ["base"]);
    assert_eq!(loaded.base_colors, [Rgb::splat(0.8)]);
    assert!(
        loaded
            .details
            .starts_with("glTF 2.0 binary, 2826 vertices, 5648 triangles")
    );
    // Bounds equal the POSITION accessor's min/max (identity node transform), to f32 rounding.
    let (json, _) = split_glb(&std::fs::read(&path).unwrap());
    let bound = |key: &str| {
        let v: Vec<f32> = serde_json::from_value(json["accessors"][0][key].clone()).unwrap();
        Vec3::new(v[0], v[1], v[2])
    };
    let (lo, hi) = mesh.bounds().unwrap();
    assert!(close(lo, bound("min"), 1e-6) && close(hi, bound("max"), 1e-6));
    // Normals are unit length to 1e-6 and mostly agree with the faces around them: the mean
    // cosine between a triangle's geometric normal and its corners' normals is over 0.9.
    assert!(mesh.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-6));
    let mean_cos: f32 = (0..mesh.triangle_count())
        .map(|t| {
            let f = face_normal(mesh, t);
            mesh.triangles[t]
                .iter()
                .map(|&v| f.dot(mesh.normals[v as usize]))
                .sum::<f32>()
                / 3.0
        })
        .sum::<f32>()
        / mesh.triangle_count() as f32;
    // Smooth vertex normals of a finely tessellated model point nearly along their faces' normals
    // (cos close to 1 on average); a mean cosine of 0.9 still catches flipped or scrambled normals
    // (mean near 0).
    assert!(mean_cos > 0.9, "mean cosine {mean_cos}");
}

#[test]
fn suzanne_glb_loads_with_its_counts() {
    let loaded = load(&models_dir().join("suzanne.glb"));
    assert_eq!(loaded.mesh.positions.len(), 7503);
    assert_eq!(loaded.mesh.triangle_count(), 14842, "{}", loaded.details);
    assert_eq!(loaded.mesh.normals.len(), 7503);
    // The material has no baseColorFactor: the glTF default is 1.
    assert_eq!(loaded.base_colors, [Rgb::ONE]);
}

// ---------------------------------------------------------------------------------------------
// Hand-made glTF fixtures
// ---------------------------------------------------------------------------------------------

#[test]
fn node_transforms_are_applied_as_computed_by_hand() {
    let loaded = load(&fixtures_dir().join("transforms.gltf"));
    let mesh = &loaded.mesh;
    // parent: p -> (1,2,3) + Ry(90)(2p), with Ry(90)(x,y,z) = (z, y, -x);
    // child: parent(p + (0,0,-5)); mirror: (-x, y, z) with reversed winding.
    // Depth-first order: parent, child, mirror. The node outside the default scene is ignored.
    let expected_corners = [
        [[1.0, 2.0, 3.0], [1.0, 2.0, 1.0], [1.0, 4.0, 3.0]],
        [[-9.0, 2.0, 3.0], [-9.0, 2.0, 1.0], [-9.0, 4.0, 3.0]],
        [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]],
    ];
    let expected_normals = [Vec3::X, Vec3::X, Vec3::Z];
    assert_eq!(mesh.positions.len(), 9);
    assert_eq!(mesh.triangle_count(), 3);
    for t in 0..3 {
        let corners = mesh.corners(t);
        for (got, want) in corners.iter().zip(expected_corners[t]) {
            assert!(
                close(*got, Vec3::from_array(want), 1e-5),
                "triangle {t}: {corners:?}"
            );
        }
        // Fronts stay fronts: the winding's normal equals the transformed vertex normals.
        assert!(close(face_normal(mesh, t), expected_normals[t], 1e-5));
        for &v in &mesh.triangles[t] {
            assert!(close(mesh.normals[v as usize], expected_normals[t], 1e-5));
        }
    }
    assert_eq!(mesh.material_names, ["clay"]);
    assert_eq!(loaded.base_colors, [Rgb::new(0.5, 0.25, 0.125)]);
    assert_eq!(mesh.material_slots, [0, 0, 0]);
}

#[test]
fn data_uri_gltf_with_u16_indices_and_no_scene_loads() {
    let loaded = load(&fixtures_dir().join("data_uri.gltf"));
    let mesh = &loaded.mesh;
    assert_eq!(mesh.positions.len(), 4);
    assert_eq!(mesh.triangles, [[0, 1, 2], [0, 2, 3]]);
    assert!(mesh.normals.iter().all(|&n| n == Vec3::Y));
    assert!((0..2).all(|t| close(face_normal(mesh, t), Vec3::Y, 1e-6)));
    assert_eq!(mesh.material_names, ["default"]);
    assert_eq!(loaded.base_colors, [DEFAULT_BASE_COLOR]);
    assert!(
        loaded.details.starts_with("glTF 2.0 JSON"),
        "{}",
        loaded.details
    );
}

#[test]
fn the_same_bytes_load_as_glb_with_a_binary_chunk() {
    // transforms.gltf with its .bin moved into the GLB binary chunk gives the same mesh.
    let dir = fixtures_dir();
    let mut json: Value =
        serde_json::from_slice(&std::fs::read(dir.join("transforms.gltf")).unwrap()).unwrap();
    json["buffers"][0].as_object_mut().unwrap().remove("uri");
    let glb = make_glb(&json, &std::fs::read(dir.join("transforms.bin")).unwrap());
    let from_glb = decode_gltf(&glb, &MeshLimits::default()).unwrap();
    let from_gltf = load(&dir.join("transforms.gltf"));
    assert_eq!(from_glb.mesh, from_gltf.mesh);
    assert_eq!(from_glb.base_colors, from_gltf.base_colors);
}

#[test]
fn strips_and_fans_unroll_counter_clockwise_and_points_are_skipped() {
    // The same unit quad in the XZ plane facing +Y, as a strip and as a fan (glTF vertex order
    // rules), plus a point primitive that must be skipped.
    let strip = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, -1.0],
    ];
    let fan = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 0.0, -1.0],
        [0.0, 0.0, -1.0],
    ];
    for (positions, mode) in [(strip, 5), (fan, 6)] {
        let mut doc = gltf_doc(&positions, None);
        doc["meshes"][0]["primitives"][0]["mode"] = json!(mode);
        let point = json!({"attributes": {"POSITION": 0}, "mode": 0});
        doc["meshes"][0]["primitives"]
            .as_array_mut()
            .unwrap()
            .push(point);
        let loaded = decode_gltf(&serde_json::to_vec(&doc).unwrap(), &MeshLimits::default())
            .unwrap_or_else(|e| panic!("mode {mode}: {e}"));
        let mesh = &loaded.mesh;
        assert_eq!(mesh.triangle_count(), 2, "mode {mode}");
        assert!(
            (0..2).all(|t| close(face_normal(mesh, t), Vec3::Y, 1e-6)),
            "mode {mode}"
        );
        let area: f32 = (0..2).map(|t| triangle_area(mesh.corners(t))).sum();
        // Two right triangles of a unit square: area 1 in f32, to a few ulps (1e-7); 1e-6.
        assert!((area - 1.0).abs() < 1e-6, "mode {mode}: area {area}");
        assert!(
            loaded
                .details
                .contains("1 point or line primitive instances skipped")
        );
    }
}

#[test]
fn normals_are_dropped_when_one_primitive_has_none() {
    let mut doc: Value =
        serde_json::from_slice(&std::fs::read(fixtures_dir().join("data_uri.gltf")).unwrap())
            .unwrap();
    let without = json!({"attributes": {"POSITION": 0}, "indices": 2});
    doc["meshes"][0]["primitives"]
        .as_array_mut()
        .unwrap()
        .push(without);
    let loaded = decode_gltf(&serde_json::to_vec(&doc).unwrap(), &MeshLimits::default()).unwrap();
    assert_eq!(loaded.mesh.triangle_count(), 4);
    assert!(loaded.mesh.normals.is_empty());
    assert!(
        loaded.details.contains("normals dropped: 1 of 2"),
        "{}",
        loaded.details
    );
}

// ---------------------------------------------------------------------------------------------
// OBJ fixtures
// ---------------------------------------------------------------------------------------------

#[test]
fn obj_cube_has_two_material_groups_with_their_kd_and_closes_outward() {
    let loaded = load(&fixtures_dir().join("cube.obj"));
    let mesh = &loaded.mesh;
    assert_eq!(mesh.material_names, ["red", "blue"]);
    assert_eq!(
        loaded.base_colors,
        [Rgb::new(0.8, 0.1, 0.1), Rgb::new(0.1, 0.2, 0.7)]
    );
    assert_eq!(mesh.triangle_count(), 12);
    // One vertex per distinct (position, normal) pair: 6 faces x 4 corners.
    assert_eq!(mesh.positions.len(), 24);
    assert_eq!(mesh.material_slots.iter().filter(|&&s| s == 0).count(), 8);
    assert_eq!(mesh.material_slots.iter().filter(|&&s| s == 1).count(), 4);
    // The blue group is exactly the +Y and -Y faces.
    for t in 0..12 {
        let n = face_normal(mesh, t);
        assert_eq!(mesh.material_slots[t] == 1, n.y.abs() > 0.5, "triangle {t}");
        for &v in &mesh.triangles[t] {
            assert!(close(mesh.normals[v as usize], n, 1e-6), "triangle {t}");
        }
    }
    // Closed forms for a cube of side 2: area 6 * 4 = 24; the divergence theorem gives the
    // volume (1/6) sum a . (b x c) = 8, positive only if every face winds outward.
    let area: f32 = (0..12).map(|t| triangle_area(mesh.corners(t))).sum();
    let volume: f32 = (0..12)
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            a.dot(b.cross(c)) / 6.0
        })
        .sum();
    // A 2 x 2 x 2 cube of 12 triangles: area 24 and volume 8, sums of f32 products exact to a few
    // ulps of 24 (2e-6); 1e-5.
    assert!((area - 24.0).abs() < 1e-5, "area {area}");
    assert!((volume - 8.0).abs() < 1e-5, "volume {volume}");
    assert!(
        loaded
            .details
            .starts_with("Wavefront OBJ, 24 vertices, 12 triangles, vertex normals")
    );
}

#[test]
fn obj_with_a_missing_mtl_keeps_its_groups_with_default_colours() {
    let loaded = load(&fixtures_dir().join("missing_mtl.obj"));
    assert_eq!(loaded.mesh.material_names, ["first", "second"]);
    assert_eq!(loaded.base_colors, [DEFAULT_BASE_COLOR; 2]);
    assert_eq!(loaded.mesh.material_slots, [0, 1]);
    assert!(loaded.mesh.normals.is_empty());
    assert!(
        loaded.details.contains("does_not_exist.mtl not found"),
        "{}",
        loaded.details
    );
}

#[test]
fn decode_obj_takes_the_material_library_as_bytes() {
    let dir = fixtures_dir();
    let obj = std::fs::read(dir.join("cube.obj")).unwrap();
    let mtl = std::fs::read(dir.join("cube.mtl")).unwrap();
    let with = decode_obj(&obj, Some(&mtl), &MeshLimits::default()).unwrap();
    assert_eq!(with, load(&dir.join("cube.obj")));
    let without = decode_obj(&obj, None, &MeshLimits::default()).unwrap();
    assert_eq!(without.base_colors, [DEFAULT_BASE_COLOR; 2]);
}

// ---------------------------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------------------------

#[test]
fn truncated_glb_fails_cleanly_at_every_cut() {
    let bytes = std::fs::read(models_dir().join("bunny.glb")).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json_end = 20 + json_len;
    for cut in [
        0,
        1,
        4,
        11,
        12,
        19,
        20,
        100,
        json_end - 1,
        json_end,
        json_end + 7,
        json_end + 8,
        bytes.len() / 2,
        bytes.len() - 1,
    ] {
        let name = format!("bunny_cut_{cut}.glb");
        expect_bad(&name, &bytes[..cut], "");
    }
    // A GLB whose header length is honest but whose binary chunk is short.
    let (json, bin) = split_glb(&bytes);
    expect_bad(
        "short_bin.glb",
        &make_glb(&json, &bin[..bin.len() / 2]),
        "byteLength",
    );
}

#[test]
fn garbage_bytes_fail_cleanly() {
    // A fixed pseudo-random sequence (64-bit LCG, Knuth's MMIX constants).
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let garbage: Vec<u8> = (0..4096)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 56) as u8
        })
        .collect();
    expect_bad("garbage.glb", &garbage, "neither");
    let mut glb_like = b"glTF\x02\0\0\0".to_vec();
    glb_like.extend_from_slice(&garbage);
    expect_bad("garbage_with_magic.glb", &glb_like, "GLB");
    expect_bad("garbage.gltf", b"{\"asset\": [1, 2", "glTF JSON");
    expect_bad("garbage.obj", &garbage, "");
}

#[test]
fn draco_and_other_required_extensions_are_refused() {
    let bytes = std::fs::read(models_dir().join("bunny.glb")).unwrap();
    let (mut json, bin) = split_glb(&bytes);
    json["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    json["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    let e = expect_bad(
        "draco.glb",
        &make_glb(&json, &bin),
        "Draco compression unsupported",
    );
    assert!(matches!(e, IoError::Unsupported { .. }));
    assert!(e.to_string().contains("uncompressed copy"), "{e}");

    // Draco used but not required, with the compressed primitive's accessors lacking data.
    json["extensionsRequired"] = json!([]);
    json["accessors"][0]
        .as_object_mut()
        .unwrap()
        .remove("bufferView");
    expect_bad(
        "draco_optional.glb",
        &make_glb(&json, &bin),
        "Draco compression unsupported",
    );

    let (mut json, bin) = split_glb(&bytes);
    json["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    expect_bad(
        "quantized.glb",
        &make_glb(&json, &bin),
        "KHR_mesh_quantization",
    );

    // A required material extension does not affect geometry and is ignored.
    let (mut json, bin) = split_glb(&bytes);
    json["extensionsRequired"] = json!(["KHR_materials_unlit"]);
    let loaded = decode_gltf(&make_glb(&json, &bin), &MeshLimits::default()).unwrap();
    assert_eq!(loaded.mesh.triangle_count(), 5648);
}

fn gltf_bytes(doc: &Value) -> Vec<u8> {
    serde_json::to_vec(doc).expect("JSON serialises")
}

#[test]
fn bad_gltf_content_fails_with_a_message_naming_file_and_fault() {
    let doc = gltf_doc(&TRIANGLE, Some(&[0, 1, 9]));
    expect_bad(
        "index.gltf",
        &gltf_bytes(&doc),
        "index 9 out of range (3 vertices)",
    );

    let nan = [[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let doc = gltf_doc(&nan, Some(&[0, 1, 2]));
    expect_bad(
        "nan.gltf",
        &gltf_bytes(&doc),
        "vertex 1 has a non-finite position",
    );

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["accessors"][0]["count"] = json!(6);
    expect_bad("bounds.gltf", &gltf_bytes(&doc), "accessor 0 out of bounds");

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["bufferViews"][0]["byteOffset"] = json!(8);
    expect_bad("view.gltf", &gltf_bytes(&doc), "bufferView 0 out of bounds");

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["accessors"][0]["count"] = json!(999_999);
    expect_bad(
        "long_count.gltf",
        &gltf_bytes(&doc),
        "accessor 0 out of bounds",
    );

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["accessors"][0]["count"] = json!(u64::MAX);
    expect_bad("huge_count.gltf", &gltf_bytes(&doc), "over the limit");

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["meshes"][0]["primitives"][0]["attributes"] = json!({"POSITION": 7});
    expect_bad(
        "no_accessor.gltf",
        &gltf_bytes(&doc),
        "accessor 7 does not exist",
    );

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["meshes"][0]["primitives"][0]["attributes"] = json!({"NORMAL": 0});
    expect_bad("no_position.gltf", &gltf_bytes(&doc), "has no POSITION");

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["accessors"][0]["type"] = json!("VEC2");
    expect_bad("vec2.gltf", &gltf_bytes(&doc), "expected Vec3 of F32");

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["meshes"][0]["primitives"][0]["material"] = json!(5);
    expect_bad(
        "material.gltf",
        &gltf_bytes(&doc),
        "material 5 does not exist",
    );

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["nodes"] = json!([{"mesh": 0, "children": [1]}, {"children": [0]}]);
    expect_bad("cycle.gltf", &gltf_bytes(&doc), "reached twice");

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,AAAA!AAA");
    expect_bad("base64.gltf", &gltf_bytes(&doc), "not base64");

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["buffers"][0]["uri"] = json!("missing%20file.bin");
    expect_bad("external.gltf", &gltf_bytes(&doc), "missing file.bin");

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["buffers"][0]["uri"] = json!("https://example.com/a.bin");
    expect_bad("remote.gltf", &gltf_bytes(&doc), "only relative file paths");

    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["asset"]["version"] = json!("1.0");
    expect_bad("version1.gltf", &gltf_bytes(&doc), "glTF version \"1.0\"");

    let degenerate = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    let doc = gltf_doc(&degenerate, None);
    expect_bad(
        "flat.gltf",
        &gltf_bytes(&doc),
        "no triangle of non-zero area",
    );
}

#[test]
fn empty_meshes_fail_with_no_triangles() {
    expect_bad(
        "empty.gltf",
        br#"{"asset": {"version": "2.0"}}"#,
        "no triangles",
    );
    let mut doc = gltf_doc(&TRIANGLE, None);
    doc["meshes"][0]["primitives"][0]["mode"] = json!(1);
    expect_bad("lines.gltf", &gltf_bytes(&doc), "no triangles");
    expect_bad(
        "vertices_only.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\n",
        "no triangles",
    );
    expect_bad("empty.obj", b"", "no triangles");
}

#[test]
fn bad_obj_lines_fail_with_file_and_line() {
    let v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\n";
    let cases = [
        (
            "index.obj",
            format!("{v}f 1 2 9\n"),
            "line 5: vertex index 9 out of range",
        ),
        (
            "zero.obj",
            format!("{v}f 0 1 2\n"),
            "line 5: vertex index 0 out of range",
        ),
        (
            // Overflows tobj 4.0.5's index arithmetic.
            "huge_negative.obj",
            format!("{v}f 1//1 2//-9223372036854775807 3//1\n"),
            "line 5: normal index -9223372036854775807 out of range",
        ),
        (
            "too_big.obj",
            format!("{v}f 99999999999999999999 1 2\n"),
            "bad vertex index",
        ),
        (
            "two_corners.obj",
            format!("{v}f 1 2\n"),
            "at least 3 corners",
        ),
        (
            "corner.obj",
            format!("{v}f 1/1/1/1 2 3\n"),
            "bad face corner",
        ),
        (
            "number.obj",
            "v 1 x 0\n".to_owned(),
            "line 1: v: \"x\" is not a number",
        ),
        (
            "short.obj",
            "v 1 2\n".to_owned(),
            "line 1: v needs 3 numbers",
        ),
        (
            "nan.obj",
            format!("v nan 0 0\n{v}f 1 2 3\n"),
            "vertex 0 has a non-finite position",
        ),
        (
            "usemtl.obj",
            format!("{v}usemtl\nf 1 2 3\n"),
            "line 5: usemtl without a name",
        ),
    ];
    for (name, text, expected) in cases {
        expect_bad(name, text.as_bytes(), expected);
    }
}

#[test]
fn a_bad_mtl_names_the_mtl_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("m.obj"),
        "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("bad.mtl"), "newmtl a\nKd 1 nan 0\n").unwrap();
    let e = read_mesh(&dir.path().join("m.obj"), &MeshLimits::default()).unwrap_err();
    assert!(e.is_bad_input());
    let message = e.to_string();
    assert!(
        message.contains("bad.mtl") && message.contains("line 2"),
        "{message}"
    );
}

#[test]
fn unknown_extensions_and_missing_files_are_bad_input() {
    let e = expect_bad("model.ply", b"ply\n", "expected .gltf, .glb or .obj");
    assert!(matches!(e, IoError::Unsupported { .. }));
    expect_bad("no_extension", b"", "expected .gltf, .glb or .obj");
    let missing = read_mesh(Path::new("no/such/model.glb"), &MeshLimits::default()).unwrap_err();
    assert!(missing.is_bad_input() && missing.to_string().contains("model.glb"));
}

#[test]
fn limits_are_enforced_before_reading() {
    let bunny = models_dir().join("bunny.glb");
    let few = MeshLimits {
        max_triangles: 5000,
        ..MeshLimits::default()
    };
    let e = read_mesh(&bunny, &few).unwrap_err();
    assert!(matches!(e, IoError::Limits { .. }), "{e}");
    assert!(
        e.to_string()
            .contains("5648 triangles, over the limit of 5000"),
        "{e}"
    );
    let small = MeshLimits {
        max_file_bytes: 1000,
        ..MeshLimits::default()
    };
    let e = read_mesh(&bunny, &small).unwrap_err();
    assert!(
        matches!(e, IoError::Limits { .. }) && e.to_string().contains("bunny.glb"),
        "{e}"
    );
    let cube = fixtures_dir().join("cube.obj");
    let e = read_mesh(
        &cube,
        &MeshLimits {
            max_triangles: 11,
            ..MeshLimits::default()
        },
    )
    .unwrap_err();
    assert!(matches!(e, IoError::Limits { .. }), "{e}");
    // An external buffer counts against the file size limit too (transforms.bin is 76 bytes).
    let gltf = fixtures_dir().join("transforms.gltf");
    let gltf_len = std::fs::metadata(&gltf).unwrap().len();
    let e = read_mesh(
        &gltf,
        &MeshLimits {
            max_file_bytes: gltf_len,
            ..MeshLimits::default()
        },
    )
    .unwrap_err();
    assert!(matches!(e, IoError::Limits { .. }) && e.to_string().contains("transforms.bin"));
}

#[test]
fn byte_level_decoding_refuses_external_buffers() {
    let bytes = std::fs::read(fixtures_dir().join("transforms.gltf")).unwrap();
    let e = decode_gltf(&bytes, &MeshLimits::default()).unwrap_err();
    assert!(
        e.to_string().contains("external file \"transforms.bin\""),
        "{e}"
    );
}

#[test]
fn every_single_byte_corruption_of_a_small_glb_is_handled() {
    // Each byte of a 1.8 kB GLB set to 0, 255, and with its low and high bits flipped, then
    // every truncation: the decoder must return (Ok or Err), never panic.
    let dir = fixtures_dir();
    let mut json: Value =
        serde_json::from_slice(&std::fs::read(dir.join("transforms.gltf")).unwrap()).unwrap();
    json["buffers"][0].as_object_mut().unwrap().remove("uri");
    let glb = make_glb(&json, &std::fs::read(dir.join("transforms.bin")).unwrap());
    let limits = MeshLimits {
        max_triangles: 1000,
        max_file_bytes: 1 << 20,
    };
    let mut loaded = 0;
    for i in 0..glb.len() {
        for value in [0, 255, glb[i] ^ 1, glb[i] ^ 0x80] {
            let mut bytes = glb.clone();
            bytes[i] = value;
            loaded += usize::from(decode_gltf(&bytes, &limits).is_ok());
        }
    }
    for cut in 0..glb.len() {
        assert!(decode_gltf(&glb[..cut], &limits).is_err(), "cut {cut}");
    }
    // Corrupting padding, names or float data leaves a loadable file.
    assert!(loaded > 0);
}

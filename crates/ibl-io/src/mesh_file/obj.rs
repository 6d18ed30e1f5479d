//! Wavefront OBJ meshes (Wavefront "Object Files (.obj)" appendix B1 of the Advanced Visualizer manual): read by
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
//! Normals, validation and the details line: see [`super::loaded`].

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use ibl_core::Rgb;
use ibl_core::glam::Vec3;
use ibl_scene::TriangleMesh;

use super::loaded::{
    DEFAULT_BASE_COLOR, DEFAULT_MATERIAL_NAME, LoadedMesh, MeshLimits, finish, normalize_or_keep,
};
use crate::error::{DecodeError, IoError};

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
pub(super) fn read_obj(
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
            // A missing library is common (an OBJ copied without its .mtl): a note. One that
            // exists but is not a regular file, or is the OBJ itself, is an error.
            if std::fs::symlink_metadata(&file).is_err() {
                parsed.notes.push(format!(
                    "material library {} not found, default base colours",
                    file.display()
                ));
                continue;
            }
            if same_file(&file, path) {
                return Err(IoError::Invalid {
                    path: path.to_path_buf(),
                    reason: format!(
                        "mtllib {} names the OBJ file itself, not a material library",
                        file.display()
                    ),
                });
            }
            let text = crate::read_bounded(&file, limits.max_file_bytes)?;
            let found = parse_mtl(&text).map_err(|e| e.with_path(&file))?;
            colors.extend(found);
        }
    }
    let base_colors = base_colors_of(&parsed.mesh.material_names, &colors);
    finish(parsed.mesh, base_colors, "Wavefront OBJ", parsed.notes).map_err(|e| e.with_path(path))
}

/// Whether two paths name the same file (canonical paths equal); false when either cannot be
/// resolved.
fn same_file(a: &Path, b: &Path) -> bool {
    matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
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

//! Scene files (`docs/SCENES.md`): reads the TOML description, then everything it names (the
//! probe, the photograph, the meshes), relative to the scene file's folder, and assembles an
//! [`ibl_scene::Scene`].
//!
//! Every error names a file: the scene file and the field at fault (`scene.toml: object[0].scale:
//! 0 is not a non-zero finite number`), or the asset and what is wrong with it, prefixed by the
//! scene field that named it (`scene.toml: object[1].file: bunny.glb: ...`).

use std::path::{Path, PathBuf};

use ibl_core::{Image, Rgb};
use ibl_scene::description::{
    BackgroundKind, GeometryDescription, MAX_SCENE_TRIANGLES, ShapeKind, shape_triangles,
};
use ibl_scene::{MeshAsset, Scene, SceneDescription};

use crate::IoError;
use crate::luminaire_file::read_luminaire;
use crate::mesh_file::{MeshLimits, read_mesh};

/// Largest scene file accepted, bytes.
pub const MAX_SCENE_BYTES: u64 = 4 << 20;

/// A scene read from a file, with the resolved paths of what it loaded.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The description as written.
    pub description: SceneDescription,
    /// The assembled scene.
    pub scene: Scene,
    /// The probe file, resolved.
    pub probe_path: PathBuf,
    /// The light file named by `[lighting] lights_file`, resolved.
    pub lights_path: Option<PathBuf>,
    /// Every input file the scene read (for "never write over an input").
    pub inputs: Vec<PathBuf>,
}

fn invalid(path: &Path, reason: impl Into<String>) -> IoError {
    IoError::Invalid {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// Parses a scene description from the text of `path` (no asset is read).
pub fn parse_scene(path: &Path, text: &str) -> Result<SceneDescription, IoError> {
    SceneDescription::from_toml(text).map_err(|e| invalid(path, e.to_string()))
}

/// The meshes of `entries` (the `table` entries of the file `path`: a scene's `local` or
/// `object`, an edits file's `object`), files relative to `path`'s folder: one entry per
/// description, `None` for shapes; with the files read. `triangles_left` is what the scene's
/// triangle limit ([`ibl_scene::description::MAX_SCENE_TRIANGLES`]) leaves: each file is read
/// with it as its limit (so no file's geometry is allocated past it) and its triangles are taken
/// from it. Errors name `path`, the field and the mesh file.
pub fn read_meshes(
    path: &Path,
    table: &str,
    entries: &[GeometryDescription],
    triangles_left: &mut usize,
) -> Result<(Vec<Option<MeshAsset>>, Vec<PathBuf>), IoError> {
    let folder = path.parent().unwrap_or(Path::new("."));
    let mut files = Vec::new();
    let meshes = entries
        .iter()
        .enumerate()
        .map(|(i, entry)| match (entry.shape, &entry.file) {
            (ShapeKind::Mesh, Some(file)) => {
                let p = folder.join(file);
                let field = format!("{table}[{i}].file");
                let defaults = MeshLimits::default();
                let limits = MeshLimits {
                    max_triangles: defaults.max_triangles.min(*triangles_left),
                    ..defaults
                };
                let loaded = read_mesh(&p, &limits).map_err(|e| {
                    let e = match e {
                        IoError::Limits { path, what }
                            if limits.max_triangles < defaults.max_triangles =>
                        {
                            IoError::Limits {
                                path,
                                what: format!(
                                    "{what} (what the scene's limit of {MAX_SCENE_TRIANGLES} \
                                     triangles leaves after the entries before it)"
                                ),
                            }
                        }
                        other => other,
                    };
                    asset_error(path, &field, e)
                })?;
                *triangles_left = triangles_left.saturating_sub(loaded.mesh.triangle_count());
                files.push(p);
                Ok(Some(MeshAsset {
                    mesh: loaded.mesh,
                    base_albedo: loaded.base_colors,
                }))
            }
            _ => Ok(None),
        })
        .collect::<Result<Vec<_>, IoError>>()?;
    Ok((meshes, files))
}

/// An asset's error, prefixed by the file `path` and the field that named it.
fn asset_error(path: &Path, field: &str, e: IoError) -> IoError {
    let message = format!("{field}: {e}");
    if e.is_bad_input() {
        invalid(path, message)
    } else {
        IoError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::other(message),
        }
    }
}

/// Reads a scene file and everything it names.
pub fn read_scene(path: &Path) -> Result<LoadedScene, IoError> {
    let text = crate::read_text(path, MAX_SCENE_BYTES)?;
    let description = parse_scene(path, &text)?;
    let folder = path.parent().unwrap_or(Path::new("."));
    let resolve = |p: &Path| folder.join(p);
    let mut inputs = vec![path.to_path_buf()];

    let probe_path = resolve(&description.probe.file);
    let probe = crate::read_image(&probe_path)
        .map_err(|e| asset_error(path, "probe.file", e))?
        .image;
    if probe.width() != 2 * probe.height() {
        return Err(invalid(
            path,
            format!(
                "probe.file: {}: {} x {} is not a 2:1 lat-long map (convert it with `ibl convert --to latlong`)",
                probe_path.display(),
                probe.width(),
                probe.height()
            ),
        ));
    }
    inputs.push(probe_path.clone());

    let photo: Option<Image<Rgb>> =
        match (description.background.kind, &description.background.file) {
            (BackgroundKind::Photo, Some(file)) => {
                let p = resolve(file);
                let image = crate::read_image(&p)
                    .map_err(|e| asset_error(path, "background.file", e))?
                    .image;
                inputs.push(p);
                Some(image)
            }
            _ => None,
        };

    // Validation has checked that the shapes alone are within the limit.
    let mut triangles_left = MAX_SCENE_TRIANGLES
        .saturating_sub(shape_triangles(&description.local) + shape_triangles(&description.object));
    let (local, local_paths) = read_meshes(path, "local", &description.local, &mut triangles_left)?;
    let (objects, object_paths) =
        read_meshes(path, "object", &description.object, &mut triangles_left)?;
    inputs.extend(local_paths);
    inputs.extend(object_paths);
    let lights_path = description.lighting.lights_file.as_deref().map(resolve);
    if let Some(p) = &lights_path {
        inputs.push(p.clone());
    }
    let mut scene = Scene::assemble(&description, probe, photo, local, objects)
        .map_err(|e| invalid(path, e.to_string()))?;
    // The luminaires (checked by `assemble`'s validation): each file read and its light placed.
    for (i, l) in description.luminaire.iter().enumerate() {
        let field = format!("luminaire[{i}]");
        let scale = l.scale(&field).map_err(|e| invalid(path, e.to_string()))?;
        let p = resolve(l.file.as_path());
        let placed = read_luminaire(
            &p,
            l.position.into(),
            l.rotation_deg,
            Rgb::from_array(l.colour),
            scale,
        )
        .map_err(|e| asset_error(path, &format!("{field}.file"), e))?;
        inputs.push(p);
        scene.luminaires.push(placed.light);
    }
    Ok(LoadedScene {
        description,
        scene,
        probe_path,
        lights_path,
        inputs,
    })
}

//! Saving the edited scene as a scene file `ibl render` reads back to the same scene: the
//! objects' placements and materials, the lighting settings and (when the user moved it) the
//! camera, written through `ibl_io::scene_write` so the file keeps its comments.
//!
//! Paths in a scene file are relative to its folder; a scene saved into another folder gets its
//! relative paths rewritten to lead to the same files from there.

use std::path::{Path, PathBuf};

use glam::Vec3;
use ibl_scene::SceneDescription;
use ibl_scene::description::CameraDescription;

use crate::ViewerError;
use crate::scene_model::SceneModel;
use crate::view_camera::OrbitControl;

/// The `[camera]` of an orbit: eye, the point it looks at, +Y up, its vertical field of view. A
/// camera over a panorama keeps the file's `image_size_px` (or takes the view's `size`).
pub fn camera_description(
    orbit: &OrbitControl,
    original: Option<&CameraDescription>,
    size: (u32, u32),
) -> CameraDescription {
    let eye = orbit.eye();
    let look_at = eye + orbit.forward() * orbit.distance.max(1.0);
    let round = |v: Vec3| v.to_array();
    CameraDescription {
        position: round(eye),
        look_at: round(look_at),
        up: [0.0, 1.0, 0.0],
        vertical_fov_deg: Some(orbit.vertical_fov.to_degrees()),
        focal_length_px: None,
        principal_point_px: None,
        image_size_px: original
            .and_then(|c| c.image_size_px)
            .or(Some([size.0, size.1])),
    }
}

/// `path` (relative to `from`) made relative to `to`; absolute paths stay as they are, and a
/// path that has no relative form is made absolute.
pub fn rebase(path: &Path, from: &Path, to: &Path) -> PathBuf {
    if path.is_absolute() {
        return path.to_path_buf();
    }
    let absolute = |p: &Path| {
        std::fs::canonicalize(p).unwrap_or_else(|_| {
            std::env::current_dir()
                .map(|d| d.join(p))
                .unwrap_or_else(|_| p.to_path_buf())
        })
    };
    let target = absolute(&from.join(path));
    let base = absolute(to);
    // Only the file system's root in common: an absolute path says more than "../../..".
    let shared = target
        .components()
        .zip(base.components())
        .take_while(|(a, b)| a == b)
        .count();
    if shared <= 1 {
        return target;
    }
    pathdiff::diff_paths(&target, &base).unwrap_or(target)
}

/// The description with every file path rebased from folder `from` to folder `to`.
pub fn rebased(description: &SceneDescription, from: &Path, to: &Path) -> SceneDescription {
    let mut d = description.clone();
    let fix = |p: &mut PathBuf| *p = rebase(p, from, to);
    fix(&mut d.probe.file);
    if let Some(p) = &mut d.background.file {
        fix(p);
    }
    if let Some(p) = &mut d.lighting.lights_file {
        fix(p);
    }
    for entry in d.local.iter_mut().chain(d.object.iter_mut()) {
        if let Some(p) = &mut entry.file {
            fix(p);
        }
    }
    for luminaire in &mut d.luminaire {
        fix(&mut luminaire.file);
    }
    if let Some(outdoor) = &mut d.outdoor {
        fix(&mut outdoor.mask);
        fix(&mut outdoor.frames.source);
    }
    d
}

fn folder(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The text of the scene file for `description`, to be written at `path`: the file as read
/// with its paths rebased to `path`'s folder (when that differs), then the edits.
pub fn scene_text(
    model: &SceneModel,
    description: &SceneDescription,
    path: &Path,
) -> Result<String, ViewerError> {
    let from = folder(&model.path);
    let to = folder(path);
    let same_folder = std::fs::canonicalize(&from).ok() == std::fs::canonicalize(&to).ok();
    let write_error = |file: &Path, e: ibl_io::scene_write::SceneWriteError| ViewerError::Input {
        path: file.to_path_buf(),
        problem: e.to_string(),
    };
    let (text, original, edited) = if same_folder {
        (
            model.text.clone(),
            model.original.clone(),
            description.clone(),
        )
    } else {
        let original = rebased(&model.original, &from, &to);
        let text = ibl_io::scene_write::edited_scene_text(&model.text, &model.original, &original)
            .map_err(|e| write_error(&model.path, e))?;
        (text, original, rebased(description, &from, &to))
    };
    edited.validate().map_err(|e| ViewerError::Input {
        path: path.to_path_buf(),
        problem: format!("the edited scene is not valid: {e}"),
    })?;
    ibl_io::scene_write::edited_scene_text(&text, &original, &edited)
        .map_err(|e| write_error(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rebasing_keeps_the_target() {
        let dir = tempfile::tempdir().expect("temp dir");
        let a = dir.path().join("a");
        let b = dir.path().join("b").join("c");
        std::fs::create_dir_all(&a).expect("mkdir");
        std::fs::create_dir_all(&b).expect("mkdir");
        std::fs::write(a.join("probe.exr"), b"x").expect("write");
        let r = rebase(Path::new("probe.exr"), &a, &b);
        assert_eq!(r, PathBuf::from("../../a/probe.exr"));
        assert_eq!(
            std::fs::canonicalize(b.join(&r)).expect("exists"),
            std::fs::canonicalize(a.join("probe.exr")).expect("exists")
        );
        assert_eq!(
            rebase(Path::new("/abs/p.exr"), &a, &b),
            PathBuf::from("/abs/p.exr")
        );
    }

    #[test]
    fn an_outdoor_scene_keeps_its_mask_and_frames_when_saved_elsewhere() {
        let text = std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/outdoor/courtyard/scene.toml"),
        )
        .expect("the bundled outdoor scene");
        let d = SceneDescription::from_toml(&text).expect("parses");
        let dir = tempfile::tempdir().expect("temp dir");
        let (from, to) = (dir.path().join("a"), dir.path().join("b").join("c"));
        std::fs::create_dir_all(&to).expect("mkdir");
        let r = rebased(&d, &from, &to);
        let outdoor = r.outdoor.expect("the [outdoor] table");
        assert_eq!(outdoor.mask, PathBuf::from("../../a/mask.png"));
        assert_eq!(outdoor.frames.source, PathBuf::from("../../a/frames"));
    }
}

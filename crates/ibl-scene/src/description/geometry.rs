//! `[[local]]` and `[[object]]`: one piece of geometry, real (the local scene, diffuse albedo per
//! material group) or virtual (a material), as a plane, box, sphere or mesh file with a transform
//! `world_from_model = T R S` (scale first, then rotation yaw/pitch/roll `Ry Rx Rz`, then
//! translation).

use std::collections::BTreeMap;
use std::path::PathBuf;

use glam::{Affine3A, Quat, Vec3};
use serde::{Deserialize, Serialize};

use super::field::{DescriptionError, finite3, invalid, nonzero, positive, reflectance};
use super::material::MaterialDescription;

/// One piece of geometry, real (`[[local]]`) or virtual (`[[object]]`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeometryDescription {
    /// A name for messages and statistics. Default `local[i]` / `object[i]`.
    pub name: Option<String>,
    /// `plane`, `box`, `sphere` or `mesh`.
    pub shape: ShapeKind,
    /// Mesh file (`.gltf`, `.glb`, `.obj`), relative to the scene file; `mesh` only.
    pub file: Option<PathBuf>,
    /// Centre of a `plane` or `sphere`, model frame. Default origin.
    pub center: Option<[f32; 3]>,
    /// Normal of a `plane` (its front side), model frame. Default +Y.
    pub normal: Option<[f32; 3]>,
    /// Side lengths of a `plane` (along its two tangents), length units.
    pub size: Option<[f32; 2]>,
    /// Radius of a `sphere`, length units.
    pub radius: Option<f32>,
    /// Minimum corner of a `box`, model frame.
    pub min: Option<[f32; 3]>,
    /// Maximum corner of a `box`, model frame.
    pub max: Option<[f32; 3]>,
    /// Scale (one number, or one per axis), applied first. Default 1.
    pub scale: Option<Scale>,
    /// Rotation, yaw/pitch/roll degrees about +Y, +X, +Z (`Ry Rx Rz`), applied second.
    pub rotate_deg: Option<[f32; 3]>,
    /// Translation, world frame, applied last.
    pub translate: Option<[f32; 3]>,
    /// Diffuse albedo of every group (real geometry), linear RGB in `[0, 1]`.
    pub albedo: Option<[f32; 3]>,
    /// Diffuse albedo per material group name (real meshes), overriding `albedo`.
    pub albedo_by_group: Option<BTreeMap<String, [f32; 3]>>,
    /// Material of a virtual object (overrides the file's base colours).
    pub material: Option<MaterialDescription>,
}

/// Shapes a geometry entry can have.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShapeKind {
    /// A rectangle.
    #[default]
    Plane,
    /// An axis-aligned box (before the transform).
    Box,
    /// A sphere (tessellated finely enough that its silhouette is smooth at render size).
    Sphere,
    /// A triangle mesh from a file.
    Mesh,
}

/// Icosphere subdivisions of a `sphere` shape (20480 triangles).
pub const SPHERE_SUBDIVISIONS: u32 = 5;

/// Most triangles in one scene, shapes and mesh files of both layers together (the same as one
/// mesh file may hold, `ibl_io::MeshLimits`). A scene costs about 240 bytes a triangle once
/// built (vertices, shading data, the BVH; 9.7 GB measured for 2000 spheres), so this bounds a
/// scene's geometry to about 5 GB.
pub const MAX_SCENE_TRIANGLES: usize = 20_000_000;

impl ShapeKind {
    /// Triangles of one built-in shape (`plane` 2, `box` 12, `sphere` 20480); `None` for a
    /// mesh, whose count is its file's.
    pub fn triangle_count(self) -> Option<usize> {
        match self {
            ShapeKind::Plane => Some(2),
            ShapeKind::Box => Some(12),
            ShapeKind::Sphere => Some(20 << (2 * SPHERE_SUBDIVISIONS)),
            ShapeKind::Mesh => None,
        }
    }
}

/// Triangles of the built-in shapes among `entries` (mesh files not counted).
pub fn shape_triangles(entries: &[GeometryDescription]) -> usize {
    entries
        .iter()
        .filter_map(|e| e.shape.triangle_count())
        .sum()
}

/// A uniform or per-axis scale.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Scale {
    /// The same factor on every axis.
    Uniform(f32),
    /// One factor per axis.
    PerAxis([f32; 3]),
}

/// Whether a geometry entry is real or virtual (they accept different material fields).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Layer {
    /// `[[local]]`: real geometry.
    Real,
    /// `[[object]]`: a virtual object.
    Virtual,
}

impl GeometryDescription {
    pub(crate) fn validate(&self, path: &str, layer: Layer) -> Result<(), DescriptionError> {
        let field = |name: &str| format!("{path}.{name}");
        let needs = |name: &str, present: bool| {
            if present {
                Ok(())
            } else {
                Err(invalid(
                    field(name),
                    format!("shape \"{}\" needs it", self.shape.name()),
                ))
            }
        };
        let refuses = |name: &str, present: bool| {
            if present {
                Err(invalid(
                    field(name),
                    format!("does not apply to shape \"{}\"", self.shape.name()),
                ))
            } else {
                Ok(())
            }
        };
        match self.shape {
            ShapeKind::Plane => {
                needs("size", self.size.is_some())?;
                refuses("file", self.file.is_some())?;
                refuses("radius", self.radius.is_some())?;
                refuses("min", self.min.is_some())?;
                refuses("max", self.max.is_some())?;
            }
            ShapeKind::Box => {
                needs("min", self.min.is_some())?;
                needs("max", self.max.is_some())?;
                refuses("file", self.file.is_some())?;
                refuses("radius", self.radius.is_some())?;
                refuses("size", self.size.is_some())?;
                refuses("normal", self.normal.is_some())?;
                refuses("center", self.center.is_some())?;
            }
            ShapeKind::Sphere => {
                needs("radius", self.radius.is_some())?;
                refuses("file", self.file.is_some())?;
                refuses("size", self.size.is_some())?;
                refuses("normal", self.normal.is_some())?;
                refuses("min", self.min.is_some())?;
                refuses("max", self.max.is_some())?;
            }
            ShapeKind::Mesh => {
                needs("file", self.file.is_some())?;
                refuses("center", self.center.is_some())?;
                refuses("normal", self.normal.is_some())?;
                refuses("size", self.size.is_some())?;
                refuses("radius", self.radius.is_some())?;
                refuses("min", self.min.is_some())?;
                refuses("max", self.max.is_some())?;
            }
        }
        if let Some(c) = self.center {
            finite3(&field("center"), c)?;
        }
        if let Some(n) = self.normal {
            finite3(&field("normal"), n)?;
            if Vec3::from(n).length() <= 0.0 {
                return Err(invalid(field("normal"), "is the zero vector"));
            }
        }
        if let Some(s) = self.size {
            positive(&field("size[0]"), s[0])?;
            positive(&field("size[1]"), s[1])?;
        }
        if let Some(r) = self.radius {
            positive(&field("radius"), r)?;
        }
        if let (Some(lo), Some(hi)) = (self.min, self.max) {
            finite3(&field("min"), lo)?;
            finite3(&field("max"), hi)?;
            if (0..3).any(|k| hi[k] <= lo[k]) {
                return Err(invalid(field("max"), "must exceed min on every axis"));
            }
        }
        match self.scale {
            Some(Scale::Uniform(s)) => nonzero(&field("scale"), s)?,
            Some(Scale::PerAxis(s)) => {
                for (k, v) in s.into_iter().enumerate() {
                    nonzero(&field(&format!("scale[{k}]")), v)?;
                }
            }
            None => {}
        }
        if let Some(r) = self.rotate_deg {
            finite3(&field("rotate_deg"), r)?;
        }
        if let Some(t) = self.translate {
            finite3(&field("translate"), t)?;
        }
        if let Some(a) = self.albedo {
            reflectance(&field("albedo"), a)?;
        }
        if let Some(groups) = &self.albedo_by_group {
            for (name, a) in groups {
                reflectance(&field(&format!("albedo_by_group.{name}")), *a)?;
            }
        }
        match layer {
            Layer::Real => {
                if self.material.is_some() {
                    return Err(invalid(
                        field("material"),
                        "real geometry is diffuse: give `albedo` (or `albedo_by_group`)",
                    ));
                }
            }
            Layer::Virtual => {
                if self.albedo_by_group.is_some() {
                    return Err(invalid(
                        field("albedo_by_group"),
                        "is for real geometry; give a virtual object a `material`",
                    ));
                }
                if let Some(m) = &self.material {
                    m.validate(&field("material"))?;
                }
            }
        }
        Ok(())
    }

    /// `world_from_model = T R S` (scale first, then rotation yaw/pitch/roll, then translation).
    pub fn world_from_model(&self) -> Affine3A {
        let scale = match self.scale {
            Some(Scale::Uniform(s)) => Vec3::splat(s),
            Some(Scale::PerAxis(s)) => Vec3::from(s),
            None => Vec3::ONE,
        };
        let [yaw, pitch, roll] = self.rotate_deg.unwrap_or_default();
        let rotation = Quat::from_rotation_y(yaw.to_radians())
            * Quat::from_rotation_x(pitch.to_radians())
            * Quat::from_rotation_z(roll.to_radians());
        Affine3A::from_scale_rotation_translation(
            scale,
            rotation,
            Vec3::from(self.translate.unwrap_or_default()),
        )
    }
}

impl ShapeKind {
    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Plane => "plane",
            ShapeKind::Box => "box",
            ShapeKind::Sphere => "sphere",
            ShapeKind::Mesh => "mesh",
        }
    }
}

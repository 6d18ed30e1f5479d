//! The scene file format (TOML, `version = 1`): what `ibl render` reads. Documented for users in
//! `docs/SCENES.md`; every field is listed there with its unit and default.
//!
//! A scene has a light probe (`[probe]`: lat-long image, `world_from_probe` rotation, radiance scale
//! and the world position of its centre), a background (`[background]`: the probe itself as a
//! panorama seen from its centre, or a photograph with a pinhole `[camera]`), **local real geometry**
//! (`[[local]]`: planes, boxes, spheres and meshes with a diffuse albedo per material group: the real
//! surfaces near the virtual objects, Debevec 1998's "local scene"), **virtual objects**
//! (`[[object]]`: meshes or shapes with a transform and a material), the renderer's settings
//! (`[render]`) and the lighting (`[lighting]`).
//!
//! Parsing refuses unknown fields (a typo is an error, not a silently ignored setting). After
//! parsing, [`SceneDescription::validate`] checks every value and names the offending field by its
//! path, e.g. `object[0].rotate_deg: not a finite number`. File paths stay relative to the scene
//! file; `ibl-io` resolves them.

use std::collections::BTreeMap;
use std::path::PathBuf;

use glam::{Affine3A, Quat, Vec3};
use serde::{Deserialize, Serialize};

/// The only format version this build reads.
pub const FORMAT_VERSION: u32 = 1;

/// A problem in a scene description, with the path of the field at fault.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field}: {problem}")]
pub struct DescriptionError {
    /// Path of the field, e.g. `object[1].scale` (or `toml` for a syntax error).
    pub field: String,
    /// What is wrong.
    pub problem: String,
}

fn invalid(field: impl Into<String>, problem: impl Into<String>) -> DescriptionError {
    DescriptionError {
        field: field.into(),
        problem: problem.into(),
    }
}

/// A whole scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDescription {
    /// Format version; must be [`FORMAT_VERSION`].
    pub version: u32,
    /// The light probe.
    pub probe: ProbeDescription,
    /// What the virtual objects are composited into.
    #[serde(default)]
    pub background: BackgroundDescription,
    /// A pinhole camera: the photograph's (photo background), or a perspective view of the
    /// panorama (panorama background; without it the render is the whole panorama).
    pub camera: Option<CameraDescription>,
    /// Real geometry standing in for the real scene near the objects.
    #[serde(default)]
    pub local: Vec<GeometryDescription>,
    /// Virtual objects.
    #[serde(default)]
    pub object: Vec<GeometryDescription>,
    /// Renderer settings.
    #[serde(default)]
    pub render: RenderDescription,
    /// Lighting approximation for the `lights` and `hybrid` modes.
    #[serde(default)]
    pub lighting: LightingDescription,
}

/// `[probe]`: the HDR light probe lighting the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeDescription {
    /// Lat-long image file, relative to the scene file.
    pub file: PathBuf,
    /// `world_from_probe` as yaw, pitch, roll in degrees (CONVENTIONS section 1). Default none.
    #[serde(default)]
    pub rotation_deg: [f32; 3],
    /// Factor applied to every probe radiance (exposure calibration). Default 1.
    #[serde(default = "one")]
    pub radiance_scale: f32,
    /// World position of the probe's centre: where the panorama is seen from. Default origin.
    #[serde(default)]
    pub position: [f32; 3],
}

fn one() -> f32 {
    1.0
}

/// `[background]`: what the render is composited into.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BackgroundDescription {
    /// `panorama` (the probe seen from its centre; the default) or `photo`.
    #[serde(default)]
    pub kind: BackgroundKind,
    /// The photograph (linear HDR or 8-bit sRGB), relative to the scene file; `photo` only.
    pub file: Option<PathBuf>,
}

/// The two kinds of background.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BackgroundKind {
    /// The probe itself, seen from its centre, as a lat-long panorama.
    #[default]
    Panorama,
    /// A photograph taken with the pinhole `[camera]`.
    Photo,
}

/// `[camera]`: a pinhole camera (glTF convention: looks along its -Z, +Y up, +X right).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDescription {
    /// Eye position, world frame.
    pub position: [f32; 3],
    /// A point the camera looks at, world frame.
    pub look_at: [f32; 3],
    /// Up hint, world frame. Default +Y.
    #[serde(default = "up")]
    pub up: [f32; 3],
    /// Vertical field of view, degrees (give this or `focal_length_px`).
    pub vertical_fov_deg: Option<f32>,
    /// Focal length in pixels of the photograph, `[fx, fy]`.
    pub focal_length_px: Option<[f32; 2]>,
    /// Principal point in pixels of the photograph, `[cx, cy]`. Default the image centre.
    pub principal_point_px: Option<[f32; 2]>,
    /// Image size `[width, height]` in pixels the intrinsics refer to: required for a view of
    /// the panorama; a photo's own size otherwise (and then it must not be given).
    pub image_size_px: Option<[u32; 2]>,
}

fn up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

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

/// A uniform or per-axis scale.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Scale {
    /// The same factor on every axis.
    Uniform(f32),
    /// One factor per axis.
    PerAxis([f32; 3]),
}

/// `material = { kind = ..., ... }` of a virtual object.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDescription {
    /// `diffuse`, `glossy` or `mirror`.
    pub kind: MaterialKind,
    /// Diffuse albedo, linear RGB in `[0, 1]` (diffuse, glossy). Default 0.5 grey.
    pub albedo: Option<[f32; 3]>,
    /// Specular reflectance (glossy) or mirror reflectance (mirror), linear RGB in `[0, 1]`.
    pub specular: Option<[f32; 3]>,
    /// Phong exponent of a glossy lobe, >= 1. Default 50.
    pub exponent: Option<f32>,
}

/// Material kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MaterialKind {
    /// Lambertian.
    Diffuse,
    /// Lambert plus a normalised Phong lobe.
    Glossy,
    /// Perfect mirror.
    Mirror,
}

/// `[render]`: renderer settings (the command line overrides them).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderDescription {
    /// `reference`, `lights` or `hybrid`. Default `reference`.
    #[serde(default)]
    pub mode: RenderMode,
    /// Output width in pixels. Default: the probe's width (panorama) or the photo's.
    pub width: Option<u32>,
    /// Samples per pixel. Default 64.
    #[serde(default = "default_spp")]
    pub spp: u32,
    /// Maximum path length in bounces (1 = direct light only). Default 4.
    #[serde(default = "default_bounces")]
    pub bounces: u32,
    /// Random seed; a render depends only on it, never on the thread count. Default 1.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// How the objects' effect on real surfaces is composited. Default `difference`.
    #[serde(default)]
    pub composite: CompositeRule,
    /// Which random numbers the samples draw. Default `sobol`.
    #[serde(default)]
    pub sampler: SamplerKind,
}

/// Which random numbers a render's samples draw (every mode).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SamplerKind {
    /// Owen-scrambled Sobol points (low discrepancy): each pair of numbers a sample draws is
    /// stratified across the pixel's samples.
    #[default]
    Sobol,
    /// Independent uniform numbers (PCG32).
    Independent,
}

impl SamplerKind {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Sobol => "sobol",
            SamplerKind::Independent => "independent",
        }
    }
}

/// How differential rendering adds the objects' effect on real surfaces to the background `B`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CompositeRule {
    /// `B + (with - without)` (Debevec 1998): exact when the local scene's albedo matches the
    /// photographed surface; a surface darker than modelled can clip to black in a shadow.
    #[default]
    Difference,
    /// `B * with / without`: the same as `difference` with the albedo estimated per pixel as
    /// `rho = pi B / E` (Grosch 2005, section 3.2), so shadows keep the photographed texture
    /// and never clip. Falls back to `difference` where `without` is 0.
    Ratio,
}

impl CompositeRule {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            CompositeRule::Difference => "difference",
            CompositeRule::Ratio => "ratio",
        }
    }
}

fn default_spp() -> u32 {
    64
}
fn default_bounces() -> u32 {
    4
}
fn default_seed() -> u64 {
    1
}

impl Default for RenderDescription {
    fn default() -> Self {
        RenderDescription {
            mode: RenderMode::default(),
            width: None,
            spp: default_spp(),
            bounces: default_bounces(),
            seed: default_seed(),
            composite: CompositeRule::default(),
            sampler: SamplerKind::default(),
        }
    }
}

/// How the scene is lit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RenderMode {
    /// Path tracing of the full probe, importance-sampled, MIS with the BSDF.
    #[default]
    Reference,
    /// Directional lights with shadows.
    Lights,
    /// Important lights with shadows plus an SH ambient with ambient occlusion.
    Hybrid,
}

impl RenderMode {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            RenderMode::Reference => "reference",
            RenderMode::Lights => "lights",
            RenderMode::Hybrid => "hybrid",
        }
    }
}

/// `[lighting]`: the approximation used by the `lights` and `hybrid` modes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightingDescription {
    /// Extraction method (`ibl lights --method` names). Default `median-cut`.
    #[serde(default = "default_method")]
    pub method: String,
    /// Number of lights. Default 16.
    #[serde(default = "default_lights")]
    pub lights: u32,
    /// A light file (`ibl lights` JSON) to use instead of extracting, relative to the scene file.
    pub lights_file: Option<PathBuf>,
    /// `hard` or `soft` (each light a cone of its own solid angle). Default `soft`.
    #[serde(default)]
    pub shadows: ShadowKind,
    /// Samples per pixel of the `lights` and `hybrid` modes (antialiasing; each sample evaluates
    /// every light once, its soft-shadow cone stratified across the samples). Default 4.
    #[serde(default = "default_lights_spp")]
    pub spp: u32,
    /// SH bands of the hybrid ambient. Default 3.
    #[serde(default = "default_bands")]
    pub ambient_bands: u32,
    /// Occlusion rays per shading point and sample (hybrid). Default 4.
    #[serde(default = "default_ao")]
    pub ao_samples: u32,
}

fn default_method() -> String {
    "median-cut".into()
}
fn default_lights() -> u32 {
    16
}
fn default_lights_spp() -> u32 {
    4
}
fn default_bands() -> u32 {
    3
}
fn default_ao() -> u32 {
    4
}

impl Default for LightingDescription {
    fn default() -> Self {
        LightingDescription {
            method: default_method(),
            lights: default_lights(),
            lights_file: None,
            shadows: ShadowKind::default(),
            spp: default_lights_spp(),
            ambient_bands: default_bands(),
            ao_samples: default_ao(),
        }
    }
}

/// Shadow kinds of the `lights` and `hybrid` modes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShadowKind {
    /// One shadow ray towards each light's direction.
    Hard,
    /// Shadow rays spread over a cone of the light's own solid angle.
    #[default]
    Soft,
}

impl ShadowKind {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ShadowKind::Hard => "hard",
            ShadowKind::Soft => "soft",
        }
    }
}

/// Largest accepted output width, pixels.
pub const MAX_WIDTH: u32 = 16384;
/// Largest accepted samples per pixel.
pub const MAX_SPP: u32 = 1 << 16;
/// Largest accepted bounce count.
pub const MAX_BOUNCES: u32 = 64;

impl SceneDescription {
    /// Parses TOML text; unknown fields and type errors are refused with their location.
    pub fn from_toml(text: &str) -> Result<SceneDescription, DescriptionError> {
        let description: SceneDescription = toml::from_str(text)
            .map_err(|e| invalid(toml_field(&e, text), toml_problem(&e, text)))?;
        description.validate()?;
        Ok(description)
    }

    /// Checks every value, naming the field at fault.
    pub fn validate(&self) -> Result<(), DescriptionError> {
        if self.version != FORMAT_VERSION {
            return Err(invalid(
                "version",
                format!(
                    "format version {} is not supported (this build reads {FORMAT_VERSION})",
                    self.version
                ),
            ));
        }
        finite3("probe.rotation_deg", self.probe.rotation_deg)?;
        finite3("probe.position", self.probe.position)?;
        positive("probe.radiance_scale", self.probe.radiance_scale)?;
        match self.background.kind {
            BackgroundKind::Panorama => {
                if self.background.file.is_some() {
                    return Err(invalid(
                        "background.file",
                        "a panorama background is the probe itself; give `kind = \"photo\"` to use a photograph",
                    ));
                }
                if let Some(camera) = &self.camera {
                    camera.validate()?;
                    match camera.image_size_px {
                        Some([w, h])
                            if (1..=MAX_WIDTH).contains(&w) && (1..=MAX_WIDTH).contains(&h) => {}
                        Some(size) => {
                            return Err(invalid(
                                "camera.image_size_px",
                                format!("{size:?} is not in 1..={MAX_WIDTH} on both axes"),
                            ));
                        }
                        None => {
                            return Err(invalid(
                                "camera.image_size_px",
                                "a view of the panorama needs its image size",
                            ));
                        }
                    }
                }
            }
            BackgroundKind::Photo => {
                if self.background.file.is_none() {
                    return Err(invalid(
                        "background.file",
                        "a photo background needs a file",
                    ));
                }
                let camera = self
                    .camera
                    .as_ref()
                    .ok_or_else(|| invalid("camera", "a photo background needs a [camera]"))?;
                camera.validate()?;
                if camera.image_size_px.is_some() {
                    return Err(invalid(
                        "camera.image_size_px",
                        "a photo camera takes the photograph's own size",
                    ));
                }
            }
        }
        for (i, g) in self.local.iter().enumerate() {
            g.validate(&format!("local[{i}]"), Layer::Real)?;
        }
        for (i, g) in self.object.iter().enumerate() {
            g.validate(&format!("object[{i}]"), Layer::Virtual)?;
        }
        let r = &self.render;
        if let Some(w) = r.width
            && !(2..=MAX_WIDTH).contains(&w)
        {
            return Err(invalid(
                "render.width",
                format!("{w} is not in 2..={MAX_WIDTH}"),
            ));
        }
        if !(1..=MAX_SPP).contains(&r.spp) {
            return Err(invalid(
                "render.spp",
                format!("{} is not in 1..={MAX_SPP}", r.spp),
            ));
        }
        if !(1..=MAX_BOUNCES).contains(&r.bounces) {
            return Err(invalid(
                "render.bounces",
                format!("{} is not in 1..={MAX_BOUNCES}", r.bounces),
            ));
        }
        let l = &self.lighting;
        if !(1..=4096).contains(&l.lights) {
            return Err(invalid(
                "lighting.lights",
                format!("{} is not in 1..=4096", l.lights),
            ));
        }
        if !(1..=MAX_SPP).contains(&l.spp) {
            return Err(invalid(
                "lighting.spp",
                format!("{} is not in 1..={MAX_SPP}", l.spp),
            ));
        }
        if !(1..=16).contains(&l.ambient_bands) {
            return Err(invalid(
                "lighting.ambient_bands",
                format!("{} is not in 1..=16", l.ambient_bands),
            ));
        }
        if !(1..=1024).contains(&l.ao_samples) {
            return Err(invalid(
                "lighting.ao_samples",
                format!("{} is not in 1..=1024", l.ao_samples),
            ));
        }
        Ok(())
    }
}

/// Whether a geometry entry is real or virtual (they accept different material fields).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Layer {
    Real,
    Virtual,
}

impl CameraDescription {
    fn validate(&self) -> Result<(), DescriptionError> {
        finite3("camera.position", self.position)?;
        finite3("camera.look_at", self.look_at)?;
        finite3("camera.up", self.up)?;
        let forward = Vec3::from(self.look_at) - Vec3::from(self.position);
        if forward.length() <= 0.0 {
            return Err(invalid("camera.look_at", "equals camera.position"));
        }
        if forward.cross(Vec3::from(self.up)).length() <= 1e-6 * forward.length() {
            return Err(invalid("camera.up", "is parallel to the viewing direction"));
        }
        match (self.vertical_fov_deg, self.focal_length_px) {
            (Some(_), Some(_)) => Err(invalid(
                "camera",
                "give either vertical_fov_deg or focal_length_px, not both",
            )),
            (None, None) => Err(invalid(
                "camera",
                "needs vertical_fov_deg or focal_length_px",
            )),
            (Some(fov), None) => {
                if fov.is_finite() && fov > 0.0 && fov < 179.0 {
                    Ok(())
                } else {
                    Err(invalid(
                        "camera.vertical_fov_deg",
                        format!("{fov} is not in (0, 179)"),
                    ))
                }
            }
            (None, Some(f)) => {
                positive("camera.focal_length_px[0]", f[0])?;
                positive("camera.focal_length_px[1]", f[1])?;
                if let Some(c) = self.principal_point_px {
                    finite3("camera.principal_point_px", [c[0], c[1], 0.0])?;
                }
                Ok(())
            }
        }
    }
}

impl GeometryDescription {
    fn validate(&self, path: &str, layer: Layer) -> Result<(), DescriptionError> {
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

impl MaterialDescription {
    fn validate(&self, path: &str) -> Result<(), DescriptionError> {
        if let Some(a) = self.albedo {
            reflectance(&format!("{path}.albedo"), a)?;
        }
        if let Some(s) = self.specular {
            reflectance(&format!("{path}.specular"), s)?;
        }
        match self.kind {
            MaterialKind::Diffuse => {
                if self.specular.is_some() || self.exponent.is_some() {
                    return Err(invalid(path, "a diffuse material takes only `albedo`"));
                }
            }
            MaterialKind::Glossy => {
                if let Some(e) = self.exponent
                    && !(e.is_finite() && (1.0..=1.0e5).contains(&e))
                {
                    return Err(invalid(
                        format!("{path}.exponent"),
                        format!("{e} is not in [1, 100000]"),
                    ));
                }
                let a = self.albedo.unwrap_or([DEFAULT_ALBEDO; 3]);
                let s = self.specular.unwrap_or([DEFAULT_SPECULAR; 3]);
                if (0..3).any(|k| a[k] + s[k] > 1.0 + 1e-6) {
                    return Err(invalid(
                        path,
                        "albedo + specular exceeds 1 in a channel (the surface would create light)",
                    ));
                }
            }
            MaterialKind::Mirror => {
                if self.albedo.is_some() || self.exponent.is_some() {
                    return Err(invalid(
                        path,
                        "a mirror takes only `specular` (its reflectance)",
                    ));
                }
            }
        }
        Ok(())
    }

    /// The material this description stands for (defaults filled in).
    pub fn material(&self) -> crate::Material {
        use ibl_core::Rgb;
        let rgb = |v: [f32; 3]| Rgb::new(v[0], v[1], v[2]);
        match self.kind {
            MaterialKind::Diffuse => crate::Material::Diffuse {
                albedo: rgb(self.albedo.unwrap_or([DEFAULT_ALBEDO; 3])),
            },
            MaterialKind::Glossy => crate::Material::Glossy {
                albedo: rgb(self.albedo.unwrap_or([DEFAULT_ALBEDO; 3])),
                specular: rgb(self.specular.unwrap_or([DEFAULT_SPECULAR; 3])),
                exponent: self.exponent.unwrap_or(DEFAULT_EXPONENT),
            },
            MaterialKind::Mirror => crate::Material::Mirror {
                reflectance: rgb(self.specular.unwrap_or([DEFAULT_MIRROR; 3])),
            },
        }
    }
}

/// Default diffuse albedo of a material description that gives none (glossy: the diffuse part).
pub const DEFAULT_ALBEDO: f32 = 0.5;
/// Default specular reflectance of a glossy material.
pub const DEFAULT_SPECULAR: f32 = 0.3;
/// Default Phong exponent of a glossy material.
pub const DEFAULT_EXPONENT: f32 = 50.0;
/// Default reflectance of a mirror.
pub const DEFAULT_MIRROR: f32 = 0.9;

fn finite3(field: &str, v: [f32; 3]) -> Result<(), DescriptionError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(invalid(field, format!("{v:?} is not finite")))
    }
}

fn positive(field: &str, v: f32) -> Result<(), DescriptionError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("{v} is not a positive finite number"),
        ))
    }
}

fn nonzero(field: &str, v: f32) -> Result<(), DescriptionError> {
    if v.is_finite() && v != 0.0 {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("{v} is not a non-zero finite number"),
        ))
    }
}

fn reflectance(field: &str, v: [f32; 3]) -> Result<(), DescriptionError> {
    if v.iter().all(|x| x.is_finite() && (0.0..=1.0).contains(x)) {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("{v:?} is not a reflectance in [0, 1]"),
        ))
    }
}

/// The dotted path of the field a TOML error points at (`object[1].material.kind`): the smallest
/// key or value of the parsed document whose byte span holds the error's span (for a "missing
/// field" error: the smallest table, with the missing key appended). A syntax error (the document
/// does not parse) is `toml`. Cost: a second parse and one walk over every key and value, linear
/// in the file size.
fn toml_field(e: &toml::de::Error, text: &str) -> String {
    let (Some(span), Ok(document)) = (e.span(), toml::de::DeTable::parse(text)) else {
        return "toml".into();
    };
    // serde's message for an absent key: "missing field `name`".
    let missing = e
        .message()
        .strip_prefix("missing field `")
        .and_then(|rest| rest.split('`').next());
    let mut search = SpanSearch {
        target: span,
        tables_only: missing.is_some(),
        best: None,
    };
    for (key, value) in document.get_ref() {
        search.visit(key.get_ref().to_string(), Some(key.span()), value);
    }
    let path = search.best.map(|(_, path)| path).unwrap_or_default();
    match (path.is_empty(), missing) {
        (true, Some(key)) => key.to_string(),
        (true, None) => "scene".into(),
        (false, Some(key)) => format!("{path}.{key}"),
        (false, None) => path,
    }
}

/// The search of [`toml_field`]: the tightest span holding `target`, and its path.
struct SpanSearch {
    target: std::ops::Range<usize>,
    /// Consider only tables' spans (a missing field belongs to a table).
    tables_only: bool,
    /// Length of the tightest span so far and the path of its key or value.
    best: Option<(usize, String)>,
}

impl SpanSearch {
    /// Records `path` when its key's or value's span holds the target more tightly than the best
    /// so far, then visits the value's entries (`path.key`) and items (`path[i]`).
    fn visit(
        &mut self,
        path: String,
        key_span: Option<std::ops::Range<usize>>,
        value: &toml::Spanned<toml::de::DeValue<'_>>,
    ) {
        let is_table = matches!(value.get_ref(), toml::de::DeValue::Table(_));
        let spans = if self.tables_only {
            if is_table {
                vec![value.span()]
            } else {
                Vec::new()
            }
        } else {
            key_span.into_iter().chain([value.span()]).collect()
        };
        for span in spans {
            let holds = span.start <= self.target.start && self.target.end <= span.end;
            if holds && self.best.as_ref().is_none_or(|(len, _)| span.len() < *len) {
                self.best = Some((span.len(), path.clone()));
            }
        }
        match value.get_ref() {
            toml::de::DeValue::Table(table) => {
                for (k, v) in table {
                    self.visit(format!("{path}.{}", k.get_ref()), Some(k.span()), v);
                }
            }
            toml::de::DeValue::Array(items) => {
                for (i, item) in items.iter().enumerate() {
                    self.visit(format!("{path}[{i}]"), None, item);
                }
            }
            _ => {}
        }
    }
}

/// The parser's message with the line and column it points at.
fn toml_problem(e: &toml::de::Error, text: &str) -> String {
    let message = e.message().trim().to_string();
    match e.span().and_then(|span| text.get(..span.start)) {
        Some(before) => {
            let line = before.matches('\n').count() + 1;
            let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            format!("{message} (line {line}, column {column})")
        }
        None => message,
    }
}

//! The scene file format (TOML, `version = 1`): what `ibl render` reads. Documented for users in
//! `docs/SCENES.md`; every field is listed there with its unit and default.
//!
//! A scene has a light probe (`[probe]`: lat-long image, `world_from_probe` rotation, radiance scale
//! and the world position of its centre), a background (`[background]`: the probe itself as a
//! panorama seen from its centre, or a photograph with a pinhole `[camera]`), **local real geometry**
//! (`[[local]]`: planes, boxes, spheres and meshes with a diffuse albedo per material group: the real
//! surfaces near the virtual objects, Debevec 1998's "local scene"), **virtual objects**
//! (`[[object]]`: meshes or shapes with a transform and a material), the renderer's settings
//! (`[render]`), the lighting (`[lighting]`), for outdoor AR under changing light (Jensen,
//! Andersen & Madsen 2006), the site, times, mask and video frames (`[outdoor]`) and, for Grosch
//! 2005's room reconstruction, the room's surfaces and material groups (`[room]`: a **room file**
//! is a scene with a `[probe]` and a `[room]`, what `ibl room` reads and writes).
//!
//! One module per table of the file ([`ProbeDescription`] in `probe`, `background`, `camera`,
//! `geometry` for `[[local]]` and `[[object]]`, `material`, `render`, `lighting`, `outdoor`,
//! `room`); this module holds the whole file and the checks that span tables (a photo background
//! needs a camera, an outdoor scene a camera and a photo background, ...).
//!
//! Parsing refuses unknown fields (a typo is an error, not a silently ignored setting). After
//! parsing, [`SceneDescription::validate`] checks every value and names the offending field by its
//! path, e.g. `object[0].rotate_deg: not a finite number`. File paths stay relative to the scene
//! file; `ibl-io` resolves them.

mod background;
mod camera;
mod field;
mod geometry;
mod lighting;
mod luminaire;
mod material;
mod outdoor;
mod probe;
mod render;
mod room;
mod toml_error;

use serde::{Deserialize, Serialize};

pub use background::{BackgroundDescription, BackgroundKind};
pub use camera::CameraDescription;
pub use field::DescriptionError;
use field::invalid;
pub(crate) use geometry::Layer;
pub use geometry::{
    GeometryDescription, MAX_SCENE_TRIANGLES, SPHERE_SUBDIVISIONS, Scale, ShapeKind,
    shape_triangles,
};
pub use lighting::{
    AUTO_AMBIENT_BANDS, AmbientBands, LightingDescription, MAX_AMBIENT_BANDS, MAX_AO_SAMPLES,
    ShadowKind, check_occlusion_rays,
};
pub use luminaire::{IntensityScale, LuminaireDescription, MAX_LUMINAIRES, validate_luminaires};
pub use material::{
    DEFAULT_ALBEDO, DEFAULT_EXPONENT, DEFAULT_MIRROR, DEFAULT_SPECULAR, MaterialDescription,
    MaterialKind,
};
pub use outdoor::{
    CivilTime, DEFAULT_NORTH, DEFAULT_PRESSURE_MBAR, DEFAULT_SAMPLES, DEFAULT_TEMPERATURE_C,
    FramesDescription, MAX_NORTH_TILT_DEG, MAX_SAMPLES, OutdoorDescription, local_civil_time,
};
pub use probe::ProbeDescription;
pub use render::{
    CompositeRule, MAX_BOUNCES, MAX_SPP, MAX_WIDTH, RenderDescription, RenderMode, SamplerKind,
};
pub use room::{
    BoxDescription, BoxFace, Facing, GroupDescription, GroupKind, HoleDescription,
    MAX_COORDINATE_M, MAX_PATCH_AREA_M2, MAX_POLYGON_VERTICES, MAX_SURFACES, MIN_PATCH_AREA_M2,
    OpeningDescription, PolygonDescription, RectangleDescription, RoomDescription,
};

/// The only format version this build reads.
pub const FORMAT_VERSION: u32 = 1;

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
    /// Goniometric point lights added to the scene (IES or EULUMDAT files), lighting its
    /// surfaces in every render mode. Default none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub luminaire: Vec<LuminaireDescription>,
    /// Outdoor AR under changing light (sun and sky estimated per video frame): the site, the
    /// probe's time, the estimation's mask and the frames. Default none: an indoor or still
    /// scene. With it, `camera` is the video camera and `background` a representative frame.
    #[serde(default)]
    pub outdoor: Option<OutdoorDescription>,
    /// The room of Grosch 2005 (`ibl room`): its surfaces, material groups and patch size, with
    /// the probe placed in it by `[probe]`. Default none. A room file is a scene with only
    /// `[probe]` and `[room]`; the renderer does not draw the room (it is the real scene the probe
    /// shows).
    #[serde(default)]
    pub room: Option<RoomDescription>,
}

impl SceneDescription {
    /// Parses TOML text; unknown fields and type errors are refused with their location.
    pub fn from_toml(text: &str) -> Result<SceneDescription, DescriptionError> {
        let deserializer = toml::de::Deserializer::parse(text)
            .map_err(|e| invalid("toml", toml_error::toml_problem(&e, text)))?;
        let description: SceneDescription = serde_path_to_error::deserialize(deserializer)
            .map_err(|e| {
                let field = toml_error::field_path(e.path(), e.inner().message());
                invalid(field, toml_error::toml_problem(e.inner(), text))
            })?;
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
        self.probe.validate()?;
        if self.outdoor.is_some() {
            if self.camera.is_none() {
                return Err(invalid(
                    "camera",
                    "an [outdoor] scene needs the calibrated video camera as its [camera]",
                ));
            }
            if self.background.kind != BackgroundKind::Photo {
                return Err(invalid(
                    "background.kind",
                    "an [outdoor] scene's background is a representative frame: give `kind = \"photo\"` and its file",
                ));
            }
        }
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
        let shapes = shape_triangles(&self.local) + shape_triangles(&self.object);
        if shapes > MAX_SCENE_TRIANGLES {
            return Err(invalid(
                "object",
                format!(
                    "the {} [[local]] and [[object]] entries' shapes make {shapes} triangles, over \
                     the limit of {MAX_SCENE_TRIANGLES} for a whole scene (a sphere is {} \
                     triangles)",
                    self.local.len() + self.object.len(),
                    ShapeKind::Sphere.triangle_count().unwrap_or(0)
                ),
            ));
        }
        self.render.validate()?;
        self.lighting.validate()?;
        validate_luminaires("luminaire", &self.luminaire)?;
        if let Some(outdoor) = &self.outdoor {
            outdoor.validate()?;
        }
        if let Some(room) = &self.room {
            room.validate()?;
        }
        Ok(())
    }
}

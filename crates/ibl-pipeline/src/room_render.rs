//! `ibl room render`: the reconstructed room re-rendered after Grosch 2005 section 4's
//! manipulations, read from an edits file: material changes (section 4.3: the changed groups'
//! radiance scaled by `rho' / rho` at once, then colour bleeding by delta radiosity over the
//! room's form factors, `bounces` bounces) and a moved camera (section 4.4: the probe projected on
//! the geometry where it saw, `B / pi` where it did not, optionally modulated by the seen texture
//! of the same face) and new goniometric lights (section 4.2: IES LM-63 or EULUMDAT files placed
//! and turned in the room, EQ5 per point with shadow rays, their light bounced like a material
//! change's) and virtual objects (section 4.1: the fast or improved display, their shadows
//! subtracted from the probe, lit by the new lights too). Without a `[view]`, the output is
//! the edited probe (lat-long); with one,
//! the view from the moved camera. `--before` writes the same picture without the edits, at the
//! same exposure, for side-by-side comparison.
//!
//! ```toml
//! version = 1
//! bounces = 1                        # colour bleeding (0: the direct change only)
//!
//! [[material]]                       # any number; each group at most once
//! group = "floor"                    # a surface group of the room file
//! reflectance = [0.60, 0.25, 0.20]   # linear RGB in [0, 1]
//!
//! [[light]]                          # any number (at most 64): a new goniometric light
//! file = "../../photometry/ies/overhead.ies"  # .ies or .ldt, relative to the edits file
//! position = [0.0, 2.2, -1.0]        # metres, world frame
//! rotation_deg = [0.0, 20.0, 0.0]    # yaw, pitch, roll of the light (0: aimed straight down)
//! colour = [1.0, 0.86, 0.7]          # its chromaticity (linear Rec. 709), default white
//! peak_intensity = 40.0              # normalised: the table's peak, probe units per sr; or
//! # nits_per_unit = 1.0              # absolute: cd/m^2 of a probe value of 1 (the default)
//!
//! display = "improved"               # virtual objects: Grosch's "improved" or "fast" display
//! important_patches = 32             # the patches that light them and cast their shadows
//! [[object]]                         # any number (at most 64), as a scene file's [[object]]
//! shape = "mesh"                     # sphere, box, plane or mesh (file relative to this file)
//! file = "../../models/bunny.glb"
//! scale = 0.25
//! translate = [1.45, 0.223, -0.75]
//! material = { kind = "diffuse", albedo = [0.75, 0.75, 0.75] }
//!
//! [view]                             # optional: a camera moved inside the room
//! position = [0.5, 1.2, 0.0]         # metres, world frame (docs/CONVENTIONS.md)
//! look_at = [0.0, 1.0, -2.0]
//! vertical_fov_deg = 60.0
//! size = [640, 480]
//! fill = "textured"                  # or "estimate" (Grosch's rho E / pi)
//! samples_per_axis = 2
//! ```
//!
//! Paths in the edits file: the lights' files, relative to the edits file. Unknown keys are
//! refused with their name and line.

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::{Vec2, Vec3};
use ibl_core::tonemap::{Display, ToneCurve, auto_exposure_stops};
use ibl_core::{Image, Rgb};
use ibl_io::WriteOptions;
use ibl_io::luminaire_file::read_luminaire;
use ibl_light::GoniometricLight;
use ibl_room::room_radiance::RoomRadiance;
use ibl_room::{
    DisplayMode, FillTexture, FillTextureSettings, Group, GroupKind, HoleFill, ImportantLights,
    LightAddition, LightAdditionSettings, MaterialChange, MaterialEdit, NovelViewSettings,
    ObjectDisplay, ObjectDisplaySettings, Room, RoomVolume, VolumeSettings, add_lights,
    change_materials, important_patches, render_novel_view,
};
use ibl_scene::description::{GeometryDescription, IntensityScale, LuminaireDescription};
use ibl_scene::{Camera, GeometryLayer};
use serde::{Deserialize, Serialize};

use crate::error::{PipelineError, Result};
use crate::progress::Progress;
use crate::room_estimate::{EstimatedRoom, SamplingOptions, estimate_read_room};
use crate::room_input::read_room;

/// Largest edits file read, bytes.
const MAX_EDITS_BYTES: u64 = 1 << 20;

/// The edits file as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct EditsFile {
    version: u32,
    #[serde(default = "one")]
    bounces: u32,
    #[serde(default)]
    material: Vec<MaterialEntry>,
    #[serde(default)]
    light: Vec<LuminaireDescription>,
    #[serde(default)]
    object: Vec<GeometryDescription>,
    #[serde(default = "default_display")]
    display: String,
    #[serde(default = "default_important")]
    important_patches: usize,
    view: Option<ViewEntry>,
}

fn default_display() -> String {
    "improved".into()
}

fn default_important() -> usize {
    32
}

/// Most virtual objects in one edits file.
pub const MAX_OBJECTS: usize = 64;
/// Most important patches asked for.
pub const MAX_IMPORTANT_PATCHES: usize = 1024;

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialEntry {
    group: String,
    reflectance: [f32; 3],
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ViewEntry {
    position: [f32; 3],
    look_at: [f32; 3],
    #[serde(default = "default_fov")]
    vertical_fov_deg: f32,
    #[serde(default = "default_size")]
    size: [u32; 2],
    #[serde(default = "default_fill")]
    fill: String,
    #[serde(default = "default_samples")]
    samples_per_axis: u32,
}

fn one() -> u32 {
    1
}
fn default_fov() -> f32 {
    60.0
}
fn default_size() -> [u32; 2] {
    [640, 480]
}
fn default_fill() -> String {
    "textured".into()
}
fn default_samples() -> u32 {
    NovelViewSettings::default().samples_per_axis
}

/// A camera moved inside the room.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewEdit {
    /// Eye, metres, world frame.
    pub position: Vec3,
    /// Point looked at.
    pub look_at: Vec3,
    /// Vertical field of view, degrees.
    pub vertical_fov_deg: f32,
    /// Output size, pixels.
    pub width: u32,
    /// Output size, pixels.
    pub height: u32,
    /// Whether the unseen surfaces' fill is modulated by the seen texture of their face.
    pub textured: bool,
    /// Rays per pixel along each axis.
    pub samples_per_axis: u32,
}

/// Most new lights in one edits file.
pub const MAX_LIGHTS: usize = ibl_scene::description::MAX_LUMINAIRES;

/// A new goniometric light as the edits file places it (its file not read yet).
#[derive(Clone, Debug, PartialEq)]
pub struct LightSpec {
    /// The `.ies` or `.ldt` file, resolved against the edits file's folder.
    pub file: PathBuf,
    /// Position, metres, world frame.
    pub position: Vec3,
    /// Yaw, pitch and roll of the light's frame, degrees (0: aimed straight down).
    pub rotation_deg: [f32; 3],
    /// Its chromaticity, linear Rec. 709 (only the ratios count).
    pub colour: Rgb,
    /// Candela to the probe's unit.
    pub scale: IntensityScale,
}

/// A light read from its file and placed.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedLight {
    /// The light, world frame, in the probe's unit.
    pub light: GoniometricLight,
    /// What is reported of it.
    pub row: LightRow,
}

/// The virtual objects, as `--json` reports them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ObjectRow {
    /// Their names.
    pub names: Vec<String>,
    /// Triangles in all.
    pub triangles: usize,
    /// `fast` or `improved` (Grosch 2005 section 4.1).
    pub display: &'static str,
    /// Important patches lighting them and casting their shadows.
    pub important_patches: usize,
}

/// One new light, as `--json` reports it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LightRow {
    /// Its file.
    pub file: String,
    /// The luminaire's name in the file.
    pub name: String,
    /// Position, metres, world frame.
    pub position: [f32; 3],
    /// The table's luminous flux (its exact integral), lm.
    pub flux_lm: f64,
    /// What the file states the luminaire emits, lm (when it says).
    pub stated_lm: Option<f64>,
    /// The table's peak, cd.
    pub peak_cd: f32,
    /// The peak in the probe's unit per sr (luminance-weighted).
    pub peak_intensity: f32,
}

/// A checked edits file.
#[derive(Clone, Debug, PartialEq)]
pub struct RoomEdits {
    /// Bounces of colour bleeding (of the changed materials and of the new lights).
    pub bounces: u32,
    /// Surface group name and its new reflectance, in file order.
    pub materials: Vec<(String, Rgb)>,
    /// New goniometric lights, in file order.
    pub lights: Vec<LightSpec>,
    /// Virtual objects, as a scene file's `[[object]]` entries (meshes not read yet).
    pub objects: Vec<GeometryDescription>,
    /// How the objects are displayed (Grosch's fast or improved display).
    pub display: DisplayMode,
    /// Important patches that light the objects and cast their shadows.
    pub important_patches: usize,
    /// The moved camera, if any.
    pub view: Option<ViewEdit>,
    /// The edits file (its objects' mesh files are relative to it).
    pub source: PathBuf,
}

/// What an edits file names, read: its lights and its objects.
#[derive(Clone, Debug)]
pub struct EditAssets {
    /// The lights, placed.
    pub lights: Vec<LoadedLight>,
    /// The virtual objects, when there are any.
    pub objects: Option<GeometryLayer>,
}

impl RoomEdits {
    /// No edits: the room as estimated, its probe as the picture.
    pub fn none() -> RoomEdits {
        RoomEdits {
            bounces: 1,
            materials: Vec::new(),
            lights: Vec::new(),
            objects: Vec::new(),
            display: DisplayMode::Improved,
            important_patches: 32,
            view: None,
            source: PathBuf::new(),
        }
    }

    /// Reads and checks `path`.
    pub fn read(path: &Path) -> Result<RoomEdits> {
        let text = ibl_io::read_text(path, MAX_EDITS_BYTES)?;
        RoomEdits::parse(&text, path)
    }

    /// Parses `text` as the edits file `path` (for messages).
    pub fn parse(text: &str, path: &Path) -> Result<RoomEdits> {
        let shown = path.display();
        let bad = |m: String| PipelineError::parameter(format!("{shown}: {m}"));
        let file: EditsFile = toml::from_str(text).map_err(|e| bad(e.to_string()))?;
        if file.version != 1 {
            return Err(bad(format!(
                "version {} (this iblkit reads version 1)",
                file.version
            )));
        }
        if file.bounces > ibl_room::material_change::MAX_BOUNCES {
            return Err(bad(format!(
                "bounces = {} (at most {})",
                file.bounces,
                ibl_room::material_change::MAX_BOUNCES
            )));
        }
        let mut materials = Vec::with_capacity(file.material.len());
        for (k, m) in file.material.iter().enumerate() {
            if !m.reflectance.iter().all(|v| (0.0..=1.0).contains(v)) {
                return Err(bad(format!(
                    "material[{k}] (group `{}`): reflectance {:?} is not in [0, 1]",
                    m.group, m.reflectance
                )));
            }
            if materials.iter().any(|(g, _): &(String, Rgb)| g == &m.group) {
                return Err(bad(format!(
                    "material[{k}]: group `{}` is changed twice",
                    m.group
                )));
            }
            materials.push((m.group.clone(), Rgb::from_array(m.reflectance)));
        }
        if file.light.len() > MAX_LIGHTS {
            return Err(bad(format!(
                "{} lights (at most {MAX_LIGHTS})",
                file.light.len()
            )));
        }
        let folder = path.parent().unwrap_or(Path::new(""));
        let lights = file
            .light
            .iter()
            .enumerate()
            .map(|(k, l)| check_light(l, &format!("light[{k}]"), folder).map_err(bad))
            .collect::<Result<Vec<_>>>()?;
        let view = match &file.view {
            None => None,
            Some(v) => Some(check_view(v).map_err(|m| bad(format!("[view] {m}")))?),
        };
        if file.object.len() > MAX_OBJECTS {
            return Err(bad(format!(
                "{} objects (at most {MAX_OBJECTS})",
                file.object.len()
            )));
        }
        let display = match file.display.as_str() {
            "improved" => DisplayMode::Improved,
            "fast" => DisplayMode::Fast,
            other => return Err(bad(format!("display `{other}` (improved or fast)"))),
        };
        if !(1..=MAX_IMPORTANT_PATCHES).contains(&file.important_patches) {
            return Err(bad(format!(
                "important_patches = {} (1 to {MAX_IMPORTANT_PATCHES})",
                file.important_patches
            )));
        }
        Ok(RoomEdits {
            bounces: file.bounces,
            materials,
            lights,
            objects: file.object,
            display,
            important_patches: file.important_patches,
            view,
            source: path.to_path_buf(),
        })
    }

    /// Reads what the edits name: the lights' files and the objects' meshes, and checks the
    /// objects as a scene file's (errors name the file, the field and the problem).
    pub fn load(&self) -> Result<EditAssets> {
        let lights = self.load_lights()?;
        let objects = if self.objects.is_empty() {
            None
        } else {
            let mut triangles_left = ibl_scene::description::MAX_SCENE_TRIANGLES
                .saturating_sub(ibl_scene::description::shape_triangles(&self.objects));
            let (meshes, _) =
                ibl_io::read_meshes(&self.source, "object", &self.objects, &mut triangles_left)?;
            let layer = ibl_scene::virtual_layer(&self.objects, meshes)
                .map_err(|e| PipelineError::parameter(format!("{}: {e}", self.source.display())))?;
            Some(layer)
        };
        Ok(EditAssets { lights, objects })
    }

    /// Reads every light's file and places it; errors name the file and the problem.
    pub fn load_lights(&self) -> Result<Vec<LoadedLight>> {
        self.lights.iter().map(load_light).collect()
    }
}

/// An edits file's `[[light]]` (a scene's `[[luminaire]]` entry), checked, its file resolved
/// against `folder`; errors name `field`.
fn check_light(
    l: &LuminaireDescription,
    field: &str,
    folder: &Path,
) -> std::result::Result<LightSpec, String> {
    l.validate(field).map_err(|e| e.to_string())?;
    let scale = l.scale(field).map_err(|e| e.to_string())?;
    Ok(LightSpec {
        file: folder.join(&l.file),
        position: Vec3::from(l.position),
        rotation_deg: l.rotation_deg,
        colour: Rgb::from_array(l.colour),
        scale,
    })
}

/// Reads `spec`'s photometric file and makes the light.
fn load_light(spec: &LightSpec) -> Result<LoadedLight> {
    let placed = read_luminaire(
        &spec.file,
        spec.position,
        spec.rotation_deg,
        spec.colour,
        spec.scale,
    )?;
    let light = placed.light;
    let peak_cd = light.table.peak();
    let row = LightRow {
        file: spec.file.display().to_string(),
        name: placed.file.name().to_string(),
        position: spec.position.to_array(),
        flux_lm: light.table.flux(),
        stated_lm: placed.file.stated_flux().luminaire_lumens(),
        peak_cd,
        peak_intensity: peak_cd / placed.nits_per_unit,
    };
    Ok(LoadedLight { light, row })
}

fn check_view(v: &ViewEntry) -> std::result::Result<ViewEdit, String> {
    let finite = |a: &[f32; 3]| a.iter().all(|x| x.is_finite());
    if !finite(&v.position) || !finite(&v.look_at) {
        return Err("position and look_at must be finite".into());
    }
    let (position, look_at) = (Vec3::from(v.position), Vec3::from(v.look_at));
    let forward = look_at - position;
    if forward.length() < 1e-6 || forward.normalize().cross(Vec3::Y).length() < 1e-6 {
        return Err("look_at must differ from position and not be straight up or down".into());
    }
    if !(v.vertical_fov_deg > 0.0 && v.vertical_fov_deg < 179.0) {
        return Err(format!(
            "vertical_fov_deg {} is not in (0, 179)",
            v.vertical_fov_deg
        ));
    }
    let [width, height] = v.size;
    if width == 0 || height == 0 || u64::from(width) * u64::from(height) > 64 << 20 {
        return Err(format!(
            "size {width} x {height} is empty or more than 64 Mpixels"
        ));
    }
    let textured = match v.fill.as_str() {
        "textured" => true,
        "estimate" => false,
        other => return Err(format!("fill `{other}` (textured or estimate)")),
    };
    if !(1..=ibl_room::novel_view::MAX_SAMPLES_PER_AXIS).contains(&v.samples_per_axis) {
        return Err(format!(
            "samples_per_axis {} (1 to {})",
            v.samples_per_axis,
            ibl_room::novel_view::MAX_SAMPLES_PER_AXIS
        ));
    }
    Ok(ViewEdit {
        position,
        look_at,
        vertical_fov_deg: v.vertical_fov_deg,
        width,
        height,
        textured,
        samples_per_axis: v.samples_per_axis,
    })
}

/// What `ibl room render` is asked to do.
#[derive(Clone, Debug)]
pub struct RoomRenderOptions {
    /// The room file.
    pub room: PathBuf,
    /// The edits file (none: the room as estimated).
    pub edits: Option<PathBuf>,
    /// The picture after the edits (`.exr`, `.hdr`, `.pfm`, `.png`, `.jpg`).
    pub output: PathBuf,
    /// The same picture before the edits, at the same exposure.
    pub before: Option<PathBuf>,
    /// The estimate's form-factor sampling.
    pub sampling: SamplingOptions,
}

/// What `ibl room render` did (its `--json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RoomRenderResult {
    /// The room file.
    pub room: String,
    /// `panorama` (the edited probe) or `view` (a moved camera).
    pub kind: &'static str,
    /// Output size, pixels.
    pub width: usize,
    /// Output size, pixels.
    pub height: usize,
    /// What the edits did (its fields sit beside these in the JSON).
    #[serde(flatten)]
    pub edit: EditReport,
    /// Exposure of `.png`/`.jpg` outputs, stops (the before picture's automatic exposure).
    pub exposure_stops: f32,
    /// Seconds: the estimate (depth map, form factors, radiosity).
    pub seconds_estimate: f64,
    /// Files written.
    pub outputs: Vec<String>,
}

/// What applying an edits file did: the demo's and `ibl room render --json`'s account of it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EditReport {
    /// The groups changed, with their reflectance before and after.
    pub materials: Vec<MaterialRow>,
    /// The lights added.
    pub lights: Vec<LightRow>,
    /// The objects inserted, if any.
    pub objects: Option<ObjectRow>,
    /// Bounces of colour bleeding made (of the changed materials and of the new lights).
    pub bounces: u32,
    /// The last bounce's largest change relative to the largest radiosity (what another bounce
    /// would add, roughly).
    pub last_bounce_relative: f32,
    /// A view's pixels whose rays all met surfaces the probe did not see (filled), fraction.
    pub filled_fraction: Option<f64>,
    /// Seconds of the edit (the material change, the new lights' patch means, the bleeding).
    pub seconds_edit: f64,
    /// Seconds of rendering the picture(s).
    pub seconds_render: f64,
}

impl RoomRenderResult {
    /// What `ibl room render` prints.
    pub fn text(&self) -> String {
        let mut text = format!("{} x {} {}", self.width, self.height, self.kind);
        for m in &self.edit.materials {
            text += &format!(
                "; {}: reflectance {:.3?} -> {:.3?}",
                m.group, m.before, m.after
            );
        }
        for l in &self.edit.lights {
            text += &format!(
                "; light {} at {:.2?}: {:.0} lm{}, peak {:.0} cd = {:.3} probe units/sr",
                l.file,
                l.position,
                l.flux_lm,
                l.stated_lm
                    .map_or(String::new(), |s| format!(" (the file states {s:.0})")),
                l.peak_cd,
                l.peak_intensity
            );
        }
        if let Some(o) = &self.edit.objects {
            text += &format!(
                "; {} object(s) ({} triangles), the {} display with {} important patches",
                o.names.len(),
                o.triangles,
                o.display,
                o.important_patches
            );
        }
        if !self.edit.materials.is_empty() || !self.edit.lights.is_empty() {
            text += &format!(
                "; {} bounce{} of colour bleeding (the last changed {:.2} %)",
                self.edit.bounces,
                if self.edit.bounces == 1 { "" } else { "s" },
                100.0 * self.edit.last_bounce_relative
            );
        }
        if let Some(f) = self.edit.filled_fraction {
            text += &format!(
                "; {:.1} % of the pixels filled (unseen by the probe)",
                100.0 * f
            );
        }
        text += &format!(
            "\nestimate {:.2} s, edit {:.3} s, picture {:.2} s; wrote {}\n",
            self.seconds_estimate,
            self.edit.seconds_edit,
            self.edit.seconds_render,
            self.outputs.join(", ")
        );
        text
    }
}

/// One changed group.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MaterialRow {
    /// Group name.
    pub group: String,
    /// The estimate's reflectance.
    pub before: [f32; 3],
    /// The edit's.
    pub after: [f32; 3],
}

/// Runs `ibl room render`.
pub fn room_render(o: &RoomRenderOptions, progress: &dyn Progress) -> Result<RoomRenderResult> {
    let edits = match &o.edits {
        Some(p) => RoomEdits::read(p)?,
        None => RoomEdits::none(),
    };
    let mut inputs: Vec<&Path> = vec![&o.room];
    inputs.extend(o.edits.as_deref());
    inputs.extend(edits.lights.iter().map(|l| l.file.as_path()));
    let folder = edits.source.parent().unwrap_or(Path::new("."));
    let mesh_files: Vec<PathBuf> = edits
        .objects
        .iter()
        .filter_map(|o| o.file.as_ref().map(|f| folder.join(f)))
        .collect();
    inputs.extend(mesh_files.iter().map(PathBuf::as_path));
    let outputs: Vec<&Path> = std::iter::once(o.output.as_path())
        .chain(o.before.as_deref())
        .collect();
    for out in &outputs {
        if ibl_io::ImageFormat::from_path(out).is_none() {
            return Err(PipelineError::parameter(format!(
                "{}: write the picture as .exr, .hdr, .pfm, .png or .jpg",
                out.display()
            )));
        }
        crate::output_paths::check_output_path(out, &inputs)?;
    }
    if o.before.as_deref() == Some(o.output.as_path()) {
        return Err(PipelineError::parameter(format!(
            "{}: --before and -o name the same file",
            o.output.display()
        )));
    }
    // The room file is read first: its probe must not be overwritten and the edited groups
    // must be its surface groups, both checked before the analysis runs.
    let input = read_room(&o.room)?;
    for out in &outputs {
        crate::output_paths::check_output_path(out, &[&input.probe_path])?;
    }
    surface_groups(&input.room, &edits, &o.room)?;
    let assets = edits.load()?;
    let start = Instant::now();
    let estimated = estimate_read_room(&o.room, input, &o.sampling, progress)?;
    let seconds_estimate = start.elapsed().as_secs_f64();
    let pictures = render_edits(&estimated, &edits, &assets, &o.room)?;
    let stops = pictures.write(&o.output, o.before.as_deref())?;
    let (width, height) = (pictures.after.width(), pictures.after.height());
    let written: Vec<String> = outputs.iter().map(|p| p.display().to_string()).collect();
    Ok(RoomRenderResult {
        room: o.room.display().to_string(),
        kind: if edits.view.is_some() {
            "view"
        } else {
            "panorama"
        },
        width,
        height,
        edit: pictures.report,
        exposure_stops: stops,
        seconds_estimate,
        outputs: written,
    })
}

/// The pictures of an estimated room before and after `edits`: the probe and the edited probe,
/// or the view from the moved camera without and with the edits (radiance, probe units).
#[derive(Clone, Debug)]
pub struct EditedPictures {
    /// Without the edits.
    pub before: Image<Rgb>,
    /// With them.
    pub after: Image<Rgb>,
    /// What the edits did.
    pub report: EditReport,
}

impl EditedPictures {
    /// Writes the picture after the edits to `after` and, when asked, the one before to
    /// `before`, PNG and JPEG at one exposure (the before picture's automatic one, ACES);
    /// returns it, stops.
    pub fn write(&self, after: &Path, before: Option<&Path>) -> Result<f32> {
        let stops = auto_exposure_stops(&self.before);
        let options = WriteOptions {
            display: Display {
                exposure_stops: stops,
                curve: ToneCurve::AcesFilmic,
            },
            ..Default::default()
        };
        ibl_io::write_image(after, &self.after, &options)?;
        if let Some(path) = before {
            ibl_io::write_image(path, &self.before, &options)?;
        }
        Ok(stops)
    }
}

/// A room with an edits file's material changes and new lights applied (no objects yet).
#[derive(Clone, Debug)]
pub struct EditedRoom {
    /// The changed groups, with their reflectance before and after.
    pub rows: Vec<MaterialRow>,
    /// The material change and its colour bleeding (per patch: `reflectance`, `radiosity`).
    pub edit: MaterialEdit,
    /// The new lights' direct light and bounces (none without new lights).
    pub addition: Option<LightAddition>,
    /// The probe with the edited materials (the lights are added at each point shown).
    pub edited_probe: Image<Rgb>,
    /// The estimate with the edit's radiosity.
    pub estimate: ibl_room::Estimate,
    /// Seconds of the edit.
    pub seconds_edit: f64,
}

impl EditedRoom {
    /// The edited room as a radiance field: the edited probe's texture, the edited estimate, the
    /// new lights' light (what a moved camera and the objects' volume see).
    pub fn radiance<'a>(&'a self, estimated: &'a EstimatedRoom) -> Result<RoomRadiance<'a>> {
        let analysis = &estimated.analysis;
        let field = RoomRadiance::new(
            &estimated.input.room,
            &analysis.depth,
            &self.edited_probe,
            &self.estimate,
        )?;
        Ok(match &self.addition {
            Some(a) => field.with_added_light(a),
            None => field,
        })
    }

    /// The edited panorama as the probe shows it, with the new lights' light (no objects).
    pub fn panorama(&self, estimated: &EstimatedRoom) -> Result<Image<Rgb>> {
        Ok(match &self.addition {
            Some(a) => a.panorama(
                &estimated.input.room,
                &estimated.analysis.depth,
                &self.edited_probe,
            )?,
            None => self.edited_probe.clone(),
        })
    }
}

/// Applies `edits`'s material changes and new lights (`assets.lights`) to `estimated` (the room
/// file `room_path`, for messages).
pub fn edit_room(
    estimated: &EstimatedRoom,
    edits: &RoomEdits,
    assets: &EditAssets,
    room_path: &Path,
) -> Result<EditedRoom> {
    let (changes, rows) = resolve_materials(estimated, edits, room_path)?;
    let start = Instant::now();
    let room = &estimated.input.room;
    let analysis = &estimated.analysis;
    let edit = change_materials(
        room,
        &analysis.estimate,
        &analysis.form_factors,
        &changes,
        edits.bounces,
    )?;
    // The new lights reflect off the edited materials and bounce as often as their change.
    let addition = if assets.lights.is_empty() {
        None
    } else {
        let settings = LightAdditionSettings {
            bounces: edits.bounces,
            ..LightAdditionSettings::default()
        };
        let placed = assets.lights.iter().map(|l| l.light.clone()).collect();
        Some(add_lights(
            room,
            &edit.reflectance,
            &analysis.form_factors,
            placed,
            &settings,
        )?)
    };
    // The probe with the edited materials: the texture a moved camera sees.
    let edited_probe = edit.panorama(&analysis.depth, &estimated.probe)?;
    let estimate = edited_estimate(estimated, &edit.radiosity);
    Ok(EditedRoom {
        rows,
        edit,
        addition,
        edited_probe,
        estimate,
        seconds_edit: start.elapsed().as_secs_f64(),
    })
}

/// The objects' lights in an edited room (`field`, its `estimate`): the `n` important patches
/// and the irradiance volume gathered with them left out of its second layer (Grosch 2005
/// section 4.1).
pub fn object_lighting(
    field: &RoomRadiance,
    estimate: &ibl_room::Estimate,
    n: usize,
) -> Result<(ImportantLights, RoomVolume)> {
    let important = important_patches(field.room(), estimate, n);
    let volume = RoomVolume::build(field, &important, &VolumeSettings::default())?;
    Ok((important, volume))
}

/// Applies `edits` to `estimated` (the room file `room_path`, for messages), with what the edits
/// name as `assets` ([`RoomEdits::load`]), and renders the pictures before and after.
pub fn render_edits(
    estimated: &EstimatedRoom,
    edits: &RoomEdits,
    assets: &EditAssets,
    room_path: &Path,
) -> Result<EditedPictures> {
    let lights = &assets.lights;
    let room = &estimated.input.room;
    let analysis = &estimated.analysis;
    let edited = edit_room(estimated, edits, assets, room_path)?;
    let EditedRoom {
        rows,
        edit,
        addition,
        estimate,
        seconds_edit,
        ..
    } = &edited;
    let start = Instant::now();
    let field = edited.radiance(estimated)?;
    let lamps: Vec<GoniometricLight> = lights.iter().map(|l| l.light.clone()).collect();
    let objects = assets.objects.as_ref().map(|objects| ObjectInputs {
        field: &field,
        estimate,
        reflectance: &edit.reflectance,
        objects,
        lamps: &lamps,
        edits,
    });
    let (before, after, filled_fraction) = match &edits.view {
        None => {
            let lit = edited.panorama(estimated)?;
            let after = match &objects {
                Some(o) => o.display(|d| Ok(d.panorama(&lit)?.image))?,
                None => lit,
            };
            (estimated.probe.clone(), after, None)
        }
        Some(view) => {
            let texture = if view.textured {
                Some(FillTexture::new(
                    room,
                    &analysis.depth,
                    &estimated.probe,
                    &analysis.estimate,
                    &FillTextureSettings::default(),
                )?)
            } else {
                None
            };
            let fill = texture
                .as_ref()
                .map_or(HoleFill::Estimate, HoleFill::Textured);
            let camera = view_camera(view);
            let settings = NovelViewSettings {
                samples_per_axis: view.samples_per_axis,
            };
            let render = |field: &RoomRadiance| -> Result<ibl_room::NovelView> {
                Ok(render_novel_view(
                    field,
                    &camera,
                    view.width,
                    view.height,
                    fill,
                    &settings,
                )?)
            };
            let before = render(&RoomRadiance::new(
                room,
                &analysis.depth,
                &estimated.probe,
                &analysis.estimate,
            )?)?;
            let after = match &objects {
                Some(o) => {
                    o.display(|d| Ok(d.view(&camera, view.width, view.height, fill)?.image))?
                }
                None => render(&field)?.image,
            };
            // Which pixels show only surfaces the probe did not see depends on the room and the
            // camera alone: the same before and after the edits.
            let filled = before.filled_mask();
            let n = filled.pixels().iter().filter(|&&f| f).count();
            let fraction = n as f64 / filled.pixels().len().max(1) as f64;
            (before.image, after, Some(fraction))
        }
    };
    let last_bounce_relative = edit
        .last_bounce_relative
        .max(addition.as_ref().map_or(0.0, |a| a.last_bounce_relative));
    Ok(EditedPictures {
        before,
        after,
        report: EditReport {
            materials: rows.clone(),
            lights: lights.iter().map(|l| l.row.clone()).collect(),
            objects: assets.objects.as_ref().map(|o| ObjectRow {
                names: o.object_names.clone(),
                triangles: o.triangle_count(),
                display: match edits.display {
                    DisplayMode::Fast => "fast",
                    DisplayMode::Improved => "improved",
                },
                important_patches: edits.important_patches,
            }),
            bounces: edit.bounces,
            last_bounce_relative,
            filled_fraction,
            seconds_edit: *seconds_edit,
            seconds_render: start.elapsed().as_secs_f64(),
        },
    })
}

/// The estimate with the edit's radiosity.
fn edited_estimate(estimated: &EstimatedRoom, radiosity: &[Rgb]) -> ibl_room::Estimate {
    let mut estimate = estimated.analysis.estimate.clone();
    for (patch, b) in estimate.patches.iter_mut().zip(radiosity) {
        patch.radiosity = *b;
    }
    estimate
}

/// What the objects' display needs of the edited room.
struct ObjectInputs<'a> {
    field: &'a RoomRadiance<'a>,
    estimate: &'a ibl_room::Estimate,
    reflectance: &'a [Rgb],
    objects: &'a GeometryLayer,
    lamps: &'a [GoniometricLight],
    edits: &'a RoomEdits,
}

impl ObjectInputs<'_> {
    /// Builds the display (the important patches, the irradiance volume of the edited room,
    /// Grosch's display with the new lights) and hands it to `picture`.
    fn display<R>(&self, picture: impl FnOnce(&ObjectDisplay) -> Result<R>) -> Result<R> {
        let (important, volume) =
            object_lighting(self.field, self.estimate, self.edits.important_patches)?;
        let settings = ObjectDisplaySettings {
            mode: self.edits.display,
            ..ObjectDisplaySettings::default()
        };
        let display = ObjectDisplay::new(
            self.field,
            &volume,
            &important,
            self.reflectance,
            self.objects,
            settings,
        )?
        .with_lamps(self.lamps);
        picture(&display)
    }
}

/// The room's group index of each edited group, in the edits' order; an error naming the room's
/// surface groups for a name that is not one of them.
fn surface_groups(room: &Room, edits: &RoomEdits, room_path: &Path) -> Result<Vec<usize>> {
    let is_surface = |g: &&Group| g.kind == GroupKind::Surface;
    edits
        .materials
        .iter()
        .map(|(name, _)| {
            room.groups
                .iter()
                .position(|g| &g.name == name && is_surface(&g))
                .ok_or_else(|| {
                    let surfaces: Vec<&str> = room
                        .groups
                        .iter()
                        .filter(is_surface)
                        .map(|g| g.name.as_str())
                        .collect();
                    PipelineError::parameter(format!(
                        "{}: no surface group `{name}` (the surface groups are: {})",
                        room_path.display(),
                        surfaces.join(", ")
                    ))
                })
        })
        .collect()
}

/// The edits as the room's material changes, with the estimate's reflectances before.
fn resolve_materials(
    estimated: &EstimatedRoom,
    edits: &RoomEdits,
    room_path: &Path,
) -> Result<(Vec<MaterialChange>, Vec<MaterialRow>)> {
    let groups = surface_groups(&estimated.input.room, edits, room_path)?;
    let estimate = &estimated.analysis.estimate;
    Ok(groups
        .into_iter()
        .zip(&edits.materials)
        .map(|(group, (name, reflectance))| {
            let change = MaterialChange {
                group,
                reflectance: *reflectance,
            };
            let row = MaterialRow {
                group: name.clone(),
                before: estimate.groups[group].reflectance.unwrap_or([0.0; 3]),
                after: reflectance.to_array(),
            };
            (change, row)
        })
        .unzip())
}

/// The pinhole camera of a view (+Y up hint; square pixels).
fn view_camera(v: &ViewEdit) -> Camera {
    let focal = Camera::focal_from_vertical_fov(v.vertical_fov_deg, v.height);
    Camera::look_at(
        v.position,
        v.look_at,
        Vec3::Y,
        Vec2::splat(focal),
        Vec2::new(v.width as f32, v.height as f32) * 0.5,
        (v.width, v.height),
    )
}

//! Light sets for renderers: glTF 2.0 with `KHR_lights_punctual` directional lights (`.gltf` JSON
//! and `.glb` binary), a Mitsuba 3 XML scene and a pbrt-v4 scene fragment, beside the iblkit JSON
//! light-set file of [`crate::light_file`]. [`LightFormat::from_path`] picks the format by
//! extension and [`write_light_file`] writes any of them atomically.
//!
//! Every writer takes [`Light`]s: `direction` is the unit vector **towards** the light (the
//! file's frame preset, CONVENTIONS section 1; the writers never change axes, the caller picks the
//! preset) and `irradiance` is `I = L A` per channel (CONVENTIONS section 4), the irradiance the
//! light gives a surface facing it, in the probe's radiance unit x sr. A light *travels* along
//! `p = -direction`.
//!
//! - **glTF** (KHR_lights_punctual): a directional light shines along its node's local -Z, so each
//!   node's `rotation` is the shortest-arc unit quaternion `[x, y, z, w]` taking `(0, 0, -1)` to
//!   `p` (half a turn about +Y when `p = +Z`; [`gltf_rotation`]). The extension defines `intensity` (lux for
//!   directional lights) as the light's strength were it white, with `color` (linear, each
//!   component in `[0, 1]` by the schema) as a per-channel multiplier. We write
//!   `color = I / max_c(I)` (largest component exactly 1) and `intensity = s max_c(I)` lux, where
//!   `s` is [`ExportOptions::lux_per_unit`], so that `color x intensity = s I` in every channel and
//!   the illuminance it delivers, the Rec. 709 luminance of `color x intensity`, is `s Y(I)` lux.
//!   With the default `s = 1` the probe's values are read as luminance in cd/m^2 (nits), for which
//!   `Y(I)` (cd/m^2 x sr = lm/m^2) already is lux; for a probe in relative units, choose `s` to
//!   make the brightest light match a measured illuminance. A black light gets `color = [1, 1, 1]`
//!   and `intensity = 0`. `I` and `A` are also kept in each light's `extras`, with the solid
//!   angle of the cone its soft shadow is sized by (`shadow_solid_angle`, the light's spread
//!   within `A`) and the share of its power in that cone (`shadow_core_fraction`; the rest
//!   spreads over `A`).
//! - **Mitsuba 3**: `<emitter type="directional">` with `direction = p` (Mitsuba's `direction` is
//!   the way the light radiates) and `irradiance = I` as `<rgb>`.
//! - **pbrt-v4**: `LightSource "distant"` with `from = direction`, `to = 0` (pbrt's light travels
//!   from `from` to `to`) and `"rgb L" = I`, `scale 1`: pbrt-v4 divides an RGB illuminant spectrum
//!   by the photometric value of the colour space's standard illuminant, so a white `L` of 1 means
//!   1 nit and a surface facing the light receives `L x scale = I`.
//!
//! Mitsuba and pbrt receive `I` in the probe's unit; [`ExportOptions::lux_per_unit`] applies to
//! glTF only, whose unit is fixed by the extension. Non-finite values, negative irradiance and
//! zero-length directions are refused with an [`ExportError`] (never written, never a panic); an
//! empty light list gives a valid file with no lights.

use std::fmt::Write as _;
use std::path::Path;

use ibl_core::glam::{DQuat, DVec3};
use ibl_core::rgb::LUMINANCE_WEIGHTS;
use serde_json::json;

use crate::IoError;
use ibl_light::Light;

use crate::light_file::LightsFile;

/// Value of glTF's `asset.generator`.
pub const GENERATOR: &str = concat!("iblkit ", env!("CARGO_PKG_VERSION"));

/// The file formats a light set can be written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightFormat {
    /// The iblkit light-set file (`.json`, [`crate::light_file`]).
    Json,
    /// glTF 2.0 JSON (`.gltf`) with `KHR_lights_punctual`.
    Gltf,
    /// Binary glTF 2.0 (`.glb`): the same JSON in a GLB container.
    Glb,
    /// Mitsuba 3 XML scene (`.xml`).
    Mitsuba,
    /// pbrt-v4 scene fragment (`.pbrt`).
    Pbrt,
}

impl LightFormat {
    /// Every format, in the order messages list them.
    pub const ALL: [LightFormat; 5] = [
        LightFormat::Json,
        LightFormat::Gltf,
        LightFormat::Glb,
        LightFormat::Mitsuba,
        LightFormat::Pbrt,
    ];

    /// The accepted extensions, for messages.
    pub const EXPECTED: &'static str = ".json (iblkit light set), .gltf or .glb (glTF 2.0, \
         KHR_lights_punctual), .xml (Mitsuba 3) or .pbrt (pbrt-v4)";

    /// The file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            LightFormat::Json => "json",
            LightFormat::Gltf => "gltf",
            LightFormat::Glb => "glb",
            LightFormat::Mitsuba => "xml",
            LightFormat::Pbrt => "pbrt",
        }
    }

    /// Human-readable name.
    pub fn name(self) -> &'static str {
        match self {
            LightFormat::Json => "iblkit light set",
            LightFormat::Gltf => "glTF 2.0",
            LightFormat::Glb => "binary glTF 2.0",
            LightFormat::Mitsuba => "Mitsuba 3 XML",
            LightFormat::Pbrt => "pbrt-v4",
        }
    }

    /// The format of a path by its extension (case-insensitive), `None` when unknown.
    pub fn from_path(path: &Path) -> Option<LightFormat> {
        let ext = path.extension()?.to_str()?;
        Self::ALL
            .into_iter()
            .find(|f| f.extension().eq_ignore_ascii_case(ext))
    }
}

/// Why a light set could not be exported (an internal failure: the lights came from our own
/// extraction, so a bad value is a bug, not the user's input).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ExportError {
    /// A light holds a value no file format can carry.
    #[error("light {index}: {what}")]
    InvalidLight {
        /// Index of the light in the list.
        index: usize,
        /// What is wrong with it.
        what: String,
    },
    /// The lux scale is not a finite positive number.
    #[error("lux per unit must be finite and positive (got {0})")]
    LuxScale(f64),
    /// The GLB container would exceed its 4 GiB size field.
    #[error("the glTF JSON is too large for a GLB file ({0} bytes)")]
    TooLarge(usize),
}

impl ExportError {
    /// Always false: the lights came from our own extraction (see the type's doc).
    pub fn is_bad_input(&self) -> bool {
        false
    }

    /// Attaches the file name; export failures are internal (`is_bad_input` is false).
    pub fn with_path(self, path: &Path) -> IoError {
        IoError::write(path, std::io::Error::other(self.to_string()))
    }
}

/// What the writers put around the lights.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportOptions {
    /// Name of the frame preset the directions are written in (stated in every file).
    pub frame: String,
    /// One line saying where the lights come from (probe, method, count), for comments.
    pub source: String,
    /// glTF only: lux per unit of `Y(I)`, the Rec. 709 luminance of a light's irradiance
    /// (probe radiance unit x sr). 1 reads the probe's values as cd/m^2.
    pub lux_per_unit: f64,
}

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            frame: "gltf".to_string(),
            source: String::new(),
            lux_per_unit: 1.0,
        }
    }
}

impl ExportOptions {
    /// Options describing a light-set file: its frame, and its probe, method and light count as
    /// the source line.
    pub fn for_file(file: &LightsFile, lux_per_unit: f64) -> ExportOptions {
        ExportOptions {
            frame: file.frame.name().to_string(),
            source: format!(
                "{}, {}, {} lights",
                file.set.provenance.probe.as_ref().map_or_else(
                    || "probe not recorded".to_string(),
                    |p| format!("{} (sha256 {})", p.path, p.sha256)
                ),
                file.set.provenance.extraction.name(),
                file.set.lights.len()
            ),
            lux_per_unit,
        }
    }
}

/// A light checked for export: unit direction towards it, irradiance per channel.
struct Checked {
    towards: DVec3,
    irradiance: [f64; 3],
}

impl Checked {
    /// The direction the light travels.
    fn propagation(&self) -> DVec3 {
        -self.towards
    }
}

fn check(lights: &[Light]) -> Result<Vec<Checked>, ExportError> {
    lights
        .iter()
        .enumerate()
        .map(|(index, l)| {
            let bad = |what: String| ExportError::InvalidLight { index, what };
            let d = l.direction;
            if !d.is_finite() || d.length() < 1e-9 {
                return Err(bad(format!(
                    "direction {:?} is not a finite non-zero vector",
                    d.to_array()
                )));
            }
            let irradiance = l.irradiance.to_array();
            if irradiance.iter().any(|c| !c.is_finite() || *c < 0.0) {
                return Err(bad(format!(
                    "irradiance {irradiance:?} is not finite and non-negative"
                )));
            }
            // Unit records are kept bit for bit; others are normalised.
            let len = d.length();
            Ok(Checked {
                towards: if (len - 1.0).abs() < 1e-12 {
                    d
                } else {
                    d / len
                },
                irradiance,
            })
        })
        .collect()
}

/// The glTF node rotation `[x, y, z, w]` that turns local -Z (where a KHR directional light
/// shines) to the travel direction `p` (normalised here): the shortest arc
/// `q = normalise(a x p, 1 + a . p)` with `a = (0, 0, -1)`, i.e. `(p_y, -p_x, 0, 1 - p_z)`, and
/// half a turn about +Y, `(0, 1, 0, 0)`, for `p = +Z`.
///
/// Near `p = +Z` the term `1 - p_z` is computed as `rho^2 / (1 + p_z)` (`rho = hypot(p_x, p_y)`)
/// and the whole quaternion divided by `rho` first, so that directions within 1e-9 rad of the
/// singular case still rotate -Z onto `p` to f64 rounding (glam's `from_rotation_arc` snaps such
/// inputs to the identity or a half turn).
pub fn gltf_rotation(p: [f64; 3]) -> [f64; 4] {
    let b = DVec3::from_array(p).normalize();
    let q = if b.z > 0.0 {
        let rho = b.x.hypot(b.y);
        if rho == 0.0 {
            return [0.0, 1.0, 0.0, 0.0];
        }
        DQuat::from_xyzw(b.y / rho, -b.x / rho, 0.0, rho / (1.0 + b.z))
    } else {
        DQuat::from_xyzw(b.y, -b.x, 0.0, 1.0 - b.z)
    };
    q.normalize().to_array()
}

/// glTF `color` and `intensity` for an irradiance `I`: `color = I / max(I)`, `intensity =
/// lux_per_unit max(I)` (see the module documentation); `[1, 1, 1]` and 0 for a black light.
pub fn gltf_color_intensity(irradiance: [f64; 3], lux_per_unit: f64) -> ([f64; 3], f64) {
    let max = irradiance.into_iter().fold(0.0f64, f64::max);
    if max > 0.0 {
        (irradiance.map(|c| c / max), lux_per_unit * max)
    } else {
        ([1.0; 3], 0.0)
    }
}

/// Rec. 709 luminance of an RGB triple in f64.
fn luminance(c: [f64; 3]) -> f64 {
    c.iter()
        .zip(LUMINANCE_WEIGHTS)
        .map(|(v, w)| v * f64::from(w))
        .sum()
}

fn light_name(index: usize) -> String {
    format!("light_{index}")
}

/// The glTF 2.0 document as a JSON value.
fn gltf_value(lights: &[Light], options: &ExportOptions) -> Result<serde_json::Value, ExportError> {
    let s = options.lux_per_unit;
    if !(s.is_finite() && s > 0.0) {
        return Err(ExportError::LuxScale(s));
    }
    let checked = check(lights)?;
    let mut gltf_lights = Vec::with_capacity(checked.len());
    let mut nodes = Vec::with_capacity(checked.len());
    for (i, (c, record)) in checked.iter().zip(lights).enumerate() {
        let (color, intensity) = gltf_color_intensity(c.irradiance, s);
        gltf_lights.push(json!({
            "name": light_name(i),
            "type": "directional",
            "color": color,
            "intensity": intensity,
            "extras": {
                "irradiance": c.irradiance,
                "illuminance_lux": s * luminance(c.irradiance),
                "solid_angle": record.solid_angle_sr,
                "shadow_solid_angle": record.shadow_solid_angle_sr(),
                "shadow_core_fraction": record.core_fraction.unwrap_or(1.0),
            },
        }));
        nodes.push(json!({
            "name": light_name(i),
            "rotation": gltf_rotation(c.propagation().to_array()),
            "extensions": { "KHR_lights_punctual": { "light": i } },
        }));
    }
    let asset = json!({
        "version": "2.0",
        "generator": GENERATOR,
        "extras": {
            "frame": options.frame,
            "source": options.source,
            "lux_per_unit": s,
        },
    });
    if nodes.is_empty() {
        // glTF requires non-empty `nodes` and scene node lists when present: leave them out.
        return Ok(json!({
            "asset": asset,
            "scenes": [{ "name": "iblkit lights" }],
            "scene": 0,
        }));
    }
    let scene_nodes: Vec<usize> = (0..nodes.len()).collect();
    Ok(json!({
        "asset": asset,
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": { "KHR_lights_punctual": { "lights": gltf_lights } },
        "nodes": nodes,
        "scenes": [{ "name": "iblkit lights", "nodes": scene_nodes }],
        "scene": 0,
    }))
}

fn json_text(value: &serde_json::Value, pretty: bool) -> String {
    // Serialising a `Value` cannot fail (its map keys are strings).
    let text = if pretty {
        serde_json::to_string_pretty(value)
    } else {
        serde_json::to_string(value)
    };
    text.unwrap_or_default()
}

/// The lights as a glTF 2.0 JSON document (`.gltf`, pretty-printed): one directional
/// `KHR_lights_punctual` light per record, each on its own node, all nodes in scene 0.
pub fn gltf_json(lights: &[Light], options: &ExportOptions) -> Result<String, ExportError> {
    Ok(json_text(&gltf_value(lights, options)?, true))
}

/// GLB chunk type of the JSON chunk (`"JSON"` as a little-endian u32).
const GLB_JSON_CHUNK: u32 = 0x4E4F_534A;

/// The lights as binary glTF (`.glb`): the 12-byte header (`glTF`, version 2, total length),
/// then one JSON chunk padded with spaces to a multiple of 4 bytes; no binary chunk.
pub fn glb(lights: &[Light], options: &ExportOptions) -> Result<Vec<u8>, ExportError> {
    let mut chunk = json_text(&gltf_value(lights, options)?, false).into_bytes();
    chunk.resize(chunk.len().next_multiple_of(4), b' ');
    let total = 12 + 8 + chunk.len();
    let (Ok(total32), Ok(chunk32)) = (u32::try_from(total), u32::try_from(chunk.len())) else {
        return Err(ExportError::TooLarge(chunk.len()));
    };
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&total32.to_le_bytes());
    out.extend_from_slice(&chunk32.to_le_bytes());
    out.extend_from_slice(&GLB_JSON_CHUNK.to_le_bytes());
    out.extend_from_slice(&chunk);
    Ok(out)
}

/// A number for the text formats: shortest round-trip decimal, in exponent form outside
/// `[1e-4, 1e9)` so that neither tiny nor huge values spell out hundreds of digits.
fn num(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || (1e-4..1e9).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Text safe inside an XML comment: one line, no `--`, not ending in `-`.
fn xml_comment(text: &str) -> String {
    let mut s: String = text
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    while s.contains("--") {
        s = s.replace("--", "- -");
    }
    if s.ends_with('-') {
        s.push(' ');
    }
    s
}

/// Text safe in a `#` comment: one line.
fn line_comment(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// The lights as a Mitsuba 3 scene: `<scene version="3.0.0">` with one `directional` emitter per
/// light (`direction` = travel direction, `irradiance` = `I` in the probe's unit); a comment
/// states the frame. Load it as is or `<include>` it from another scene.
pub fn mitsuba_xml(lights: &[Light], options: &ExportOptions) -> Result<String, ExportError> {
    let checked = check(lights)?;
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n");
    // Writing to a String cannot fail.
    let _ = writeln!(
        s,
        "<!-- {} directional lights written by {GENERATOR}\n     from {}.\n     \
         Frame: {} (the vectors are in that preset's axes; iblkit's own frame, gltf, is\n     \
         right-handed, +Y up, -Z forward). direction = the way the light travels (minus the\n     \
         direction towards it); irradiance = I = L A, the irradiance on a surface facing the\n     \
         light, linear Rec. 709 RGB in the probe's radiance unit. -->",
        checked.len(),
        xml_comment(&options.source),
        xml_comment(&options.frame),
    );
    s.push_str("<scene version=\"3.0.0\">\n");
    for (i, c) in checked.iter().enumerate() {
        let [px, py, pz] = c.propagation().to_array();
        let [r, g, b] = c.irradiance;
        let _ = writeln!(
            s,
            "    <emitter type=\"directional\" id=\"{}\">\n        \
             <vector name=\"direction\" value=\"{}, {}, {}\"/>\n        \
             <rgb name=\"irradiance\" value=\"{}, {}, {}\"/>\n    </emitter>",
            light_name(i),
            num(px),
            num(py),
            num(pz),
            num(r),
            num(g),
            num(b)
        );
    }
    s.push_str("</scene>\n");
    Ok(s)
}

/// The lights as a pbrt-v4 scene fragment: one `LightSource "distant"` per light (`from` = the
/// direction towards the light, `to` = the origin, `"rgb L"` = `I`, `scale` 1), for `Include`
/// after `WorldBegin`; comments state the frame and the units.
pub fn pbrt_scene(lights: &[Light], options: &ExportOptions) -> Result<String, ExportError> {
    let checked = check(lights)?;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# {} directional lights written by {GENERATOR}\n# from {}.\n\
         # Frame: {} (the vectors are in that preset's axes, written as is). iblkit's own frame,\n\
         # gltf, is right-handed, +Y up, -Z forward; pbrt scenes are often set up left-handed, so\n\
         # pick the `ibl lights --frame` preset that matches the scene you include this in.\n\
         # Each light travels from \"from\" (the direction towards it) to \"to\" (the origin).\n\
         # \"rgb L\" is I = L A, the irradiance on a surface facing the light (linear Rec. 709 RGB,\n\
         # the probe's radiance unit): pbrt-v4 divides an RGB illuminant spectrum by the\n\
         # photometric value of its colour space's standard illuminant (white 1 = 1 nit), so the\n\
         # irradiance delivered is L x scale.",
        checked.len(),
        line_comment(&options.source),
        line_comment(&options.frame),
    );
    for c in &checked {
        let [x, y, z] = c.towards.to_array();
        let [r, g, b] = c.irradiance;
        let _ = writeln!(
            s,
            "LightSource \"distant\" \"point3 from\" [{} {} {}] \"point3 to\" [0 0 0] \
             \"rgb L\" [{} {} {}] \"float scale\" [1]",
            num(x),
            num(y),
            num(z),
            num(r),
            num(g),
            num(b)
        );
    }
    Ok(s)
}

/// Encodes a light-set file in `format`. `.json` is the light-set file itself, byte for byte what
/// [`crate::light_file::write_lights_file`] writes; the other formats take its lights, frame and
/// source (see [`ExportOptions::for_file`]).
pub fn encode_light_file(
    format: LightFormat,
    file: &LightsFile,
    lux_per_unit: f64,
) -> Result<Vec<u8>, ExportError> {
    let options = ExportOptions::for_file(file, lux_per_unit);
    Ok(match format {
        LightFormat::Json => file.to_json().into_bytes(),
        LightFormat::Gltf => gltf_json(&file.set.lights, &options)?.into_bytes(),
        LightFormat::Glb => glb(&file.set.lights, &options)?,
        LightFormat::Mitsuba => mitsuba_xml(&file.set.lights, &options)?.into_bytes(),
        LightFormat::Pbrt => pbrt_scene(&file.set.lights, &options)?.into_bytes(),
    })
}

/// Writes a light-set file in the format its extension names ([`LightFormat::from_path`]),
/// atomically. An unknown extension is [`IoError::Unsupported`] (the user's input at fault).
pub fn write_light_file(path: &Path, file: &LightsFile, lux_per_unit: f64) -> Result<(), IoError> {
    let format = LightFormat::from_path(path).ok_or_else(|| IoError::Unsupported {
        path: path.to_path_buf(),
        what: format!(
            "light-set file extension (expected {})",
            LightFormat::EXPECTED
        ),
    })?;
    let bytes = encode_light_file(format, file, lux_per_unit).map_err(|e| e.with_path(path))?;
    crate::write_atomically(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ibl_core::rgb::Rgb64;
    use ibl_core::{FramePreset, Rgb};
    use ibl_light::{Extraction, LightSet, ProbeRef, Provenance};

    fn record(direction: [f64; 3], irradiance: [f64; 3]) -> Light {
        Light {
            direction: DVec3::from_array(direction),
            radiance: Rgb::splat(1.0),
            solid_angle_sr: 0.01,
            irradiance: Rgb64::from_array(irradiance),
            region: None,
            spread_sr: None,
            core_fraction: None,
            side: None,
        }
    }

    /// Directions covering the degenerate cases (towards +-Z, the poles) and generic ones.
    fn sample_lights() -> Vec<Light> {
        let dirs = [
            [0.0, 0.0, -1.0],
            [0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.3, 0.8, -0.52],
            [-0.6, 0.1, 0.79],
            [1e-9, 0.0, 1.0],
        ];
        dirs.iter()
            .enumerate()
            .map(|(i, d)| {
                let v = DVec3::from_array(*d).normalize().to_array();
                let k = i as f64;
                record(v, [0.5 + k, 2.0 + 0.1 * k, 0.25 * k])
            })
            .collect()
    }

    fn rotate(q: [f64; 4], v: DVec3) -> DVec3 {
        DQuat::from_array(q) * v
    }

    fn f(v: &serde_json::Value) -> f64 {
        v.as_f64().unwrap_or(f64::NAN)
    }

    fn arr<const N: usize>(v: &serde_json::Value) -> [f64; N] {
        std::array::from_fn(|i| f(&v[i]))
    }

    fn check_gltf(doc: &serde_json::Value, lights: &[Light], lux: f64) {
        assert_eq!(doc["asset"]["version"], "2.0");
        assert!(
            doc["asset"]["generator"]
                .as_str()
                .is_some_and(|g| g.starts_with("iblkit"))
        );
        assert_eq!(doc["extensionsUsed"][0], "KHR_lights_punctual");
        let gl = doc["extensions"]["KHR_lights_punctual"]["lights"]
            .as_array()
            .cloned()
            .unwrap_or_default();
        let nodes = doc["nodes"].as_array().cloned().unwrap_or_default();
        assert_eq!((gl.len(), nodes.len()), (lights.len(), lights.len()));
        assert_eq!(
            doc["scenes"][0]["nodes"].as_array().map(Vec::len),
            Some(lights.len())
        );
        for (i, l) in lights.iter().enumerate() {
            let node = &nodes[i];
            let light = &gl[node["extensions"]["KHR_lights_punctual"]["light"]
                .as_u64()
                .unwrap_or(u64::MAX) as usize];
            assert_eq!(light["type"], "directional");
            let q: [f64; 4] = arr(&node["rotation"]);
            let len = q.iter().map(|c| c * c).sum::<f64>().sqrt();
            assert!((len - 1.0).abs() < 1e-12, "{q:?}");
            let shines = rotate(q, DVec3::NEG_Z);
            let want = -l.direction;
            assert!((shines - want).length() < 1e-12, "{i}: {shines} vs {want}");
            let color: [f64; 3] = arr(&light["color"]);
            assert!(color.iter().all(|c| (0.0..=1.0).contains(c)), "{color:?}");
            let intensity = f(&light["intensity"]);
            for (c, irradiance) in color.iter().zip(l.irradiance.to_array()) {
                let got = c * intensity;
                let want = lux * irradiance;
                assert!(
                    (got - want).abs() <= 1e-12 * want.max(1.0),
                    "{i}: {got} {want}"
                );
            }
            let y = luminance(color.map(|c| c * intensity));
            assert!((y - lux * luminance(l.irradiance.to_array())).abs() < 1e-9);
            assert!((f(&light["extras"]["illuminance_lux"]) - y).abs() < 1e-9);
            assert_eq!(f(&light["extras"]["shadow_solid_angle"]), 0.01);
            assert_eq!(f(&light["extras"]["shadow_core_fraction"]), 1.0);
        }
    }

    #[test]
    fn gltf_nodes_shine_along_minus_the_direction_and_keep_the_irradiance() {
        let lights = sample_lights();
        let options = ExportOptions {
            lux_per_unit: 3.5,
            ..Default::default()
        };
        let text = gltf_json(&lights, &options).expect("exports");
        let doc: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
        check_gltf(&doc, &lights, 3.5);
    }

    #[test]
    fn glb_has_the_header_and_a_padded_json_chunk() {
        let lights = sample_lights();
        let bytes = glb(&lights, &ExportOptions::default()).expect("exports");
        assert_eq!(&bytes[0..4], b"glTF");
        let u32_at =
            |o: usize| u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
        assert_eq!(u32_at(4), 2);
        assert_eq!(u32_at(8) as usize, bytes.len());
        let chunk_len = u32_at(12) as usize;
        assert_eq!(chunk_len % 4, 0);
        assert_eq!(u32_at(16), GLB_JSON_CHUNK);
        assert_eq!(&bytes[16..20], b"JSON");
        assert_eq!(20 + chunk_len, bytes.len());
        let doc: serde_json::Value =
            serde_json::from_slice(&bytes[20..]).expect("JSON chunk parses (space padding)");
        check_gltf(&doc, &lights, 1.0);
    }

    #[test]
    fn color_is_normalised_to_its_largest_component() {
        let (c, e) = gltf_color_intensity([2.0, 4.0, 1.0], 10.0);
        assert_eq!(c, [0.5, 1.0, 0.25]);
        assert_eq!(e, 40.0);
        assert_eq!(gltf_color_intensity([0.0; 3], 1.0), ([1.0; 3], 0.0));
    }

    #[test]
    fn rotation_handles_the_antiparallel_case() {
        for p in [
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [0.0, 1.0, 0.0],
            [1e-12, -3e-13, 1.0],
            [-1e-200, 0.0, 1.0],
            [1e-9, 1e-9, -1.0],
        ] {
            let p = DVec3::from_array(p).normalize().to_array();
            let q = gltf_rotation(p);
            let got = rotate(q, DVec3::NEG_Z);
            assert!(
                (got - DVec3::from_array(p)).length() < 1e-12,
                "{p:?}: {got}"
            );
        }
    }

    /// Numbers inside `value="..."` after `name="<name>"`, in order of the emitters.
    fn mitsuba_values(xml: &str, name: &str) -> Vec<[f64; 3]> {
        let key = format!("name=\"{name}\" value=\"");
        xml.match_indices(&key)
            .map(|(at, _)| {
                let rest = &xml[at + key.len()..];
                let end = rest.find('"').unwrap_or(0);
                let v: Vec<f64> = rest[..end]
                    .split(',')
                    .map(|t| t.trim().parse().unwrap_or(f64::NAN))
                    .collect();
                [v[0], v[1], v[2]]
            })
            .collect()
    }

    #[test]
    fn mitsuba_emitters_travel_away_from_the_light_with_irradiance_i() {
        let lights = sample_lights();
        let options = ExportOptions {
            frame: "paper".into(),
            source: "probe--x.exr, median-cut, 8 lights-".into(),
            ..Default::default()
        };
        let xml = mitsuba_xml(&lights, &options).expect("exports");
        assert!(xml.contains("<scene version=\"3.0.0\">") && xml.trim_end().ends_with("</scene>"));
        assert_eq!(
            xml.matches("<emitter type=\"directional\"").count(),
            lights.len()
        );
        assert!(xml.contains("Frame: paper"));
        // The comment must stay a well-formed XML comment.
        let comment = &xml[xml.find("<!--").unwrap_or(0) + 4..xml.find("-->").unwrap_or(0)];
        assert!(
            !comment.contains("--") && !comment.ends_with('-'),
            "{comment}"
        );
        let dirs = mitsuba_values(&xml, "direction");
        let irr = mitsuba_values(&xml, "irradiance");
        assert_eq!((dirs.len(), irr.len()), (lights.len(), lights.len()));
        for (i, l) in lights.iter().enumerate() {
            for c in 0..3 {
                assert_eq!(dirs[i][c], -l.direction.to_array()[c]);
                assert_eq!(irr[i][c], l.irradiance.to_array()[c]);
            }
        }
    }

    #[test]
    fn pbrt_lights_go_from_the_light_direction_to_the_origin() {
        let lights = sample_lights();
        let text = pbrt_scene(&lights, &ExportOptions::default()).expect("exports");
        let light_lines: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
        assert_eq!(light_lines.len(), lights.len());
        assert!(text.contains("Frame: gltf") && text.contains("left-handed"));
        for (line, l) in light_lines.iter().zip(&lights) {
            assert!(line.starts_with("LightSource \"distant\""), "{line}");
            let groups: Vec<Vec<f64>> = line
                .split('[')
                .skip(1)
                .map(|g| {
                    g.split(']')
                        .next()
                        .unwrap_or("")
                        .split_whitespace()
                        .map(|t| t.parse().unwrap_or(f64::NAN))
                        .collect()
                })
                .collect();
            assert_eq!(groups.len(), 4, "{line}");
            assert_eq!(groups[0], l.direction.to_array().to_vec());
            assert_eq!(groups[1], vec![0.0; 3]);
            assert_eq!(groups[2], l.irradiance.to_array().to_vec());
            assert_eq!(groups[3], vec![1.0]);
        }
    }

    #[test]
    fn numbers_round_trip_in_text() {
        for x in [
            0.0,
            -0.0,
            1.0,
            0.1,
            1e-300,
            5e-5,
            123456.789,
            1e12,
            -3.25e-7,
            f64::MAX,
        ] {
            let back: f64 = num(x).parse().unwrap_or(f64::NAN);
            assert_eq!(back, x, "{}", num(x));
        }
        assert_eq!(num(1e-300), "1e-300");
    }

    #[test]
    fn empty_lists_give_valid_files() {
        let o = ExportOptions::default();
        let doc: serde_json::Value =
            serde_json::from_str(&gltf_json(&[], &o).expect("exports")).expect("JSON");
        assert_eq!(doc["asset"]["version"], "2.0");
        assert!(doc.get("nodes").is_none() && doc.get("extensionsUsed").is_none());
        assert!(glb(&[], &o).expect("exports").len().is_multiple_of(4));
        let xml = mitsuba_xml(&[], &o).expect("exports");
        assert!(xml.contains("<scene version=\"3.0.0\">\n</scene>"));
        let pbrt = pbrt_scene(&[], &o).expect("exports");
        assert!(pbrt.lines().all(|l| l.starts_with('#')));
    }

    #[test]
    fn invalid_values_are_refused() {
        let o = ExportOptions::default();
        let cases = [
            record([f64::NAN, 0.0, 1.0], [1.0; 3]),
            record([0.0; 3], [1.0; 3]),
            record([0.0, 1.0, 0.0], [1.0, f64::NAN, 1.0]),
            record([0.0, 1.0, 0.0], [1.0, f64::INFINITY, 1.0]),
            record([0.0, 1.0, 0.0], [1.0, -1.0, 1.0]),
        ];
        for bad in cases {
            let lights = vec![record([0.0, 1.0, 0.0], [1.0; 3]), bad];
            for result in [
                gltf_json(&lights, &o).map(String::into_bytes),
                glb(&lights, &o),
                mitsuba_xml(&lights, &o).map(String::into_bytes),
                pbrt_scene(&lights, &o).map(String::into_bytes),
            ] {
                assert!(
                    matches!(result, Err(ExportError::InvalidLight { index: 1, .. })),
                    "{result:?}"
                );
            }
        }
        for lux in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let o = ExportOptions {
                lux_per_unit: lux,
                ..Default::default()
            };
            assert!(matches!(gltf_json(&[], &o), Err(ExportError::LuxScale(_))));
        }
    }

    #[test]
    fn formats_come_from_the_extension() {
        for f in LightFormat::ALL {
            let p = format!("a/b.{}", f.extension().to_uppercase());
            assert_eq!(LightFormat::from_path(Path::new(&p)), Some(f));
        }
        assert_eq!(LightFormat::from_path(Path::new("x.txt")), None);
        assert_eq!(LightFormat::from_path(Path::new("json")), None);
    }

    #[test]
    fn json_export_is_the_light_set_file() {
        let file = LightsFile {
            set: LightSet {
                provenance: Provenance {
                    extraction: Extraction::MedianCut { splits: 3 },
                    probe: Some(ProbeRef {
                        path: "p.exr".into(),
                        width: 4,
                        height: 2,
                        sha256: "0".repeat(64),
                    }),
                },
                lights: sample_lights(),
            },
            frame: FramePreset::Gltf,
            ambient: None,
        };
        let dir = tempfile::tempdir().expect("tempdir");
        let a = dir.path().join("a.json");
        write_light_file(&a, &file, 1.0).expect("writes");
        let back = crate::light_file::read_lights_file(&a).expect("reads");
        // serde_json's default float parser may differ from the written value in the last bit.
        assert_eq!(back.set.provenance, file.set.provenance);
        assert_eq!(back.set.lights.len(), file.set.lights.len());
        for (x, y) in back.set.lights.iter().zip(&file.set.lights) {
            // One f64 ulp of a unit component is 1.1e-16; 1e-15 allows a few.
            assert!((x.direction - y.direction).abs().max_element() < 1e-15);
            assert_eq!(x.irradiance, y.irradiance);
        }
        let b = dir.path().join("b.json");
        crate::light_file::write_lights_file(&b, &file).expect("writes");
        assert_eq!(std::fs::read(&a).ok(), std::fs::read(&b).ok());
        let bad = write_light_file(&dir.path().join("c.txt"), &file, 1.0);
        assert!(bad.is_err_and(|e| e.is_bad_input() && e.to_string().contains(".gltf")));
    }
}

//! The JSON light-set file, CONVENTIONS section 7: `"format": "iblkit.lights/1"`, the source probe
//! (path, size, sha256), the frame the directions are written in, the method with its parameters,
//! and per light `direction`, `radiance`, `solid_angle` (sr), `irradiance` (`I = L A`) and optional
//! region bounds in probe pixels and `spread` (sr, the solid angle soft shadows are sized by); a
//! hybrid set adds its SH ambient.
//!
//! The lights are `ibl_light` types as they are (their serde form is the per-light record); the
//! method is [`ibl_light::Extraction`], written as its name and its parameters as named numbers
//! (whole values as JSON integers). Readers in other languages need nothing but a JSON parser.
//!
//! [`read_light_set`] is what a renderer wants: the lights checked (unit directions, finite
//! non-negative irradiance and solid angle) and turned from the file's frame into iblkit's.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;

use ibl_core::FramePreset;
use ibl_light::{Extraction, Light, LightSet, ProbeRef, Provenance};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::IoError;

/// Value of the `format` field.
pub const LIGHTS_FORMAT: &str = "iblkit.lights/1";

/// Largest light-set file read, bytes (a million lights).
pub const MAX_LIGHTS_FILE_BYTES: u64 = 256 << 20;

/// The SH ambient of a hybrid light set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AmbientRecord {
    /// The basis (see [`crate::sh_file::SH_CONVENTION`]).
    pub convention: String,
    /// Number of bands (`coefficients` has `bands^2` entries).
    pub bands: usize,
    /// Radiance coefficients `[l*l + l + m]`, linear RGB, in the file's frame.
    pub radiance: Vec<[f64; 3]>,
}

/// A whole light-set file.
#[derive(Clone, Debug, PartialEq)]
pub struct LightsFile {
    /// The lights with their provenance; directions in `frame`'s axes.
    pub set: LightSet,
    /// Frame preset of the directions (`gltf` = iblkit's world frame).
    pub frame: FramePreset,
    /// Hybrid lighting: the SH ambient that carries the rest of the probe (radiance
    /// coefficients in `frame`; the lights' irradiance plus the ambient's gives the probe's).
    pub ambient: Option<AmbientRecord>,
}

/// The file as written: the fields in the schema's order.
#[derive(Serialize)]
struct Written<'a> {
    format: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    probe: Option<&'a ProbeRef>,
    frame: &'static str,
    method: WrittenMethod<'a>,
    lights: &'a [Light],
    #[serde(skip_serializing_if = "Option::is_none")]
    ambient: Option<&'a AmbientRecord>,
}

#[derive(Serialize)]
struct WrittenMethod<'a> {
    name: &'a str,
    parameters: serde_json::Value,
}

/// The file as read: the fields the schema allows (unknown ones are ignored, as a newer writer
/// may add some).
#[derive(Deserialize)]
struct ReadFile {
    format: String,
    #[serde(default)]
    probe: Option<ProbeRef>,
    frame: String,
    method: ReadMethod,
    lights: Vec<Light>,
    #[serde(default)]
    ambient: Option<AmbientRecord>,
}

#[derive(Deserialize)]
struct ReadMethod {
    name: String,
    #[serde(default)]
    parameters: serde_json::Map<String, serde_json::Value>,
}

/// A method's parameters as JSON numbers, whole values as integers (`"splits": 4`); non-finite
/// values become `null`.
pub fn parameters_json(parameters: &BTreeMap<String, f64>) -> serde_json::Value {
    const EXACT: f64 = 9_007_199_254_740_992.0; // 2^53
    serde_json::Value::Object(
        parameters
            .iter()
            .map(|(k, &v)| {
                let value = if v.fract() == 0.0 && v.abs() <= EXACT {
                    serde_json::json!(v as i64)
                } else {
                    serde_json::json!(v)
                };
                (k.clone(), value)
            })
            .collect(),
    )
}

impl LightsFile {
    /// The file as pretty JSON.
    pub fn to_json(&self) -> String {
        let written = Written {
            format: LIGHTS_FORMAT,
            probe: self.set.provenance.probe.as_ref(),
            frame: self.frame.name(),
            method: WrittenMethod {
                name: self.set.provenance.extraction.name(),
                parameters: parameters_json(&self.set.provenance.extraction.parameters()),
            },
            lights: &self.set.lights,
            ambient: self.ambient.as_ref(),
        };
        // Serialising plain data to a string cannot fail.
        serde_json::to_string_pretty(&written).unwrap_or_default()
    }

    /// Parses a light-set file's bytes; `path` names it in errors.
    pub fn from_json(path: &Path, bytes: &[u8]) -> Result<LightsFile, IoError> {
        let invalid = |reason: String| IoError::Invalid {
            path: path.to_path_buf(),
            reason,
        };
        let read: ReadFile = serde_json::from_slice(bytes)
            .map_err(|e| invalid(format!("not an iblkit light-set file: {e}")))?;
        if read.format != LIGHTS_FORMAT {
            return Err(IoError::Unsupported {
                path: path.to_path_buf(),
                what: format!(
                    "light-set format `{}` (expected `{LIGHTS_FORMAT}`)",
                    read.format
                ),
            });
        }
        let frame = FramePreset::from_name(&read.frame)
            .ok_or_else(|| invalid(format!("unknown frame '{}'", read.frame)))?;
        let numbers: BTreeMap<String, f64> = read
            .method
            .parameters
            .iter()
            .filter_map(|(k, v)| match v {
                serde_json::Value::Number(n) => n.as_f64().map(|x| (k.clone(), x)),
                serde_json::Value::Null => Some((k.clone(), f64::NAN)),
                _ => None,
            })
            .collect();
        let extraction = Extraction::from_parameters(&read.method.name, &numbers)
            .map_err(|e| invalid(e.to_string()))?;
        Ok(LightsFile {
            set: LightSet {
                provenance: Provenance {
                    extraction,
                    probe: read.probe,
                },
                lights: read.lights,
            },
            frame,
            ambient: read.ambient,
        })
    }
}

/// SHA-256 of bytes, lower-case hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// SHA-256 of a file, lower-case hex. Streams the file (O(1) memory).
pub fn sha256_file(path: &Path) -> Result<String, IoError> {
    let io = |source| IoError::Io {
        path: path.to_path_buf(),
        source,
    };
    // Streamed, so no size bound; but a device or a FIFO would never end: regular files only.
    crate::check_regular(path, &std::fs::metadata(path).map_err(io)?)?;
    let mut file = std::fs::File::open(path).map_err(io)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = file.read(&mut buf).map_err(io)?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
    }
    Ok(hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect())
}

/// Writes a light-set file as pretty JSON, atomically.
pub fn write_lights_file(path: &Path, file: &LightsFile) -> Result<(), IoError> {
    crate::write_atomically(path, file.to_json().as_bytes())
}

/// Reads a light-set file, checking its `format`, `frame` and method parameters. At most
/// [`MAX_LIGHTS_FILE_BYTES`] are read.
pub fn read_lights_file(path: &Path) -> Result<LightsFile, IoError> {
    let bytes = crate::read_bounded(path, MAX_LIGHTS_FILE_BYTES)?;
    LightsFile::from_json(path, &bytes)
}

/// Reads a light-set file as a light set in iblkit's world frame: every light must have a unit
/// direction (within 1e-3, renormalised) and finite, non-negative irradiance and solid angle.
/// The ambient of a hybrid file is not part of a light set and is not returned.
pub fn read_light_set(path: &Path) -> Result<LightSet, IoError> {
    let bytes = crate::read_bounded(path, MAX_LIGHTS_FILE_BYTES)?;
    light_set_from_json(path, &bytes)
}

/// How far (as `y`, probe frame) a light with a [`ibl_light::Light::side`] may lie on the other
/// side of the horizon: the file's rounding of a light on the horizon (directions are written
/// with 17 significant digits, so this is generous).
const SIDE_TOLERANCE: f64 = 1e-9;

/// [`read_light_set`] on a file's bytes (`path` names it in errors).
pub fn light_set_from_json(path: &Path, bytes: &[u8]) -> Result<LightSet, IoError> {
    let file = LightsFile::from_json(path, bytes)?;
    let world_from_preset = file.frame.world_from_preset().as_dmat3();
    let mut set = file.set.transformed(world_from_preset);
    for (i, l) in set.lights.iter_mut().enumerate() {
        let d = l.direction;
        let irradiance = l.irradiance.to_array();
        let ok = d.is_finite()
            && (d.length() - 1.0).abs() < 1e-3
            && irradiance.iter().all(|c| c.is_finite() && *c >= 0.0)
            && l.solid_angle_sr.is_finite()
            && l.solid_angle_sr >= 0.0
            && l.spread_sr
                .is_none_or(|a| a.is_finite() && (0.0..=4.0 * std::f64::consts::PI).contains(&a))
            && l.core_fraction.is_none_or(|f| (0.0..=1.0).contains(&f))
            && l.side
                .is_none_or(|side| side.up().dot(l.direction) >= -SIDE_TOLERANCE);
        if !ok {
            return Err(IoError::Invalid {
                path: path.to_path_buf(),
                reason: format!(
                    "light {i}: direction must be a unit vector, irradiance and solid angle \
                     finite and non-negative, spread (if given) from 0 to 4 pi sr and \
                     core_fraction (if given) from 0 to 1, and a light with a side (\"above\" \
                     or \"below\") on that side of the horizon or on it"
                ),
            });
        }
        l.direction = d.normalize();
    }
    Ok(set)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ibl_core::Rgb;
    use ibl_core::glam::DVec3;
    use ibl_core::rgb::Rgb64;
    use ibl_light::{FitReport, HorizonSide, PixelRegion};

    fn file(frame: FramePreset) -> LightsFile {
        LightsFile {
            set: LightSet {
                provenance: Provenance {
                    extraction: Extraction::IrradianceOptimization(FitReport {
                        iterations: 3,
                        total_iterations: 9,
                        converged: true,
                        initial_cost: 2.0,
                        final_cost: 0.25,
                        fit_rms_err_pct: 1.5,
                        fit_mean_abs_err_pct: 1.0,
                        fit_normals: 6144,
                        lights_above_horizon: Some(7),
                    }),
                    probe: Some(ProbeRef {
                        path: "p.exr".into(),
                        width: 8,
                        height: 4,
                        sha256: "0".repeat(64),
                    }),
                },
                lights: vec![Light {
                    direction: DVec3::new(0.6, 0.8, 0.0),
                    radiance: Rgb::new(1.0, 2.0, 3.0),
                    solid_angle_sr: 0.5,
                    irradiance: Rgb64::new(0.5, 1.0, 1.5),
                    region: Some(PixelRegion {
                        x0: 0,
                        y0: 1,
                        x1: 2,
                        y1: 3,
                    }),
                    spread_sr: Some(0.25),
                    core_fraction: Some(0.75),
                    side: None,
                }],
            },
            frame,
            ambient: None,
        }
    }

    #[test]
    fn the_schema_is_written_in_order_with_integer_parameters() {
        let text = file(FramePreset::Gltf).to_json();
        let keys: Vec<usize> = [
            "\"format\"",
            "\"probe\"",
            "\"frame\"",
            "\"method\"",
            "\"lights\"",
        ]
        .iter()
        .map(|k| text.find(k).expect(k))
        .collect();
        assert!(keys.windows(2).all(|w| w[0] < w[1]), "{text}");
        assert!(text.contains("\"converged\": 1,") && text.contains("\"iterations\": 3,"));
        assert!(text.contains("\"solid_angle\": 0.5") && text.contains("\"x1\": 2"));
        assert!(text.contains("\"spread\": 0.25"), "{text}");
        assert!(text.contains("\"core_fraction\": 0.75"), "{text}");
        assert!(!text.contains("ambient"));
    }

    #[test]
    fn files_round_trip() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("l.json");
        let want = file(FramePreset::Blender);
        write_lights_file(&path, &want).expect("writes");
        // Every value is exact in binary and short, so serde_json reads it back bit for bit.
        assert_eq!(read_lights_file(&path).expect("reads"), want);
    }

    #[test]
    fn light_sets_come_back_in_the_world_frame_checked() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("l.json");
        write_lights_file(&path, &file(FramePreset::Blender)).expect("writes");
        let set = read_light_set(&path).expect("reads");
        // Blender's axes: ours = (x, z, -y); (0.6, 0.8, 0) -> (0.6, 0, -0.8), exact.
        assert!((set.lights[0].direction - DVec3::new(0.6, 0.0, -0.8)).length() < 1e-15);
        let mut bad = file(FramePreset::Gltf);
        bad.set.lights[0].direction = DVec3::new(2.0, 0.0, 0.0);
        write_lights_file(&path, &bad).expect("writes");
        let e = read_light_set(&path).unwrap_err();
        assert!(e.is_bad_input() && e.to_string().contains("light 0"), "{e}");
        let mut bad = file(FramePreset::Gltf);
        bad.set.lights[0].core_fraction = Some(1.5);
        write_lights_file(&path, &bad).expect("writes");
        let e = read_light_set(&path).unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains("core_fraction"),
            "{e}"
        );
        std::fs::write(&path, b"{\"format\": \"other/1\"}").expect("writes");
        assert!(read_lights_file(&path).is_err_and(|e| e.is_bad_input()));
    }

    #[test]
    fn a_lights_side_of_the_horizon_round_trips_and_must_hold() {
        // Blender's file axes: the file's (0.6, 0.8, 0) is ours (0.6, 0, -0.8), on the horizon;
        // "above" and "below" name our horizon whatever the preset.
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("l.json");
        for side in [HorizonSide::Above, HorizonSide::Below] {
            let mut want = file(FramePreset::Blender);
            want.set.lights[0].side = Some(side);
            write_lights_file(&path, &want).expect("writes");
            let text = std::fs::read_to_string(&path).expect("reads");
            let name = if side == HorizonSide::Above {
                "above"
            } else {
                "below"
            };
            assert!(text.contains(&format!("\"side\": \"{name}\"")), "{text}");
            assert_eq!(read_lights_file(&path).expect("reads"), want);
            assert_eq!(
                read_light_set(&path).expect("reads").lights[0].side,
                Some(side)
            );
        }
        // A light said to stand for the light above the horizon that lies below it.
        let mut bad = file(FramePreset::Gltf);
        bad.set.lights[0].side = Some(HorizonSide::Above);
        bad.set.lights[0].direction = DVec3::new(0.6, -0.8, 0.0);
        write_lights_file(&path, &bad).expect("writes");
        let e = read_light_set(&path).unwrap_err();
        assert!(e.is_bad_input() && e.to_string().contains("side"), "{e}");
        std::fs::write(&path, text_with_side("sideways")).expect("writes");
        assert!(read_light_set(&path).is_err_and(|e| e.is_bad_input()));
    }

    /// A one-light file whose light's side is `side`.
    fn text_with_side(side: &str) -> String {
        file(FramePreset::Gltf).to_json().replace(
            "\"core_fraction\": 0.75",
            &format!("\"core_fraction\": 0.75, \"side\": \"{side}\""),
        )
    }
}

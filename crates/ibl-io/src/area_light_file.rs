//! The JSON area-light file, CONVENTIONS section 7 (`"format": "iblkit.area-lights/1"`): a room's
//! important light patches (Grosch 2005, section 3.3), as `ibl room lights` writes them and
//! `ibl render --lights` reads them.
//!
//! Fields: `probe` (path, size, sha256 of the probe the room was estimated from), `room` (the
//! room file, as given), `frame` (always `room`: the room's world frame, +Y up, metres, the
//! floor at `y = 0`), `world_from_probe` (the calibrated rotation from the probe's frame to the
//! room's, 3 rows of 3), `probe_position` (the probe's centre in the room, metres),
//! `important_flux_fraction` (the share of the room's luminous flux the lights carry) and per
//! light `patch` (the room's patch index), `group`, `position` (centroid, metres), `normal`
//! (unit, the side it radiates to), `area` (m^2), `radiance` (Lambertian `L = B / pi`, linear
//! RGB, in the units of the probe *file*: the room's `radiance_scale` is not applied, as in the
//! directional light file) and `corners` (3 or 4, metres, in order around the patch).
//!
//! A renderer without local lights reads the file through [`AreaLightsFile::distant_lights`]:
//! each patch as a directional light seen from the probe's centre (the point a render scene's
//! origin stands for), in the probe's frame.

use std::path::Path;

use ibl_core::glam::{DMat3, DVec3, Vec3};
use ibl_core::{Rgb, UnitDir};
use ibl_light::{AreaPatch, Extraction, LightSet, ProbeRef, Provenance};
use serde::{Deserialize, Serialize};

use crate::IoError;

/// Value of the `format` field.
pub const AREA_LIGHTS_FORMAT: &str = "iblkit.area-lights/1";

/// Value of the `frame` field.
pub const ROOM_FRAME: &str = "room";

/// Largest area-light file read, bytes.
pub const MAX_AREA_LIGHTS_FILE_BYTES: u64 = 64 << 20;

/// One important patch.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AreaLightRecord {
    /// The room's patch index.
    pub patch: u32,
    /// Its material group.
    pub group: String,
    /// Centroid, metres, room frame.
    pub position: [f64; 3],
    /// Unit front normal, room frame.
    pub normal: [f64; 3],
    /// Area, m^2.
    #[serde(rename = "area")]
    pub area_m2: f64,
    /// Lambertian radiance `B / pi`, linear RGB, the probe file's unit.
    pub radiance: [f64; 3],
    /// Corners in order around the patch (3 or 4), metres, room frame.
    pub corners: Vec<[f64; 3]>,
}

impl AreaLightRecord {
    /// The patch as `ibl-light` data (f32, the precision it was computed in).
    pub fn area_patch(&self) -> AreaPatch {
        AreaPatch {
            position: DVec3::from_array(self.position).as_vec3(),
            normal: UnitDir::from_dvec3(DVec3::from_array(self.normal)).unwrap_or(UnitDir::UP),
            area_m2: self.area_m2 as f32,
            radiance: Rgb::from_array(self.radiance.map(|c| c as f32)),
        }
    }
}

/// A whole area-light file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AreaLightsFile {
    /// Always [`AREA_LIGHTS_FORMAT`].
    pub format: String,
    /// The probe the room's radiance came from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe: Option<ProbeRef>,
    /// The room file, as given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub room: Option<String>,
    /// Always [`ROOM_FRAME`].
    pub frame: String,
    /// Rotation from the probe's frame to the room's, rows.
    pub world_from_probe: [[f64; 3]; 3],
    /// The probe's centre, metres, room frame.
    pub probe_position: [f64; 3],
    /// Fraction of the room's luminous flux the lights carry, in `[0, 1]`.
    pub important_flux_fraction: f64,
    /// The important patches, largest luminous flux first.
    pub lights: Vec<AreaLightRecord>,
}

impl AreaLightsFile {
    /// A file of `lights` with the format and frame fields set.
    pub fn new(
        world_from_probe: DMat3,
        probe_position: Vec3,
        important_flux_fraction: f64,
        lights: Vec<AreaLightRecord>,
    ) -> AreaLightsFile {
        let r = world_from_probe.transpose();
        AreaLightsFile {
            format: AREA_LIGHTS_FORMAT.to_string(),
            probe: None,
            room: None,
            frame: ROOM_FRAME.to_string(),
            world_from_probe: [
                r.x_axis.to_array(),
                r.y_axis.to_array(),
                r.z_axis.to_array(),
            ],
            probe_position: probe_position.as_dvec3().to_array(),
            important_flux_fraction,
            lights,
        }
    }

    /// The rotation `world_from_probe` as a matrix.
    pub fn world_from_probe(&self) -> DMat3 {
        let [a, b, c] = self.world_from_probe;
        DMat3::from_cols_array(&[a[0], b[0], c[0], a[1], b[1], c[1], a[2], b[2], c[2]])
    }

    /// The file as pretty JSON.
    pub fn to_json(&self) -> String {
        // Serialising plain data to a string cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// Parses and checks an area-light file's bytes; `path` names it in errors, which name the
    /// field at fault (`lights[3].normal: not a unit vector`).
    pub fn from_json(path: &Path, bytes: &[u8]) -> Result<AreaLightsFile, IoError> {
        let invalid = |reason: String| IoError::Invalid {
            path: path.to_path_buf(),
            reason,
        };
        let mut de = serde_json::Deserializer::from_slice(bytes);
        let file: AreaLightsFile = serde_path_to_error::deserialize(&mut de)
            .map_err(|e| invalid(format!("not an iblkit area-light file: {e}")))?;
        if file.format != AREA_LIGHTS_FORMAT {
            return Err(IoError::Unsupported {
                path: path.to_path_buf(),
                what: format!(
                    "format: `{}` (expected `{AREA_LIGHTS_FORMAT}`)",
                    file.format
                ),
            });
        }
        file.check().map_err(invalid)?;
        Ok(file)
    }

    /// Every field's range: unit normals and an orthonormal rotation (1e-3), finite positions,
    /// positive areas, finite non-negative radiance, 3 or 4 corners.
    fn check(&self) -> Result<(), String> {
        if self.frame != ROOM_FRAME {
            return Err(format!("frame: `{}` (expected `{ROOM_FRAME}`)", self.frame));
        }
        let finite = |v: &[f64]| v.iter().all(|c| c.is_finite());
        let m = self.world_from_probe();
        let orthonormal = finite(&m.to_cols_array())
            && (m.transpose() * m - DMat3::IDENTITY)
                .to_cols_array()
                .iter()
                .all(|e| e.abs() < 1e-3)
            && m.determinant() > 0.0;
        if !orthonormal {
            return Err("world_from_probe: not a rotation (orthonormal, determinant 1)".into());
        }
        if !finite(&self.probe_position) {
            return Err("probe_position: not finite".into());
        }
        if !(0.0..=1.0 + 1e-9).contains(&self.important_flux_fraction) {
            return Err("important_flux_fraction: not in [0, 1]".into());
        }
        for (i, l) in self.lights.iter().enumerate() {
            let field = |name: &str, problem: &str| format!("lights[{i}].{name}: {problem}");
            if !finite(&l.position) {
                return Err(field("position", "not finite"));
            }
            let n = DVec3::from_array(l.normal);
            if !n.is_finite() || (n.length() - 1.0).abs() > 1e-3 {
                return Err(field("normal", "not a unit vector"));
            }
            if !(l.area_m2.is_finite() && l.area_m2 > 0.0 && l.area_m2 < f64::from(f32::MAX)) {
                return Err(field("area", "must be a positive, finite number of m^2"));
            }
            if !l
                .radiance
                .iter()
                .all(|c| c.is_finite() && *c >= 0.0 && *c < f64::from(f32::MAX))
            {
                return Err(field("radiance", "must be finite and non-negative"));
            }
            if !(3..=4).contains(&l.corners.len()) || !l.corners.iter().all(|c| finite(c)) {
                return Err(field("corners", "must be 3 or 4 finite points"));
            }
        }
        Ok(())
    }

    /// The patches as directional lights seen from the probe's centre, in the probe's frame
    /// (as a directional light file with `--frame ours` holds them), radiance in the probe
    /// file's unit: see [`AreaPatch::as_distant_light`]. Patches that face away from the probe
    /// give no light.
    pub fn distant_lights(&self) -> LightSet {
        let probe_from_world = self.world_from_probe().transpose();
        let at = DVec3::from_array(self.probe_position);
        let lights = self
            .lights
            .iter()
            .filter_map(|l| l.area_patch().as_distant_light(at))
            .map(|mut l| {
                // The file's rotation is orthonormal to 1e-3 only: renormalise (found by the
                // `light_files` fuzz target, a direction 5e-4 off unit length).
                l.direction = (probe_from_world * l.direction).normalize();
                l
            })
            .collect();
        LightSet {
            provenance: Provenance {
                extraction: Extraction::ImportantPatches {
                    patches: self.lights.len() as u32,
                },
                probe: self.probe.clone(),
            },
            lights,
        }
    }
}

/// Writes an area-light file as pretty JSON, atomically.
pub fn write_area_lights_file(path: &Path, file: &AreaLightsFile) -> Result<(), IoError> {
    crate::write_atomically(path, file.to_json().as_bytes())
}

/// Reads and checks an area-light file (at most [`MAX_AREA_LIGHTS_FILE_BYTES`]).
pub fn read_area_lights_file(path: &Path) -> Result<AreaLightsFile, IoError> {
    let bytes = crate::read_bounded(path, MAX_AREA_LIGHTS_FILE_BYTES)?;
    AreaLightsFile::from_json(path, &bytes)
}

/// The directional lights a scene's `[lighting] lights_file` gives: a light-set file as it is,
/// an area-light file (`ibl room lights`) as its patches seen from the probe's centre
/// ([`AreaLightsFile::distant_lights`]). Probe frame; the file's radiance unit.
pub fn read_scene_lights(path: &Path) -> Result<LightSet, IoError> {
    if is_area_lights_file(path)? {
        Ok(read_area_lights_file(path)?.distant_lights())
    } else {
        crate::light_file::read_light_set(path)
    }
}

/// Whether the file at `path` is an area-light file (its `format` field says so); reads at most
/// [`MAX_AREA_LIGHTS_FILE_BYTES`].
pub fn is_area_lights_file(path: &Path) -> Result<bool, IoError> {
    let bytes = crate::read_bounded(path, MAX_AREA_LIGHTS_FILE_BYTES)?;
    Ok(is_area_lights_json(&bytes))
}

/// Whether `bytes` are an area-light file (their `format` field says so), for readers that take
/// either kind of light file.
pub fn is_area_lights_json(bytes: &[u8]) -> bool {
    #[derive(Deserialize)]
    struct Format {
        format: String,
    }
    serde_json::from_slice::<Format>(bytes).is_ok_and(|f| f.format == AREA_LIGHTS_FORMAT)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> AreaLightsFile {
        AreaLightsFile::new(
            DMat3::from_rotation_y(0.5),
            Vec3::new(1.0, 1.5, 2.0),
            0.25,
            vec![AreaLightRecord {
                patch: 7,
                group: "window".into(),
                position: [1.0, 3.5, 2.0],
                normal: [0.0, -1.0, 0.0],
                area_m2: 0.04,
                radiance: [10.0, 8.0, 6.0],
                corners: vec![
                    [0.9, 3.5, 1.9],
                    [1.1, 3.5, 1.9],
                    [1.1, 3.5, 2.1],
                    [0.9, 3.5, 2.1],
                ],
            }],
        )
    }

    #[test]
    fn a_rotation_orthonormal_to_the_tolerance_still_gives_unit_directions() {
        // Found by the `light_files` fuzz target: rows scaled by 1.0004 pass the 1e-3 check.
        let mut file = sample();
        for row in &mut file.world_from_probe {
            for v in row.iter_mut() {
                *v *= 1.0004;
            }
        }
        assert!(file.check().is_ok());
        let set = file.distant_lights();
        assert!(!set.lights.is_empty());
        for l in &set.lights {
            assert!(
                (l.direction.length() - 1.0).abs() < 1e-12,
                "{}",
                l.direction.length()
            );
        }
    }

    #[test]
    fn round_trip_and_rotation_layout() {
        let file = sample();
        let back = AreaLightsFile::from_json(Path::new("a.json"), file.to_json().as_bytes())
            .expect("parses");
        assert_eq!(back, file);
        // Rows: the matrix read back is the one given (to f64 rounding of one product).
        let d = back.world_from_probe() - DMat3::from_rotation_y(0.5);
        assert!(d.to_cols_array().iter().all(|e| e.abs() < 1e-15));
        assert!(is_area_lights_json(file.to_json().as_bytes()));
        assert!(!is_area_lights_json(br#"{"format": "iblkit.lights/1"}"#));
    }

    #[test]
    fn a_patch_above_the_probe_is_a_light_from_above() {
        // 2 m straight above the probe, facing down: Omega = A / r^2 = 0.01 sr; the direction in
        // the probe's frame is still up (a rotation about y keeps y).
        let set = sample().distant_lights();
        assert_eq!(set.lights.len(), 1);
        let l = &set.lights[0];
        // f32 position and area: 1e-6 relative covers their rounding.
        assert!((l.solid_angle_sr - 0.01).abs() < 1e-8);
        assert!((l.direction - DVec3::Y).length() < 1e-6);
        assert_eq!(set.provenance.extraction.name(), "important-patches");
    }

    #[test]
    fn errors_name_the_field() {
        let text = sample().to_json();
        let cases = [
            (
                text.replace("\"area\": 0.04", "\"area\": -1.0"),
                "lights[0].area",
            ),
            (text.replace("-1.0,", "-2.0,"), "lights[0].normal"),
            (text.replace("\"room\"", "\"probe\""), "frame"),
            (text.replace("\"group\"", "\"grp\""), "lights[0]"),
            (text.replace("0.25", "1.5"), "important_flux_fraction"),
        ];
        for (bad, field) in cases {
            let e = AreaLightsFile::from_json(Path::new("bad.json"), bad.as_bytes())
                .expect_err(field)
                .to_string();
            assert!(e.contains("bad.json") && e.contains(field), "{field}: {e}");
        }
        let wrong = text.replace("iblkit.area-lights/1", "iblkit.area-lights/9");
        let e = AreaLightsFile::from_json(Path::new("v.json"), wrong.as_bytes()).expect_err("v9");
        assert!(e.is_bad_input());
    }
}

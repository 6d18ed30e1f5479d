//! The JSON light-set file, CONVENTIONS section 7: `"format": "iblkit.lights/1"`, the source probe
//! (path, size, sha256), the frame the directions are written in, the method with its parameters,
//! and per light `direction`, `radiance`, `solid_angle` (sr), `irradiance` (`I = L A`) and optional
//! region bounds in probe pixels.
//!
//! The schema is plain data (arrays, no iblkit types) so that this crate stays below the extraction
//! crate; readers in other languages need nothing but a JSON parser.

use std::io::Read;
use std::path::Path;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::IoError;

/// Value of the `format` field.
pub const LIGHTS_FORMAT: &str = "iblkit.lights/1";

/// The probe a light set was extracted from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProbeRef {
    /// Path as given on the command line.
    pub path: String,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// SHA-256 of the file's bytes, lower-case hex.
    pub sha256: String,
}

/// The extraction method and its parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MethodRef {
    /// Method name, e.g. `median-cut`.
    pub name: String,
    /// Its parameters, method-specific.
    pub parameters: serde_json::Value,
}

/// Pixel bounds of the region a light stands for: columns `x0..x1`, rows `y0..y1` (half-open, row
/// 0 at the top).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct RegionRecord {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
}

/// One directional light.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LightRecord {
    /// Unit direction towards the light, in the file's `frame`.
    pub direction: [f64; 3],
    /// Radiance, linear RGB (the probe's unit).
    pub radiance: [f32; 3],
    /// Solid angle of the source, sr.
    pub solid_angle: f64,
    /// `I = L A` per channel: irradiance on a surface facing the light.
    pub irradiance: [f64; 3],
    /// The probe pixels it stands for (region methods).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub region: Option<RegionRecord>,
}

/// A whole light-set file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LightsFile {
    /// Always [`LIGHTS_FORMAT`].
    pub format: String,
    /// Source probe.
    pub probe: ProbeRef,
    /// Frame preset of the directions (`gltf` = iblkit's world frame).
    pub frame: String,
    /// Method and parameters.
    pub method: MethodRef,
    /// The lights.
    pub lights: Vec<LightRecord>,
    /// Hybrid lighting: the SH ambient that carries the rest of the probe (radiance
    /// coefficients in the file's `frame`; the lights' irradiance plus the ambient's gives the
    /// probe's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ambient: Option<AmbientRecord>,
}

/// The SH ambient of a hybrid light set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AmbientRecord {
    /// The basis (see [`crate::sh_file::SH_CONVENTION`]).
    pub convention: String,
    /// Number of bands (`coefficients` has `bands^2` entries).
    pub bands: usize,
    /// Radiance coefficients `[l*l + l + m]`, linear RGB.
    pub radiance: Vec<[f64; 3]>,
}

/// SHA-256 of a file, lower-case hex. Streams the file (O(1) memory).
pub fn sha256_file(path: &Path) -> Result<String, IoError> {
    let io = |source| IoError::Io {
        path: path.to_path_buf(),
        source,
    };
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
    let text = serde_json::to_string_pretty(file).map_err(|e| IoError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e),
    })?;
    crate::write_atomically(path, text.as_bytes())
}

/// Reads a light-set file, checking its `format`.
pub fn read_lights_file(path: &Path) -> Result<LightsFile, IoError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let file: LightsFile = serde_json::from_slice(&bytes).map_err(|e| IoError::Invalid {
        path: path.to_path_buf(),
        reason: format!("not an iblkit light-set file: {e}"),
    })?;
    if file.format != LIGHTS_FORMAT {
        return Err(IoError::Unsupported {
            path: path.to_path_buf(),
            what: format!(
                "light-set format `{}` (expected `{LIGHTS_FORMAT}`)",
                file.format
            ),
        });
    }
    Ok(file)
}

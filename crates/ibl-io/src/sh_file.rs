//! Spherical-harmonic lighting files: iblkit's own JSON (any number of bands, radiance or
//! irradiance) and the 9-coefficient (3-band) layouts other tools exchange, each with the target
//! tool's basis signs, normalisation, pi factors, channel layout and frame. Every conversion is a
//! per-coefficient factor on iblkit's radiance coefficients `c_i` (CONVENTIONS section 5b),
//! `stored_i = factor_i c_i` per channel, then a layout of the 27 numbers:
//!
//! | format | stored | layout | source of the convention |
//! |---|---|---|---|
//! | `json` | `c_i` (or `e_i = A_l c_i` with `quantity: irradiance`), any bands | `[[r,g,b], ...]` | this crate |
//! | `threejs` | `c_i` | `LightProbe` JSON, `sh`: 27 floats, RGB per coefficient | three.js `src/math/SphericalHarmonics3.js` (`getAt`, `toArray`), `src/lights/LightProbe.js` (`toJSON`) |
//! | `filament` | `F_i c_i` | `sh.txt`: 9 lines `(r, g, b); // Llm` | Filament `tools/cmgen/src/cmgen.cpp` (`outputSh`), `libs/ibl/src/CubemapSH.cpp` (`preprocessSHForShader`), `shaders/src/surface_light_indirect.fs` |
//! | `unity` | `F_i z_i c_i` | 27 floats, channel-major (`[rgb * 9 + i]`) | Unity `SphericalHarmonicsL2.bindings.cs` (indexer), SRP core `SphericalHarmonics.hlsl` (`SHEvalLinearL0L1`, `PackSH`) |
//! | `webxr` | `c_i` | 27 floats, RGB per coefficient | W3C Lighting Estimation `sphericalHarmonicsCoefficients`; three.js `XREstimatedLight.js` reads it as `SphericalHarmonics3` |
//! | `arkit` | `s_i c_i` | 27 floats, channel-major | Apple `ARDirectionalLightEstimate.sphericalHarmonicsCoefficients` (layout); signs: Unity's ARKit plugin (`ARLightEstimate.cs`) |
//! | `gltf-ext` | `s_i A_l c_i` | `EXT_lights_image_based` light, `irradianceCoefficients` 9 x `[r, g, b]` | KhronosGroup glTF `EXT_lights_image_based` README; basis as Babylon.js's loader reads it |
//!
//! with `F_i = k_i A_l / pi` (the "pre-scaled irradiance": coefficient times basis constant `k_i`
//! times the Lambert factor, over pi, so the tool's polynomial gives `E(n) / pi`, the radiance of a
//! white Lambertian surface): `0.282095, 0.325735 (x3), 0.273137, 0.273137, 0.078848, 0.273137,
//! 0.136569`; `s_i` the Condon-Shortley signs `+ - + - + - + - +` of tools whose basis carries
//! them (they cancel in `F_i`, which is why Filament and Unity store positive factors);
//! `z_i = + + - + + - + - +` the change to Unity's left-handed frame (world z negated, so iblkit's
//! forward -Z is Unity's forward +Z); and `A_l = pi, 2 pi / 3, pi / 4`. three.js, Filament, WebXR
//! and glTF share iblkit's frame (right-handed, +Y up, -Z forward).
//!
//! Caveats kept in the docs (docs/CONVENTIONS.md): cmgen windows its SH by default (run it with
//! `--sh-window=no` to compare numbers); ARKit documents only the layout; the glTF extension
//! defines no basis (Babylon.js, its only open reader, uses Condon-Shortley irradiance) and needs
//! specular images we do not write, so `gltf-ext` is a fragment to merge into a glTF file.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::IoError;
use ibl_light::ProbeRef;

/// Value of the `format` field of iblkit's SH JSON.
pub const SH_FORMAT: &str = "iblkit.sh/1";

/// Largest SH file read (they are a few kilobytes).
const MAX_SH_FILE_BYTES: u64 = 4 << 20;

/// An SH lighting file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShFileFormat {
    /// iblkit's JSON (`iblkit.sh/1`): any bands, radiance or irradiance.
    Json,
    /// three.js `LightProbe` JSON (radiance, `SphericalHarmonics3`).
    ThreeJs,
    /// Filament `sh.txt` (pre-scaled irradiance, cmgen's text).
    Filament,
    /// Unity `SphericalHarmonicsL2` as 27 channel-major floats (pre-scaled irradiance, Unity frame).
    Unity,
    /// WebXR `sphericalHarmonicsCoefficients` (27 floats, RGB per coefficient).
    WebXr,
    /// ARKit `sphericalHarmonicsCoefficients` (27 floats, channel-major, Condon-Shortley signs).
    ArKit,
    /// glTF `EXT_lights_image_based` light (Condon-Shortley irradiance coefficients), a fragment.
    GltfExt,
}

impl ShFileFormat {
    /// Every format, in the order help texts list them.
    pub const ALL: [ShFileFormat; 7] = [
        ShFileFormat::Json,
        ShFileFormat::ThreeJs,
        ShFileFormat::Filament,
        ShFileFormat::Unity,
        ShFileFormat::WebXr,
        ShFileFormat::ArKit,
        ShFileFormat::GltfExt,
    ];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ShFileFormat::Json => "json",
            ShFileFormat::ThreeJs => "threejs",
            ShFileFormat::Filament => "filament",
            ShFileFormat::Unity => "unity",
            ShFileFormat::WebXr => "webxr",
            ShFileFormat::ArKit => "arkit",
            ShFileFormat::GltfExt => "gltf-ext",
        }
    }

    /// The format of a name (`None` if unknown).
    pub fn from_name(name: &str) -> Option<ShFileFormat> {
        ShFileFormat::ALL.into_iter().find(|f| f.name() == name)
    }

    /// `factor_i` of the module doc: `stored_i = factor_i c_i` (1 for iblkit's JSON).
    pub fn factors(self) -> [f64; 9] {
        let pi = std::f64::consts::PI;
        let root = pi.sqrt();
        let k = [
            0.5 / root,
            3f64.sqrt() / (2.0 * root),
            3f64.sqrt() / (2.0 * root),
            3f64.sqrt() / (2.0 * root),
            15f64.sqrt() / (2.0 * root),
            15f64.sqrt() / (2.0 * root),
            5f64.sqrt() / (4.0 * root),
            15f64.sqrt() / (2.0 * root),
            15f64.sqrt() / (4.0 * root),
        ];
        let a = lambert_factors();
        let cs = [1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0];
        let z_flip = [1.0, 1.0, -1.0, 1.0, 1.0, -1.0, 1.0, -1.0, 1.0];
        std::array::from_fn(|i| match self {
            ShFileFormat::Json | ShFileFormat::ThreeJs | ShFileFormat::WebXr => 1.0,
            ShFileFormat::Filament => k[i] * a[i] / pi,
            ShFileFormat::Unity => k[i] * a[i] / pi * z_flip[i],
            ShFileFormat::ArKit => cs[i],
            ShFileFormat::GltfExt => cs[i] * a[i],
        })
    }
}

/// The Lambert factor `A_l` of each of the first nine coefficients (`pi`, `2 pi / 3` x3, `pi / 4`
/// x5).
fn lambert_factors() -> [f64; 9] {
    let pi = std::f64::consts::PI;
    std::array::from_fn(|i| match i {
        0 => pi,
        1..=3 => 2.0 * pi / 3.0,
        _ => pi / 4.0,
    })
}

/// Whether coefficients hold radiance or irradiance (iblkit's JSON only).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShQuantity {
    /// `c_lm`: radiance coefficients.
    Radiance,
    /// `e_lm = A_l c_lm`: irradiance coefficients.
    Irradiance,
}

/// iblkit's SH JSON file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShFile {
    /// Always [`SH_FORMAT`].
    pub format: String,
    /// The basis, in words (CONVENTIONS section 5b).
    pub convention: String,
    /// The frame of the directions (`gltf`: iblkit's world frame).
    pub frame: String,
    /// Radiance or irradiance coefficients.
    pub quantity: ShQuantity,
    /// Number of bands (`coefficients` has `bands^2` entries).
    pub bands: usize,
    /// The window applied to the bands (`none`, `lanczos`, `hann`).
    pub window: String,
    /// The source probe, when there is one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe: Option<ProbeRef>,
    /// Coefficients `[sh_index(l, m)]`, linear RGB.
    pub coefficients: Vec<[f64; 3]>,
}

/// The basis sentence written into iblkit's JSON.
pub const SH_CONVENTION: &str = "real orthonormal SH without the Condon-Shortley phase, index l*l+l+m, on world (x, y, z) with z the polar axis (iblkit docs/CONVENTIONS.md section 5b)";

/// The 27 stored numbers of a 9-coefficient format from iblkit radiance coefficients (at least
/// 9; only the first 9 are used), in the format's layout order.
fn stored_values(format: ShFileFormat, c: &[[f64; 3]]) -> Vec<f64> {
    let f = format.factors();
    let channel_major = matches!(format, ShFileFormat::Unity | ShFileFormat::ArKit);
    if channel_major {
        (0..3)
            .flat_map(|ch| (0..9).map(move |i| (ch, i)))
            .map(|(ch, i)| f[i] * c[i][ch])
            .collect()
    } else {
        (0..9)
            .flat_map(|i| (0..3).map(move |ch| (i, ch)))
            .map(|(i, ch)| f[i] * c[i][ch])
            .collect()
    }
}

/// iblkit radiance coefficients from the 27 stored numbers of a 9-coefficient format.
fn radiance_from_values(format: ShFileFormat, v: &[f64]) -> Vec<[f64; 3]> {
    let f = format.factors();
    let channel_major = matches!(format, ShFileFormat::Unity | ShFileFormat::ArKit);
    (0..9)
        .map(|i| {
            std::array::from_fn(|ch| {
                let x = if channel_major {
                    v[ch * 9 + i]
                } else {
                    v[i * 3 + ch]
                };
                x / f[i]
            })
        })
        .collect()
}

/// The text of `file` in `format`: iblkit's JSON as it is, or for the 9-coefficient formats its
/// first 9 radiance coefficients converted (an error for irradiance or fewer than 3 bands).
pub fn format_sh(format: ShFileFormat, file: &ShFile) -> Result<String, String> {
    if file.coefficients.len() != file.bands * file.bands {
        return Err(format!(
            "{} bands need {} coefficients; got {}",
            file.bands,
            file.bands * file.bands,
            file.coefficients.len()
        ));
    }
    if !file.coefficients.iter().flatten().all(|v| v.is_finite()) {
        return Err("a coefficient is not a finite number".into());
    }
    let json = |value: &serde_json::Value| {
        serde_json::to_string_pretty(value)
            .map(|s| s + "\n")
            .map_err(|e| e.to_string())
    };
    if format == ShFileFormat::Json {
        return serde_json::to_string_pretty(file)
            .map(|s| s + "\n")
            .map_err(|e| e.to_string());
    }
    if file.quantity != ShQuantity::Radiance || file.bands < 3 {
        return Err(format!(
            "{} needs radiance coefficients of at least 3 bands",
            format.name()
        ));
    }
    let v = stored_values(format, &file.coefficients);
    match format {
        ShFileFormat::Json | ShFileFormat::ThreeJs => json(&serde_json::json!({
            "metadata": {"version": 4.6, "type": "Object", "generator": "iblkit"},
            "object": {
                "uuid": "00000000-0000-4000-8000-000000000000",
                "type": "LightProbe",
                "name": "iblkit",
                "layers": 1,
                "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],
                "up": [0, 1, 0],
                "color": 16_777_215,
                "intensity": 1,
                "sh": v,
            }
        })),
        ShFileFormat::Filament => {
            // cmgen's `outputSh`: fixed with 15 decimals, the label after `//`.
            let mut s = String::new();
            for (i, name) in FILAMENT_NAMES.iter().enumerate() {
                s.push_str(&format!(
                    "({:>18.15}, {:>18.15}, {:>18.15}); // L{name}, irradiance, pre-scaled base\n",
                    v[3 * i],
                    v[3 * i + 1],
                    v[3 * i + 2]
                ));
            }
            Ok(s)
        }
        ShFileFormat::Unity => json(&serde_json::json!({
            "format": "unity.SphericalHarmonicsL2",
            "layout": "sh[rgb, i] = values[rgb * 9 + i] (the SphericalHarmonicsL2 indexer)",
            "frame": "Unity: left-handed, +Y up, +Z forward (iblkit z negated)",
            "values": v,
        })),
        ShFileFormat::WebXr => json(&serde_json::json!({
            "format": "webxr.sphericalHarmonicsCoefficients",
            "layout": "9 coefficients x (r, g, b), radiance, as three.js SphericalHarmonics3.fromArray reads it",
            "sphericalHarmonicsCoefficients": v,
        })),
        ShFileFormat::ArKit => json(&serde_json::json!({
            "format": "arkit.sphericalHarmonicsCoefficients",
            "layout": "3 planes (r, g, b) x 9 coefficients, radiance with Condon-Shortley signs",
            "sphericalHarmonicsCoefficients": v,
        })),
        ShFileFormat::GltfExt => {
            let rows: Vec<[f64; 3]> = v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            json(&serde_json::json!({
                "extensionsUsed": ["EXT_lights_image_based"],
                "extensions": {"EXT_lights_image_based": {"lights": [{
                    "name": "iblkit",
                    "rotation": [0.0, 0.0, 0.0, 1.0],
                    "intensity": 1.0,
                    "irradianceCoefficients": rows,
                    "specularImageSize": 0,
                    "specularImages": [],
                }]}},
            }))
        }
    }
}

/// The `Llm` labels of Filament's `sh.txt`, in file order.
const FILAMENT_NAMES: [&str; 9] = ["00", "1-1", "10", "11", "2-2", "2-1", "20", "21", "22"];

/// Reads SH coefficients from the text of a file in `format`: iblkit's JSON as it is, any other
/// format as 3 bands of iblkit radiance coefficients (window `none`, no probe).
pub fn parse_sh(format: ShFileFormat, text: &str) -> Result<ShFile, String> {
    if format == ShFileFormat::Json {
        let file: ShFile = serde_json::from_str(text).map_err(|e| e.to_string())?;
        if file.format != SH_FORMAT {
            return Err(format!(
                "format is '{}', expected '{SH_FORMAT}'",
                file.format
            ));
        }
        if file.bands == 0 || file.bands > 64 || file.coefficients.len() != file.bands * file.bands
        {
            return Err(format!(
                "{} bands with {} coefficients (need 1 to 64 bands and bands^2 coefficients)",
                file.bands,
                file.coefficients.len()
            ));
        }
        if !file.coefficients.iter().flatten().all(|v| v.is_finite()) {
            return Err("a coefficient is not a finite number".into());
        }
        return Ok(file);
    }
    let values: Vec<f64> = if format == ShFileFormat::Filament {
        let mut v = Vec::with_capacity(27);
        for (k, line) in text.lines().filter(|l| !l.trim().is_empty()).enumerate() {
            let inner = line
                .trim()
                .strip_prefix('(')
                .and_then(|rest| rest.split_once(')'))
                .map(|(nums, _)| nums)
                .ok_or_else(|| format!("line {}: expected '(r, g, b)'", k + 1))?;
            for part in inner.split(',') {
                v.push(
                    part.trim().parse::<f64>().map_err(|_| {
                        format!("line {}: '{}' is not a number", k + 1, part.trim())
                    })?,
                );
            }
        }
        v
    } else {
        let value: serde_json::Value = serde_json::from_str(text).map_err(|e| e.to_string())?;
        let array = match format {
            ShFileFormat::ThreeJs => &value["object"]["sh"],
            ShFileFormat::Unity => &value["values"],
            ShFileFormat::WebXr | ShFileFormat::ArKit => &value["sphericalHarmonicsCoefficients"],
            _ => {
                &value["extensions"]["EXT_lights_image_based"]["lights"][0]["irradianceCoefficients"]
            }
        };
        let flat: Vec<&serde_json::Value> = match array.as_array() {
            Some(a) if format == ShFileFormat::GltfExt => a
                .iter()
                .flat_map(|row| {
                    row.as_array()
                        .map(|r| r.iter().collect())
                        .unwrap_or_else(Vec::new)
                })
                .collect(),
            Some(a) => a.iter().collect(),
            None => {
                return Err(format!(
                    "no coefficient array where {} keeps it",
                    format.name()
                ));
            }
        };
        let intensity = match format {
            ShFileFormat::ThreeJs => value["object"]["intensity"].as_f64().unwrap_or(1.0),
            ShFileFormat::GltfExt => {
                value["extensions"]["EXT_lights_image_based"]["lights"][0]["intensity"]
                    .as_f64()
                    .unwrap_or(1.0)
            }
            _ => 1.0,
        };
        flat.iter()
            .map(|x| {
                x.as_f64()
                    .map(|v| v * intensity)
                    .ok_or("a coefficient is not a number")
            })
            .collect::<Result<_, _>>()?
    };
    if values.len() != 27 {
        return Err(format!(
            "{} numbers, expected 27 (9 coefficients x RGB)",
            values.len()
        ));
    }
    if !values.iter().all(|v| v.is_finite()) {
        return Err("a coefficient is not a finite number".into());
    }
    Ok(ShFile {
        format: SH_FORMAT.to_string(),
        convention: SH_CONVENTION.to_string(),
        frame: "gltf".to_string(),
        quantity: ShQuantity::Radiance,
        bands: 3,
        window: "none".to_string(),
        probe: None,
        coefficients: radiance_from_values(format, &values),
    })
}

/// Reads an SH file (at most 4 MiB) in `format`.
pub fn read_sh_file(path: &Path, format: ShFileFormat) -> Result<ShFile, IoError> {
    let text = crate::read_text(path, MAX_SH_FILE_BYTES)?;
    parse_sh(format, &text).map_err(|reason| IoError::Invalid {
        path: path.to_path_buf(),
        reason: format!("{} SH file: {reason}", format.name()),
    })
}

/// Writes `file` in `format`, atomically.
pub fn write_sh_file(path: &Path, format: ShFileFormat, file: &ShFile) -> Result<(), IoError> {
    let text = format_sh(format, file).map_err(|reason| IoError::Invalid {
        path: path.to_path_buf(),
        reason,
    })?;
    crate::write_atomically(path, text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> ShFile {
        ShFile {
            format: SH_FORMAT.into(),
            convention: SH_CONVENTION.into(),
            frame: "gltf".into(),
            quantity: ShQuantity::Radiance,
            bands: 3,
            window: "none".into(),
            probe: None,
            coefficients: (0..9)
                .map(|i| [1.0 + i as f64, -0.5 * i as f64, 0.25 / (1.0 + i as f64)])
                .collect(),
        }
    }

    #[test]
    fn every_format_round_trips() {
        let file = sample();
        for format in ShFileFormat::ALL {
            let text = format_sh(format, &file).unwrap();
            let back = parse_sh(format, &text).unwrap();
            for (a, b) in file.coefficients.iter().zip(&back.coefficients) {
                for ch in 0..3 {
                    assert!(
                        (a[ch] - b[ch]).abs() < 1e-12 * (1.0 + a[ch].abs()),
                        "{}",
                        format.name()
                    );
                }
            }
        }
    }

    #[test]
    fn known_factors() {
        let f = ShFileFormat::Filament.factors();
        for (got, want) in f.iter().zip([
            0.282095, 0.325735, 0.325735, 0.325735, 0.273137, 0.273137, 0.078848, 0.273137,
            0.136569,
        ]) {
            assert!((got - want).abs() < 1e-6);
        }
        // A uniform radiance C has c0 = 2 sqrt(pi) C; Unity's ambient colour sh[., 0] is C.
        let c0 = 2.0 * std::f64::consts::PI.sqrt();
        assert!((ShFileFormat::Unity.factors()[0] * c0 - 1.0).abs() < 1e-12);
        assert_eq!(ShFileFormat::Unity.factors()[2].signum(), -1.0);
        assert!(
            (ShFileFormat::GltfExt.factors()[1] + 2.0 * std::f64::consts::PI / 3.0).abs() < 1e-12
        );
    }

    /// iblkit's irradiance `E(n) = sum_i A_l c_i k_i P_i(n)` from its radiance coefficients.
    fn iblkit_irradiance(c: &[[f64; 3]], n: [f64; 3], ch: usize) -> f64 {
        let [x, y, z] = n;
        let basis = [
            0.282095,
            0.488603 * y,
            0.488603 * z,
            0.488603 * x,
            1.092548 * x * y,
            1.092548 * y * z,
            0.315392 * (3.0 * z * z - 1.0),
            1.092548 * x * z,
            0.546274 * (x * x - y * y),
        ];
        let a = lambert_factors();
        (0..9).map(|i| a[i] * c[i][ch] * basis[i]).sum()
    }

    /// Each format's numbers, evaluated the way the target tool evaluates them, give iblkit's
    /// irradiance. The tools' formulas, with where they were read:
    /// - three.js `src/math/SphericalHarmonics3.js`, `getIrradianceAt` (and the GLSL
    ///   `shGetIrradianceAt` in `src/renderers/shaders/ShaderChunk/lights_pars_begin.glsl.js`):
    ///   `0.886227 c0 + 2 * 0.511664 (c1 y + c2 z + c3 x) + 2 * 0.429043 (c4 xy + c5 yz + c7 xz)
    ///   + c6 (0.743125 z^2 - 0.247708) + 0.429043 c8 (x^2 - y^2)` = E.
    /// - Filament `shaders/src/surface_light_indirect.fs`, `Irradiance_SphericalHarmonics`:
    ///   `S0 + S1 y + S2 z + S3 x + S4 yx + S5 yz + S6 (3z^2 - 1) + S7 zx + S8 (x^2 - y^2)` = E / pi
    ///   (Lambert's 1/pi is baked in, `sh.txt` as cmgen's `outputSh` writes it).
    /// - Unity SRP core `ShaderLibrary/SphericalHarmonics.hlsl`, `SHEvalLinearL0L1` +
    ///   `SHEvalLinearL2` on Unity's normal (iblkit z negated): the same polynomial = E / pi.
    /// - Babylon.js `sphericalPolynomial.ts` (`preScaleForRendering` with the Condon-Shortley
    ///   `SH3ylmBasisConstants`, after `convertIrradianceToLambertianRadiance`) for the glTF
    ///   extension: `sum_i (g_i / pi) s_i k_i P_i(n)` = E / pi.
    /// - ARKit, radiance with Condon-Shortley signs: `sum_i A_l (s_i r_i) s_i k_i P_i(n)` = E.
    #[test]
    fn targets_evaluate_to_iblkit_irradiance() {
        let pi = std::f64::consts::PI;
        let file = sample();
        let c = &file.coefficients;
        let poly = |n: [f64; 3]| {
            let [x, y, z] = n;
            [
                1.0,
                y,
                z,
                x,
                x * y,
                y * z,
                3.0 * z * z - 1.0,
                x * z,
                x * x - y * y,
            ]
        };
        let k = [
            0.282095, 0.488603, 0.488603, 0.488603, 1.092548, 1.092548, 0.315392, 1.092548,
            0.546274,
        ];
        let s = [1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0];
        let a = lambert_factors();
        for n in [
            [0.0, 1.0, 0.0],
            [0.6, 0.0, -0.8],
            [-0.48, 0.6, 0.64],
            [0.0, 0.0, 1.0],
        ] {
            for ch in 0..3 {
                let want = iblkit_irradiance(c, n, ch);
                let tol = 1e-5 * (1.0 + want.abs());
                let get = |format: ShFileFormat| {
                    let v = stored_values(format, c);
                    move |i: usize| {
                        if matches!(format, ShFileFormat::Unity | ShFileFormat::ArKit) {
                            v[ch * 9 + i]
                        } else {
                            v[i * 3 + ch]
                        }
                    }
                };
                let [x, y, z] = n;
                let t = get(ShFileFormat::ThreeJs);
                let three = 0.886227 * t(0)
                    + 2.0 * 0.511664 * (t(1) * y + t(2) * z + t(3) * x)
                    + 2.0 * 0.429043 * (t(4) * x * y + t(5) * y * z + t(7) * x * z)
                    + t(6) * (0.743125 * z * z - 0.247708)
                    + 0.429043 * t(8) * (x * x - y * y);
                assert!((three - want).abs() < tol, "three.js {three} vs {want}");
                let f = get(ShFileFormat::Filament);
                let filament: f64 = poly(n).iter().enumerate().map(|(i, p)| f(i) * p).sum();
                assert!((pi * filament - want).abs() < tol, "filament");
                let u = get(ShFileFormat::Unity);
                let unity: f64 = poly([x, y, -z])
                    .iter()
                    .enumerate()
                    .map(|(i, p)| u(i) * p)
                    .sum();
                assert!((pi * unity - want).abs() < tol, "unity");
                let g = get(ShFileFormat::GltfExt);
                let babylon: f64 = poly(n)
                    .iter()
                    .enumerate()
                    .map(|(i, p)| g(i) / pi * s[i] * k[i] * p)
                    .sum();
                assert!((pi * babylon - want).abs() < tol, "gltf-ext");
                let r = get(ShFileFormat::ArKit);
                let arkit: f64 = poly(n)
                    .iter()
                    .enumerate()
                    .map(|(i, p)| a[i] * r(i) * s[i] * k[i] * p)
                    .sum();
                assert!((arkit - want).abs() < tol, "arkit");
                let w = get(ShFileFormat::WebXr);
                let webxr: f64 = poly(n)
                    .iter()
                    .enumerate()
                    .map(|(i, p)| a[i] * w(i) * k[i] * p)
                    .sum();
                assert!((webxr - want).abs() < tol, "webxr");
            }
        }
    }

    #[test]
    fn refusals() {
        let mut file = sample();
        file.quantity = ShQuantity::Irradiance;
        assert!(format_sh(ShFileFormat::ThreeJs, &file).is_err());
        assert!(format_sh(ShFileFormat::Json, &file).is_ok());
        assert!(parse_sh(ShFileFormat::Filament, "(1, 2, 3)\n").is_err());
        assert!(parse_sh(ShFileFormat::Filament, "(1, x, 3)\n").is_err());
        assert!(parse_sh(ShFileFormat::Unity, "{}").is_err());
        assert!(parse_sh(ShFileFormat::Json, "{\"format\": \"other\"}").is_err());
    }
}

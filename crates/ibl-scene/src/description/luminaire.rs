//! `[[luminaire]]` (a scene file) and `[[light]]` (an edits file, `ibl room render --edit`): a
//! goniometric point light (Grosch 2005 section 4.2) from an IES LM-63 or EULUMDAT file, placed
//! in the world frame and scaled to the probe's radiance unit (CONVENTIONS section 6). The file
//! is read by `ibl-io` (`luminaire_file`); this is its description only.

use std::path::PathBuf;

use ibl_core::Rgb;
use serde::{Deserialize, Serialize};

use super::field::{DescriptionError, finite3, invalid};

/// Most luminaires in one file.
pub const MAX_LUMINAIRES: usize = 64;

/// How a luminaire's candela become the probe's radiance unit (CONVENTIONS section 6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IntensityScale {
    /// Absolute: a probe value of 1 is this many cd/m^2, so the light delivers `I / k` probe
    /// units of radiance times sr.
    NitsPerUnit(f32),
    /// Normalised: the table scaled so that its peak is this many probe units per sr (the
    /// probe's scale unknown, the light set by eye).
    PeakIntensity(f32),
}

/// One luminaire as a file places it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LuminaireDescription {
    /// The `.ies` or `.ldt` file, relative to the file that names it.
    pub file: PathBuf,
    /// Position, metres, world frame.
    pub position: [f32; 3],
    /// Yaw, pitch and roll of the light's frame, degrees (0 0 0: aimed straight down). Default 0.
    #[serde(default)]
    pub rotation_deg: [f32; 3],
    /// Chromaticity, linear Rec. 709 (only the ratios count). Default white.
    #[serde(default = "white")]
    pub colour: [f32; 3],
    /// Absolute scale: cd/m^2 per probe unit (the default, 1, when neither is given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nits_per_unit: Option<f32>,
    /// Normalised scale: the table's peak in probe units per sr.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_intensity: Option<f32>,
}

fn white() -> [f32; 3] {
    [1.0; 3]
}

impl LuminaireDescription {
    /// Checks the numbers; `field` names the entry in errors (`luminaire[0]`).
    pub fn validate(&self, field: &str) -> Result<(), DescriptionError> {
        finite3(&format!("{field}.position"), self.position)?;
        finite3(&format!("{field}.rotation_deg"), self.rotation_deg)?;
        let colour = Rgb::from_array(self.colour);
        if !colour.is_valid_radiance() || colour.luminance() <= 0.0 {
            return Err(invalid(
                format!("{field}.colour"),
                format!(
                    "{:?} must be finite, not negative and not black",
                    self.colour
                ),
            ));
        }
        self.scale(field).map(|_| ())
    }

    /// The intensity scale (checked: one of the two, positive and finite).
    pub fn scale(&self, field: &str) -> Result<IntensityScale, DescriptionError> {
        let positive = |v: f32| v.is_finite() && v > 0.0;
        match (self.nits_per_unit, self.peak_intensity) {
            (Some(_), Some(_)) => Err(invalid(
                field,
                "give nits_per_unit (absolute) or peak_intensity (normalised), not both",
            )),
            (Some(k), None) if positive(k) => Ok(IntensityScale::NitsPerUnit(k)),
            (None, Some(p)) if positive(p) => Ok(IntensityScale::PeakIntensity(p)),
            (None, None) => Ok(IntensityScale::NitsPerUnit(1.0)),
            _ => Err(invalid(
                field,
                "nits_per_unit and peak_intensity must be positive and finite",
            )),
        }
    }
}

/// Checks a file's luminaires (`table` names them in errors: `luminaire`, `light`).
pub fn validate_luminaires(
    table: &str,
    luminaires: &[LuminaireDescription],
) -> Result<(), DescriptionError> {
    if luminaires.len() > MAX_LUMINAIRES {
        return Err(invalid(
            table,
            format!("{} entries; at most {MAX_LUMINAIRES}", luminaires.len()),
        ));
    }
    for (i, l) in luminaires.iter().enumerate() {
        l.validate(&format!("{table}[{i}]"))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<LuminaireDescription, String> {
        toml::from_str(text).map_err(|e| e.to_string())
    }

    #[test]
    fn a_luminaire_reads_with_its_defaults() {
        let l = parse("file = \"a.ies\"\nposition = [0, 2, 0]\n").expect("parses");
        assert_eq!(l.rotation_deg, [0.0; 3]);
        assert_eq!(l.colour, [1.0; 3]);
        assert_eq!(l.scale("l"), Ok(IntensityScale::NitsPerUnit(1.0)));
        let l = parse("file = \"a.ies\"\nposition = [0, 2, 0]\npeak_intensity = 40\n").unwrap();
        assert_eq!(l.scale("l"), Ok(IntensityScale::PeakIntensity(40.0)));
        assert!(parse("file = \"a.ies\"\nposition = [0, 2, 0]\nbrightness = 4\n").is_err());
    }

    #[test]
    fn bad_numbers_are_refused_naming_the_field() {
        let ok = parse("file = \"a.ies\"\nposition = [0, 2, 0]\n").expect("parses");
        let both = LuminaireDescription {
            nits_per_unit: Some(1.0),
            peak_intensity: Some(2.0),
            ..ok.clone()
        };
        assert!(
            both.validate("luminaire[0]")
                .is_err_and(|e| e.field == "luminaire[0]")
        );
        let negative = LuminaireDescription {
            peak_intensity: Some(-2.0),
            ..ok.clone()
        };
        assert!(negative.validate("luminaire[0]").is_err());
        let black = LuminaireDescription {
            colour: [0.0; 3],
            ..ok.clone()
        };
        assert!(
            black
                .validate("luminaire[1]")
                .is_err_and(|e| e.field == "luminaire[1].colour")
        );
        let nowhere = LuminaireDescription {
            position: [f32::NAN, 0.0, 0.0],
            ..ok.clone()
        };
        assert!(
            nowhere
                .validate("luminaire[2]")
                .is_err_and(|e| e.field == "luminaire[2].position")
        );
        let many = vec![ok; MAX_LUMINAIRES + 1];
        assert!(validate_luminaires("luminaire", &many).is_err());
        assert!(validate_luminaires("luminaire", &many[..MAX_LUMINAIRES]).is_ok());
    }
}

//! A luminaire placed by a scene's `[[luminaire]]` or an edits file's `[[light]]`
//! (`ibl_scene::description::LuminaireDescription`): its photometric file read
//! ([`crate::photometry`]), its candela scaled to the probe's radiance unit (CONVENTIONS
//! section 6) and its frame turned by yaw, pitch and roll.

use std::path::Path;

use ibl_core::glam::Vec3;
use ibl_core::{EulerDegrees, Rgb};
use ibl_light::{GoniometricLight, intensity_per_candela_for};
use ibl_scene::description::IntensityScale;

use crate::IoError;
use crate::photometry::{PhotometricFile, read_photometry};

/// A luminaire read and placed.
#[derive(Clone, Debug)]
pub struct PlacedLuminaire {
    /// The light, world frame, in the probe's unit.
    pub light: GoniometricLight,
    /// The file as read (name, stated flux).
    pub file: PhotometricFile,
    /// cd/m^2 per probe unit, as given or from a normalised peak.
    pub nits_per_unit: f32,
}

/// Reads the photometric file `path` and places its light at `position` (metres, world frame),
/// turned by `rotation_deg` (yaw, pitch, roll; 0 0 0 aims it straight down), coloured by
/// `colour` (only the ratios count) and scaled by `scale`. A table that emits nothing is
/// refused, naming the file.
pub fn read_luminaire(
    path: &Path,
    position: Vec3,
    rotation_deg: [f32; 3],
    colour: Rgb,
    scale: IntensityScale,
) -> Result<PlacedLuminaire, IoError> {
    let file = read_photometry(path)?;
    let table = file.table().clone();
    let peak_cd = table.peak();
    let nits_per_unit = match scale {
        IntensityScale::NitsPerUnit(k) => k,
        IntensityScale::PeakIntensity(p) => peak_cd / p,
    };
    let intensity_per_candela = intensity_per_candela_for(colour, nits_per_unit);
    if peak_cd.is_nan() || peak_cd <= 0.0 || intensity_per_candela.max_channel() <= 0.0 {
        return Err(IoError::Invalid {
            path: path.to_path_buf(),
            reason: format!("the luminaire emits no light (peak {peak_cd} cd)"),
        });
    }
    let [yaw_deg, pitch_deg, roll_deg] = rotation_deg;
    let light = GoniometricLight {
        position,
        world_from_light: EulerDegrees {
            yaw_deg,
            pitch_deg,
            roll_deg,
        }
        .world_from_probe(),
        table,
        intensity_per_candela,
    };
    Ok(PlacedLuminaire {
        light,
        file,
        nits_per_unit,
    })
}

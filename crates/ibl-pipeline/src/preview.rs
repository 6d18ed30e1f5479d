//! Tone-mapped 8-bit previews (`ibl preview`): exposure in stops (automatic by default: the
//! log-average luminance maps to middle grey), a tone curve, then sRGB encoding
//! (`ibl_core::tonemap`).

use std::path::Path;

use ibl_core::tonemap::{Display, ToneCurve, auto_exposure_stops};
use ibl_io::{ImageFormat, WriteOptions};

use crate::error::{PipelineError, Result};

/// Writes `output` (PNG or JPEG) from the HDR `input`; `exposure_stops` `None` picks it from the
/// image. Returns the exposure used, in stops.
pub fn preview(
    input: &Path,
    output: &Path,
    exposure_stops: Option<f32>,
    curve: ToneCurve,
) -> Result<f32> {
    if let Some(e) = exposure_stops
        && !e.is_finite()
    {
        return Err(PipelineError::parameter(
            "--exposure must be a finite number of stops",
        ));
    }
    if !matches!(
        ImageFormat::from_path(output),
        Some(ImageFormat::Png | ImageFormat::Jpeg)
    ) {
        return Err(PipelineError::parameter(format!(
            "{}: a preview is written as .png or .jpg",
            output.display()
        )));
    }
    crate::output_paths::check_output_path(output, &[input])?;
    let loaded = ibl_io::read_image(input)?;
    let stops = exposure_stops.unwrap_or_else(|| auto_exposure_stops(&loaded.image));
    let options = WriteOptions {
        display: Display {
            exposure_stops: stops,
            curve,
        },
        ..Default::default()
    };
    ibl_io::write_image(output, &loaded.image, &options)?;
    Ok(stops)
}

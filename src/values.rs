//! Parsers of option values that clap's derive cannot express as a plain enum: frame presets,
//! rotations, SH windows and formats, extraction models, the camera response, exposure times,
//! circles and angle lists. Each returns the typed value or a message clap prints as a usage
//! error (exit status 2).

use std::path::PathBuf;

use ibl_capture::ball::Circle;
use ibl_core::{EulerDegrees, FramePreset};
use ibl_extract::ModelSpec;
use ibl_io::ShFileFormat;
use ibl_light::LightSource;
use ibl_sh::Window;

/// A frame preset by name: gltf, paper, threejs, blender.
pub fn frame(name: &str) -> Result<FramePreset, String> {
    FramePreset::from_name(name)
        .ok_or_else(|| format!("unknown frame `{name}` (gltf, paper, threejs, blender)"))
}

/// `Y,P,R` in degrees.
pub fn rotation(text: &str) -> Result<EulerDegrees, String> {
    let v = numbers::<f32>(text)
        .filter(|v| v.len() == 3)
        .ok_or_else(|| format!("`{text}`: expected three angles in degrees, e.g. 90,0,0"))?;
    Ok(EulerDegrees {
        yaw_deg: v[0],
        pitch_deg: v[1],
        roll_deg: v[2],
    })
}

/// Comma-separated finite numbers, or `None` when any is not one.
fn numbers<T: std::str::FromStr + Into<f64> + Copy>(text: &str) -> Option<Vec<T>> {
    let v: Vec<T> = text
        .split(',')
        .map(|p| p.trim().parse::<T>())
        .collect::<Result<_, _>>()
        .ok()?;
    v.iter().all(|x| (*x).into().is_finite()).then_some(v)
}

/// A list of angles, degrees.
#[derive(Clone, Debug, PartialEq)]
pub struct AngleList(pub Vec<f32>);

/// Degrees, comma-separated (`0,90`).
pub fn angles(text: &str) -> Result<AngleList, String> {
    numbers::<f32>(text)
        .map(AngleList)
        .ok_or_else(|| format!("`{text}`: expected degrees, e.g. 0,90"))
}

/// `x,y,r` in pixels (radius positive).
pub fn circle(text: &str) -> Result<Circle, String> {
    match numbers::<f64>(text).as_deref() {
        Some(&[cx, cy, r]) if r > 0.0 => Ok(Circle { cx, cy, r }),
        _ => Err(format!("`{text}`: expected x,y,r in pixels")),
    }
}

/// Exposure times, seconds.
#[derive(Clone, Debug, PartialEq)]
pub struct ExposureList(pub Vec<f64>);

/// Exposure times in seconds, numbers or fractions (`1/250,1/60,0.25`).
pub fn exposure_times(text: &str) -> Result<ExposureList, String> {
    ibl_io::photo::parse_exposure_times(text).map(ExposureList)
}

/// An SH window: none, lanczos or hann.
pub fn window(name: &str) -> Result<Window, String> {
    name.parse()
}

/// An SH exchange format by name.
pub fn sh_format(name: &str) -> Result<ShFileFormat, String> {
    ShFileFormat::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = ShFileFormat::ALL.iter().map(|f| f.name()).collect();
        format!(
            "{name}: unknown SH format (expected one of: {})",
            names.join(", ")
        )
    })
}

/// A light source: an extraction method or `sun`.
pub fn light_source(name: &str) -> Result<LightSource, String> {
    name.parse()
        .map_err(|e: ibl_light::MethodError| e.to_string())
}

/// A list of lighting models, in order, without repeats.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelList(pub Vec<ModelSpec>);

/// `all` or a comma-separated list of models (methods, `sun`, `<lights>+sh<B>`, `sh<B>`).
pub fn models(list: &str) -> Result<ModelList, String> {
    ibl_pipeline::eval::parse_methods(list)
        .map(ModelList)
        .map_err(|e| e.to_string())
}

/// How the camera's response is known: `recover`, `linear` or a CSV file.
#[derive(Clone, Debug, PartialEq)]
pub enum ResponseArg {
    /// Recovered from the exposures.
    Recover,
    /// Linear.
    Linear,
    /// A curve file.
    File(PathBuf),
}

/// Parses `--response`.
pub fn response(text: &str) -> Result<ResponseArg, String> {
    Ok(match text {
        "recover" => ResponseArg::Recover,
        "linear" => ResponseArg::Linear,
        file => ResponseArg::File(PathBuf::from(file)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_parse_or_say_what_they_expect() {
        assert_eq!(rotation("90, 0,-5").map(|r| r.roll_deg), Ok(-5.0));
        assert!(rotation("90,0").is_err() && rotation("a,b,c").is_err());
        assert!(rotation("inf,0,0").is_err());
        assert_eq!(angles("0,90"), Ok(AngleList(vec![0.0, 90.0])));
        assert_eq!(circle("1,2,3").map(|c| c.r), Ok(3.0));
        assert!(circle("1,2,0").is_err() && circle("1,2").is_err());
        assert!(frame("blender").is_ok() && frame("maya").is_err());
        assert_eq!(
            response("curve.csv"),
            Ok(ResponseArg::File("curve.csv".into()))
        );
    }
}

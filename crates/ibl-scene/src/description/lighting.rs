//! `[lighting]`: the approximation the `lights` and `hybrid` modes use: the extraction method
//! (an [`ibl_light::LightSource`]: a method name or `sun`) and light count, or a light file; the
//! shadows; the hybrid ambient's SH bands and occlusion rays.

use std::path::PathBuf;

use ibl_light::{LightSource, Method};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::field::{DescriptionError, invalid};
use super::render::MAX_SPP;

/// `[lighting]`: the approximation used by the `lights` and `hybrid` modes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightingDescription {
    /// Extraction method (`ibl lights --method` names, or `sun`). Default `median-cut`.
    #[serde(
        default = "default_method",
        serialize_with = "method_name",
        deserialize_with = "method_from_name"
    )]
    pub method: LightSource,
    /// Number of lights. Default 16.
    #[serde(default = "default_lights")]
    pub lights: u32,
    /// A light file (`ibl lights` JSON) to use instead of extracting, relative to the scene file.
    pub lights_file: Option<PathBuf>,
    /// `hard` or `soft` (each light a cone of its own solid angle). Default `soft`.
    #[serde(default)]
    pub shadows: ShadowKind,
    /// Samples per pixel of the `lights` and `hybrid` modes (antialiasing; each sample evaluates
    /// every light once, its soft-shadow cone stratified across the samples). Default 4.
    #[serde(default = "default_lights_spp")]
    pub spp: u32,
    /// Adaptive antialiasing (after Mitchell 1987): every pixel takes one sample first, and only
    /// pixels whose first sample differs from its 3 x 3 neighbourhood's (a silhouette, a
    /// penumbra, a change of surface) take the rest of `spp`. Default `true`; `false` gives
    /// every pixel all `spp` samples.
    #[serde(default = "default_adaptive")]
    pub adaptive: bool,
    /// The deviation `|value - mean| / (value + mean)` of a pixel's first sample from its
    /// neighbours' mean, per channel, above which an adaptive pixel takes all `spp` samples.
    /// Default 0.02, in `(0, 1]`.
    #[serde(default = "default_adaptive_contrast")]
    pub adaptive_contrast: f32,
    /// SH bands of the hybrid ambient that its occlusion rays read (a surface nothing occludes
    /// gets 16). Default 7: the rays' bands 3 and 4 carry the lights' own error where an
    /// occluder hides part of the sky, and with each side of the horizon read apart the bands
    /// up to 6 pay too (docs/RENDERING.md, "The hybrid's bands", "The ambient's two band
    /// counts" and "The ambient at the horizon").
    #[serde(default = "default_bands")]
    pub ambient_bands: u32,
    /// Occlusion rays per shading point and sample (hybrid). Default 4.
    #[serde(default = "default_ao")]
    pub ao_samples: u32,
}

fn default_method() -> LightSource {
    LightSource::Method(Method::MedianCut)
}

fn method_name<S: Serializer>(method: &LightSource, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(method.name())
}

fn method_from_name<'de, D: Deserializer<'de>>(d: D) -> Result<LightSource, D::Error> {
    let name = String::deserialize(d)?;
    name.parse().map_err(serde::de::Error::custom)
}
fn default_lights() -> u32 {
    16
}
fn default_lights_spp() -> u32 {
    4
}
fn default_adaptive() -> bool {
    true
}
fn default_adaptive_contrast() -> f32 {
    0.02
}
fn default_bands() -> u32 {
    7
}
fn default_ao() -> u32 {
    4
}

impl Default for LightingDescription {
    fn default() -> Self {
        LightingDescription {
            method: default_method(),
            lights: default_lights(),
            lights_file: None,
            shadows: ShadowKind::default(),
            spp: default_lights_spp(),
            adaptive: default_adaptive(),
            adaptive_contrast: default_adaptive_contrast(),
            ambient_bands: default_bands(),
            ao_samples: default_ao(),
        }
    }
}

/// Shadow kinds of the `lights` and `hybrid` modes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShadowKind {
    /// One shadow ray towards each light's direction.
    Hard,
    /// Shadow rays spread over a cone of the light's own solid angle.
    #[default]
    Soft,
}

impl ShadowKind {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ShadowKind::Hard => "hard",
            ShadowKind::Soft => "soft",
        }
    }
}

impl LightingDescription {
    /// Checks the counts against their ranges.
    pub(crate) fn validate(&self) -> Result<(), DescriptionError> {
        if !(1..=4096).contains(&self.lights) {
            return Err(invalid(
                "lighting.lights",
                format!("{} is not in 1..=4096", self.lights),
            ));
        }
        if !(1..=MAX_SPP).contains(&self.spp) {
            return Err(invalid(
                "lighting.spp",
                format!("{} is not in 1..={MAX_SPP}", self.spp),
            ));
        }
        if !(self.adaptive_contrast > 0.0 && self.adaptive_contrast <= 1.0) {
            return Err(invalid(
                "lighting.adaptive_contrast",
                format!("{} is not in (0, 1]", self.adaptive_contrast),
            ));
        }
        if !(1..=16).contains(&self.ambient_bands) {
            return Err(invalid(
                "lighting.ambient_bands",
                format!("{} is not in 1..=16", self.ambient_bands),
            ));
        }
        if !(1..=1024).contains(&self.ao_samples) {
            return Err(invalid(
                "lighting.ao_samples",
                format!("{} is not in 1..=1024", self.ao_samples),
            ));
        }
        Ok(())
    }
}

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
    /// gets 16): a count in 1..=16, or `"auto"` (the default), which grows with the occlusion
    /// rays a pixel traces ([`AmbientBands::resolve`]).
    #[serde(default)]
    pub ambient_bands: AmbientBands,
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
            ambient_bands: AmbientBands::Auto,
            ao_samples: default_ao(),
        }
    }
}

/// Most occlusion rays per shading point and sample (`ao_samples`).
pub const MAX_AO_SAMPLES: u32 = 1024;

/// Largest `ambient_bands` count.
pub const MAX_AMBIENT_BANDS: u32 = 16;

/// `[lighting] ambient_bands`: how many SH bands of the hybrid ambient its occlusion rays read.
///
/// The rays' bands trade bias for noise. More bands carry more of what the lights miss where an
/// occluder hides part of the sky (less bias), but each ray reads a rougher function, so a
/// pixel's few rays scatter more (more noise). Measured on the render study's two scenes
/// (docs/RENDERING.md, "How many bands the rays read"), the best count grows by about one band
/// each time a pixel's occlusion rays double: 3 bands at 4 samples of 4 rays, 5 at 16
/// samples, 7 at 64, and no better beyond 7 at 256.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AmbientBands {
    /// Chosen from the rays a pixel traces ([`AmbientBands::resolve`]).
    #[default]
    Auto,
    /// This many bands, in 1..=[`MAX_AMBIENT_BANDS`].
    Fixed(u32),
}

/// Fewest and most bands [`AmbientBands::Auto`] gives.
pub const AUTO_AMBIENT_BANDS: std::ops::RangeInclusive<u32> = 3..=7;

impl AmbientBands {
    /// The bands the rays read in a render of `spp` samples per pixel with `rays` occlusion
    /// rays per sample: a fixed count as it is; `Auto` gives `log2(spp rays) - 1` rounded down
    /// (one band more each time the pixel's rays double), within [`AUTO_AMBIENT_BANDS`].
    pub fn resolve(self, spp: u32, rays: u32) -> usize {
        match self {
            AmbientBands::Fixed(bands) => bands as usize,
            AmbientBands::Auto => {
                let pixel_rays = u64::from(spp.max(1)) * u64::from(rays.max(1));
                let bands = pixel_rays.ilog2().saturating_sub(1);
                bands.clamp(*AUTO_AMBIENT_BANDS.start(), *AUTO_AMBIENT_BANDS.end()) as usize
            }
        }
    }

    /// `Ok` for `auto` and a count in 1..=[`MAX_AMBIENT_BANDS`]; otherwise why not, for the
    /// caller to prefix with the field or option that gave it.
    pub fn check(self) -> Result<(), String> {
        match self {
            AmbientBands::Fixed(bands) if !(1..=MAX_AMBIENT_BANDS).contains(&bands) => Err(
                format!("{bands} is not in 1..={MAX_AMBIENT_BANDS} (or \"auto\")"),
            ),
            _ => Ok(()),
        }
    }

    /// `auto` or the count, as files and the command line write it.
    pub fn name(self) -> String {
        match self {
            AmbientBands::Auto => "auto".to_owned(),
            AmbientBands::Fixed(bands) => bands.to_string(),
        }
    }
}

impl std::str::FromStr for AmbientBands {
    type Err = String;

    /// `auto` or a count in 1..=[`MAX_AMBIENT_BANDS`].
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.trim().eq_ignore_ascii_case("auto") {
            return Ok(AmbientBands::Auto);
        }
        match s.trim().parse::<u32>() {
            Ok(bands) if AmbientBands::Fixed(bands).check().is_ok() => {
                Ok(AmbientBands::Fixed(bands))
            }
            _ => Err(format!(
                "'{s}' is not \"auto\" or a band count in 1..={MAX_AMBIENT_BANDS}"
            )),
        }
    }
}

/// `Ok` for a count of occlusion rays per sample in 1..=[`MAX_AO_SAMPLES`]; otherwise why not,
/// for the caller to prefix with the field or option that gave it.
pub fn check_occlusion_rays(rays: u32) -> Result<(), String> {
    if (1..=MAX_AO_SAMPLES).contains(&rays) {
        Ok(())
    } else {
        Err(format!("{rays} is not in 1..={MAX_AO_SAMPLES}"))
    }
}

impl Serialize for AmbientBands {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            AmbientBands::Auto => s.serialize_str("auto"),
            AmbientBands::Fixed(bands) => s.serialize_u32(*bands),
        }
    }
}

impl<'de> Deserialize<'de> for AmbientBands {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        /// What a file may hold: a count or a word.
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Written {
            Count(i64),
            Word(String),
        }
        match Written::deserialize(d)? {
            // The range is checked with the description's other counts (`validate`).
            Written::Count(n) => u32::try_from(n).map(AmbientBands::Fixed).map_err(|_| {
                serde::de::Error::custom(format!("{n} is not in 1..={MAX_AMBIENT_BANDS}"))
            }),
            Written::Word(word) => word.parse().map_err(serde::de::Error::custom),
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
        self.ambient_bands
            .check()
            .map_err(|e| invalid("lighting.ambient_bands", e))?;
        check_occlusion_rays(self.ao_samples).map_err(|e| invalid("lighting.ao_samples", e))?;
        Ok(())
    }
}

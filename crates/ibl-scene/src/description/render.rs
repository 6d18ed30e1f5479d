//! `[render]`: the renderer's settings (mode, size, samples, bounces, seed, composite rule,
//! sampler, adaptive sampling); the command line overrides them. Limits on each setting are here.

use serde::{Deserialize, Serialize};

use super::field::{DescriptionError, invalid};

/// `[render]`: renderer settings (the command line overrides them).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderDescription {
    /// `reference`, `lights` or `hybrid`. Default `reference`.
    #[serde(default)]
    pub mode: RenderMode,
    /// Output width in pixels. Default: the probe's width (panorama) or the photo's.
    pub width: Option<u32>,
    /// Samples per pixel. Default 64.
    #[serde(default = "default_spp")]
    pub spp: u32,
    /// Maximum path length in bounces (1 = direct light only). Default 4.
    #[serde(default = "default_bounces")]
    pub bounces: u32,
    /// Random seed; a render depends only on it, never on the thread count. Default 1.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// How the objects' effect on real surfaces is composited. Default `difference`.
    #[serde(default)]
    pub composite: CompositeRule,
    /// Which random numbers the samples draw. Default `sobol`.
    #[serde(default)]
    pub sampler: SamplerKind,
    /// Adaptive sampling of the reference mode: the same paths in all, more of them where a
    /// pilot pass finds noise, still unbiased (`ibl-render`'s `sample_allocation`). Default
    /// false.
    #[serde(default)]
    pub adaptive_sampling: bool,
}

/// Which random numbers a render's samples draw (every mode).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SamplerKind {
    /// Owen-scrambled Sobol points (low discrepancy): each pair of numbers a sample draws is
    /// stratified across the pixel's samples.
    #[default]
    Sobol,
    /// Independent uniform numbers (PCG32).
    Independent,
}

impl SamplerKind {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Sobol => "sobol",
            SamplerKind::Independent => "independent",
        }
    }
}

/// How differential rendering adds the objects' effect on real surfaces to the background `B`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CompositeRule {
    /// `B + (with - without)` (Debevec 1998): exact when the local scene's albedo matches the
    /// photographed surface; a surface darker than modelled can clip to black in a shadow.
    #[default]
    Difference,
    /// `B * with / without`: the same as `difference` with the albedo estimated per pixel as
    /// `rho = pi B / E` (Grosch 2005, section 3.2), so shadows keep the photographed texture
    /// and never clip. Falls back to `difference` where `without` is 0.
    Ratio,
}

impl CompositeRule {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            CompositeRule::Difference => "difference",
            CompositeRule::Ratio => "ratio",
        }
    }
}

fn default_spp() -> u32 {
    64
}
fn default_bounces() -> u32 {
    4
}
fn default_seed() -> u64 {
    1
}

impl Default for RenderDescription {
    fn default() -> Self {
        RenderDescription {
            mode: RenderMode::default(),
            width: None,
            spp: default_spp(),
            bounces: default_bounces(),
            seed: default_seed(),
            composite: CompositeRule::default(),
            sampler: SamplerKind::default(),
            adaptive_sampling: false,
        }
    }
}

/// How the scene is lit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RenderMode {
    /// Path tracing of the full probe, importance-sampled, MIS with the BSDF.
    #[default]
    Reference,
    /// Directional lights with shadows.
    Lights,
    /// Important lights with shadows plus an SH ambient with ambient occlusion.
    Hybrid,
}

impl RenderMode {
    /// The mode [`RenderMode::name`] names.
    pub fn from_name(name: &str) -> Option<RenderMode> {
        [
            RenderMode::Reference,
            RenderMode::Lights,
            RenderMode::Hybrid,
        ]
        .into_iter()
        .find(|m| m.name() == name)
    }

    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            RenderMode::Reference => "reference",
            RenderMode::Lights => "lights",
            RenderMode::Hybrid => "hybrid",
        }
    }
}

/// Largest accepted output width, pixels.
pub const MAX_WIDTH: u32 = 16384;
/// Largest accepted samples per pixel.
pub const MAX_SPP: u32 = 1 << 16;
/// Largest accepted bounce count.
pub const MAX_BOUNCES: u32 = 64;

impl RenderDescription {
    /// Checks width, samples and bounces against the limits.
    pub(crate) fn validate(&self) -> Result<(), DescriptionError> {
        if let Some(w) = self.width
            && !(2..=MAX_WIDTH).contains(&w)
        {
            return Err(invalid(
                "render.width",
                format!("{w} is not in 2..={MAX_WIDTH}"),
            ));
        }
        if !(1..=MAX_SPP).contains(&self.spp) {
            return Err(invalid(
                "render.spp",
                format!("{} is not in 1..={MAX_SPP}", self.spp),
            ));
        }
        if !(1..=MAX_BOUNCES).contains(&self.bounces) {
            return Err(invalid(
                "render.bounces",
                format!("{} is not in 1..={MAX_BOUNCES}", self.bounces),
            ));
        }
        Ok(())
    }
}

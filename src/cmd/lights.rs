//! `ibl lights`: approximate a lat-long probe by N directional lights with any extraction method
//! and write them as JSON, glTF, Mitsuba 3 or pbrt-v4 (`ibl_pipeline::lights`).

use std::path::PathBuf;

use clap::{ArgGroup, Args, ValueEnum};
use ibl_core::FramePreset;
use ibl_extract::{ExtractOptions, FitDomain};
use ibl_light::Method;
use ibl_pipeline::lights::{LightsOptions, lights};

use crate::probe_arg::ProbeMappingArgs;
use crate::progress::Bars;
use crate::values;

/// Extraction methods, as named on the command line (the same names as [`Method::name`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Median cut (Debevec 2005): 2^K regions of equal energy, a light at each energy centroid.
    MedianCut,
    /// Median cut for any N: cut next the region whose cut most lowers the error bound.
    AdaptiveMedianCut,
    /// LightGen (Cohen & Debevec 2001): weighted k-means clusters of the probe's energy, any N.
    #[value(name = "lightgen")]
    LightGen,
    /// Variance minimisation (Viriyothai & Debevec 2009): cuts of least energy spread, any N.
    VarianceMinimization,
    /// Irradiance optimisation (Madsen et al. 2003): lights fitted to the irradiance, any N.
    IrradianceOptimization,
}

/// What irradiance optimisation fits (`--fit-domain`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FitDomainArg {
    /// The lights above and below the horizon fitted apart, each to its hemisphere's
    /// irradiance: a ground plane then shadows the probe's lower share only (for rendering).
    Hemispheres,
    /// One fit to the whole sphere's irradiance (the paper's; lowest unshadowed error).
    Sphere,
}

impl FitDomainArg {
    /// The library's choice.
    pub fn domain(self) -> FitDomain {
        match self {
            FitDomainArg::Hemispheres => FitDomain::Hemispheres,
            FitDomainArg::Sphere => FitDomain::Sphere,
        }
    }
}

impl MethodArg {
    /// The library's method.
    pub fn method(self) -> Method {
        match self {
            MethodArg::MedianCut => Method::MedianCut,
            MethodArg::AdaptiveMedianCut => Method::AdaptiveMedianCut,
            MethodArg::LightGen => Method::LightGen,
            MethodArg::VarianceMinimization => Method::VarianceMinimization,
            MethodArg::IrradianceOptimization => Method::IrradianceOptimization,
        }
    }
}

/// Arguments of `ibl lights`.
#[derive(Args)]
#[command(
    group(ArgGroup::new("outputs").required(true).multiple(true).args(["output", "overlay"])),
    after_help = "\
The format of each -o file follows its extension:
  .json         iblkit light set (direction, radiance, solid angle, I = L A, region per light)
  .gltf, .glb   glTF 2.0 with KHR_lights_punctual directional lights (intensity in lux)
  .xml          Mitsuba 3 scene with one directional emitter per light (irradiance I)
  .pbrt         pbrt-v4 fragment with one distant light per light (rgb L = I)
With --ambient-sh B the light set becomes hybrid lighting: the lights plus an SH ambient of B
bands carrying the rest of the probe (total power conserved), written into the .json file
(`ambient`); the other formats have no place for it (use `ibl sh` for the probe's SH).
Directions are written in the --frame preset's axes in every format (glTF itself is defined in
the gltf frame). The overlay is drawn on the probe as stored, whatever the frame.

Examples:
  ibl lights assets/probes/sky.exr -n 16 -o sky-16.json
  ibl lights probe.hdr -n 64 -o lights.gltf --overlay lights.png
  ibl lights probe.exr -n 12 --method adaptive-median-cut -o scene.xml -o scene.pbrt
  ibl lights probe.exr -n 8 --method lightgen --seed 7 -o sun.glb --lux-per-unit 20
  ibl lights probe.hdr -n 32 -o lights.json --frame blender --json
  ibl lights sky.exr -n 1 --method irradiance-optimization --ambient-sh 3 -o sun+sh9.json
  ibl lights sky.exr -n 32 --method irradiance-optimization --fit-domain sphere -o paper.json"
)]
pub struct LightsArgs {
    /// The probe (.exr, .hdr, .pfm, .png, .jpg), lat-long or any mapping `--mapping` names.
    pub probe: PathBuf,
    #[command(flatten)]
    pub probe_mapping: ProbeMappingArgs,
    /// Number of lights (median cut: a power of two; every other method: any N >= 1).
    #[arg(short = 'n', long, value_name = "N")]
    pub count: usize,
    /// Extraction method.
    #[arg(long, value_enum, default_value = "median-cut")]
    pub method: MethodArg,
    /// Seed of the methods' random choices (lightgen, irradiance-optimization); the same seed
    /// gives the same lights.
    #[arg(long, default_value_t = ExtractOptions::default().seed, value_name = "SEED")]
    pub seed: u64,
    /// Irradiance optimisation only: fit the lights above and below the horizon apart
    /// (`hemispheres`, so a ground plane shadows the right share, as `ibl render` does) or the
    /// whole sphere at once (`sphere`, the paper's fit: 2 to 8 times lower unshadowed irradiance
    /// error, as `ibl eval` scores it).
    #[arg(long, value_enum, default_value = "hemispheres", value_name = "DOMAIN")]
    pub fit_domain: FitDomainArg,
    /// Output file, format by extension: .json, .gltf, .glb, .xml (Mitsuba 3), .pbrt (pbrt-v4).
    /// Repeat to write several formats from one extraction.
    #[arg(short = 'o', long, value_name = "FILE")]
    pub output: Vec<PathBuf>,
    /// Frame of the written directions: gltf (ours), paper, threejs, blender.
    #[arg(long, default_value = "gltf", value_name = "PRESET", value_parser = values::frame)]
    pub frame: FramePreset,
    /// glTF only: lux per unit of a light's luminance Y(I), I = L A. The default 1 reads the
    /// probe's values as cd/m^2; a light's glTF intensity is LUX x max(I), its colour I / max(I).
    #[arg(long, default_value_t = 1.0, value_name = "LUX")]
    pub lux_per_unit: f64,
    /// Also write a PNG of the tone-mapped probe with each light's region outlined and its
    /// direction marked (bigger markers for stronger lights), enlarged to at least 1024 pixels wide.
    #[arg(long, value_name = "FILE.png")]
    pub overlay: Option<PathBuf>,
    /// Hybrid lighting: add an SH ambient of this many bands (3 = SH9) that carries the rest of
    /// the probe; written to .json outputs only.
    #[arg(long, value_name = "B")]
    pub ambient_sh: Option<usize>,
    /// Print a JSON summary (method, lights made and asked, seconds, power, outputs) on stdout
    /// instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs `ibl lights`.
pub fn run(args: &LightsArgs) -> anyhow::Result<()> {
    let options = LightsOptions {
        probe: args.probe.clone(),
        mapping: args.probe_mapping.mapping()?,
        count: args.count,
        method: args.method.method(),
        seed: args.seed,
        fit_domain: args.fit_domain.domain(),
        outputs: args.output.clone(),
        frame: args.frame,
        lux_per_unit: args.lux_per_unit,
        overlay: args.overlay.clone(),
        ambient_sh: args.ambient_sh,
    };
    let result = lights(&options, &Bars::default())?;
    let set = &result.set;
    if args.json {
        let summary = serde_json::json!({
            "probe": args.probe.display().to_string(),
            "probe_input": result.probe,
            "method": options.method.name(),
            "n": set.lights.len(),
            "requested": args.count,
            "seed": args.seed,
            "frame": args.frame.name(),
            "seconds": result.seconds,
            "total_power": set.total_power(),
            "probe_power": result.probe_power,
            "parameters": result.parameters,
            "ambient_sh_bands": args.ambient_sh,
            "outputs": args.output.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            "overlay": args.overlay.as_ref().map(|p| p.display().to_string()),
        });
        println!("{summary:#}");
    } else {
        print!("{}", result.summary_text());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_names_match_the_library() {
        let args: Vec<MethodArg> = MethodArg::value_variants().to_vec();
        assert_eq!(args.len(), Method::ALL.len());
        for (arg, method) in args.iter().zip(Method::ALL) {
            assert_eq!(arg.method(), method);
            let name = arg.to_possible_value().map(|v| v.get_name().to_string());
            assert_eq!(name.as_deref(), Some(method.name()));
        }
    }
}

//! `ibl render`: virtual objects lit by a light probe, composited into the probe panorama or a
//! photograph by differential rendering, in the reference, lights or hybrid mode
//! (`ibl_pipeline::render`). Writes the composite as EXR plus a tone-mapped PNG beside it, and on
//! request the layers (with and without the objects, object coverage).

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use ibl_light::LightSource;
use ibl_pipeline::render::{Layers, RenderJob, View, render_scene};
use ibl_scene::{AmbientBands, RenderMode, SamplerKind, ShadowKind};

use crate::progress::Bars;
use crate::values;

/// Lighting modes on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// Path tracing of the full probe (importance sampling + MIS), several bounces.
    Reference,
    /// Directional lights with shadows.
    Lights,
    /// Important lights with shadows plus an SH ambient with ambient occlusion.
    Hybrid,
}

/// Shadow kinds on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ShadowArg {
    /// One shadow ray along each light's direction.
    Hard,
    /// Shadow rays over a cone of each light's solid angle.
    Soft,
}

/// Samplers on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SamplerArg {
    /// Owen-scrambled Sobol points (low discrepancy).
    Sobol,
    /// Independent uniform random numbers.
    Independent,
}

/// Arguments of `ibl render`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl render assets/scenes/bunny-sky.toml -o bunny.exr                       reference, 64 spp
  ibl render assets/scenes/bunny-sky.toml -o pano.exr --panorama --width 1024  whole panorama
  ibl render assets/scenes/bunny-sky.toml -o b16.exr --mode lights -n 16 --method lightgen
  ibl render scene.toml -o b.exr --mode lights --lights lights.json --shadows soft
  ibl render scene.toml -o h.exr --mode hybrid --method sun -n 1 --spp 16 --json
  ibl render scene.toml -o h.exr --mode hybrid --spp 64 --ambient-bands 9 --ao-rays 8
  ibl render scene.toml -o b.exr --width 640 --spp 256 --layers              + with/without/alpha
  ibl render scene.toml -o b.exr --sampler independent                       no low discrepancy
  ibl render scene.toml -o b.exr --spp 64 --adaptive-sampling      64 spp on average, where noisy

Writes OUT (EXR, or any format ibl writes) and OUT's .png preview, tone-mapped with the exposure
of the background; --layers adds OUT-with, OUT-without (local scene with and without the objects)
and OUT-alpha (the objects' pixel coverage). Scene files: docs/SCENES.md.")]
pub struct RenderArgs {
    /// Scene file (TOML, docs/SCENES.md).
    pub scene: PathBuf,
    /// Output image (.exr recommended; .hdr, .pfm also work).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: PathBuf,
    /// Lighting mode (default: the scene's `[render] mode`).
    #[arg(long, value_enum)]
    pub mode: Option<ModeArg>,
    /// Light file (`ibl lights ... -o lights.json`) to use instead of extracting lights.
    #[arg(long, value_name = "FILE")]
    pub lights: Option<PathBuf>,
    /// Extraction method for lights/hybrid (median-cut, adaptive-median-cut, lightgen,
    /// variance-minimization, irradiance-optimization, sun).
    #[arg(long, value_name = "METHOD", value_parser = values::light_source)]
    pub method: Option<LightSource>,
    /// Number of lights to extract.
    #[arg(short = 'n', long = "n", value_name = "N")]
    pub n: Option<usize>,
    /// Hard or soft shadows (lights and hybrid).
    #[arg(long, value_enum)]
    pub shadows: Option<ShadowArg>,
    /// Samples per pixel (default: the scene's `[render] spp` for the reference, `[lighting] spp`
    /// for the lights and hybrid modes).
    #[arg(long, value_name = "N")]
    pub spp: Option<u32>,
    /// Random numbers of the samples (default: the scene's `[render] sampler`, sobol).
    #[arg(long, value_enum)]
    pub sampler: Option<SamplerArg>,
    /// SH bands the hybrid ambient's occlusion rays read: `auto` (3 at 4 samples of 4 rays, 5 at
    /// 16, 7 from 64) or 1..=16 (default: the scene's `[lighting] ambient_bands`).
    #[arg(long, value_name = "auto|B", value_parser = str::parse::<AmbientBands>)]
    pub ambient_bands: Option<AmbientBands>,
    /// Occlusion rays per shading point and sample (hybrid; default: `[lighting] ao_samples`).
    #[arg(long, value_name = "N")]
    pub ao_rays: Option<u32>,
    /// Give every pixel all its samples in the lights and hybrid modes (default: the scene's
    /// `[lighting] adaptive`, on: one sample first, the rest only where neighbours differ).
    #[arg(long)]
    pub no_adaptive: bool,
    /// Reference: --spp paths per pixel on average, more where a pilot pass finds noise, without
    /// bias (default: the scene's `[render] adaptive_sampling`, off).
    #[arg(long)]
    pub adaptive_sampling: bool,
    /// Output width in pixels (panorama: height = width / 2; photo: its aspect ratio).
    #[arg(long, value_name = "W")]
    pub width: Option<u32>,
    /// Surface vertices per path (1 = direct light only).
    #[arg(long, value_name = "N")]
    pub bounces: Option<u32>,
    /// Random seed (the image depends on it only, not on the thread count).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Render the whole panorama from the probe's centre, not the `[camera]` (panoramas only).
    #[arg(long)]
    pub panorama: bool,
    /// Also write the with/without-objects renders and the object coverage.
    #[arg(long)]
    pub layers: bool,
    /// Print a JSON summary (timings, rays per second, statistics) on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `ibl render`.
pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    let job = RenderJob {
        scene: args.scene.clone(),
        output: args.output.clone(),
        mode: args.mode.map(|m| match m {
            ModeArg::Reference => RenderMode::Reference,
            ModeArg::Lights => RenderMode::Lights,
            ModeArg::Hybrid => RenderMode::Hybrid,
        }),
        lights_file: args.lights.clone(),
        method: args.method,
        lights: args.n,
        shadows: args.shadows.map(|s| match s {
            ShadowArg::Hard => ShadowKind::Hard,
            ShadowArg::Soft => ShadowKind::Soft,
        }),
        spp: args.spp,
        sampler: args.sampler.map(|s| match s {
            SamplerArg::Sobol => SamplerKind::Sobol,
            SamplerArg::Independent => SamplerKind::Independent,
        }),
        ambient_bands: args.ambient_bands,
        occlusion_rays: args.ao_rays,
        no_adaptive: args.no_adaptive,
        adaptive_sampling: args.adaptive_sampling,
        width: args.width,
        bounces: args.bounces,
        seed: args.seed,
        view: if args.panorama {
            View::Panorama
        } else {
            View::SceneCamera
        },
        layers: if args.layers {
            Layers::All
        } else {
            Layers::Composite
        },
    };
    let summary = render_scene(&job, &Bars::default())?;
    if !super::print_json(args.json, &summary)? {
        println!("{summary}");
    }
    Ok(())
}

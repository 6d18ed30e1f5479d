//! `ibl prefilter`: engine-ready environment maps from one probe (what Filament's cmgen, cmft
//! and the Khronos glTF-IBL-Sampler make): the GGX-prefiltered specular mip chain as a KTX2 or
//! DDS cube map (and optionally a lat-long chain), the irradiance cube `E / pi`, spherical
//! harmonics in any tool's convention, and the split-sum DFG table: parse, one pipeline call
//! (`ibl_pipeline::prefilter`), print. `docs/PREFILTER.md` has the conventions and the roughness
//! each engine expects at each level.

use std::path::PathBuf;

use clap::Args;
use ibl_io::{ShFileFormat, TexelFormat};
use ibl_pipeline::EnvMapping;
use ibl_pipeline::prefilter::{DfgLayout, EngineTarget, PrefilterJob, prefilter};

use crate::progress::Bars;
use crate::values;

/// Arguments of `ibl prefilter`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl prefilter probe.exr -o specular.ktx2                     Khronos/glTF chain, 256 px faces
  ibl prefilter probe.exr -o env.ktx2 --target filament --irradiance irr.ktx2 --sh sh.txt \\
      --sh-format filament --dfg dfg.ktx2                      everything Filament needs
  ibl prefilter probe.hdr -o env.dds --target unity --format rgb9e5
  ibl prefilter probe.exr -o spec.ktx2 --latlong spec-ll.ktx2 --preview chain.png
  ibl prefilter --dfg brdf.png --dfg-size 256                  only the DFG table (no probe)

Targets (roughness of mip m of L levels; r = perceptual roughness):
  khronos   r = m / (L - 1), L = log2(size)     glTF-IBL-Sampler, glTF-Sample-Viewer
  bevy      r = m / (L - 1), full chain         Bevy EnvironmentMapLight
  filament  m / (L - 1) = r (2 - r), to 16 px   Filament cmgen / IndirectLight
  unity     m = 6 r (1.7 - 0.7 r), 7 levels     Unity built-in and SRP
  threejs   r from the face size, to 16 px      three.js PMREM (roughnessToMip)")]
pub struct PrefilterArgs {
    /// The probe (any mapping `ibl info` recognises; a KTX2/DDS cube is a cube map).
    pub probe: Option<PathBuf>,
    /// Mapping of the probe (default: from its shape).
    #[arg(long, value_name = "MAPPING", value_parser = mapping)]
    pub mapping: Option<EnvMapping>,
    /// The specular mip chain as a cube map (.ktx2 or .dds).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Whose roughness-per-level convention to follow: khronos, bevy, filament, unity, threejs.
    #[arg(long, default_value = "khronos", value_name = "ENGINE", value_parser = target)]
    pub target: EngineTarget,
    /// Face size of level 0 in pixels (a power of two).
    #[arg(long, default_value_t = 256, value_name = "S")]
    pub size: usize,
    /// GGX samples per texel.
    #[arg(long, default_value_t = 256, value_name = "N")]
    pub samples: usize,
    /// Texel format of the KTX2/DDS outputs: rgba16f, rgba32f or rgb9e5.
    #[arg(long, default_value = "rgba16f", value_name = "FORMAT", value_parser = texel_format)]
    pub format: TexelFormat,
    /// Also the chain as a lat-long 2D texture with mips (.ktx2 or .dds).
    #[arg(long, value_name = "FILE")]
    pub latlong: Option<PathBuf>,
    /// Width of the lat-long chain's level 0 (default: 4 x the face size).
    #[arg(long, value_name = "W")]
    pub latlong_width: Option<usize>,
    /// The irradiance cube E / pi (.ktx2/.dds cube, or an image file as a horizontal cross).
    #[arg(long, value_name = "FILE")]
    pub irradiance: Option<PathBuf>,
    /// Face size of the irradiance cube.
    #[arg(long, default_value_t = 32, value_name = "S")]
    pub irradiance_size: usize,
    /// Spherical harmonics of the probe (see --sh-format).
    #[arg(long, value_name = "FILE")]
    pub sh: Option<PathBuf>,
    /// SH convention: json (iblkit), filament, threejs, unity, webxr, arkit, gltf-ext.
    #[arg(long, default_value = "json", value_name = "FORMAT", value_parser = values::sh_format)]
    pub sh_format: ShFileFormat,
    /// SH bands (3 for every format but json).
    #[arg(long, default_value_t = 3, value_name = "B")]
    pub bands: usize,
    /// The split-sum DFG table (.ktx2/.dds as RG; .exr/.pfm/.hdr/.png as RGB with blue 0).
    #[arg(long, value_name = "FILE")]
    pub dfg: Option<PathBuf>,
    /// DFG table size in texels.
    #[arg(long, default_value_t = 128, value_name = "N")]
    pub dfg_size: usize,
    /// DFG channels: scale-bias (R = A, G = B) or multiscatter (R = B, G = A + B, Filament).
    #[arg(long, default_value = "scale-bias", value_name = "LAYOUT", value_parser = dfg_layout)]
    pub dfg_layout: DfgLayout,
    /// A tone-mapped PNG of the whole specular chain, one cube cross per level.
    #[arg(long, value_name = "FILE.png")]
    pub preview: Option<PathBuf>,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
}

fn mapping(name: &str) -> Result<EnvMapping, String> {
    EnvMapping::parse(name, 180.0).map_err(|e| e.to_string())
}

fn target(name: &str) -> Result<EngineTarget, String> {
    EngineTarget::from_name(name).ok_or_else(|| {
        format!("unknown --target `{name}` (khronos, bevy, filament, unity, threejs)")
    })
}

fn texel_format(name: &str) -> Result<TexelFormat, String> {
    TexelFormat::from_name(name)
        .filter(|f| f.channels() == 3)
        .ok_or_else(|| format!("unknown --format `{name}` (rgba16f, rgba32f, rgb9e5)"))
}

fn dfg_layout(name: &str) -> Result<DfgLayout, String> {
    DfgLayout::from_name(name)
        .ok_or_else(|| format!("unknown DFG layout `{name}` (scale-bias, multiscatter)"))
}

/// Runs `ibl prefilter`.
pub fn run(args: &PrefilterArgs) -> anyhow::Result<()> {
    let job = PrefilterJob {
        probe: args.probe.clone(),
        mapping: args.mapping,
        target: args.target,
        face_size: args.size,
        samples: args.samples,
        texel: args.format,
        output: args.output.clone(),
        latlong: args.latlong.clone(),
        latlong_width: args.latlong_width,
        irradiance: args.irradiance.clone(),
        irradiance_size: args.irradiance_size,
        sh: args.sh.clone(),
        sh_format: args.sh_format,
        bands: args.bands,
        dfg: args.dfg.clone(),
        dfg_size: args.dfg_size,
        dfg_layout: args.dfg_layout,
        preview: args.preview.clone(),
    };
    let summary = prefilter(&job, &Bars::default())?;
    if super::print_json(args.json, &summary)? {
        return Ok(());
    }
    if !summary.roughness.is_empty() {
        let levels: Vec<String> = summary
            .roughness
            .iter()
            .enumerate()
            .map(|(m, r)| format!("{}px r={r:.3}", args.size >> m))
            .collect();
        println!(
            "{} levels for {} ({} samples): {}",
            levels.len(),
            args.target.name(),
            args.samples,
            levels.join(", ")
        );
    }
    println!("prefiltered in {:.2} s", summary.seconds);
    Ok(())
}

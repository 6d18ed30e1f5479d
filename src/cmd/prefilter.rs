//! `ibl prefilter`: engine-ready environment maps from one probe (what Filament's cmgen, cmft
//! and the Khronos glTF-IBL-Sampler make): the GGX-prefiltered specular mip chain as a KTX2 or
//! DDS cube map (and optionally a lat-long chain), the irradiance cube `E / pi`, spherical
//! harmonics in any tool's convention, and the split-sum DFG table. Parse, check every output
//! path, one library call (`ibl_mapping::prefilter`), write. `docs/PREFILTER.md` has the
//! conventions and the roughness each engine expects at each level.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use ibl_io::light_file::ProbeRef;
use ibl_io::sh_file::{SH_CONVENTION, SH_FORMAT};
use ibl_io::{
    Display, ImageFormat, ShFile, ShFileFormat, ShQuantity, TexelFormat, Texture, ToneCurve,
    WriteOptions,
};
use ibl_mapping::{
    CubeLayout, DfgLayout, DfgOptions, EngineTarget, Mapping, PrefilterOptions, SpecularOptions,
};
use serde::Serialize;

use crate::envmap_files::{self, MappingArg};
use crate::failure::usage;

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
    #[arg(long, value_name = "MAPPING")]
    pub mapping: Option<String>,
    /// The specular mip chain as a cube map (.ktx2 or .dds).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Whose roughness-per-level convention to follow: khronos, bevy, filament, unity, threejs.
    #[arg(long, default_value = "khronos", value_name = "ENGINE")]
    pub target: String,
    /// Face size of level 0 in pixels (a power of two).
    #[arg(long, default_value_t = 256, value_name = "S")]
    pub size: usize,
    /// GGX samples per texel.
    #[arg(long, default_value_t = 256, value_name = "N")]
    pub samples: usize,
    /// Texel format of the KTX2/DDS outputs: rgba16f, rgba32f or rgb9e5.
    #[arg(long, default_value = "rgba16f", value_name = "FORMAT")]
    pub format: String,
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
    #[arg(long, default_value = "json", value_name = "FORMAT")]
    pub sh_format: String,
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
    #[arg(long, default_value = "scale-bias", value_name = "LAYOUT")]
    pub dfg_layout: String,
    /// A tone-mapped PNG of the whole specular chain, one cube cross per level.
    #[arg(long, value_name = "FILE.png")]
    pub preview: Option<PathBuf>,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// DFG samples per texel (1024, as Filament's cmgen; the error is under 3e-3).
const DFG_SAMPLES: usize = 1024;

/// What `--json` prints.
#[derive(Serialize)]
struct Summary {
    probe: Option<String>,
    target: Option<&'static str>,
    face_size: Option<usize>,
    samples: Option<usize>,
    format: &'static str,
    /// Perceptual roughness of each level.
    roughness: Vec<f64>,
    seconds: f64,
    outputs: Vec<String>,
}

/// Refuses an output whose folder does not exist, that is an input, or whose extension is not
/// one of `allowed` (names for the message).
fn check_output(path: &Path, inputs: &[&Path], allowed: &[ImageFormat]) -> anyhow::Result<()> {
    let format = ImageFormat::from_path(path);
    if !format.is_some_and(|f| allowed.contains(&f)) {
        let names: Vec<_> = allowed.iter().map(|f| format!(".{}", f.name())).collect();
        return Err(usage(format!(
            "{}: unsupported output format here (use {})",
            path.display(),
            names.join(", ")
        )));
    }
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(usage(format!(
            "{}: the folder {} does not exist",
            path.display(),
            dir.display()
        )));
    }
    ibl_io::ensure_output_is_not_input(path, inputs)?;
    Ok(())
}

const TEXTURES: [ImageFormat; 2] = [ImageFormat::Ktx2, ImageFormat::Dds];
const IMAGES: [ImageFormat; 6] = [
    ImageFormat::Ktx2,
    ImageFormat::Dds,
    ImageFormat::Exr,
    ImageFormat::Hdr,
    ImageFormat::Pfm,
    ImageFormat::Png,
];

/// Runs `ibl prefilter`.
pub fn run(args: &PrefilterArgs) -> anyhow::Result<()> {
    let target = EngineTarget::from_name(&args.target).ok_or_else(|| {
        usage(format!(
            "unknown --target `{}` (khronos, bevy, filament, unity, threejs)",
            args.target
        ))
    })?;
    let texel = TexelFormat::from_name(&args.format)
        .filter(|f| f.channels() == 3)
        .ok_or_else(|| {
            usage(format!(
                "unknown --format `{}` (rgba16f, rgba32f, rgb9e5)",
                args.format
            ))
        })?;
    let dfg_layout = match args.dfg_layout.as_str() {
        "scale-bias" => DfgLayout::ScaleBias,
        "multiscatter" | "multi-scatter" => DfgLayout::MultiScatter,
        other => {
            return Err(usage(format!(
                "unknown --dfg-layout `{other}` (scale-bias, multiscatter)"
            )));
        }
    };
    let sh_format = ShFileFormat::from_name(&args.sh_format)
        .ok_or_else(|| usage(format!("unknown --sh-format `{}`", args.sh_format)))?;
    if args.sh.is_some() && sh_format != ShFileFormat::Json && args.bands != 3 {
        return Err(usage(format!(
            "--sh-format {} holds 3 bands; use --bands 3 or --sh-format json",
            sh_format.name()
        )));
    }
    let wants_probe = args.output.is_some()
        || args.latlong.is_some()
        || args.irradiance.is_some()
        || args.sh.is_some()
        || args.preview.is_some();
    if !wants_probe && args.dfg.is_none() {
        return Err(usage(
            "say what to write: -o FILE (specular cube), --latlong, --irradiance, --sh, --dfg or --preview",
        ));
    }
    if wants_probe && args.probe.is_none() {
        return Err(usage("these outputs need a probe: ibl prefilter PROBE ..."));
    }
    if args.latlong_width.is_some() && args.latlong.is_none() {
        return Err(usage("--latlong-width needs --latlong FILE"));
    }
    let inputs: Vec<&Path> = args.probe.iter().map(PathBuf::as_path).collect();
    let mut named: Vec<&Path> = Vec::new();
    for (path, allowed) in [
        (&args.output, &TEXTURES[..]),
        (&args.latlong, &TEXTURES[..]),
        (&args.irradiance, &IMAGES[..]),
        (&args.dfg, &IMAGES[..]),
        (&args.preview, &[ImageFormat::Png][..]),
    ] {
        if let Some(p) = path {
            check_output(p, &inputs, allowed)?;
            if named.contains(&p.as_path()) {
                return Err(usage(format!("{} is named twice", p.display())));
            }
            named.push(p);
        }
    }
    if let Some(p) = &args.sh {
        let dir = p
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        if !dir.is_dir() {
            return Err(usage(format!(
                "{}: the folder {} does not exist",
                p.display(),
                dir.display()
            )));
        }
        ibl_io::ensure_output_is_not_input(p, &inputs)?;
    }

    let specular_wanted = args.output.is_some() || args.latlong.is_some() || args.preview.is_some();
    let options = PrefilterOptions {
        specular: specular_wanted.then_some(SpecularOptions {
            face_size: args.size,
            target,
            samples: args.samples,
            latlong_width: args
                .latlong
                .as_ref()
                .map(|_| args.latlong_width.unwrap_or(4 * args.size)),
        }),
        irradiance_face: args.irradiance.as_ref().map(|_| args.irradiance_size),
        sh_bands: args.sh.as_ref().map(|_| args.bands),
        dfg: args.dfg.as_ref().map(|_| DfgOptions {
            size: args.dfg_size,
            samples: DFG_SAMPLES,
            layout: dfg_layout,
        }),
    };
    ibl_mapping::prefilter::check_options(&options).map_err(|e| usage(e.to_string()))?;

    let start = Instant::now();
    let (image, mapping) = match &args.probe {
        Some(path) if wants_probe => {
            let mapping = args
                .mapping
                .as_deref()
                .map(|m| MappingArg::parse(m, 180.0))
                .transpose()?;
            let env = envmap_files::load(path, mapping)?;
            crate::cmd::convert::report_clamped(&env);
            (env.image, env.mapping)
        }
        // Only the DFG table: no probe is read.
        _ => (
            ibl_core::Image::filled(2, 1, ibl_core::Rgb::ZERO),
            Mapping::LatLong,
        ),
    };
    let bar = crate::progress::bar("prefiltering", 1);
    let maps = ibl_mapping::prefilter(
        &image,
        mapping,
        &options,
        &crate::progress::rows_callback(&bar),
    )
    .with_context(|| {
        args.probe
            .as_ref()
            .map_or("prefilter".to_string(), |p| p.display().to_string())
    })?;
    bar.finish_and_clear();

    let mut outputs = Vec::new();
    let mut roughness = Vec::new();
    if let Some(chain) = &maps.specular {
        roughness.clone_from(&chain.roughness);
        if let Some(out) = &args.output {
            ibl_io::write_texture(out, &Texture::from_cube_levels(&chain.cube), texel)?;
            outputs.push(out.display().to_string());
        }
        if let Some(out) = &args.latlong {
            ibl_io::write_texture(out, &Texture::from_image_levels(&chain.latlong), texel)?;
            outputs.push(out.display().to_string());
        }
        if let Some(out) = &args.preview {
            let sheet = chain.contact_sheet(64)?;
            let display = Display {
                exposure_stops: ibl_io::tonemap::auto_exposure_stops(&sheet),
                curve: ToneCurve::AcesFilmic,
            };
            let opts = WriteOptions {
                display,
                ..WriteOptions::default()
            };
            ibl_io::write_image(out, &sheet, &opts)?;
            outputs.push(out.display().to_string());
        }
    }
    if let (Some(out), Some(faces)) = (&args.irradiance, &maps.irradiance) {
        if ImageFormat::from_path(out).is_some_and(ImageFormat::is_texture) {
            ibl_io::write_texture(
                out,
                &Texture::from_cube_levels(std::slice::from_ref(faces)),
                texel,
            )?;
        } else {
            let cross = ibl_mapping::join_cube_faces(faces, CubeLayout::HorizontalCross)?;
            envmap_files::save(
                out,
                &cross,
                MappingArg::Single(Mapping::Cube(CubeLayout::HorizontalCross)),
                &WriteOptions::default(),
                &inputs,
            )?;
        }
        outputs.push(out.display().to_string());
    }
    if let (Some(out), Some(sh), Some(probe)) = (&args.sh, &maps.sh, &args.probe) {
        let file = ShFile {
            format: SH_FORMAT.to_string(),
            convention: SH_CONVENTION.to_string(),
            frame: "gltf".to_string(),
            quantity: ShQuantity::Radiance,
            bands: sh.bands(),
            window: "none".to_string(),
            probe: Some(ProbeRef {
                path: probe.display().to_string(),
                width: image.width(),
                height: image.height(),
                sha256: ibl_io::light_file::sha256_file(probe)?,
            }),
            coefficients: sh.coefficients().to_vec(),
        };
        ibl_io::write_sh_file(out, sh_format, &file)?;
        outputs.push(out.display().to_string());
    }
    if let (Some(out), Some(dfg)) = (&args.dfg, &maps.dfg) {
        if ImageFormat::from_path(out).is_some_and(ImageFormat::is_texture) {
            let rg = if texel == TexelFormat::Rgba32Float {
                TexelFormat::Rg32Float
            } else {
                TexelFormat::Rg16Float
            };
            ibl_io::write_texture(out, &Texture::from_rg(dfg.size, dfg.size, &dfg.texels), rg)?;
        } else {
            let img = ibl_core::Image::from_fn_par(dfg.size, dfg.size, |i, j| {
                let [r, g] = dfg.get(i, j);
                ibl_core::Rgb::new(r, g, 0.0)
            });
            // A picture of the table (PNG is sRGB-encoded, 8-bit): use KTX2, DDS or EXR for data.
            let opts = WriteOptions {
                display: Display {
                    exposure_stops: 0.0,
                    curve: ToneCurve::Clamp,
                },
                ..WriteOptions::default()
            };
            ibl_io::write_image(out, &img, &opts)?;
        }
        outputs.push(out.display().to_string());
    }
    let seconds = start.elapsed().as_secs_f64();
    let summary = Summary {
        probe: args.probe.as_ref().map(|p| p.display().to_string()),
        target: maps.specular.as_ref().map(|_| target.name()),
        face_size: maps.specular.as_ref().map(|_| args.size),
        samples: maps.specular.as_ref().map(|_| args.samples),
        format: texel.name(),
        roughness,
        seconds,
        outputs,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
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
                target.name(),
                args.samples,
                levels.join(", ")
            );
        }
        println!("prefiltered in {seconds:.2} s");
    }
    for o in &summary.outputs {
        eprintln!("wrote {o}");
    }
    Ok(())
}

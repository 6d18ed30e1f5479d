//! `ibl lights`: approximate a lat-long probe by N directional lights with any extraction method
//! (Madsen & Laursen 2006) and write them as the JSON light set of CONVENTIONS section 7, glTF 2.0
//! (`KHR_lights_punctual`, `.gltf`/`.glb`), a Mitsuba 3 scene or a pbrt-v4 fragment
//! (`ibl_io::light_export`), directions in any frame preset; optionally a picture of the regions
//! and lights on the tone-mapped probe (`ibl_eval::overlay`, the paper's Figure 3).
//!
//! Everything is checked before the probe is read (flags, output extensions, outputs naming an
//! input), so a mistake costs no extraction time; every file is written atomically.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use clap::{ArgGroup, Args, ValueEnum};
use ibl_core::FramePreset;
use ibl_core::rgb::Rgb64;
use ibl_extract::{ExtractOptions, LightSet, Method};
use ibl_io::LightFormat;
use ibl_io::light_file::{
    AmbientRecord, LIGHTS_FORMAT, LightRecord, LightsFile, MethodRef, ProbeRef, RegionRecord,
};
use ibl_mapping::Mapping;

use crate::cmd::convert::parse_frame;
use crate::envmap_files::{self, MappingArg};
use crate::failure::usage;

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
  ibl lights sky.exr -n 1 --method irradiance-optimization --ambient-sh 3 -o sun+sh9.json"
)]
pub struct LightsArgs {
    /// Lat-long probe (.exr, .hdr, .pfm).
    pub probe: PathBuf,
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
    /// Output file, format by extension: .json, .gltf, .glb, .xml (Mitsuba 3), .pbrt (pbrt-v4).
    /// Repeat to write several formats from one extraction.
    #[arg(short = 'o', long, value_name = "FILE")]
    pub output: Vec<PathBuf>,
    /// Frame of the written directions: gltf (ours), paper, threejs, blender.
    #[arg(long, default_value = "gltf", value_name = "PRESET")]
    pub frame: String,
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

/// An output to write and its format.
struct Output<'a> {
    path: &'a Path,
    format: LightFormat,
}

/// The usage error for an `-n` the method cannot make.
fn count_error(method: Method, n: usize) -> anyhow::Error {
    match method {
        Method::MedianCut => usage(format!(
            "-n {n}: median cut makes a power of two lights (1, 2, 4, ... up to {}); use \
             --method adaptive-median-cut (or any other method) for other counts",
            1u64 << ibl_extract::median_cut::MAX_SPLITS
        )),
        _ => usage(format!("-n {n}: {method} needs at least one light")),
    }
}

/// Checks the flags and the output paths, before any work.
fn check_args(args: &LightsArgs) -> anyhow::Result<Vec<Output<'_>>> {
    if !(args.lux_per_unit.is_finite() && args.lux_per_unit > 0.0) {
        return Err(usage(format!(
            "--lux-per-unit must be a finite positive number (got {})",
            args.lux_per_unit
        )));
    }
    let method = args.method.method();
    if !method.accepts(args.count) {
        return Err(count_error(method, args.count));
    }
    let outputs = args
        .output
        .iter()
        .map(|path| {
            let format = LightFormat::from_path(path).ok_or_else(|| {
                usage(format!(
                    "{}: unknown light-set format (expected {})",
                    path.display(),
                    LightFormat::EXPECTED
                ))
            })?;
            Ok(Output { path, format })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    if let Some(bands) = args.ambient_sh {
        if bands == 0 || bands > ibl_sh::MAX_BANDS {
            return Err(usage(format!(
                "--ambient-sh must be between 1 and {}",
                ibl_sh::MAX_BANDS
            )));
        }
        if let Some(o) = outputs.iter().find(|o| o.format != LightFormat::Json) {
            return Err(usage(format!(
                "{}: {} has no place for an SH ambient; write the hybrid to a .json file \
                 (and the probe's SH with `ibl sh --format ...`)",
                o.path.display(),
                o.format.name()
            )));
        }
    }
    if let Some(overlay) = &args.overlay
        && !matches!(
            ibl_io::ImageFormat::from_path(overlay),
            Some(ibl_io::ImageFormat::Png)
        )
    {
        return Err(usage(format!(
            "{}: the overlay is written as .png",
            overlay.display()
        )));
    }
    let all: Vec<&Path> = args
        .output
        .iter()
        .chain(&args.overlay)
        .map(PathBuf::as_path)
        .collect();
    for (i, path) in all.iter().enumerate() {
        if all[..i].contains(path) {
            return Err(usage(format!(
                "{}: named twice as an output",
                path.display()
            )));
        }
        ibl_io::ensure_output_is_not_input(path, &[args.probe.as_path()])?;
    }
    Ok(outputs)
}

/// A method's parameters as JSON numbers, whole values as integers (`"splits": 4`).
fn parameters_json(parameters: &BTreeMap<String, f64>) -> serde_json::Value {
    const EXACT: f64 = 9_007_199_254_740_992.0; // 2^53
    serde_json::Value::Object(
        parameters
            .iter()
            .map(|(k, &v)| {
                let value = if v.fract() == 0.0 && v.abs() <= EXACT {
                    serde_json::json!(v as i64)
                } else {
                    serde_json::json!(v)
                };
                (k.clone(), value)
            })
            .collect(),
    )
}

/// Runs `ibl lights`.
pub fn run(args: &LightsArgs) -> anyhow::Result<()> {
    let frame = parse_frame(&args.frame)?;
    let outputs = check_args(args)?;
    let method = args.method.method();
    if frame != FramePreset::Gltf {
        for o in &outputs {
            if matches!(o.format, LightFormat::Gltf | LightFormat::Glb) {
                eprintln!(
                    "note: {}: glTF is defined in the gltf frame; writing the directions in the \
                     {} preset's axes as asked",
                    o.path.display(),
                    frame.name()
                );
            }
        }
    }

    let env = envmap_files::load(&args.probe, Some(MappingArg::Single(Mapping::LatLong)))?;
    crate::cmd::convert::report_clamped(&env);
    let spinner = indicatif::ProgressBar::new_spinner();
    spinner.set_message(format!("{method}: {} lights", args.count));
    spinner.enable_steady_tick(Duration::from_millis(120));
    let start = Instant::now();
    let extraction = ibl_extract::extract(
        &env.image,
        method,
        args.count,
        &ExtractOptions { seed: args.seed },
    );
    let seconds = start.elapsed().as_secs_f64();
    spinner.finish_and_clear();
    let extraction =
        extraction.map_err(|e| usage(format!("{}: {method}: {e}", args.probe.display())))?;
    let set = &extraction.set;
    eprintln!("{method}: {} lights in {seconds:.2} s", set.lights.len());
    if set.lights.len() != args.count {
        // Median cut, for one, cannot cut a region of one pixel.
        eprintln!(
            "note: {method} made {} lights, not the {} asked",
            set.lights.len(),
            args.count
        );
    }

    let m = frame.preset_from_world().as_dmat3();
    let ambient = match args.ambient_sh {
        Some(bands) => {
            let hybrid = ibl_extract::Hybrid::from_probe(
                &env.image,
                set.clone(),
                bands,
                ibl_sh::Window::None,
            )
            .map_err(|e| usage(format!("{}: {e}", args.probe.display())))?;
            Some(AmbientRecord {
                convention: ibl_io::sh_file::SH_CONVENTION.to_string(),
                bands,
                radiance: hybrid.ambient.transformed(m).coefficients().to_vec(),
            })
        }
        None => None,
    };
    let file = LightsFile {
        format: LIGHTS_FORMAT.to_string(),
        probe: ProbeRef {
            path: args.probe.display().to_string(),
            width: env.image.width(),
            height: env.image.height(),
            sha256: ibl_io::light_file::sha256_file(&args.probe)?,
        },
        frame: frame.name().to_string(),
        method: MethodRef {
            name: set.method.clone(),
            parameters: parameters_json(&extraction.parameters),
        },
        lights: set
            .lights
            .iter()
            .map(|l| LightRecord {
                direction: (m * l.dir()).to_array(),
                radiance: l.radiance.to_array(),
                solid_angle: l.solid_angle_sr,
                irradiance: l.irradiance,
                region: l.region.map(|r| RegionRecord {
                    x0: r.x0,
                    y0: r.y0,
                    x1: r.x1,
                    y1: r.y1,
                }),
            })
            .collect(),
        ambient,
    };
    for o in &outputs {
        ibl_io::write_light_file(o.path, &file, args.lux_per_unit)?;
        eprintln!(
            "wrote {} ({}, {} lights, {} frame)",
            o.path.display(),
            o.format.name(),
            set.lights.len(),
            frame.name()
        );
    }
    if let Some(path) = &args.overlay {
        let picture = ibl_eval::overlay::draw_overlay(
            &env.image,
            set,
            &ibl_eval::overlay::OverlayOptions::default(),
        );
        let png = ibl_io::ldr::encode_png(&picture).map_err(|e| e.with_path(path))?;
        ibl_io::write_atomically(path, &png)?;
        eprintln!(
            "wrote {} ({} x {} overlay)",
            path.display(),
            picture.width(),
            picture.height()
        );
    }

    let probe_power = ibl_mapping::power(&env.image, Mapping::LatLong);
    if args.json {
        let summary = serde_json::json!({
            "probe": args.probe.display().to_string(),
            "method": method.name(),
            "n": set.lights.len(),
            "requested": args.count,
            "seed": args.seed,
            "frame": frame.name(),
            "seconds": seconds,
            "total_power": set.total_power(),
            "probe_power": probe_power,
            "parameters": file.method.parameters,
            "ambient_sh_bands": args.ambient_sh,
            "outputs": args.output.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            "overlay": args.overlay.as_ref().map(|p| p.display().to_string()),
        });
        println!("{summary:#}");
    } else {
        print_summary(set, &probe_power);
    }
    Ok(())
}

fn print_summary(set: &LightSet, probe_power: &[f64; 3]) {
    let p = set.total_power();
    println!(
        "{} lights by {}; power {:.5e} {:.5e} {:.5e} (probe {:.5e} {:.5e} {:.5e})",
        set.lights.len(),
        set.method,
        p[0],
        p[1],
        p[2],
        probe_power[0],
        probe_power[1],
        probe_power[2]
    );
    let mut order: Vec<usize> = (0..set.lights.len()).collect();
    let lum = |i: &usize| {
        let [r, g, b] = set.lights[*i].irradiance;
        Rgb64 { r, g, b }.luminance()
    };
    order.sort_by(|a, b| lum(b).total_cmp(&lum(a)));
    println!("strongest lights (world direction, solid angle sr, irradiance I = L A):");
    for i in order.iter().take(5) {
        let l = &set.lights[*i];
        println!(
            "  ({:+.4}, {:+.4}, {:+.4})  {:.3e}  {:.4e} {:.4e} {:.4e}",
            l.direction[0],
            l.direction[1],
            l.direction[2],
            l.solid_angle_sr,
            l.irradiance[0],
            l.irradiance[1],
            l.irradiance[2]
        );
    }
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

    #[test]
    fn whole_parameters_are_integers() {
        let p = BTreeMap::from([
            ("splits".to_string(), 4.0),
            ("tolerance".to_string(), 0.25),
            ("converged".to_string(), 1.0),
        ]);
        assert_eq!(
            parameters_json(&p).to_string(),
            r#"{"converged":1,"splits":4,"tolerance":0.25}"#
        );
    }
}

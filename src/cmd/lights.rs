//! `ibl lights`: approximate a lat-long probe by N directional lights (Madsen & Laursen 2006) and
//! write the light set as the JSON file of CONVENTIONS section 7, directions in any frame preset.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use ibl_core::rgb::Rgb64;
use ibl_extract::LightSet;
use ibl_io::light_file::{
    LIGHTS_FORMAT, LightRecord, LightsFile, MethodRef, ProbeRef, RegionRecord,
};
use ibl_mapping::Mapping;

use crate::cmd::convert::parse_frame;
use crate::envmap_files::{self, MappingArg};
use crate::failure::usage;

/// Extraction methods available.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MethodArg {
    /// Median cut (Debevec 2005): 2^K regions of equal energy, a light at each energy centroid.
    MedianCut,
}

/// Arguments of `ibl lights`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl lights assets/probes/sky.exr -n 16 -o sky-16.json
  ibl lights probe.hdr -n 64 --method median-cut -o lights.json --frame blender")]
pub struct LightsArgs {
    /// Lat-long probe (.exr, .hdr, .pfm).
    pub probe: PathBuf,
    /// Number of lights (a power of two for median cut).
    #[arg(short = 'n', long, value_name = "N")]
    pub count: usize,
    /// Extraction method.
    #[arg(long, value_enum, default_value = "median-cut")]
    pub method: MethodArg,
    /// Output file (.json).
    #[arg(short = 'o', long, value_name = "FILE")]
    pub output: PathBuf,
    /// Frame of the written directions: gltf (ours), paper, threejs, blender.
    #[arg(long, default_value = "gltf", value_name = "PRESET")]
    pub frame: String,
}

/// Runs `ibl lights`.
pub fn run(args: &LightsArgs) -> anyhow::Result<()> {
    let frame = parse_frame(&args.frame)?;
    if !args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
    {
        return Err(usage(format!(
            "{}: light sets are written as .json",
            args.output.display()
        )));
    }
    ibl_io::ensure_output_is_not_input(&args.output, &[args.probe.as_path()])?;
    let env = envmap_files::load(&args.probe, Some(MappingArg::Single(Mapping::LatLong)))?;
    crate::cmd::convert::report_clamped(&env);
    let (set, parameters) = match args.method {
        MethodArg::MedianCut => {
            if args.count == 0 || !args.count.is_power_of_two() {
                return Err(usage(format!(
                    "median cut makes a power of two lights; -n {} is not one",
                    args.count
                )));
            }
            let splits = args.count.trailing_zeros();
            let set =
                ibl_extract::median_cut(&env.image, splits).map_err(|e| usage(e.to_string()))?;
            (set, serde_json::json!({ "splits": splits }))
        }
    };
    let m = frame.preset_from_world().as_dmat3();
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
            parameters,
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
    };
    ibl_io::light_file::write_lights_file(&args.output, &file)?;
    print_summary(&set, &ibl_mapping::power(&env.image, Mapping::LatLong));
    eprintln!(
        "wrote {} ({} lights, {} frame)",
        args.output.display(),
        set.lights.len(),
        frame.name()
    );
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

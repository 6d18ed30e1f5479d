//! `ibl irradiance`: the irradiance a Lambertian surface receives from a lat-long probe
//! (CONVENTIONS sections 4-5), either on M Fibonacci normals as `nx,ny,nz,r,g,b` CSV rows (the
//! ground truth of Madsen & Laursen 2006 section 5, for anyone who wants to check it) or as an
//! irradiance environment map in any mapping (lat-long, cube, ...): each texel holds `E(n)` for
//! the texel's direction `n`. Methods: exact (every pixel), fast (the probe reduced to 64 x 32
//! energy-conserving blocks) or spherical harmonics (Lambert convolution of B bands). Every
//! approximate run states its error against the exact ground truth on 20000 normals.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use clap::{Args, ValueEnum};
use ibl_core::glam::DVec3;
use ibl_core::{Image, Rgb, fibonacci_normals};
use ibl_io::WriteOptions;
use ibl_mapping::Mapping;
use ibl_sh::{MAX_BANDS, Window, project_latlong};
use serde::Serialize;

use crate::envmap_files::{self, MappingArg};
use crate::failure::usage;

/// How to compute the irradiance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum IrradianceMethod {
    /// Brute force over every pixel (the ground truth).
    Exact,
    /// The probe reduced to 64 x 32 energy-conserving blocks first (mean error under 0.1 %).
    Fast,
    /// Spherical harmonics: the probe projected on `--bands` bands, Lambert-convolved.
    Sh,
}

/// Arguments of `ibl irradiance`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl irradiance assets/probes/sky.exr --csv sky-E.csv               20000 normals, exact
  ibl irradiance probe.hdr --normals 2000 --method fast --csv E.csv
  ibl irradiance probe.exr -o irr.exr                                 lat-long map, 128 x 64, exact
  ibl irradiance probe.exr -o irr.exr --method sh --bands 3           the usual SH9 irradiance map
  ibl irradiance probe.exr -o irr.hdr --to cube-hcross --width 256    cube cross, faces 64 x 64")]
pub struct IrradianceArgs {
    /// Lat-long probe (.exr, .hdr, .pfm).
    pub probe: PathBuf,
    /// Exact (every pixel), fast (reduced probe) or sh (Lambert-convolved spherical harmonics).
    #[arg(long, value_enum, default_value = "exact")]
    pub method: IrradianceMethod,
    /// SH bands for `--method sh` (3 = the 9 coefficients engines use).
    #[arg(long, default_value_t = 3, value_name = "B")]
    pub bands: usize,
    /// SH window against ringing: none, lanczos or hann.
    #[arg(long, default_value = "none", value_name = "WINDOW")]
    pub window: String,
    /// Output CSV: a header line, then `nx,ny,nz,r,g,b` per Fibonacci normal (k = 0..M-1).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Number of Fibonacci normals M for `--csv`.
    #[arg(long, default_value_t = ibl_core::fibonacci::DEFAULT_NORMAL_COUNT, value_name = "M")]
    pub normals: usize,
    /// Output irradiance map (.exr, .hdr, .pfm; `{face}` pattern with `--to cube-faces`).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Mapping of the irradiance map: latlong, cube-hcross, cube-vcross, cube-strip, cube-faces,
    /// angular, mirror-ball.
    #[arg(long, default_value = "latlong", value_name = "MAPPING")]
    pub to: String,
    /// Width of the irradiance map in pixels (irradiance is smooth: small maps suffice).
    #[arg(long, default_value_t = 128, value_name = "W")]
    pub width: usize,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Largest number of normals accepted (the CSV is about 100 bytes a row).
const MAX_NORMALS: usize = 10_000_000;

/// Largest irradiance-map width accepted.
const MAX_WIDTH: usize = 16_384;

/// Normals on which approximate methods are scored against the exact ground truth.
const CHECK_NORMALS: usize = 20_000;

/// What `--json` prints.
#[derive(Serialize)]
struct Summary {
    probe: String,
    method: IrradianceMethod,
    bands: Option<usize>,
    window: Option<&'static str>,
    seconds: f64,
    /// Mean irradiance over `mean_over_normals` Fibonacci normals.
    mean_irradiance: [f64; 3],
    mean_over_normals: usize,
    /// Error against the exact ground truth on 20000 Fibonacci normals (approximate methods).
    mean_err_pct: Option<f64>,
    max_err_pct: Option<f64>,
    outputs: Vec<String>,
}

/// An irradiance evaluator for one probe and method.
enum Evaluator<'a> {
    /// Rows streamed through the cache, all normals per block of rows.
    Exact(&'a Image<Rgb>),
    Fast(&'a Image<Rgb>),
    Sh(ibl_sh::IrradianceSh),
}

impl Evaluator<'_> {
    fn irradiance(&self, dirs: &[DVec3]) -> Vec<[f64; 3]> {
        match self {
            Evaluator::Exact(probe) => ibl_core::irradiance_exact(probe, dirs),
            Evaluator::Fast(probe) => {
                ibl_eval::irradiance_fast(probe, dirs, ibl_eval::FAST_DEFAULT_SIZE)
            }
            Evaluator::Sh(sh) => sh.eval_many(dirs),
        }
    }
}

/// Runs `ibl irradiance`.
pub fn run(args: &IrradianceArgs) -> anyhow::Result<()> {
    if args.csv.is_none() && args.output.is_none() {
        return Err(usage(
            "say where to write: --csv FILE (Fibonacci normals) and/or -o FILE (irradiance map)",
        ));
    }
    if args.normals == 0 || args.normals > MAX_NORMALS {
        return Err(usage(format!(
            "--normals must be between 1 and {MAX_NORMALS}"
        )));
    }
    if args.width == 0 || args.width > MAX_WIDTH {
        return Err(usage(format!("--width must be between 1 and {MAX_WIDTH}")));
    }
    if args.bands == 0 || args.bands > MAX_BANDS {
        return Err(usage(format!("--bands must be between 1 and {MAX_BANDS}")));
    }
    let window: Window = args.window.parse().map_err(usage)?;
    let mapping = MappingArg::parse(&args.to, 180.0)?;
    if matches!(
        mapping,
        MappingArg::Single(Mapping::Fisheye { .. } | Mapping::DualFisheye { .. })
    ) {
        return Err(usage(
            "--to: fisheye mappings do not cover the sphere; use latlong, a cube or angular",
        ));
    }
    let inputs = [args.probe.as_path()];
    for out in args.csv.iter().chain(&args.output) {
        ibl_io::ensure_output_is_not_input(out, &inputs)?;
    }
    if args.csv.is_some() && args.csv == args.output {
        return Err(usage("--csv and -o name the same file"));
    }
    let env = envmap_files::load(&args.probe, Some(MappingArg::Single(Mapping::LatLong)))?;
    crate::cmd::convert::report_clamped(&env);

    let spinner = indicatif::ProgressBar::new_spinner();
    spinner.set_message(format!("{:?} irradiance", args.method).to_lowercase());
    spinner.enable_steady_tick(Duration::from_millis(120));
    let start = Instant::now();
    let evaluator = match args.method {
        IrradianceMethod::Exact => Evaluator::Exact(&env.image),
        IrradianceMethod::Fast => Evaluator::Fast(&env.image),
        IrradianceMethod::Sh => Evaluator::Sh(
            project_latlong(&env.image, args.bands)
                .map_err(|e| anyhow::anyhow!("{}: {e}", args.probe.display()))?
                .irradiance(window),
        ),
    };
    let mut outputs = Vec::new();
    // The CSV's values, kept when its normals are the summary's (no second evaluation).
    let mut reusable: Option<Vec<[f64; 3]>> = None;
    if let Some(csv) = &args.csv {
        let normals = fibonacci_normals(args.normals);
        let e = evaluator.irradiance(&normals);
        let mut text = String::with_capacity(normals.len() * 100 + 32);
        text.push_str("nx,ny,nz,r,g,b\n");
        for (n, v) in normals.iter().zip(&e) {
            let _ = writeln!(text, "{},{},{},{},{},{}", n.x, n.y, n.z, v[0], v[1], v[2]);
        }
        ibl_io::write_atomically(csv, text.as_bytes())?;
        outputs.push(csv.display().to_string());
        let exact_output = args.method == IrradianceMethod::Exact;
        if exact_output || args.normals == CHECK_NORMALS {
            reusable = Some(e);
        }
    }
    if let Some(out) = &args.output {
        let map = irradiance_map(&evaluator, mapping.in_memory(), args.width);
        let written = envmap_files::save(out, &map, mapping, &WriteOptions::default(), &inputs)?;
        outputs.extend(written.iter().map(|p| p.display().to_string()));
    }
    let seconds = start.elapsed().as_secs_f64();
    // The mean irradiance, and for approximate methods the error against the exact ground truth,
    // on the CSV's own values when they serve: an exact CSV is already the answer (its mean is
    // over its own normals), and an approximate one on the 20000 check normals is the check.
    let check = match reusable {
        Some(values) => values,
        None => evaluator.irradiance(&fibonacci_normals(CHECK_NORMALS)),
    };
    let mean_over_normals = check.len();
    let mean = ibl_eval::channel_means(&check);
    let errors = (args.method != IrradianceMethod::Exact).then(|| {
        let truth = ibl_eval::irradiance_exact(&env.image, &fibonacci_normals(CHECK_NORMALS));
        ibl_eval::IrradianceError::between(&truth, &check)
    });
    spinner.finish_and_clear();
    let is_sh = args.method == IrradianceMethod::Sh;
    let summary = Summary {
        probe: args.probe.display().to_string(),
        method: args.method,
        bands: is_sh.then_some(args.bands),
        window: is_sh.then_some(window.name()),
        seconds,
        mean_irradiance: mean,
        mean_over_normals,
        mean_err_pct: errors.as_ref().map(|e| e.mean_err_pct),
        max_err_pct: errors.as_ref().map(|e| e.max_err_pct),
        outputs,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        let what = if is_sh {
            format!(
                "sh irradiance ({} bands, window {})",
                args.bands,
                window.name()
            )
        } else {
            format!("{:?} irradiance", args.method).to_lowercase()
        };
        println!(
            "{what} in {seconds:.2} s; mean E = {:.5e} {:.5e} {:.5e} (over {mean_over_normals} normals)",
            mean[0], mean[1], mean[2]
        );
        if let (Some(m), Some(x)) = (summary.mean_err_pct, summary.max_err_pct) {
            println!(
                "error against the exact ground truth on {CHECK_NORMALS} normals: mean {m:.3} %, max {x:.3} % of the mean irradiance"
            );
        }
    }
    for o in &summary.outputs {
        eprintln!("wrote {o}");
    }
    Ok(())
}

/// The irradiance map: `E(n)` at every texel centre's direction of `mapping` at `width`
/// (texels outside a disc mapping's disc, or in an unused cross cell, are black). O(texels) calls
/// of the evaluator, which runs them in parallel.
fn irradiance_map(evaluator: &Evaluator, mapping: Mapping, width: usize) -> Image<Rgb> {
    let (w, h) = mapping.size_for_width(width);
    let mut dirs = Vec::with_capacity(w * h);
    let mut index = Vec::with_capacity(w * h);
    for j in 0..h {
        for i in 0..w {
            if let Some(d) = mapping.pixel_dir(w, h, i as f64 + 0.5, j as f64 + 0.5) {
                dirs.push(d);
                index.push((i, j));
            }
        }
    }
    let e = evaluator.irradiance(&dirs);
    let mut img = Image::filled(w, h, Rgb::ZERO);
    for ((i, j), v) in index.into_iter().zip(e) {
        *img.get_mut(i, j) = Rgb::new(v[0] as f32, v[1] as f32, v[2] as f32);
    }
    img
}

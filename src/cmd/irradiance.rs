//! `ibl irradiance`: the ground truth of Madsen & Laursen 2006 section 5 (CONVENTIONS sections 4-5)
//! for anyone who wants to check it: `E(n) = sum_p L_p max(0, n . d_p) dOmega_p` on M Fibonacci
//! normals, every pixel, exact solid angles, f64, written as `nx,ny,nz,r,g,b` rows.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use clap::{Args, ValueEnum};
use ibl_core::fibonacci_normals;
use ibl_mapping::Mapping;

use crate::envmap_files::{self, MappingArg};
use crate::failure::usage;

/// How to compute the irradiance.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum IrradianceMethod {
    /// Brute force over every pixel (the ground truth).
    Exact,
    /// The probe reduced to 64 x 32 energy-conserving blocks first (mean error under 0.1 %).
    Fast,
}

/// Arguments of `ibl irradiance`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl irradiance assets/probes/sky.exr --csv sky-E.csv               20000 normals, exact
  ibl irradiance probe.hdr --normals 2000 --method fast --csv E.csv")]
pub struct IrradianceArgs {
    /// Lat-long probe (.exr, .hdr, .pfm).
    pub probe: PathBuf,
    /// Number of Fibonacci normals M.
    #[arg(long, default_value_t = ibl_core::fibonacci::DEFAULT_NORMAL_COUNT, value_name = "M")]
    pub normals: usize,
    /// Exact (every pixel) or fast (reduced probe).
    #[arg(long, value_enum, default_value = "exact")]
    pub method: IrradianceMethod,
    /// Output CSV: a header line, then `nx,ny,nz,r,g,b` per normal (k = 0..M-1).
    #[arg(long, value_name = "FILE")]
    pub csv: PathBuf,
}

/// Largest number of normals accepted (the CSV is about 100 bytes a row).
const MAX_NORMALS: usize = 10_000_000;

/// Runs `ibl irradiance`.
pub fn run(args: &IrradianceArgs) -> anyhow::Result<()> {
    if args.normals == 0 || args.normals > MAX_NORMALS {
        return Err(usage(format!(
            "--normals must be between 1 and {MAX_NORMALS}"
        )));
    }
    ibl_io::ensure_output_is_not_input(&args.csv, &[args.probe.as_path()])?;
    let env = envmap_files::load(&args.probe, Some(MappingArg::Single(Mapping::LatLong)))?;
    crate::cmd::convert::report_clamped(&env);
    let normals = fibonacci_normals(args.normals);
    let spinner = indicatif::ProgressBar::new_spinner();
    spinner.set_message(format!("irradiance on {} normals", args.normals));
    spinner.enable_steady_tick(Duration::from_millis(120));
    let start = Instant::now();
    let e = match args.method {
        IrradianceMethod::Exact => ibl_eval::irradiance_exact(&env.image, &normals),
        IrradianceMethod::Fast => {
            ibl_eval::irradiance_fast(&env.image, &normals, ibl_eval::FAST_DEFAULT_SIZE)
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    spinner.finish_and_clear();
    let mut text = String::with_capacity(normals.len() * 100 + 32);
    text.push_str("nx,ny,nz,r,g,b\n");
    for (n, v) in normals.iter().zip(&e) {
        let _ = writeln!(text, "{},{},{},{},{},{}", n.x, n.y, n.z, v[0], v[1], v[2]);
    }
    ibl_io::write_atomically(&args.csv, text.as_bytes())?;
    let mean = ibl_eval::channel_means(&e);
    println!(
        "{:?} irradiance on {} normals in {seconds:.2} s; mean E = {:.5e} {:.5e} {:.5e}",
        args.method, args.normals, mean[0], mean[1], mean[2]
    );
    eprintln!("wrote {}", args.csv.display());
    Ok(())
}

//! `ibl info`: what an HDR image holds (`ibl_pipeline::info`), as text or JSON.

use std::path::PathBuf;

use clap::Args;
use ibl_core::FramePreset;
use ibl_pipeline::EnvMapping;
use ibl_pipeline::info::Info;

use crate::values;

/// Arguments of `ibl info`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl info assets/probes/esplanade.exr
  ibl info probe.hdr --json | jq .brightest
  ibl info ball.exr --mapping mirror-ball
  ibl info env.ktx2                         # a KTX2/DDS cube: format, levels, faces
  ibl info probe.exr --frame blender        # brightest direction in Blender's Z-up axes
  ibl info huge.jpg --header                # size and format only, nothing decoded")]
pub struct InfoArgs {
    /// The image to describe (.hdr, .exr, .pfm, .png, .jpg; .ktx2 and .dds: level 0, a cube map
    /// as its six faces side by side).
    pub file: PathBuf,
    /// Mapping of the image (default: guessed from its shape; 2:1 is lat-long, 1:1 angular; a
    /// shape that names none is described without its power and brightest direction).
    #[arg(long, value_name = "MAPPING")]
    pub mapping: Option<String>,
    /// Field of view in degrees for the fisheye mappings.
    #[arg(long, default_value_t = 180.0, value_name = "DEG")]
    pub fov: f32,
    /// Axes in which to print the brightest direction: gltf (ours), paper, threejs, blender.
    #[arg(long, default_value = "gltf", value_name = "PRESET", value_parser = values::frame)]
    pub frame: FramePreset,
    /// Read only the header: format, size and the mapping its shape names, at once and without
    /// decoding a pixel, whatever the image's size (no statistics).
    #[arg(long)]
    pub header: bool,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs `ibl info`.
pub fn run(args: &InfoArgs) -> anyhow::Result<()> {
    let mapping = args
        .mapping
        .as_deref()
        .map(|m| EnvMapping::parse(m, args.fov))
        .transpose()?;
    if args.header {
        let h = ibl_pipeline::info::header_info(&args.file, mapping)?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&h)?);
        } else {
            let guessed = if h.mapping_guessed {
                " (guessed from shape)"
            } else {
                ""
            };
            let limits = if h.within_limits {
                "within the limits"
            } else {
                "over the pixel limit: refused unless --max-pixels allows it"
            };
            println!("file        {}", h.file);
            println!("format      {}", h.format);
            println!(
                "size        {} x {} ({} pixels, {limits})",
                h.width, h.height, h.pixels
            );
            println!("mapping     {}{guessed}", h.mapping);
        }
        return Ok(());
    }
    let info = ibl_pipeline::info::probe_info(&args.file, mapping, args.frame)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&info)?);
    } else {
        print_text(&info);
    }
    Ok(())
}

fn print_text(i: &Info) {
    let guessed = if i.mapping_guessed {
        " (guessed from shape; --mapping to override)"
    } else if i.mapping == ibl_pipeline::info::UNKNOWN_MAPPING {
        " (its shape names none: not read as a probe; --mapping to name one)"
    } else {
        ""
    };
    println!("file        {}", i.file);
    println!("format      {} ({})", i.format, i.encoding);
    println!("size        {} x {}", i.width, i.height);
    println!("mapping     {}{guessed}", i.mapping);
    println!("             {:>12} {:>12} {:>12}", "R", "G", "B");
    println!(
        "min         {:>12.5e} {:>12.5e} {:>12.5e}",
        i.min[0], i.min[1], i.min[2]
    );
    println!(
        "max         {:>12.5e} {:>12.5e} {:>12.5e}",
        i.max[0], i.max[1], i.max[2]
    );
    println!(
        "mean        {:>12.5e} {:>12.5e} {:>12.5e}",
        i.mean[0], i.mean[1], i.mean[2]
    );
    match i.power {
        Some(p) => println!(
            "power       {:>12.5e} {:>12.5e} {:>12.5e}   (sum L dOmega)",
            p[0], p[1], p[2]
        ),
        None => println!("power       needs a mapping: name one with --mapping"),
    }
    let dr = &i.dynamic_range;
    println!(
        "range       luminance {:.3e} .. {:.3e}: {:.3e}:1 ({:.1} stops)",
        dr.min_positive_luminance, dr.max_luminance, dr.ratio, dr.stops
    );
    println!(
        "invalid     {} negative, {} NaN/Inf values (clamped to 0; raw min {:.4e} {:.4e} {:.4e})",
        i.negative_values, i.nonfinite_values, i.raw_min[0], i.raw_min[1], i.raw_min[2]
    );
    let b = &i.brightest;
    let direction = match b.direction {
        Some(d) => format!(
            "direction ({:+.4}, {:+.4}, {:+.4}) [{} axes], ",
            d[0], d[1], d[2], i.frame
        ),
        None => String::new(),
    };
    println!(
        "brightest   {direction}pixel ({}, {}), radiance ({:.4e}, {:.4e}, {:.4e})",
        b.pixel[0], b.pixel[1], b.radiance[0], b.radiance[1], b.radiance[2]
    );
}

//! `ibl info`: what an HDR image holds (`ibl_pipeline::info`), as text or JSON.

use std::path::PathBuf;

use clap::Args;
use ibl_core::FramePreset;
use ibl_pipeline::EnvMapping;

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
        match args.json {
            true => println!("{}", serde_json::to_string_pretty(&h)?),
            false => print!("{h}"),
        }
        return Ok(());
    }
    let info = ibl_pipeline::info::probe_info(&args.file, mapping, args.frame)?;
    match args.json {
        true => println!("{}", serde_json::to_string_pretty(&info)?),
        false => print!("{info}"),
    }
    Ok(())
}

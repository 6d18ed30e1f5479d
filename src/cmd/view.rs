//! `ibl view`: the real-time viewer (`ibl-viewer`): a probe, or a scene file with its virtual
//! objects composited into the probe or the photo, every light casting a shadow. In a window by
//! default; `--headless` renders offscreen with the same code and writes the last frame.

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use ibl_core::{Image, Rgb};
use ibl_io::{Display, ToneCurve, WriteOptions};
use ibl_viewer::headless::{self, HeadlessOptions, Motion};
use ibl_viewer::probe_pass::{ProbeLayer, ProbeProjection};
use ibl_viewer::scene_renderer::GlossySource;
use ibl_viewer::window::{self, WindowOptions};
use ibl_viewer::{GpuContext, HeadlessRun, ProbeModel, ProbeViewSettings, SceneModel};
use serde::Serialize;

use crate::cmd::preview::CurveArg;
use crate::failure::usage;
use crate::progress;

/// Glossy reflections on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum GlossyArg {
    /// The glossy lobe lit by the shadowed lights (as `ibl render`).
    Lights,
    /// The glossy lobe reflecting the prefiltered probe (unshadowed).
    Environment,
}

/// What the probe viewer shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LayerArg {
    /// The probe's radiance.
    Radiance,
    /// Its SH irradiance divided by pi (a white diffuse surface).
    Irradiance,
}

/// Arguments of `ibl view`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl view assets/probes/sky.exr                         look around a probe (drag, wheel, keys 1-6)
  ibl view assets/scenes/bunny-sky.toml                  the bunny with 16 shadowed lights
  ibl view assets/scenes/bunny-sky.toml --headless --size 640x480 -o frame.png --json
  ibl view assets/scenes/bunny-sky.toml --headless --bench --frames 120
  ibl view probe.exr --headless --flat --method lightgen -n 32 -o lights.png
  ibl view scene.toml --screenshot window.png           open the window, save it with its UI, quit

In the window: left-drag turns the camera (or moves the object under the cursor), Shift-drag
turns the object, Ctrl-drag scales it, right-drag pans, the wheel zooms; F12 saves the frame as
EXR and PNG, Ctrl+S saves the scene, F11 toggles full screen; drop a probe or scene file onto the
window to open it. -o FRAME writes FRAME and FRAME's .exr (or .png) twin.")]
pub struct ViewArgs {
    /// A probe (any format and mapping ibl reads) or a scene file (.toml, docs/SCENES.md).
    pub input: PathBuf,
    /// Render offscreen (no window) and write the last frame.
    #[arg(long)]
    pub headless: bool,
    /// Frame size, WIDTHxHEIGHT pixels (headless; the window starts at this size).
    #[arg(long, value_name = "WxH", default_value = "640x480")]
    pub size: String,
    /// Frames to render (headless; default 1, or 120 with --bench).
    #[arg(long, value_name = "K")]
    pub frames: Option<u32>,
    /// Output frame (.png or .exr; the other is written beside it). Headless only.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Orbit the camera and move the first object for K frames; report fps (median, p95).
    #[arg(long)]
    pub bench: bool,
    /// Print a JSON summary (per-frame CPU and GPU times, statistics) on stdout.
    #[arg(long)]
    pub json: bool,
    /// Save a screenshot of the window with its UI to FILE once it has drawn, then quit.
    #[arg(long, value_name = "FILE", conflicts_with = "headless")]
    pub screenshot: Option<PathBuf>,
    /// Mapping of a probe file (default: guessed from its shape).
    #[arg(long, value_name = "MAPPING")]
    pub mapping: Option<String>,
    /// Show the probe flat (lat-long) instead of looking around from its centre.
    #[arg(long)]
    pub flat: bool,
    /// What the probe viewer shows.
    #[arg(long, value_enum, default_value = "radiance")]
    pub layer: LayerArg,
    /// Laplacian sharpening of the probe, 0 to 2.
    #[arg(long, default_value_t = 0.0)]
    pub sharpen: f32,
    /// Exposure in stops (default: automatic, as `ibl preview` and `ibl render`).
    #[arg(long, value_name = "STOPS", allow_hyphen_values = true)]
    pub exposure: Option<f32>,
    /// Tone curve.
    #[arg(long, value_enum, default_value = "reinhard")]
    pub tonemap: CurveArg,
    /// Light method of the probe overlay or the scene (default: the scene's, or median-cut).
    #[arg(long, value_name = "METHOD")]
    pub method: Option<String>,
    /// Number of lights (default: the scene's, or 16).
    #[arg(short = 'n', long = "n", value_name = "N")]
    pub n: Option<u32>,
    /// SH bands of the probe's irradiance layer or the scene's hybrid ambient.
    #[arg(long, value_name = "B")]
    pub bands: Option<u32>,
    /// Overlays on a probe (comma-separated: lights, regions, dominant; or none).
    #[arg(long, value_name = "LIST", default_value = "lights,dominant")]
    pub overlay: String,
    /// Shadow map side per light, texels (shrunk when the atlas would exceed 4096^2).
    #[arg(long, value_name = "TEXELS", default_value_t = headless::DEFAULT_SHADOW_TILE)]
    pub shadow_size: u32,
    /// Glossy reflections.
    #[arg(long, value_enum, default_value = "lights")]
    pub glossy: GlossyArg,
    /// Background rays per pixel axis (4, as `ibl render`, antialiases the magnified probe).
    #[arg(long, value_name = "N", default_value_t = 4)]
    pub background_rays: u32,
}

/// Parses `WxH`.
fn parse_size(text: &str) -> anyhow::Result<(u32, u32)> {
    let bad = || usage(format!("--size {text}: expected WIDTHxHEIGHT, e.g. 640x480"));
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.trim().parse().map_err(|_| bad())?, h.trim().parse().map_err(|_| bad())?);
    let max = ibl_viewer::frame_targets::MAX_OUTPUT_SIDE;
    if !(1..=max).contains(&w) || !(1..=max).contains(&h) {
        return Err(usage(format!("--size {text}: each side must be 1 to {max}")));
    }
    Ok((w, h))
}

fn is_scene(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}

/// The PNG and EXR a frame goes to.
fn frame_outputs(output: &Path) -> anyhow::Result<(PathBuf, PathBuf)> {
    match ibl_io::ImageFormat::from_path(output) {
        Some(ibl_io::ImageFormat::Png) => Ok((output.to_path_buf(), output.with_extension("exr"))),
        Some(ibl_io::ImageFormat::Exr) => Ok((output.with_extension("png"), output.to_path_buf())),
        _ => Err(usage(format!(
            "{}: a frame is written as .png or .exr (both are written)",
            output.display()
        ))),
    }
}

/// What `--json` prints.
#[derive(Serialize)]
struct Summary<'a> {
    input: String,
    kind: &'static str,
    width: u32,
    height: u32,
    frames: usize,
    motion: Motion,
    adapter: &'a ibl_viewer::gpu::AdapterSummary,
    lights: usize,
    lighting: &'a str,
    lighting_seconds: f64,
    shadow_map_texels: u32,
    statistics: &'a ibl_viewer::headless::RunStatistics,
    per_frame: Vec<FrameSummary>,
    outputs: Vec<String>,
}

#[derive(Serialize)]
struct FrameSummary {
    cpu_ms: f64,
    gpu_ms: Option<f64>,
    wall_ms: f64,
    passes_ms: Option<Vec<(String, f64)>>,
    real_shadows_drawn: bool,
    virtual_shadows_drawn: bool,
}

fn probe_settings(args: &ViewArgs, model: &ProbeModel) -> anyhow::Result<ProbeViewSettings> {
    let mut settings = ProbeViewSettings::for_probe(&model.latlong);
    if args.flat {
        settings.projection = ProbeProjection::LatLong;
    }
    settings.layer = match args.layer {
        LayerArg::Radiance => ProbeLayer::Radiance,
        LayerArg::Irradiance => ProbeLayer::ShIrradiance,
    };
    if !(0.0..=2.0).contains(&args.sharpen) {
        return Err(usage(format!("--sharpen {}: must be 0 to 2", args.sharpen)));
    }
    settings.sharpen = args.sharpen;
    settings.display = display(args, settings.display.exposure_stops)?;
    if let Some(method) = &args.method {
        settings.spec = method
            .parse()
            .map_err(|e: ibl_extract::ExtractError| usage(format!("--method: {e}")))?;
    }
    if let Some(n) = args.n {
        settings.lights = n as usize;
    }
    if let Some(b) = args.bands {
        if !(1..=16).contains(&b) {
            return Err(usage(format!("--bands {b}: must be 1 to 16")));
        }
        settings.bands = b as usize;
    }
    let mut overlays = ibl_viewer::probe_model::Overlays {
        lights: false,
        regions: false,
        dominant: false,
    };
    for item in args.overlay.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        match item {
            "lights" => overlays.lights = true,
            "regions" => overlays.regions = true,
            "dominant" => overlays.dominant = true,
            "none" => {}
            other => {
                return Err(usage(format!(
                    "--overlay: unknown overlay `{other}` (expected lights, regions, dominant or none)"
                )));
            }
        }
    }
    settings.overlays = overlays;
    Ok(settings)
}

fn display(args: &ViewArgs, automatic: f32) -> anyhow::Result<Display> {
    if let Some(e) = args.exposure
        && !e.is_finite()
    {
        return Err(usage("--exposure must be a finite number of stops"));
    }
    Ok(Display {
        exposure_stops: args.exposure.unwrap_or(automatic),
        curve: ToneCurve::from(args.tonemap),
    })
}

fn apply_scene_overrides(args: &ViewArgs, model: &mut SceneModel) -> anyhow::Result<()> {
    let lighting = &mut model.description.lighting;
    if let Some(m) = &args.method {
        lighting.method = m.clone();
    }
    if let Some(n) = args.n {
        if !(1..=4096).contains(&n) {
            return Err(usage(format!("-n {n}: must be 1 to 4096")));
        }
        lighting.lights = n;
    }
    if let Some(b) = args.bands {
        if !(1..=16).contains(&b) {
            return Err(usage(format!("--bands {b}: must be 1 to 16")));
        }
        lighting.ambient_bands = b;
    }
    Ok(())
}

fn glossy(args: &ViewArgs) -> GlossySource {
    match args.glossy {
        GlossyArg::Lights => GlossySource::Lights,
        GlossyArg::Environment => GlossySource::Environment,
    }
}

/// Runs `ibl view`.
pub fn run(args: &ViewArgs) -> anyhow::Result<()> {
    let size = parse_size(&args.size)?;
    if !(1..=8).contains(&args.background_rays) {
        return Err(usage("--background-rays must be 1 to 8"));
    }
    if !(64..=8192).contains(&args.shadow_size) {
        return Err(usage("--shadow-size must be 64 to 8192 texels"));
    }
    let mapping = match &args.mapping {
        Some(name) => Some(ibl_mapping::Mapping::parse(name, 180.0).ok_or_else(|| {
            usage(format!("--mapping: unknown mapping `{name}`"))
        })?),
        None => None,
    };
    if !args.headless {
        if args.output.is_some() || args.bench || args.frames.is_some() {
            return Err(usage("-o, --frames and --bench need --headless"));
        }
        return window::run(WindowOptions {
            input: Some(args.input.clone()),
            mapping,
            size,
            screenshot: args.screenshot.clone(),
            shadow_tile: args.shadow_size,
        })
        .map_err(anyhow::Error::from);
    }
    let outputs = match &args.output {
        Some(o) => Some(frame_outputs(o)?),
        None => None,
    };
    let frames = args.frames.unwrap_or(if args.bench { 120 } else { 1 });
    if !(1..=100_000).contains(&frames) {
        return Err(usage("--frames must be 1 to 100000"));
    }
    let motion = if args.bench { Motion::Orbit } else { Motion::Still };
    let mut options = HeadlessOptions {
        size,
        frames,
        motion,
        shadow_tile: args.shadow_size,
        glossy: glossy(args),
        background_rays: args.background_rays,
        display: None,
    };
    let bar = progress::bar("frames", u64::from(frames));
    let callback = |done: usize, total: usize| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    };
    let (run, kind, inputs) = if is_scene(&args.input) {
        let mut model = SceneModel::open(&args.input)?;
        apply_scene_overrides(args, &mut model)?;
        check_outputs(outputs.as_ref(), &model.inputs)?;
        options.display = Some(display(args, headless::auto_exposure(&model))?);
        let gpu = GpuContext::headless()?;
        (headless::render_scene(&gpu, &model, &options, &callback)?, "scene", model.inputs)
    } else {
        let model = ProbeModel::open(&args.input, mapping)?;
        let inputs = vec![args.input.clone()];
        check_outputs(outputs.as_ref(), &inputs)?;
        let settings = probe_settings(args, &model)?;
        let gpu = GpuContext::headless()?;
        (headless::render_probe(&gpu, &model, &settings, &options, &callback)?, "probe", inputs)
    };
    bar.finish_and_clear();
    drop(inputs);
    let mut written = Vec::new();
    if let Some((png, exr)) = &outputs {
        write_frame(&run, png, exr)?;
        written = vec![png.display().to_string(), exr.display().to_string()];
    }
    report(args, &run, kind, motion, written)
}

fn check_outputs(outputs: Option<&(PathBuf, PathBuf)>, inputs: &[PathBuf]) -> anyhow::Result<()> {
    let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    if let Some((png, exr)) = outputs {
        ibl_io::ensure_output_is_not_input(png, &inputs)?;
        ibl_io::ensure_output_is_not_input(exr, &inputs)?;
    }
    Ok(())
}

/// Writes the frame: the tone-mapped picture as PNG (exactly what was shown) and the radiance
/// as EXR.
fn write_frame(run: &HeadlessRun, png: &Path, exr: &Path) -> anyhow::Result<()> {
    let picture = &run.images.display;
    let bytes = ibl_io::ldr::encode_png(picture).map_err(|e| e.with_path(png))?;
    ibl_io::write_atomically(png, &bytes)?;
    let radiance: &Image<Rgb> = &run.images.radiance;
    ibl_io::write_image(exr, radiance, &WriteOptions::default())?;
    Ok(())
}

fn report(
    args: &ViewArgs,
    run: &HeadlessRun,
    kind: &'static str,
    motion: Motion,
    outputs: Vec<String>,
) -> anyhow::Result<()> {
    let s = &run.statistics;
    if args.json {
        let summary = Summary {
            input: args.input.display().to_string(),
            kind,
            width: run.images.display.width() as u32,
            height: run.images.display.height() as u32,
            frames: run.frames.len(),
            motion,
            adapter: &run.adapter,
            lights: run.lights,
            lighting: &run.lighting,
            lighting_seconds: run.lighting_seconds,
            shadow_map_texels: run.shadow_tile,
            statistics: s,
            per_frame: run
                .frames
                .iter()
                .map(|f| FrameSummary {
                    cpu_ms: f.cpu_seconds * 1e3,
                    gpu_ms: f.gpu_seconds.map(|g| g * 1e3),
                    wall_ms: f.wall_seconds * 1e3,
                    passes_ms: f.passes.as_ref().map(|p| {
                        p.passes.iter().map(|(n, t)| (n.clone(), t * 1e3)).collect()
                    }),
                    real_shadows_drawn: f.drew_real_shadows,
                    virtual_shadows_drawn: f.drew_virtual_shadows,
                })
                .collect(),
            outputs,
        };
        println!("{}", serde_json::to_string_pretty(&summary)?);
        return Ok(());
    }
    let gpu = s
        .gpu_ms_median
        .map_or(String::new(), |g| format!(", GPU {g:.1} ms"));
    println!(
        "{}: {} frames of {} x {} on {}{}: {:.1} fps median ({:.1} ms), {:.1} fps at p95 ({:.1} ms); CPU {:.1} ms{gpu}{}",
        args.input.display(),
        run.frames.len(),
        run.images.display.width(),
        run.images.display.height(),
        run.adapter.line(),
        if run.lights > 0 {
            format!(", {}, shadow maps {}^2", run.lighting, run.shadow_tile)
        } else {
            String::new()
        },
        s.fps_median,
        s.frame_ms_median,
        s.fps_p95,
        s.frame_ms_p95,
        s.cpu_ms_median,
        if outputs.is_empty() {
            String::new()
        } else {
            format!("; wrote {}", outputs.join(", "))
        }
    );
    Ok(())
}

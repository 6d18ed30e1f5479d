//! `ibl render`: virtual objects lit by a light probe, composited into the probe panorama or a
//! photograph by differential rendering (`ibl-render`), in one of three lighting modes: the
//! path-traced reference, N directional lights with shadows, or lights plus an occluded SH ambient.
//! Writes the composite as EXR plus a tone-mapped PNG beside it, and on request the layers (with
//! and without the objects, object coverage).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context as _;
use clap::{Args, ValueEnum};
use ibl_core::glam::DVec3;
use ibl_core::{FramePreset, Image, Rgb};
use ibl_extract::{Light, LightSet};
use ibl_io::{Display, WriteOptions};
use ibl_render::lighting::LightingPlan;
use ibl_render::{RenderOutput, RenderSettings, SamplerKind};
use ibl_scene::{RenderMode, ShadowKind};
use serde::Serialize;

use crate::failure::usage;
use crate::progress;

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

impl From<ModeArg> for RenderMode {
    fn from(m: ModeArg) -> Self {
        match m {
            ModeArg::Reference => RenderMode::Reference,
            ModeArg::Lights => RenderMode::Lights,
            ModeArg::Hybrid => RenderMode::Hybrid,
        }
    }
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
  ibl render scene.toml -o b.exr --width 640 --spp 256 --layers              + with/without/alpha
  ibl render scene.toml -o b.exr --sampler independent                       no low discrepancy

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
    /// Light file (`ibl lights ... -o lights.json`) for the lights and hybrid modes, instead of
    /// extracting.
    #[arg(long, value_name = "FILE")]
    pub lights: Option<PathBuf>,
    /// Extraction method for lights/hybrid (median-cut, adaptive-median-cut, lightgen,
    /// variance-minimization, irradiance-optimization, sun).
    #[arg(long, value_name = "METHOD")]
    pub method: Option<String>,
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
    /// Output width in pixels (panorama: height = width / 2; photo: its aspect ratio).
    #[arg(long, value_name = "W")]
    pub width: Option<u32>,
    /// Surface vertices per path (1 = direct light only).
    #[arg(long, value_name = "N")]
    pub bounces: Option<u32>,
    /// Random seed (the image depends on it only, not on the thread count).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Render the whole panorama seen from the probe's centre, ignoring the scene's `[camera]`
    /// (panorama backgrounds only).
    #[arg(long)]
    pub panorama: bool,
    /// Also write the with/without-objects renders and the object coverage.
    #[arg(long)]
    pub layers: bool,
    /// Print a JSON summary (timings, rays per second, statistics) on stdout.
    #[arg(long)]
    pub json: bool,
}

/// What `--json` prints.
#[derive(Serialize)]
struct Summary {
    scene: String,
    mode: &'static str,
    lights: Option<LightsSummary>,
    width: u32,
    height: u32,
    spp: u32,
    bounces: u32,
    seed: u64,
    sampler: &'static str,
    seconds_lighting: f64,
    seconds_render: f64,
    rays: u64,
    rays_per_second: f64,
    paths: u64,
    paths_without_objects: u64,
    object_coverage: f64,
    real_triangles: usize,
    virtual_triangles: usize,
    outputs: Vec<String>,
}

#[derive(Serialize)]
struct LightsSummary {
    source: String,
    count: usize,
    shadows: &'static str,
}

/// Runs `ibl render`.
pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    let loaded = ibl_io::read_scene(&args.scene)?;
    let mut inputs: Vec<&Path> = loaded.inputs.iter().map(PathBuf::as_path).collect();
    if let Some(l) = &args.lights {
        inputs.push(l);
    }
    let outputs = output_paths(&args.output, args.layers);
    for out in &outputs {
        // Refuse an unwritable format now, not after the render.
        if ibl_io::ImageFormat::from_path(out).is_none() {
            return Err(usage(format!(
                "{}: unknown output format (use .exr, .hdr, .pfm, .png or .jpg)",
                out.display()
            )));
        }
        ibl_io::ensure_output_is_not_input(out, &inputs)?;
    }
    let mut loaded = loaded;
    if args.panorama {
        if !matches!(loaded.scene.background, ibl_scene::Background::Panorama) {
            return Err(usage(format!(
                "{}: --panorama needs a panorama background (this scene has a photograph)",
                args.scene.display()
            )));
        }
        loaded.scene.camera = ibl_scene::Camera::Panorama {
            position: loaded.scene.probe.position,
            world_from_probe: loaded.scene.probe.world_from_probe,
        };
    }
    let scene = &loaded.scene;
    let mut plan = LightingPlan::from_scene(scene);
    if let Some(m) = args.mode {
        plan.mode = m.into();
    }
    if let Some(m) = &args.method {
        plan.method = m.clone();
    }
    if let Some(n) = args.n {
        plan.lights = n;
    }
    if let Some(s) = args.shadows {
        plan.shadows = match s {
            ShadowArg::Hard => ShadowKind::Hard,
            ShadowArg::Soft => ShadowKind::Soft,
        };
    }
    if let Some(seed) = args.seed {
        plan.seed = seed;
    }
    let lights_file = args.lights.clone().or(loaded.lights_path.clone());
    if let Some(path) = &lights_file {
        // Light files hold the probe file's units: apply the scene's radiance scale.
        let scale = f64::from(loaded.description.probe.radiance_scale);
        // A light file named by the scene: say which scene and field named it.
        let mut set = read_light_set(path).map_err(|e| match args.lights {
            Some(_) => e,
            None => e.context(format!("{}: lighting.lights_file", args.scene.display())),
        })?;
        for light in &mut set.lights {
            light.irradiance = light.irradiance.map(|c| c * scale);
            light.radiance *= scale as f32;
        }
        plan.given = Some(set);
    }
    let defaults = RenderSettings::for_scene(scene, plan.mode);
    let settings = RenderSettings {
        width: args.width.or(defaults.width),
        spp: args.spp.unwrap_or(defaults.spp),
        bounces: args.bounces.unwrap_or(defaults.bounces),
        seed: args.seed.unwrap_or(defaults.seed),
        sampler: match args.sampler {
            Some(SamplerArg::Sobol) => SamplerKind::Sobol,
            Some(SamplerArg::Independent) => SamplerKind::Independent,
            None => defaults.sampler,
        },
        ..defaults
    };
    check_settings(&settings)?;

    let started = Instant::now();
    let (lighting, set) = plan
        .build(scene)
        .map_err(|e| usage(format!("{}: lighting: {e}", args.scene.display())))?;
    let seconds_lighting = started.elapsed().as_secs_f64();

    let bar = progress::bar("rendering", 1);
    let started = Instant::now();
    let output = ibl_render::render(scene, &lighting, &settings, &progress::rows_callback(&bar))
        .map_err(|e| usage(format!("{}: {e}", args.scene.display())))?;
    bar.finish_and_clear();
    let seconds_render = started.elapsed().as_secs_f64();

    write_outputs(&output, &outputs)?;

    let stats = output.stats;
    let summary = Summary {
        scene: args.scene.display().to_string(),
        mode: plan.mode.name(),
        lights: set.as_ref().map(|s| LightsSummary {
            source: lights_file.as_ref().map_or_else(
                || format!("{} (extracted)", plan.method),
                |p| p.display().to_string(),
            ),
            count: s.lights.len(),
            shadows: plan.shadows.name(),
        }),
        width: stats.width,
        height: stats.height,
        spp: stats.spp,
        bounces: settings.bounces,
        seed: settings.seed,
        sampler: settings.sampler.name(),
        seconds_lighting,
        seconds_render,
        rays: stats.rays,
        rays_per_second: stats.rays as f64 / seconds_render.max(1e-9),
        paths: stats.paths,
        paths_without_objects: stats.paths_without_objects,
        object_coverage: stats.object_coverage,
        real_triangles: scene.real.triangle_count(),
        virtual_triangles: scene.virtual_objects.triangle_count(),
        outputs: outputs.iter().map(|p| p.display().to_string()).collect(),
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        println!(
            "{}: {} x {}, {} spp, {} mode{}: {:.2} s, {:.1} M rays/s; wrote {}",
            args.scene.display(),
            stats.width,
            stats.height,
            stats.spp,
            plan.mode.name(),
            summary.lights.as_ref().map_or(String::new(), |l| format!(
                " ({} lights, {} shadows)",
                l.count, l.shadows
            )),
            seconds_render,
            summary.rays_per_second / 1e6,
            summary.outputs.join(", ")
        );
    }
    Ok(())
}

fn check_settings(s: &RenderSettings) -> anyhow::Result<()> {
    use ibl_scene::description::{MAX_BOUNCES, MAX_SPP, MAX_WIDTH};
    if !(1..=MAX_SPP).contains(&s.spp) {
        return Err(usage(format!("--spp {} is not in 1..={MAX_SPP}", s.spp)));
    }
    if !(1..=MAX_BOUNCES).contains(&s.bounces) {
        return Err(usage(format!(
            "--bounces {} is not in 1..={MAX_BOUNCES}",
            s.bounces
        )));
    }
    if let Some(w) = s.width
        && !(2..=MAX_WIDTH).contains(&w)
    {
        return Err(usage(format!("--width {w} is not in 2..={MAX_WIDTH}")));
    }
    Ok(())
}

/// The composite, its PNG preview, and the layers: `OUT`, `OUT.png`, `OUT-with.EXT`, ...
fn output_paths(output: &Path, layers: bool) -> Vec<PathBuf> {
    let mut paths = vec![output.to_path_buf(), output.with_extension("png")];
    if layers {
        let ext = output
            .extension()
            .map_or("exr".to_string(), |e| e.to_string_lossy().into_owned());
        let stem = output
            .file_stem()
            .map_or("render".to_string(), |s| s.to_string_lossy().into_owned());
        for layer in ["with", "without"] {
            paths.push(output.with_file_name(format!("{stem}-{layer}.{ext}")));
            paths.push(output.with_file_name(format!("{stem}-{layer}.png")));
        }
        paths.push(output.with_file_name(format!("{stem}-alpha.png")));
    }
    paths
}

/// Writes the images named by [`output_paths`], in its order.
fn write_outputs(output: &RenderOutput, paths: &[PathBuf]) -> anyhow::Result<()> {
    let display = WriteOptions {
        display: Display {
            exposure_stops: ibl_io::tonemap::auto_exposure_stops(&output.background),
            ..Display::default()
        },
        ..WriteOptions::default()
    };
    let alpha: Image<Rgb> = output.object_coverage.map(|&a| Rgb::splat(a));
    let plain = WriteOptions::default();
    let images: Vec<(&Image<Rgb>, &WriteOptions)> = vec![
        (&output.composite, &display),
        (&output.composite, &display),
        (&output.with_objects, &display),
        (&output.with_objects, &display),
        (&output.without_objects, &display),
        (&output.without_objects, &display),
        (&alpha, &plain),
    ];
    for (path, (image, options)) in paths.iter().zip(images) {
        ibl_io::write_image(path, image, options)?;
    }
    Ok(())
}

/// Reads an `ibl lights` JSON file as a light set in iblkit's frame (the probe's frame).
pub fn read_light_set(path: &Path) -> anyhow::Result<LightSet> {
    let file = ibl_io::light_file::read_lights_file(path)?;
    let preset = FramePreset::from_name(&file.frame).ok_or_else(|| {
        usage(format!(
            "{}: unknown frame '{}'",
            path.display(),
            file.frame
        ))
    })?;
    let world_from_preset = preset.world_from_preset().as_dmat3();
    let lights = file
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let d = world_from_preset * DVec3::from_array(l.direction);
            let ok = d.is_finite()
                && (d.length() - 1.0).abs() < 1e-3
                && l.irradiance.iter().all(|c| c.is_finite() && *c >= 0.0)
                && l.solid_angle.is_finite()
                && l.solid_angle >= 0.0;
            if !ok {
                return Err(usage(format!(
                    "{}: light {i}: direction must be a unit vector and irradiance and solid angle finite and non-negative",
                    path.display()
                )));
            }
            Ok(Light {
                direction: d.normalize().to_array(),
                radiance: Rgb::from_array(l.radiance),
                solid_angle_sr: l.solid_angle,
                irradiance: l.irradiance,
                region: None,
            })
        })
        .collect::<anyhow::Result<Vec<Light>>>()
        .with_context(|| format!("reading lights from {}", path.display()))?;
    Ok(LightSet {
        method: file.method.name.clone(),
        lights,
    })
}

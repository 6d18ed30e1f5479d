//! Virtual objects lit by a light probe and composited into the probe panorama or a photograph by
//! differential rendering (`ibl render`; `ibl-render`), in one of three lighting modes: the
//! path-traced reference, N directional lights with shadows, or lights plus an occluded SH
//! ambient ([`crate::lighting_plan`]). Writes the composite as EXR (or any format iblkit writes)
//! plus a tone-mapped PNG beside it, and on request the layers (with and without the objects,
//! object coverage).

use std::path::{Path, PathBuf};
use std::time::Instant;

use ibl_core::tonemap::{Display, auto_exposure_stops};
use ibl_core::{Image, Rgb};
use ibl_io::WriteOptions;
use ibl_light::LightSource;
use ibl_render::{RenderOutput, RenderSettings, SamplerKind};
use ibl_scene::description::{MAX_BOUNCES, MAX_SPP, MAX_WIDTH, check_occlusion_rays};
use ibl_scene::{AmbientBands, RenderMode, ShadowKind};
use serde::Serialize;

use crate::envmap_files::check_output;
use crate::error::{Context, PipelineError, Result};
use crate::lighting_plan::LightingPlan;
use crate::progress::{Progress, rows};

/// Where the render looks from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum View {
    /// The scene's `[camera]` (or the whole panorama when it has none).
    #[default]
    SceneCamera,
    /// The whole panorama seen from the probe's centre (panorama backgrounds only).
    Panorama,
}

/// Which images are written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Layers {
    /// The composite and its preview.
    #[default]
    Composite,
    /// Also the local scene with and without the objects and the objects' coverage.
    All,
}

/// A render: the scene file and what the front end overrides (`None`: the scene's value).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderJob {
    /// Scene file (TOML, docs/SCENES.md).
    pub scene: PathBuf,
    /// Output image.
    pub output: PathBuf,
    /// Lighting mode.
    pub mode: Option<RenderMode>,
    /// A light file for the lights and hybrid modes, instead of extracting.
    pub lights_file: Option<PathBuf>,
    /// Extraction method (or the dominant light).
    pub method: Option<LightSource>,
    /// Number of lights to extract.
    pub lights: Option<usize>,
    /// Shadows of the lights and hybrid modes.
    pub shadows: Option<ShadowKind>,
    /// Samples per pixel (`None`: the scene's `[render] spp` for the reference, `[lighting] spp`
    /// for the lights and hybrid modes).
    pub spp: Option<u32>,
    /// Random numbers of the samples.
    pub sampler: Option<SamplerKind>,
    /// SH bands the hybrid ambient's occlusion rays read (`[lighting] ambient_bands`).
    pub ambient_bands: Option<AmbientBands>,
    /// Occlusion rays per shading point and sample of the hybrid (`[lighting] ao_samples`).
    pub occlusion_rays: Option<u32>,
    /// Every pixel takes all its samples in the lights and hybrid modes (`false`: the scene's
    /// `[lighting] adaptive`, on by default).
    pub no_adaptive: bool,
    /// Adaptive sampling of the reference mode (`false`: the scene's `[render]
    /// adaptive_sampling`, off by default).
    pub adaptive_sampling: bool,
    /// Output width in pixels.
    pub width: Option<u32>,
    /// Surface vertices per path.
    pub bounces: Option<u32>,
    /// Random seed.
    pub seed: Option<u64>,
    /// Where the render looks from.
    pub view: View,
    /// Which images are written.
    pub layers: Layers,
}

/// The lights of a render in its summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LightsSummary {
    /// The light file, or `<method> (extracted)`.
    pub source: String,
    /// Number of lights.
    pub count: usize,
    /// `hard` or `soft`.
    pub shadows: &'static str,
    /// Hybrid mode: the SH bands the ambient's occlusion rays read and the rays per sample
    /// (`None` in the lights mode).
    pub ambient: Option<AmbientSummary>,
}

/// The hybrid ambient of a render in its summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AmbientSummary {
    /// SH bands the occlusion rays read (`[lighting] ambient_bands` resolved for the render's
    /// samples per pixel).
    pub ray_bands: usize,
    /// `auto` or the scene's fixed count.
    pub ambient_bands: String,
    /// Occlusion rays per shading point and sample.
    pub occlusion_rays: u32,
}

/// What a render did (the JSON of `ibl render --json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RenderSummary {
    /// The scene file, as given.
    pub scene: String,
    /// The mode.
    pub mode: &'static str,
    /// The lights (lights and hybrid modes).
    pub lights: Option<LightsSummary>,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel (the most a pixel takes with adaptive antialiasing).
    pub spp: u32,
    /// Adaptive antialiasing's contrast threshold (lights and hybrid modes; `None`: off).
    pub adaptive_contrast: Option<f32>,
    /// Adaptive sampling of the reference mode: `spp` is then the mean.
    pub adaptive_sampling: bool,
    /// Pixels that took all `spp` samples (adaptive sampling: more than `spp`).
    pub refined_pixels: u64,
    /// Bounces.
    pub bounces: u32,
    /// Seed.
    pub seed: u64,
    /// `sobol` or `independent`.
    pub sampler: &'static str,
    /// Seconds to make the lighting.
    pub seconds_lighting: f64,
    /// Seconds to render.
    pub seconds_render: f64,
    /// Rays traced.
    pub rays: u64,
    /// Rays per second of rendering.
    pub rays_per_second: f64,
    /// Paths traced.
    pub paths: u64,
    /// Paths traced again without the objects.
    pub paths_without_objects: u64,
    /// Share of pixels the objects cover.
    pub object_coverage: f64,
    /// Triangles of the local scene.
    pub real_triangles: usize,
    /// Triangles of the virtual objects.
    pub virtual_triangles: usize,
    /// Files written.
    pub outputs: Vec<String>,
}

/// The one-line summary `ibl render` prints: size, samples (with the share of pixels adaptive
/// antialiasing refined), mode and lights, time, ray rate and the files written.
impl std::fmt::Display for RenderSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let pixels = (u64::from(self.width) * u64::from(self.height)).max(1);
        let share = 100.0 * self.refined_pixels as f64 / pixels as f64;
        let spp = match (self.adaptive_contrast, self.adaptive_sampling) {
            (Some(_), _) => format!("up to {} spp ({share:.0} % of pixels refined)", self.spp),
            (None, true) => format!(
                "{} spp on average, adaptive ({share:.0} % of pixels took more)",
                self.spp
            ),
            (None, false) => format!("{} spp", self.spp),
        };
        let lights = self.lights.as_ref().map_or(String::new(), |l| {
            let ambient = l.ambient.as_ref().map_or(String::new(), |a| {
                format!(
                    ", ambient read in {} bands by {} rays a sample",
                    a.ray_bands, a.occlusion_rays
                )
            });
            format!(" ({} lights, {} shadows{ambient})", l.count, l.shadows)
        });
        write!(
            f,
            "{}: {} x {}, {spp}, {} mode{lights}: {:.2} s, {:.1} M rays/s; wrote {}",
            self.scene,
            self.width,
            self.height,
            self.mode,
            self.seconds_render,
            self.rays_per_second / 1e6,
            self.outputs.join(", ")
        )
    }
}

/// Reads the scene, builds the lighting, renders and writes the images.
pub fn render_scene(job: &RenderJob, progress: &dyn Progress) -> Result<RenderSummary> {
    let scene_name = job.scene.display().to_string();
    let mut loaded = ibl_io::read_scene(&job.scene)?;
    let mut inputs: Vec<&Path> = loaded.inputs.iter().map(PathBuf::as_path).collect();
    if let Some(l) = &job.lights_file {
        inputs.push(l);
    }
    let outputs = output_paths(&job.output, job.layers);
    for out in &outputs {
        // Refuse an unwritable format now, not after the render.
        check_output(out, &inputs)?;
    }
    if job.view == View::Panorama {
        if !matches!(loaded.scene.background, ibl_scene::Background::Panorama) {
            return Err(PipelineError::parameter(format!(
                "{scene_name}: --panorama needs a panorama background (this scene has a photograph)"
            )));
        }
        loaded.scene.camera = ibl_scene::Camera::Panorama {
            position: loaded.scene.probe.position,
            world_from_probe: loaded.scene.probe.world_from_probe,
        };
    }
    let scene = &loaded.scene;
    let mut plan = LightingPlan::from_scene(scene);
    plan.mode = job.mode.unwrap_or(plan.mode);
    plan.source = job.method.unwrap_or(plan.source);
    plan.lights = job.lights.unwrap_or(plan.lights);
    plan.shadows = job.shadows.unwrap_or(plan.shadows);
    plan.seed = job.seed.unwrap_or(plan.seed);
    plan.ambient_bands = job.ambient_bands.unwrap_or(plan.ambient_bands);
    plan.occlusion_rays = job.occlusion_rays.unwrap_or(plan.occlusion_rays);
    let lights_file = job.lights_file.clone().or(loaded.lights_path.clone());
    if let Some(path) = &lights_file {
        let scale = loaded.description.probe.radiance_scale;
        plan = match (job.lights_file.is_some(), plan.with_light_file(path, scale)) {
            (_, Ok(plan)) => plan,
            (true, Err(e)) => return Err(e),
            // A light file named by the scene: say which scene and field named it.
            (false, Err(e)) => return Err(e.context(format!("{scene_name}: lighting.lights_file"))),
        };
    }
    let defaults = RenderSettings::for_scene(scene, plan.mode);
    let settings = RenderSettings {
        width: job.width.or(defaults.width),
        spp: job.spp.unwrap_or(defaults.spp),
        bounces: job.bounces.unwrap_or(defaults.bounces),
        seed: job.seed.unwrap_or(defaults.seed),
        sampler: job.sampler.unwrap_or(defaults.sampler),
        adaptive: defaults.adaptive.filter(|_| !job.no_adaptive),
        adaptive_sampling: defaults.adaptive_sampling
            || (job.adaptive_sampling && plan.mode == RenderMode::Reference),
        ..defaults
    };
    check_settings(&settings)?;
    check_ambient(job)?;

    let started = Instant::now();
    let (lighting, set) = plan
        .build(scene, settings.spp)
        .context(format!("{scene_name}: lighting"))?;
    let seconds_lighting = started.elapsed().as_secs_f64();

    progress.begin("rendering", 1);
    let started = Instant::now();
    let output = ibl_render::render(scene, &lighting, &settings, &rows(progress));
    progress.end();
    let output = output.context(&scene_name)?;
    let seconds_render = started.elapsed().as_secs_f64();

    write_outputs(&output, &outputs)?;

    let stats = output.stats;
    Ok(RenderSummary {
        scene: scene_name,
        mode: plan.mode.name(),
        lights: set.as_ref().map(|s| LightsSummary {
            source: lights_file.as_ref().map_or_else(
                || format!("{} (extracted)", plan.source),
                |p| p.display().to_string(),
            ),
            count: s.lights.len(),
            shadows: plan.shadows.name(),
            ambient: (plan.mode == RenderMode::Hybrid).then(|| AmbientSummary {
                ray_bands: plan.ray_bands(settings.spp),
                ambient_bands: plan.ambient_bands.name(),
                occlusion_rays: plan.occlusion_rays,
            }),
        }),
        width: stats.width,
        height: stats.height,
        spp: stats.spp,
        adaptive_contrast: settings
            .adaptive
            .filter(|_| plan.mode != RenderMode::Reference),
        adaptive_sampling: settings.adaptive_sampling,
        refined_pixels: stats.refined_pixels,
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
    })
}

fn check_settings(s: &RenderSettings) -> Result<()> {
    if !(1..=MAX_SPP).contains(&s.spp) {
        return Err(PipelineError::parameter(format!(
            "--spp {} is not in 1..={MAX_SPP}",
            s.spp
        )));
    }
    if !(1..=MAX_BOUNCES).contains(&s.bounces) {
        return Err(PipelineError::parameter(format!(
            "--bounces {} is not in 1..={MAX_BOUNCES}",
            s.bounces
        )));
    }
    if let Some(w) = s.width
        && !(2..=MAX_WIDTH).contains(&w)
    {
        return Err(PipelineError::parameter(format!(
            "--width {w} is not in 2..={MAX_WIDTH}"
        )));
    }
    Ok(())
}

/// The hybrid ambient's overrides against their ranges.
fn check_ambient(job: &RenderJob) -> Result<()> {
    let bands = job.ambient_bands.map_or(Ok(()), AmbientBands::check);
    let rays = job.occlusion_rays.map_or(Ok(()), check_occlusion_rays);
    bands
        .map_err(|e| format!("--ambient-bands {e}"))
        .and_then(|()| rays.map_err(|e| format!("--ao-rays {e}")))
        .map_err(PipelineError::parameter)
}

/// The composite, its PNG preview, and the layers: `OUT`, `OUT.png`, `OUT-with.EXT`, ...
fn output_paths(output: &Path, layers: Layers) -> Vec<PathBuf> {
    let mut paths = vec![output.to_path_buf(), output.with_extension("png")];
    if layers == Layers::All {
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
    // A PNG output is its own preview: written and reported once.
    paths.dedup();
    paths
}

/// Writes the images named by [`output_paths`], in its order.
fn write_outputs(output: &RenderOutput, paths: &[PathBuf]) -> Result<()> {
    let display = WriteOptions {
        display: Display {
            exposure_stops: auto_exposure_stops(&output.background),
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

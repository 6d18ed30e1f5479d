//! The headless path: the window's renderers drawing offscreen, frame after frame, timed.
//!
//! `frames` draws K frames of the scene as it is (the first draws the shadow atlases, the others
//! reuse them: what an idle window costs); `bench` orbits the camera once around the objects and
//! moves the first object along a small circle (turning it as it goes), so every frame redraws
//! the virtual atlas and the real atlas when the object leaves its region: what dragging an
//! object while the camera moves costs. Each frame is timed on the CPU (recording and
//! submitting), on the GPU (timestamps, per pass, when the device has them) and by the wall clock
//! from the start of recording until the GPU has finished, which is what the frame rate counts.

use std::time::Instant;

use glam::Vec3;
use ibl_core::tonemap::Display;
use serde::Serialize;

use crate::ViewerError;
use crate::frame_targets::FrameImages;
use crate::gpu::{AdapterSummary, GpuContext};
use crate::lighting::{SceneLighting, SceneLightingRequest, scene_lighting};
use crate::probe_model::{ProbeModel, ProbeViewSettings};
use crate::probe_renderer::ProbeRenderer;
use crate::room_overlay::{OverlayView, RoomOverlay};
use crate::scene_model::SceneModel;
use crate::scene_renderer::{FrameReport, GlossySource, SceneFrameSettings, SceneRenderer};
use crate::sequence_player::{PlayedFrame, SequencePlayer};
use crate::timing::{PassTimes, median_p95};
use crate::view_camera::{OrbitControl, OutputCamera};

/// What the frames do.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Motion {
    /// Nothing moves.
    Still,
    /// The camera orbits and the first object moves (the benchmark).
    Orbit,
    /// An outdoor sequence plays, one frame of it per frame, the camera fixed (its own).
    Sequence,
}

/// How to render headless.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadlessOptions {
    /// Output size, pixels.
    pub size: (u32, u32),
    /// How many frames.
    pub frames: u32,
    /// Still or orbit.
    pub motion: Motion,
    /// Shadow map side per light, texels.
    pub shadow_tile: u32,
    /// Glossy reflections.
    pub glossy: GlossySource,
    /// Background rays per pixel axis.
    pub background_rays: u32,
    /// Exposure and curve; `None`: automatic from the probe, Reinhard (as `ibl render`).
    pub display: Option<Display>,
    /// An outdoor sequence's sky as this many shadowed lights (0: the unshadowed ambient;
    /// [`SequencePlayer::sky_lights`]).
    pub sky_lights: usize,
    /// Per-tile light culling on real surfaces ([`SceneFrameSettings::light_culling`]).
    pub light_culling: bool,
    /// Closed objects' away-facing triangles left out of the shadow maps
    /// ([`SceneFrameSettings::shadow_culling`]).
    pub shadow_culling: bool,
    /// Coarser copies of the objects in the shadow maps
    /// ([`SceneFrameSettings::shadow_levels`]).
    pub shadow_levels: bool,
}

impl Default for HeadlessOptions {
    fn default() -> Self {
        HeadlessOptions {
            size: (640, 480),
            frames: 1,
            motion: Motion::Still,
            shadow_tile: DEFAULT_SHADOW_TILE,
            glossy: GlossySource::Lights,
            background_rays: 4,
            display: None,
            sky_lights: 0,
            light_culling: true,
            shadow_culling: true,
            shadow_levels: true,
        }
    }
}

/// Default shadow map side per light, texels.
pub const DEFAULT_SHADOW_TILE: u32 = 1024;

/// The timing of one frame.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FrameTiming {
    /// Seconds of CPU work recording and submitting it.
    pub cpu_seconds: f64,
    /// Seconds of GPU work (sum over its passes), when the device has timestamps.
    pub gpu_seconds: Option<f64>,
    /// Seconds from the start of recording until the GPU finished.
    pub wall_seconds: f64,
    /// GPU seconds per pass.
    pub passes: Option<PassTimes>,
    /// Whether the real atlas was redrawn.
    pub drew_real_shadows: bool,
    /// Whether the virtual atlas was redrawn.
    pub drew_virtual_shadows: bool,
}

/// Frame-rate statistics over a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RunStatistics {
    /// Frames per second at the median wall-clock frame time.
    pub fps_median: f64,
    /// Frames per second at the 95th-percentile frame time (the slowest 5 % are slower).
    pub fps_p95: f64,
    /// Median wall-clock frame time, milliseconds.
    pub frame_ms_median: f64,
    /// 95th-percentile wall-clock frame time, milliseconds.
    pub frame_ms_p95: f64,
    /// Median CPU time per frame, milliseconds.
    pub cpu_ms_median: f64,
    /// Median GPU time per frame, milliseconds (when timestamps exist).
    pub gpu_ms_median: Option<f64>,
}

/// A headless run.
#[derive(Clone, Debug)]
pub struct HeadlessRun {
    /// The last frame.
    pub images: FrameImages,
    /// Every frame's timing.
    pub frames: Vec<FrameTiming>,
    /// The adapter.
    pub adapter: AdapterSummary,
    /// Lights drawn (0 for a probe).
    pub lights: usize,
    /// Their description.
    pub lighting: String,
    /// Seconds spent making the lights (before the first frame; a sequence: the mean per
    /// frame, each frame making its own).
    pub lighting_seconds: f64,
    /// Shadow map side per light, texels.
    pub shadow_tile: u32,
    /// Statistics over the frames (the first excluded when there are more than one: it uploads
    /// and draws what the others reuse).
    pub statistics: RunStatistics,
    /// The sequence frames played, in order (a sequence only).
    pub played: Vec<PlayedFrame>,
    /// Seconds of the sequence's offline step (a sequence only).
    pub setup_seconds: Option<f64>,
}

fn statistics(frames: &[FrameTiming]) -> RunStatistics {
    let steady = if frames.len() > 1 {
        &frames[1..]
    } else {
        frames
    };
    let wall: Vec<f64> = steady.iter().map(|f| f.wall_seconds).collect();
    let cpu: Vec<f64> = steady.iter().map(|f| f.cpu_seconds).collect();
    let gpu: Vec<f64> = steady.iter().filter_map(|f| f.gpu_seconds).collect();
    let (m, p95) = median_p95(&wall);
    RunStatistics {
        fps_median: if m > 0.0 { 1.0 / m } else { 0.0 },
        fps_p95: if p95 > 0.0 { 1.0 / p95 } else { 0.0 },
        frame_ms_median: m * 1e3,
        frame_ms_p95: p95 * 1e3,
        cpu_ms_median: median_p95(&cpu).0 * 1e3,
        gpu_ms_median: (!gpu.is_empty()).then(|| median_p95(&gpu).0 * 1e3),
    }
}

/// The camera headless frames start from: the scene's own view, or (a panorama without a
/// `[camera]`) forward from the probe's centre with a 60-degree field of view.
pub fn scene_camera(model: &SceneModel, width: u32, height: u32) -> OutputCamera {
    OutputCamera::from_scene(&model.scene.camera, width, height).unwrap_or_else(|| {
        let orbit = OrbitControl {
            target: model.scene.probe.position,
            distance: 0.0,
            yaw: 0.0,
            pitch: 0.0,
            vertical_fov: 60f32.to_radians(),
        };
        orbit.camera(width, height)
    })
}

/// The orbit a benchmark flies: about the objects' centre at the starting camera's distance.
fn bench_orbit(model: &SceneModel, start: &OutputCamera) -> OrbitControl {
    let target = model.objects_sphere().map_or(
        start.position + start.ray(0.5 * start.size.0 as f32, 0.5 * start.size.1 as f32),
        |(c, _)| c,
    );
    let offset = start.position - target;
    let distance = offset.length().max(0.1);
    OrbitControl::from_view(start.position, -offset, distance, start.vertical_fov())
}

/// Waits for the GPU to finish everything submitted.
fn finish(gpu: &GpuContext) -> Result<(), ViewerError> {
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| ViewerError::Gpu(format!("waiting for the frame: {e}")))?;
    gpu.take_errors()
}

/// A scene frame's timing once the GPU has finished it (its pass times read); `cpu_before` is
/// CPU work before the frame was recorded (a sequence frame's reading and estimation).
fn scene_frame_timing(
    gpu: &GpuContext,
    renderer: &mut SceneRenderer,
    report: &FrameReport,
    cpu_before: f64,
    wall_seconds: f64,
) -> FrameTiming {
    let passes = renderer.read_pass_times(gpu, true);
    FrameTiming {
        cpu_seconds: cpu_before + report.cpu_seconds,
        gpu_seconds: passes.as_ref().map(PassTimes::total),
        wall_seconds,
        passes,
        drew_real_shadows: report.drew_real_shadows,
        drew_virtual_shadows: report.drew_virtual_shadows,
    }
}

/// Makes the scene's lights now (the headless path waits for them; the window does not).
pub fn lights_now(model: &SceneModel) -> Result<(SceneLighting, f64), ViewerError> {
    let started = Instant::now();
    let lighting = scene_lighting(&SceneLightingRequest {
        scene: std::sync::Arc::clone(&model.scene),
        plan: model.lighting_plan(),
    })
    .map_err(|e| ViewerError::Lighting(format!("{}: {e}", model.path.display())))?;
    Ok((lighting, started.elapsed().as_secs_f64()))
}

/// Renders `options.frames` frames of a scene offscreen; `progress(done, total)` after each.
/// The scene is left as it was (a benchmark's motion is undone).
pub fn render_scene(
    gpu: &GpuContext,
    model: &SceneModel,
    options: &HeadlessOptions,
    progress: &dyn Fn(usize, usize),
) -> Result<HeadlessRun, ViewerError> {
    let (lighting, lighting_seconds) = lights_now(model)?;
    render_scene_lit(gpu, model, lighting, lighting_seconds, options, progress)
}

/// [`render_scene`] with lights made elsewhere (`lighting`, made in `lighting_seconds`): a
/// room's live display, whose lights are the room's.
pub fn render_scene_lit(
    gpu: &GpuContext,
    model: &SceneModel,
    lighting: SceneLighting,
    lighting_seconds: f64,
    options: &HeadlessOptions,
    progress: &dyn Fn(usize, usize),
) -> Result<HeadlessRun, ViewerError> {
    let (w, h) = options.size;
    let lights = lighting.lights.len();
    let summary = lighting.summary.clone();
    let mut renderer = SceneRenderer::new(gpu, model, w, h, options.shadow_tile)?;
    renderer.set_lighting(gpu, lighting);
    let display = options.display.unwrap_or(Display {
        exposure_stops: auto_exposure(model),
        ..Display::default()
    });
    let start = scene_camera(model, w, h);
    let orbit = bench_orbit(model, &start);
    let mut moving = model.clone();
    let radius = model.objects_sphere().map_or(0.1, |(_, r)| r);
    let frames = options.frames.max(1) as usize;
    let mut timings = Vec::with_capacity(frames);
    for k in 0..frames {
        let camera = match options.motion {
            Motion::Still => start,
            Motion::Orbit | Motion::Sequence => {
                let phase = std::f32::consts::TAU * k as f32 / frames as f32;
                let mut o = orbit;
                o.turn(phase, 0.0);
                if moving.object_count() > 0 {
                    moving.description.object[0] = model.description.object[0].clone();
                    let circle = Vec3::new(phase.cos() - 1.0, 0.0, phase.sin()) * (0.5 * radius);
                    moving.translate(0, circle);
                    moving.rotate(0, phase.to_degrees());
                }
                o.camera(w, h)
            }
        };
        let settings = SceneFrameSettings {
            camera,
            display,
            glossy: options.glossy,
            background_rays: options.background_rays,
            shadow_tile: options.shadow_tile,
            selected: None,
            light_culling: options.light_culling,
            shadow_culling: options.shadow_culling,
            shadow_levels: options.shadow_levels,
        };
        let started = Instant::now();
        let report = renderer.render(gpu, &moving, &settings);
        finish(gpu)?;
        let wall_seconds = started.elapsed().as_secs_f64();
        timings.push(scene_frame_timing(
            gpu,
            &mut renderer,
            &report,
            0.0,
            wall_seconds,
        ));
        progress(k + 1, frames);
    }
    let images = renderer.targets().read_back(gpu)?;
    Ok(HeadlessRun {
        images,
        statistics: statistics(&timings),
        frames: timings,
        adapter: gpu.summary.clone(),
        lights,
        lighting: summary,
        lighting_seconds,
        shadow_tile: renderer.shadow_tile(),
        played: Vec::new(),
        setup_seconds: None,
    })
}

/// Plays `options.frames` frames of an outdoor sequence offscreen (from its first frame, again
/// from the first after the last), each frame one sequence frame: read, estimated, relit and
/// drawn with the scene's camera; `progress(done, total)` after each. A frame's wall time counts
/// all of it, from reading the frame to the GPU's end.
pub fn render_sequence(
    gpu: &GpuContext,
    model: &SceneModel,
    player: &mut SequencePlayer,
    options: &HeadlessOptions,
    progress: &dyn Fn(usize, usize),
) -> Result<HeadlessRun, ViewerError> {
    let (w, h) = options.size;
    player.sky_lights = options.sky_lights;
    let mut renderer = SceneRenderer::new(gpu, model, w, h, options.shadow_tile)?;
    let display = options.display.unwrap_or(Display {
        exposure_stops: auto_exposure(model),
        ..Display::default()
    });
    let settings = SceneFrameSettings {
        camera: scene_camera(model, w, h),
        display,
        glossy: options.glossy,
        background_rays: options.background_rays,
        shadow_tile: options.shadow_tile,
        selected: None,
        light_culling: options.light_culling,
        shadow_culling: options.shadow_culling,
        shadow_levels: options.shadow_levels,
    };
    let frames = options.frames.max(1) as usize;
    let mut timings = Vec::with_capacity(frames);
    let mut played = Vec::with_capacity(frames);
    let mut summary = String::new();
    let mut lighting_seconds = 0.0;
    for k in 0..frames {
        let started = Instant::now();
        let step = player.step()?;
        summary = step.lighting.summary.clone();
        let cpu_started = Instant::now();
        let frame = step.show(gpu, model, &mut renderer, player.relit_map());
        let upload_seconds = cpu_started.elapsed().as_secs_f64();
        let report = renderer.render(gpu, model, &settings);
        finish(gpu)?;
        let wall_seconds = started.elapsed().as_secs_f64();
        let f = &frame;
        lighting_seconds += f.lighting_seconds;
        let before = f.read_seconds + f.estimate_seconds + f.lighting_seconds + upload_seconds;
        timings.push(scene_frame_timing(
            gpu,
            &mut renderer,
            &report,
            before,
            wall_seconds,
        ));
        played.push(frame);
        progress(k + 1, frames);
    }
    let images = renderer.targets().read_back(gpu)?;
    Ok(HeadlessRun {
        images,
        statistics: statistics(&timings),
        frames: timings,
        adapter: gpu.summary.clone(),
        lights: renderer.lighting().map_or(0, |l| l.lights.len()),
        lighting: summary,
        lighting_seconds: lighting_seconds / frames as f64,
        shadow_tile: renderer.shadow_tile(),
        played,
        setup_seconds: Some(player.setup_seconds),
    })
}

/// The exposure `ibl render` previews a scene with: automatic from its background.
pub fn auto_exposure(model: &SceneModel) -> f32 {
    match &model.scene.background {
        ibl_scene::Background::Photo(photo) => ibl_core::tonemap::auto_exposure_stops(photo),
        ibl_scene::Background::Panorama => {
            ibl_core::tonemap::auto_exposure_stops(&model.scene.probe.radiance)
        }
    }
}

/// Renders `options.frames` frames of the probe viewer offscreen (overlays computed first).
pub fn render_probe(
    gpu: &GpuContext,
    model: &ProbeModel,
    settings: &ProbeViewSettings,
    options: &HeadlessOptions,
    progress: &dyn Fn(usize, usize),
) -> Result<HeadlessRun, ViewerError> {
    render_probe_with(gpu, model, settings, options, None, progress)
}

/// [`render_probe`] with the room overlays drawn over every frame (marked lines, room edges).
pub fn render_probe_with(
    gpu: &GpuContext,
    model: &ProbeModel,
    settings: &ProbeViewSettings,
    options: &HeadlessOptions,
    room: Option<&RoomOverlay>,
    progress: &dyn Fn(usize, usize),
) -> Result<HeadlessRun, ViewerError> {
    let (w, h) = options.size;
    let mut renderer = ProbeRenderer::new(gpu, model, w, h)?;
    let started = Instant::now();
    let needs_overlay = settings.overlays.lights
        || settings.overlays.regions
        || settings.overlays.dominant
        || settings.layer == crate::probe_pass::ProbeLayer::ShIrradiance;
    let mut lights = 0;
    let mut lighting = String::new();
    if needs_overlay {
        let overlay = crate::lighting::probe_overlay(&crate::lighting::ProbeOverlayRequest {
            probe: std::sync::Arc::clone(&model.latlong),
            spec: settings.spec,
            lights: settings.lights,
            bands: settings.bands,
        })
        .map_err(|e| ViewerError::Lighting(format!("{}: {e}", model.path.display())))?;
        lights = overlay.set.lights.len();
        lighting = format!(
            "{lights} {} lights, SH{} irradiance",
            settings.spec,
            settings.bands * settings.bands
        );
        renderer.set_overlay(gpu, overlay);
    }
    let lighting_seconds = started.elapsed().as_secs_f64();
    let frames = options.frames.max(1) as usize;
    let mut timings = Vec::with_capacity(frames);
    let mut view = *settings;
    for k in 0..frames {
        if options.motion == Motion::Orbit {
            view.orbit = settings.orbit;
            view.orbit
                .turn(std::f32::consts::TAU * k as f32 / frames as f32, 0.0);
        }
        let started = Instant::now();
        let segments = room
            .map(|r| r.segments(&OverlayView::of_settings(&view, w, h), 1.0))
            .unwrap_or_default();
        let cpu_seconds = renderer.render_with(gpu, &view, 1.0, &segments);
        finish(gpu)?;
        let wall_seconds = started.elapsed().as_secs_f64();
        let passes = renderer.read_pass_times(gpu, true);
        timings.push(FrameTiming {
            cpu_seconds,
            gpu_seconds: passes.as_ref().map(PassTimes::total),
            wall_seconds,
            passes,
            drew_real_shadows: false,
            drew_virtual_shadows: false,
        });
        progress(k + 1, frames);
    }
    let images = renderer.targets().read_back(gpu)?;
    Ok(HeadlessRun {
        images,
        statistics: statistics(&timings),
        frames: timings,
        adapter: gpu.summary.clone(),
        lights,
        lighting,
        lighting_seconds,
        shadow_tile: 0,
        played: Vec::new(),
        setup_seconds: None,
    })
}

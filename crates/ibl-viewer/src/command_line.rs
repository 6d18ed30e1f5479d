//! The viewer's command line (`ibl view`): its arguments, parsed by clap, and the one call that
//! opens the window or runs the headless job. It lives in the viewer, a front end, so the `ibl`
//! binary only forwards the arguments and prints the summary.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use ibl_core::tonemap::ToneCurve;
use ibl_pipeline::Progress;

use crate::headless::{self, HeadlessOptions, Motion};
use crate::probe_model::Overlays;
use crate::probe_pass::{ProbeLayer, ProbeProjection};
use crate::scene_renderer::GlossySource;
use crate::view_job::{ProbeExtras, ProbeViewOptions, ViewJob, ViewSummary, is_scene};
use crate::window::{self, WindowOptions};
use crate::{Mapping, ViewerError};

/// The tone curves on the command line (`ibl view`, `ibl preview`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CurveArg {
    /// Clip at 1.
    Clamp,
    /// `x / (1 + x)`.
    Reinhard,
    /// ACES filmic (Narkowicz fit).
    Aces,
}

impl From<CurveArg> for ToneCurve {
    fn from(c: CurveArg) -> ToneCurve {
        match c {
            CurveArg::Clamp => ToneCurve::Clamp,
            CurveArg::Reinhard => ToneCurve::Reinhard,
            CurveArg::Aces => ToneCurve::AcesFilmic,
        }
    }
}

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
  ibl view assets/outdoor/courtyard/scene.toml          play an outdoor sequence: sun and sky per frame
  ibl view assets/outdoor/courtyard/scene.toml --headless --bench --frames 24 --json
  ibl view probe.exr --marks marks.json --room room.toml  marked lines and the room over the probe
  ibl view probe.exr --marks marks.json --headless --yaw 30 --fov 100 -o shot.png
  ibl view assets/probes/apartment.exr --room assets/rooms/apartment/room.toml \
      --edit assets/rooms/apartment/edits-light.toml      the room with a new IES light

In the window: left-drag turns the camera (or moves the object under the cursor), Shift-drag
turns the object, Ctrl-drag scales it, right-drag pans, the wheel zooms; F12 saves the frame as
EXR and PNG, Ctrl+S saves the scene, F11 toggles full screen; drop a probe or scene file onto the
window to open it. -o FRAME writes FRAME and FRAME's .exr (or .png) twin.

A scene with an [outdoor] table (docs/OUTDOOR.md) is played as a sequence: each frame's sun
and sky are estimated as `ibl outdoor` does, and the frame, the sun (with its shadow) and the
ambient are drawn live; the Sequence section plays, pauses and steps, and shows the estimates,
their chart and the relit map. Headless, --frames K plays K sequence frames.

Room tools (probe; docs/ROOMS.md): marked lines are drawn x red, y green, z blue, the room's
edges white. In the window's Room section, M switches marking on: a left-drag draws a line
(right-drag turns), X/Y/Z pick its axis, Backspace removes the last; \"calibrate\" runs `ibl
room calibrate`'s calibration, \"save marks\" writes the marks file. \"edit the room's materials\"
estimates the room; then a click picks a surface's group and a colour sets its new reflectance,
shown at once with its colour bleeding (Grosch 2005 section 4.3).")]
pub struct ViewArgs {
    /// A probe (any format and mapping ibl reads) or a scene file (.toml, docs/SCENES.md).
    pub input: PathBuf,
    /// Render offscreen (no window) and write the last frame.
    #[arg(long)]
    pub headless: bool,
    /// Frame size, WIDTHxHEIGHT pixels (headless; the window starts at this size).
    #[arg(long, value_name = "WxH", default_value = "640x480", value_parser = frame_size)]
    pub size: (u32, u32),
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
    #[arg(long, value_name = "MAPPING", value_parser = mapping)]
    pub mapping: Option<Mapping>,
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
    #[arg(long, value_name = "LIST", default_value = "lights,dominant", value_parser = overlays)]
    pub overlay: Overlays,
    /// Shadow map side per light, texels (shrunk when the atlas would exceed 4096^2).
    #[arg(long, value_name = "TEXELS", default_value_t = headless::DEFAULT_SHADOW_TILE,
          value_parser = clap::value_parser!(u32).range(64..=8192))]
    pub shadow_size: u32,
    /// Glossy reflections.
    #[arg(long, value_enum, default_value = "lights")]
    pub glossy: GlossyArg,
    /// The background's antialiasing: where the probe is magnified each pixel takes its area's
    /// share of the 2 x 2 texels under it (as `ibl render`); elsewhere (a pole, a minified probe)
    /// N x N rays per pixel. 1: the texel at the pixel's centre only.
    #[arg(long, value_name = "N", default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=8))]
    pub background_rays: u32,
    /// Marks file (`iblkit.marks/1`, docs/ROOMS.md) whose lines are drawn over a probe; the
    /// window's Room section adds to them and saves them.
    #[arg(long, value_name = "MARKS.json")]
    pub marks: Option<PathBuf>,
    /// Room file (docs/ROOMS.md) whose edges are drawn over a probe, seen from its probe; the
    /// window's Room section edits its materials by clicking.
    #[arg(long, value_name = "ROOM.toml")]
    pub room: Option<PathBuf>,
    /// Edits file (`ibl room render --edit`'s: materials, lights, objects) applied to --room:
    /// the edited panorama is shown instead of the probe.
    #[arg(long, value_name = "EDITS.toml", requires = "room")]
    pub edit: Option<PathBuf>,
    /// Draw the --edit file's objects live on the GPU, in the room as the real layer, with
    /// Grosch's display the file names (fast or improved): they can be dragged, every patch's
    /// shadow following. The frame is the scene camera's: the file's `[view]`, or from the
    /// probe's centre towards the objects.
    #[arg(long, requires = "edit")]
    pub live: bool,
    /// An outdoor sequence's sky as N shadowed median-cut lights (a power of two; 0: the
    /// unshadowed SH ambient): the objects' sky shadow, one shadow map per light.
    #[arg(long, value_name = "N", default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=64))]
    pub sky_lights: u32,
    /// Test every light on every real surface instead of only the lights whose virtual shadow
    /// can reach the pixel's 8 x 8 tile (the same frame, slower; for checking the culling or
    /// measuring what it saves).
    #[arg(long)]
    pub no_light_culling: bool,
    /// Draw every triangle of a closed virtual object into the shadow maps instead of only
    /// those facing the light (the same shadow maps, slower; for checking the culling or
    /// measuring what it saves).
    #[arg(long)]
    pub no_shadow_culling: bool,
    /// Draw the virtual objects' full meshes into the shadow maps instead of their coarser
    /// copies where those lie within half a texel (slower; for checking the copies or
    /// measuring what they save).
    #[arg(long)]
    pub no_shadow_levels: bool,
    /// Camera yaw over a probe, degrees (0 looks along -Z, positive looks left).
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub yaw: Option<f32>,
    /// Camera pitch over a probe, degrees (positive looks up), -89 to 89.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub pitch: Option<f32>,
    /// Vertical field of view over a probe, degrees, 10 to 150 (default 75).
    #[arg(long, value_name = "DEG")]
    pub fov: Option<f32>,
}

impl ViewArgs {
    /// The probe's camera and room overlays the arguments ask for.
    pub fn probe_extras(&self) -> ProbeExtras {
        ProbeExtras {
            yaw_deg: self.yaw,
            pitch_deg: self.pitch,
            fov_deg: self.fov,
            marks: self.marks.clone(),
            room: self.room.clone(),
            edit: self.edit.clone(),
            live: self.live,
        }
    }
}

/// `WxH`, each side 1 to the viewer's limit.
fn frame_size(text: &str) -> Result<(u32, u32), String> {
    let max = crate::frame_targets::MAX_OUTPUT_SIDE;
    let bad = || format!("`{text}`: expected WIDTHxHEIGHT, each side 1 to {max}, e.g. 640x480");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let side = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|v| (1..=max).contains(v))
    };
    Ok((side(w).ok_or_else(bad)?, side(h).ok_or_else(bad)?))
}

/// A mapping by name (`ibl convert`'s names but six face files; fisheyes at 180 degrees).
fn mapping(name: &str) -> Result<Mapping, String> {
    match ibl_pipeline::EnvMapping::parse(name, 180.0).map_err(|e| e.to_string())? {
        ibl_pipeline::EnvMapping::Single(m) => Ok(m),
        ibl_pipeline::EnvMapping::CubeFaces => {
            Err("the viewer reads one image, not six faces".into())
        }
    }
}

/// `lights,regions,dominant` or `none`.
fn overlays(text: &str) -> Result<Overlays, String> {
    let mut o = Overlays {
        lights: false,
        regions: false,
        dominant: false,
    };
    for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        match item {
            "lights" => o.lights = true,
            "regions" => o.regions = true,
            "dominant" => o.dominant = true,
            "none" => {}
            other => {
                return Err(format!(
                    "unknown overlay `{other}` (lights, regions, dominant, none)"
                ));
            }
        }
    }
    Ok(o)
}

/// Runs `ibl view`: the window until it is closed (`None`), or the headless job and its
/// summary.
pub fn run(args: &ViewArgs, progress: &dyn Progress) -> Result<Option<ViewSummary>, ViewerError> {
    let extras = args.probe_extras();
    if !args.headless {
        if args.output.is_some() || args.bench || args.frames.is_some() {
            return Err(ViewerError::Parameter(
                "-o, --frames and --bench need --headless".into(),
            ));
        }
        if is_scene(&args.input) && !extras.is_empty() {
            return Err(ViewerError::Parameter(
                "--marks, --room, --yaw, --pitch and --fov apply to a probe, not a scene".into(),
            ));
        }
        // A bad angle, marks or room file is the command's error (status 2), before any window.
        extras.check()?;
        window::run(WindowOptions {
            input: Some(args.input.clone()),
            mapping: args.mapping,
            size: args.size,
            screenshot: args.screenshot.clone(),
            shadow_tile: args.shadow_size,
            probe: extras,
        })?;
        return Ok(None);
    }
    let job = ViewJob {
        input: args.input.clone(),
        mapping: args.mapping,
        output: args.output.clone(),
        frames: HeadlessOptions {
            size: args.size,
            frames: args.frames.unwrap_or(if args.bench { 120 } else { 1 }),
            motion: if args.bench {
                Motion::Orbit
            } else {
                Motion::Still
            },
            shadow_tile: args.shadow_size,
            glossy: match args.glossy {
                GlossyArg::Lights => GlossySource::Lights,
                GlossyArg::Environment => GlossySource::Environment,
            },
            background_rays: args.background_rays,
            display: None,
            sky_lights: args.sky_lights as usize,
            light_culling: !args.no_light_culling,
            shadow_culling: !args.no_shadow_culling,
            shadow_levels: !args.no_shadow_levels,
        },
        exposure_stops: args.exposure,
        curve: ToneCurve::from(args.tonemap),
        method: args.method.clone(),
        lights: args.n,
        bands: args.bands,
        probe: ProbeViewOptions {
            projection: if args.flat {
                ProbeProjection::LatLong
            } else {
                ProbeProjection::LookAround
            },
            layer: match args.layer {
                LayerArg::Radiance => ProbeLayer::Radiance,
                LayerArg::Irradiance => ProbeLayer::ShIrradiance,
            },
            sharpen: args.sharpen,
            overlays: args.overlay,
        },
    };
    job.run_with(&extras, progress).map(Some)
}

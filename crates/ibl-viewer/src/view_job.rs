//! `ibl view --headless` as one job (the pattern of `ibl-pipeline`: options in, files written
//! through `ibl-io`, a summary out), so that every front end (the command line, the demo, tests)
//! runs the same steps: open a probe or a scene, apply the overrides, check the outputs before any
//! work, render K frames offscreen ([`crate::headless`]), write the last frame as PNG (exactly what
//! was shown, tone-mapped) and EXR (its linear radiance), and return the timings.
//!
//! It lives in the viewer rather than in `ibl-pipeline` because it drives the GPU: the pipeline
//! sits below the front ends and carries no GPU dependency.

use std::path::{Path, PathBuf};

use ibl_core::tonemap::{Display, ToneCurve};
use ibl_extract::ModelSpec;
use ibl_light::LightSource;
use ibl_mapping::Mapping;
use ibl_pipeline::Progress;
use ibl_pipeline::room_input::{read_marks, read_room};
use ibl_scene::AmbientBands;
use serde::Serialize;

use crate::gpu::AdapterSummary;
use crate::headless::{self, HeadlessOptions, HeadlessRun, Motion, RunStatistics};
use crate::probe_model::{Overlays, ProbeModel, ProbeViewSettings};
use crate::probe_pass::{ProbeLayer, ProbeProjection};
use crate::room_overlay::RoomOverlay;
use crate::scene_model::SceneModel;
use crate::sequence_player::{PlayedFrame, SequencePlayer};
use crate::view_camera::OrbitControl;
use crate::{GpuContext, ViewerError};

/// Most SH bands the viewer's irradiance layer and ambient take.
pub const MAX_BANDS: u32 = 16;
/// Most lights a scene may ask the viewer for.
pub const MAX_LIGHTS: u32 = 4096;

/// What the probe viewer shows, when the input is a probe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeViewOptions {
    /// Looking around from the centre, or the flat lat-long.
    pub projection: ProbeProjection,
    /// Radiance or SH irradiance.
    pub layer: ProbeLayer,
    /// Laplacian sharpening strength, 0 to 2 (Grosch 2005 section 3).
    pub sharpen: f32,
    /// Which overlays are drawn.
    pub overlays: Overlays,
}

/// Options of a probe view beyond [`ProbeViewOptions`]: where the camera looks, and the room
/// overlays (Grosch 2005 section 3.1, docs/ROOMS.md): a marks file's lines and a room file's
/// edges drawn over the panorama ([`crate::room_overlay`]). The default changes nothing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ProbeExtras {
    /// The camera's yaw, degrees (about the probe's +Y; 0 looks along -Z, positive looks left).
    pub yaw_deg: Option<f32>,
    /// Its pitch, degrees (positive looks up), within +-89.
    pub pitch_deg: Option<f32>,
    /// Its vertical field of view, degrees, 10 to 150.
    pub fov_deg: Option<f32>,
    /// A marks file (`iblkit.marks/1`) whose lines are drawn.
    pub marks: Option<PathBuf>,
    /// A room file whose edges are drawn.
    pub room: Option<PathBuf>,
    /// An edits file (`ibl room render --edit`'s, docs/ROOMS.md) applied to the room: the
    /// edited panorama is shown instead of the probe (needs `room`).
    pub edit: Option<PathBuf>,
    /// Draw the edits' objects live on the GPU, the room as the real layer (Grosch's display
    /// the edits file names; `crate::room_live`), instead of showing the CPU's panorama.
    pub live: bool,
}

impl ProbeExtras {
    /// Whether it asks for nothing.
    pub fn is_empty(&self) -> bool {
        *self == ProbeExtras::default()
    }

    /// The files it reads (checked against the outputs).
    pub fn inputs(&self) -> Vec<PathBuf> {
        self.marks
            .iter()
            .chain(&self.room)
            .chain(&self.edit)
            .cloned()
            .collect()
    }

    /// The room and edits file of a live display (`live` with both given), else `None`.
    pub fn live_room(&self) -> Option<(&Path, &Path)> {
        match (self.live, &self.room, &self.edit) {
            (true, Some(room), Some(edit)) => Some((room, edit)),
            _ => None,
        }
    }

    /// Turns `orbit` as asked (angles checked).
    pub fn aim(&self, orbit: &mut OrbitControl) -> Result<(), ViewerError> {
        let bad = |what: &str, v: f32, range: &str| {
            ViewerError::Parameter(format!("{what} {v} degrees: must be {range}"))
        };
        if let Some(y) = self.yaw_deg {
            if !y.is_finite() {
                return Err(bad("yaw", y, "a finite angle"));
            }
            orbit.yaw = y.to_radians().rem_euclid(std::f32::consts::TAU);
        }
        if let Some(p) = self.pitch_deg {
            if !(-89.0..=89.0).contains(&p) {
                return Err(bad("pitch", p, "-89 to 89"));
            }
            orbit.pitch = p.to_radians();
        }
        if let Some(f) = self.fov_deg {
            if !(10.0..=150.0).contains(&f) {
                return Err(bad("field of view", f, "10 to 150"));
            }
            orbit.vertical_fov = f.to_radians();
        }
        Ok(())
    }

    /// Checks the angles and reads the files, for a caller that uses them later (the window).
    pub fn check(&self) -> Result<(), ViewerError> {
        let mut orbit = OrbitControl {
            target: glam::Vec3::ZERO,
            distance: 0.0,
            yaw: 0.0,
            pitch: 0.0,
            vertical_fov: 1.0,
        };
        self.aim(&mut orbit)?;
        if self.edit.is_some() && self.room.is_none() {
            return Err(ViewerError::Parameter(
                "--edit applies an edits file to a room: give the room with --room".into(),
            ));
        }
        if let Some(edit) = &self.edit
            && !self.live
        {
            crate::room_edit::read_panorama_edits(edit)?;
        }
        self.overlay().map(|_| ())
    }

    /// Reads the marks and room files (a bad one is an error naming it) into the overlay;
    /// `None` when it names neither.
    pub fn overlay(&self) -> Result<Option<RoomOverlay>, ViewerError> {
        if self.marks.is_none() && self.room.is_none() {
            return Ok(None);
        }
        let marks = self.marks.as_deref().map(read_marks).transpose()?;
        let room = self.room.as_deref().map(read_room).transpose()?;
        Ok(Some(RoomOverlay::new(
            marks.as_ref(),
            room.as_ref().map(|r| &r.room),
        )))
    }
}

/// One headless run of `ibl view`.
#[derive(Clone, Debug)]
pub struct ViewJob {
    /// A probe (any format and mapping) or a scene file (`.toml`).
    pub input: PathBuf,
    /// The probe's mapping (`None`: guessed from its shape).
    pub mapping: Option<Mapping>,
    /// The frame to write (`.png` or `.exr`; its twin of the other format is written beside it).
    pub output: Option<PathBuf>,
    /// Size, frames, motion, shadow maps, glossy source, background rays (its `display` is
    /// ignored: it is made from `exposure_stops` and `curve`).
    pub frames: HeadlessOptions,
    /// Exposure in stops (`None`: automatic, as `ibl preview` and `ibl render`).
    pub exposure_stops: Option<f32>,
    /// Tone curve.
    pub curve: ToneCurve,
    /// Light method: a scene's `[lighting] method` override, or the probe overlay's model.
    pub method: Option<String>,
    /// Number of lights (default: the scene's, or 16 on a probe).
    pub lights: Option<u32>,
    /// SH bands of the probe's irradiance layer or the scene's hybrid ambient.
    pub bands: Option<u32>,
    /// Probe viewer settings (ignored for a scene).
    pub probe: ProbeViewOptions,
}

/// What was viewed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ViewKind {
    /// A light probe.
    Probe,
    /// A scene file.
    Scene,
    /// A scene file with an `[outdoor]` table, played as a sequence.
    Sequence,
}

/// One frame in the summary.
#[derive(Clone, Debug, Serialize)]
pub struct FrameSummary {
    /// CPU time recording and submitting the frame, ms.
    pub cpu_ms: f64,
    /// GPU time (timestamps), ms, when the device has them.
    pub gpu_ms: Option<f64>,
    /// Wall-clock time until the GPU finished, ms.
    pub wall_ms: f64,
    /// GPU time per pass, ms.
    pub passes_ms: Option<Vec<(String, f64)>>,
    /// Whether the real geometry's shadow atlas was redrawn.
    pub real_shadows_drawn: bool,
    /// Whether the virtual objects' shadow atlas was redrawn.
    pub virtual_shadows_drawn: bool,
}

/// What a headless run did (`--json` prints it).
#[derive(Clone, Debug, Serialize)]
pub struct ViewSummary {
    /// The input as given.
    pub input: String,
    /// Probe or scene.
    pub kind: ViewKind,
    /// Frame width, pixels.
    pub width: u32,
    /// Frame height, pixels.
    pub height: u32,
    /// Frames rendered.
    pub frames: usize,
    /// Still or orbiting.
    pub motion: Motion,
    /// The GPU adapter.
    pub adapter: AdapterSummary,
    /// Lights drawn.
    pub lights: usize,
    /// Their description.
    pub lighting: String,
    /// Seconds spent making the lights before the first frame.
    pub lighting_seconds: f64,
    /// Shadow map side per light, texels (0 for a probe).
    pub shadow_map_texels: u32,
    /// Frame-rate statistics (first frame excluded when there are several).
    pub statistics: RunStatistics,
    /// Every frame.
    pub per_frame: Vec<FrameSummary>,
    /// Files written.
    pub outputs: Vec<String>,
    /// The sequence played (a sequence only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sequence: Option<SequenceSummary>,
}

/// What a sequence run played.
#[derive(Clone, Debug, Serialize)]
pub struct SequenceSummary {
    /// Seconds of the offline step (maps, sample sites, volume weights), before the first frame.
    pub setup_seconds: f64,
    /// Every frame played, with its estimate and the CPU seconds of each step.
    pub frames: Vec<PlayedFrame>,
}

/// Whether `path` is a scene file (`.toml`) rather than a probe.
pub fn is_scene(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}

/// The PNG and EXR a frame goes to.
pub fn frame_outputs(output: &Path) -> Result<(PathBuf, PathBuf), ViewerError> {
    match ibl_io::ImageFormat::from_path(output) {
        Some(ibl_io::ImageFormat::Png) => Ok((output.to_path_buf(), output.with_extension("exr"))),
        Some(ibl_io::ImageFormat::Exr) => Ok((output.with_extension("png"), output.to_path_buf())),
        _ => Err(ViewerError::Parameter(format!(
            "{}: a frame is written as .png or .exr (both are written)",
            output.display()
        ))),
    }
}

fn check_bands(bands: u32) -> Result<usize, ViewerError> {
    if (1..=MAX_BANDS).contains(&bands) {
        Ok(bands as usize)
    } else {
        Err(ViewerError::Parameter(format!(
            "SH bands {bands}: must be 1 to {MAX_BANDS}"
        )))
    }
}

/// `--sky-lights N`: a power of two (median cut), for a sequence only.
fn check_sky_lights(n: usize, sequence: bool) -> Result<(), ViewerError> {
    if n == 0 {
        return Ok(());
    }
    if !sequence {
        return Err(ViewerError::Parameter(
            "--sky-lights applies to an outdoor sequence (a scene with an [outdoor] table)".into(),
        ));
    }
    if !n.is_power_of_two() {
        return Err(ViewerError::Parameter(format!(
            "--sky-lights {n}: the sky is split by median cut, which makes a power of two lights"
        )));
    }
    Ok(())
}

fn check_outputs(
    outputs: Option<&(PathBuf, PathBuf)>,
    inputs: &[PathBuf],
) -> Result<(), ViewerError> {
    let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    if let Some((png, exr)) = outputs {
        ibl_io::ensure_output_is_not_input(png, &inputs)?;
        ibl_io::ensure_output_is_not_input(exr, &inputs)?;
    }
    Ok(())
}

impl ViewJob {
    fn display(&self, automatic: f32) -> Result<Display, ViewerError> {
        if self.exposure_stops.is_some_and(|e| !e.is_finite()) {
            return Err(ViewerError::Parameter(
                "the exposure must be a finite number of stops".into(),
            ));
        }
        Ok(Display {
            exposure_stops: self.exposure_stops.unwrap_or(automatic),
            curve: self.curve,
        })
    }

    fn probe_settings(&self, model: &ProbeModel) -> Result<ProbeViewSettings, ViewerError> {
        let mut settings = ProbeViewSettings::for_probe(&model.latlong);
        settings.projection = self.probe.projection;
        settings.layer = self.probe.layer;
        if !(0.0..=2.0).contains(&self.probe.sharpen) {
            return Err(ViewerError::Parameter(format!(
                "sharpening {}: must be 0 to 2",
                self.probe.sharpen
            )));
        }
        settings.sharpen = self.probe.sharpen;
        settings.display = self.display(settings.display.exposure_stops)?;
        if let Some(method) = &self.method {
            settings.spec = method
                .parse::<ModelSpec>()
                .map_err(|e| ViewerError::Parameter(format!("method: {e}")))?;
        }
        if let Some(n) = self.lights {
            settings.lights = n as usize;
        }
        if let Some(b) = self.bands {
            settings.bands = check_bands(b)?;
        }
        settings.overlays = self.probe.overlays;
        Ok(settings)
    }

    fn apply_scene_overrides(&self, model: &mut SceneModel) -> Result<(), ViewerError> {
        let lighting = &mut model.description.lighting;
        if let Some(m) = &self.method {
            lighting.method = m
                .parse::<LightSource>()
                .map_err(|e| ViewerError::Parameter(format!("method: {e}")))?;
        }
        if let Some(n) = self.lights {
            if !(1..=MAX_LIGHTS).contains(&n) {
                return Err(ViewerError::Parameter(format!(
                    "{n} lights: must be 1 to {MAX_LIGHTS}"
                )));
            }
            lighting.lights = n;
        }
        if let Some(b) = self.bands {
            lighting.ambient_bands = AmbientBands::Fixed(check_bands(b)? as u32);
        }
        Ok(())
    }

    /// Runs the job: checks the outputs, renders, writes the last frame, returns the summary.
    pub fn run(&self, progress: &dyn Progress) -> Result<ViewSummary, ViewerError> {
        self.run_with(&ProbeExtras::default(), progress)
    }

    /// [`ViewJob::run`] with a probe's camera and room overlays (refused for a scene).
    pub fn run_with(
        &self,
        extras: &ProbeExtras,
        progress: &dyn Progress,
    ) -> Result<ViewSummary, ViewerError> {
        if is_scene(&self.input) && !extras.is_empty() {
            return Err(ViewerError::Parameter(
                "--marks, --room, --yaw, --pitch and --fov apply to a probe, not a scene".into(),
            ));
        }
        let outputs = self.output.as_deref().map(frame_outputs).transpose()?;
        if !(1..=100_000).contains(&self.frames.frames) {
            return Err(ViewerError::Parameter("frames: must be 1 to 100000".into()));
        }
        let mut options = self.frames;
        let frames = u64::from(options.frames);
        let (run, kind) = if let Some((room, edit)) = extras.live_room() {
            let run = self.run_live(room, edit, extras, outputs.as_ref(), &mut options, progress);
            (run?, ViewKind::Scene)
        } else if is_scene(&self.input) {
            let mut model = SceneModel::open(&self.input)?;
            self.apply_scene_overrides(&mut model)?;
            check_outputs(outputs.as_ref(), &model.inputs)?;
            options.display = Some(self.display(headless::auto_exposure(&model))?);
            let sequence = SequencePlayer::is_sequence(&model.description);
            check_sky_lights(options.sky_lights, sequence)?;
            if sequence {
                options.motion = Motion::Sequence;
                let centre = model.objects_sphere().map(|(c, _)| c);
                progress.begin("sequence: offline maps and sample sites", 0);
                let written: Vec<&Path> = outputs
                    .iter()
                    .flat_map(|(png, exr)| [png.as_path(), exr.as_path()])
                    .collect();
                let player = SequencePlayer::open(&self.input, centre, &written);
                progress.end();
                let mut player = player?;
                let gpu = GpuContext::headless()?;
                progress.begin("frames", frames);
                let run =
                    headless::render_sequence(&gpu, &model, &mut player, &options, &|d, t| {
                        progress.update(d as u64, t as u64, None);
                    });
                progress.end();
                (run?, ViewKind::Sequence)
            } else {
                let gpu = GpuContext::headless()?;
                progress.begin("frames", frames);
                let run = headless::render_scene(&gpu, &model, &options, &|d, t| {
                    progress.update(d as u64, t as u64, None);
                });
                progress.end();
                (run?, ViewKind::Scene)
            }
        } else {
            let mut model = ProbeModel::open(&self.input, self.mapping)?;
            let mut inputs = extras.inputs();
            inputs.push(self.input.clone());
            check_outputs(outputs.as_ref(), &inputs)?;
            let mut settings = self.probe_settings(&model)?;
            extras.check()?;
            extras.aim(&mut settings.orbit)?;
            let room = extras.overlay()?;
            if let (Some(room), Some(edit)) = (&extras.room, &extras.edit) {
                progress.begin("room: estimate and edits", 0);
                let edited = crate::room_edit::edited_panorama(room, edit, &model.latlong);
                progress.end();
                model.latlong = std::sync::Arc::new(edited?);
            }
            let gpu = GpuContext::headless()?;
            progress.begin("frames", frames);
            let run = headless::render_probe_with(
                &gpu,
                &model,
                &settings,
                &options,
                room.as_ref(),
                &|d, t| {
                    progress.update(d as u64, t as u64, None);
                },
            );
            progress.end();
            (run?, ViewKind::Probe)
        };
        let mut written = Vec::new();
        if let Some((png, exr)) = &outputs {
            write_frame(&run, png, exr)?;
            written = vec![png.display().to_string(), exr.display().to_string()];
        }
        let mut summary = summary(&self.input, &run, kind, options.motion, written);
        if kind == ViewKind::Sequence {
            summary.sequence = Some(SequenceSummary {
                setup_seconds: run.setup_seconds.unwrap_or(0.0),
                frames: run.played,
            });
        }
        Ok(summary)
    }
}

impl ViewJob {
    /// The frames of a room's live display (`extras.live_room()`: `room` and `edit`) with
    /// `options` (its display is set here, from the scene).
    fn run_live(
        &self,
        room: &Path,
        edit: &Path,
        extras: &ProbeExtras,
        outputs: Option<&(PathBuf, PathBuf)>,
        options: &mut HeadlessOptions,
        progress: &dyn Progress,
    ) -> Result<HeadlessRun, ViewerError> {
        extras.check()?;
        let mut inputs = extras.inputs();
        inputs.push(self.input.clone());
        check_outputs(outputs, &inputs)?;
        progress.begin("room: estimate, edits, volume", 0);
        let live = crate::room_live::room_live(room, edit, progress);
        progress.end();
        let live = live?;
        options.display = Some(self.display(headless::auto_exposure(&live.model))?);
        let gpu = GpuContext::headless()?;
        progress.begin("frames", u64::from(options.frames));
        let run =
            headless::render_scene_lit(&gpu, &live.model, live.lighting, 0.0, options, &|d, t| {
                progress.update(d as u64, t as u64, None);
            });
        progress.end();
        run
    }
}

/// Writes a frame: the tone-mapped picture as PNG (exactly what was shown) and the radiance as
/// EXR, each atomically.
pub fn write_frame(run: &HeadlessRun, png: &Path, exr: &Path) -> Result<(), ViewerError> {
    let bytes = ibl_io::ldr::encode_png(&run.images.display).map_err(|e| e.with_path(png))?;
    ibl_io::write_atomically(png, &bytes)?;
    ibl_io::write_image(exr, &run.images.radiance, &ibl_io::WriteOptions::default())?;
    Ok(())
}

fn summary(
    input: &Path,
    run: &HeadlessRun,
    kind: ViewKind,
    motion: Motion,
    outputs: Vec<String>,
) -> ViewSummary {
    ViewSummary {
        input: input.display().to_string(),
        kind,
        width: run.images.display.width() as u32,
        height: run.images.display.height() as u32,
        frames: run.frames.len(),
        motion,
        adapter: run.adapter.clone(),
        lights: run.lights,
        lighting: run.lighting.clone(),
        lighting_seconds: run.lighting_seconds,
        shadow_map_texels: run.shadow_tile,
        statistics: run.statistics,
        per_frame: run
            .frames
            .iter()
            .map(|f| FrameSummary {
                cpu_ms: f.cpu_seconds * 1e3,
                gpu_ms: f.gpu_seconds.map(|g| g * 1e3),
                wall_ms: f.wall_seconds * 1e3,
                passes_ms: f
                    .passes
                    .as_ref()
                    .map(|p| p.passes.iter().map(|(n, t)| (n.clone(), t * 1e3)).collect()),
                real_shadows_drawn: f.drew_real_shadows,
                virtual_shadows_drawn: f.drew_virtual_shadows,
            })
            .collect(),
        outputs,
        sequence: None,
    }
}

impl ViewSummary {
    /// The summary as one line of text (what `ibl view --headless` prints).
    pub fn line(&self) -> String {
        let s = self;
        let t = &s.statistics;
        let gpu = t
            .gpu_ms_median
            .map_or(String::new(), |g| format!(", GPU {g:.1} ms"));
        // A scene's lights cast shadows; a probe's lights are only drawn over it.
        let lights = match (s.lights, s.shadow_map_texels) {
            (0, _) => String::new(),
            (_, 0) => format!(", {}", s.lighting),
            (_, texels) => format!(", {}, shadow maps {texels}^2", s.lighting),
        };
        let wrote = if s.outputs.is_empty() {
            String::new()
        } else {
            format!("; wrote {}", s.outputs.join(", "))
        };
        format!(
            "{}: {} frames of {} x {} on {}{lights}: {:.1} fps median ({:.1} ms), {:.1} fps at p95 ({:.1} ms); CPU {:.1} ms{gpu}{wrote}",
            s.input,
            s.frames,
            s.width,
            s.height,
            s.adapter.line(),
            t.fps_median,
            t.frame_ms_median,
            t.fps_p95,
            t.frame_ms_p95,
            t.cpu_ms_median,
        )
    }
}

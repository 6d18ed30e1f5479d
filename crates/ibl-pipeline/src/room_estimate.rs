//! `ibl room estimate`: a room file and the probe it names to every patch's radiosity and
//! reflectance (Grosch 2005 section 3.2: depth map, `B = pi L` from the probe, form factors by ray
//! casting, `rho = B / E` with the hidden-region iteration), written into a folder as the
//! Table-1 report (`report.json`, `report.md`: reflectance per group and iteration, the
//! important patches of section 3.3) and three pictures: `rho-panorama.png` (the panorama with
//! every patch coloured by its reflectance, hidden patches hatched), `overlay.png` (the model's
//! edges over the tone-mapped probe) and `cutaway.png` (the room from above, coloured by
//! reflectance).
//!
//! The folder is created if needed; every file is written atomically and none may be an input.

use std::path::{Path, PathBuf};
use std::time::Instant;

use ibl_core::glam::{Vec2, Vec3};
use ibl_core::tonemap::{Display, ToneCurve, auto_exposure_stops, to_srgb8};
use ibl_core::{Image, Rgb};
use ibl_room::picture::{reflectance_cutaway, reflectance_panorama, room_overlay};
use ibl_room::{
    AnalysisSettings, ImportantLights, Room, RoomAnalysis, RoomReport, important_patches,
};
use ibl_scene::Camera;

use crate::error::{Context, PipelineError, Result};
use crate::progress::Progress;
use crate::room_input::{RoomInput, analyse, read_probe, read_room};

/// Largest number of form-factor rays per patch a command accepts (the library's bound).
pub const MAX_RAYS_PER_PATCH: u32 = ibl_room::form_factors::MAX_RAYS_PER_PATCH;

/// How the estimate is sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplingOptions {
    /// Form-factor rays per patch (rounded to `a^2 b^2` strata).
    pub rays_per_patch: u32,
    /// Seed of the form factors' jitter.
    pub seed: u64,
}

impl Default for SamplingOptions {
    fn default() -> Self {
        let ff = AnalysisSettings::default().form_factors;
        SamplingOptions {
            rays_per_patch: ff.rays_per_patch,
            seed: ff.seed,
        }
    }
}

impl SamplingOptions {
    /// The analysis settings, after checking the ray count.
    pub fn settings(&self) -> Result<AnalysisSettings> {
        if self.rays_per_patch == 0 || self.rays_per_patch > MAX_RAYS_PER_PATCH {
            return Err(PipelineError::parameter(format!(
                "--rays-per-patch must be between 1 and {MAX_RAYS_PER_PATCH} (got {})",
                self.rays_per_patch
            )));
        }
        let mut settings = AnalysisSettings::default();
        settings.form_factors.rays_per_patch = self.rays_per_patch;
        settings.form_factors.seed = self.seed;
        Ok(settings)
    }
}

/// What to estimate and where to write it.
#[derive(Clone, Debug, PartialEq)]
pub struct EstimateOptions {
    /// The room file (`[probe]` and `[room]` tables).
    pub room: PathBuf,
    /// Folder of the report and pictures.
    pub out_dir: PathBuf,
    /// Important patches listed in the report.
    pub important: usize,
    /// Sampling of the form factors.
    pub sampling: SamplingOptions,
}

/// The files an estimate writes into its folder.
pub const ESTIMATE_FILES: [&str; 5] = [
    "report.json",
    "report.md",
    "rho-panorama.png",
    "overlay.png",
    "cutaway.png",
];

/// What the estimate made.
#[derive(Clone, Debug)]
pub struct EstimateResult {
    /// The report (Table 1), as written.
    pub report: RoomReport,
    /// Seconds the analysis took (depth map, observation, form factors, iteration).
    pub seconds: f64,
    /// The files written.
    pub outputs: Vec<PathBuf>,
}

/// The output paths, checked before any work.
fn check(o: &EstimateOptions) -> Result<Vec<PathBuf>> {
    if o.out_dir.exists() && !o.out_dir.is_dir() {
        return Err(PipelineError::parameter(format!(
            "{}: -o names a file; it must be a folder (created if missing)",
            o.out_dir.display()
        )));
    }
    let outputs: Vec<PathBuf> = ESTIMATE_FILES.iter().map(|f| o.out_dir.join(f)).collect();
    for out in &outputs {
        ibl_io::ensure_output_is_not_input(out, &[o.room.as_path()])?;
    }
    Ok(outputs)
}

/// A PNG, atomically.
pub(crate) fn write_png(path: &Path, image: &Image<[u8; 3]>) -> Result<()> {
    let bytes =
        ibl_io::ldr::encode_png(image).map_err(|e| PipelineError::from(e.with_path(path)))?;
    ibl_io::write_atomically(path, &bytes)?;
    Ok(())
}

/// The camera of the cut-away picture: above the room, looking down at its floor's centre.
fn cutaway_camera(room: &Room, width: u32, height: u32) -> Option<Camera> {
    let (lo, hi) = room.bounds()?;
    let centre = 0.5 * (lo + hi);
    let size = (hi - lo).length();
    let eye = Vec3::new(
        centre.x + 0.35 * size,
        hi.y + 0.9 * size,
        centre.z + 0.6 * size,
    );
    Some(Camera::look_at(
        eye,
        Vec3::new(centre.x, lo.y, centre.z),
        Vec3::Y,
        Vec2::splat(Camera::focal_from_vertical_fov(45.0, height)),
        Vec2::new(width as f32 / 2.0, height as f32 / 2.0),
        (width, height),
    ))
}

/// Writes the three pictures of an analysis: `rho-panorama.png`, `overlay.png`, `cutaway.png`
/// into `dir`.
pub fn write_pictures(
    dir: &Path,
    room: &Room,
    probe: &Image<Rgb>,
    analysis: &RoomAnalysis,
) -> Result<()> {
    write_png(
        &dir.join("rho-panorama.png"),
        &reflectance_panorama(&analysis.depth, &analysis.estimate),
    )?;
    let display = Display {
        exposure_stops: auto_exposure_stops(probe),
        curve: ToneCurve::Reinhard,
    };
    write_png(
        &dir.join("overlay.png"),
        &room_overlay(&analysis.depth, &to_srgb8(probe, &display), [255, 220, 0]),
    )?;
    let (w, h) = (800, 600);
    let camera = cutaway_camera(room, w, h)
        .ok_or_else(|| PipelineError::parameter("the room has no surfaces to draw"))?;
    write_png(
        &dir.join("cutaway.png"),
        &reflectance_cutaway(room, &analysis.estimate, &camera, w, h),
    )
}

/// An estimated room: the input, the probe as analysed, the analysis and its time.
pub struct EstimatedRoom {
    /// The room file and room.
    pub input: RoomInput,
    /// The probe, `radiance_scale` applied.
    pub probe: Image<Rgb>,
    /// Depth map, observations, form factors, estimate.
    pub analysis: RoomAnalysis,
    /// Seconds of the analysis.
    pub seconds: f64,
}

/// Reads the room and its probe and runs the analysis.
pub fn estimate_room(
    room: &Path,
    sampling: &SamplingOptions,
    progress: &dyn Progress,
) -> Result<EstimatedRoom> {
    estimate_read_room(room, read_room(room)?, sampling, progress)
}

/// [`estimate_room`] on a room file already read (`input`, from `room`): for a job that checks
/// the room's contents before the analysis starts.
pub fn estimate_read_room(
    room: &Path,
    input: RoomInput,
    sampling: &SamplingOptions,
    progress: &dyn Progress,
) -> Result<EstimatedRoom> {
    let settings = sampling.settings()?;
    let probe = read_probe(&input, progress)?;
    let start = Instant::now();
    let analysis = analyse(&input, &probe, &settings, progress)?;
    let seconds = start.elapsed().as_secs_f64();
    progress.note(&format!(
        "{}: {} patches estimated in {seconds:.2} s ({} form-factor rays per patch)",
        room.display(),
        input.room.patches.len(),
        analysis.form_factors.rays_per_patch
    ));
    Ok(EstimatedRoom {
        input,
        probe,
        analysis,
        seconds,
    })
}

/// The report of an estimated room with its `n` important patches.
pub fn report(estimated: &EstimatedRoom, n: usize) -> (RoomReport, ImportantLights) {
    let room = &estimated.input.room;
    let lights = important_patches(room, &estimated.analysis.estimate, n);
    (
        RoomReport::new(room, &estimated.analysis, Some(&lights)),
        lights,
    )
}

/// Estimates the room and writes the report and the pictures.
pub fn room_estimate(o: &EstimateOptions, progress: &dyn Progress) -> Result<EstimateResult> {
    let outputs = check(o)?;
    o.sampling.settings()?;
    let estimated = estimate_room(&o.room, &o.sampling, progress)?;
    let (report, _) = report(&estimated, o.important);
    std::fs::create_dir_all(&o.out_dir).map_err(|e| {
        PipelineError::from(ibl_io::IoError::Io {
            path: o.out_dir.clone(),
            source: e,
        })
    })?;
    ibl_io::write_atomically(&outputs[0], report.to_json()?.as_bytes())?;
    ibl_io::write_atomically(&outputs[1], report.to_markdown().as_bytes())?;
    write_pictures(
        &o.out_dir,
        &estimated.input.room,
        &estimated.probe,
        &estimated.analysis,
    )
    .context(o.out_dir.display().to_string())?;
    for out in &outputs {
        progress.note(&format!("wrote {}", out.display()));
    }
    Ok(EstimateResult {
        report,
        seconds: estimated.seconds,
        outputs,
    })
}

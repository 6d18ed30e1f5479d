//! The outdoor AR job (`ibl outdoor`; Jensen, Andersen & Madsen 2006, `ibl-outdoor`): a scene
//! file with an `[outdoor]` table (docs/SCENES.md) and its folder of video frames give, per
//! frame, the estimated sun and sky (`P_d`, `P_a`), the relit environment map, and the virtual
//! objects composited into the frame with shadows both ways.
//!
//! Outputs, in the output folder: `estimates.csv` (one row per frame), `estimates.json` (the
//! whole [`OutdoorSummary`]), `estimates.svg` (the chart of `P_d` and `P_a` over the local time),
//! `composites/NAME.exr` and `.png` per frame (the scene's `[[object]]`s composited; the PNGs share
//! one exposure, the first frame's, so the light's changes show), and on request
//! `relit/NAME.exr` (the relit map, probe frame, the sun left out).

use std::path::{Path, PathBuf};
use std::time::Instant;

use ibl_core::tonemap::{Display, auto_exposure_stops, to_srgb8};
use ibl_io::WriteOptions;
use ibl_outdoor::plot::{SeriesPoint, estimates_svg};
use ibl_outdoor::{CompositeSettings, FrameCompositor, FrameResult};
use serde::Serialize;

use crate::error::{Context, PipelineError, Result};
use crate::outdoor_sequence::{OutdoorSequence, SequenceFrame, frame_name};
use crate::output_paths::{check_output_folder, check_output_path};
use crate::progress::Progress;
use crate::video::VideoWriter;

/// Width and height of the estimates' chart, pixels.
const CHART_SIZE: (u32, u32) = (900, 620);
/// Frame rate of the output video unless asked otherwise.
pub const DEFAULT_VIDEO_FPS: f64 = 10.0;

/// What `ibl outdoor` is asked to do.
#[derive(Clone, Debug, PartialEq)]
pub struct OutdoorJob {
    /// The scene file (with an `[outdoor]` table).
    pub scene: PathBuf,
    /// The output folder (created when missing).
    pub out_dir: PathBuf,
    /// Composite the scene's objects into each frame.
    pub composites: bool,
    /// Write each frame's relit map.
    pub relit_maps: bool,
    /// The composite's render settings.
    pub composite: CompositeSettings,
    /// Process at most this many frames (from the first).
    pub max_frames: Option<usize>,
    /// Also write the composites (or the frames, without composites) as a video (through
    /// `ffmpeg`, the container from the extension) at `video_fps` frames per second.
    pub video: Option<PathBuf>,
    /// Frame rate of `video`.
    pub video_fps: f64,
}

impl OutdoorJob {
    /// The job with the default settings: composites on, relit maps off.
    pub fn new(scene: PathBuf, out_dir: PathBuf) -> OutdoorJob {
        OutdoorJob {
            scene,
            out_dir,
            composites: true,
            relit_maps: false,
            composite: CompositeSettings::default(),
            max_frames: None,
            video: None,
            video_fps: DEFAULT_VIDEO_FPS,
        }
    }
}

/// One frame of the run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutdoorFrame {
    /// Index in the sequence.
    pub index: usize,
    /// The name of its outputs (the file's stem, or `frame_NNNNN` of a video).
    pub name: String,
    /// The frame file (or the video it came from).
    pub file: PathBuf,
    /// Local time `YYYY-MM-DDTHH:MM:SS`.
    pub local_time: String,
    /// Local time of day, hours.
    pub hour: f64,
    /// The sun's elevation, degrees.
    pub sun_elevation_deg: f64,
    /// What the system estimated (raw and used estimate, sun light, sky condition).
    pub result: FrameResult,
    /// The composite (EXR), relative to the output folder.
    pub composite: Option<PathBuf>,
    /// The relit map (EXR), relative to the output folder.
    pub relit_map: Option<PathBuf>,
    /// Seconds the estimation, relighting and volume refresh took.
    pub estimate_seconds: f64,
    /// Seconds the composite took.
    pub composite_seconds: f64,
}

/// What the run did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutdoorSummary {
    /// The scene file.
    pub scene: PathBuf,
    /// Frames processed, in order.
    pub frames: Vec<OutdoorFrame>,
    /// Frames skipped because the sun was below the horizon at their time.
    pub skipped: Vec<PathBuf>,
    /// Seconds of the offline step (maps, sample sites, volume weights).
    pub setup_seconds: f64,
    /// Sample sites drawn on the marked surfaces.
    pub sample_sites: usize,
    /// The video written (`--video`), as given.
    pub video: Option<PathBuf>,
    /// The per-frame table, the summary and the chart, relative to the output folder.
    pub csv: PathBuf,
    /// See `csv`.
    pub json: PathBuf,
    /// See `csv`.
    pub chart: PathBuf,
}

/// Runs the job: offline maps from the probe, then every frame.
pub fn run_outdoor(job: &OutdoorJob, progress: &dyn Progress) -> Result<OutdoorSummary> {
    check_output_folder(&job.out_dir)?;
    if !(job.video_fps.is_finite() && job.video_fps > 0.0 && job.video_fps <= 1000.0) {
        return Err(PipelineError::parameter(format!(
            "--video-fps {}: not in (0, 1000]",
            job.video_fps
        )));
    }
    let mut sequence = OutdoorSequence::open(&job.scene, job.max_frames)?;
    check_outputs(job, &sequence.inputs(), &sequence.frame_files)?;
    let scene = &sequence.loaded.scene;
    progress.begin("outdoor: offline maps and sample sites", 0);
    let setup_start = Instant::now();
    let system = sequence.system();
    progress.end();
    let mut system = system?;
    let setup_seconds = setup_start.elapsed().as_secs_f64();
    let compositor = (job.composites && scene.virtual_objects.triangle_count() > 0)
        .then(|| {
            FrameCompositor::new(
                scene.real.clone(),
                scene.virtual_objects.clone(),
                scene.camera,
                scene.probe.position,
                scene.probe.world_from_probe,
                job.composite,
            )
        })
        .transpose()?;

    ibl_io::create_dir_all(&job.out_dir)?;
    for (wanted, dir) in [
        (compositor.is_some(), "composites"),
        (job.relit_maps, "relit"),
    ] {
        if wanted {
            ibl_io::create_dir_all(&job.out_dir.join(dir))?;
        }
    }
    let total = sequence
        .frame_count()
        .unwrap_or(job.max_frames.unwrap_or(0)) as u64;
    progress.begin("outdoor: frames", total);
    let mut frames = Vec::with_capacity(sequence.frame_files.len());
    let mut display: Option<WriteOptions> = None;
    let mut writer: Option<VideoWriter> = None;
    let mut skipped = Vec::new();
    while let Some(next) = sequence.next_frame()? {
        let SequenceFrame {
            index,
            name,
            file: path,
            time,
            local_time,
            hour,
            image,
        } = next;
        let Some(frame) = image else {
            progress.note(&format!(
                "{} ({name}): the sun is below the horizon at {local_time}: skipped",
                path.display()
            ));
            skipped.push(path.clone());
            continue;
        };
        let t0 = Instant::now();
        let result = system
            .process(time, &frame)
            .context(path.display().to_string())?;
        let estimate_seconds = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let options = display.get_or_insert_with(|| WriteOptions {
            display: Display {
                exposure_stops: auto_exposure_stops(&frame),
                ..Display::default()
            },
            ..WriteOptions::default()
        });
        let (composite, shown) = match &compositor {
            Some(c) => {
                let lighting = system.frame_lighting(&result)?;
                let out = c.composite(&frame, &lighting)?;
                let rel = PathBuf::from("composites").join(format!("{name}.exr"));
                ibl_io::write_image(&job.out_dir.join(&rel), &out.composite, options)?;
                ibl_io::write_image(
                    &job.out_dir.join(rel.with_extension("png")),
                    &out.composite,
                    options,
                )?;
                (Some(rel), out.composite)
            }
            None => (None, frame),
        };
        if let Some(video) = &job.video {
            let size = (shown.width(), shown.height());
            if writer.is_none() {
                writer = Some(VideoWriter::create(video, size, job.video_fps)?);
            }
            if let Some(w) = writer.as_mut() {
                w.push(&to_srgb8(&shown, &options.display))?;
            }
        }
        let composite_seconds = t1.elapsed().as_secs_f64();
        let relit_map = if job.relit_maps {
            let rel = PathBuf::from("relit").join(format!("{name}.exr"));
            ibl_io::write_image(
                &job.out_dir.join(&rel),
                system.relit_map(),
                &WriteOptions::default(),
            )?;
            Some(rel)
        } else {
            None
        };
        frames.push(OutdoorFrame {
            index,
            name,
            file: path,
            local_time,
            hour,
            sun_elevation_deg: f64::from(result.sun_direction[1].clamp(-1.0, 1.0))
                .asin()
                .to_degrees(),
            result,
            composite,
            relit_map,
            estimate_seconds,
            composite_seconds,
        });
        progress.update(index as u64 + 1, total, None);
    }
    progress.end();
    if frames.is_empty() {
        return Err(PipelineError::parameter(format!(
            "{}: no frame in daylight (every frame's time puts the sun below the horizon, or the video has no frame)",
            sequence.source.display()
        )));
    }
    let video = match writer {
        Some(w) => Some(w.finish()?),
        None => None,
    };
    let summary = OutdoorSummary {
        scene: job.scene.clone(),
        skipped,
        video,
        sample_sites: system.sites().pixels().len(),
        frames,
        setup_seconds,
        csv: PathBuf::from("estimates.csv"),
        json: PathBuf::from("estimates.json"),
        chart: PathBuf::from("estimates.svg"),
    };
    write_tables(&summary, &job.out_dir, &job.scene.display().to_string())?;
    Ok(summary)
}

/// Checks, before any work, that no output lands on an input (the scene, what it names, the
/// frames, the mask).
fn check_outputs(job: &OutdoorJob, sequence_inputs: &[PathBuf], frames: &[PathBuf]) -> Result<()> {
    let inputs: Vec<&Path> = sequence_inputs.iter().map(PathBuf::as_path).collect();
    let mut outputs: Vec<PathBuf> = ["estimates.csv", "estimates.json", "estimates.svg"]
        .iter()
        .map(|f| job.out_dir.join(f))
        .collect();
    for (index, frame) in frames.iter().enumerate() {
        let name = frame_name(frame, index);
        if job.composites {
            outputs.push(job.out_dir.join("composites").join(format!("{name}.exr")));
            outputs.push(job.out_dir.join("composites").join(format!("{name}.png")));
        }
        if job.relit_maps {
            outputs.push(job.out_dir.join("relit").join(format!("{name}.exr")));
        }
    }
    for output in &outputs {
        ibl_io::ensure_output_is_not_input(output, &inputs)?;
    }
    if let Some(video) = &job.video {
        // Inside the output folder, which the run creates, or in a folder that exists.
        let in_out_dir = video.parent() == Some(job.out_dir.as_path()) && !job.out_dir.exists();
        if in_out_dir {
            ibl_io::ensure_output_is_not_input(video, &inputs)?;
        } else {
            check_output_path(video, &inputs)?;
        }
    }
    Ok(())
}

/// A CSV field: quoted (with inner quotes doubled) when it holds a comma, a quote or a line break.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// The chart of a run's estimates, with the true values when `truth` has one per frame.
pub fn chart_svg(
    summary: &OutdoorSummary,
    truth: Option<&[([f32; 3], [f32; 3])]>,
    title: &str,
) -> Result<String> {
    let points: Vec<SeriesPoint> = summary
        .frames
        .iter()
        .map(|f| SeriesPoint {
            hour: f.hour,
            sun: f.result.estimate.sun,
            sky: f.result.estimate.sky,
            truth: truth.and_then(|t| t.get(f.index).copied()),
            label: format!("{:?}", f.result.sky_condition).to_lowercase(),
        })
        .collect();
    Ok(estimates_svg(&points, title, CHART_SIZE)?)
}

/// `estimates.csv`, `estimates.json` and `estimates.svg`.
fn write_tables(summary: &OutdoorSummary, out_dir: &Path, scene: &str) -> Result<()> {
    let mut csv = String::from(
        "frame,file,local_time,sun_elevation_deg,sky,p_d_r,p_d_g,p_d_b,p_a_r,p_a_g,p_a_b,p_d_std_g,p_a_std_g,inliers,samples,composite\n",
    );
    for f in &summary.frames {
        let e = &f.result.estimate;
        csv.push_str(&format!(
            "{},{},{},{:.3},{:?},{},{},{},{},{},{},{},{},{},{},{}\n",
            f.index,
            csv_field(&f.file.display().to_string()),
            f.local_time,
            f.sun_elevation_deg,
            f.result.sky_condition,
            e.sun[0],
            e.sun[1],
            e.sun[2],
            e.sky[0],
            e.sky[1],
            e.sky[2],
            e.sun_std[1],
            e.sky_std[1],
            e.inliers,
            e.samples,
            f.composite
                .as_ref()
                .map_or(String::new(), |p| csv_field(&p.display().to_string())),
        ));
    }
    ibl_io::write_atomically(&out_dir.join(&summary.csv), csv.as_bytes())?;
    // Serialising plain data to a string cannot fail (non-finite numbers become null).
    let json = serde_json::to_string_pretty(summary).unwrap_or_default();
    ibl_io::write_atomically(&out_dir.join(&summary.json), json.as_bytes())?;
    let svg = chart_svg(summary, None, &format!("sun and sky over {scene}"))?;
    ibl_io::write_atomically(&out_dir.join(&summary.chart), svg.as_bytes())?;
    Ok(())
}

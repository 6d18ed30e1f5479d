//! An outdoor scene's frame sequence, opened for playing (Jensen, Andersen & Madsen 2006): the
//! scene file with its `[outdoor]` table (docs/SCENES.md), its frames (an image folder or a video
//! decoded by `ffmpeg`) with each frame's instant, the mask of diffuse surfaces, and the system
//! the offline step builds from them. `ibl outdoor` ([`crate::outdoor`]) and the viewer's
//! sequence mode (`ibl view SCENE.toml`) both play a sequence through this type, so they read
//! the same frames at the same times and estimate the same `P_d` and `P_a`.
//!
//! Opening reads the scene, the mask and the frame list and checks everything a run needs (no
//! daylight frame, a mask that marks nothing, frames and mask of different sizes are refused
//! before the offline step); [`OutdoorSequence::system`] is the offline step (seconds);
//! [`OutdoorSequence::next_frame`] reads the frames in order.

use std::path::{Path, PathBuf};

use glam::Vec3;
use ibl_core::{Image, Rgb};
use ibl_io::LoadedScene;
use ibl_outdoor::{
    Atmosphere, CameraSetup, CaptureSource, Location, OutdoorSystem, ProbeCapture, SampleSettings,
    SmoothingOptions, SystemSettings, Timestamp, VolumeRefresh, VolumeSettings,
};
use ibl_scene::description::{CivilTime, OutdoorDescription};
use ibl_sh::VolumeGrid;

use crate::error::{Context, PipelineError, Result};
use crate::video::VideoReader;

/// Frame file extensions read from the frames folder (case-insensitive).
pub const FRAME_EXTENSIONS: [&str; 6] = ["exr", "hdr", "pfm", "png", "jpg", "jpeg"];
/// Most frames one run reads (a day at one frame per second is 86 400).
pub const MAX_FRAMES: usize = 100_000;
/// Key-point directions of the irradiance volume (width of each point's lat-long).
const VOLUME_DIRECTIONS: usize = 32;
/// Margin of the volume's box around the objects, metres.
const VOLUME_MARGIN_M: f64 = 1.0;

/// An outdoor scene and its frames, ready to play.
pub struct OutdoorSequence {
    /// The scene file as given.
    pub scene_path: PathBuf,
    /// The scene as read (its description and the assembled scene).
    pub loaded: LoadedScene,
    /// Its `[outdoor]` table.
    pub outdoor: OutdoorDescription,
    /// The frames folder or video.
    pub source: PathBuf,
    /// The frame files, in order (empty for a video).
    pub frame_files: Vec<PathBuf>,
    /// The mask file.
    pub mask_path: PathBuf,
    /// The mask: the diffuse surfaces the estimation samples.
    pub mask: Image<bool>,
    /// The site.
    pub location: Location,
    /// The system's settings from the `[outdoor]` table.
    pub settings: SystemSettings,
    /// Local time of the first frame.
    pub start_civil: CivilTime,
    probe_time: Timestamp,
    start: Timestamp,
    reader: Option<VideoReader>,
    max_frames: Option<usize>,
    /// Index of the next frame [`OutdoorSequence::next_frame`] reads.
    next: usize,
}

/// A frame of the sequence with its instant.
#[derive(Clone, Debug)]
pub struct SequenceFrame {
    /// Index in the sequence.
    pub index: usize,
    /// The name of its outputs (the file's stem, or `frame_NNNNN` of a video).
    pub name: String,
    /// The frame file (or the video it came from).
    pub file: PathBuf,
    /// The instant it was taken.
    pub time: Timestamp,
    /// Local time `YYYY-MM-DDTHH:MM:SS`.
    pub local_time: String,
    /// Local time of day, hours.
    pub hour: f64,
    /// Its linear radiance, `None` for a night frame (not read).
    pub image: Option<Image<Rgb>>,
}

impl SequenceFrame {
    /// Whether the sun was above the horizon (the frame was read); night frames are skipped.
    pub fn is_daylight(&self) -> bool {
        self.image.is_some()
    }
}

impl OutdoorSequence {
    /// Opens `scene` (it must have an `[outdoor]` table) and checks its frames, mask and times;
    /// at most `max_frames` frames are played.
    pub fn open(scene: &Path, max_frames: Option<usize>) -> Result<OutdoorSequence> {
        let scene_shown = scene.display().to_string();
        let loaded = ibl_io::read_scene(scene)?;
        let outdoor = loaded.description.outdoor.clone().ok_or_else(|| {
            PipelineError::parameter(format!(
                "{scene_shown}: has no [outdoor] table (docs/SCENES.md): an outdoor sequence needs the site, the probe's time, the mask and the frames"
            ))
        })?;
        let base = scene.parent().unwrap_or(Path::new("."));
        let source = base.join(&outdoor.frames.source);
        let (frame_files, reader) = if source.is_file() {
            (Vec::new(), Some(VideoReader::open(&source)?))
        } else {
            (list_frames(&source, max_frames)?, None)
        };
        let mask_path = base.join(&outdoor.mask);
        let location = location(&outdoor);
        let probe_time = timestamp(&outdoor.probe_local_time()?, outdoor.utc_offset_hours)
            .context(format!("{scene_shown}: outdoor.probe_time"))?;
        let start_civil = outdoor.frames.start_local_time()?;
        let start = timestamp(&start_civil, outdoor.utc_offset_hours)
            .context(format!("{scene_shown}: outdoor.frames.start"))?;
        let mask = read_mask(&mask_path)?;
        if let Some(r) = &reader {
            let (w, h) = r.size();
            if (w as usize, h as usize) != (mask.width(), mask.height()) {
                return Err(PipelineError::parameter(format!(
                    "{}: {w} x {h} frames, but the mask {} is {} x {}: frames and mask must be the same size",
                    source.display(),
                    mask_path.display(),
                    mask.width(),
                    mask.height()
                )));
            }
        }
        let settings = system_settings(&outdoor, &loaded.scene)?;
        let sequence = OutdoorSequence {
            scene_path: scene.to_path_buf(),
            loaded,
            outdoor,
            source,
            frame_files,
            mask_path,
            mask,
            location,
            settings,
            start_civil,
            probe_time,
            start,
            reader,
            max_frames,
            next: 0,
        };
        // A video's length is not known before it is decoded: its frames are checked one by one.
        let any_daylight = sequence.reader.is_some()
            || (0..sequence.frame_files.len()).try_fold(false, |any, i| {
                Ok::<_, PipelineError>(any || sequence.daylight(i)?)
            })?;
        if !any_daylight {
            return Err(PipelineError::parameter(format!(
                "{scene_shown}: the sun is below the horizon at every frame's time, so every frame would be skipped (check outdoor.frames.start and utc_offset_hours)"
            )));
        }
        Ok(sequence)
    }

    /// Every file the sequence reads: the scene, what it names, the frames (or the video) and
    /// the mask.
    pub fn inputs(&self) -> Vec<PathBuf> {
        let mut inputs = vec![self.scene_path.clone(), self.mask_path.clone()];
        inputs.extend(self.loaded.inputs.iter().cloned());
        inputs.push(self.source.clone());
        inputs.extend(self.frame_files.iter().cloned());
        inputs
    }

    /// Frames in the sequence, when known before decoding (a folder; `None` for a video).
    pub fn frame_count(&self) -> Option<usize> {
        self.reader.is_none().then_some(self.frame_files.len())
    }

    /// The instant of frame `index`.
    pub fn frame_time(&self, index: usize) -> Timestamp {
        self.start
            .plus_seconds(self.outdoor.frames.seconds_after_start(index))
    }

    /// Whether the sun is above the horizon at frame `index`'s time (the model is for daylight).
    pub fn daylight(&self, index: usize) -> Result<bool> {
        Ok(self
            .location
            .sun_direction(self.frame_time(index), self.settings.delta_t)?
            .y
            > 0.0)
    }

    /// The offline step (Jensen, Andersen & Madsen 2006 section 4): the maps from the probe,
    /// the sample sites in the camera, the volume weights; seconds of work.
    pub fn system(&self) -> Result<OutdoorSystem> {
        let scene = &self.loaded.scene;
        OutdoorSystem::new(
            scene.real.clone(),
            self.location,
            &ProbeCapture {
                radiance: scene.probe.radiance.clone(),
                position: scene.probe.position,
                world_from_probe: scene.probe.world_from_probe,
                time: self.probe_time,
                lighting: CaptureSource::Measured,
            },
            &CameraSetup {
                camera: scene.camera,
                frame_size: (self.mask.width(), self.mask.height()),
                mask: self.mask.clone(),
            },
            self.settings,
        )
        .context(self.scene_path.display().to_string())
    }

    /// The next frame in order (a night frame without its image), or `None` after the last.
    pub fn next_frame(&mut self) -> Result<Option<SequenceFrame>> {
        let index = self.next;
        if self.max_frames.is_some_and(|m| index >= m) {
            return Ok(None);
        }
        let (file, name, decoded) = match self.reader.as_mut() {
            Some(r) => match r.next_frame()? {
                Some(image) => (
                    self.source.clone(),
                    format!("frame_{index:05}"),
                    Some(image),
                ),
                None => return Ok(None),
            },
            None => match self.frame_files.get(index) {
                Some(p) => (p.clone(), frame_name(p, index), None),
                None => return Ok(None),
            },
        };
        self.next += 1;
        let after = self.outdoor.frames.seconds_after_start(index);
        let image = if self.daylight(index)? {
            let image = match decoded {
                Some(image) => image,
                None => ibl_io::read_image(&file)?.image,
            };
            let mask = &self.mask;
            if (image.width(), image.height()) != (mask.width(), mask.height()) {
                return Err(PipelineError::parameter(format!(
                    "{}: {} x {} pixels, but the mask {} is {} x {}: frames and mask must be the same size",
                    file.display(),
                    image.width(),
                    image.height(),
                    self.mask_path.display(),
                    mask.width(),
                    mask.height()
                )));
            }
            Some(image)
        } else {
            None
        };
        Ok(Some(SequenceFrame {
            index,
            name,
            file,
            time: self.start.plus_seconds(after),
            local_time: local_time_label(&self.start_civil, after),
            hour: civil_hour(&self.start_civil) + after / 3600.0,
            image,
        }))
    }

    /// Starts again from the first frame (a video is opened again).
    pub fn rewind(&mut self) -> Result<()> {
        if self.reader.is_some() {
            self.reader = Some(VideoReader::open(&self.source)?);
        }
        self.next = 0;
        Ok(())
    }
}

/// The name of a frame's outputs: its file stem.
pub(crate) fn frame_name(path: &Path, index: usize) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| format!("{index:05}"))
}

/// The frame files of `dir` (images with a [`FRAME_EXTENSIONS`] extension, by file name).
fn list_frames(dir: &Path, max_frames: Option<usize>) -> Result<Vec<PathBuf>> {
    let mut files = ibl_io::list_dir(dir)?;
    files.retain(|p| {
        p.extension()
            .is_some_and(|x| FRAME_EXTENSIONS.iter().any(|e| x.eq_ignore_ascii_case(e)))
    });
    if files.is_empty() {
        return Err(PipelineError::parameter(format!(
            "{}: no frames (images ending in .{})",
            dir.display(),
            FRAME_EXTENSIONS.join(", .")
        )));
    }
    if files.len() > MAX_FRAMES {
        return Err(PipelineError::parameter(format!(
            "{}: {} frames, more than {MAX_FRAMES} in one run",
            dir.display(),
            files.len()
        )));
    }
    files.truncate(max_frames.unwrap_or(usize::MAX).max(1));
    Ok(files)
}

/// The mask image: every pixel with a non-zero channel is marked.
fn read_mask(path: &Path) -> Result<Image<bool>> {
    let image = ibl_io::read_image(path)?.image;
    let mask = image.map(|p| p.max_channel() > 0.0);
    if !mask.pixels().iter().any(|&m| m) {
        return Err(PipelineError::parameter(format!(
            "{}: the mask marks no pixel (non-black pixels are the diffuse surfaces the estimation samples)",
            path.display()
        )));
    }
    Ok(mask)
}

/// The site of the `[outdoor]` table.
fn location(outdoor: &OutdoorDescription) -> Location {
    Location {
        elevation_m: outdoor.elevation_m,
        utc_offset_hours: outdoor.utc_offset_hours,
        north: outdoor.north_unit(),
        atmosphere: Atmosphere {
            pressure_mbar: outdoor.pressure_mbar,
            temperature_c: outdoor.temperature_c,
        },
        ..Location::new(outdoor.latitude_deg, outdoor.longitude_deg)
    }
}

/// The instant of a local civil time at `utc_offset_hours`.
fn timestamp(civil: &CivilTime, utc_offset_hours: f64) -> Result<Timestamp> {
    let &(year, month, day, hour, minute, second) = civil;
    Ok(Timestamp::from_local(
        year,
        month,
        day,
        hour,
        minute,
        second,
        utc_offset_hours,
    )?)
}

/// Hours since local midnight.
fn civil_hour(civil: &CivilTime) -> f64 {
    let &(_, _, _, hour, minute, second) = civil;
    f64::from(hour) + f64::from(minute) / 60.0 + second / 3600.0
}

/// `YYYY-MM-DDTHH:MM:SS` of `seconds` after `start` (whole days roll over the date's day only
/// for the label; the instant itself comes from [`Timestamp`]).
fn local_time_label(start: &CivilTime, seconds: f64) -> String {
    let &(year, month, day, ..) = start;
    let total = (civil_hour(start) * 3600.0 + seconds).round() as i64;
    let (days, rest) = (total.div_euclid(86_400), total.rem_euclid(86_400));
    format!(
        "{year:04}-{month:02}-{:02}T{:02}:{:02}:{:02}",
        i64::from(day) + days,
        rest / 3600,
        rest / 60 % 60,
        rest % 60
    )
}

/// The system's settings from the `[outdoor]` table: the sample count, smoothing, and a volume
/// over the objects when `volume_spacing_m` is given.
fn system_settings(
    outdoor: &OutdoorDescription,
    scene: &ibl_scene::Scene,
) -> Result<SystemSettings> {
    let volume = match outdoor.volume_spacing_m {
        Some(spacing) => {
            let (lo, hi) = scene
                .virtual_objects
                .bvh
                .bounds()
                .unwrap_or((scene.probe.position, scene.probe.position));
            let margin = Vec3::splat(VOLUME_MARGIN_M as f32);
            let grid =
                VolumeGrid::covering((lo - margin).as_dvec3(), (hi + margin).as_dvec3(), spacing)?;
            Some(VolumeSettings {
                grid,
                directions_width: VOLUME_DIRECTIONS,
                refresh: VolumeRefresh::KeyPoints,
            })
        }
        None => None,
    };
    Ok(SystemSettings {
        samples: SampleSettings {
            count: outdoor.samples as usize,
            ..SampleSettings::default()
        },
        smoothing: outdoor.smoothing.then(SmoothingOptions::default),
        volume,
        ..SystemSettings::default()
    })
}

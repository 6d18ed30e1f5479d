//! The inputs of the room jobs (`ibl room ...`, Grosch 2005 section 3): a room file or a marks
//! file read with a size bound and parsed with every error naming the file and the field
//! (`room.toml: room.box[2].min: ...`), the probe a room file names (relative to the room file),
//! and the analysis of section 3.2 run with its progress reported.
//!
//! The probe's radiance is multiplied by the room file's `probe.radiance_scale` before the
//! analysis, so radiosity and the report are in scaled units; files that hold radiance (the
//! area-light file) divide it out again (CONVENTIONS section 7: light files are in the probe
//! file's units).

use std::path::{Path, PathBuf};

use ibl_core::{Image, Rgb};
use ibl_room::{AnalysisSettings, MarksFile, Room, RoomAnalysis, RoomFile, Stage, analyse_room};

use crate::error::{Context, PipelineError, Result};
use crate::progress::Progress;

/// Largest room or marks file read, bytes (both are hand-sized text).
pub const MAX_ROOM_TEXT_BYTES: u64 = 16 << 20;

/// Reads a text file of at most [`MAX_ROOM_TEXT_BYTES`].
fn read_text(path: &Path) -> Result<String> {
    Ok(ibl_io::read_text(path, MAX_ROOM_TEXT_BYTES)?)
}

/// A marks file, parsed and validated.
pub fn read_marks(path: &Path) -> Result<MarksFile> {
    MarksFile::from_json(&read_text(path)?).context(path.display().to_string())
}

/// A room file with the room it describes (patches and BVH built) and the probe path it names,
/// resolved against the room file's folder.
#[derive(Clone, Debug)]
pub struct RoomInput {
    /// The file as parsed.
    pub file: RoomFile,
    /// The resolved room.
    pub room: Room,
    /// The probe file.
    pub probe_path: PathBuf,
}

/// Reads and resolves a room file.
pub fn read_room(path: &Path) -> Result<RoomInput> {
    let name = path.display().to_string();
    let file = RoomFile::from_toml(&read_text(path)?).context(name.clone())?;
    let room = Room::from_file(&file).context(name)?;
    let probe_path = path
        .parent()
        .unwrap_or(Path::new("."))
        .join(&file.probe.file);
    Ok(RoomInput {
        file,
        room,
        probe_path,
    })
}

/// The room's probe (lat-long radiance) with the room file's `radiance_scale` applied.
pub fn read_probe(input: &RoomInput, progress: &dyn Progress) -> Result<Image<Rgb>> {
    let loaded = ibl_io::read_image(&input.probe_path)?;
    let clamped = loaded.report.negative_values + loaded.report.nonfinite_values;
    if clamped > 0 {
        progress.note(&format!(
            "note: {}: {clamped} negative, NaN or infinite values read as 0",
            input.probe_path.display()
        ));
    }
    let scale = input.file.probe.radiance_scale;
    Ok(loaded.image.map(|&l| l * scale))
}

/// Runs the analysis of section 3.2 (depth map, probe radiosity, form factors, the estimate)
/// as one task with the stage as its detail.
pub fn analyse(
    input: &RoomInput,
    probe: &Image<Rgb>,
    settings: &AnalysisSettings,
    progress: &dyn Progress,
) -> Result<RoomAnalysis> {
    progress.begin(
        &format!("room: {} patches", input.room.patches.len()),
        input.room.patches.len() as u64,
    );
    let result = analyse_room(&input.room, probe, settings, &|stage, done, total| {
        let detail = match stage {
            Stage::DepthMap => "depth map",
            Stage::FormFactors => "form factors",
            Stage::Estimate => "reflectance estimate",
        };
        progress.update(done as u64, total as u64, Some(detail));
    });
    progress.end();
    result.map_err(|e| PipelineError::from(e).context(input.probe_path.display().to_string()))
}

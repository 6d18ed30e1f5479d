//! `ibl room lights`: a room file and its probe to the room's `N` important light patches
//! (Grosch 2005 section 3.3: the patches of highest luminous flux `phi = B A` under the estimated
//! radiosity), written as an area-light file (`iblkit.area-lights/1`,
//! `ibl_io::area_light_file`) that `ibl render --lights` reads. The rest of the room's light is
//! the "unimportant" light; the file states the share of the flux the important patches carry.
//!
//! Radiance in the file is in the probe *file*'s units (the room's `radiance_scale` divided out),
//! as in every light file (CONVENTIONS section 7).

use std::path::{Path, PathBuf};

use ibl_io::area_light_file::{AreaLightRecord, AreaLightsFile, write_area_lights_file};
use ibl_light::ProbeRef;

use crate::error::{PipelineError, Result};
use crate::progress::Progress;
use crate::room_estimate::{EstimatedRoom, SamplingOptions, estimate_room, report};

/// Largest number of important patches asked for.
pub const MAX_IMPORTANT_PATCHES: usize = 65_536;

/// Which lights and where.
#[derive(Clone, Debug, PartialEq)]
pub struct RoomLightsOptions {
    /// The room file.
    pub room: PathBuf,
    /// The area-light file to write (`.json`).
    pub output: PathBuf,
    /// Number of important patches.
    pub count: usize,
    /// Sampling of the form factors.
    pub sampling: SamplingOptions,
}

/// What was written.
#[derive(Clone, Debug, PartialEq)]
pub struct RoomLightsResult {
    /// The file as written.
    pub file: AreaLightsFile,
    /// Patches in the room.
    pub patches: usize,
    /// Seconds of the analysis.
    pub seconds: f64,
}

impl RoomLightsResult {
    /// The summary `ibl room lights --json` prints.
    pub fn summary_json(&self, room: &Path, output: &Path) -> serde_json::Value {
        serde_json::json!({
            "room": room.display().to_string(),
            "output": output.display().to_string(),
            "patches": self.patches,
            "lights": self.file.lights.len(),
            "important_flux_fraction": self.file.important_flux_fraction,
            "seconds": self.seconds,
            "groups": self.file.lights.iter().map(|l| l.group.as_str()).collect::<Vec<_>>(),
        })
    }

    /// What `ibl room lights` prints.
    pub fn text(&self, output: &Path) -> String {
        format!(
            "{} of {} patches, {:.1} % of the room's luminous flux, in {}\n",
            self.file.lights.len(),
            self.patches,
            100.0 * self.file.important_flux_fraction,
            output.display()
        )
    }
}

fn check(o: &RoomLightsOptions) -> Result<()> {
    if o.count == 0 || o.count > MAX_IMPORTANT_PATCHES {
        return Err(PipelineError::parameter(format!(
            "-n must be between 1 and {MAX_IMPORTANT_PATCHES} (got {})",
            o.count
        )));
    }
    if o.output.extension().and_then(|e| e.to_str()) != Some("json") {
        return Err(PipelineError::parameter(format!(
            "{}: the area-light file is written as .json",
            o.output.display()
        )));
    }
    o.sampling.settings()?;
    ibl_io::ensure_output_is_not_input(&o.output, &[o.room.as_path()])?;
    Ok(())
}

/// Estimates the room and writes its important patches.
pub fn room_lights(o: &RoomLightsOptions, progress: &dyn Progress) -> Result<RoomLightsResult> {
    check(o)?;
    let estimated = estimate_room(&o.room, &o.sampling, progress)?;
    let file = write_lights(&estimated, &o.room, &o.output, o.count, progress)?;
    Ok(RoomLightsResult {
        file,
        patches: estimated.input.room.patches.len(),
        seconds: estimated.seconds,
    })
}

/// Writes the `count` important patches of an estimated room (read from `room_path`) to
/// `output` as an area-light file.
pub fn write_lights(
    estimated: &EstimatedRoom,
    room_path: &Path,
    output: &Path,
    count: usize,
    progress: &dyn Progress,
) -> Result<AreaLightsFile> {
    ibl_io::ensure_output_is_not_input(output, &[room_path, estimated.input.probe_path.as_path()])?;
    let (_, lights) = report(estimated, count);
    let room = &estimated.input.room;
    if lights.important.len() < count {
        progress.note(&format!(
            "note: the room has {} patches, fewer than the {count} asked",
            room.patches.len()
        ));
    }
    let unscale = 1.0 / f64::from(estimated.input.file.probe.radiance_scale);
    let records = lights
        .important
        .iter()
        .map(|l| {
            let patch = &room.patches[l.patch as usize];
            AreaLightRecord {
                patch: l.patch,
                group: room.groups[patch.group as usize].name.clone(),
                position: l.position.map(f64::from),
                normal: l.normal.map(f64::from),
                area_m2: f64::from(l.area_m2),
                radiance: l.radiance.map(|c| f64::from(c) * unscale),
                corners: l.corners.iter().map(|c| c.map(f64::from)).collect(),
            }
        })
        .collect();
    let mut file = AreaLightsFile::new(
        room.world_from_probe.as_dmat3(),
        room.probe_position,
        lights.important_flux_fraction,
        records,
    );
    let probe_path = &estimated.input.probe_path;
    file.probe = Some(ProbeRef {
        path: probe_path.display().to_string(),
        width: estimated.probe.width(),
        height: estimated.probe.height(),
        sha256: ibl_io::light_file::sha256_file(probe_path)?,
    });
    file.room = Some(room_path.display().to_string());
    write_area_lights_file(output, &file)?;
    progress.note(&format!(
        "wrote {}: {} patches, {:.1} % of the room's luminous flux",
        output.display(),
        file.lights.len(),
        100.0 * file.important_flux_fraction
    ));
    Ok(file)
}

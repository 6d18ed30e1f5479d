//! `ibl room calibrate`: a marks file (line segments marked in perspective views of the probe,
//! each assigned to an axis; scale marks; shapes by constraints) to the frame and the scale of
//! Grosch 2005 section 3.1: vanishing points by least squares with each line's residual, the
//! rotation `world_from_probe`, the probe's height from the scale marks, and (when the file has
//! shapes) the room file they make. Optionally, for comparison, the automatic Manhattan proposal
//! on the probe (beyond the paper: RANSAC over vanishing-point hypotheses of detected segments)
//! and its angle to the marked calibration.
//!
//! Outputs are checked before any work: the room file must be a `.toml` that names no input.

use std::path::{Path, PathBuf};

use ibl_core::glam::{DMat3, DVec3};
use ibl_room::{
    Calibration, ManhattanProposal, ManhattanSettings, MarksFile, Scale, calibrate,
    line_observations, probe_height, propose_manhattan_frame, reconstruct,
};
use serde::Serialize;

use crate::error::{Context, PipelineError, Result};
use crate::progress::{self, Progress};
use crate::room_input::read_marks;

/// What to calibrate and where to write it.
#[derive(Clone, Debug, PartialEq)]
pub struct CalibrateOptions {
    /// The marks file (`iblkit.room-marks/1`).
    pub marks: PathBuf,
    /// Where to write the room file the marked shapes make (`.toml`); the probe is named
    /// relative to it.
    pub room_output: Option<PathBuf>,
    /// Also run the automatic Manhattan proposal on the probe and compare.
    pub propose: bool,
}

/// The automatic proposal and how far it is from the marked calibration.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ProposalComparison {
    /// The proposal.
    pub proposal: ManhattanProposal,
    /// Rotation angle between the proposal and the calibration, degrees.
    pub angle_to_calibration_deg: f64,
}

/// What calibration found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CalibrateResult {
    /// Marked lines used.
    pub lines: usize,
    /// Frame, vanishing points and residuals.
    pub calibration: Calibration,
    /// The probe's height (absent when the file has no scale marks).
    pub scale: Option<Scale>,
    /// The automatic proposal, when asked.
    pub proposal: Option<ProposalComparison>,
    /// The room file written, if any.
    pub room_output: Option<String>,
    /// Shapes in the room file written.
    pub shapes: usize,
}

impl CalibrateResult {
    /// What `ibl room calibrate` prints: the frame and its residuals, the scale, the proposal
    /// and the room file written.
    pub fn text(&self) -> String {
        let c = &self.calibration;
        let mut text = format!(
            "{} lines: rotation [yaw, pitch, roll] {:.3?} deg, RMS residual {:.3} deg (largest {:.3})\n",
            self.lines,
            c.rotation_deg,
            c.rms_residual_deg,
            c.line_residuals_deg.iter().copied().fold(0.0, f64::max)
        );
        if let Some(s) = &self.scale {
            text += &format!(
                "probe {:.3} m above the floor ({} scale marks, spread {:.2} %)\n",
                s.probe_height_m,
                s.marks.len(),
                100.0 * s.spread
            );
        }
        if let Some(p) = &self.proposal {
            text += &format!(
                "automatic proposal: {:.3} deg from the marked frame ({} segments, residual {:.3} deg)\n",
                p.angle_to_calibration_deg, p.proposal.segments, p.proposal.rms_residual_deg
            );
        }
        if let Some(out) = &self.room_output {
            text += &format!("room file {out}: {} shapes\n", self.shapes);
        }
        text
    }
}

/// The angle of the rotation `a^T b`, degrees (accurate for small angles too: atan2 of the
/// skew part's length and the trace).
pub fn rotation_angle_deg(a: DMat3, b: DMat3) -> f64 {
    let d = a.transpose() * b;
    let skew = DVec3::new(
        d.y_axis.z - d.z_axis.y,
        d.z_axis.x - d.x_axis.z,
        d.x_axis.y - d.y_axis.x,
    );
    (0.5 * skew.length())
        .atan2(0.5 * (d.x_axis.x + d.y_axis.y + d.z_axis.z - 1.0))
        .to_degrees()
}

/// `target` relative to the folder `base` (both absolute), as a room file names its probe.
fn relative_to(target: &Path, base: &Path) -> String {
    let t: Vec<_> = target.components().collect();
    let b: Vec<_> = base.components().collect();
    let common = t.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &t[common..] {
        out.push(c);
    }
    out.to_string_lossy().into_owned()
}

/// The folder a path's file lies in, absolute.
fn absolute_folder(path: &Path) -> Result<PathBuf> {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    folder.canonicalize().map_err(|e| {
        PipelineError::from(ibl_io::IoError::Io {
            path: folder.to_path_buf(),
            source: e,
        })
    })
}

fn check(o: &CalibrateOptions) -> Result<()> {
    if let Some(out) = &o.room_output {
        if out.extension().and_then(|e| e.to_str()) != Some("toml") {
            return Err(PipelineError::parameter(format!(
                "{}: the room file is written as .toml",
                out.display()
            )));
        }
        absolute_folder(out)?;
        ibl_io::ensure_output_is_not_input(out, &[o.marks.as_path()])?;
    }
    Ok(())
}

/// The frame and the scale of parsed marks.
#[derive(Clone, Debug, PartialEq)]
pub struct MarksCalibration {
    /// Marked lines used (segments whose ends are distinct directions).
    pub lines: usize,
    /// Frame, vanishing points and residuals (each line's, in the marks file's order).
    pub calibration: Calibration,
    /// The probe's height (absent when the marks have no scale marks).
    pub scale: Option<Scale>,
}

/// The calibration of parsed marks: the vanishing points, `world_from_probe` with every line's
/// residual, and the probe's height from the scale marks; what [`room_calibrate`] computes
/// before it writes anything (the viewer's "calibrate" runs it on the marks being edited).
/// `name` names the marks in errors.
pub fn calibrate_marks(marks: &MarksFile, name: &str) -> Result<MarksCalibration> {
    let lines = line_observations(marks);
    let calibration = calibrate(&lines).context(name.to_string())?;
    let scale = if marks.scale.is_empty() {
        None
    } else {
        Some(probe_height(marks, calibration.world_from_probe()).context(name.to_string())?)
    };
    Ok(MarksCalibration {
        lines: lines.len(),
        calibration,
        scale,
    })
}

/// Calibrates, scales, optionally proposes, and writes the room file.
pub fn room_calibrate(o: &CalibrateOptions, progress: &dyn Progress) -> Result<CalibrateResult> {
    check(o)?;
    let name = o.marks.display().to_string();
    let marks = read_marks(&o.marks)?;
    let MarksCalibration {
        lines,
        calibration,
        scale,
    } = calibrate_marks(&marks, &name)?;
    let world_from_probe = calibration.world_from_probe();
    let marks_folder = absolute_folder(&o.marks)?;
    // Canonical where the probe exists, so the room file names it without `a/../` detours.
    let probe_path = marks.probe.as_ref().map(|p| {
        let joined = marks_folder.join(&p.file);
        joined.canonicalize().unwrap_or(joined)
    });
    let proposal = if o.propose {
        let probe_path = probe_path.as_ref().ok_or_else(|| {
            PipelineError::parameter(format!(
                "{name}: --propose needs the probe, and the marks file names none (`probe.file`)"
            ))
        })?;
        let probe = ibl_io::read_image(probe_path)?.image;
        let proposal = progress::task(progress, "Manhattan proposal", || {
            propose_manhattan_frame(&probe, &ManhattanSettings::default())
        })
        .context(probe_path.display().to_string())?;
        let m = proposal.world_from_probe;
        let auto = DMat3::from_cols_array(&[
            m[0][0], m[1][0], m[2][0], m[0][1], m[1][1], m[2][1], m[0][2], m[1][2], m[2][2],
        ]);
        Some(ProposalComparison {
            angle_to_calibration_deg: rotation_angle_deg(auto, world_from_probe),
            proposal,
        })
    } else {
        None
    };
    let mut shapes = 0;
    if let Some(out) = &o.room_output {
        let scale = scale.as_ref().ok_or_else(|| {
            PipelineError::parameter(format!(
                "{name}: a room file needs the scale: the marks file has no `scale` marks"
            ))
        })?;
        let probe_path = probe_path.as_ref().ok_or_else(|| {
            PipelineError::parameter(format!(
                "{name}: a room file names its probe, and the marks file names none (`probe.file`)"
            ))
        })?;
        let relative = relative_to(probe_path, &absolute_folder(out)?);
        let file = reconstruct(&marks, &calibration, scale, &relative).context(name.clone())?;
        shapes = file.room.rectangles.len() + file.room.boxes.len() + file.room.polygons.len();
        let header = format!(
            "# Made by `ibl room calibrate {name} -o {}`: {} lines, RMS residual {:.3} deg; \
             probe {:.3} m above the floor.\n",
            out.display(),
            lines,
            calibration.rms_residual_deg,
            scale.probe_height_m
        );
        let text = header + &file.to_toml()?;
        ibl_io::write_atomically(out, text.as_bytes())?;
        progress.note(&format!("wrote {}", out.display()));
    }
    Ok(CalibrateResult {
        lines,
        calibration,
        scale,
        proposal,
        room_output: o.room_output.as_ref().map(|p| p.display().to_string()),
        shapes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_climb_to_the_common_folder() {
        assert_eq!(
            relative_to(Path::new("/a/b/probe.exr"), Path::new("/a/c/d")),
            "../../b/probe.exr"
        );
        assert_eq!(
            relative_to(Path::new("/a/probe.exr"), Path::new("/a")),
            "probe.exr"
        );
    }

    #[test]
    fn a_rotation_angle_is_what_was_turned() {
        let a = DMat3::from_rotation_y(0.3);
        let b = a * DMat3::from_rotation_x(0.01);
        // atan2 form: f64 rounding only, far below 1e-9 degrees.
        assert!((rotation_angle_deg(a, b) - 0.01f64.to_degrees()).abs() < 1e-9);
    }
}

//! The scale of the reconstruction (Grosch 2005, section 3.1: "the user defines two points with a
//! known distance to determine the unknown scaling factor ... usually the distance between floor
//! and ceiling"), as the probe centre's height `h` above the floor.
//!
//! The world origin is the floor point below the probe: the probe sits at `(0, h, 0)` and the
//! floor is `y = 0`. With world directions `d` (calibrated `world_from_probe` applied to a marked
//! pixel's direction) and `tan(e) = d_y / |d_xz|` a direction's elevation:
//! - **probe height** `h` given directly;
//! - **vertical**: a floor point and a point above it on one vertical line at distance `D`: both
//!   are at the same horizontal distance `r` from the probe, `r (tan e_upper - tan e_lower) = D`,
//!   and the floor point gives `h = -r tan e_lower`;
//! - **floor distance**: two floor points `h d / (-d_y)` at distance `D`: `h = D / |d_a,xz /
//!   (-d_a,y) - d_b,xz / (-d_b,y)|`.
//!
//! Several marks are averaged (equal weights) and each one's value is reported, so a bad mark
//! shows as an outlier.

use glam::{DMat3, DVec3};
use serde::Serialize;

use crate::RoomError;
use crate::marks::{MarksFile, ScaleMark};

/// One scale mark's result.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ScaleCheck {
    /// Index in the marks file's `scale` list.
    pub mark: usize,
    /// The probe height this mark alone gives, metres.
    pub probe_height_m: f64,
}

/// The scale: the probe centre's height above the floor.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Scale {
    /// Mean of the marks' heights, metres.
    pub probe_height_m: f64,
    /// Each mark's own value.
    pub marks: Vec<ScaleCheck>,
    /// Largest deviation of one mark from the mean, relative to the mean.
    pub spread: f64,
}

/// World direction of a named point.
pub(crate) fn point_direction(
    marks: &MarksFile,
    world_from_probe: DMat3,
    name: &str,
) -> Result<DVec3, RoomError> {
    let (view, at) = marks
        .point(name)
        .ok_or_else(|| RoomError::invalid("points", format!("no point is named `{name}`")))?;
    Ok((world_from_probe * view.direction(at[0], at[1])).normalize())
}

fn elevation_tan(d: DVec3) -> f64 {
    d.y / d.x.hypot(d.z).max(1e-12)
}

/// The probe height from the marks' scale list under a calibrated `world_from_probe`.
pub fn probe_height(marks: &MarksFile, world_from_probe: DMat3) -> Result<Scale, RoomError> {
    if marks.scale.is_empty() {
        return Err(RoomError::invalid(
            "scale",
            "no scale mark: give the probe height or two points at a known distance",
        ));
    }
    let below_horizon = |field: String, name: &str, d: DVec3| -> Result<(), RoomError> {
        if d.y < -1e-6 {
            Ok(())
        } else {
            Err(RoomError::invalid(
                field,
                format!("point `{name}` is not below the horizon, so it cannot lie on the floor"),
            ))
        }
    };
    let mut checks = Vec::new();
    for (k, mark) in marks.scale.iter().enumerate() {
        let f = format!("scale[{k}]");
        let h = match mark {
            ScaleMark::ProbeHeight { height_m } => *height_m,
            ScaleMark::Vertical {
                lower,
                upper,
                distance_m,
            } => {
                let dl = point_direction(marks, world_from_probe, lower)?;
                let du = point_direction(marks, world_from_probe, upper)?;
                below_horizon(format!("{f}.lower"), lower, dl)?;
                let rise = elevation_tan(du) - elevation_tan(dl);
                if rise <= 1e-9 {
                    return Err(RoomError::invalid(
                        format!("{f}.upper"),
                        format!("point `{upper}` is not above `{lower}` as seen from the probe"),
                    ));
                }
                let r = distance_m / rise;
                -r * elevation_tan(dl)
            }
            ScaleMark::FloorDistance { a, b, distance_m } => {
                let da = point_direction(marks, world_from_probe, a)?;
                let db = point_direction(marks, world_from_probe, b)?;
                below_horizon(format!("{f}.a"), a, da)?;
                below_horizon(format!("{f}.b"), b, db)?;
                let pa = da / -da.y;
                let pb = db / -db.y;
                let gap = (pa.x - pb.x).hypot(pa.z - pb.z);
                if gap <= 1e-9 {
                    return Err(RoomError::invalid(
                        format!("{f}.b"),
                        "the two points are in one direction from the probe",
                    ));
                }
                distance_m / gap
            }
        };
        checks.push(ScaleCheck {
            mark: k,
            probe_height_m: h,
        });
    }
    let mean = checks.iter().map(|c| c.probe_height_m).sum::<f64>() / checks.len() as f64;
    let spread = checks
        .iter()
        .map(|c| (c.probe_height_m - mean).abs() / mean)
        .fold(0.0, f64::max);
    Ok(Scale {
        probe_height_m: mean,
        marks: checks,
        spread,
    })
}

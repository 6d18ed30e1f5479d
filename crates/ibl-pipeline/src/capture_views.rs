//! Probes from views of the world (`ibl capture ball`, `ibl capture fisheye`): mirror-ball
//! photographs unwrapped to lat-long, several views taken from different sides merged by
//! reliability so that the camera and the photographer disappear; two opposite equidistant
//! fisheye images, or one dual-fisheye frame, stitched with a feathered seam.

use std::path::{Path, PathBuf};

use ibl_capture::ball::{Circle, find_ball, merge_views, unwrap_ball};
use ibl_capture::fisheye::{FisheyeOptions, stitch_fisheye_pair};
use ibl_core::{EulerDegrees, Rgb};
use ibl_io::WriteOptions;
use serde::Serialize;

use crate::capture::{sibling, write_with_preview};
use crate::error::{Context, PipelineError, Result};

/// One mirror-ball photograph.
#[derive(Clone, Debug, PartialEq)]
pub struct BallView {
    /// The photo (HDR, or 8-bit decoded as sRGB).
    pub photo: PathBuf,
    /// The ball in the photo, pixels; `None`: found automatically.
    pub circle: Option<Circle>,
    /// Yaw of the view about +Y, degrees (the first view defines the probe's frame).
    pub yaw_deg: f32,
}

/// What to unwrap and merge.
#[derive(Clone, Debug, PartialEq)]
pub struct BallJob {
    /// The views.
    pub views: Vec<BallView>,
    /// Output lat-long probe.
    pub output: PathBuf,
    /// Width of the output.
    pub width: usize,
}

/// One view in the summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BallViewSummary {
    /// The photo, as given.
    pub photo: String,
    /// The ball.
    pub circle: Circle,
    /// Whether the ball was found (or given).
    pub found: bool,
    /// Yaw of the view, degrees.
    pub yaw_deg: f32,
    /// Share of the sphere this view sees reliably (reliability above 0.5).
    pub reliable_fraction: f64,
}

/// What `capture ball` did (its `--json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BallSummary {
    /// Per view.
    pub views: Vec<BallViewSummary>,
    /// Output width.
    pub width: usize,
    /// Files written.
    pub outputs: Vec<String>,
}

impl BallSummary {
    /// What `ibl capture ball` prints: each view's ball and reliable fraction, the files.
    pub fn text(&self) -> String {
        let mut text = String::new();
        for v in &self.views {
            text += &format!(
                "{}: ball at ({:.1}, {:.1}) radius {:.1} px ({}), yaw {} deg, {:.0} % of the sphere reliable\n",
                v.photo,
                v.circle.cx,
                v.circle.cy,
                v.circle.r,
                if v.found { "found" } else { "given" },
                v.yaw_deg,
                100.0 * v.reliable_fraction
            );
        }
        text + &format!("wrote {}\n", self.outputs.join(", "))
    }
}

/// The yaws of `n` views when none are given: 0, 90, 180, ... degrees.
pub fn default_yaws(n: usize) -> Vec<f32> {
    (0..n).map(|k| 90.0 * k as f32).collect()
}

/// Unwraps every view, merges them and writes the probe, its preview and each view's
/// reliability map (`<stem>-reliability-<k>.png`).
pub fn unwrap_balls(job: &BallJob) -> Result<BallSummary> {
    if job.views.is_empty() {
        return Err(PipelineError::parameter(
            "give at least one mirror-ball photo",
        ));
    }
    if let Some(v) = job.views.iter().find(|v| !v.yaw_deg.is_finite()) {
        return Err(PipelineError::parameter(format!(
            "--yaw: {} is not a finite angle",
            v.yaw_deg
        )));
    }
    let mut outputs = vec![job.output.clone(), job.output.with_extension("png")];
    for k in 0..job.views.len() {
        outputs.push(sibling(&job.output, &format!("-reliability-{k}.png")));
    }
    let inputs: Vec<&Path> = job.views.iter().map(|v| v.photo.as_path()).collect();
    for out in &outputs {
        crate::output_paths::check_output_path(out, &inputs)?;
    }
    let what = format!("--width {}", job.width);
    crate::output_paths::check_output_pixels(&what, job.width, job.width / 2)?;
    let mut views = Vec::new();
    let mut summary = Vec::new();
    let mut reliability_maps = Vec::new();
    for view in &job.views {
        let path = view.photo.display().to_string();
        let photo = ibl_io::read_image(&view.photo)?.image;
        let (circle, found) = match view.circle {
            Some(c) => (c, false),
            None => (find_ball(&photo).context(&path)?, true),
        };
        let unwrapped = unwrap_ball(&photo, circle, job.width).context(&path)?;
        let reliable = unwrapped
            .reliability
            .pixels()
            .iter()
            .filter(|&&r| r > 0.5)
            .count();
        if reliable == 0 {
            // Issue 13: "0 % of the sphere reliable" used to exit 0 with an empty probe.
            return Err(PipelineError::parameter(format!(
                "{path}: no part of the sphere is reliable with the ball at ({:.1}, {:.1}) radius \
                 {:.1} px{}: the circle does not fit a mirror ball; check it (--circle X,Y,R)",
                circle.cx,
                circle.cy,
                circle.r,
                if found { " (found automatically)" } else { "" }
            )));
        }
        summary.push(BallViewSummary {
            photo: path,
            circle,
            found,
            yaw_deg: view.yaw_deg,
            reliable_fraction: reliable as f64 / unwrapped.reliability.len().max(1) as f64,
        });
        reliability_maps.push(unwrapped.reliability.map(|&r| Rgb::splat(r)));
        views.push((unwrapped, view.yaw_deg));
    }
    // Nothing is written until every view has unwrapped.
    for (k, grey) in reliability_maps.iter().enumerate() {
        ibl_io::write_image(&outputs[2 + k], grey, &WriteOptions::default())?;
    }
    let probe = merge_views(&views).context("merging the views")?;
    write_with_preview(&job.output, &probe)?;
    Ok(BallSummary {
        views: summary,
        width: job.width,
        outputs: outputs.iter().map(|p| p.display().to_string()).collect(),
    })
}

/// What to stitch.
#[derive(Clone, Debug, PartialEq)]
pub struct FisheyeJob {
    /// The front fisheye (looks -Z), or one dual-fisheye frame (2:1, front circle left).
    pub front: PathBuf,
    /// The back fisheye (looks +Z), unless `front` is a dual frame.
    pub back: Option<PathBuf>,
    /// Output lat-long probe.
    pub output: PathBuf,
    /// Field of view of each lens, degrees (more than 180).
    pub fov_deg: f32,
    /// Small rotation of the back lens from ideal.
    pub back_rotation: EulerDegrees,
    /// Width of the seam's feather, degrees.
    pub blend_deg: f32,
    /// Width of the output.
    pub width: usize,
}

/// What `capture fisheye` wrote: the probe's size and files.
#[derive(Clone, Debug, PartialEq)]
pub struct Stitched {
    /// Width of the probe.
    pub width: usize,
    /// Height of the probe.
    pub height: usize,
    /// The probe and its preview.
    pub outputs: [PathBuf; 2],
}

/// Stitches the fisheye pair (or dual frame) and writes the probe and its preview.
pub fn stitch_fisheyes(job: &FisheyeJob) -> Result<Stitched> {
    let mut inputs: Vec<&Path> = vec![&job.front];
    if let Some(b) = &job.back {
        inputs.push(b);
    }
    let outputs = [job.output.clone(), job.output.with_extension("png")];
    for out in &outputs {
        crate::output_paths::check_output_path(out, &inputs)?;
    }
    let what = format!("--width {}", job.width);
    crate::output_paths::check_output_pixels(&what, job.width, job.width / 2)?;
    let front = ibl_io::read_image(&job.front)?.image;
    let back = match &job.back {
        Some(p) => Some(ibl_io::read_image(p)?.image),
        None => None,
    };
    let options = FisheyeOptions {
        fov_deg: job.fov_deg,
        back_rotation: job.back_rotation,
        width: job.width,
        blend_deg: job.blend_deg,
    };
    let probe = stitch_fisheye_pair(&front, back.as_ref(), options)
        .context(job.front.display().to_string())?;
    write_with_preview(&job.output, &probe)?;
    Ok(Stitched {
        width: probe.width(),
        height: probe.height(),
        outputs,
    })
}

//! An automatic proposal of the room's axes (beyond Grosch 2005, who marks every line by hand):
//! line segments detected in perspective views of the panorama ([`crate::line_detection`]),
//! then RANSAC over Manhattan-frame hypotheses, then the same least-squares refinement as marked
//! lines ([`crate::vanishing::refine_rotation`]), so the user starts from a proposal and only
//! corrects it.
//!
//! Each segment is a great circle with unit normal `n` (probe frame). A hypothesis takes two
//! random segments for a first vanishing direction `v1 = n_a x n_b`, a third for the second,
//! `v2 = v1 x n_c` (on that circle and orthogonal to `v1`), and `v3 = v1 x v2`. It scores the
//! summed angular length of the segments whose circle passes within `inlier_deg` of one of the
//! three (`|n . v| < sin(inlier_deg)`). The best of `hypotheses` draws (a seeded PCG stream:
//! deterministic) is refined on its inliers, each assigned to its nearest direction. Axis names:
//! the direction nearest the probe's up becomes `y` (pointing up), and of the four ways to name
//! the other two the rotation nearest the identity is kept. The reported residual is the RMS
//! angle between the inliers' circles and their axes.

use glam::DVec3;
use ibl_core::{Image, Rgb};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;
use rayon::prelude::*;
use serde::Serialize;

use crate::RoomError;
use crate::line_detection::{
    LineDetectionSettings, detect_segments, detection_views, segment_directions,
};
use crate::marks::Axis;
use crate::vanishing::{LineObservation, nearest_rotation, refine_rotation, rotation_degrees};

/// Settings of the proposal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ManhattanSettings {
    /// Side of each detection view, pixels (0: a quarter of the panorama's width).
    pub view_side_px: u32,
    /// The segment detector.
    pub detection: LineDetectionSettings,
    /// RANSAC draws.
    pub hypotheses: u32,
    /// Largest angle between a segment's circle and its vanishing direction, degrees.
    pub inlier_deg: f64,
    /// Seed of the draws.
    pub seed: u64,
}

impl Default for ManhattanSettings {
    fn default() -> Self {
        ManhattanSettings {
            view_side_px: 0,
            detection: LineDetectionSettings::default(),
            hypotheses: 4000,
            inlier_deg: 1.5,
            seed: 1,
        }
    }
}

/// The proposed frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ManhattanProposal {
    /// Rotation from probe to world directions (rows).
    pub world_from_probe: [[f64; 3]; 3],
    /// The same as `[yaw, pitch, roll]` degrees.
    pub rotation_deg: [f64; 3],
    /// Segments detected in all views.
    pub segments: usize,
    /// Inlier segments per axis `x`, `y`, `z`.
    pub inliers: [usize; 3],
    /// RMS angle between the inliers' circles and their axes, degrees.
    pub rms_residual_deg: f64,
}

/// A segment as a great circle, with its angular length.
#[derive(Clone, Copy, Debug)]
struct Circle {
    normal: DVec3,
    length: f64,
}

/// Detects segments in `probe` (lat-long radiance) and proposes the Manhattan frame.
pub fn propose_manhattan_frame(
    probe: &Image<Rgb>,
    settings: &ManhattanSettings,
) -> Result<ManhattanProposal, RoomError> {
    if probe.width() < 16 || probe.height() < 8 {
        return Err(RoomError::Parameter(format!(
            "a {} x {} probe is too small to detect lines in",
            probe.width(),
            probe.height()
        )));
    }
    let side = if settings.view_side_px == 0 {
        (probe.width() as u32 / 4).clamp(64, 2048)
    } else {
        settings.view_side_px.clamp(16, 4096)
    };
    let circles: Vec<Circle> = detection_views(side)
        .par_iter()
        .flat_map_iter(|view| {
            let picture = view.render(probe);
            detect_segments(&picture, &settings.detection)
                .into_iter()
                .filter_map(|s| {
                    let (a, b) = segment_directions(view, &s);
                    let c = a.cross(b);
                    (c.length() > 1e-9).then(|| Circle {
                        normal: c.normalize(),
                        length: c.length().atan2(a.dot(b)),
                    })
                })
                .collect::<Vec<_>>()
        })
        .collect();
    propose_from_circles(&circles, settings)
}

fn propose_from_circles(
    circles: &[Circle],
    settings: &ManhattanSettings,
) -> Result<ManhattanProposal, RoomError> {
    if circles.len() < 3 {
        return Err(RoomError::Unobservable(format!(
            "{} line segments found in the panorama: the proposal needs at least 3",
            circles.len()
        )));
    }
    let threshold = settings.inlier_deg.to_radians().sin();
    let score = |frame: &[DVec3; 3]| -> f64 {
        circles
            .iter()
            .filter(|c| frame.iter().any(|v| c.normal.dot(*v).abs() < threshold))
            .map(|c| c.length)
            .sum()
    };
    let mut rng = Pcg32::seed_from_u64(settings.seed);
    let mut best: Option<([DVec3; 3], f64)> = None;
    let n = circles.len();
    for _ in 0..settings.hypotheses {
        let (a, b, c) = (
            rng.random_range(0..n),
            rng.random_range(0..n),
            rng.random_range(0..n),
        );
        let v1 = circles[a].normal.cross(circles[b].normal);
        if v1.length() < 1e-6 {
            continue;
        }
        let v1 = v1.normalize();
        let v2 = v1.cross(circles[c].normal);
        if v2.length() < 1e-6 {
            continue;
        }
        let v2 = v2.normalize();
        let frame = [v1, v2, v1.cross(v2)];
        let s = score(&frame);
        if best.as_ref().is_none_or(|(_, b)| s > *b) {
            best = Some((frame, s));
        }
    }
    let (frame, _) = best.ok_or_else(|| {
        RoomError::Unobservable("no two segments in the panorama define a direction".into())
    })?;
    // Name the axes: y nearest the probe's up, then the rotation nearest the identity.
    let up = (0..3)
        .max_by(|&i, &j| frame[i].y.abs().total_cmp(&frame[j].y.abs()))
        .unwrap_or(1);
    let y = if frame[up].y < 0.0 {
        -frame[up]
    } else {
        frame[up]
    };
    let others: Vec<DVec3> = (0..3).filter(|&i| i != up).map(|i| frame[i]).collect();
    let mut start = None;
    let mut best_trace = f64::NEG_INFINITY;
    for &x in &[others[0], -others[0], others[1], -others[1]] {
        let m = nearest_rotation(glam::DMat3::from_cols(x, y, x.cross(y)));
        let trace = m.x_axis.x + m.y_axis.y + m.z_axis.z;
        if trace > best_trace {
            best_trace = trace;
            start = Some(m);
        }
    }
    let mut probe_from_world = start.unwrap_or(glam::DMat3::IDENTITY);
    let mut labelled = Vec::new();
    for _ in 0..3 {
        labelled.clear();
        for c in circles {
            let (axis, dot) = Axis::ALL
                .iter()
                .map(|&a| (a, c.normal.dot(probe_from_world.col(a.index())).abs()))
                .min_by(|x, y| x.1.total_cmp(&y.1))
                .unwrap_or((Axis::X, 1.0));
            if dot < threshold {
                labelled.push(LineObservation {
                    axis,
                    normal: c.normal,
                    weight: c.length * c.length,
                });
            }
        }
        probe_from_world = refine_rotation(&labelled, probe_from_world);
    }
    let mut inliers = [0usize; 3];
    let mut sq = 0.0;
    for l in &labelled {
        inliers[l.axis.index()] += 1;
        let a = l
            .normal
            .dot(probe_from_world.col(l.axis.index()))
            .abs()
            .min(1.0)
            .asin()
            .to_degrees();
        sq += a * a;
    }
    let world_from_probe = probe_from_world.transpose();
    Ok(ManhattanProposal {
        world_from_probe: [0, 1, 2].map(|r| world_from_probe.row(r).to_array()),
        rotation_deg: rotation_degrees(world_from_probe),
        segments: circles.len(),
        inliers,
        rms_residual_deg: (sq / labelled.len().max(1) as f64).sqrt(),
    })
}

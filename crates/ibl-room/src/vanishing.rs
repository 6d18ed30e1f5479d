//! Vanishing points and the room's axes from marked lines (Grosch 2005, section 3.1, after
//! Grosch 2001): `world_from_probe`.
//!
//! A segment marked in a view is a great circle on the sphere of directions around the probe:
//! the plane through the probe centre and the segment's two end directions, with unit normal
//! `n = d_from x d_to` (probe frame). Lines parallel to a world axis meet at its vanishing point
//! `v`, which lies on every such circle: `n . v = 0`. The **least-squares vanishing point**
//! minimises `sum_i w_i (n_i . v)^2` over unit `v`: the eigenvector of the smallest eigenvalue of
//! `M = sum_i w_i n_i n_i^T` (weights `w_i = l_i^2`, `l_i` the segment's angular length, because
//! the normal of a segment whose ends are off by `sigma` is off by about `sigma / l_i`). Working on
//! the sphere is the same as the paper's image-plane vanishing point `(x_inf, y_inf)` in one view
//! (its direction `(-x_inf / f, -y_inf / f, 1)` in the paper's camera frame is the ray through
//! that pixel, [`crate::view::PerspectiveView::direction`]) but also combines segments from
//! several views and stays finite when the vanishing point is at infinity in the image. Each
//! point's **residual** is the RMS (and largest) angle `asin |n_i . v|` between its lines' circles
//! and the point.
//!
//! **Axes** (the paper): `x` and `z` from two vanishing points, `y = z x x`, orthonormalised (here
//! by the polar decomposition, the nearest rotation); when `y` is marked instead of one of them,
//! the missing axis follows by the same right-handed cross product. Each point is a direction up
//! to sign: `y` is taken pointing up in the probe (positive probe y), and of the two remaining
//! choices the rotation closest to the identity. Then the rotation is **refined** on all lines of
//! all axes at once (Gauss-Newton on `R exp([w]x)`, residual `n_i . R e_axis`, the three axes kept
//! orthogonal), which is what reaches a tenth of a degree with 1-pixel noise (tested). The result
//! is `probe_from_world = [x y z]` (columns) and `world_from_probe` its transpose.

use glam::{DMat3, DQuat, DVec3, EulerRot};
use nalgebra::{Matrix3, SymmetricEigen};
use serde::Serialize;

use crate::RoomError;
use crate::marks::{Axis, MarksFile};

/// One marked segment as a great circle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineObservation {
    /// The world axis it is parallel to.
    pub axis: Axis,
    /// Unit normal of its great circle's plane, probe frame.
    pub normal: DVec3,
    /// Least-squares weight: its angular length squared, rad^2.
    pub weight: f64,
}

impl LineObservation {
    /// The circle through probe directions `a` and `b` (unit); `None` when they (nearly)
    /// coincide or are opposite.
    pub fn new(axis: Axis, a: DVec3, b: DVec3) -> Option<LineObservation> {
        let c = a.cross(b);
        let length = c.length().atan2(a.dot(b));
        (c.length() > 1e-9).then(|| LineObservation {
            axis,
            normal: c / c.length(),
            weight: length * length,
        })
    }
}

/// The lines of every view of a marks file, as great circles.
pub fn line_observations(marks: &MarksFile) -> Vec<LineObservation> {
    marks
        .views
        .iter()
        .flat_map(|v| {
            v.lines.iter().filter_map(|l| {
                LineObservation::new(
                    l.axis,
                    v.camera.direction(l.from[0], l.from[1]),
                    v.camera.direction(l.to[0], l.to[1]),
                )
            })
        })
        .collect()
}

/// A vanishing point with its residual.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct VanishingPoint {
    /// The axis.
    pub axis: Axis,
    /// Unit direction, probe frame (sign as chosen for the axes).
    pub direction: [f64; 3],
    /// Lines used.
    pub lines: usize,
    /// RMS angle between the lines' circles and the point, degrees.
    pub rms_residual_deg: f64,
    /// Largest such angle, degrees.
    pub max_residual_deg: f64,
}

fn residuals_deg(lines: &[&LineObservation], v: DVec3) -> (f64, f64) {
    let angles: Vec<f64> = lines
        .iter()
        .map(|l| l.normal.dot(v).abs().min(1.0).asin().to_degrees())
        .collect();
    let rms = (angles.iter().map(|a| a * a).sum::<f64>() / angles.len().max(1) as f64).sqrt();
    (rms, angles.iter().copied().fold(0.0, f64::max))
}

/// The least-squares vanishing point of `lines` (all of one axis; at least two that are not
/// the same circle).
pub fn vanishing_point(
    axis: Axis,
    lines: &[&LineObservation],
) -> Result<VanishingPoint, RoomError> {
    if lines.len() < 2 {
        return Err(RoomError::Unobservable(format!(
            "axis {}: {} line(s) marked, a vanishing point needs at least 2",
            axis.name(),
            lines.len()
        )));
    }
    let mut m = Matrix3::<f64>::zeros();
    for l in lines {
        let n = nalgebra::Vector3::new(l.normal.x, l.normal.y, l.normal.z);
        m += n * n.transpose() * l.weight;
    }
    let eigen = SymmetricEigen::new(m);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
    // Two distinct circles make the two largest eigenvalues clearly positive.
    if eigen.eigenvalues[order[1]] <= 1e-9 * eigen.eigenvalues[order[2]].max(1e-300) {
        return Err(RoomError::Unobservable(format!(
            "axis {}: the marked lines all lie on one great circle",
            axis.name()
        )));
    }
    let e = eigen.eigenvectors.column(order[0]);
    let v = DVec3::new(e[0], e[1], e[2]).normalize();
    let (rms, max) = residuals_deg(lines, v);
    Ok(VanishingPoint {
        axis,
        direction: v.to_array(),
        lines: lines.len(),
        rms_residual_deg: rms,
        max_residual_deg: max,
    })
}

/// The rotation nearest to `m` (polar decomposition by SVD).
pub fn nearest_rotation(m: DMat3) -> DMat3 {
    let a = Matrix3::from_fn(|r, c| m.col(c)[r]);
    let svd = a.svd(true, true);
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return DMat3::IDENTITY;
    };
    let mut r = u * vt;
    if r.determinant() < 0.0 {
        let mut u2 = u;
        u2.column_mut(2).neg_mut();
        r = u2 * vt;
    }
    DMat3::from_cols_array(&[
        r[(0, 0)],
        r[(1, 0)],
        r[(2, 0)],
        r[(0, 1)],
        r[(1, 1)],
        r[(2, 1)],
        r[(0, 2)],
        r[(1, 2)],
        r[(2, 2)],
    ])
}

/// `probe_from_world` from two axes' vanishing directions (Grosch: `x`, `z`, then `y = z x x`),
/// orthonormalised, with signs as the module notes say.
pub fn axes_from_two(first: (Axis, DVec3), second: (Axis, DVec3)) -> Result<DMat3, RoomError> {
    let mut dirs: [Option<DVec3>; 3] = [None; 3];
    for (axis, d) in [first, second] {
        if dirs[axis.index()].is_some() {
            return Err(RoomError::Parameter(format!(
                "two vanishing points for axis {}",
                axis.name()
            )));
        }
        dirs[axis.index()] = Some(d.normalize());
    }
    let best = |x: DVec3, y: DVec3, z: DVec3| -> DMat3 {
        // y up in the probe, then of +-x the rotation nearest the identity (largest trace).
        let y = if y.y < 0.0 { -y } else { y };
        let candidates = [x, -x].map(|x| {
            let z_fit = if z.dot(x.cross(y)) < 0.0 { -z } else { z };
            nearest_rotation(DMat3::from_cols(x, y, z_fit))
        });
        let trace = |m: &DMat3| m.x_axis.x + m.y_axis.y + m.z_axis.z;
        if trace(&candidates[0]) >= trace(&candidates[1]) {
            candidates[0]
        } else {
            candidates[1]
        }
    };
    Ok(match dirs {
        [Some(x), None, Some(z)] => best(x, z.cross(x), z),
        [Some(x), Some(y), None] => best(x, y, x.cross(y)),
        [None, Some(y), Some(z)] => best(y.cross(z), y, z),
        _ => {
            return Err(RoomError::Parameter(
                "axes_from_two needs two different axes".into(),
            ));
        }
    })
}

/// Gauss-Newton refinement of `probe_from_world` on every line: minimises `sum_i w_i (n_i .
/// R e_axis(i))^2` over rotations. Returns the refined rotation.
pub fn refine_rotation(lines: &[LineObservation], start: DMat3) -> DMat3 {
    let mut r = start;
    for _ in 0..20 {
        let mut jtj = Matrix3::<f64>::zeros();
        let mut jtr = nalgebra::Vector3::<f64>::zeros();
        for l in lines {
            let e = [DVec3::X, DVec3::Y, DVec3::Z][l.axis.index()];
            let residual = l.normal.dot(r * e);
            // d/dw n . R exp([w]x) e = (e x R^T n) . w
            let j = e.cross(r.transpose() * l.normal);
            let jv = nalgebra::Vector3::new(j.x, j.y, j.z);
            jtj += jv * jv.transpose() * l.weight;
            jtr += jv * (residual * l.weight);
        }
        let Some(step) = jtj.try_inverse().map(|inv| -(inv * jtr)) else {
            break;
        };
        let w = DVec3::new(step[0], step[1], step[2]);
        let angle = w.length();
        if angle < 1e-14 {
            break;
        }
        r = nearest_rotation(r * DMat3::from_axis_angle(w / angle, angle));
        if angle < 1e-12 {
            break;
        }
    }
    r
}

/// The calibration of the probe from marked lines.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Calibration {
    /// Rotation from probe directions to world directions (rows).
    pub world_from_probe: [[f64; 3]; 3],
    /// The same as `[yaw, pitch, roll]` degrees (`Ry Rx Rz`, `docs/CONVENTIONS.md` section 1),
    /// what a room file's `probe.rotation_deg` takes.
    pub rotation_deg: [f64; 3],
    /// Each marked axis's least-squares vanishing point (directions of the refined frame).
    pub vanishing_points: Vec<VanishingPoint>,
    /// RMS angle between every line's circle and its axis in the refined frame, degrees.
    pub rms_residual_deg: f64,
    /// Each line's angle to its axis in the refined frame, degrees, in the order given (a mark
    /// far above the others is probably assigned to the wrong axis or misplaced).
    pub line_residuals_deg: Vec<f64>,
    /// How far the refinement turned the paper's two-point axes, degrees.
    pub refinement_deg: f64,
}

impl Calibration {
    /// `world_from_probe` as a matrix.
    pub fn world_from_probe(&self) -> DMat3 {
        let m = self.world_from_probe;
        DMat3::from_cols_array(&[
            m[0][0], m[1][0], m[2][0], m[0][1], m[1][1], m[2][1], m[0][2], m[1][2], m[2][2],
        ])
    }
}

/// `[yaw, pitch, roll]` degrees with `R = Ry(yaw) Rx(pitch) Rz(roll)`.
pub fn rotation_degrees(world_from_probe: DMat3) -> [f64; 3] {
    let (yaw, pitch, roll) = DQuat::from_mat3(&world_from_probe).to_euler(EulerRot::YXZ);
    [yaw.to_degrees(), pitch.to_degrees(), roll.to_degrees()]
}

/// Calibrates the probe from great circles of at least two axes (two lines each).
pub fn calibrate(lines: &[LineObservation]) -> Result<Calibration, RoomError> {
    let by_axis: Vec<Vec<&LineObservation>> = Axis::ALL
        .iter()
        .map(|&a| lines.iter().filter(|l| l.axis == a).collect())
        .collect();
    let mut points = Vec::new();
    for axis in Axis::ALL {
        if by_axis[axis.index()].len() >= 2 {
            points.push(vanishing_point(axis, &by_axis[axis.index()])?);
        }
    }
    if points.len() < 2 {
        return Err(RoomError::Unobservable(format!(
            "lines marked for {} axis(es) with at least two lines each; the axes need two",
            points.len()
        )));
    }
    // The paper's pair: x and z when both are there, else the two available.
    let pick = |a: Axis| points.iter().find(|p| p.axis == a);
    let (first, second) = match (pick(Axis::X), pick(Axis::Y), pick(Axis::Z)) {
        (Some(x), _, Some(z)) => (x, z),
        (Some(x), Some(y), None) => (x, y),
        (None, Some(y), Some(z)) => (y, z),
        _ => {
            return Err(RoomError::Numerical(
                "two vanishing points but no pair".into(),
            ));
        }
    };
    let dir = |p: &VanishingPoint| DVec3::from_array(p.direction);
    let paper = axes_from_two((first.axis, dir(first)), (second.axis, dir(second)))?;
    let refined = refine_rotation(lines, paper);
    let change = (paper.transpose() * refined).to_cols_array();
    let trace = change[0] + change[4] + change[8];
    let refinement_deg = ((trace - 1.0) / 2.0).clamp(-1.0, 1.0).acos().to_degrees();
    let vanishing_points = points
        .iter()
        .map(|p| {
            let axis_dir = refined.col(p.axis.index());
            let (rms, max) = residuals_deg(&by_axis[p.axis.index()], axis_dir);
            VanishingPoint {
                direction: axis_dir.to_array(),
                rms_residual_deg: rms,
                max_residual_deg: max,
                ..*p
            }
        })
        .collect();
    let line_residuals_deg: Vec<f64> = lines
        .iter()
        .map(|l| {
            l.normal
                .dot(refined.col(l.axis.index()))
                .abs()
                .min(1.0)
                .asin()
                .to_degrees()
        })
        .collect();
    let rms_residual_deg = (line_residuals_deg.iter().map(|a| a * a).sum::<f64>()
        / line_residuals_deg.len().max(1) as f64)
        .sqrt();
    let world_from_probe = refined.transpose();
    let rows = [0, 1, 2].map(|r| world_from_probe.row(r).to_array());
    Ok(Calibration {
        world_from_probe: rows,
        rotation_deg: rotation_degrees(world_from_probe),
        vanishing_points,
        rms_residual_deg,
        line_residuals_deg,
        refinement_deg,
    })
}

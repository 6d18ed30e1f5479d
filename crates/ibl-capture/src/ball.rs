//! Mirror-ball light probes: finding the ball in a photograph, unwrapping it to a lat-long map
//! with a per-texel reliability, and merging views taken from different sides of the ball.
//!
//! Inputs are linear HDR photographs (`Image<Rgb>`, radiance in any consistent unit, row 0 at
//! the top, already merged from brackets). Pixel (i, j) covers `[i, i + 1) x [j, j + 1)` in
//! continuous pixel coordinates, so its centre is `(i + 0.5, j + 0.5)`.
//!
//! **Model** (CONVENTIONS section 3, Debevec 1998 "Rendering synthetic objects into real
//! scenes"): an orthographic camera on the ball's +Z looks towards -Z. The ball's outline in the
//! photo is the circle `(cx, cy, r)`; a photo point has disc coordinates `a = (x - cx) / r`,
//! `b = (cy - y) / r` (up positive), `rho = sqrt(a^2 + b^2)`, the normal there is
//! `n = (a, b, sqrt(1 - rho^2))` and the reflected direction is `d = i - 2 (i . n) n` with
//! `i = (0, 0, -1)`. Inverse: `(a, b) = (d_x, d_y) / sqrt(2 (1 + d_z))` and
//! `rho = sqrt((1 - d_z) / 2) = sin(alpha / 2)`, `alpha` the angle between `d` and +Z. The ball
//! centre reflects the camera (+Z: the camera and the photographer appear there); the rim is the
//! blind spot straight behind the ball (-Z). The ball's frame is the world frame of the probe
//! with the camera on +Z: a view's `yaw_deg` in [`merge_views`] turns it into a common frame.
//!
//! **Finding the ball** ([`find_ball`]). On a box-filtered copy at most 512 pixels across
//! (factor `f`), the log luminance `ln(Y + eps)` (`eps` = 1e-3 of the mean, so the detector does
//! not depend on exposure) gives Sobel gradients; edge points are the local maxima along the
//! gradient whose magnitude exceeds 0.1 (about a 22 % step per pixel). Each edge point votes for
//! circle centres along its gradient line on both sides (the gradient Hough transform: Kimme,
//! Ballard & Sklansky 1975; Ballard 1981), because random 3-point RANSAC draws all three points
//! on the rim with a probability that falls with the cube of the rim's share of the edge points
//! (a textured reflection inside the ball easily drops it below 1e-3). Each of the 6 strongest
//! centre peaks gets its 2 most common radii among the edge points whose gradient is radial
//! (within 30 degrees). Each candidate is refitted three times to the strongest radial edge
//! point per angular sector within 5, then 2.5 coarse pixels of it (the outline is the
//! strongest step along a ray in most photos, while the compressed reflection just inside the
//! rim is concentric texture that would pull a plain inlier fit inwards) by robust geometric
//! least squares (Kasa's algebraic fit, then Gauss-Newton on `|p - c| - r`, residuals beyond
//! `max(3 sigma, floor)` trimmed, sigma = 1.4826 times the median absolute residual), and the
//! candidate with the most inliers (radial, within 1.5 coarse pixels) wins. It is then
//! *verified*: the radial edge points on the circle per pixel of its visible circumference (the
//! support, at least 0.5) must be at least 3 times as dense as in the sparser of the two rings
//! of the same width just inside and just outside it (a real outline separates two regions;
//! noise or texture is as dense beside a circle as on it). Finally the circle is refined twice
//! at full resolution (search windows `2 f + 2`, then 2 pixels): along `max(64, pi r)` rays
//! from the centre the linear luminance profile is sampled every 1/4 pixel (bilinear); the edge
//! is where it crosses the mean of its values 1.25 pixels either side of the steepest log step
//! (a half-level crossing, unbiased for a symmetric blur and a constant level on each side;
//! reading the levels closer would blur them, further would let the reflection's fast radial
//! change near the rim bias them); rays with under 25 % contrast are dropped and the circle is
//! fitted robustly (floor 0.25 px) to the crossings. On synthetic balls of 130 to 512 pixels
//! rendered from four of the bundled probes and box-filtered into a dark photo, the centre is
//! found within 0.2 px and the radius 0.1 to 0.2 px too large. The outline must be visible: a
//! ball whose rim is as bright as the background around it (the rim reflects what is behind
//! the ball, which is what surrounds it in the photo) may be refused or fitted to an inner
//! circle; give the circle by hand then. Cost O(W H) for the downsampling and the edges,
//! O(N r_max) for the votes (N edge points of the coarse copy), O(r^2) for the refinement
//! (`pi r` rays of a few dozen samples).
//!
//! **Unwrapping** ([`unwrap_ball`]). The circle's bounding square is resampled bilinearly into
//! a `ceil(2 r)`-pixel square (the disc inscribed, as `ibl_mapping::Mapping::MirrorBall` wants;
//! 0 where it leaves the photo), which `ibl_mapping::resample` turns into the lat-long map
//! (energy-conserving area averaging). Cost O(r^2 + W H k^2) (see `ibl_mapping::resample`).
//!
//! **Reliability** (per lat-long texel, in [0, 1], at the texel's centre direction `d`):
//! `reliability = rim(rho) * sampling(rho) * camera(alpha) * inside`, with
//!
//! * `rim = 1 - smoothstep((rho - rho0) / (1 - rho0))`, `rho0` = [`BallReliability::rim_start`]
//!   (0.9): 1 below `rho0`, 0 at the rim. Beyond `rho = 0.9` light meets the ball at over 64
//!   degrees from its normal (the chrome's Fresnel reflectance and colour change) and an error
//!   `delta` in the circle moves the direction by `2 delta / (r sqrt(1 - rho^2))`, over 2.3
//!   times more than at the centre and unboundedly more towards the rim.
//! * `sampling = min(1, (pi / H) r sqrt(1 - rho^2) / 2)`: the mirror ball is an equal-area map
//!   (`dOmega = 4 da db`: every photo pixel covers `4 / r^2` sr), so the solid angle per source
//!   pixel says nothing; what degrades is its shape. One photo pixel spans
//!   `2 / (r sqrt(1 - rho^2))` radians radially and `2 sqrt(1 - rho^2) / r` tangentially; the
//!   factor is the output texel's angular height `pi / H` over the radial span, capped at 1: the
//!   share of the output's detail the photo delivers along its worst axis.
//! * `camera = smoothstep((alpha - cone) / feather)`, `cone` = [`BallReliability::camera_cone_deg`]
//!   (30 degrees) and `feather` = [`BallReliability::camera_feather_deg`] (10): 0 within `cone`
//!   of +Z, the direction back towards the camera, whose reflection shows the camera, tripod and
//!   photographer instead of the scene (`cone = 0` turns this off). At 30 degrees this covers a
//!   photographer about 1.2 m wide standing 1.1 m from the ball.
//! * `inside`: 0 where the photo point lies outside the photo.
//!
//! **Merging** ([`merge_views`]). View k's maps are turned into the common frame by
//! `world_from_view = Ry(yaw_k)` (CONVENTIONS section 1; the camera of a view with yaw 90
//! degrees stands on the common frame's +X) with `ibl_mapping::rotate`, rotating `w_k L_k` and
//! `w_k` (premultiplied, so an unreliable texel does not bleed into its neighbours), and blended
//! as `L = sum_k w_k L_k / sum_k w_k`: where one view is occluded (its camera cone, its rim) the
//! other wins outright. Where no view has any reliability the plain mean of the rotated views is
//! used. Two views 90 degrees apart cover the sphere: each view's camera cone and rim lie 90
//! degrees from the other's axis, at `rho = 0.71` of its ball. Cost: three rotations per view.

use std::f64::consts::{PI, TAU};

use glam::DVec3;
use ibl_core::{EulerDegrees, Image, LatLong, Rgb};
use ibl_mapping::{Mapping, resample, rotate};
use rayon::prelude::*;

use crate::CaptureError;

/// The outline of a mirror ball in a photo, in continuous pixel coordinates (pixel (i, j)'s
/// centre is `(i + 0.5, j + 0.5)`, x to the right, y down).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Circle {
    /// Centre, pixels from the left edge.
    pub cx: f64,
    /// Centre, pixels from the top edge.
    pub cy: f64,
    /// Radius, pixels.
    pub r: f64,
}

/// A mirror-ball photo unwrapped to lat-long, in the ball's frame (camera on +Z).
#[derive(Clone, Debug, PartialEq)]
pub struct Unwrapped {
    /// Radiance, `width x width / 2` lat-long (CONVENTIONS section 2), the photo's unit.
    pub probe: Image<Rgb>,
    /// How far each texel can be trusted, in [0, 1], same size (see the module note).
    pub reliability: Image<f32>,
}

/// Parameters of the reliability model of [`unwrap_ball_with`] (see the module note).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BallReliability {
    /// Ball radius fraction `rho0` in [0, 1) where the rim fall-off starts (default 0.9).
    pub rim_start: f64,
    /// Half-angle, degrees in [0, 180), of the cone around the direction back to the camera
    /// (+Z) whose reliability is 0 (default 30; 0 turns the camera cone off).
    pub camera_cone_deg: f64,
    /// Degrees in [0, 180) beyond the cone over which the reliability rises to 1 (default 10).
    pub camera_feather_deg: f64,
}

impl Default for BallReliability {
    fn default() -> Self {
        BallReliability {
            rim_start: 0.9,
            camera_cone_deg: 30.0,
            camera_feather_deg: 10.0,
        }
    }
}

/// The detector works on a copy at most this many pixels across.
const COARSE_MAX: usize = 512;
/// Smallest photo side, pixels.
const MIN_SIDE: usize = 16;
/// Log-luminance gradient (per pixel, Sobel / 8) an edge point needs: about a 22 % step.
const EDGE_THRESHOLD: f32 = 0.1;
/// Fewest edge points worth searching.
const MIN_EDGE_POINTS: usize = 24;
/// Smallest ball radius, coarse pixels.
const MIN_RADIUS: f64 = 6.0;
/// An edge point is radial when its gradient is within 30 degrees of the radius.
const COS_RADIAL: f64 = 0.866;
/// Inlier band half-width, coarse pixels.
const TOLERANCE: f64 = 1.5;
/// Centre peaks examined.
const PEAKS: usize = 6;
/// Least fraction of the visible circumference with a radial edge point.
const MIN_SUPPORT: f64 = 0.5;
/// Least ratio of the edge density on the circle to the sparser ring beside it.
const MIN_CONTRAST: f64 = 3.0;
/// Rays of the fine stage whose two levels differ by less than this fraction are dropped.
const MIN_RAY_CONTRAST: f64 = 0.25;
/// The fine stage reads its two levels this many pixels either side of the steepest step.
const LEVEL_OFFSET: f64 = 1.25;
/// Profile sampling step of the fine stage, pixels.
const RAY_STEP: f64 = 0.25;

/// `3x^2 - 2x^3` on [0, 1], clamped outside (C1 ramp from 0 to 1).
pub(crate) fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Luminance with negative and non-finite values read as 0.
fn luminance(c: Rgb) -> f32 {
    let y = c.luminance();
    if y.is_finite() && y > 0.0 { y } else { 0.0 }
}

/// An edge point of the coarse copy: position (continuous coarse pixels) and unit gradient.
#[derive(Clone, Copy, Debug)]
struct EdgePoint {
    p: (f64, f64),
    n: (f64, f64),
    /// Gradient magnitude (log luminance per pixel).
    m: f32,
}

/// The box-filtered luminance copy the detector works on.
struct Coarse {
    /// Downsampling factor (photo pixels per coarse pixel along each axis).
    factor: usize,
    width: usize,
    height: usize,
    /// `ln(Y + eps)`.
    log_lum: Vec<f32>,
    /// Mean linear luminance.
    mean: f64,
}

impl Coarse {
    fn new(photo: &Image<Rgb>) -> Self {
        let factor = photo
            .width()
            .max(photo.height())
            .div_ceil(COARSE_MAX)
            .max(1);
        let (width, height) = (photo.width() / factor, photo.height() / factor);
        let lum: Vec<f32> = (0..height)
            .into_par_iter()
            .flat_map_iter(|j| {
                (0..width).map(move |i| {
                    let mut sum = 0.0f64;
                    for y in j * factor..(j + 1) * factor {
                        for c in &photo.row(y)[i * factor..(i + 1) * factor] {
                            sum += f64::from(luminance(*c));
                        }
                    }
                    (sum / (factor * factor) as f64) as f32
                })
            })
            .collect();
        let mean = lum.iter().map(|&v| f64::from(v)).sum::<f64>() / lum.len().max(1) as f64;
        let eps = (1e-3 * mean).max(f64::from(f32::MIN_POSITIVE)) as f32;
        let log_lum = lum.iter().map(|&v| (v + eps).ln()).collect();
        Coarse {
            factor,
            width,
            height,
            log_lum,
            mean,
        }
    }

    /// Sobel gradients `(gx, gy) / 8` of the interior pixels (0 on the border).
    fn gradients(&self) -> Vec<(f32, f32)> {
        let (w, h) = (self.width, self.height);
        let l = |i: usize, j: usize| self.log_lum[j * w + i];
        (0..h)
            .into_par_iter()
            .flat_map_iter(|j| {
                (0..w).map(move |i| {
                    if i == 0 || j == 0 || i + 1 >= w || j + 1 >= h {
                        return (0.0, 0.0);
                    }
                    let gx = (l(i + 1, j - 1) + 2.0 * l(i + 1, j) + l(i + 1, j + 1))
                        - (l(i - 1, j - 1) + 2.0 * l(i - 1, j) + l(i - 1, j + 1));
                    let gy = (l(i - 1, j + 1) + 2.0 * l(i, j + 1) + l(i + 1, j + 1))
                        - (l(i - 1, j - 1) + 2.0 * l(i, j - 1) + l(i + 1, j - 1));
                    (gx / 8.0, gy / 8.0)
                })
            })
            .collect()
    }

    /// Edge points: gradient magnitude above [`EDGE_THRESHOLD`] and a local maximum along the
    /// gradient direction (quantised to 45 degrees). Row order, deterministic.
    fn edges(&self) -> Vec<EdgePoint> {
        let (w, h) = (self.width, self.height);
        let grad = self.gradients();
        let mag: Vec<f32> = grad.iter().map(|&(x, y)| x.hypot(y)).collect();
        let rows: Vec<Vec<EdgePoint>> = (1..h.saturating_sub(1))
            .into_par_iter()
            .map(|j| {
                let mut out = Vec::new();
                for i in 1..w - 1 {
                    let k = j * w + i;
                    let m = mag[k];
                    if m <= EDGE_THRESHOLD {
                        continue;
                    }
                    let (gx, gy) = grad[k];
                    // Neighbour offset along the gradient, quantised to 45 degrees.
                    let angle = gy.atan2(gx).to_degrees().rem_euclid(180.0);
                    let (di, dj): (isize, isize) = if !(22.5..157.5).contains(&angle) {
                        (1, 0)
                    } else if angle < 67.5 {
                        (1, 1)
                    } else if angle < 112.5 {
                        (0, 1)
                    } else {
                        (-1, 1)
                    };
                    let at = |si: isize| {
                        let x = (i as isize + si * di) as usize;
                        let y = (j as isize + si * dj) as usize;
                        mag[y * w + x]
                    };
                    if m >= at(1) && m > at(-1) {
                        out.push(EdgePoint {
                            p: (i as f64 + 0.5, j as f64 + 0.5),
                            n: (f64::from(gx / m), f64::from(gy / m)),
                            m,
                        });
                    }
                }
                out
            })
            .collect();
        rows.into_iter().flatten().collect()
    }
}

/// Cosine between an edge point's gradient and the radius through it (absolute value), and its
/// distance from the centre.
fn radial(e: &EdgePoint, cx: f64, cy: f64) -> (f64, f64) {
    let (dx, dy) = (e.p.0 - cx, e.p.1 - cy);
    let d = dx.hypot(dy);
    if d <= 0.0 {
        return (0.0, 0.0);
    }
    ((e.n.0 * dx + e.n.1 * dy).abs() / d, d)
}

/// Edge points within `tol` of the circle with a radial gradient.
fn inliers(edges: &[EdgePoint], c: &Circle, tol: f64) -> Vec<(f64, f64)> {
    edges
        .iter()
        .filter_map(|e| {
            let (cos, d) = radial(e, c.cx, c.cy);
            (cos >= COS_RADIAL && (d - c.r).abs() <= tol).then_some(e.p)
        })
        .collect()
}

/// Circle centre candidates: peaks of the gradient Hough accumulator (each edge point votes
/// along its gradient line, both ways, at distances `MIN_RADIUS..=r_max`), smoothed by a 3 x 3
/// box, suppressed within `MIN_RADIUS` of a stronger peak. Deterministic.
fn centre_peaks(edges: &[EdgePoint], w: usize, h: usize, r_max: f64) -> Vec<(f64, f64)> {
    let mut acc = vec![0u32; w * h];
    for e in edges {
        for sign in [-1.0, 1.0] {
            let mut t = MIN_RADIUS;
            while t <= r_max {
                let (x, y) = (e.p.0 + sign * t * e.n.0, e.p.1 + sign * t * e.n.1);
                if x < 0.0 || y < 0.0 || x >= w as f64 || y >= h as f64 {
                    break;
                }
                acc[y as usize * w + x as usize] += 1;
                t += 1.0;
            }
        }
    }
    let mut smooth = vec![0u32; w * h];
    for j in 1..h.saturating_sub(1) {
        for i in 1..w - 1 {
            let mut s = 0;
            for y in j - 1..=j + 1 {
                s += acc[y * w + i - 1] + acc[y * w + i] + acc[y * w + i + 1];
            }
            smooth[j * w + i] = s;
        }
    }
    let mut peaks = Vec::new();
    let reach = MIN_RADIUS as isize;
    for _ in 0..PEAKS {
        let Some(k) = strongest(&smooth) else {
            break;
        };
        let (i, j) = ((k % w) as isize, (k / w) as isize);
        // Centroid of the raw votes around the peak: sub-cell centre.
        let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
        for y in (j - 1).max(0)..=(j + 1).min(h as isize - 1) {
            for x in (i - 1).max(0)..=(i + 1).min(w as isize - 1) {
                let v = f64::from(acc[y as usize * w + x as usize]);
                sx += v * (x as f64 + 0.5);
                sy += v * (y as f64 + 0.5);
                sw += v;
            }
        }
        peaks.push((sx / sw.max(1.0), sy / sw.max(1.0)));
        for y in (j - reach).max(0)..=(j + reach).min(h as isize - 1) {
            for x in (i - reach).max(0)..=(i + reach).min(w as isize - 1) {
                smooth[y as usize * w + x as usize] = 0;
            }
        }
    }
    peaks
}

/// Index of the largest positive count (the first of equals); `None` when every count is 0.
fn strongest(counts: &[u32]) -> Option<usize> {
    let (k, &best) = counts
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(&a.0)))?;
    (best > 0).then_some(k)
}

/// The two most common radii (1-pixel bins smoothed by `[1, 2, 1]`) of the radial edge points
/// around a centre.
fn radius_candidates(edges: &[EdgePoint], c: (f64, f64), r_max: f64) -> Vec<f64> {
    let bins = r_max.ceil() as usize + 2;
    let mut hist = vec![0u32; bins];
    for e in edges {
        let (cos, d) = radial(e, c.0, c.1);
        if cos >= COS_RADIAL && d >= MIN_RADIUS && d <= r_max {
            hist[d as usize] += 1;
        }
    }
    let mut smooth: Vec<u32> = (0..bins)
        .map(|k| {
            let left = if k > 0 { hist[k - 1] } else { 0 };
            let right = hist.get(k + 1).copied().unwrap_or(0);
            left + 2 * hist[k] + right
        })
        .collect();
    let mut out = Vec::new();
    for _ in 0..2 {
        let Some(k) = strongest(&smooth) else {
            break;
        };
        out.push(k as f64 + 0.5);
        for v in &mut smooth[k.saturating_sub(3)..(k + 4).min(bins)] {
            *v = 0;
        }
    }
    out
}

/// Least-squares circle through points: Kasa's algebraic fit (`x^2 + y^2 + D x + E y + F = 0`,
/// on coordinates relative to the centroid), then Gauss-Newton on the geometric residuals
/// `|p - c| - r`. `None` for fewer than three points or a degenerate (collinear) set.
fn fit_circle(points: &[(f64, f64)]) -> Option<Circle> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |a, p| (a.0 + p.0 / n, a.1 + p.1 / n));
    let mut ata = glam::DMat3::ZERO;
    let mut atb = DVec3::ZERO;
    for &(x, y) in points {
        let (x, y) = (x - mx, y - my);
        let row = DVec3::new(x, y, 1.0);
        ata += glam::DMat3::from_cols(row * row.x, row * row.y, row * row.z);
        atb += row * -(x * x + y * y);
    }
    if ata.determinant().abs() < 1e-12 * n.powi(3) {
        return None;
    }
    let s = ata.inverse() * atb;
    let (mut cx, mut cy) = (-0.5 * s.x, -0.5 * s.y);
    let mut r = (cx * cx + cy * cy - s.z).max(0.0).sqrt();
    for _ in 0..10 {
        let mut jtj = glam::DMat3::ZERO;
        let mut jte = DVec3::ZERO;
        for &(x, y) in points {
            let (dx, dy) = (x - mx - cx, y - my - cy);
            let d = dx.hypot(dy).max(1e-12);
            let jac = DVec3::new(-dx / d, -dy / d, -1.0);
            jtj += glam::DMat3::from_cols(jac * jac.x, jac * jac.y, jac * jac.z);
            jte += jac * (d - r);
        }
        if jtj.determinant().abs() < 1e-12 {
            break;
        }
        let step = jtj.inverse() * -jte;
        cx += step.x;
        cy += step.y;
        r += step.z;
        if step.length() < 1e-9 {
            break;
        }
    }
    let c = Circle {
        cx: cx + mx,
        cy: cy + my,
        r,
    };
    (c.cx.is_finite() && c.cy.is_finite() && r.is_finite() && r > 0.0).then_some(c)
}

/// Refits a coarse circle to the outline: in each of `max(32, pi r)` angular sectors the
/// strongest radial edge point within `band` pixels of the circle (a ball's outline is the
/// strongest step along a ray in most photos; the compressed reflection just inside the rim is
/// concentric texture that would otherwise pull a fit inwards), then a robust fit.
fn refit_outline(edges: &[EdgePoint], c: &Circle, band: f64) -> Option<Circle> {
    let sectors = ((PI * c.r).ceil() as usize).clamp(32, 1440);
    let mut strongest: Vec<Option<&EdgePoint>> = vec![None; sectors];
    for e in edges {
        let (cos, d) = radial(e, c.cx, c.cy);
        if cos < COS_RADIAL || (d - c.r).abs() > band {
            continue;
        }
        let t = (e.p.1 - c.cy).atan2(e.p.0 - c.cx).rem_euclid(TAU);
        let k = ((t / TAU * sectors as f64) as usize).min(sectors - 1);
        if strongest[k].is_none_or(|s| e.m > s.m) {
            strongest[k] = Some(e);
        }
    }
    let points: Vec<(f64, f64)> = strongest.iter().flatten().map(|e| e.p).collect();
    robust_fit(&points, 0.5)
}

/// Fits a circle to `points` with robust trimming: residuals beyond `max(3 sigma, floor)`
/// (`sigma = 1.4826` times the median absolute residual) are dropped and the fit repeated, up to
/// three times.
fn robust_fit(points: &[(f64, f64)], floor: f64) -> Option<Circle> {
    let mut c = fit_circle(points)?;
    let mut kept: Vec<(f64, f64)> = points.to_vec();
    for _ in 0..3 {
        let mut res: Vec<f64> = kept
            .iter()
            .map(|p| ((p.0 - c.cx).hypot(p.1 - c.cy) - c.r).abs())
            .collect();
        res.sort_by(f64::total_cmp);
        let sigma = 1.4826 * res[res.len() / 2];
        let limit = (3.0 * sigma).max(floor);
        let next: Vec<(f64, f64)> = kept
            .iter()
            .copied()
            .filter(|p| ((p.0 - c.cx).hypot(p.1 - c.cy) - c.r).abs() <= limit)
            .collect();
        if next.len() == kept.len() || next.len() < 3 {
            break;
        }
        kept = next;
        c = fit_circle(&kept)?;
    }
    Some(c)
}

/// Support and contrast of a coarse circle (see the module note): radial edge points on it per
/// pixel of visible circumference, and that density over the sparser of the two rings beside it.
fn verify(edges: &[EdgePoint], c: &Circle, w: usize, h: usize) -> (f64, f64) {
    let (mut on, mut inner, mut outer) = (0usize, 0usize, 0usize);
    for e in edges {
        let (cos, d) = radial(e, c.cx, c.cy);
        if cos < COS_RADIAL {
            continue;
        }
        let off = d - c.r;
        if off.abs() <= TOLERANCE {
            on += 1;
        } else if (-3.0 * TOLERANCE..-TOLERANCE).contains(&off) {
            inner += 1;
        } else if off > TOLERANCE && off <= 3.0 * TOLERANCE {
            outer += 1;
        }
    }
    // The share of each ring inside the image's interior (where edges can be found).
    let visible = |radius: f64| {
        let steps = 720;
        let inside = (0..steps)
            .filter(|&k| {
                let t = TAU * k as f64 / steps as f64;
                let (x, y) = (c.cx + radius * t.cos(), c.cy + radius * t.sin());
                x > 1.0 && y > 1.0 && x < (w - 1) as f64 && y < (h - 1) as f64
            })
            .count();
        TAU * radius.max(0.0) * inside as f64 / steps as f64
    };
    let density = |count: usize, radius: f64| {
        let len = visible(radius);
        if len > 0.0 { count as f64 / len } else { 0.0 }
    };
    let support = density(on, c.r);
    let beside = density(inner, c.r - 2.0 * TOLERANCE).min(density(outer, c.r + 2.0 * TOLERANCE));
    let contrast = if beside > 0.0 {
        support / beside
    } else {
        f64::INFINITY
    };
    (support, contrast)
}

/// Bilinear luminance at continuous photo coordinates; `None` outside the pixel centres' hull.
fn luminance_at(photo: &Image<Rgb>, x: f64, y: f64) -> Option<f64> {
    let (fx, fy) = (x - 0.5, y - 0.5);
    if !(fx >= 0.0 && fy >= 0.0) {
        return None;
    }
    let (i0, j0) = (fx as usize, fy as usize);
    if i0 + 1 >= photo.width() || j0 + 1 >= photo.height() {
        return None;
    }
    let (tx, ty) = (fx - i0 as f64, fy - j0 as f64);
    let l = |i: usize, j: usize| f64::from(luminance(*photo.get(i, j)));
    Some(
        (1.0 - ty) * ((1.0 - tx) * l(i0, j0) + tx * l(i0 + 1, j0))
            + ty * ((1.0 - tx) * l(i0, j0 + 1) + tx * l(i0 + 1, j0 + 1)),
    )
}

/// The outline point along the ray at angle `t` from the centre of `c`, searched within
/// `search` pixels of the circle (module note); `None` when the ray leaves the photo or has too
/// little contrast.
fn ray_edge(photo: &Image<Rgb>, c: &Circle, t: f64, search: f64, eps: f64) -> Option<(f64, f64)> {
    let (ux, uy) = (t.cos(), t.sin());
    let margin = 3.0 + 2.0 * RAY_STEP;
    let s0 = (c.r - search - margin).max(0.0);
    let count = ((c.r + search + margin - s0) / RAY_STEP) as usize + 1;
    let mut profile = Vec::with_capacity(count);
    for k in 0..count {
        let s = s0 + k as f64 * RAY_STEP;
        profile.push(luminance_at(photo, c.cx + s * ux, c.cy + s * uy)?);
    }
    let s_of = |k: usize| s0 + k as f64 * RAY_STEP;
    // Steepest log step inside the search window.
    let mut best = (0usize, 0.0f64);
    for k in 1..count - 1 {
        let s = s_of(k);
        if (s - c.r).abs() > search {
            continue;
        }
        let step = ((profile[k + 1] + eps).ln() - (profile[k - 1] + eps).ln()).abs();
        if step > best.1 {
            best = (k, step);
        }
    }
    // The profile at any radius (linear between samples).
    let at = |s: f64| {
        let x = ((s - s0) / RAY_STEP).clamp(0.0, (count - 1) as f64);
        let k = (x as usize).min(count - 2);
        let t = x - k as f64;
        (1.0 - t) * profile[k] + t * profile[k + 1]
    };
    let steepest = s_of(best.0);
    let (inner, outer) = (at(steepest - LEVEL_OFFSET), at(steepest + LEVEL_OFFSET));
    if (inner - outer).abs() < MIN_RAY_CONTRAST * inner.max(outer) {
        return None;
    }
    let half = 0.5 * (inner + outer);
    let mut edge: Option<f64> = None;
    for k in 0..count - 1 {
        let (a, b) = (profile[k] - half, profile[k + 1] - half);
        let s = s_of(k);
        if (s - steepest).abs() > LEVEL_OFFSET || a * b > 0.0 || a == b {
            continue;
        }
        let x = s + RAY_STEP * a / (a - b);
        if edge.is_none_or(|e| (x - steepest).abs() < (e - steepest).abs()) {
            edge = Some(x);
        }
    }
    let edge = edge?;
    Some((c.cx + edge * ux, c.cy + edge * uy))
}

/// Refines a circle on the full-resolution photo from the outline points along `max(64, pi r)`
/// rays (module note); the input circle back if too few rays find the outline.
fn refine(photo: &Image<Rgb>, c: Circle, search: f64, eps: f64) -> Circle {
    let rays = ((PI * c.r).ceil() as usize).clamp(64, 4096);
    let points: Vec<(f64, f64)> = (0..rays)
        .into_par_iter()
        .filter_map(|k| ray_edge(photo, &c, TAU * k as f64 / rays as f64, search, eps))
        .collect();

    if points.len() < 16 {
        return c;
    }
    robust_fit(&points, 0.25).unwrap_or(c)
}

/// Finds the mirror ball in a photo (module note): coarse gradient-Hough detection, a robust
/// least-squares fit, verification, and sub-pixel refinement at full resolution. Errors with
/// [`CaptureError::Invalid`] when the photo is too small or black, has too few edges, or no
/// circle is supported well enough (the message gives the measured support and contrast).
/// Deterministic. Cost O(W H + N r_max) (module note).
pub fn find_ball(photo: &Image<Rgb>) -> Result<Circle, CaptureError> {
    let (w, h) = (photo.width(), photo.height());
    if w < MIN_SIDE || h < MIN_SIDE {
        return Err(CaptureError::Invalid(format!(
            "no ball found: the photo is {w} x {h} pixels, at least {MIN_SIDE} x {MIN_SIDE} needed"
        )));
    }
    let coarse = Coarse::new(photo);
    if coarse.width < MIN_SIDE || coarse.height < MIN_SIDE {
        return Err(CaptureError::Invalid(format!(
            "no ball found: the photo ({w} x {h}) is too elongated to search"
        )));
    }
    if coarse.mean.is_nan() || coarse.mean <= 0.0 {
        return Err(CaptureError::Invalid(
            "no ball found: the photo is black".into(),
        ));
    }
    let edges = coarse.edges();
    if edges.len() < MIN_EDGE_POINTS {
        return Err(CaptureError::Invalid(format!(
            "no ball found: only {} edge points (log-luminance steps over {EDGE_THRESHOLD} per \
             pixel), at least {MIN_EDGE_POINTS} needed",
            edges.len()
        )));
    }
    let (cw, ch) = (coarse.width, coarse.height);
    let r_max = 0.55 * cw.max(ch) as f64;
    let mut best: Option<(usize, Circle)> = None;
    for centre in centre_peaks(&edges, cw, ch, r_max) {
        for r in radius_candidates(&edges, centre, r_max) {
            let mut c = Circle {
                cx: centre.0,
                cy: centre.1,
                r,
            };
            for band in [5.0, 2.5, 2.5] {
                match refit_outline(&edges, &c, band) {
                    Some(next) => c = next,
                    None => break,
                }
            }
            let n = inliers(&edges, &c, TOLERANCE).len();
            if best.is_none_or(|(m, _)| n > m) {
                best = Some((n, c));
            }
        }
    }
    let Some((_, circle)) = best else {
        return Err(CaptureError::Invalid(format!(
            "no ball found: {} edge points but no circle centre candidate",
            edges.len()
        )));
    };
    let (support, contrast) = verify(&edges, &circle, cw, ch);
    let f = coarse.factor as f64;
    let scaled = Circle {
        cx: circle.cx * f,
        cy: circle.cy * f,
        r: circle.r * f,
    };
    if !(support >= MIN_SUPPORT && contrast >= MIN_CONTRAST) || circle.r < MIN_RADIUS {
        return Err(CaptureError::Invalid(format!(
            "no ball found: the best circle (centre ({:.1}, {:.1}), radius {:.1} px) has radial \
             edges along {:.0} % of its circumference (at least {:.0} % needed), {:.1} times as \
             dense as beside it (at least {MIN_CONTRAST} needed)",
            scaled.cx,
            scaled.cy,
            scaled.r,
            100.0 * support,
            100.0 * MIN_SUPPORT,
            contrast
        )));
    }
    let eps = 1e-3 * coarse.mean;
    let first = refine(photo, scaled, 2.0 * f + 2.0, eps);
    Ok(refine(photo, first, 2.0, eps))
}

/// Bilinear radiance at continuous photo coordinates (edge pixels clamped), 0 outside the photo;
/// negative and non-finite channels are read as 0.
fn radiance_at(photo: &Image<Rgb>, x: f64, y: f64) -> Rgb {
    let (w, h) = (photo.width(), photo.height());
    if !(x >= 0.0 && y >= 0.0 && x <= w as f64 && y <= h as f64) {
        return Rgb::ZERO;
    }
    let (fx, fy) = (
        (x - 0.5).clamp(0.0, (w - 1) as f64),
        (y - 0.5).clamp(0.0, (h - 1) as f64),
    );
    let (i0, j0) = (fx as usize, fy as usize);
    let (i1, j1) = ((i0 + 1).min(w - 1), (j0 + 1).min(h - 1));
    let (tx, ty) = ((fx - i0 as f64) as f32, (fy - j0 as f64) as f32);
    let px = |i: usize, j: usize| {
        photo
            .get(i, j)
            .map(|v| if v.is_finite() && v > 0.0 { v } else { 0.0 })
    };
    let top = px(i0, j0) * (1.0 - tx) + px(i1, j0) * tx;
    let bottom = px(i0, j1) * (1.0 - tx) + px(i1, j1) * tx;
    top * (1.0 - ty) + bottom * ty
}

/// Unwraps a mirror ball to a `width x width / 2` lat-long map with the default
/// [`BallReliability`]; see [`unwrap_ball_with`].
pub fn unwrap_ball(
    photo: &Image<Rgb>,
    circle: Circle,
    width: usize,
) -> Result<Unwrapped, CaptureError> {
    unwrap_ball_with(photo, circle, width, &BallReliability::default())
}

/// Unwraps the mirror ball `circle` of `photo` to a lat-long map `2 s x s` pixels with
/// `s = width / 2`, in the ball's frame (camera on +Z), with the per-texel reliability of
/// `model` (module note). Errors with [`CaptureError::Parameter`] for a width under 2, a circle
/// that is not finite, has a radius under 2 pixels or over the photo's larger side, or a centre
/// outside the photo, or a model out of range. Cost O(r^2 + W H k^2).
pub fn unwrap_ball_with(
    photo: &Image<Rgb>,
    circle: Circle,
    width: usize,
    model: &BallReliability,
) -> Result<Unwrapped, CaptureError> {
    let (pw, ph) = (photo.width() as f64, photo.height() as f64);
    let Circle { cx, cy, r } = circle;
    if width < 2 {
        return Err(CaptureError::Parameter(format!(
            "the lat-long width must be at least 2, got {width}"
        )));
    }
    if !(cx.is_finite() && cy.is_finite() && r >= 2.0 && r <= pw.max(ph)) {
        return Err(CaptureError::Parameter(format!(
            "the ball circle (centre ({cx}, {cy}), radius {r}) needs a radius from 2 to {} pixels",
            pw.max(ph)
        )));
    }
    if !(cx >= 0.0 && cy >= 0.0 && cx <= pw && cy <= ph) {
        return Err(CaptureError::Parameter(format!(
            "the ball's centre ({cx:.1}, {cy:.1}) lies outside the {pw} x {ph} photo"
        )));
    }
    let in_range = |v: f64, hi: f64| v >= 0.0 && v < hi;
    if !(in_range(model.rim_start, 1.0)
        && in_range(model.camera_cone_deg, 180.0)
        && in_range(model.camera_feather_deg, 180.0))
    {
        return Err(CaptureError::Parameter(format!(
            "reliability model out of range: rim start {} (in [0, 1)), camera cone {} and \
             feather {} degrees (in [0, 180))",
            model.rim_start, model.camera_cone_deg, model.camera_feather_deg
        )));
    }
    let side = ((2.0 * r).ceil() as usize).max(2);
    let pixel = 2.0 * r / side as f64;
    let crop = Image::from_fn_par(side, side, |i, j| {
        let x = cx - r + (i as f64 + 0.5) * pixel;
        let y = cy - r + (j as f64 + 0.5) * pixel;
        radiance_at(photo, x, y)
    });
    let (w, h) = Mapping::LatLong.size_for_width(width);
    let probe = resample(
        &crop,
        Mapping::MirrorBall,
        Mapping::LatLong,
        w,
        h,
        glam::Mat3::IDENTITY,
        &|_, _| {},
    )
    .map_err(|e| CaptureError::Parameter(e.to_string()))?;
    let ll = LatLong::new(w, h);
    let texel = PI / h as f64;
    let reliability = Image::from_fn_par(w, h, |i, j| {
        let d = ll.pixel_dir64(i, j);
        let rho2 = ((1.0 - d.z) / 2.0).clamp(0.0, 1.0);
        let rho = rho2.sqrt();
        let rim = 1.0 - smoothstep((rho - model.rim_start) / (1.0 - model.rim_start));
        let sampling = (texel * r * (1.0 - rho2).sqrt() / 2.0).min(1.0);
        let alpha = d.z.clamp(-1.0, 1.0).acos().to_degrees();
        let camera = if model.camera_feather_deg > 0.0 {
            smoothstep((alpha - model.camera_cone_deg) / model.camera_feather_deg)
        } else if alpha >= model.camera_cone_deg {
            1.0
        } else {
            0.0
        };
        let k = (2.0 * (1.0 + d.z)).max(1e-300).sqrt();
        let (x, y) = (cx + r * d.x / k, cy - r * d.y / k);
        let inside = x >= 0.0 && y >= 0.0 && x <= pw && y <= ph;
        if inside {
            (rim * sampling * camera) as f32
        } else {
            0.0
        }
    });
    Ok(Unwrapped { probe, reliability })
}

/// Merges unwrapped views of the same ball taken from different sides into one lat-long probe
/// in the common frame: view k is turned by `world_from_view = Ry(yaw_k)` (degrees, right-hand
/// rule about +Y: its camera stood at `Ry(yaw_k) (+Z)`) and the views are blended by
/// reliability (module note). Errors with [`CaptureError::Invalid`] for no views, views of
/// different sizes or a reliability map that does not match its probe, and with
/// [`CaptureError::Parameter`] for a non-finite yaw. Cost: three `ibl_mapping::rotate` calls per
/// view (none for a yaw that is a multiple of 360 degrees).
pub fn merge_views(views: &[(Unwrapped, f32)]) -> Result<Image<Rgb>, CaptureError> {
    let Some((first, _)) = views.first() else {
        return Err(CaptureError::Invalid(
            "no mirror-ball views to merge".into(),
        ));
    };
    let (w, h) = (first.probe.width(), first.probe.height());
    for (k, (view, yaw)) in views.iter().enumerate() {
        let sizes = [
            (view.probe.width(), view.probe.height()),
            (view.reliability.width(), view.reliability.height()),
        ];
        if sizes.iter().any(|&s| s != (w, h)) {
            return Err(CaptureError::Invalid(format!(
                "view {k}: probe {} x {} and reliability {} x {}, but view 0 is {w} x {h}",
                sizes[0].0, sizes[0].1, sizes[1].0, sizes[1].1
            )));
        }
        if !yaw.is_finite() {
            return Err(CaptureError::Parameter(format!(
                "view {k}: the yaw must be finite, got {yaw}"
            )));
        }
    }
    let n = w * h;
    let mut weighted = vec![[0.0f64; 3]; n];
    let mut weights = vec![0.0f64; n];
    let mut plain = vec![[0.0f64; 3]; n];
    for (view, yaw) in views {
        let premultiplied = Image::from_vec(
            w,
            h,
            view.probe
                .pixels()
                .iter()
                .zip(view.reliability.pixels())
                .map(|(&c, &r)| c * r)
                .collect(),
        )
        .map_err(|e| CaptureError::Invalid(e.to_string()))?;
        let weight = view.reliability.map(|&r| Rgb::splat(r));
        let turn = |img: &Image<Rgb>| -> Result<Image<Rgb>, CaptureError> {
            if yaw.rem_euclid(360.0) == 0.0 {
                return Ok(img.clone());
            }
            let world_from_view = EulerDegrees {
                yaw_deg: *yaw,
                ..Default::default()
            }
            .world_from_probe();
            rotate(img, Mapping::LatLong, world_from_view, &|_, _| {})
                .map_err(|e| CaptureError::Parameter(e.to_string()))
        };
        let premultiplied = turn(&premultiplied)?;
        let weight = turn(&weight)?;
        let radiance = turn(&view.probe)?;
        for k in 0..n {
            let (p, q, c) = (
                premultiplied.pixels()[k],
                weight.pixels()[k],
                radiance.pixels()[k],
            );
            for ch in 0..3 {
                weighted[k][ch] += f64::from(p[ch]);
                plain[k][ch] += f64::from(c[ch]);
            }
            weights[k] += f64::from(q.r);
        }
    }
    let count = views.len() as f64;
    let pixels = (0..n)
        .map(|k| {
            let [r, g, b] = if weights[k] > 1e-6 {
                weighted[k].map(|v| (v / weights[k]).max(0.0) as f32)
            } else {
                plain[k].map(|v| (v / count).max(0.0) as f32)
            };
            Rgb::new(r, g, b)
        })
        .collect();
    Image::from_vec(w, h, pixels).map_err(|e| CaptureError::Invalid(e.to_string()))
}

//! Straight line segments detected in perspective views of the panorama, for the automatic
//! Manhattan-frame proposal ([`crate::manhattan`]).
//!
//! A region-growing detector in the manner of LSD (von Gioi et al. 2010, "LSD: a fast line
//! segment detector with a false detection control"), without its a-contrario validation: on the
//! view's log luminance (HDR edges span decades), smoothed by a 3 x 3 binomial kernel, the
//! gradient `(g_x, g_y)` by central differences and the level-line angle `atan2(g_x, -g_y)`
//! (along the edge, oriented by the gradient's polarity). Pixels above a gradient threshold are
//! visited strongest first; each unvisited one seeds a region that grows over 8-neighbours whose
//! level-line angle is within 22.5 degrees of the region's mean direction. A region becomes a
//! segment when it is long (at least `min_length_px`), thin (width at most a fifth of its length)
//! and dense (at least 60 % of its bounding rectangle), its line fitted by gradient-weighted
//! principal axes and its ends at the extreme projections. Cost: O(pixels) per view.

use glam::DVec3;
use ibl_core::{Image, Rgb};

use crate::view::PerspectiveView;

/// Detector settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineDetectionSettings {
    /// Smallest gradient of the log luminance, per pixel, to start or join a region.
    pub min_gradient: f32,
    /// Shortest segment, view pixels.
    pub min_length_px: f32,
    /// Angle tolerance of region growing, radians.
    pub angle_tolerance_rad: f32,
}

impl Default for LineDetectionSettings {
    fn default() -> Self {
        LineDetectionSettings {
            min_gradient: 0.08,
            min_length_px: 20.0,
            angle_tolerance_rad: 22.5f32.to_radians(),
        }
    }
}

/// A detected segment, view pixels (continuous coordinates).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// One end.
    pub from: [f64; 2],
    /// The other end.
    pub to: [f64; 2],
    /// Pixels in its region.
    pub pixels: u32,
}

/// The segments of one view (`image` is that view, any radiance units).
pub fn detect_segments(image: &Image<Rgb>, settings: &LineDetectionSettings) -> Vec<Segment> {
    let (w, h) = (image.width(), image.height());
    if w < 3 || h < 3 {
        return Vec::new();
    }
    let log: Vec<f32> = image
        .pixels()
        .iter()
        .map(|l| (l.luminance().max(0.0) + 1e-4).ln())
        .collect();
    // 3 x 3 binomial smoothing (1 2 1), edges clamped.
    let at = |v: &[f32], x: i64, y: i64| -> f32 {
        let xc = x.clamp(0, w as i64 - 1) as usize;
        let yc = y.clamp(0, h as i64 - 1) as usize;
        v[yc * w + xc]
    };
    let mut smooth = vec![0.0f32; w * h];
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let mut s = 0.0;
            for (dy, wy) in [(-1, 1.0), (0, 2.0), (1, 1.0)] {
                for (dx, wx) in [(-1, 1.0), (0, 2.0), (1, 1.0)] {
                    s += wx * wy * at(&log, x + dx, y + dy);
                }
            }
            smooth[y as usize * w + x as usize] = s / 16.0;
        }
    }
    let mut magnitude = vec![0.0f32; w * h];
    let mut angle = vec![0.0f32; w * h];
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let gx = 0.5 * (smooth[y * w + x + 1] - smooth[y * w + x - 1]);
            let gy = 0.5 * (smooth[(y + 1) * w + x] - smooth[(y - 1) * w + x]);
            magnitude[y * w + x] = gx.hypot(gy);
            angle[y * w + x] = gx.atan2(-gy);
        }
    }
    let mut order: Vec<usize> = (0..w * h)
        .filter(|&i| magnitude[i] >= settings.min_gradient)
        .collect();
    order.sort_by(|&a, &b| magnitude[b].total_cmp(&magnitude[a]).then(a.cmp(&b)));
    let mut used = vec![false; w * h];
    let mut segments = Vec::new();
    let mut region: Vec<usize> = Vec::new();
    for &seed in &order {
        if used[seed] {
            continue;
        }
        region.clear();
        region.push(seed);
        used[seed] = true;
        let (mut sx, mut sy) = (angle[seed].cos(), angle[seed].sin());
        let mut k = 0;
        while k < region.len() {
            let p = region[k];
            k += 1;
            let (px, py) = ((p % w) as i64, (p / w) as i64);
            let mean = sy.atan2(sx);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (qx, qy) = (px + dx, py + dy);
                    if qx < 1 || qy < 1 || qx >= w as i64 - 1 || qy >= h as i64 - 1 {
                        continue;
                    }
                    let q = qy as usize * w + qx as usize;
                    if used[q] || magnitude[q] < settings.min_gradient {
                        continue;
                    }
                    let mut diff = angle[q] - mean;
                    while diff > std::f32::consts::PI {
                        diff -= std::f32::consts::TAU;
                    }
                    while diff < -std::f32::consts::PI {
                        diff += std::f32::consts::TAU;
                    }
                    if diff.abs() <= settings.angle_tolerance_rad {
                        used[q] = true;
                        region.push(q);
                        sx += angle[q].cos();
                        sy += angle[q].sin();
                    }
                }
            }
        }
        if let Some(s) = fit_segment(&region, &magnitude, w, settings) {
            segments.push(s);
        }
    }
    segments
}

/// Gradient-weighted principal-axis fit of a region; `None` unless long, thin and dense.
fn fit_segment(
    region: &[usize],
    magnitude: &[f32],
    w: usize,
    settings: &LineDetectionSettings,
) -> Option<Segment> {
    if (region.len() as f32) < settings.min_length_px {
        return None;
    }
    let (mut sw, mut cx, mut cy) = (0.0f64, 0.0f64, 0.0f64);
    for &p in region {
        let m = f64::from(magnitude[p]);
        sw += m;
        cx += m * ((p % w) as f64 + 0.5);
        cy += m * ((p / w) as f64 + 0.5);
    }
    let (cx, cy) = (cx / sw, cy / sw);
    let (mut xx, mut yy, mut xy) = (0.0f64, 0.0f64, 0.0f64);
    for &p in region {
        let m = f64::from(magnitude[p]);
        let (dx, dy) = ((p % w) as f64 + 0.5 - cx, (p / w) as f64 + 0.5 - cy);
        xx += m * dx * dx;
        yy += m * dy * dy;
        xy += m * dx * dy;
    }
    let theta = 0.5 * (2.0 * xy).atan2(xx - yy);
    let (ux, uy) = (theta.cos(), theta.sin());
    let (mut lo, mut hi, mut wlo, mut whi) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &p in region {
        let (dx, dy) = ((p % w) as f64 + 0.5 - cx, (p / w) as f64 + 0.5 - cy);
        let along = dx * ux + dy * uy;
        let across = -dx * uy + dy * ux;
        lo = lo.min(along);
        hi = hi.max(along);
        wlo = wlo.min(across);
        whi = whi.max(across);
    }
    let length = hi - lo + 1.0;
    let width = whi - wlo + 1.0;
    let dense = region.len() as f64 >= 0.6 * length * width;
    if length < f64::from(settings.min_length_px) || width > 0.2 * length || !dense {
        return None;
    }
    Some(Segment {
        from: [cx + lo * ux, cy + lo * uy],
        to: [cx + hi * ux, cy + hi * uy],
        pixels: region.len() as u32,
    })
}

/// The views that cover the panorama for detection: eight around the horizon (every 45
/// degrees, 70 degrees vertical field), four tilted 55 degrees up and four 55 degrees down,
/// each `side x side` pixels.
pub fn detection_views(side: u32) -> Vec<PerspectiveView> {
    let mut views = Vec::new();
    for (pitch, count) in [(0.0, 8), (55.0, 4), (-55.0, 4)] {
        for k in 0..count {
            views.push(PerspectiveView {
                yaw_deg: 360.0 * f64::from(k) / f64::from(count)
                    + if pitch == 0.0 { 0.0 } else { 45.0 },
                pitch_deg: pitch,
                roll_deg: 0.0,
                vertical_fov_deg: 70.0,
                width: side,
                height: side,
            });
        }
    }
    views
}

/// The probe-frame end directions of a segment seen in `view`.
pub fn segment_directions(view: &PerspectiveView, s: &Segment) -> (DVec3, DVec3) {
    (
        view.direction(s.from[0], s.from[1]),
        view.direction(s.to[0], s.to[1]),
    )
}

//! Irradiance spheres (the paper's Figure 4): a diffuse unit sphere shaded by the irradiance
//! `E(n)` of the ground truth and of an approximation, and a false-colour map of their error.
//!
//! Each view is an orthographic picture of the unit sphere, `size` x `size` pixels, +Y up. Pixel
//! `(i, j)` has disc coordinates `a = 2 (i + 0.5) / size - 1`, `b = 1 - 2 (j + 0.5) / size`
//! (CONVENTIONS section 3), `r^2 = a^2 + b^2 <= 1`, and shows the normal
//!
//! ```text
//! View::FromPlusZ   n = ( a, b,  sqrt(1 - r^2))   camera on +Z looking along -Z, +X right
//! View::FromMinusZ  n = (-a, b, -sqrt(1 - r^2))   camera on -Z looking along +Z, +X left
//! ```
//!
//! so the first shows the hemisphere of normals facing +Z (lit by what lies behind a viewer who
//! looks forward, the panorama's seam) and the second the normals facing -Z (lit by the
//! panorama's centre). Rim pixels are blended with the background by their covered fraction.
//!
//! Shading: the ground truth is [`RowIrradiance::irradiance_at`] (exact, every probe pixel), the
//! approximation `sum_i I_i max(0, n . w_i)` ([`LightSet::irradiance_at`]). Both are displayed
//! with the same exposure: `x = E / E_max`, with `E_max` the largest ground-truth channel value
//! over both views, then clamped to 1 and sRGB-encoded; an approximation brighter than any
//! ground-truth normal clips to white. The error map shows, per pixel,
//! `100 mean_c |E_c - E_gt,c| / mu_c` (the per-normal term of `mean_err%`, CONVENTIONS section 5;
//! `mu_c` the mean ground truth over the scoring normals) on the viridis scale from 0 to
//! [`SphereFigure::error_range_pct`] (default [`DEFAULT_ERROR_RANGE_PCT`]); larger errors take
//! the top colour. A legend bar beside the map gives the scale.

use ibl_core::glam::DVec3;
use ibl_core::tonemap::linear_to_srgb8;
use ibl_core::{Image, RowIrradiance};
use ibl_light::LightSet;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use rayon::prelude::*;

use crate::colour_scale::viridis;
use crate::plot::{PlotError, TextMode, draw_label, ensure_font, rgb_image};

/// Default side of one sphere view, pixels.
pub const DEFAULT_SPHERE_SIZE: usize = 256;

/// Default top of the error colour scale, per cent of the mean irradiance.
pub const DEFAULT_ERROR_RANGE_PCT: f64 = 10.0;

/// Which hemisphere of normals a view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Camera on +Z looking along -Z (+X right): normals facing +Z.
    FromPlusZ,
    /// Camera on -Z looking along +Z (+X left): normals facing -Z.
    FromMinusZ,
}

impl View {
    /// Both views, in figure order.
    pub const BOTH: [View; 2] = [View::FromPlusZ, View::FromMinusZ];

    /// Row label in the figure.
    fn label(self) -> [&'static str; 2] {
        match self {
            View::FromPlusZ => ["seen from +Z", "(+X right)"],
            View::FromMinusZ => ["seen from -Z", "(+X left)"],
        }
    }
}

/// The normal shown at pixel `(i, j)` of a `size` x `size` view and the fraction of the pixel
/// the sphere covers (`0` outside; rim pixels use the nearest point on the rim).
pub fn view_normal(view: View, size: usize, i: usize, j: usize) -> (DVec3, f64) {
    let s = size.max(1) as f64;
    let a = 2.0 * (i as f64 + 0.5) / s - 1.0;
    let b = 1.0 - 2.0 * (j as f64 + 0.5) / s;
    let r = (a * a + b * b).sqrt();
    // Covered fraction: a linear ramp one pixel wide across the rim.
    let coverage = ((1.0 - r) * s / 2.0 + 0.5).clamp(0.0, 1.0);
    let (a, b) = if r > 1.0 { (a / r, b / r) } else { (a, b) };
    let z = (1.0 - a * a - b * b).max(0.0).sqrt();
    let n = match view {
        View::FromPlusZ => DVec3::new(a, b, z),
        View::FromMinusZ => DVec3::new(-a, b, -z),
    };
    (n.normalize_or_zero(), coverage)
}

/// Irradiance on both views of the sphere: per pixel RGB and covered fraction.
#[derive(Clone, Debug, PartialEq)]
pub struct SphereField {
    size: usize,
    /// `[view][pixel]`: irradiance (0 where uncovered) and coverage.
    values: [Vec<([f64; 3], f64)>; 2],
}

impl SphereField {
    /// Evaluates `irradiance(n)` on every covered pixel of both views (data-parallel).
    pub fn new(size: usize, irradiance: impl Fn(DVec3) -> [f64; 3] + Sync) -> Self {
        let view = |v: View| -> Vec<([f64; 3], f64)> {
            (0..size * size)
                .into_par_iter()
                .with_min_len(512)
                .map(|p| {
                    let (n, cov) = view_normal(v, size, p % size, p / size);
                    if cov > 0.0 {
                        (irradiance(n), cov)
                    } else {
                        ([0.0; 3], 0.0)
                    }
                })
                .collect()
        };
        SphereField {
            size,
            values: View::BOTH.map(view),
        }
    }

    /// The exact irradiance of a probe (build `RowIrradiance::new(probe)` once per probe).
    pub fn ground_truth(probe: &RowIrradiance, size: usize) -> Self {
        Self::new(size, |n| probe.irradiance_at(n))
    }

    /// The irradiance of a light set.
    pub fn of_light_set(set: &LightSet, size: usize) -> Self {
        Self::new(size, |n| set.irradiance_at(n))
    }

    /// Side of one view, pixels.
    pub fn size(&self) -> usize {
        self.size
    }

    /// Largest channel value over every covered pixel of both views.
    fn max_value(&self) -> f64 {
        self.values
            .iter()
            .flatten()
            .filter(|(_, c)| *c > 0.0)
            .flat_map(|(e, _)| e.iter().copied())
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max)
    }
}

/// Settings and labels of a sphere figure.
#[derive(Clone, Debug, PartialEq)]
pub struct SphereFigure {
    /// Title line (e.g. the probe, method and N).
    pub title: String,
    /// Second line (e.g. the method's scores).
    pub subtitle: String,
    /// Column heading of the approximation (e.g. `median-cut, 16 lights`).
    pub approx_label: String,
    /// Top of the error colour scale, per cent of the mean irradiance.
    pub error_range_pct: f64,
}

const BACKGROUND: [u8; 3] = [255, 255, 255];
const MARGIN: usize = 16;
const LABEL_W: usize = 118;
const GAP: usize = 14;
const HEADER_H: usize = 86;
const COLUMN_H: usize = 28;
const BAR_W: usize = 22;
const BAR_AREA_W: usize = 120;

fn blend(c: [u8; 3], bg: [u8; 3], cov: f64) -> [u8; 3] {
    std::array::from_fn(|k| (f64::from(c[k]) * cov + f64::from(bg[k]) * (1.0 - cov)).round() as u8)
}

/// The figure: rows = the two views, columns = ground truth, approximation, error map, with a
/// colour bar for the error. `mu` is the mean ground-truth irradiance per channel on the scoring
/// normals (the report's `mean_irradiance`). Both fields must have the same size.
pub fn figure(
    truth: &SphereField,
    approx: &SphereField,
    mu: [f64; 3],
    labels: &SphereFigure,
) -> Result<Image<[u8; 3]>, PlotError> {
    ensure_font()?;
    let s = truth.size;
    if s == 0 || approx.size != s {
        return Err(PlotError(format!(
            "sphere views differ in size ({} and {})",
            truth.size, approx.size
        )));
    }
    let width = MARGIN + LABEL_W + 3 * s + 2 * GAP + GAP + BAR_AREA_W + MARGIN;
    let height = HEADER_H + COLUMN_H + 2 * s + GAP + MARGIN;
    let mut buf = vec![255u8; width * height * 3];
    let scale = {
        let m = truth.max_value();
        if m > 0.0 { 1.0 / m } else { 1.0 }
    };
    let range = if labels.error_range_pct > 0.0 {
        labels.error_range_pct
    } else {
        DEFAULT_ERROR_RANGE_PCT
    };
    let shade = |e: [f64; 3]| -> [u8; 3] {
        std::array::from_fn(|c| linear_to_srgb8((e[c] * scale).clamp(0.0, 1.0) as f32))
    };
    let channels: Vec<usize> = (0..3).filter(|&c| mu[c] > 0.0).collect();
    let error_colour = |g: [f64; 3], a: [f64; 3]| -> [u8; 3] {
        if channels.is_empty() {
            return viridis(0.0);
        }
        let e: f64 = channels
            .iter()
            .map(|&c| (a[c] - g[c]).abs() / mu[c])
            .sum::<f64>()
            / channels.len() as f64;
        viridis(100.0 * e / range)
    };
    let x0 = MARGIN + LABEL_W;
    let y0 = HEADER_H + COLUMN_H;
    for (v, _) in View::BOTH.iter().enumerate() {
        let top = y0 + v * (s + GAP);
        for p in 0..s * s {
            let (i, j) = (p % s, p / s);
            let (g, cov) = truth.values[v][p];
            if cov <= 0.0 {
                continue;
            }
            let (a, _) = approx.values[v][p];
            let colours = [shade(g), shade(a), error_colour(g, a)];
            for (col, c) in colours.into_iter().enumerate() {
                let x = x0 + col * (s + GAP) + i;
                let o = ((top + j) * width + x) * 3;
                buf[o..o + 3].copy_from_slice(&blend(c, BACKGROUND, cov));
            }
        }
    }
    // Colour bar, top = range, bottom = 0.
    let bar_x = x0 + 3 * s + 2 * GAP + GAP;
    let bar_h = 2 * s + GAP;
    for j in 0..bar_h {
        let t = 1.0 - (j as f64 + 0.5) / bar_h as f64;
        let c = viridis(t);
        for i in 0..BAR_W {
            let o = ((y0 + j) * width + bar_x + i) * 3;
            buf[o..o + 3].copy_from_slice(&c);
        }
    }
    draw_labels(&mut buf, (width, height), labels, s, range)?;
    rgb_image(width, height, &buf)
}

/// Draws the text of a sphere figure over its pixels.
fn draw_labels(
    buf: &mut [u8],
    (width, height): (usize, usize),
    labels: &SphereFigure,
    s: usize,
    range: f64,
) -> Result<(), PlotError> {
    let root = BitMapBackend::with_buffer(buf, (width as u32, height as u32)).into_drawing_area();
    let black = RGBColor(20, 20, 20);
    let grey = RGBColor(80, 80, 80);
    let text = |t: &str, size: f64, c: RGBColor, h: HPos, v: VPos, x: usize, y: usize| {
        draw_label(
            &root,
            TextMode::Glyphs,
            t,
            (size, c),
            (h, v),
            (x as i32, y as i32),
        )
    };
    text(
        &labels.title,
        24.0,
        black,
        HPos::Center,
        VPos::Top,
        width / 2,
        12,
    )?;
    text(
        &labels.subtitle,
        15.0,
        grey,
        HPos::Center,
        VPos::Top,
        width / 2,
        48,
    )?;
    let x0 = MARGIN + LABEL_W;
    let y0 = HEADER_H + COLUMN_H;
    let columns = [
        "ground truth (exact)",
        labels.approx_label.as_str(),
        "error |E - E_gt| / mu",
    ];
    for (col, label) in columns.iter().enumerate() {
        let cx = x0 + col * (s + GAP) + s / 2;
        text(label, 16.0, black, HPos::Center, VPos::Bottom, cx, y0 - 6)?;
    }
    for (v, view) in View::BOTH.iter().enumerate() {
        let cy = y0 + v * (s + GAP) + s / 2;
        let [l1, l2] = view.label();
        text(l1, 15.0, black, HPos::Left, VPos::Bottom, MARGIN, cy)?;
        text(l2, 14.0, grey, HPos::Left, VPos::Top, MARGIN, cy + 4)?;
    }
    let bar_x = x0 + 3 * s + 3 * GAP;
    let bar_h = 2 * s + GAP;
    text(
        "error, %",
        15.0,
        black,
        HPos::Left,
        VPos::Bottom,
        bar_x,
        y0 - 6,
    )?;
    for k in 0..=4 {
        let f = k as f64 / 4.0;
        let y = y0 + ((1.0 - f) * (bar_h - 1) as f64).round() as usize;
        let value = range * f;
        let label = if k == 4 {
            format!(">= {}", trim(value))
        } else {
            trim(value)
        };
        root.draw(&PathElement::new(
            vec![
                ((bar_x + BAR_W) as i32, y as i32),
                ((bar_x + BAR_W + 5) as i32, y as i32),
            ],
            black.stroke_width(1),
        ))
        .map_err(PlotError::drawing)?;
        text(
            &label,
            14.0,
            black,
            HPos::Left,
            VPos::Center,
            bar_x + BAR_W + 9,
            y,
        )?;
    }
    root.present().map_err(PlotError::drawing)
}

/// A scale value without needless decimals (2.5, 5, 10).
fn trim(v: f64) -> String {
    let s = format!("{v:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_show_opposite_hemispheres() {
        let (n, cov) = view_normal(View::FromPlusZ, 101, 50, 50);
        assert!((n - DVec3::Z).length() < 1e-12 && cov == 1.0);
        let (n, _) = view_normal(View::FromMinusZ, 101, 50, 50);
        assert!((n + DVec3::Z).length() < 1e-12);
        // Right edge, middle row: +X from +Z, -X from -Z; top centre: +Y.
        let (n, _) = view_normal(View::FromPlusZ, 101, 100, 50);
        assert!(n.x > 0.99);
        let (n, _) = view_normal(View::FromMinusZ, 101, 100, 50);
        assert!(n.x < -0.99);
        let (n, _) = view_normal(View::FromPlusZ, 101, 50, 0);
        assert!(n.y > 0.99);
        assert_eq!(view_normal(View::FromPlusZ, 101, 0, 0).1, 0.0);
    }

    #[test]
    fn figure_of_a_perfect_approximation_has_no_error_colour() {
        let f = SphereField::new(32, |n| [1.0 + n.y, 1.0, 0.5]);
        let labels = SphereFigure {
            title: "t".into(),
            subtitle: "s".into(),
            approx_label: "a".into(),
            error_range_pct: 5.0,
        };
        let img = figure(&f, &f, [1.0, 1.0, 0.5], &labels).unwrap();
        // Centre of the error panel of the first view.
        let x = MARGIN + LABEL_W + 2 * (32 + GAP) + 16;
        let y = HEADER_H + COLUMN_H + 16;
        assert_eq!(*img.get(x, y), viridis(0.0));
    }
}

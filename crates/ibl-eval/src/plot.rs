//! Error-vs-N charts (the paper's Figure 6): for one probe or the average over probes, the
//! irradiance error of every method against the number of lights N, on log-log axes.
//!
//! Two panels side by side: left `mean_err%`, right `max_err%` (CONVENTIONS section 5: per cent
//! of the channel's mean irradiance, averaged over RGB); x is N, y the error; one colour per
//! method (the same colour for a method in every chart), dots at the measured N, lines joining
//! consecutive measured N; dashed grey lines at 1 % and 5 % (labelled at the left, where the
//! curves are still high), the thresholds of `report.md`.
//! Points that are missing (skipped or failed runs), zero, negative or not finite cannot sit on a
//! log axis and are left out; a line never bridges a missing N.
//!
//! Each chart renders to an SVG string ([`render_svg`]) and to an 8-bit RGB image
//! ([`render_png`], for PNG files) with `plotters`. Text in the bitmap is drawn by `ab_glyph`
//! with DejaVu Sans embedded in the library (`assets/fonts/`, see its `LICENSE.md`), so no system
//! font is needed; the SVG names the generic family `sans-serif` and the viewer's font draws it.
//!
//! Bitmap text is placed glyph by glyph: plotters 0.3.7 draws an `ab_glyph` string with every
//! glyph's ink at its pen position, ignoring the glyph's left side bearing, which spaces narrow
//! letters unevenly ("ri ght"). `FontMetrics` reads the advance widths and bearings from the
//! font's `hhea`, `hmtx` and `cmap` tables, and each glyph is drawn alone at
//! `pen + lsb * scale`, with `scale = size / (ascender - descender)` as `ab_glyph` uses.

use std::fmt;
use std::sync::OnceLock;

use ibl_core::Image;
use ibl_light::Method;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::sweep::{Report, Status};

/// DejaVu Sans (regular), the font of every chart and figure (`assets/fonts/LICENSE.md`).
static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// The family name the embedded font is registered under (and the SVG asks for).
pub(crate) const FONT_FAMILY: &str = "sans-serif";

/// Default chart size in pixels (width, height).
pub const PLOT_SIZE: (u32, u32) = (1280, 560);

/// Why a chart or figure could not be drawn.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlotError(pub String);

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for PlotError {}

impl PlotError {
    /// Always false: a chart that cannot be drawn is an internal failure (font, backend), never
    /// the user's input.
    pub fn is_bad_input(&self) -> bool {
        false
    }

    /// Wraps a drawing error.
    pub(crate) fn drawing(e: impl fmt::Display) -> Self {
        PlotError(format!("drawing failed: {e}"))
    }
}

/// Registers the embedded font with plotters once per process.
pub(crate) fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, FONT).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError("the embedded font could not be loaded".into()))
    }
}

/// A text style in the embedded font.
fn text_style(size: f64, color: RGBColor, h: HPos, v: VPos) -> TextStyle<'static> {
    let mut style = TextStyle::from((FONT_FAMILY, size).into_font()).pos(Pos::new(h, v));
    style.color = color.to_backend_color();
    style
}

fn be_u16(d: &[u8], o: usize) -> Option<u16> {
    Some(u16::from_be_bytes([*d.get(o)?, *d.get(o + 1)?]))
}

fn be_i16(d: &[u8], o: usize) -> Option<i16> {
    be_u16(d, o).map(|v| v as i16)
}

fn be_u32(d: &[u8], o: usize) -> Option<u32> {
    Some(u32::from_be_bytes([
        *d.get(o)?,
        *d.get(o + 1)?,
        *d.get(o + 2)?,
        *d.get(o + 3)?,
    ]))
}

/// Horizontal metrics of a TrueType font: what glyph-by-glyph placement needs.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct FontMetrics {
    /// `ascender - descender` from `hhea`, font units (the `ab_glyph` pixel-size unit).
    height: f64,
    /// `(advance width, left side bearing)` per glyph id, font units.
    h_metrics: Vec<(u16, i16)>,
    /// Basic Multilingual Plane character to glyph id (cmap format 4 segments:
    /// `(start, end, id_delta, id_range_offset, offset of that field)`).
    segments: Vec<(u16, u16, i16, u16, usize)>,
    /// The font file, to resolve `id_range_offset` into its glyph id array.
    font: &'static [u8],
}

impl FontMetrics {
    /// Parses the `hhea`, `hmtx` and `cmap` (format 4) tables; `None` if any is missing.
    fn parse(font: &'static [u8]) -> Option<Self> {
        let tables = usize::from(be_u16(font, 4)?);
        let find = |tag: &[u8; 4]| -> Option<usize> {
            (0..tables).find_map(|i| {
                let rec = 12 + 16 * i;
                (font.get(rec..rec + 4)? == tag).then_some(be_u32(font, rec + 8)? as usize)
            })
        };
        let hhea = find(b"hhea")?;
        let height = f64::from(be_i16(font, hhea + 4)?) - f64::from(be_i16(font, hhea + 6)?);
        let long = usize::from(be_u16(font, hhea + 34)?);
        let hmtx = find(b"hmtx")?;
        let h_metrics = (0..long)
            .map(|g| Some((be_u16(font, hmtx + 4 * g)?, be_i16(font, hmtx + 4 * g + 2)?)))
            .collect::<Option<Vec<_>>>()?;
        let cmap = find(b"cmap")?;
        let subtables = usize::from(be_u16(font, cmap + 2)?);
        let sub = (0..subtables).find_map(|i| {
            let rec = cmap + 4 + 8 * i;
            let (platform, encoding) = (be_u16(font, rec)?, be_u16(font, rec + 2)?);
            let off = cmap + be_u32(font, rec + 4)? as usize;
            let unicode = (platform == 3 && encoding == 1) || platform == 0;
            (unicode && be_u16(font, off)? == 4).then_some(off)
        })?;
        let seg_count = usize::from(be_u16(font, sub + 6)? / 2);
        let ends = sub + 14;
        let starts = ends + 2 * seg_count + 2;
        let deltas = starts + 2 * seg_count;
        let ranges = deltas + 2 * seg_count;
        let segments = (0..seg_count)
            .map(|k| {
                Some((
                    be_u16(font, starts + 2 * k)?,
                    be_u16(font, ends + 2 * k)?,
                    be_i16(font, deltas + 2 * k)?,
                    be_u16(font, ranges + 2 * k)?,
                    ranges + 2 * k,
                ))
            })
            .collect::<Option<Vec<_>>>()?;
        (height > 0.0 && !h_metrics.is_empty()).then_some(FontMetrics {
            height,
            h_metrics,
            segments,
            font,
        })
    }

    /// Glyph id of a character (0, the missing glyph, when the font has none).
    fn glyph(&self, c: char) -> usize {
        let Ok(c) = u16::try_from(u32::from(c)) else {
            return 0;
        };
        let Some(&(start, _, delta, range, at)) =
            self.segments.iter().find(|s| s.0 <= c && c <= s.1)
        else {
            return 0;
        };
        if range == 0 {
            return usize::from(c.wrapping_add(delta as u16));
        }
        let o = at + usize::from(range) + 2 * usize::from(c - start);
        match be_u16(self.font, o) {
            Some(0) | None => 0,
            Some(g) => usize::from(g.wrapping_add(delta as u16)),
        }
    }

    /// `(advance, left side bearing)` of a character, font units.
    fn h_metrics(&self, c: char) -> (f64, f64) {
        let g = self.glyph(c);
        let advance = self.h_metrics[g.min(self.h_metrics.len() - 1)].0;
        let lsb = self.h_metrics.get(g).map_or(0, |m| m.1);
        (f64::from(advance), f64::from(lsb))
    }

    /// Width of a string at pixel size `size` (sum of advances, no kerning).
    pub(crate) fn width(&self, text: &str, size: f64) -> f64 {
        text.chars().map(|c| self.h_metrics(c).0).sum::<f64>() * size / self.height
    }
}

/// The metrics of the embedded font (parsed once).
fn font_metrics() -> Option<&'static FontMetrics> {
    static METRICS: OnceLock<Option<FontMetrics>> = OnceLock::new();
    METRICS.get_or_init(|| FontMetrics::parse(FONT)).as_ref()
}

/// How text reaches a backend.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TextMode {
    /// One text element per string (SVG: the viewer lays the text out).
    Strings,
    /// One glyph at a time at its metric position (bitmaps; see the module doc).
    Glyphs,
}

/// Draws `text` in the embedded font at `pos` (area pixels) anchored by `(h, v)`.
pub(crate) fn draw_label<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    mode: TextMode,
    text: &str,
    (size, color): (f64, RGBColor),
    (h, v): (HPos, VPos),
    pos: (i32, i32),
) -> Result<(), PlotError> {
    let metrics = match mode {
        TextMode::Strings => None,
        TextMode::Glyphs => font_metrics(),
    };
    let Some(m) = metrics else {
        return area
            .draw_text(text, &text_style(size, color, h, v), pos)
            .map_err(PlotError::drawing);
    };
    let scale = size / m.height;
    let width = m.width(text, size);
    let mut pen = f64::from(pos.0)
        - match h {
            HPos::Left => 0.0,
            HPos::Center => width / 2.0,
            HPos::Right => width,
        };
    let style = text_style(size, color, HPos::Left, v);
    let mut glyph = [0u8; 4];
    for c in text.chars() {
        let (advance, lsb) = m.h_metrics(c);
        if !c.is_whitespace() {
            let x = (pen + lsb * scale).round() as i32;
            area.draw_text(c.encode_utf8(&mut glyph), &style, (x, pos.1))
                .map_err(PlotError::drawing)?;
        }
        pen += advance * scale;
    }
    Ok(())
}

/// Okabe-Ito colours (distinguishable with colour-vision deficiencies), one per method in
/// [`Method::ALL`] order, then for unknown names.
const PALETTE: [RGBColor; 7] = [
    RGBColor(213, 94, 0),    // vermillion
    RGBColor(0, 114, 178),   // blue
    RGBColor(0, 158, 115),   // bluish green
    RGBColor(204, 121, 167), // reddish purple
    RGBColor(230, 159, 0),   // orange
    RGBColor(86, 180, 233),  // sky blue
    RGBColor(0, 0, 0),       // black
];

/// The colour of a method: fixed by its place in [`Method::ALL`], so it is the same in every
/// chart; names that are not methods take the remaining colours by `index`.
pub fn method_color(method: &str, index: usize) -> RGBColor {
    let known = Method::ALL.iter().position(|m| m.name() == method);
    let slot = known.unwrap_or(Method::ALL.len() + index % (PALETTE.len() - Method::ALL.len()));
    PALETTE[slot % PALETTE.len()]
}

/// One measured point of a curve; a missing error leaves a gap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvePoint {
    /// Light count N.
    pub n: usize,
    /// `mean_err%` at N, if it ran.
    pub mean_err_pct: Option<f64>,
    /// `max_err%` at N, if it ran.
    pub max_err_pct: Option<f64>,
}

/// The errors of one method against N.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Method name.
    pub method: String,
    /// One point per swept N, in increasing N.
    pub points: Vec<CurvePoint>,
}

/// A chart: a title, a subtitle and one curve per method.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorChart {
    /// Probe name, or "average over K probes".
    pub title: String,
    /// What is plotted (normals, metric scale).
    pub subtitle: String,
    /// One curve per method.
    pub curves: Vec<Curve>,
    /// Captions of the left panel (the points' `mean_err_pct`) and the right one (`max_err_pct`).
    pub panel_captions: [String; 2],
    /// Values marked by dashed lines, and the unit written after them (`" %"`).
    pub thresholds: (Vec<f64>, String),
}

impl ErrorChart {
    /// The panel captions and thresholds of the irradiance-error charts.
    fn irradiance_axes() -> ([String; 2], (Vec<f64>, String)) {
        (
            [
                "mean error (mean_err), % of mean irradiance".to_string(),
                "max error (max_err), % of mean irradiance".to_string(),
            ],
            (crate::report::THRESHOLDS_PCT.to_vec(), " %".to_string()),
        )
    }
}

/// Which panel a value belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Panel {
    Mean,
    Max,
}

impl Panel {
    fn value(self, p: &CurvePoint) -> Option<f64> {
        let v = match self {
            Panel::Mean => p.mean_err_pct,
            Panel::Max => p.max_err_pct,
        }?;
        (v.is_finite() && v > 0.0).then_some(v)
    }

    fn caption(self, chart: &ErrorChart) -> &str {
        match self {
            Panel::Mean => &chart.panel_captions[0],
            Panel::Max => &chart.panel_captions[1],
        }
    }
}

fn sorted_counts(report: &Report) -> Vec<usize> {
    let mut counts = report.counts.clone();
    counts.sort_unstable();
    counts.dedup();
    counts
}

fn subtitle(report: &Report) -> String {
    format!(
        "irradiance error vs number of lights N, {} Fibonacci normals; per cent of the mean irradiance, averaged over RGB",
        report.normals
    )
}

/// One curve per method of the report, over its sorted counts, with the (mean, max) errors that
/// `errors(method, n)` finds (`None` where there is no result).
fn curves(
    report: &Report,
    errors: impl Fn(&str, usize) -> (Option<f64>, Option<f64>),
) -> Vec<Curve> {
    let counts = sorted_counts(report);
    report
        .methods
        .iter()
        .map(|m| Curve {
            method: m.clone(),
            points: counts
                .iter()
                .map(|&n| {
                    let (mean_err_pct, max_err_pct) = errors(m, n);
                    CurvePoint {
                        n,
                        mean_err_pct,
                        max_err_pct,
                    }
                })
                .collect(),
        })
        .collect()
}

impl ErrorChart {
    /// The chart of probe `index` of a report (`None` if there is no such probe).
    pub fn for_probe(report: &Report, index: usize) -> Option<Self> {
        let probe = report.probes.get(index)?;
        let curves = curves(report, |m, n| {
            probe
                .rows
                .iter()
                .find(|r| r.method == m && r.n == n && r.status == Status::Ok)
                .map_or((None, None), |r| (r.mean_err_pct, r.max_err_pct))
        });
        let (panel_captions, thresholds) = Self::irradiance_axes();
        Some(ErrorChart {
            title: probe.name.clone(),
            subtitle: subtitle(report),
            curves,
            panel_captions,
            thresholds,
        })
    }

    /// The chart of the averages over every probe of a report.
    pub fn average(report: &Report) -> Self {
        let k = report.probes.len();
        let curves = curves(report, |m, n| {
            report
                .averages
                .iter()
                .find(|a| a.method == m && a.n == n)
                .map_or((None, None), |a| {
                    (Some(a.mean_err_pct), Some(a.max_err_pct))
                })
        });
        let (panel_captions, thresholds) = Self::irradiance_axes();
        ErrorChart {
            title: format!("average over {k} probe{}", if k == 1 { "" } else { "s" }),
            subtitle: subtitle(report),
            curves,
            panel_captions,
            thresholds,
        }
    }
}

/// Tick values on a log axis from `lo` to `hi` (both > 0): 1-2-3-5-7 per decade over at most one
/// decade, 1-2-5 up to 4.2 decades, powers of ten beyond.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let decades = (hi / lo).log10();
    let mantissas: &[f64] = if decades <= 1.0 {
        &[1.0, 2.0, 3.0, 5.0, 7.0]
    } else if decades <= 4.2 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let (e0, e1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let mut ticks = Vec::new();
    for e in e0..=e1 {
        for m in mantissas {
            let v = m * 10f64.powi(e);
            if v >= lo && v <= hi {
                ticks.push(v);
            }
        }
    }
    ticks
}

/// A tick label: as many decimals as the value needs (0.05, 0.5, 5, 50).
fn tick_label(v: f64) -> String {
    let decimals = (-v.log10().floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// The value range of a panel padded by a factor 1.6 each way (`None` when it has no point).
fn value_range(chart: &ErrorChart, panel: Panel) -> Option<(f64, f64)> {
    let values = chart
        .curves
        .iter()
        .flat_map(|c| c.points.iter().filter_map(|p| panel.value(p)));
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    (hi > 0.0).then_some((lo / 1.6, hi * 1.6))
}

/// The N range padded by a factor 1.35 each way.
fn count_range(chart: &ErrorChart) -> (f64, f64) {
    let ns = chart
        .curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.n));
    let (lo, hi) = ns.fold((usize::MAX, 0usize), |(lo, hi), n| (lo.min(n), hi.max(n)));
    if hi == 0 {
        (0.5, 2.0)
    } else {
        (lo.max(1) as f64 / 1.35, hi as f64 * 1.35)
    }
}

/// Runs of consecutive points with a value (so lines never bridge a gap).
fn segments(curve: &Curve, panel: Panel) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for p in &curve.points {
        match panel.value(p) {
            Some(v) => {
                if let Some(last) = out.last_mut() {
                    last.push((p.n as f64, v));
                }
            }
            None => out.push(Vec::new()),
        }
    }
    out.retain(|s| !s.is_empty());
    out
}

const INK: RGBColor = RGBColor(20, 20, 20);
const GREY: RGBColor = RGBColor(100, 100, 100);

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    mode: TextMode,
    chart: &ErrorChart,
    panel: Panel,
) -> Result<(), PlotError> {
    let (x0, x1) = count_range(chart);
    let range = value_range(chart, panel);
    let (y0, y1) = range.unwrap_or((0.1, 100.0));
    let mut x_ticks: Vec<f64> = chart
        .curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.n as f64))
        .collect();
    x_ticks.sort_by(f64::total_cmp);
    x_ticks.dedup();
    let y_ticks = log_ticks(y0, y1);
    let w = area.dim_in_pixel().0 as i32;
    draw_label(
        area,
        mode,
        panel.caption(chart),
        (19.0, INK),
        (HPos::Center, VPos::Top),
        (w / 2, 4),
    )?;
    let mut cc = ChartBuilder::on(area)
        .margin(14)
        .margin_top(40)
        .x_label_area_size(64)
        .y_label_area_size(50)
        .build_cartesian_2d(
            (x0..x1).log_scale().with_key_points(x_ticks.clone()),
            (y0..y1).log_scale().with_key_points(y_ticks.clone()),
        )
        .map_err(PlotError::drawing)?;
    // Tick labels are drawn below with `draw_label`, so the mesh draws empty ones.
    cc.configure_mesh()
        .x_label_formatter(&|_| String::new())
        .y_label_formatter(&|_| String::new())
        .bold_line_style(RGBColor(0, 0, 0).mix(0.12))
        .light_line_style(TRANSPARENT)
        .draw()
        .map_err(PlotError::drawing)?;
    let base = area.get_base_pixel();
    let at = |x: f64, y: f64| {
        let (px, py) = cc.backend_coord(&(x, y));
        (px - base.0, py - base.1)
    };
    for &x in &x_ticks {
        let (px, py) = at(x, y0);
        let label = format!("{}", x.round());
        draw_label(
            area,
            mode,
            &label,
            (15.0, INK),
            (HPos::Center, VPos::Top),
            (px, py + 8),
        )?;
    }
    for &y in &y_ticks {
        let (px, py) = at(x0, y);
        let label = tick_label(y);
        draw_label(
            area,
            mode,
            &label,
            (15.0, INK),
            (HPos::Right, VPos::Center),
            (px - 8, py),
        )?;
    }
    let (left, bottom) = at(x0, y0);
    let (right, top) = at(x1, y1);
    let thresholds: Vec<(f64, i32)> = chart
        .thresholds
        .0
        .iter()
        .copied()
        .filter(|t| *t > y0 && *t < y1)
        .map(|t| (t, at(x1, t).1))
        .collect();
    draw_label(
        area,
        mode,
        "number of lights N",
        (16.0, INK),
        (HPos::Center, VPos::Top),
        ((left + right) / 2, bottom + 34),
    )?;
    for (t, py) in thresholds {
        cc.draw_series(DashedLineSeries::new(
            vec![(x0, t), (x1, t)],
            7,
            5,
            GREY.stroke_width(1),
        ))
        .map_err(PlotError::drawing)?;
        let label = format!("{t}{}", chart.thresholds.1);
        draw_label(
            area,
            mode,
            &label,
            (14.0, GREY),
            (HPos::Left, VPos::Bottom),
            (left + 4, py - 2),
        )?;
    }
    for (i, curve) in chart.curves.iter().enumerate() {
        let color = method_color(&curve.method, i);
        for seg in segments(curve, panel) {
            cc.draw_series(LineSeries::new(seg.clone(), color.stroke_width(2)))
                .map_err(PlotError::drawing)?;
            cc.draw_series(seg.into_iter().map(|p| Circle::new(p, 4, color.filled())))
                .map_err(PlotError::drawing)?;
        }
    }
    if range.is_none() {
        draw_label(
            area,
            mode,
            "no data",
            (20.0, GREY),
            (HPos::Center, VPos::Center),
            ((left + right) / 2, (top + bottom) / 2),
        )?;
    }
    Ok(())
}

fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    mode: TextMode,
    chart: &ErrorChart,
) -> Result<(), PlotError> {
    let mut y = 70;
    draw_label(
        area,
        mode,
        "method",
        (17.0, INK),
        (HPos::Left, VPos::Center),
        (8, y),
    )?;
    for (i, curve) in chart.curves.iter().enumerate() {
        y += 28;
        let color = method_color(&curve.method, i);
        area.draw(&PathElement::new(
            vec![(8, y), (44, y)],
            color.stroke_width(2),
        ))
        .map_err(PlotError::drawing)?;
        area.draw(&Circle::new((26, y), 4, color.filled()))
            .map_err(PlotError::drawing)?;
        draw_label(
            area,
            mode,
            &curve.method,
            (15.0, INK),
            (HPos::Left, VPos::Center),
            (52, y),
        )?;
    }
    y += 44;
    let dashed = chart
        .thresholds
        .0
        .iter()
        .map(|t| format!("{t}{}", chart.thresholds.1))
        .collect::<Vec<_>>()
        .join(" and ");
    let dashed = if dashed.is_empty() {
        String::new()
    } else {
        format!("dashed: {dashed}")
    };
    let notes = [
        "dots: measured N",
        dashed.as_str(),
        "missing dot: skipped",
        "or failed (report.md)",
    ];
    for note in notes.into_iter().filter(|n| !n.is_empty()) {
        draw_label(
            area,
            mode,
            note,
            (14.0, GREY),
            (HPos::Left, VPos::Center),
            (8, y),
        )?;
        y += 22;
    }
    Ok(())
}

fn draw_chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    mode: TextMode,
    chart: &ErrorChart,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(PlotError::drawing)?;
    let (w, _) = root.dim_in_pixel();
    let (header, body) = root.split_vertically(76);
    let centre = w as i32 / 2;
    draw_label(
        &header,
        mode,
        &chart.title,
        (26.0, INK),
        (HPos::Center, VPos::Top),
        (centre, 10),
    )?;
    draw_label(
        &header,
        mode,
        &chart.subtitle,
        (15.0, GREY),
        (HPos::Center, VPos::Top),
        (centre, 46),
    )?;
    let legend_width = 230.min(w / 4);
    let (panels, legend) = body.split_horizontally(w - legend_width);
    let halves = panels.split_evenly((1, 2));
    for (area, panel) in halves.iter().zip([Panel::Mean, Panel::Max]) {
        draw_panel(area, mode, chart, panel)?;
    }
    draw_legend(&legend, mode, chart)?;
    root.present().map_err(PlotError::drawing)
}

/// The chart as an SVG document of `size` pixels (width, height).
pub fn render_svg(chart: &ErrorChart, size: (u32, u32)) -> Result<String, PlotError> {
    ensure_font()?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw_chart(&root, TextMode::Strings, chart)?;
    }
    Ok(svg)
}

/// The chart as an 8-bit RGB image of `size` pixels (width, height), ready for PNG encoding.
pub fn render_png(chart: &ErrorChart, size: (u32, u32)) -> Result<Image<[u8; 3]>, PlotError> {
    ensure_font()?;
    let (w, h) = (size.0 as usize, size.1 as usize);
    if w == 0 || h == 0 {
        return Err(PlotError(format!("cannot draw a {w} x {h} chart")));
    }
    let mut buf = vec![255u8; w * h * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        draw_chart(&root, TextMode::Glyphs, chart)?;
    }
    rgb_image(w, h, &buf)
}

/// An RGB byte buffer (rows of `3 w` bytes) as an image.
pub(crate) fn rgb_image(w: usize, h: usize, buf: &[u8]) -> Result<Image<[u8; 3]>, PlotError> {
    let pixels: Vec<[u8; 3]> = buf.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    Image::from_vec(w, h, pixels).map_err(|e| PlotError(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_cover_the_range() {
        assert_eq!(
            log_ticks(0.5, 60.0),
            vec![0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0]
        );
        assert_eq!(
            log_ticks(0.001, 100.0),
            vec![0.001, 0.01, 0.1, 1.0, 10.0, 100.0]
        );
        assert_eq!(tick_label(0.05), "0.05");
        assert_eq!(tick_label(50.0), "50");
    }

    #[test]
    fn gaps_split_lines() {
        let p = |n, v: Option<f64>| CurvePoint {
            n,
            mean_err_pct: v,
            max_err_pct: v,
        };
        let c = Curve {
            method: "x".into(),
            points: vec![
                p(1, Some(10.0)),
                p(2, Some(5.0)),
                p(4, None),
                p(8, Some(0.0)),
                p(16, Some(f64::NAN)),
                p(32, Some(1.0)),
            ],
        };
        assert_eq!(
            segments(&c, Panel::Mean),
            vec![vec![(1.0, 10.0), (2.0, 5.0)], vec![(32.0, 1.0)]]
        );
    }

    #[test]
    fn glyph_layout_matches_ab_glyph() {
        ensure_font().unwrap();
        let m = font_metrics().unwrap();
        assert_ne!(m.glyph('a'), 0);
        assert_eq!(m.glyph('\u{10FFFF}'), 0);
        // plotters' own layout (ab_glyph advances, plus kerning) of strings without kerned pairs.
        for text in [
            "number of lights N",
            "mean error 0.125 %",
            "irradiance-optimization",
        ] {
            let style = text_style(15.0, RGBColor(0, 0, 0), HPos::Left, VPos::Top);
            let ((x0, _), (x1, _)) = style.font.layout_box(text).unwrap();
            let ours = m.width(text, 15.0);
            assert!(
                (ours - f64::from(x1 - x0)).abs() <= 1.0,
                "{text}: {ours} vs {}",
                x1 - x0
            );
        }
    }

    #[test]
    fn methods_keep_their_colour() {
        assert_eq!(method_color("median-cut", 3), PALETTE[0]);
        assert_ne!(method_color("median-cut", 0), method_color("lightgen", 0));
    }
}

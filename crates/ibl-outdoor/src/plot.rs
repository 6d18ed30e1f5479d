//! The estimates over a sequence as an SVG chart: `P_d` (top) and `P_a` (bottom) against the
//! local time of day, one line per channel (red, green, blue) for the estimate and dots for the
//! truth when it is known (the synthetic day), the weather written under the time axis.
//!
//! Drawn with `plotters`' SVG backend; text is emitted as SVG text in the generic `sans-serif`
//! family, with DejaVu Sans (`assets/fonts/`, Bitstream Vera licence) registered for the
//! layout's text measurements, so no system font is needed.

use std::sync::OnceLock;

use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::OutdoorError;

/// DejaVu Sans (regular), embedded (`assets/fonts/LICENSE.md`).
static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// One point in time of the chart.
#[derive(Clone, Debug, PartialEq)]
pub struct SeriesPoint {
    /// Local time, hours (e.g. 13.5 for 13:30).
    pub hour: f64,
    /// Estimated `P_d`, RGB.
    pub sun: [f32; 3],
    /// Estimated `P_a`, RGB.
    pub sky: [f32; 3],
    /// True `P_d` and `P_a`, when known.
    pub truth: Option<([f32; 3], [f32; 3])>,
    /// A short label (the weather), drawn under the axis when it changes.
    pub label: String,
}

fn ensure_font() -> Result<(), OutdoorError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_ok()
    });
    ok.then_some(())
        .ok_or_else(|| OutdoorError::Numerical("the embedded font could not be loaded".into()))
}

fn drawing(e: impl std::fmt::Display) -> OutdoorError {
    OutdoorError::Numerical(format!("drawing the chart: {e}"))
}

const CHANNELS: [(&str, RGBColor); 3] = [
    ("R", RGBColor(220, 40, 40)),
    ("G", RGBColor(30, 150, 40)),
    ("B", RGBColor(40, 70, 220)),
];

/// The chart of `points` (in time order), `size` in pixels, as an SVG document.
pub fn estimates_svg(
    points: &[SeriesPoint],
    title: &str,
    size: (u32, u32),
) -> Result<String, OutdoorError> {
    if points.is_empty() {
        return Err(OutdoorError::Parameter("no points to plot".into()));
    }
    ensure_font()?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(drawing)?;
        let root = root.titled(title, ("sans-serif", 22)).map_err(drawing)?;
        let (top, bottom) = root.split_vertically(size.1 as i32 / 2 - 10);
        let (h0, h1) = points.iter().fold((f64::MAX, f64::MIN), |(a, b), p| {
            (a.min(p.hour), b.max(p.hour))
        });
        let span = (h1 - h0).max(0.5);
        let x_range = (h0 - 0.03 * span)..(h1 + 0.03 * span);
        for (panel, name, pick) in [(&top, "P_d (sun)", 0usize), (&bottom, "P_a (sky)", 1usize)] {
            let value = |p: &SeriesPoint, c: usize| -> (f32, Option<f32>) {
                if pick == 0 {
                    (p.sun[c], p.truth.map(|t| t.0[c]))
                } else {
                    (p.sky[c], p.truth.map(|t| t.1[c]))
                }
            };
            let y_max = points
                .iter()
                .flat_map(|p| {
                    (0..3).flat_map(move |c| {
                        let (e, t) = value(p, c);
                        [e, t.unwrap_or(0.0)]
                    })
                })
                .filter(|v| v.is_finite())
                .fold(0.0f32, f32::max)
                .max(1e-6) as f64
                * 1.1;
            let mut chart = ChartBuilder::on(panel)
                .margin(12)
                .x_label_area_size(if pick == 1 { 48 } else { 28 })
                .y_label_area_size(64)
                .caption(name, ("sans-serif", 18))
                .build_cartesian_2d(x_range.clone(), 0.0..y_max)
                .map_err(drawing)?;
            chart
                .configure_mesh()
                .x_desc(if pick == 1 { "local time (hours)" } else { "" })
                .y_desc("radiance")
                .x_label_formatter(&|h| {
                    format!(
                        "{:02}:{:02}",
                        h.floor() as i32,
                        ((h.fract()) * 60.0).round() as i32
                    )
                })
                .draw()
                .map_err(drawing)?;
            for (c, (label, color)) in CHANNELS.iter().enumerate() {
                chart
                    .draw_series(LineSeries::new(
                        points.iter().map(|p| (p.hour, f64::from(value(p, c).0))),
                        color.stroke_width(2),
                    ))
                    .map_err(drawing)?
                    .label(format!("{label} estimate"))
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
                    });
                chart
                    .draw_series(points.iter().filter_map(|p| {
                        value(p, c)
                            .1
                            .map(|t| Circle::new((p.hour, f64::from(t)), 4, color.stroke_width(1)))
                    }))
                    .map_err(drawing)?;
            }
            if pick == 0 {
                let mut last = String::new();
                for p in points {
                    if p.label != last {
                        chart
                            .draw_series(std::iter::once(Text::new(
                                p.label.clone(),
                                (p.hour, y_max * 0.95),
                                ("sans-serif", 13).into_font().color(&BLACK.mix(0.7)),
                            )))
                            .map_err(drawing)?;
                        last = p.label.clone();
                    }
                }
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperRight)
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .draw()
                    .map_err(drawing)?;
            }
        }
        root.present().map_err(drawing)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_a_day() {
        let points: Vec<SeriesPoint> = (0..5)
            .map(|k| SeriesPoint {
                hour: 9.0 + k as f64,
                sun: [1.0 + k as f32 * 0.1; 3],
                sky: [0.2; 3],
                truth: Some(([1.0; 3], [0.21; 3])),
                label: if k < 3 {
                    "clear".into()
                } else {
                    "overcast".into()
                },
            })
            .collect();
        let svg = estimates_svg(&points, "test day", (900, 600)).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("overcast") && svg.contains("P_d"));
        assert!(estimates_svg(&[], "empty", (900, 600)).is_err());
    }
}

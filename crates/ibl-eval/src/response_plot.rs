//! The chart of a camera response curve (Debevec & Malik 1997, their Figure 2): for each colour
//! channel, the log relative exposure `g(z) = ln E dt` against the pixel code `z`, as SVG and as
//! an 8-bit image. Curves are given as plain tables so this crate needs no capture types.

use ibl_core::Image;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use crate::plot::{PlotError, TextMode, draw_label, ensure_font};

/// Size of the response chart, pixels.
pub const RESPONSE_PLOT_SIZE: (u32, u32) = (720, 480);

const CHANNELS: [(&str, RGBColor); 3] = [
    ("R", RGBColor(213, 40, 40)),
    ("G", RGBColor(30, 150, 60)),
    ("B", RGBColor(40, 80, 210)),
];

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    mode: TextMode,
    curves: [&[f32]; 3],
    title: &str,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(PlotError::drawing)?;
    let levels = curves.iter().map(|c| c.len()).max().unwrap_or(0).max(2);
    let finite = curves
        .iter()
        .flat_map(|c| c.iter())
        .filter(|v| v.is_finite());
    let (lo, hi) = finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
        (lo.min(v), hi.max(v))
    });
    let (lo, hi) = if lo < hi {
        (f64::from(lo) - 0.2, f64::from(hi) + 0.2)
    } else {
        (-1.0, 1.0)
    };
    let (w, _) = root.dim_in_pixel();
    draw_label(
        root,
        mode,
        title,
        (20.0, BLACK),
        (HPos::Center, VPos::Top),
        (w as i32 / 2, 8),
    )?;
    let mut chart = ChartBuilder::on(root)
        .margin(16)
        .margin_top(44)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(0.0..(levels - 1) as f64, lo..hi)
        .map_err(PlotError::drawing)?;
    chart
        .configure_mesh()
        .x_desc("pixel code z")
        .y_desc("g(z) = ln(relative exposure)")
        .draw()
        .map_err(PlotError::drawing)?;
    for (curve, (name, color)) in curves.iter().zip(CHANNELS) {
        chart
            .draw_series(LineSeries::new(
                curve
                    .iter()
                    .enumerate()
                    .filter(|(_, v)| v.is_finite())
                    .map(|(z, &v)| (z as f64, f64::from(v))),
                color.stroke_width(2),
            ))
            .map_err(PlotError::drawing)?
            .label(name)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(PlotError::drawing)?;
    root.present().map_err(PlotError::drawing)
}

/// The chart as SVG: `curves[c][z] = g(z)` of channel c (R, G, B).
pub fn response_svg(curves: [&[f32]; 3], title: &str) -> Result<String, PlotError> {
    ensure_font()?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, RESPONSE_PLOT_SIZE).into_drawing_area();
        draw(&root, TextMode::Strings, curves, title)?;
    }
    Ok(svg)
}

/// The chart as an 8-bit RGB image.
pub fn response_png(curves: [&[f32]; 3], title: &str) -> Result<Image<[u8; 3]>, PlotError> {
    ensure_font()?;
    let (w, h) = (RESPONSE_PLOT_SIZE.0 as usize, RESPONSE_PLOT_SIZE.1 as usize);
    let mut buf = vec![255u8; w * h * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buf, RESPONSE_PLOT_SIZE).into_drawing_area();
        draw(&root, TextMode::Glyphs, curves, title)?;
    }
    let pixels = buf.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    Image::from_vec(w, h, pixels).map_err(|e| PlotError(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_a_curve() {
        let g: Vec<f32> = (0..256).map(|z| ((z as f32 + 1.0) / 256.0).ln()).collect();
        let svg = response_svg([&g, &g, &g], "test").unwrap();
        assert!(svg.contains("<svg"));
        let png = response_png([&g, &g, &g], "test").unwrap();
        assert_eq!(png.width(), 720);
        assert!(png.pixels().iter().any(|p| p != &[255, 255, 255]));
    }
}

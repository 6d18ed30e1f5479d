//! The worked example of `docs/PHOTOMETRY.md`: reads every bundled IES file
//! (`assets/photometry/ies/`) and the synthetic IES and EULUMDAT files of the tests, prints the
//! flux table (Markdown) and draws polar candela plots of two bundled files as one SVG.
//!
//! `cargo run -p ibl-io --example photometry_report -- docs/images/photometry-polar.svg`
//! (run from the workspace root; without an argument nothing is drawn).

use std::path::{Path, PathBuf};

use ibl_io::{PhotometricFile, StatedFlux, read_photometry};
use ibl_light::{CandelaTable, EqualAreaMap};
use plotters::prelude::*;
use plotters::style::FontStyle;

/// DejaVu Sans, as every chart of the project (`assets/fonts/LICENSE.md`).
static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .is_some_and(|x| x.eq_ignore_ascii_case("ies") || x.eq_ignore_ascii_case("ldt"))
        })
        .collect();
    files.sort();
    files
}

/// One Markdown row: file, format, symmetry, stated figure, integrated flux, error, map flux.
fn row(path: &Path, file: &PhotometricFile) -> String {
    let name = path
        .file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into_owned());
    let table = file.table();
    let flux = table.flux();
    let map = EqualAreaMap::from_table(table, 128, 4);
    let map_error = (map.flux() / flux - 1.0) * 100.0;
    let symmetry = match file {
        PhotometricFile::Ies(f) => format!("{:?}", f.symmetry),
        PhotometricFile::Ldt(f) => format!("{:?}", f.symmetry),
    };
    let (stated, compared) = match file.stated_flux() {
        StatedFlux::Absolute => ("absolute (-1)".to_string(), "-".to_string()),
        StatedFlux::Lamps { lamp_lumens } => (
            format!("lamps {lamp_lumens:.1}"),
            format!("implied LOR {:.4}", flux / lamp_lumens),
        ),
        StatedFlux::LampsAndLor {
            lamp_lumens,
            light_output_ratio,
        } => {
            let luminaire = lamp_lumens * light_output_ratio;
            (
                format!("{lamp_lumens:.1} x LOR {light_output_ratio:.4} = {luminaire:.2}"),
                format!("{:+.3} %", (flux / luminaire - 1.0) * 100.0),
            )
        }
    };
    format!(
        "| {name} | {} | {symmetry} | {stated} | {flux:.2} | {compared} | {map_error:+.3} % |",
        file.format()
    )
}

/// The curve of the plane pair `c` / `c + 180` of a polar plot: `(x, y)` with the nadir down,
/// plane `c` to the right.
fn plane_curve(table: &CandelaTable, c: f32) -> Vec<(f64, f64)> {
    let right = (0..=360).map(|k| (k as f32 * 0.5, c));
    let left = (0..=360).rev().map(|k| (k as f32 * 0.5, c + 180.0));
    right
        .chain(left)
        .map(|(gamma, plane)| {
            let i = f64::from(table.intensity_deg(gamma, plane));
            let side = if plane == c { 1.0 } else { -1.0 };
            let g = f64::from(gamma).to_radians();
            (side * i * g.sin(), -i * g.cos())
        })
        .collect()
}

/// A ring value at a round number: 1, 2 or 5 times a power of ten, about a quarter of `peak`.
fn ring_step(peak: f64) -> f64 {
    let raw = peak / 4.0;
    let decade = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|s| *s >= raw)
        .unwrap_or(decade * 10.0)
}

fn draw(out: &Path, panels: &[(&str, &CandelaTable)]) -> Result<(), Box<dyn std::error::Error>> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| "the embedded font could not be loaded")?;
    let root = SVGBackend::new(out, (1100, 590)).into_drawing_area();
    root.fill(&WHITE)?;
    for (area, (title, table)) in root.split_evenly((1, panels.len())).iter().zip(panels) {
        let step = ring_step(f64::from(table.peak()));
        let r = step * (f64::from(table.peak()) / step).ceil();
        let mut chart = ChartBuilder::on(area)
            .caption(*title, ("sans-serif", 18))
            .margin(12)
            .build_cartesian_2d(-r * 1.08..r * 1.08, -r * 1.14..r * 1.06)?;
        let grey = RGBColor(190, 190, 190);
        let mut ring = step;
        while ring <= r * 1.0001 {
            let circle: Vec<(f64, f64)> = (0..=180)
                .map(|k| {
                    let a = f64::from(k) * 2.0_f64.to_radians();
                    (ring * a.cos(), ring * a.sin())
                })
                .collect();
            chart.draw_series(LineSeries::new(circle, grey.stroke_width(1)))?;
            chart.draw_series(std::iter::once(Text::new(
                format!("{ring} cd"),
                // Beside the ring, just above the right-hand horizontal (100 degrees from the nadir).
                (ring * 0.985, ring * 0.17),
                ("sans-serif", 11)
                    .into_font()
                    .color(&RGBColor(110, 110, 110)),
            )))?;
            ring += step;
        }
        for k in 0..12 {
            let a = f64::from(k) * 30.0_f64.to_radians();
            let spoke = vec![(0.0, 0.0), (r * a.sin(), -r * a.cos())];
            chart.draw_series(LineSeries::new(spoke, grey.stroke_width(1)))?;
        }
        for (label, (x, y)) in [
            ("0 (nadir)", (-r * 0.08, -r * 1.04)),
            ("90", (r * 1.0, r * 0.02)),
            ("180", (0.0, r * 1.02)),
        ] {
            chart.draw_series(std::iter::once(Text::new(
                label,
                (x, y),
                ("sans-serif", 12).into_font(),
            )))?;
        }
        let blue = RGBColor(31, 119, 180);
        let red = RGBColor(214, 39, 40);
        chart
            .draw_series(LineSeries::new(
                plane_curve(table, 0.0),
                blue.stroke_width(2),
            ))?
            .label("C0 (right) - C180 (left)")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], blue.stroke_width(2))
            });
        if !table.is_rotationally_symmetric() {
            chart
                .draw_series(LineSeries::new(
                    plane_curve(table, 90.0),
                    red.stroke_width(2),
                ))?
                .label("C90 (right) - C270 (left)")
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], red.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.9))
            .border_style(grey)
            .label_font(("sans-serif", 12))
            .draw()?;
    }
    root.present()?;
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bundled = crate_dir.join("../../assets/photometry/ies");
    let synthetic = crate_dir.join("tests/data/photometry");
    println!(
        "| file | format | symmetry | stated (lm) | integrated (lm) | error against the stated \
         luminaire lumens | equal-area map 128^2 vs exact |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut read = Vec::new();
    for path in files_in(&bundled).into_iter().chain(files_in(&synthetic)) {
        let file = read_photometry(&path)?;
        println!("{}", row(&path, &file));
        read.push((path, file));
    }
    if let Some(out) = std::env::args_os().nth(1) {
        let get = |n: &str| {
            read.iter()
                .find(|(p, _)| p.ends_with(n))
                .map(|(_, f)| f.table())
                .ok_or_else(|| format!("{n} not found"))
        };
        let panels = [
            (
                "defined_diffuse.ies (rotationally symmetric)",
                get("defined_diffuse.ies")?,
            ),
            (
                "medium_scatter.ies (symmetric to C0-C180)",
                get("medium_scatter.ies")?,
            ),
        ];
        draw(Path::new(&out), &panels)?;
        eprintln!("wrote {}", Path::new(&out).display());
    }
    Ok(())
}

//! Perspective views of a probe for marking (Grosch 2005, section 3.1), as tone-mapped PNGs.
//!
//! Without a marks file: eight views around the horizon (every 45 degrees, 90 degrees vertical
//! field, 800 x 600) with a pixel grid every 50 pixels (brighter every 100), to read mark
//! positions off. With one: every view of the file with its lines drawn (x red, y green, z blue)
//! and its points as yellow crosses, what `docs/ROOMS.md` shows (`--grid` adds the grid).
//!
//! ```sh
//! cargo run --release -p ibl-room --example room_views -- PROBE.exr OUT_DIR [--marks MARKS.json]
//!     [--exposure STOPS]
//! ```

use std::path::PathBuf;

use ibl_core::Image;
use ibl_io::tonemap::{Display, ToneCurve, auto_exposure_stops, to_srgb8};
use ibl_room::marks::Axis;
use ibl_room::{MarksFile, PerspectiveView};

fn put(image: &mut Image<[u8; 3]>, x: i64, y: i64, c: [u8; 3]) {
    if x >= 0 && y >= 0 && (x as usize) < image.width() && (y as usize) < image.height() {
        *image.get_mut(x as usize, y as usize) = c;
    }
}

fn line(image: &mut Image<[u8; 3]>, a: [f64; 2], b: [f64; 2], c: [u8; 3]) {
    let steps = ((b[0] - a[0]).abs().max((b[1] - a[1]).abs()).ceil() as usize).max(1);
    for k in 0..=steps {
        let t = k as f64 / steps as f64;
        let (x, y) = (a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t);
        for (dx, dy) in [(0, 0), (1, 0), (0, 1)] {
            put(image, x.floor() as i64 + dx, y.floor() as i64 + dy, c);
        }
    }
}

/// 3 x 5 digits, rows top to bottom, bit 2 = left column.
const DIGITS: [[u8; 5]; 10] = [
    [7, 5, 5, 5, 7],
    [2, 6, 2, 2, 7],
    [7, 1, 7, 4, 7],
    [7, 1, 7, 1, 7],
    [5, 5, 7, 1, 1],
    [7, 4, 7, 1, 7],
    [7, 4, 7, 5, 7],
    [7, 1, 1, 1, 1],
    [7, 5, 7, 5, 7],
    [7, 5, 7, 1, 7],
];

/// Writes `n` at `(x, y)` in 3 x 5 digits scaled by 2, on a black box.
fn number(image: &mut Image<[u8; 3]>, n: usize, x: i64, y: i64, c: [u8; 3]) {
    let text = n.to_string();
    for (k, ch) in text.bytes().enumerate() {
        let d = DIGITS[(ch - b'0') as usize];
        for (row, bits) in d.iter().enumerate() {
            for col in 0..4 {
                for (sx, sy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let on = col < 3 && bits & (4 >> col) != 0;
                    let px = x + k as i64 * 8 + col as i64 * 2 + sx;
                    let py = y + row as i64 * 2 + sy;
                    put(image, px, py, if on { c } else { [0, 0, 0] });
                }
            }
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut positional = Vec::new();
    let (mut marks_path, mut exposure, mut grid, mut detect) = (None, None, false, false);
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--marks" => {
                marks_path = args.get(i + 1).map(PathBuf::from);
                i += 1;
            }
            "--exposure" => {
                exposure = args.get(i + 1).map(|s| s.parse::<f32>()).transpose()?;
                i += 1;
            }
            "--grid" => grid = true,
            "--detect" => detect = true,
            other => positional.push(PathBuf::from(other)),
        }
        i += 1;
    }
    let [probe_path, out] = positional.as_slice() else {
        return Err(
            "usage: room_views PROBE OUT_DIR [--marks MARKS.json] [--exposure STOPS]".into(),
        );
    };
    let probe = ibl_io::read_image(probe_path)?.image;
    let display = Display {
        exposure_stops: exposure.unwrap_or_else(|| auto_exposure_stops(&probe)),
        curve: ToneCurve::Reinhard,
    };
    std::fs::create_dir_all(out)?;
    let marks = marks_path
        .map(|p| -> Result<MarksFile, Box<dyn std::error::Error>> {
            Ok(MarksFile::from_json(&std::fs::read_to_string(&p)?)
                .map_err(|e| format!("{}: {e}", p.display()))?)
        })
        .transpose()?;
    let views: Vec<(String, PerspectiveView)> = match &marks {
        Some(m) => m.views.iter().map(|v| (v.name.clone(), v.camera)).collect(),
        None => (0..8)
            .map(|k| {
                (
                    format!("yaw{:03}", k * 45),
                    PerspectiveView {
                        yaw_deg: f64::from(k * 45),
                        pitch_deg: 0.0,
                        roll_deg: 0.0,
                        vertical_fov_deg: 90.0,
                        width: 800,
                        height: 600,
                    },
                )
            })
            .collect(),
    };
    for (name, view) in &views {
        let radiance = view.render(&probe);
        let mut picture = to_srgb8(&radiance, &display);
        if marks.is_none() || grid {
            for y in 0..picture.height() {
                for x in 0..picture.width() {
                    if x % 50 == 0 || y % 50 == 0 {
                        let strong = x % 100 == 0 || y % 100 == 0;
                        let p = picture.get_mut(x, y);
                        *p = if strong {
                            [255, 0, 255]
                        } else {
                            p.map(|c| c / 2 + 64)
                        };
                    }
                }
            }
        }
        if let Some(m) = &marks {
            let v = m.views.iter().find(|v| &v.name == name).ok_or("view")?;
            for l in &v.lines {
                let c = match l.axis {
                    Axis::X => [255, 40, 40],
                    Axis::Y => [40, 255, 40],
                    Axis::Z => [60, 120, 255],
                };
                line(&mut picture, l.from, l.to, c);
            }
            for p in &v.points {
                let [x, y] = p.at;
                line(&mut picture, [x - 6.0, y], [x + 6.0, y], [255, 230, 0]);
                line(&mut picture, [x, y - 6.0], [x, y + 6.0], [255, 230, 0]);
            }
        }
        if detect {
            let segments = ibl_room::line_detection::detect_segments(
                &radiance,
                &ibl_room::line_detection::LineDetectionSettings::default(),
            );
            for (k, seg) in segments.iter().enumerate() {
                line(&mut picture, seg.from, seg.to, [0, 255, 255]);
                let mid = [
                    0.5 * (seg.from[0] + seg.to[0]),
                    0.5 * (seg.from[1] + seg.to[1]),
                ];
                number(
                    &mut picture,
                    k,
                    mid[0] as i64 + 3,
                    mid[1] as i64 + 3,
                    [255, 255, 0],
                );
                println!(
                    "{name} segment {k}: [{:.1}, {:.1}] -> [{:.1}, {:.1}]",
                    seg.from[0], seg.from[1], seg.to[0], seg.to[1]
                );
            }
        }
        let path = out.join(format!("{name}.png"));
        ibl_io::write_atomically(&path, &ibl_io::ldr::encode_png(&picture)?)?;
        println!("{}", path.display());
    }
    Ok(())
}

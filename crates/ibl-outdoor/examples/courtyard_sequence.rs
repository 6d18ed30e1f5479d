//! Writes the bundled outdoor sequence (`assets/outdoor/courtyard/`): the synthetic courtyard of
//! `ibl_outdoor::courtyard` as a scene file with an `[outdoor]` table that `ibl outdoor` and
//! `ibl demo` read, rendered by the project's own path tracer.
//!
//! ```sh
//! cargo run --release -p ibl-outdoor --example courtyard_sequence -- assets/outdoor/courtyard
//! ```
//!
//! Writes `scene.toml`, `model.obj` and `model.mtl` (the courtyard with its albedos), `probe.exr`
//! (256 x 128, taken at 09:30), `mask.png` (every pixel that sees the model: it is all diffuse),
//! `frames/HHMM.exr` (160 x 120, half floats, hourly from 10:00 to 17:00: a cloud at 11:00, overcast at 14:00
//! and 15:00) and `truth.csv` (each frame's true `P_d` and `P_a`). Renders: 3 bounces (the light
//! the buildings throw into the shade is there, as in a real yard), the probe at 64 spp and the
//! frames at 48 spp, independent samples; the frames' per-pixel noise is about 1 / sqrt(48) of
//! their variance per sample (docs/OUTDOOR.md states the measured floor of the figures).

use std::fmt::Write as _;
use std::path::Path;

use ibl_io::{ExrOptions, ExrPrecision, WriteOptions, write_atomically, write_image};
use ibl_outdoor::courtyard::Courtyard;
use ibl_outdoor::synthetic::SyntheticDay;

/// Frames of the standard day used: every other one (hourly from 10:00).
const FRAMES: [usize; 8] = [1, 3, 5, 7, 9, 11, 13, 15];

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "assets/outdoor/courtyard".into());
    let out = Path::new(&out);
    std::fs::create_dir_all(out.join("frames")).expect("create the output folder");
    let day = SyntheticDay {
        bounces: 3,
        ..SyntheticDay::standard()
    };
    let yard = Courtyard::new(day.frame_size);
    let capture = day.frame_truth(0).expect("the capture's light");
    let probe = day
        .render_probe(&yard, &capture, 1)
        .expect("render the probe");
    write_image(&out.join("probe.exr"), &probe, &WriteOptions::default()).expect("probe.exr");
    let size = (day.frame_size.0 as usize, day.frame_size.1 as usize);
    let mask = yard
        .diffuse_mask(size)
        .map(|&m| ibl_core::Rgb::splat(if m { 1.0 } else { 0.0 }));
    write_image(&out.join("mask.png"), &mask, &WriteOptions::default()).expect("mask.png");
    write_model(&yard, out);
    let mut truth = String::from("frame,local_time,weather,p_d_r,p_d_g,p_d_b,p_a_r,p_a_g,p_a_b\n");
    for (n, &k) in FRAMES.iter().enumerate() {
        let t = day.frame_truth(k).expect("the frame's light");
        let frame = day
            .render_frame(&yard, &t, 100 + k as u64)
            .expect("render a frame");
        let minutes = 9 * 60 + 30 + 30 * k;
        let name = format!("{:02}{:02}", minutes / 60, minutes % 60);
        // Half floats: 3 significant digits, far below the frames' noise, half the size.
        let half = WriteOptions {
            exr: ExrOptions {
                precision: ExrPrecision::Half,
                ..ExrOptions::default()
            },
            ..WriteOptions::default()
        };
        write_image(
            &out.join("frames").join(format!("{name}.exr")),
            &frame,
            &half,
        )
        .expect("a frame");
        let (pd, pa) = (t.parameters.sun, t.parameters.sky);
        let _ = writeln!(
            truth,
            "{n},2024-04-20T{:02}:{:02}:00,{:?},{},{},{},{},{},{}",
            minutes / 60,
            minutes % 60,
            t.weather,
            pd[0],
            pd[1],
            pd[2],
            pa[0],
            pa[1],
            pa[2]
        );
        eprintln!("frame {name} written");
    }
    write_atomically(&out.join("truth.csv"), truth.as_bytes()).expect("truth.csv");
}

/// `model.obj` and `model.mtl`: every triangle of the yard, one material per albedo.
fn write_model(yard: &Courtyard, out: &Path) {
    let layer = &yard.layer;
    let mut mtl = String::from("# The synthetic courtyard's albedos (ibl_outdoor::courtyard)\n");
    for (i, m) in layer.materials.iter().enumerate() {
        let a = m.diffuse_albedo();
        let _ = writeln!(mtl, "newmtl m{i}\nKd {} {} {}\n", a.r, a.g, a.b);
    }
    let mut obj = String::from(
        "# The synthetic courtyard of ibl_outdoor::courtyard, metres, world frame (+Y up, north -Z)\nmtllib model.mtl\n",
    );
    for t in &layer.triangles {
        for v in t {
            let _ = writeln!(obj, "v {} {} {}", v.x, v.y, v.z);
        }
    }
    let mut current = u32::MAX;
    for (i, s) in layer.surfaces.iter().enumerate() {
        if s.material != current {
            current = s.material;
            let _ = writeln!(obj, "usemtl m{current}");
        }
        let _ = writeln!(obj, "f {} {} {}", 3 * i + 1, 3 * i + 2, 3 * i + 3);
    }
    write_atomically(&out.join("model.mtl"), mtl.as_bytes()).expect("model.mtl");
    write_atomically(&out.join("model.obj"), obj.as_bytes()).expect("model.obj");
}

use std::path::PathBuf;
use glam::{Mat3, Vec3};
use ibl_core::{Image, LatLong, Rgb};
use ibl_io::{WriteOptions, read_image, write_image};
use ibl_outdoor::courtyard::Courtyard;
use ibl_outdoor::synthetic::SyntheticDay;
use ibl_outdoor::transfer::{cosine_direction, ray_offset};
use ibl_outdoor::view::{ProbeProjection, cast};
use ibl_scene::Ray;

fn cached(name: &str, f: impl FnOnce() -> Image<Rgb>) -> Image<Rgb> {
    let p = PathBuf::from(format!("/tmp/odiag/{name}.pfm"));
    if let Ok(l) = read_image(&p) { return l.image; }
    let t = std::time::Instant::now();
    let im = f();
    eprintln!("rendered {name} in {:.1} s", t.elapsed().as_secs_f64());
    write_image(&p, &im, &WriteOptions::default()).unwrap();
    im
}

fn main() {
    let day = SyntheticDay { environment_width: 4096, ..SyntheticDay::standard() };
    let yard = Courtyard::new(day.frame_size);
    let layer = &yard.layer;
    let proj = ProbeProjection::new(layer, yard.probe_position, Mat3::IDENTITY, 256);
    let (w, h) = (256usize, 128usize);
    // M1: hits of cosine rays from probe surface pixels.
    let (mut rays, mut hits, mut seen) = (0u64, 0u64, 0u64);
    let off = ray_offset(layer);
    for p in (0..w * h).step_by(5) {
        let Some(x) = proj.view.hits()[p] else { continue };
        for a in 0..8 { for b in 0..8 {
            let wdir = cosine_direction(x.normal, (a as f32 + 0.5) / 8.0, (b as f32 + 0.5) / 8.0);
            rays += 1;
            if let Some(y) = cast(layer, &Ray::new(x.position + x.normal * off, wdir)) {
                hits += 1;
                if proj.pixel_of(y.position).is_some() { seen += 1; }
            }
        }}
    }
    println!("probe pixels: rays {rays}, hit a surface {:.1} %, of those seen by the probe {:.1} %", 100.0 * hits as f64 / rays as f64, 100.0 * seen as f64 / hits as f64);
    // M2: bounce convergence of the truth at capture.
    let truth = day.frame_truth(0).unwrap();
    let mut imgs = Vec::new();
    for b in [1u32, 2, 3, 8] {
        let d = SyntheticDay { bounces: b, ..day.clone() };
        imgs.push((b, cached(&format!("conv_b{b}_e4096"), || d.render_probe(&yard, &truth, 77).unwrap())));
    }
    let omega = LatLong::new(w, h).row_solid_angles();
    let mean = |im: &Image<Rgb>| -> f64 { let mut s = 0.0; let mut n = 0.0; for p in 0..w*h { if proj.view.hits()[p].is_some() { s += im.pixels()[p].g as f64 * omega[p / w]; n += omega[p / w]; } } s / n };
    let m1 = mean(&imgs[0].1);
    for (b, im) in &imgs { println!("bounces {b}: mean surface radiance (green) {:.5} ({:+.2} % over direct)", mean(im), 100.0 * (mean(im) / m1 - 1.0)); }
}

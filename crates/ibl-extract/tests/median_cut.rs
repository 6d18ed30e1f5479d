//! Median cut: 2^K lights that partition the probe, conserve its power to f64 rounding, split
//! energy evenly, and reduce to exact answers on a constant environment and a single bright pixel.

use std::path::PathBuf;

use ibl_core::{Image, LatLong, Rgb};
use ibl_extract::{ExtractError, median_cut};

fn bundled_probes() -> Vec<(String, Image<Rgb>)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/probes");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("assets/probes")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "exr"))
        .collect();
    paths.sort();
    assert!(paths.len() >= 4);
    paths
        .iter()
        .map(|p| {
            let name = p.file_stem().expect("stem").to_string_lossy().into_owned();
            (
                name,
                ibl_io::read_image(p).expect("bundled probe reads").image,
            )
        })
        .collect()
}

fn probe_power(img: &Image<Rgb>) -> [f64; 3] {
    let ll = LatLong::new(img.width(), img.height());
    let mut p = [0.0; 3];
    for y in 0..img.height() {
        let sr = ll.row_solid_angle(y);
        for px in img.row(y) {
            for (pc, v) in p.iter_mut().zip(px.to_array()) {
                *pc += f64::from(v) * sr;
            }
        }
    }
    p
}

#[test]
fn lights_partition_the_probe_and_conserve_power_on_every_bundled_probe() {
    for (name, img) in bundled_probes() {
        let want = probe_power(&img);
        for k in 0..=8 {
            let set = median_cut(&img, k).unwrap();
            // 2^K lights, unless a round met a single-pixel region (it cannot be cut: a sun or
            // skylight so bright that equal-energy regions shrink to one pixel).
            let singles = set
                .lights
                .iter()
                .filter(|l| l.region.unwrap().width() * l.region.unwrap().height() == 1)
                .count();
            assert!(set.lights.len() <= 1 << k, "{name} K={k}");
            if set.lights.len() < 1 << k {
                assert!(
                    singles > 0,
                    "{name} K={k}: lights missing without a single-pixel region"
                );
                println!(
                    "{name} K={k}: {} lights ({singles} single-pixel regions)",
                    set.lights.len()
                );
            }
            let area: usize = set
                .lights
                .iter()
                .map(|l| l.region.unwrap().width() * l.region.unwrap().height())
                .sum();
            assert_eq!(
                area,
                img.width() * img.height(),
                "{name} K={k}: regions do not tile"
            );
            let got = set.total_power();
            for c in 0..3 {
                let rel = (got[c] - want[c]).abs() / want[c];
                // Region sums reorganise the probe's power sum (per-row f64 sums, summed-area table
                // differences): equal to f64 rounding (about 1e-15 relative); 1e-6 is far above
                // that and still catches any lost region.
                assert!(
                    rel < 1e-6,
                    "{name} K={k} channel {c}: {} vs {} ({rel:e})",
                    got[c],
                    want[c]
                );
            }
            let sr: f64 = set.lights.iter().map(|l| l.solid_angle_sr).sum();
            // Region solid angles are exact lat-long row sums; they add to 4 pi to f64 rounding
            // over 2^K regions (about 1e-13); 1e-9 leaves a margin of 1e4.
            assert!(
                (sr - 4.0 * std::f64::consts::PI).abs() < 1e-9,
                "{name} K={k}: {sr}"
            );
            for l in &set.lights {
                let d = l.direction;
                // Centroids are normalised in f64: unit to a few ulps.
                assert!((d.length() - 1.0).abs() < 1e-12);
                for c in 0..3 {
                    let i = f64::from(l.radiance.to_array()[c]) * l.solid_angle_sr;
                    // L = I / A is stored in f32: L A equals I to f32 rounding (6e-8 relative);
                    // 1e-6 is 16 f32 ulps.
                    assert!((i - l.irradiance[c]).abs() <= 1e-6 * l.irradiance[c].max(1e-12));
                }
            }
        }
    }
}

#[test]
fn regions_hold_nearly_equal_energy() {
    // With cuts between pixels, each of the 2^K regions holds 1/2^K of the energy to within the
    // energy of the rows/columns the cuts could not split; on a smooth synthetic sky that is tight.
    let (w, h) = (256, 128);
    let img = Image::from_fn_par(w, h, |x, y| {
        let v = (y as f32 + 0.5) / h as f32;
        let u = (x as f32 + 0.5) / w as f32;
        Rgb::splat(1.0 + 3.0 * (1.0 - v) + (6.0 * u).sin().abs())
    });
    let ll = LatLong::new(w, h);
    let set = median_cut(&img, 4).unwrap();
    let energies: Vec<f64> = set
        .lights
        .iter()
        .map(|l| {
            let r = l.region.unwrap();
            (r.y0..r.y1)
                .flat_map(|y| (r.x0..r.x1).map(move |x| (x, y)))
                .map(|(x, y)| f64::from(img.get(x, y).luminance()) * ll.row_solid_angle(y))
                .sum()
        })
        .collect();
    let mean = energies.iter().sum::<f64>() / energies.len() as f64;
    for e in &energies {
        // Cuts fall between pixel rows and columns, so a region holds half its parent's energy to
        // within one row or column of it; on this 256 x 128 sky with 16 regions (each about 64 x 32
        // pixels) one row or column is 1.5 to 3 % of a region; 8 % allows for both dimensions of
        // the cuts that made it.
        assert!(
            (e / mean - 1.0).abs() < 0.08,
            "region energy {e} vs mean {mean}"
        );
    }
}

#[test]
fn constant_environment_first_cut_is_down_the_middle() {
    let img = Image::filled(64, 32, Rgb::splat(2.0));
    let set = median_cut(&img, 1).unwrap();
    let r: Vec<_> = set.lights.iter().map(|l| l.region.unwrap()).collect();
    // The full sphere is 2 pi wide at the equator and pi tall: the first cut splits columns.
    assert_eq!((r[0].x1, r[1].x0), (32, 32));
    // Each half is a hemisphere (left: -X, right: +X) with power 2 * 2 pi.
    for (l, sign) in set.lights.iter().zip([-1.0, 1.0]) {
        // The hemisphere's energy centroid is exactly -X or +X by symmetry; f64 sums over 1024
        // pixels round to 1e-15, margin 1e6.
        assert!((l.direction.x - sign).abs() < 1e-9, "{:?}", l.direction);
        for c in 0..3 {
            assert!((l.irradiance[c] - 4.0 * std::f64::consts::PI).abs() < 1e-9);
        }
        // L = I / A with I = 2 * 2 pi and A = 2 pi: 2 in f32 to rounding.
        assert!((l.radiance.r - 2.0).abs() < 1e-6);
    }
}

#[test]
fn a_single_bright_pixel_becomes_one_light_in_its_direction() {
    let (w, h) = (128, 64);
    let (px, py) = (90, 20);
    let mut img = Image::filled(w, h, Rgb::splat(1e-3));
    *img.get_mut(px, py) = Rgb::new(5e4, 4e4, 3e4);
    let ll = LatLong::new(w, h);
    let d = ll.pixel_dir64(px, py);
    let set = median_cut(&img, 5).unwrap();
    let owner = set
        .lights
        .iter()
        .find(|l| {
            let r = l.region.unwrap();
            (r.x0..r.x1).contains(&px) && (r.y0..r.y1).contains(&py)
        })
        .unwrap();
    // The bright pixel (5e4 against 1e-3) dominates its region's energy centroid: the neighbours
    // pull the centroid by their energy share (below 1e-6 of the region's), so cos > 0.99999 (0.26
    // degrees) has a wide margin.
    assert!(
        owner.direction.dot(d) > 0.99999,
        "{:?} vs {d:?}",
        owner.direction
    );
    let pixel_power = 5e4 * ll.row_solid_angle(py);
    // The region holds the pixel's power plus its dim neighbours' (each 5e7 times weaker): within 1
    // % of the pixel's power.
    assert!(owner.irradiance[0] >= pixel_power && owner.irradiance[0] < pixel_power * 1.01);
}

#[test]
fn bad_parameters_are_errors() {
    let img = Image::filled(8, 4, Rgb::ONE);
    assert!(matches!(
        median_cut(&img, 17),
        Err(ExtractError::Parameter(_))
    ));
    let empty = Image::from_vec(0, 0, Vec::<Rgb>::new()).unwrap();
    assert!(matches!(
        median_cut(&empty, 1),
        Err(ExtractError::Invalid(_))
    ));
    // More rounds than pixels can take: single-pixel regions stay whole, power is kept.
    let set = median_cut(&img, 6).unwrap();
    assert_eq!(set.lights.len(), 32);
}

//! The bundled probes (`assets/probes/*.{exr,hdr}`): each `.exr` and `.hdr` pair holds the same
//! image. The `.exr` keeps a few negative values (DWAB ringing in the original) that the `.hdr`
//! clamped, so the comparison is done after sanitising, within RGBE precision.

use std::path::PathBuf;

use ibl_io::{ImageFormat, read_image};

fn probe(name: &str, ext: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/probes")
        .join(format!("{name}.{ext}"))
}

/// Every bundled probe name (each has an `.exr` and an `.hdr`).
fn bundled_probes() -> Vec<String> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/probes");
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("assets/probes")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "exr"))
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    names.sort();
    assert!(names.len() >= 4, "bundled probes: {names:?}");
    names
}

#[test]
fn exr_and_hdr_probes_agree_within_rgbe_precision() {
    for name in bundled_probes() {
        let name = name.as_str();
        let exr = read_image(&probe(name, "exr")).expect("exr reads");
        let hdr = read_image(&probe(name, "hdr")).expect("hdr reads");
        assert_eq!(
            (exr.format, hdr.format),
            (ImageFormat::Exr, ImageFormat::Hdr)
        );
        assert_eq!(
            (exr.image.width(), exr.image.height()),
            (512, 256),
            "{name}"
        );
        assert_eq!(
            (hdr.image.width(), hdr.image.height()),
            (512, 256),
            "{name}"
        );
        assert!(hdr.report.is_clean(), "{name}: {:?}", hdr.report);
        assert_eq!(exr.report.nonfinite_values, 0, "{name}");

        let mut worst: f32 = 0.0;
        let mut peak: f32 = 0.0;
        for (e, h) in exr.image.pixels().iter().zip(hdr.image.pixels()) {
            let m = e.max_channel();
            peak = peak.max(m);
            let d = (e.r - h.r)
                .abs()
                .max((e.g - h.g).abs())
                .max((e.b - h.b).abs());
            // Channels too small for RGBE's shared exponent (below 2^-128 relative) round to 0.
            let rel = if m > 1e-30 { d / m } else { d };
            worst = worst.max(rel);
        }
        println!(
            "{name}: exr {} | hdr {} | exr negatives clamped: {} (raw min {:?}), non-finite: {} | \
             peak {peak:.4e} | max error relative to pixel max {worst:.3e}",
            exr.details,
            hdr.details,
            exr.report.negative_values,
            exr.report.raw_min,
            exr.report.nonfinite_values
        );
        assert!(
            worst <= 1.0 / 256.0 * (1.0 + 1e-5),
            "{name}: relative error {worst}"
        );
    }
}

#[test]
fn esplanade_has_the_documented_dwab_negatives() {
    let exr = read_image(&probe("esplanade", "exr")).expect("reads");
    assert!(exr.report.negative_values > 0);
    assert!(
        exr.report.raw_min.to_array().iter().any(|&v| v < -1000.0),
        "{:?}",
        exr.report.raw_min
    );
    assert!(
        exr.image
            .pixels()
            .iter()
            .map(|p| p.max_channel())
            .fold(0.0, f32::max)
            > 1e4
    );
}

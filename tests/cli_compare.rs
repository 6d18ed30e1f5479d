//! End-to-end tests of `ibl compare`: the metrics against their closed forms, error images (false
//! colour and raw), masks, LDR inputs, and exit code 2 with the files named for bad input.

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

use common::{ibl, stderr};
use ibl_core::{Image, Rgb};

fn json(o: &Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout).unwrap()
}

fn write(dir: &Path, name: &str, image: &Image<Rgb>) -> PathBuf {
    let path = dir.join(name);
    ibl_io::write_image(&path, image, &ibl_io::WriteOptions::default()).unwrap();
    path
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Reference 0.5 everywhere, test 0.5 + 0.125 (32 x 24 EXRs, exact in f32).
fn offset_pair(dir: &Path) -> (PathBuf, PathBuf) {
    let reference = write(dir, "ref.exr", &Image::filled(32, 24, Rgb::splat(0.5)));
    let test = write(dir, "test.exr", &Image::filled(32, 24, Rgb::splat(0.625)));
    (test, reference)
}

#[test]
fn metrics_match_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let (test, reference) = offset_pair(dir.path());
    let o = ibl(&["compare", s(&test), s(&reference), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    let num = |k: &str| v[k].as_f64().unwrap();
    // delta = 0.125 on b = 0.5: rmse = mean|d| = max|d| = delta, relMSE = delta^2 / (b^2 + 0.01),
    // PSNR = 10 log10(b^2 / delta^2) = 12.04 dB.
    let delta = 0.125;
    assert!((num("rmse") - delta).abs() < 1e-12);
    assert!((num("mean_abs") - delta).abs() < 1e-12);
    assert!((num("max_abs") - delta).abs() < 1e-12);
    let rel = delta * delta / (0.25 + 0.01);
    // delta = 0.125 and b = 0.5 are exact in binary: the relative MSE is one f64 division of exact
    // values; 1e-12.
    assert!(
        (num("relative_mse") - rel).abs() < 1e-12,
        "{}",
        num("relative_mse")
    );
    assert_eq!(num("relative_mse_epsilon"), 0.01);
    // PSNR = 10 log10(0.25 / delta^2) through one f64 log10: rounding of order 1e-15; 1e-9.
    assert!((num("psnr_db") - 10.0 * (0.25f64 / (delta * delta)).log10()).abs() < 1e-9);
    assert_eq!(v["pixels"], 32 * 24);
    assert_eq!(v["flip"]["range"], "hdr");
    let flip = v["flip"]["mean"].as_f64().unwrap();
    assert!(flip > 0.0 && flip < 1.0, "{flip}");
    // A uniform offset gives the same FLIP everywhere: every percentile equals the mean.
    for p in ["p50", "p90", "p99", "max"] {
        assert!((v["flip"][p].as_f64().unwrap() - flip).abs() < 1e-5, "{p}");
    }
    assert!(v["error_image"].is_null());
    // Identical images: every metric 0, PSNR undefined.
    let o = ibl(&["compare", s(&reference), s(&reference), "--json"]);
    let v = json(&o);
    assert_eq!(v["rmse"], 0.0);
    assert_eq!(v["flip"]["mean"], 0.0);
    assert!(v["psnr_db"].is_null());
    // The text form states the same numbers.
    let o = ibl(&["compare", s(&test), s(&reference)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("rmse        1.250000e-1"), "{text}");
    assert!(text.contains("flip        mean"), "{text}");
}

#[test]
fn error_images_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let (test, reference) = offset_pair(dir.path());
    // Default: false-colour FLIP as PNG.
    let png = dir.path().join("flip.png");
    let o = ibl(&[
        "compare",
        s(&test),
        s(&reference),
        "--error-image",
        s(&png),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v["error_image"]["metric"], "flip");
    assert_eq!(v["error_image"]["encoding"], "false-colour");
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"));
    let picture = ibl_io::read_image(&png).unwrap().image;
    assert_eq!((picture.width(), picture.height()), (32, 24));
    // Raw relative squared error as EXR: delta^2 / (b^2 + 0.01) in every pixel.
    let exr = dir.path().join("relmse.exr");
    let o = ibl(&[
        "compare",
        s(&test),
        s(&reference),
        "--metric",
        "relmse",
        "--error-image",
        s(&exr),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let map = ibl_io::read_image(&exr).unwrap().image;
    let want = 0.125f32 * 0.125 / 0.26;
    // The raw relMSE map in f32 (EXR float): 0.125^2 / 0.26 to f32 rounding (6e-8 relative); 1e-6.
    assert!(
        map.pixels()
            .iter()
            .all(|p| (p.g - want).abs() < 1e-6 * want.max(1.0))
    );
    // Raw absolute error: 0.125 everywhere.
    let abs = dir.path().join("abs.pfm");
    let o = ibl(&[
        "compare",
        s(&test),
        s(&reference),
        "--metric",
        "abs",
        "--error-image",
        s(&abs),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let map = ibl_io::read_image(&abs).unwrap().image;
    // |a - b| = 0.125 exactly in f32 and EXR float; 1e-7 allows one rounding.
    assert!(map.pixels().iter().all(|p| (p.r - 0.125).abs() < 1e-7));
}

#[test]
fn mask_restricts_the_comparison() {
    let dir = tempfile::tempdir().unwrap();
    // The test differs from the reference only in the left half; the mask keeps the right half.
    let reference = write(dir.path(), "ref.exr", &Image::filled(16, 8, Rgb::ONE));
    let test_img = Image::from_fn_par(16, 8, |x, _| Rgb::splat(if x < 8 { 3.0 } else { 1.0 }));
    let test = write(dir.path(), "test.exr", &test_img);
    let mask_img = Image::from_fn_par(16, 8, |x, _| if x >= 8 { Rgb::ONE } else { Rgb::ZERO });
    let mask = write(dir.path(), "mask.exr", &mask_img);
    let o = ibl(&[
        "compare",
        s(&test),
        s(&reference),
        "--mask",
        s(&mask),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v["pixels"], 64);
    assert_eq!(v["rmse"], 0.0);
    // Unmasked: half the pixels off by 2: rmse = sqrt(4 / 2), mean |d| = 1.
    let v = json(&ibl(&["compare", s(&test), s(&reference), "--json"]));
    assert!((v["rmse"].as_f64().unwrap() - 2f64.sqrt()).abs() < 1e-12);
    assert!((v["mean_abs"].as_f64().unwrap() - 1.0).abs() < 1e-12);
    // A mask of another size is refused.
    let small = write(dir.path(), "small.exr", &Image::filled(4, 4, Rgb::ONE));
    let o = ibl(&["compare", s(&test), s(&reference), "--mask", s(&small)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("small.exr"), "{}", stderr(&o));
}

#[test]
fn ldr_pictures_use_ldr_flip() {
    let dir = tempfile::tempdir().unwrap();
    let white = write(
        dir.path(),
        "white.png",
        &Image::filled(16, 16, Rgb::splat(1.0e6)),
    );
    let black = write(dir.path(), "black.png", &Image::filled(16, 16, Rgb::ZERO));
    let o = ibl(&["compare", s(&black), s(&white), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v["flip"]["range"], "ldr");
    assert!(v["flip"]["exposures"].as_array().unwrap().is_empty());
    let flip = v["flip"]["mean"].as_f64().unwrap();
    // Black against white is FLIP's largest difference: the mean is 1 but for the filters' edge
    // handling on a 16 x 16 image; above 0.95.
    assert!(flip > 0.95 && flip <= 1.0, "black against white: {flip}");
    // RMSE of 0 against 1 (8-bit codes 0 and 255 decode exactly to 0 and 1): 1 to f32 rounding;
    // 1e-6.
    assert!((v["rmse"].as_f64().unwrap() - 1.0).abs() < 1e-6);
}

#[test]
fn bad_input_exits_2_and_names_the_files() {
    let dir = tempfile::tempdir().unwrap();
    let (test, reference) = offset_pair(dir.path());
    // Sizes differ.
    let other = write(dir.path(), "other.exr", &Image::filled(31, 24, Rgb::ONE));
    let o = ibl(&["compare", s(&other), s(&reference)]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(
        err.contains("other.exr") && err.contains("ref.exr"),
        "{err}"
    );
    // A missing file.
    let missing = dir.path().join("missing.exr");
    let o = ibl(&["compare", s(&test), s(&missing)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("missing.exr"), "{}", stderr(&o));
    // The error image over an input is refused, and the input is untouched.
    let before = std::fs::read(&test).unwrap();
    let o = ibl(&[
        "compare",
        s(&test),
        s(&reference),
        "--error-image",
        s(&test),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("test.exr"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&test).unwrap(), before, "input changed");
    // Unknown error-image extension, and a viewing condition out of range.
    let txt = dir.path().join("e.txt");
    let o = ibl(&["compare", s(&test), s(&reference), "--error-image", s(&txt)]);
    assert_eq!(o.status.code(), Some(2));
    let o = ibl(&["compare", s(&test), s(&reference), "--ppd", "0"]);
    assert_eq!(o.status.code(), Some(2));
}

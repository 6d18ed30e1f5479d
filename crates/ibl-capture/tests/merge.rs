//! Response recovery and HDR merging on brackets synthesised from `assets/probes/apartment.exr`:
//! the probe's radiance times a 7-step exposure ladder (2 stops apart), Gaussian read and shot
//! noise, a known gamma-like response with a toe (a different exponent per channel) and 8-bit
//! rounding, all seeded. Also exact closed forms for linear data, the saturation fall-backs, pixel
//! weights, CSV round trips and every refused input.

#![allow(clippy::unwrap_used)] // tests may panic

use std::path::Path;
use std::sync::OnceLock;

use ibl_capture::CaptureError;
use ibl_capture::merge::{MergeOptions, MergeResult, Weighting, merge, merge_linear};
use ibl_capture::response::{RecoverOptions, ResponseCurve};
use ibl_core::{Image, Rgb};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Exponent per channel of the synthetic camera's response.
const GAMMA: [f64; 3] = [2.0, 2.2, 2.4];
/// Offset of the toe (linear exposure units, full scale 1).
const TOE: f64 = 0.004;
/// Read noise and shot-noise factor of the synthetic sensor (full scale 1).
const READ_NOISE: f64 = 0.0003;
const SHOT_NOISE: f64 = 0.004;

/// The known response before white balance: linear exposure X in [0, 1] to a fraction of full
/// scale y in [0, 1].
fn raw_response(x: f64, c: usize) -> f64 {
    let p = 1.0 / GAMMA[c];
    ((x + TOE).powf(p) - TOE.powf(p)) / ((1.0 + TOE).powf(p) - TOE.powf(p))
}

/// Its inverse: the linear exposure of fraction y.
fn raw_inverse(y: f64, c: usize) -> f64 {
    let p = 1.0 / GAMMA[c];
    let span = (1.0 + TOE).powf(p) - TOE.powf(p);
    (y * span + TOE.powf(p)).powf(GAMMA[c]) - TOE
}

/// Per-channel gain making the camera white-balanced: equal codes 128 mean equal exposures.
fn white_balance(c: usize) -> f64 {
    raw_inverse(128.0 / 255.0, c) / raw_inverse(128.0 / 255.0, 1)
}

/// The known response of channel c: exposure X to a fraction of full scale.
fn response(x: f64, c: usize) -> f64 {
    raw_response((x * white_balance(c)).clamp(0.0, 1.0), c)
}

/// The known `g(z) = ln f^-1(z / 255)` (code z stands for the centre of its rounding interval).
fn true_g(z: usize, c: usize) -> f64 {
    (raw_inverse(z as f64 / 255.0, c) / white_balance(c)).ln()
}

fn gaussian(rng: &mut Pcg64) -> f64 {
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

struct Bracket {
    radiance: Image<Rgb>,
    images: Vec<Image<[u8; 3]>>,
    times: Vec<f64>,
}

/// The probe and its 7 exposures (2 stops apart, the middle one putting the median luminance at
/// 18 % of full scale), noisy and 8-bit.
fn bracket() -> &'static Bracket {
    static BRACKET: OnceLock<Bracket> = OnceLock::new();
    BRACKET.get_or_init(|| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/probes/apartment.exr");
        let radiance = ibl_io::read_image(&path).unwrap().image;
        let mut luminance: Vec<f32> = radiance.pixels().iter().map(|p| p.luminance()).collect();
        luminance.sort_by(f32::total_cmp);
        let median = luminance[luminance.len() / 2] as f64;
        let times: Vec<f64> = (0..7).map(|j| 0.18 / median * 4f64.powi(j - 3)).collect();
        let mut rng = Pcg64::seed_from_u64(1997);
        let images = times
            .iter()
            .map(|&t| {
                let data = radiance
                    .pixels()
                    .iter()
                    .map(|p| {
                        let e = p.to_array();
                        std::array::from_fn(|c| {
                            let x = e[c] as f64 * t;
                            let noisy = x
                                + READ_NOISE * gaussian(&mut rng)
                                + SHOT_NOISE * x.sqrt() * gaussian(&mut rng);
                            (255.0 * response(noisy.max(0.0), c)).round() as u8
                        })
                    })
                    .collect();
                Image::from_vec(radiance.width(), radiance.height(), data).unwrap()
            })
            .collect();
        Bracket {
            radiance,
            images,
            times,
        }
    })
}

fn recovered() -> &'static ResponseCurve {
    static CURVE: OnceLock<ResponseCurve> = OnceLock::new();
    CURVE.get_or_init(|| {
        let b = bracket();
        ResponseCurve::recover(&b.images, &b.times, &RecoverOptions::default()).unwrap()
    })
}

/// Largest |recovered - true| of `ln X` over codes 10..=245, after removing the mean difference
/// (the unknown additive constant), per channel.
fn curve_errors(curve: &ResponseCurve) -> [f64; 3] {
    std::array::from_fn(|c| {
        let g = curve.log_exposure()[c];
        let d: Vec<f64> = (10..=245).map(|z| g[z] as f64 - true_g(z, c)).collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        d.iter().map(|v| (v - mean).abs()).fold(0.0, f64::max)
    })
}

/// Relative errors of `merged` against the source radiance over pixels with, in every channel, a
/// code strictly between the black and saturation levels in at least one exposure, after the
/// global scale (median of the ratios): returns (median, 99th percentile, max).
fn radiance_errors(merged: &Image<Rgb>, options: &MergeOptions) -> (f64, f64, f64) {
    let b = bracket();
    let usable = |i: usize, c: usize| {
        b.images.iter().any(|im| {
            let z = im.pixels()[i][c];
            z > options.black_level && z < options.saturation_level
        })
    };
    let mut pairs = Vec::new();
    for i in 0..merged.len() {
        let (m, s) = (
            merged.pixels()[i].to_array(),
            b.radiance.pixels()[i].to_array(),
        );
        for c in 0..3 {
            if usable(i, c) && s[c] > 0.0 {
                pairs.push((m[c] as f64, s[c] as f64));
            }
        }
    }
    let mut ratios: Vec<f64> = pairs.iter().map(|(m, s)| s / m).collect();
    ratios.sort_by(f64::total_cmp);
    let scale = ratios[ratios.len() / 2];
    let mut errors: Vec<f64> = pairs
        .iter()
        .map(|(m, s)| (scale * m - s).abs() / s)
        .collect();
    errors.sort_by(f64::total_cmp);
    let at = |q: f64| errors[((errors.len() - 1) as f64 * q) as usize];
    (at(0.5), at(0.99), at(1.0))
}

fn true_curve() -> ResponseCurve {
    // Code 0 has no finite inverse; put it one below code 1 (it carries no weight anyway).
    ResponseCurve::from_table(std::array::from_fn(|c| {
        (0..256)
            .map(|z| true_g(z.max(1), c) as f32 - if z == 0 { 1.0 } else { 0.0 })
            .collect()
    }))
    .unwrap()
}

fn invalid_message<T: std::fmt::Debug>(result: Result<T, CaptureError>) -> String {
    match result {
        Err(CaptureError::Invalid(message)) => message,
        other => panic!("expected CaptureError::Invalid, got {other:?}"),
    }
}

fn is_parameter<T: std::fmt::Debug>(result: Result<T, CaptureError>) -> bool {
    matches!(result, Err(CaptureError::Parameter(_)))
}

fn solid(width: usize, height: usize, code: u8) -> Image<[u8; 3]> {
    Image::filled(width, height, [code; 3])
}

/// Recovered curve vs the known one: max |difference of ln X| over codes 10..=245, after removing
/// the mean difference, below 0.05 in every channel (measured 0.015, 0.009, 0.007).
#[test]
fn recovered_curve_matches_the_known_response() {
    let errors = curve_errors(recovered());
    eprintln!("max |ln X error| over codes 10..=245, R G B: {errors:.4?}");
    for (c, e) in errors.iter().enumerate() {
        assert!(*e < 0.05, "channel {c}: max |ln X error| {e}");
    }
    for g in recovered().log_exposure() {
        assert_eq!(g[128], 0.0);
        assert!(g.windows(2).all(|w| w[1] >= w[0]), "not monotonic");
    }
}

/// Merged radiance vs the probe on pixel channels with a usable code in some exposure, after the
/// global scale (median of ratios): median relative error < 1.5 %, 99th percentile < 4 %, max <
/// 12 %, for both weightings and both the recovered and the true curve (measured with the
/// recovered curve: hat 0.66 % / 2.5 % / 7.2 %).
#[test]
fn merged_radiance_matches_the_probe() {
    let b = bracket();
    let truth = true_curve();
    for weighting in [Weighting::Hat, Weighting::NoiseAware] {
        let options = MergeOptions {
            weighting,
            ..MergeOptions::default()
        };
        for (name, curve) in [("recovered", recovered()), ("true", &truth)] {
            let merged = merge(&b.images, &b.times, curve, &options).unwrap();
            let (median, p99, max) = radiance_errors(&merged.image, &options);
            eprintln!(
                "{weighting:?}, {name} curve: relative error median {median:.4}, p99 {p99:.4}, \
                 max {max:.4}; {} black pixels",
                merged.black_pixels
            );
            assert!(
                median < 0.015 && p99 < 0.04 && max < 0.12,
                "{weighting:?}, {name} curve: median {median}, p99 {p99}, max {max}"
            );
            assert_eq!(merged.saturated_pixels, 0);
            assert!(merged.black_pixels < merged.image.len() / 100);
        }
    }
}

/// 8-bit linear data with codes `n dt` (n = 1..=255, dt = 1, 2, 4, 8) through
/// `ResponseCurve::linear`: every pixel merges to exactly n / 255 (relative error < 2e-6), the
/// pixels saturated in every exposure (n >= 250) included, and they are counted.
#[test]
fn linear_curve_reproduces_a_linear_bracket() {
    let times = [1.0, 2.0, 4.0, 8.0];
    let radiance = |n: usize| [n, n, 256 - n];
    let images: Vec<Image<[u8; 3]>> = times
        .iter()
        .map(|&t| {
            let data = (1..=255)
                .map(|n| radiance(n).map(|e| (e * t as usize).min(255) as u8))
                .collect();
            Image::from_vec(255, 1, data).unwrap()
        })
        .collect();
    let curve = ResponseCurve::linear(256).unwrap();
    for weighting in [Weighting::Hat, Weighting::NoiseAware] {
        let options = MergeOptions {
            weighting,
            ..MergeOptions::default()
        };
        let merged = merge(&images, &times, &curve, &options).unwrap();
        for (i, p) in merged.image.pixels().iter().enumerate() {
            for (c, (n, got)) in radiance(i + 1).iter().zip(p.to_array()).enumerate() {
                let e = *n as f64 / 255.0;
                let got = got as f64;
                // Linear response, one exposure per pixel: X = (n / 255) / t in f32 with
                // power-of-two times; the weighted mean of one value is itself but for f32 rounding
                // of the log and exp (a few 1e-7 relative); 2e-6.
                assert!(
                    (got - e).abs() <= 2e-6 * e,
                    "pixel {i} channel {c}: {got} vs {e}"
                );
            }
        }
        // Red/green n >= 250 (6 pixels) and blue 256 - n >= 250 (6 pixels).
        assert_eq!(merged.saturated_pixels, 12);
        assert_eq!(merged.black_pixels, 0);
    }
}

/// Linear float exposures `min(E dt, 1)` merge to exactly E (relative error < 1e-6) wherever one
/// exposure is below saturation; pixels saturated everywhere give the lower bound
/// `min(E dt_min, 1) / dt_min`, and are counted.
#[test]
fn merge_linear_reproduces_linear_exposures() {
    let times = [1.0 / 64.0, 1.0 / 16.0, 0.25, 1.0];
    let mut rng = Pcg64::seed_from_u64(7);
    let (w, h) = (64, 48);
    let radiance: Vec<[f32; 3]> = (0..w * h)
        .map(|_| std::array::from_fn(|_| 10f32.powf(rng.random_range(-3.5f32..2.0))))
        .collect();
    let images: Vec<Image<Rgb>> = times
        .iter()
        .map(|&t| {
            let data = radiance
                .iter()
                .map(|e| Rgb::from_array(e.map(|v| (v * t as f32).min(1.0))))
                .collect();
            Image::from_vec(w, h, data).unwrap()
        })
        .collect();
    let options = MergeOptions::default();
    let merged = merge_linear(&images, &times, &options).unwrap();
    let saturation = 250.0 / 255.0;
    let mut saturated = 0;
    for (i, p) in merged.image.pixels().iter().enumerate() {
        let mut any = false;
        for (c, (got, e)) in p.to_array().into_iter().zip(radiance[i]).enumerate() {
            if e * times[0] as f32 >= saturation {
                any = true;
                assert_eq!(got, (e * times[0] as f32).min(1.0) * 64.0);
                assert!(got <= e);
            } else {
                // Unsaturated pixels: every exposure gives the same X in exact arithmetic; the
                // weighted mean in f32 differs by rounding only (1e-7 relative); 1e-6.
                assert!(
                    (got - e).abs() <= 1e-6 * e,
                    "pixel {i} channel {c}: {got} vs {e}"
                );
            }
        }
        saturated += usize::from(any);
    }
    assert!(saturated > 0);
    assert_eq!(merged.saturated_pixels, saturated);
}

/// One pixel seen with codes 60 (dt = 1 s) and 200 (dt = 2 s) through the linear curve: the merge
/// is the weighted mean of the paper's equation 6 with the hat weights 58/124 and 50/124 (black 2,
/// saturation 250), and with the noise-aware weights halving the shorter exposure's.
#[test]
fn weights_follow_the_closed_form() {
    let images = [solid(1, 1, 60), solid(1, 1, 200)];
    let times = [1.0, 2.0];
    let curve = ResponseCurve::linear(256).unwrap();
    let ln_e = [(60f64 / 255.0).ln(), (200f64 / 255.0).ln() - 2f64.ln()];
    for (weighting, w) in [
        (Weighting::Hat, [58.0 / 124.0, 50.0 / 124.0]),
        (Weighting::NoiseAware, [0.5 * 58.0 / 124.0, 50.0 / 124.0]),
    ] {
        let options = MergeOptions {
            weighting,
            ..MergeOptions::default()
        };
        let got = merge(&images, &times, &curve, &options)
            .unwrap()
            .image
            .pixels()[0]
            .g as f64;
        let expected = ((w[0] * ln_e[0] + w[1] * ln_e[1]) / (w[0] + w[1])).exp();
        // The closed form of the weighted log-average in f64 against the merge's f32: f32 rounding
        // of exp and log (1e-7 relative); 1e-6.
        assert!(
            (got - expected).abs() < 1e-6 * expected,
            "{weighting:?}: {got} vs {expected}"
        );
    }
}

/// A pixel saturated in every exposure takes the shortest exposure's value, one black in every
/// exposure the longest's, and both are counted.
#[test]
fn saturated_and_black_pixels_fall_back() {
    let times = [0.5, 2.0, 1.0];
    let images: Vec<Image<[u8; 3]>> = [[255u8, 0, 100], [255, 1, 230], [255, 0, 160]]
        .iter()
        .map(|codes| Image::from_vec(3, 1, codes.map(|z| [z; 3]).to_vec()).unwrap())
        .collect();
    let curve = ResponseCurve::linear(256).unwrap();
    let merged = merge(&images, &times, &curve, &MergeOptions::default()).unwrap();
    let p = merged.image.pixels();
    // Saturated in every exposure: the shortest exposure's value 1 / 0.5 = 2, exact in f32 to
    // rounding; 1e-6.
    assert!((p[0].r - 1.0 / 0.5).abs() < 1e-6);
    // Black in every exposure: the longest exposure's first code over its time, 1 / 255 / 2, to f32
    // rounding (1e-10 absolute); 1e-9.
    assert!((p[1].r - 1.0 / 255.0 / 2.0).abs() < 1e-9);
    assert_eq!((merged.saturated_pixels, merged.black_pixels), (1, 1));
}

/// Per-pixel weights: a ghost painted into exposure 3 and weighted out there leaves the merge
/// exactly as without that exposure in the region (where another exposure is usable) and as the
/// clean merge elsewhere; weights that remove every exposure of a pixel are ignored for it.
#[test]
fn pixel_weights_remove_a_ghost() {
    let b = bracket();
    let (w, h) = (b.radiance.width(), b.radiance.height());
    let curve = recovered();
    let in_ghost = |x: usize, y: usize| (w / 4..w / 2).contains(&x) && (h / 4..h / 2).contains(&y);
    let mut ghosted = b.images.clone();
    for y in 0..h {
        for x in 0..w {
            if in_ghost(x, y) {
                *ghosted[3].get_mut(x, y) = [(x * 7 % 256) as u8, 128, (y * 13 % 256) as u8];
            }
        }
    }
    let weights: Vec<Image<f32>> = (0..7)
        .map(|j| {
            Image::from_fn_par(
                w,
                h,
                |x, y| if j == 3 && in_ghost(x, y) { 0.0 } else { 1.0 },
            )
        })
        .collect();
    let options = MergeOptions {
        pixel_weights: Some(weights),
        ..MergeOptions::default()
    };
    let weighted = merge(&ghosted, &b.times, curve, &options).unwrap().image;
    let clean = merge(&b.images, &b.times, curve, &MergeOptions::default())
        .unwrap()
        .image;
    let mut without: Vec<Image<[u8; 3]>> = b.images.clone();
    without.remove(3);
    let mut times = b.times.clone();
    times.remove(3);
    let six = merge(&without, &times, curve, &MergeOptions::default())
        .unwrap()
        .image;
    // Where no other exposure is usable the ghost's weights are ignored; skip those pixels.
    let seen_by_others = |x: usize, y: usize| {
        (0..3).all(|c| {
            without.iter().any(|im| {
                let z = im.get(x, y)[c];
                z > 2 && z < 250
            })
        })
    };
    let mut compared = 0;
    for y in 0..h {
        for x in 0..w {
            if !in_ghost(x, y) {
                assert_eq!(weighted.get(x, y), clean.get(x, y), "({x}, {y})");
            } else if seen_by_others(x, y) {
                assert_eq!(weighted.get(x, y), six.get(x, y), "({x}, {y})");
                compared += 1;
            }
        }
    }
    assert!(compared > w * h / 20, "{compared}");
    let zero = MergeOptions {
        pixel_weights: Some(vec![Image::filled(w, h, 0.0); 7]),
        ..MergeOptions::default()
    };
    assert_eq!(
        merge(&b.images, &b.times, curve, &zero).unwrap().image,
        clean
    );
}

/// Results do not depend on the number of threads.
#[test]
fn results_do_not_depend_on_thread_count() {
    let b = bracket();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let (curve, merged) = one.install(|| {
        let curve =
            ResponseCurve::recover(&b.images, &b.times, &RecoverOptions::default()).unwrap();
        let merged = merge(&b.images, &b.times, &curve, &MergeOptions::default()).unwrap();
        (curve, merged)
    });
    assert_eq!(&curve, recovered());
    let many: MergeResult =
        merge(&b.images, &b.times, recovered(), &MergeOptions::default()).unwrap();
    assert_eq!(merged, many);
}

/// `to_csv` / `from_csv` round-trip exactly; the linear curve's closed form.
#[test]
fn csv_round_trip_and_linear_curve() {
    let csv = recovered().to_csv();
    assert!(csv.starts_with("code,r,g,b\n0,"));
    assert_eq!(csv.lines().count(), 257);
    assert_eq!(&ResponseCurve::from_csv(&csv).unwrap(), recovered());
    // Without header, with comments, blank lines and CRLF.
    let body: String = csv.lines().skip(1).map(|l| format!("{l}\r\n")).collect();
    let text = format!("# a curve\r\n\r\n{body}");
    assert_eq!(&ResponseCurve::from_csv(&text).unwrap(), recovered());

    let linear = ResponseCurve::linear(256).unwrap();
    assert_eq!(linear.levels(), 256);
    // The linear curve is n / 255 in f32: 255 / 255 = 1 and 51 / 255 = 0.2 to f32 rounding (1e-8);
    // 1e-6.
    assert!((linear.exposure_of(255).g - 1.0).abs() < 1e-6);
    assert!((linear.exposure_of(51).r - 0.2).abs() < 1e-6);
    // Code 0 is set to a quarter of code 1, 0.25 / 255, to f32 rounding (1e-10); 1e-9.
    assert!((linear.exposure_of(0).b - 0.25 / 255.0).abs() < 1e-9);
    assert_eq!(linear.exposure_of(1000), linear.exposure_of(255));
    assert!(is_parameter(ResponseCurve::linear(1)));
}

/// Curves that are not finite, decrease, or are malformed are refused as `Invalid`.
#[test]
fn bad_curves_are_refused() {
    let ok: Vec<f32> = (0..4).map(|z| z as f32).collect();
    let with = |v: Vec<f32>| [ok.clone(), v, ok.clone()];
    assert!(
        invalid_message(ResponseCurve::from_table(with(vec![0.0, 1.0, 0.5, 2.0])))
            .contains("must not decrease")
    );
    assert!(
        invalid_message(ResponseCurve::from_table(with(vec![
            0.0,
            f32::NAN,
            1.0,
            2.0
        ])))
        .contains("not finite")
    );
    assert!(invalid_message(ResponseCurve::from_table(with(vec![0.0, 1.0]))).contains("codes"));
    assert!(ResponseCurve::from_table([vec![0.0], vec![0.0], vec![0.0]]).is_err());
    for text in [
        "",
        "code,r,g\n0,1,2\n",
        "code,r,g,b\n0,1,2,3\n2,1,2,3\n",
        "0,1,2,3\n1,1,x,3\n",
        "0,1,2,3\n1,1,2\n",
        "0,1,2,3\n1,0,2,3\n",
        "0,1,2,3\ncode,r,g,b\n",
    ] {
        invalid_message(ResponseCurve::from_csv(text));
    }
}

/// Brackets the method cannot use are refused as `Invalid` with a clear message; bad parameters
/// as `Parameter`; nothing panics.
#[test]
fn bad_brackets_are_refused() {
    let b = bracket();
    let (w, h) = (32, 24);
    let options = RecoverOptions::default();
    let ramp =
        |t: f64| Image::from_fn_par(w, h, |x, y| [((x * 8 + y) as f64 * t).min(255.0) as u8; 3]);
    let good = vec![ramp(1.0), ramp(2.0)];

    // Recovery.
    assert!(
        invalid_message(ResponseCurve::recover(&good[..1], &[1.0], &options))
            .contains("at least 2 exposures")
    );
    let sizes = vec![ramp(1.0), solid(w, h + 1, 100)];
    assert!(
        invalid_message(ResponseCurve::recover(&sizes, &[1.0, 2.0], &options))
            .contains("same size")
    );
    assert!(
        invalid_message(ResponseCurve::recover(&good, &[1.0], &options))
            .contains("every exposure needs its time")
    );
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(
            invalid_message(ResponseCurve::recover(&good, &[1.0, bad], &options))
                .contains("finite and positive")
        );
    }
    assert!(
        invalid_message(ResponseCurve::recover(&good, &[0.5, 0.5], &options))
            .contains("different exposure times")
    );
    let saturated = vec![solid(w, h, 255); 3];
    assert!(
        invalid_message(ResponseCurve::recover(
            &saturated,
            &[1.0, 2.0, 4.0],
            &options
        ))
        .contains("saturated or black")
    );
    let black = vec![solid(w, h, 0); 3];
    assert!(
        invalid_message(ResponseCurve::recover(&black, &[1.0, 2.0, 4.0], &options))
            .contains("saturated or black")
    );
    let empty = vec![solid(0, 0, 9); 2];
    assert!(
        invalid_message(ResponseCurve::recover(&empty, &[1.0, 2.0], &options)).contains("empty")
    );
    let lambda = RecoverOptions {
        smoothness: f64::NAN,
        ..options
    };
    assert!(is_parameter(ResponseCurve::recover(
        &b.images, &b.times, &lambda
    )));
    let few = RecoverOptions {
        sample_pixels: Some(10),
        ..options
    };
    assert!(is_parameter(ResponseCurve::recover(
        &b.images, &b.times, &few
    )));

    // Merging.
    let curve = ResponseCurve::linear(256).unwrap();
    let m = MergeOptions::default();
    assert!(invalid_message(merge(&[], &[], &curve, &m)).contains("no exposures"));
    assert!(invalid_message(merge(&sizes, &[1.0, 2.0], &curve, &m)).contains("same size"));
    assert!(invalid_message(merge(&good, &[1.0], &curve, &m)).contains("needs its time"));
    assert!(
        invalid_message(merge(&saturated, &[1.0, 2.0, 4.0], &curve, &m))
            .contains("every pixel is saturated in every exposure")
    );
    assert!(
        invalid_message(merge(&black, &[1.0, 2.0, 4.0], &curve, &m))
            .contains("every pixel is black in every exposure")
    );
    let short = ResponseCurve::linear(16).unwrap();
    assert!(invalid_message(merge(&good, &[1.0, 2.0], &short, &m)).contains("256"));
    let levels = MergeOptions {
        black_level: 100,
        saturation_level: 101,
        ..MergeOptions::default()
    };
    assert!(is_parameter(merge(&good, &[1.0, 2.0], &curve, &levels)));
    for weights in [
        vec![Image::filled(w, h, 1.0f32)],
        vec![Image::filled(w, h, 1.0f32), Image::filled(w, h + 1, 1.0)],
        vec![Image::filled(w, h, 1.0f32), Image::filled(w, h, 1.5)],
        vec![Image::filled(w, h, 1.0f32), Image::filled(w, h, f32::NAN)],
    ] {
        let o = MergeOptions {
            pixel_weights: Some(weights),
            ..MergeOptions::default()
        };
        assert!(is_parameter(merge(&good, &[1.0, 2.0], &curve, &o)));
    }
    // A single exposure is a valid (if noisy) merge: g(z) - ln dt.
    let single = merge(&good[..1], &[2.0], &curve, &m).unwrap();
    assert!((single.image.get(10, 0).r - 80.0 / 255.0 / 2.0).abs() < 1e-6);

    // Linear merging.
    let linear: Vec<Image<Rgb>> = vec![Image::filled(w, h, Rgb::splat(0.5)); 2];
    assert!(invalid_message(merge_linear(&linear, &[1.0], &m)).contains("needs its time"));
    let mut nan = linear.clone();
    *nan[1].get_mut(3, 2) = Rgb::new(0.5, f32::NAN, 0.5);
    assert!(invalid_message(merge_linear(&nan, &[1.0, 2.0], &m)).contains("(3, 2)"));
    let white = vec![Image::filled(w, h, Rgb::splat(1.0)); 2];
    assert!(invalid_message(merge_linear(&white, &[1.0, 2.0], &m)).contains("saturated"));
}

//! Display transform: sRGB values at known points, monotone curves, exposure in stops and a sane
//! automatic exposure on a bundled probe.

use std::path::PathBuf;

use ibl_core::tonemap::{Display, ToneCurve, auto_exposure_stops, to_srgb8};
use ibl_core::{Image, Rgb};
use ibl_io::read_image;

fn one(v: f32, display: Display) -> [u8; 3] {
    *to_srgb8(&Image::filled(1, 1, Rgb::splat(v)), &display).get(0, 0)
}

#[test]
fn clamp_at_zero_exposure_matches_srgb() {
    let d = Display {
        exposure_stops: 0.0,
        curve: ToneCurve::Clamp,
    };
    assert_eq!(one(1.0, d), [255; 3]);
    assert_eq!(one(0.5, d), [188; 3]);
    assert_eq!(one(0.0, d), [0; 3]);
    assert_eq!(one(0.0031308, d), [10; 3]); // linear segment: 12.92 * x * 255 = 10.3
    assert_eq!(one(0.215_861, d), [128; 3]); // linear value of sRGB 128/255
    assert_eq!(one(7.0, d), [255; 3]);
    // Exposure is in stops: +1 doubles, so 0.25 at +1 looks like 0.5 at 0.
    assert_eq!(
        one(
            0.25,
            Display {
                exposure_stops: 1.0,
                ..d
            }
        ),
        [188; 3]
    );
    assert_eq!(
        one(
            2.0,
            Display {
                exposure_stops: -2.0,
                ..d
            }
        ),
        [188; 3]
    );
}

#[test]
fn curves_are_monotone_and_reach_white() {
    for curve in [ToneCurve::Clamp, ToneCurve::Reinhard, ToneCurve::AcesFilmic] {
        let d = Display {
            exposure_stops: 0.0,
            curve,
        };
        let xs: Vec<f32> = (0..=4000)
            .map(|i| 10f32.powf(-4.0 + i as f32 * 0.002))
            .collect();
        let img =
            Image::from_vec(xs.len(), 1, xs.iter().map(|&v| Rgb::splat(v)).collect()).expect("row");
        let out = to_srgb8(&img, &d);
        for w in out.row(0).windows(2) {
            assert!(w[1][0] >= w[0][0], "{curve:?} not monotone");
        }
        for (i, &v) in xs.iter().enumerate().skip(1) {
            assert!(curve.apply(v) >= curve.apply(xs[i - 1]), "{curve:?} at {v}");
        }
        let last = out.row(0).last().copied().unwrap_or_default();
        // Reinhard approaches white only asymptotically: 1e4 / (1 + 1e4) -> 255 after rounding.
        assert_eq!(last, [255; 3], "{curve:?}");
        println!(
            "{curve:?}: 0.18 -> {:?}, 1 -> {:?}, 4 -> {:?}",
            one(0.18, d),
            one(1.0, d),
            one(4.0, d)
        );
    }
    assert_eq!(ToneCurve::default(), ToneCurve::Reinhard);
    assert_eq!(
        one(
            1.0,
            Display {
                exposure_stops: 0.0,
                curve: ToneCurve::Reinhard
            }
        ),
        [188; 3]
    );
}

#[test]
fn auto_exposure_is_sane_on_a_probe() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/probes/esplanade.exr");
    let probe = read_image(&path).expect("reads").image;
    let stops = auto_exposure_stops(&probe);
    println!("esplanade auto exposure: {stops:+.3} stops");
    assert!(
        stops.is_finite() && (-10.0..10.0).contains(&stops),
        "{stops}"
    );
    // The log-average of the exposed image is middle grey.
    let scale = stops.exp2();
    let (sum, n) = probe
        .pixels()
        .iter()
        .map(|p| p.luminance())
        .filter(|&l| l > 0.0)
        .fold((0.0f64, 0u32), |(s, n), l| {
            (s + f64::from(l * scale).ln(), n + 1)
        });
    // Automatic exposure maps the log-average luminance to 0.18: the exposure is kept in f32 stops
    // (rounding 1e-7 relative) and the check re-sums f32 luminances; 1e-3 of 0.18 is far above
    // both.
    assert!(((sum / f64::from(n)).exp() - 0.18).abs() < 1e-3);
    // A small sun 10^6 times brighter barely moves it; a black half does not move it at all.
    let mut sunny = probe.clone();
    for x in 0..4 {
        *sunny.get_mut(x, 10) = Rgb::splat(1e6);
    }
    // Four 1e6 pixels among 131072 move the log average by about 4 ln(1e6) / 131072 = 4e-4 (6e-4
    // stop); 0.1 stop is what a viewer would notice.
    assert!((auto_exposure_stops(&sunny) - stops).abs() < 0.1);
    let mut half_black = probe.clone();
    half_black.pixels_mut()[..512 * 128].fill(Rgb::ZERO);
    let lower_half_only =
        Image::from_vec(512, 128, probe.pixels()[512 * 128..].to_vec()).expect("half");
    // Black pixels are left out of the log average: the two images average the same pixels, in a
    // different order of f64 sums (1e-12); 1e-4 stop.
    assert!(
        (auto_exposure_stops(&half_black) - auto_exposure_stops(&lower_half_only)).abs() < 1e-4
    );
}

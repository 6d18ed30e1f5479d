//! Irradiance optimisation: closed forms (one bright pixel, a constant environment), thread-count
//! independence, and the bundled probes: it converges for every N tried, never ends worse than it
//! started, and scores on the 20000 scoring normals (which it never saw) within stated bounds.
//! Tables print with
//! `cargo test -p ibl-extract --test irradiance_optimization -- --nocapture`.

#![allow(clippy::unwrap_used)] // tests may panic
#![allow(clippy::needless_range_loop)] // channels are indexed 0..3 alongside other arrays

use std::path::Path;
use std::time::Instant;

use ibl_core::glam::DVec3;
use ibl_core::{Image, LatLong, Rgb, fibonacci_normals, irradiance_exact};
use ibl_extract::irradiance_optimization::{FIT_NORMAL_COUNT, fit_irradiance, fit_normals};
use ibl_extract::{OptimizationOptions, fit_hemispheres, irradiance_optimization};
use ibl_metrics::IrradianceError;

fn probes() -> Vec<(String, Image<Rgb>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/probes");
    let probes = ibl_io::read_images_in(&dir, "exr").expect("the bundled probes load");
    assert!(!probes.is_empty(), "no probes in {}", dir.display());
    probes
}

/// (mean_err%, max_err%) of CONVENTIONS section 5.
fn errors(truth: &[[f64; 3]], approx: &[[f64; 3]]) -> (f64, f64) {
    let e = IrradianceError::between(truth, approx);
    (e.mean_err_pct, e.max_err_pct)
}

fn score(probe: &Image<Rgb>, n: usize) -> (f64, f64, ibl_extract::Fit) {
    let normals: Vec<DVec3> = fibonacci_normals(20_000);
    let truth = irradiance_exact(probe, &normals);
    let fit = irradiance_optimization(probe, n, &OptimizationOptions::default()).unwrap();
    let approx: Vec<[f64; 3]> = normals.iter().map(|&v| fit.set.irradiance_at(v)).collect();
    let (mean, max) = errors(&truth, &approx);
    (mean, max, fit)
}

#[test]
fn fit_normals_are_not_the_scoring_normals() {
    let fit = fit_normals();
    let scoring = fibonacci_normals(20_000);
    assert_eq!(fit.len(), FIT_NORMAL_COUNT);
    // No fitting normal lies within 1e-6 rad of a scoring normal (checked on a subset).
    for f in fit.iter().step_by(64) {
        let closest = scoring.iter().map(|s| s.dot(*f)).fold(-1.0f64, f64::max);
        assert!(closest < 1.0 - 1e-12, "{f}");
    }
}

#[test]
fn one_bright_pixel_is_one_light() {
    // A single lit pixel is a (tiny) cosine lobe: one fitted light must sit at the pixel's
    // direction and carry its power L dOmega; the error is then pixel-size small.
    let (w, h) = (128usize, 64usize);
    let (pi_, pj) = (37usize, 21usize);
    let mut probe = Image::filled(w, h, Rgb::ZERO);
    *probe.get_mut(pi_, pj) = Rgb::new(1000.0, 500.0, 250.0);
    let ll = LatLong::new(w, h);
    let d = ll.pixel_dir64(pi_, pj);
    let power = 1000.0 * ll.row_solid_angle(pj);
    let (mean, max, fit) = score(&probe, 1);
    let light = fit.set.lights[0];
    println!(
        "one pixel: mean {mean:.2e} % max {max:.2e} % angle {:.2e} rad",
        light.direction.angle_between(d)
    );
    // One bright pixel is a point light: the fit lands on its direction and power to the
    // optimiser's convergence tolerance (1e-3 relative in cost, far finer in the five parameters of
    // one light); 1e-6 rad and 1e-6 relative.
    assert!(light.direction.angle_between(d) < 1e-6);
    assert!((light.irradiance[0] / power - 1.0).abs() < 1e-6);
    assert!((light.irradiance[1] / light.irradiance[0] - 0.5).abs() < 1e-6);
    // Irradiance of a point light matched by a point light: the only error is the pixel's own
    // extent (0.7 degrees of a 512 x 256 probe), whose effect on the clamped cosine is of order its
    // solid angle, 1e-4 of a per cent; thresholds 1e-4 % mean and 1e-3 % max (the printed line
    // shows the values).
    assert!(mean < 1e-4 && max < 1e-3);
    assert!(fit.report.converged);
}

#[test]
fn each_fitted_light_is_sized_by_its_cell_of_the_probe() {
    // The sky probe at N = 32: the fit splits the sun between its two strongest lights. Each
    // light's source is its cell (the pixels nearest it): the cells cover the sphere (4 pi to
    // the rounding of summed pixel solid angles, 1e-9), radiance x solid angle is the fitted
    // power (f32 radiance: 1e-6 relative), and every light has a measured spread and core fraction.
    // (A spread may exceed its cell: a light near its cell's edge whose power lies at the far
    // side has a wide half-energy cone. Shadows take the smaller of the two.) The sun's two
    // lights shadow as the sun does: measured spreads 5.7e-4 and 3.1e-4 sr (the sun covers about
    // one 1.5e-4 sr pixel, and each light sits about 0.75 degrees off it), bound 1e-3 sr, where
    // their cells hold 0.11 and 0.12 sr of sky; before cells every fitted light was the paper's
    // 1-degree disc (2.4e-4 sr) whatever it stood for.
    let (_, sky) = probes().into_iter().find(|(n, _)| n == "sky").unwrap();
    let fit = irradiance_optimization(&sky, 32, &OptimizationOptions::default()).unwrap();
    let total: f64 = fit.set.lights.iter().map(|l| l.solid_angle_sr).sum();
    assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-9, "{total}");
    for l in &fit.set.lights {
        for c in 0..3 {
            let i = l.irradiance[c];
            let la = f64::from(l.radiance.to_array()[c]) * l.solid_angle_sr;
            assert!((la - i).abs() <= 1e-6 * i, "{la} vs {i}");
        }
        let spread = l.spread_sr.unwrap();
        assert!(spread > 0.0 && spread.is_finite(), "{spread}");
        assert!(l.shadow_solid_angle_sr() <= l.solid_angle_sr);
        assert!((0.0..=1.0).contains(&l.core_fraction.unwrap()));
    }
    for sun in &fit.set.lights[..2] {
        println!(
            "sun light: cell {:.3} sr, spread {:.2e} sr",
            sun.solid_angle_sr,
            sun.spread_sr.unwrap()
        );
        assert!(sun.spread_sr.unwrap() < 1e-3 && sun.solid_angle_sr > 0.05);
    }
}

/// `probe` with the rows of the other half black: the upper half (rows `0..h/2`) when `upper`.
fn half(probe: &Image<Rgb>, upper: bool) -> Image<Rgb> {
    let h = probe.height();
    Image::from_fn_par(probe.width(), h, |i, j| {
        if (j < h.div_ceil(2)) == upper {
            *probe.get(i, j)
        } else {
            Rgb::ZERO
        }
    })
}

/// The irradiance at `n` of the lights that stand for one side of the horizon (above when
/// `upper`), each as soft shadows render it: its cones folded onto its side
/// (`Light::soft_points`, 256 points a cone), or as a point (`soft` false).
fn side_irradiance(set: &ibl_light::LightSet, n: DVec3, upper: bool, soft: bool) -> [f64; 3] {
    let side = if upper {
        ibl_light::HorizonSide::Above
    } else {
        ibl_light::HorizonSide::Below
    };
    let mut e = [0.0; 3];
    for l in set.lights.iter().filter(|l| l.side == Some(side)) {
        let c: f64 = if soft {
            l.soft_points(256)
                .iter()
                .map(|(p, w)| w * n.dot(*p).max(0.0))
                .sum()
        } else {
            n.dot(l.direction).max(0.0)
        };
        for ch in 0..3 {
            e[ch] += l.irradiance[ch] * c;
        }
    }
    e
}

#[test]
fn fitted_apart_the_lights_carry_what_a_ground_lets_through() {
    // A ground plane at the horizon passes the probe's upper hemisphere and stops the lower one:
    // the irradiance a surface above it gets is the upper half's alone, E_up(n). Fitted to the
    // whole sphere, a light may stand for light from both sides of the horizon, so the lights
    // above it carry E_up badly; fitted apart (fit_hemispheres), the lights above the
    // horizon carry E_up and those below carry E_down, each to the accuracy of a fit of that
    // many lights, as the renderer draws them: soft, folded onto their side, with the powers
    // solved for that. Apartment probe, 16 lights, scored on 20000 normals (measured: mean error
    // of E_up 8.03 % whole-sphere (as points: it gives its lights no side), 0.51 % apart; E_down
    // 8.92 % and 0.63 %; the same lights taken as points, 2.34 % and 2.81 %: their powers are
    // solved for the soft model). Bounds: apart below 1.2 %, whole-sphere above 6 %: a third or
    // more of margin on each side, for another CPU's nearby local minimum (the golden test
    // allows a fit 15 %).
    let (_, apt) = probes()
        .into_iter()
        .find(|(n, _)| n == "apartment")
        .unwrap();
    let normals = fibonacci_normals(20_000);
    let truth =
        [true, false].map(|up| ibl_core::RowIrradiance::new(&half(&apt, up)).irradiance(&normals));
    let o = OptimizationOptions::default();
    let sphere = irradiance_optimization(&apt, 16, &o).unwrap();
    let apart = fit_hemispheres(&apt, 16, &o).unwrap();
    for (k, upper) in [true, false].into_iter().enumerate() {
        let whole = {
            let approx: Vec<[f64; 3]> = normals
                .iter()
                .map(|&n| {
                    let mut e = [0.0; 3];
                    for l in sphere.set.lights.iter() {
                        if (l.direction.y > 0.0) == upper {
                            let c = n.dot(l.direction).max(0.0);
                            for ch in 0..3 {
                                e[ch] += l.irradiance[ch] * c;
                            }
                        }
                    }
                    e
                })
                .collect();
            errors(&truth[k], &approx).0
        };
        let apart_err = |soft: bool| {
            let approx: Vec<[f64; 3]> = normals
                .iter()
                .map(|&n| side_irradiance(&apart.set, n, upper, soft))
                .collect();
            errors(&truth[k], &approx).0
        };
        let (split, as_points) = (apart_err(true), apart_err(false));
        println!(
            "upper {upper}: mean error whole sphere {whole:.2} %, apart {split:.2} % (as points \
             {as_points:.2} %)"
        );
        assert!(split < 1.2 && whole > 6.0, "{split} {whole}");
    }
    // The report says how the lights were shared: by the halves' powers (52 % above: 8 of 16),
    // each half's lights marked with their side and on it (or on the horizon); the whole
    // sphere's have no side.
    assert_eq!(sphere.report.lights_above_horizon, None);
    assert!(sphere.set.lights.iter().all(|l| l.side.is_none()));
    assert_eq!(apart.report.lights_above_horizon, Some(8));
    let above = ibl_light::HorizonSide::Above;
    let count = apart
        .set
        .lights
        .iter()
        .filter(|l| l.side == Some(above))
        .count();
    assert_eq!(count, 8);
    for l in &apart.set.lights {
        let side = l.side.expect("a side");
        assert!(
            l.direction.dot(side.up()) >= 0.0,
            "{:?} {side:?}",
            l.direction
        );
    }
    assert!(apart.report.converged);
    // The report scores the lights as drawn (on the 6144 fitting normals): the same quantity as
    // the soft lights' error on the whole probe's irradiance here (20000 scoring normals).
    // Measured: 0.356 % reported, 0.382 % scored; bound: within a fifth (the two normal sets).
    let whole_truth = ibl_core::RowIrradiance::new(&apt).irradiance(&normals);
    let drawn: Vec<[f64; 3]> = normals
        .iter()
        .map(|&n| {
            let (up, down) = (
                side_irradiance(&apart.set, n, true, true),
                side_irradiance(&apart.set, n, false, true),
            );
            [0, 1, 2].map(|c| up[c] + down[c])
        })
        .collect();
    let scored = errors(&whole_truth, &drawn).0;
    let reported = apart.report.fit_mean_abs_err_pct;
    println!(
        "whole probe as drawn: {scored:.3} % on the scoring normals, {reported:.3} % reported"
    );
    assert!((reported / scored - 1.0).abs() < 0.2, "{reported} {scored}");
}

#[test]
fn hemispheres_of_one_light_or_one_lit_half_fit_as_one() {
    // One light cannot be shared: the whole-sphere fit. A probe lit only above the horizon: all
    // the lights go above, fitted to it whole (same lights as the sphere's fit of that half).
    let o = OptimizationOptions::default();
    let probe = Image::from_fn_par(64, 32, |i, j| {
        Rgb::new(1.0 + (i % 5) as f32, 1.0, (j % 3) as f32)
    });
    let one = fit_hemispheres(&probe, 1, &o).unwrap();
    assert_eq!(one.report.lights_above_horizon, None);
    let upper = half(&probe, true);
    let fit = fit_hemispheres(&upper, 6, &o).unwrap();
    assert_eq!(fit.report.lights_above_horizon, Some(6));
    assert!(fit.set.lights.iter().all(|l| l.direction.y >= 0.0));
}

#[test]
fn constant_environment_floor() {
    // E = pi L on every normal; N directional lights can only approximate the flat field with
    // clamped-cosine lobes, so this is the floor N lights reach on the smoothest possible probe.
    // Measured: N=16 0.89 % / 4.5 %, N=64 0.17 % / 0.77 % (mean / max).
    let probe = Image::filled(256, 128, Rgb::new(1.0, 2.0, 3.0));
    for (n, mean_bound, max_bound) in [(16usize, 1.0, 5.5), (64, 0.2, 1.2)] {
        let (mean, max, fit) = score(&probe, n);
        println!("constant N={n}: mean {mean:.3} % max {max:.3} %");
        assert!(fit.report.converged);
        assert!(mean < mean_bound && max < max_bound, "N={n}: {mean} {max}");
        // Colour is carried exactly: every light has radiance in the ratio 1:2:3.
        for l in &fit.set.lights {
            assert!((l.irradiance[1] / l.irradiance[0] - 2.0).abs() < 1e-6);
        }
    }
}

#[test]
fn bit_identical_whatever_the_thread_count() {
    let probe = Image::from_fn_par(64, 32, |i, j| {
        Rgb::new(
            1.0 + (i % 7) as f32,
            0.5 + (j % 5) as f32,
            ((i * j) % 11) as f32,
        )
    });
    let run = |k: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(k)
            .build()
            .unwrap()
            .install(|| {
                let o = OptimizationOptions::default();
                [
                    irradiance_optimization(&probe, 9, &o).unwrap(),
                    fit_hemispheres(&probe, 9, &o).unwrap(),
                ]
            })
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn bad_parameters_are_errors() {
    let probe = Image::filled(16, 8, Rgb::new(1.0, 1.0, 1.0));
    assert!(irradiance_optimization(&probe, 0, &OptimizationOptions::default()).is_err());
    assert!(irradiance_optimization(&probe, 5000, &OptimizationOptions::default()).is_err());
    assert!(fit_hemispheres(&probe, 0, &OptimizationOptions::default()).is_err());
    assert!(fit_hemispheres(&probe, 5000, &OptimizationOptions::default()).is_err());
    let empty = Image::filled(0, 0, Rgb::ZERO);
    assert!(irradiance_optimization(&empty, 4, &OptimizationOptions::default()).is_err());
    assert!(fit_hemispheres(&empty, 4, &OptimizationOptions::default()).is_err());
    let no_columns = Image::filled(0, 8, Rgb::ZERO);
    assert!(fit_hemispheres(&no_columns, 4, &OptimizationOptions::default()).is_err());
    // A black probe: nothing to fit, zero lights, converged.
    let black = Image::filled(16, 8, Rgb::ZERO);
    let fit = irradiance_optimization(&black, 4, &OptimizationOptions::default()).unwrap();
    assert_eq!(fit.set.lights.len(), 4);
    assert!(fit.set.total_power().iter().all(|&p| p == 0.0));
    // NaN and negative pixels count as 0.
    let mut odd = Image::filled(32, 16, Rgb::new(1.0, 1.0, 1.0));
    *odd.get_mut(3, 3) = Rgb::new(f32::NAN, -5.0, f32::INFINITY);
    let fit = irradiance_optimization(&odd, 4, &OptimizationOptions::default()).unwrap();
    assert!(fit.set.lights.iter().all(|l| {
        l.irradiance
            .to_array()
            .iter()
            .all(|v| v.is_finite() && *v >= 0.0)
    }));
}

#[test]
fn bundled_probes_converge_and_score_within_bounds() {
    // Bounds are the measured values (printed) with about 25 % headroom, rounded up.
    // (probe, N, mean_err% bound, max_err% bound)
    let bounds: &[(&str, usize, f64, f64)] = &[
        ("apartment", 16, 1.1, 5.0),
        ("apartment", 64, 0.2, 1.2),
        ("esplanade", 16, 0.9, 4.3),
        ("esplanade", 64, 0.14, 0.9),
        ("night", 16, 1.2, 5.5),
        ("night", 64, 0.2, 1.1),
        ("sky", 16, 0.55, 3.0),
        ("sky", 64, 0.12, 1.0),
        ("sunset", 16, 1.2, 6.5),
        ("sunset", 64, 0.2, 1.25),
    ];
    for (name, probe) in probes() {
        for n in [1usize, 3, 16, 64] {
            let t = Instant::now();
            let (mean, max, fit) = score(&probe, n);
            let r = &fit.report;
            println!(
                "{name:10} N={n:3}: mean {mean:7.3} %  max {max:7.3} %  iterations {:3} (all levels {:4})  cost {:.3e} -> {:.3e}  {:.2} s",
                r.iterations,
                r.total_iterations,
                r.initial_cost,
                r.final_cost,
                t.elapsed().as_secs_f64()
            );
            assert_eq!(fit.set.lights.len(), n);
            assert!(r.converged, "{name} N={n} did not converge");
            assert!(r.final_cost <= r.initial_cost);
            for l in &fit.set.lights {
                // Directions are renormalised after every step: unit to f64 rounding (1e-16); 1e-9
                // leaves room for the tangent-plane update.
                assert!((l.direction.length() - 1.0).abs() < 1e-9);
                assert!(
                    l.irradiance
                        .to_array()
                        .iter()
                        .all(|v| v.is_finite() && *v >= 0.0)
                );
            }
            if let Some(&(_, _, mb, xb)) = bounds.iter().find(|b| b.0 == name && b.1 == n) {
                assert!(
                    mean <= mb && max <= xb,
                    "{name} N={n}: {mean} > {mb} or {max} > {xb}"
                );
            }
        }
    }
}

#[test]
fn fit_irradiance_refuses_normals_that_do_not_cover_the_sphere() {
    // The step model assumes evenly spread normals: a hemisphere, too few normals or a
    // non-unit normal is refused with a message, never fitted badly.
    let all = fibonacci_normals(2000);
    let target = |normals: &[DVec3]| -> Vec<[f64; 3]> {
        normals
            .iter()
            .map(|n| [2.0 * n.y.max(0.0) + 0.5 * n.x.max(0.0); 3])
            .collect()
    };
    let hemisphere: Vec<DVec3> = all.iter().copied().filter(|n| n.y > 0.0).collect();
    let options = OptimizationOptions::default();
    let err = fit_irradiance(hemisphere.clone(), target(&hemisphere), 4, &options).unwrap_err();
    assert!(err.to_string().contains("cover the sphere evenly"), "{err}");
    let few = fibonacci_normals(32);
    assert!(fit_irradiance(few.clone(), target(&few), 4, &options).is_err());
    let mut scaled = all.clone();
    scaled[7] *= 2.0;
    let err = fit_irradiance(scaled.clone(), target(&scaled), 4, &options).unwrap_err();
    assert!(err.to_string().contains("normal 7"), "{err}");
    // Evenly spread normals of any count fit: the target is exactly two lights.
    let fit = fit_irradiance(all.clone(), target(&all), 2, &options).unwrap();
    assert!(fit.report.converged);
    assert!(fit.report.fit_mean_abs_err_pct < 0.01, "{:?}", fit.report);
}

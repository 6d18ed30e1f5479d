//! Bracket alignment (median threshold bitmaps) and ghost weights on a synthetic bracket toned
//! from `assets/probes/apartment.exr`: a 256 x 128 crop with detail, 5 exposures 2 stops apart,
//! `code = round(255 (L t)^(1 / 2.2))` so the inverted response is `X(z) = (z / 255)^2.2`.

use std::path::Path;
use std::sync::OnceLock;

use ibl_capture::CaptureError;
use ibl_capture::align::{AlignOptions, Shift, align_bracket, align_to, apply_shift};
use ibl_capture::ghost::{GhostOptions, ghost_weights, reference_exposure};
use ibl_core::{Image, Rgb};
use rand::{Rng, SeedableRng};

const CROP_X: i32 = 128;
const CROP_Y: i32 = 96;
const W: usize = 256;
const H: usize = 128;
const GAMMA: f32 = 2.2;

fn probe() -> &'static Image<Rgb> {
    static PROBE: OnceLock<Image<Rgb>> = OnceLock::new();
    PROBE.get_or_init(|| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/probes/apartment.exr");
        ibl_io::read_image(&path)
            .expect("the bundled probe loads")
            .image
    })
}

fn luminance(p: &Rgb) -> f32 {
    0.2126 * p.r + 0.7152 * p.g + 0.0722 * p.b
}

/// Exposure times in seconds: 4^(k - 2) / 30, k = 0..5 (2 stops apart, middle 1/30 s).
fn times_s() -> Vec<f32> {
    (0..5).map(|k| 4f32.powi(k - 2) / 30.0).collect()
}

/// Radiance scale putting the crop's median luminance at 18 % of full scale in the middle
/// exposure (code 117).
fn radiance_scale() -> f32 {
    let p = probe();
    let mut lum: Vec<f32> = (0..H)
        .flat_map(|y| (0..W).map(move |x| (x, y)))
        .map(|(x, y)| luminance(p.get(CROP_X as usize + x, CROP_Y as usize + y)))
        .collect();
    lum.sort_by(f32::total_cmp);
    0.18 / (lum[lum.len() / 2] * times_s()[2])
}

fn code(value: f32) -> u8 {
    (255.0 * value.clamp(0.0, 1.0).powf(1.0 / GAMMA)).round() as u8
}

/// Exposure `k` of the crop with its content displaced by `shift` (`image(x + dx, y + dy) =
/// unshifted(x, y)`), read from the probe so every pixel is real data.
fn exposure(k: usize, shift: Shift) -> Image<[u8; 3]> {
    let p = probe();
    let scale = radiance_scale() * times_s()[k];
    let (x0, y0) = (CROP_X - shift.dx, CROP_Y - shift.dy);
    Image::from_fn_par(W, H, |x, y| {
        let l = p.get((x0 + x as i32) as usize, (y0 + y as i32) as usize);
        [code(l.r * scale), code(l.g * scale), code(l.b * scale)]
    })
}

/// `image` with independent noise of -1, 0 or +1 code on every channel (clamped to 0..=255),
/// standing in for sensor noise.
fn with_noise(mut image: Image<[u8; 3]>, seed: u64) -> Image<[u8; 3]> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    for z in image.pixels_mut().iter_mut().flatten() {
        *z = z.saturating_add_signed(rng.random_range(-1i8..=1));
    }
    image
}

fn inverse_gamma(_channel: usize, z: u8) -> f32 {
    (f32::from(z) / 255.0).powf(GAMMA)
}

fn shift(dx: i32, dy: i32) -> Shift {
    Shift { dx, dy }
}

#[test]
fn align_bracket_recovers_known_shifts_exactly() {
    let shifts = [
        shift(7, -3),
        shift(-12, 5),
        shift(0, 0),
        shift(3, 9),
        shift(-5, -11),
    ];
    let bracket: Vec<_> = shifts
        .iter()
        .enumerate()
        .map(|(k, &s)| with_noise(exposure(k, s), k as u64))
        .collect();
    let found = align_bracket(&bracket, &AlignOptions::default()).unwrap();
    assert_eq!(found, shifts);
    // Each image against the reference directly, and the reverse direction.
    for (k, &s) in shifts.iter().enumerate() {
        let options = AlignOptions::default();
        assert_eq!(align_to(&bracket[2], &bracket[k], &options).unwrap(), s);
        let back = align_to(&bracket[k], &bracket[2], &options).unwrap();
        assert_eq!(back, shift(-s.dx, -s.dy), "exposure {k}");
    }
}

#[test]
fn max_levels_bounds_the_search() {
    // 0 halvings: only +-1 pixel is reachable, so a shift of (7, -3) cannot be found; 2 halvings
    // reach 7 pixels.
    let reference = exposure(2, shift(0, 0));
    let moved = exposure(2, shift(7, -3));
    let found = align_to(&reference, &moved, &AlignOptions { max_levels: 0 }).unwrap();
    assert!(found.dx.abs() <= 1 && found.dy.abs() <= 1, "{found:?}");
    let found = align_to(&reference, &moved, &AlignOptions { max_levels: 2 }).unwrap();
    assert_eq!(found, shift(7, -3));
}

#[test]
fn apply_shift_undoes_the_displacement_and_marks_the_border() {
    let s = shift(-12, 5);
    let unshifted = exposure(1, shift(0, 0));
    let moved = exposure(1, s);
    let (aligned, valid) = apply_shift(&moved, s);
    let mut invalid = 0;
    for y in 0..H {
        for x in 0..W {
            if *valid.get(x, y) {
                assert_eq!(aligned.get(x, y), unshifted.get(x, y), "pixel ({x}, {y})");
            } else {
                invalid += 1;
                // Nearest edge pixel of the moved image.
                let cx = (x as i32 + s.dx).clamp(0, W as i32 - 1) as usize;
                let cy = (y as i32 + s.dy).clamp(0, H as i32 - 1) as usize;
                assert_eq!(aligned.get(x, y), moved.get(cx, cy));
            }
        }
    }
    // 12 columns and 5 rows shifted in, their 12 x 5 corner counted once.
    assert_eq!(invalid, 12 * H + 5 * W - 12 * 5);
}

#[test]
fn flat_noise_and_tiny_images_give_zero_shift() {
    let options = AlignOptions::default();
    let flat = Image::filled(W, H, [90u8, 90, 90]);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let noise = Image::from_vec(
        W,
        H,
        (0..W * H)
            .map(|_| [rng.random(), rng.random(), rng.random()])
            .collect(),
    )
    .unwrap();
    assert_eq!(align_to(&flat, &flat, &options).unwrap(), shift(0, 0));
    assert_eq!(align_to(&noise, &noise, &options).unwrap(), shift(0, 0));
    // A flat image has no pixel outside the exclusion band: nothing to compare, shift 0.
    assert_eq!(align_to(&flat, &noise, &options).unwrap(), shift(0, 0));
    assert_eq!(align_to(&noise, &flat, &options).unwrap(), shift(0, 0));
    let tiny = Image::filled(3, 2, [10u8, 200, 30]);
    assert_eq!(
        align_bracket(&[tiny.clone(), tiny], &options).unwrap(),
        vec![shift(0, 0); 2]
    );
}

#[test]
fn mismatched_or_empty_inputs_are_invalid() {
    let options = AlignOptions::default();
    let a = Image::filled(W, H, [0u8; 3]);
    let b = Image::filled(W - 1, H, [0u8; 3]);
    let empty = Image::filled(0, 0, [0u8; 3]);
    assert!(matches!(
        align_to(&a, &b, &options),
        Err(CaptureError::Invalid(_))
    ));
    assert!(matches!(
        align_bracket(&[a.clone(), a.clone(), b.clone()], &options),
        Err(CaptureError::Invalid(_))
    ));
    assert!(matches!(
        align_bracket(&[], &options),
        Err(CaptureError::Invalid(_))
    ));
    assert!(matches!(
        align_to(&empty, &empty, &options),
        Err(CaptureError::Invalid(_))
    ));

    let ghost = GhostOptions::default();
    let pair = [a.clone(), b];
    assert!(matches!(
        ghost_weights(&pair, &[1.0, 2.0], &inverse_gamma, &ghost),
        Err(CaptureError::Invalid(_))
    ));
    let pair = [a.clone(), a];
    for times in [&[1.0][..], &[1.0, 0.0], &[1.0, f32::NAN]] {
        assert!(matches!(
            ghost_weights(&pair, times, &inverse_gamma, &ghost),
            Err(CaptureError::Invalid(_))
        ));
    }
    assert!(matches!(
        ghost_weights(&[], &[], &inverse_gamma, &ghost),
        Err(CaptureError::Invalid(_))
    ));
    let narrow = GhostOptions {
        dark_code: 100,
        bright_code: 101,
        ..ghost
    };
    assert!(matches!(
        ghost_weights(&pair, &[1.0, 2.0], &inverse_gamma, &narrow),
        Err(CaptureError::Parameter(_))
    ));
    let nan_response = |_: usize, _: u8| f32::NAN;
    assert!(matches!(
        ghost_weights(&pair, &[1.0, 2.0], &nan_response, &ghost),
        Err(CaptureError::Parameter(_))
    ));
}

/// Two one-pixel exposures, linear response `X(z) = z`, equal times, no extra noise, no
/// smoothing: code 100 (the reference, index 0 on a tie) against code `z`. Sigmas are one code's
/// relative width, `1 / z`, so the gap in sigmas is `ln(z / 100) / hypot(1 / 100, 1 / z)`.
#[test]
fn ghost_weight_follows_the_documented_ramp() {
    let options = GhostOptions {
        relative_noise: 0.0,
        smoothing_radius: 0,
        ..GhostOptions::default()
    };
    let linear = |_: usize, z: u8| f32::from(z);
    for z in [100u8, 104, 106, 108, 110, 90] {
        let images = [Image::filled(1, 1, [100u8; 3]), Image::filled(1, 1, [z; 3])];
        let weights = ghost_weights(&images, &[1.0, 1.0], &linear, &options).unwrap();
        let zf = f64::from(z);
        let k = (zf / 100.0).ln().abs() / (0.01f64).hypot(1.0 / zf);
        let expected = ((6.0 - k) / 3.0).clamp(0.0, 1.0);
        assert_eq!(*weights[0].get(0, 0), 1.0);
        let got = f64::from(*weights[1].get(0, 0));
        assert!(
            (got - expected).abs() < 1e-4,
            "z {z}: {got} vs {expected} (k {k})"
        );
    }
}

/// Pastes a `[x0, x0 + w) x [y0, y0 + h)` rectangle of `value` into `image`.
fn paste(image: &mut Image<[u8; 3]>, rect: (usize, usize, usize, usize), value: [u8; 3]) {
    let (x0, y0, w, h) = rect;
    for y in y0..y0 + h {
        for x in x0..x0 + w {
            *image.get_mut(x, y) = value;
        }
    }
}

fn mean_weight(weights: &Image<f32>, inside: impl Fn(usize, usize) -> bool) -> f32 {
    let mut sum = 0.0;
    let mut count = 0;
    for y in 0..weights.height() {
        for x in 0..weights.width() {
            if inside(x, y) {
                sum += *weights.get(x, y);
                count += 1;
            }
        }
    }
    sum / count as f32
}

#[test]
fn ghost_weights_reject_moving_rectangles_only() {
    let mut bracket: Vec<_> = (0..5)
        .map(|k| with_noise(exposure(k, shift(0, 0)), 10 + k as u64))
        .collect();
    let times = times_s();
    // The reference is the exposure with the most pixels in codes 26..=229; the objects go
    // into the others.
    let reference = reference_exposure(&bracket).unwrap();
    println!("reference exposure {reference}");
    // A white (saturated) object in the darkest exposure, a black one in the brightest, a
    // mid-grey one in exposure 3: (exposure, rectangle (x, y, w, h), code).
    let objects = [
        (0, (40, 30, 24, 16), [255u8; 3]),
        (4, (150, 70, 30, 20), [0u8; 3]),
        (3, (200, 20, 20, 20), [128u8, 128, 128]),
    ];
    for &(k, rect, value) in &objects {
        assert_ne!(k, reference);
        paste(&mut bracket[k], rect, value);
    }
    let options = GhostOptions::default();
    let weights = ghost_weights(&bracket, &times, &inverse_gamma, &options).unwrap();
    assert_eq!(weights.len(), 5);
    assert!(weights[reference].pixels().iter().all(|&w| w == 1.0));
    for (k, w) in weights.iter().enumerate() {
        assert!(w.pixels().iter().all(|v| (0.0..=1.0).contains(v)));
        match objects.iter().find(|o| o.0 == k) {
            Some(&(_, (x0, y0, rw, rh), _)) => {
                let inside = mean_weight(w, |x, y| {
                    (x0..x0 + rw).contains(&x) && (y0..y0 + rh).contains(&y)
                });
                // Away from it: beyond the filters' reach of 2 r = 4 pixels (+ 2 spare).
                let margin = 2 * options.smoothing_radius + 2;
                let away = mean_weight(w, |x, y| {
                    x + margin < x0
                        || x >= x0 + rw + margin
                        || y + margin < y0
                        || y >= y0 + rh + margin
                });
                println!("exposure {k}: inside {inside:.4}, away {away:.4}");
                assert!(inside < 0.1, "exposure {k}: mean weight inside {inside}");
                assert!(away > 0.95, "exposure {k}: mean weight away {away}");
            }
            None => {
                let all = mean_weight(w, |_, _| true);
                println!("exposure {k}: mean {all:.4}");
                assert!(all > 0.95, "exposure {k}: mean weight {all}");
            }
        }
    }
}

//! Fisheye pairs: lens images rendered from the bundled `apartment` probe (lat-long -> 195-degree
//! equidistant fisheye with `ibl_mapping::resample`) are stitched back into the probe, as a pair
//! and as one dual frame, with and without a back-lens misalignment; a real Gear 360 frame
//! (`assets/fisheye`) stitches plausibly.

#![allow(clippy::unwrap_used)] // tests may panic

use std::path::Path;

use ibl_capture::CaptureError;
use ibl_capture::fisheye::{FisheyeOptions, stitch_fisheye_pair};
use ibl_core::glam::Mat3;
use ibl_core::{EulerDegrees, Image, Rgb};
use ibl_mapping::{Mapping, resample};

const FOV: f32 = 195.0;
/// Side of each rendered lens image (finer than the probe: a 195-degree circle of 512 pixels
/// has 0.94 pixels per probe texel).
const LENS: usize = 384;

fn asset(path: &str) -> Image<Rgb> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets")
        .join(path);
    ibl_io::read_image(&path).unwrap().image
}

/// A fisheye image of `env` through a lens with `world_from_lens` (resample wants the
/// destination world, the lens, from the source world: its transpose).
fn lens_image(env: &Image<Rgb>, world_from_lens: Mat3) -> Image<Rgb> {
    resample(
        env,
        Mapping::LatLong,
        Mapping::Fisheye { fov_deg: FOV },
        LENS,
        LENS,
        world_from_lens.transpose(),
        &|_, _| {},
    )
    .unwrap()
}

fn back_pose(error: EulerDegrees) -> Mat3 {
    Mat3::from_rotation_y(std::f32::consts::PI) * error.world_from_probe()
}

fn options(width: usize) -> FisheyeOptions {
    FisheyeOptions {
        fov_deg: FOV,
        width,
        ..Default::default()
    }
}

/// Relative mean absolute error of luminance, solid-angle weighted:
/// `sum |Y_a - Y_b| dOmega / sum Y_b dOmega`.
fn relative_mae(a: &Image<Rgb>, b: &Image<Rgb>) -> f64 {
    ibl_metrics::relative_luminance_mae(a, b, None).expect("comparable probes")
}

/// The two lens images side by side: a dual-fisheye frame.
fn side_by_side(front: &Image<Rgb>, back: &Image<Rgb>) -> Image<Rgb> {
    let h = front.height();
    Image::from_fn_par(2 * h, h, |i, j| {
        if i < h {
            *front.get(i, j)
        } else {
            *back.get(i - h, j)
        }
    })
}

#[test]
fn a_pair_and_a_dual_frame_reassemble_the_probe() {
    let env = asset("probes/apartment.exr");
    let front = lens_image(&env, Mat3::IDENTITY);
    let back = lens_image(&env, back_pose(EulerDegrees::default()));
    let pair = stitch_fisheye_pair(&front, Some(&back), options(512)).unwrap();
    assert_eq!((pair.width(), pair.height()), (512, 256));
    let err = relative_mae(&pair, &env);
    println!("pair: relative MAE of luminance {:.2} %", 100.0 * err);
    assert!(err < 0.04, "{err}");
    // At a quarter of the cost (256 x 128): the same lenses in one 2:1 frame stitch to exactly
    // the same map, and a hard seam changes it little (the lenses agree where they overlap).
    let small = stitch_fisheye_pair(&front, Some(&back), options(256)).unwrap();
    let dual = stitch_fisheye_pair(&side_by_side(&front, &back), None, options(256)).unwrap();
    assert_eq!(dual, small);
    let hard = FisheyeOptions {
        blend_deg: 0.0,
        ..options(256)
    };
    let seam_change = relative_mae(
        &stitch_fisheye_pair(&front, Some(&back), hard).unwrap(),
        &small,
    );
    println!(
        "hard seam vs 10-degree feather: {:.4} %",
        100.0 * seam_change
    );
    assert!(seam_change < 0.01, "{seam_change}");
}

#[test]
fn a_back_lens_rotation_is_undone() {
    let env = asset("probes/apartment.exr");
    let error = EulerDegrees {
        yaw_deg: 2.0,
        pitch_deg: -1.5,
        roll_deg: 3.0,
    };
    let front = lens_image(&env, Mat3::IDENTITY);
    let back = lens_image(&env, back_pose(error));
    let corrected = FisheyeOptions {
        back_rotation: error,
        ..options(512)
    };
    let err = relative_mae(
        &stitch_fisheye_pair(&front, Some(&back), corrected).unwrap(),
        &env,
    );
    let err_ignored = relative_mae(
        &stitch_fisheye_pair(&front, Some(&back), options(512)).unwrap(),
        &env,
    );
    println!(
        "rotated back lens: relative MAE {:.2} % corrected, {:.2} % ignored",
        100.0 * err,
        100.0 * err_ignored
    );
    assert!(err < 0.04, "{err}");
    assert!(err_ignored > 2.0 * err, "{err_ignored} vs {err}");
}

#[test]
fn bad_sizes_and_fields_of_view_are_refused() {
    let square = Image::filled(64, 64, Rgb::ONE);
    let other = Image::filled(32, 32, Rgb::ONE);
    let wide = Image::filled(128, 64, Rgb::ONE);
    let odd = Image::filled(100, 64, Rgb::ONE);
    let ok = options(64);
    assert!(stitch_fisheye_pair(&square, Some(&square), ok).is_ok());
    assert!(stitch_fisheye_pair(&wide, None, ok).is_ok());
    let invalid = |r: Result<Image<Rgb>, CaptureError>| matches!(r, Err(CaptureError::Invalid(_)));
    let parameter =
        |r: Result<Image<Rgb>, CaptureError>| matches!(r, Err(CaptureError::Parameter(_)));
    assert!(invalid(stitch_fisheye_pair(&square, Some(&other), ok)));
    assert!(invalid(stitch_fisheye_pair(&wide, Some(&wide), ok)));
    assert!(invalid(stitch_fisheye_pair(&odd, None, ok)));
    assert!(invalid(stitch_fisheye_pair(&square, None, ok)));
    for fov_deg in [180.0, 170.0, 360.5, f32::NAN] {
        let bad = FisheyeOptions { fov_deg, ..ok };
        assert!(
            parameter(stitch_fisheye_pair(&wide, None, bad)),
            "{fov_deg}"
        );
    }
    assert!(
        stitch_fisheye_pair(
            &wide,
            None,
            FisheyeOptions {
                fov_deg: 360.0,
                ..ok
            }
        )
        .is_ok()
    );
    for blend_deg in [-1.0, 15.5, f32::INFINITY] {
        let bad = FisheyeOptions { blend_deg, ..ok };
        assert!(
            parameter(stitch_fisheye_pair(&wide, None, bad)),
            "{blend_deg}"
        );
    }
    let tilted = FisheyeOptions {
        back_rotation: EulerDegrees {
            pitch_deg: 20.0,
            ..Default::default()
        },
        ..ok
    };
    assert!(parameter(stitch_fisheye_pair(&wide, None, tilted)));
    let zero = FisheyeOptions { width: 1, ..ok };
    assert!(parameter(stitch_fisheye_pair(&wide, None, zero)));
}

#[test]
fn a_real_gear360_frame_stitches_plausibly() {
    let frame = asset("fisheye/dual_fisheye_frame_2560x1280.png");
    assert_eq!((frame.width(), frame.height()), (2560, 1280));
    // Halved (2 x 2 box) to keep the test fast: 640-pixel circles of 195 degrees still hold
    // 1.15 pixels per texel of a 1024-wide panorama.
    let half = Image::from_fn_par(1280, 640, |i, j| {
        (*frame.get(2 * i, 2 * j)
            + *frame.get(2 * i + 1, 2 * j)
            + *frame.get(2 * i, 2 * j + 1)
            + *frame.get(2 * i + 1, 2 * j + 1))
            * 0.25
    });
    let pano = stitch_fisheye_pair(&half, None, options(1024)).unwrap();
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("gear360_stitched.png");
    ibl_io::write_image(&out, &pano, &Default::default()).unwrap();
    println!("stitched frame written to {}", out.display());
    assert_eq!((pano.width(), pano.height()), (1024, 512));
    assert!(pano.pixels().iter().all(|c| c.is_valid_radiance()));
    // Mean luminance of a column over the rows 10 % to 90 % of the height.
    let column = |i: usize| {
        (51..461)
            .map(|j| f64::from(pano.get(i, j).luminance()))
            .sum::<f64>()
            / 410.0
    };
    // The seams are the planes z = 0 of the lenses: columns 256 (-X) and 768 (+X). The two
    // columns either side of each seam must continue their neighbours 8 pixels (2.8 degrees)
    // further out.
    for seam in [256, 768] {
        let at_seam = 0.5 * (column(seam - 1) + column(seam));
        let beside = 0.5 * (column(seam - 9) + column(seam + 8));
        let jump = (at_seam / beside - 1.0).abs();
        println!(
            "seam at column {seam}: {at_seam:.4} vs {beside:.4} beside ({:.1} %)",
            100.0 * jump
        );
        assert!(jump < 0.1, "{seam}: {at_seam} vs {beside}");
    }
    // Sky above, pavement below.
    let rows = |range: std::ops::Range<usize>| {
        let n = (range.len() * 1024) as f64;
        range
            .flat_map(|j| (0..1024).map(move |i| (i, j)))
            .map(|(i, j)| f64::from(pano.get(i, j).luminance()))
            .sum::<f64>()
            / n
    };
    let (sky, ground) = (rows(0..128), rows(384..512));
    println!("mean luminance: top quarter {sky:.4}, bottom quarter {ground:.4}");
    assert!(sky > 1.5 * ground, "{sky} vs {ground}");
}

//! The golden helper: bless, match, mismatch with failure images, missing golden, both formats.

use ibl_core::{Image, Rgb};
use ibl_golden::{GoldenError, Goldens, Metric, Mode, Outcome};

fn ramp(bright: f32) -> Image<Rgb> {
    Image::from_fn_par(16, 8, |x, y| {
        Rgb::new(x as f32 / 16.0 * bright, y as f32 / 8.0, 0.25)
    })
}

fn goldens(dir: &std::path::Path, mode: Mode) -> Goldens {
    Goldens {
        mode,
        failures: dir.join("failures"),
    }
}

#[test]
fn bless_then_match_then_fail_with_images() {
    let dir = tempfile::tempdir().expect("tempdir");
    for golden in [dir.path().join("g/ramp.exr"), dir.path().join("g/ramp.png")] {
        let missing = goldens(dir.path(), Mode::Compare).check(
            "ramp",
            &ramp(1.0),
            &golden,
            Metric::MaxAbs(0.0),
        );
        assert!(matches!(missing, Err(GoldenError::Missing { .. })));
        let blessed = goldens(dir.path(), Mode::Bless)
            .check("ramp", &ramp(1.0), &golden, Metric::MaxAbs(0.0))
            .expect("blesses");
        assert_eq!(blessed, Outcome::Blessed);
        // The same image matches exactly: EXR stores f32 as is, PNG stores 8-bit codes and the
        // check compares the image as a PNG would store it.
        let matched = goldens(dir.path(), Mode::Compare)
            .check("ramp", &ramp(1.0), &golden, Metric::MaxAbs(0.0))
            .expect("matches");
        assert_eq!(matched, Outcome::Matched(0.0));
        // Red times 1.5: at x = 10 the red is 0.9375 against 0.625 (under the PNG's clip at 1), a
        // difference of 0.3125 in linear light (8-bit rounding moves it by under 0.01): far over
        // the threshold 0.01 in both formats.
        let err = goldens(dir.path(), Mode::Compare)
            .check("ramp", &ramp(1.5), &golden, Metric::MaxAbs(0.01))
            .expect_err("differs");
        match err {
            GoldenError::Mismatch {
                value, failures, ..
            } => {
                assert!(value > 0.01, "{value}");
                let ext = golden.extension().and_then(|e| e.to_str()).unwrap_or("");
                for f in [
                    format!("actual.{ext}"),
                    format!("expected.{ext}"),
                    "difference.exr".into(),
                ] {
                    assert!(failures.join(&f).is_file(), "{f}");
                }
            }
            other => panic!("expected a mismatch, got {other}"),
        }
        // FLIP and relative MSE as metrics: the same image scores 0.
        for metric in [Metric::MeanFlip(1e-6), Metric::RelativeMse(1e-12)] {
            assert_eq!(
                goldens(dir.path(), Mode::Compare)
                    .check("ramp", &ramp(1.0), &golden, metric)
                    .expect("matches"),
                Outcome::Matched(0.0)
            );
        }
    }
}

#[test]
fn a_different_size_is_incomparable() {
    let dir = tempfile::tempdir().expect("tempdir");
    let golden = dir.path().join("g.exr");
    goldens(dir.path(), Mode::Bless)
        .check("g", &ramp(1.0), &golden, Metric::MaxAbs(0.0))
        .expect("blesses");
    let small = Image::filled(4, 4, Rgb::ONE);
    let err = goldens(dir.path(), Mode::Compare).check("g", &small, &golden, Metric::MaxAbs(0.0));
    assert!(matches!(err, Err(GoldenError::Incomparable { .. })));
}

//! Image goldens for tests (the renderer's, the viewer's screenshots): an image is compared with a
//! stored golden by a stated [`Metric`] and threshold; a missing golden fails; goldens change only
//! when the test runs with `IBL_BLESS=1` (explicitly, never on a mismatch); a failed comparison
//! writes the image, the golden and their difference under `target/golden-failures/<name>/`.
//!
//! Goldens are files in any format `ibl-io` reads and writes losslessly: `.exr` (float, ZIP) for
//! linear HDR images, `.png` for 8-bit pictures (compared in linear light after sRGB decoding; an
//! 8-bit code survives the round trip exactly). Every check reports the metric's value so a test
//! can print it next to its threshold.

use std::path::{Path, PathBuf};

use ibl_core::tonemap::{Display, ToneCurve};
use ibl_core::{Image, Rgb};
use ibl_io::{IoError, WriteOptions};
use ibl_metrics::{DifferenceError, FlipOptions, FlipRange, ImageDifference};

/// Environment variable that makes [`check`] write goldens instead of comparing.
pub const BLESS_VAR: &str = "IBL_BLESS";

/// Environment variable naming the folder for failure images (default
/// `<workspace>/target/golden-failures`).
pub const FAILURES_VAR: &str = "IBL_GOLDEN_FAILURES";

/// How an image is compared with its golden, and the largest value that passes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Metric {
    /// Mean FLIP (LDR mode for `.png` goldens, HDR otherwise) at most this.
    MeanFlip(f64),
    /// Relative MSE `mean (a - b)^2 / (b^2 + 0.01)` at most this.
    RelativeMse(f64),
    /// Largest absolute channel difference at most this (image units; 0 for bit-exact up to the
    /// file's precision).
    MaxAbs(f64),
}

impl Metric {
    /// The threshold.
    pub fn threshold(self) -> f64 {
        match self {
            Metric::MeanFlip(t) | Metric::RelativeMse(t) | Metric::MaxAbs(t) => t,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Metric::MeanFlip(_) => "mean FLIP",
            Metric::RelativeMse(_) => "relative MSE",
            Metric::MaxAbs(_) => "max |a - b|",
        }
    }
}

/// What a check did.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// The image matches its golden: the metric's value (at most the threshold).
    Matched(f64),
    /// `IBL_BLESS` was set: the golden was written.
    Blessed,
}

/// Why a check failed.
#[derive(Debug, thiserror::Error)]
pub enum GoldenError {
    /// No golden yet.
    #[error("{}: no golden image; run the test with {BLESS_VAR}=1 to create it", path.display())]
    Missing {
        /// Where the golden should be.
        path: PathBuf,
    },
    /// The image differs from its golden beyond the threshold.
    #[error(
        "{name}: {metric} {value:.6e} is over the threshold {threshold:.6e}; the image, the golden \
         and their difference are in {}; if the change is meant, rerun with {BLESS_VAR}=1",
        failures.display()
    )]
    Mismatch {
        /// The golden's name.
        name: String,
        /// The metric.
        metric: &'static str,
        /// Its value.
        value: f64,
        /// The threshold.
        threshold: f64,
        /// Where the failure images went.
        failures: PathBuf,
    },
    /// The image cannot be compared with the golden (a different size).
    #[error("{}: {source}", path.display())]
    Incomparable {
        /// The golden.
        path: PathBuf,
        /// Why.
        source: DifferenceError,
    },
    /// Reading or writing a file.
    #[error(transparent)]
    Io(#[from] IoError),
}

/// Whether the golden is an 8-bit picture.
fn is_ldr(path: &Path) -> bool {
    matches!(
        ibl_io::ImageFormat::from_path(path),
        Some(ibl_io::ImageFormat::Png | ibl_io::ImageFormat::Jpeg)
    )
}

/// Writes `image` losslessly for `path`'s format (8-bit sRGB without tone mapping for `.png`).
fn write(path: &Path, image: &Image<Rgb>) -> Result<(), IoError> {
    let options = WriteOptions {
        display: Display {
            exposure_stops: 0.0,
            curve: ToneCurve::Clamp,
        },
        ..WriteOptions::default()
    };
    ibl_io::write_image(path, image, &options)
}

/// Whether a check compares or writes the golden.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Compare with the stored golden; a missing golden fails.
    Compare,
    /// Write the golden (`IBL_BLESS=1`).
    Bless,
}

/// Where failure images go and whether goldens are compared or written.
#[derive(Clone, Debug, PartialEq)]
pub struct Goldens {
    /// Compare or bless.
    pub mode: Mode,
    /// Folder of failure images (one sub-folder per failed check).
    pub failures: PathBuf,
}

impl Goldens {
    /// From the environment: blessing when `IBL_BLESS=1`; failures in `$IBL_GOLDEN_FAILURES`,
    /// else `target/golden-failures` of the workspace (the nearest folder above the current one
    /// that holds a `Cargo.lock`).
    pub fn from_env() -> Goldens {
        let mode = if std::env::var_os(BLESS_VAR).is_some_and(|v| v == "1") {
            Mode::Bless
        } else {
            Mode::Compare
        };
        let failures = match std::env::var_os(FAILURES_VAR) {
            Some(dir) => PathBuf::from(dir),
            None => {
                let cwd = std::env::current_dir().unwrap_or_else(|_| PathBuf::from("."));
                let root = cwd
                    .ancestors()
                    .find(|d| d.join("Cargo.lock").is_file())
                    .unwrap_or(&cwd)
                    .to_path_buf();
                root.join("target").join("golden-failures")
            }
        };
        Goldens { mode, failures }
    }

    /// Compares `image` with the golden at `golden`, or writes it in [`Mode::Bless`]; `name`
    /// names the failure folder.
    pub fn check(
        &self,
        name: &str,
        image: &Image<Rgb>,
        golden: &Path,
        metric: Metric,
    ) -> Result<Outcome, GoldenError> {
        if self.mode == Mode::Bless {
            if let Some(dir) = golden.parent() {
                ibl_io::create_dir_all(dir)?;
            }
            write(golden, image)?;
            return Ok(Outcome::Blessed);
        }
        if !golden.is_file() {
            return Err(GoldenError::Missing {
                path: golden.to_path_buf(),
            });
        }
        let ldr = is_ldr(golden);
        let expected = ibl_io::read_image(golden)?.image;
        // Compare what the golden's format would store of the image: like with like.
        let stored = if ldr {
            as_stored_8bit(image)
        } else {
            image.clone()
        };
        let value = measure(&stored, &expected, metric, ldr).map_err(|source| {
            GoldenError::Incomparable {
                path: golden.to_path_buf(),
                source,
            }
        })?;
        if value <= metric.threshold() {
            return Ok(Outcome::Matched(value));
        }
        let failures = self.failures.join(name);
        ibl_io::create_dir_all(&failures)?;
        let ext = if ldr { "png" } else { "exr" };
        write(&failures.join(format!("actual.{ext}")), image)?;
        write(&failures.join(format!("expected.{ext}")), &expected)?;
        let difference = Image::from_fn_par(expected.width(), expected.height(), |x, y| {
            (*stored.get(x, y) - *expected.get(x, y)).map(f32::abs)
        });
        write(&failures.join("difference.exr"), &difference)?;
        Err(GoldenError::Mismatch {
            name: name.to_string(),
            metric: metric.name(),
            value,
            threshold: metric.threshold(),
            failures,
        })
    }
}

/// `image` as an 8-bit sRGB file would give it back: each channel encoded to a code and decoded.
fn as_stored_8bit(image: &Image<Rgb>) -> Image<Rgb> {
    use ibl_core::tonemap::{linear_to_srgb8, srgb_to_linear};
    image.map(|p| p.map(|c| srgb_to_linear(f32::from(linear_to_srgb8(c)) / 255.0)))
}

/// [`Goldens::check`] with the settings of [`Goldens::from_env`].
pub fn check(
    name: &str,
    image: &Image<Rgb>,
    golden: &Path,
    metric: Metric,
) -> Result<Outcome, GoldenError> {
    Goldens::from_env().check(name, image, golden, metric)
}

/// The metric's value of `image` against `golden`.
fn measure(
    image: &Image<Rgb>,
    golden: &Image<Rgb>,
    metric: Metric,
    ldr: bool,
) -> Result<f64, DifferenceError> {
    Ok(match metric {
        Metric::MeanFlip(_) => {
            let options = FlipOptions {
                range: if ldr { FlipRange::Ldr } else { FlipRange::Hdr },
                ..FlipOptions::default()
            };
            ibl_metrics::flip(image, golden, &options)?.mean()
        }
        Metric::RelativeMse(_) => ImageDifference::between(image, golden, None)?.relative_mse,
        Metric::MaxAbs(_) => ImageDifference::between(image, golden, None)?.max_abs,
    })
}

//! Display transforms: linear radiance to 8-bit sRGB for PNG/JPEG previews, and the sRGB transfer
//! functions used both ways (the EOTF also decodes 8/16-bit PNG and JPEG input to linear).
//!
//! A preview pixel is `round(255 * oetf(curve(L * 2^exposure_stops)))` per channel, where `oetf` is
//! the piecewise sRGB encoding (IEC 61966-2-1) and `curve` one of [`ToneCurve`]. Non-finite and
//! negative values display as black.

use std::sync::LazyLock;

use crate::{Image, Rgb};
use rayon::prelude::*;

/// How exposed linear values above 1 are brought into the displayable range `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ToneCurve {
    /// `min(x, 1)`: exact below 1, hard clip above.
    Clamp,
    /// Per-channel Reinhard `x / (1 + x)`: never clips, compresses highlights smoothly.
    #[default]
    Reinhard,
    /// Narkowicz's 2015 fit of the ACES filmic curve,
    /// `x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)` clamped to `[0, 1]`, applied per channel
    /// to the exposed value as is (no extra 0.6 pre-scale).
    AcesFilmic,
}

impl ToneCurve {
    /// Every curve, in the order the command line lists them.
    pub const ALL: [ToneCurve; 3] = [ToneCurve::Clamp, ToneCurve::Reinhard, ToneCurve::AcesFilmic];

    /// `clamp`, `reinhard` or `aces`, as the command line, the viewer and batch specs name it.
    pub fn name(self) -> &'static str {
        match self {
            ToneCurve::Clamp => "clamp",
            ToneCurve::Reinhard => "reinhard",
            ToneCurve::AcesFilmic => "aces",
        }
    }

    /// The curve [`ToneCurve::name`] names.
    pub fn from_name(name: &str) -> Option<ToneCurve> {
        ToneCurve::ALL.into_iter().find(|c| c.name() == name)
    }

    /// Applies the curve to one exposed linear value (`x >= 0`), giving a value in `[0, 1]`.
    pub fn apply(self, x: f32) -> f32 {
        match self {
            ToneCurve::Clamp => x.min(1.0),
            ToneCurve::Reinhard => x / (1.0 + x),
            ToneCurve::AcesFilmic => {
                // The curve reaches 1 near x = 7.24; capping avoids inf / inf.
                let x = x.min(1.0e4);
                let y = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
                y.clamp(0.0, 1.0)
            }
        }
    }
}

/// A display transform: exposure then tone curve then sRGB encoding.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Display {
    /// Exposure in stops: values are multiplied by `2^exposure_stops` before the curve.
    pub exposure_stops: f32,
    /// The tone curve.
    pub curve: ToneCurve,
}

/// The sRGB encoding (OETF): linear `[0, 1]` to non-linear `[0, 1]`, IEC 61966-2-1.
pub fn linear_to_srgb(x: f32) -> f32 {
    if x <= 0.003_130_8 {
        12.92 * x.max(0.0)
    } else {
        1.055 * x.min(1.0).powf(1.0 / 2.4) - 0.055
    }
}

/// The sRGB decoding (EOTF): non-linear `[0, 1]` to linear `[0, 1]`, IEC 61966-2-1.
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.040_45 {
        v.max(0.0) / 12.92
    } else {
        ((v.min(1.0) + 0.055) / 1.055).powf(2.4)
    }
}

/// `THRESHOLDS[k - 1]` is the smallest linear value whose sRGB code rounds to `k` (1..=255):
/// `srgb_to_linear((k - 0.5) / 255)`. Encoding by binary search over it gives the same code as
/// `round(255 * linear_to_srgb(y))` without a `powf` per channel.
static THRESHOLDS: LazyLock<[f32; 255]> =
    LazyLock::new(|| std::array::from_fn(|i| srgb_to_linear((i as f32 + 0.5) / 255.0)));

/// Linear `[0, 1]` to the nearest 8-bit sRGB code.
pub fn linear_to_srgb8(y: f32) -> u8 {
    encode8(&THRESHOLDS, y)
}

fn encode8(thresholds: &[f32; 255], y: f32) -> u8 {
    // At most 255 thresholds lie below y, so the count fits in a u8.
    thresholds.partition_point(|&t| t <= y) as u8
}

/// One linear radiance channel to an 8-bit display value.
fn display_channel(thresholds: &[f32; 255], v: f32, scale: f32, curve: ToneCurve) -> u8 {
    // `v > 0` is false for NaN too.
    let x = if v > 0.0 { v * scale } else { 0.0 };
    let x = if x.is_finite() { x } else { f32::MAX };
    encode8(thresholds, curve.apply(x))
}

/// Maps linear radiance to 8-bit sRGB with `display` (exposure, curve, sRGB OETF, rounding to
/// nearest), in parallel over rows. Negative, NaN and infinite inputs are treated as 0 (+Inf as
/// the largest float).
pub fn to_srgb8(image: &Image<Rgb>, display: &Display) -> Image<[u8; 3]> {
    let scale = display.exposure_stops.exp2();
    let curve = display.curve;
    let t: &[f32; 255] = &THRESHOLDS;
    let data: Vec<[u8; 3]> = image
        .pixels()
        .par_iter()
        .with_min_len(4096)
        .map(|p| {
            [
                display_channel(t, p.r, scale, curve),
                display_channel(t, p.g, scale, curve),
                display_channel(t, p.b, scale, curve),
            ]
        })
        .collect();
    Image::from_vec(image.width(), image.height(), data)
        .unwrap_or_else(|_| Image::filled(image.width(), image.height(), [0; 3]))
}

/// Middle grey that the log-average luminance is mapped to by [`auto_exposure_stops`].
pub const MIDDLE_GREY: f32 = 0.18;

/// An exposure (in stops) that maps the image's log-average luminance to [`MIDDLE_GREY`] (0.18):
/// `log2(0.18 / exp(mean(ln L)))`, the mean taken over the pixels whose Rec. 709 luminance `L` is
/// finite and positive, every such pixel weighted equally (not by solid angle).
///
/// The logarithm makes a small very bright sun barely move the result, and skipping zeros keeps
/// black borders from dragging it down. The result is clamped to `[-32, 32]` stops; an image with
/// no positive pixel gets 0.
pub fn auto_exposure_stops(image: &Image<Rgb>) -> f32 {
    let (sum, count) = image
        .pixels()
        .par_iter()
        .with_min_len(4096)
        .fold(
            || (0.0f64, 0u64),
            |(s, n), p| {
                let l = p.luminance();
                if l > 0.0 && l.is_finite() {
                    (s + f64::from(l).ln(), n + 1)
                } else {
                    (s, n)
                }
            },
        )
        .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    if count == 0 {
        return 0.0;
    }
    let log_average = (sum / count as f64).exp();
    let stops = (f64::from(MIDDLE_GREY) / log_average).log2();
    stops.clamp(-32.0, 32.0) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_transfer_round_trips() {
        for i in 0..=255 {
            let v = i as f32 / 255.0;
            let back = linear_to_srgb(srgb_to_linear(v));
            assert!((back - v).abs() < 1e-5, "{v} -> {back}");
        }
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
        assert_eq!(srgb_to_linear(0.0), 0.0);
    }

    #[test]
    fn srgb8_lookup_matches_the_formula() {
        for i in 0..=100_000 {
            let y = i as f32 / 100_000.0;
            let direct = (linear_to_srgb(y) * 255.0 + 0.5) as u8;
            let fast = linear_to_srgb8(y);
            assert!(direct.abs_diff(fast) <= 1, "{y}: {direct} vs {fast}");
        }
        for k in 0..=255u8 {
            assert_eq!(linear_to_srgb8(srgb_to_linear(k as f32 / 255.0)), k);
        }
        assert_eq!(linear_to_srgb8(0.5), 188);
        assert_eq!(linear_to_srgb8(1.0), 255);
        assert_eq!(linear_to_srgb8(f32::NAN), 0);
    }

    #[test]
    fn curves_map_zero_to_zero_and_stay_in_range() {
        for c in [ToneCurve::Clamp, ToneCurve::Reinhard, ToneCurve::AcesFilmic] {
            assert_eq!(c.apply(0.0), 0.0);
            for x in [1e-6, 0.5, 1.0, 10.0, 1e30, f32::MAX] {
                let y = c.apply(x);
                assert!((0.0..=1.0).contains(&y), "{c:?}({x}) = {y}");
            }
        }
    }

    #[test]
    fn invalid_values_display_black_or_white() {
        let d = Display {
            exposure_stops: 0.0,
            curve: ToneCurve::Clamp,
        };
        let t = &THRESHOLDS;
        assert_eq!(display_channel(t, f32::NAN, 1.0, d.curve), 0);
        assert_eq!(display_channel(t, -3.0, 1.0, d.curve), 0);
        assert_eq!(display_channel(t, f32::INFINITY, 1.0, d.curve), 255);
        assert_eq!(display_channel(t, f32::MAX, 4.0, ToneCurve::Reinhard), 255);
    }

    #[test]
    fn auto_exposure_of_uniform_image() {
        let img = Image::filled(4, 4, Rgb::splat(0.72));
        assert!((auto_exposure_stops(&img) - (-2.0)).abs() < 1e-5);
        assert_eq!(auto_exposure_stops(&Image::filled(2, 2, Rgb::ZERO)), 0.0);
    }
}

//! Clamping of invalid radiance values, done once by [`crate::read_image`] after decoding.
//!
//! A radiance is never negative and always finite, but real files contain both: lossy EXR
//! compressions (DWAA/DWAB) ring below zero beside bright suns, and renderers leak NaN and Inf.
//! Every downstream sum (irradiance, median cut, SH projection) would be poisoned by one such
//! value, so they are replaced by 0 here and counted, per channel value, so that the tool can say
//! how many it clamped (see `docs/CONVENTIONS.md`, section 4).

use ibl_core::{Image, Rgb};
use rayon::prelude::*;

/// What sanitising did to an image's channel values (each of r, g, b counts separately).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SanitizeReport {
    /// Finite channel values below zero that were set to 0 (`-0.0` is not counted).
    pub negative_values: u64,
    /// NaN, +Inf and -Inf channel values that were set to 0.
    pub nonfinite_values: u64,
    /// Per-channel minimum of the finite values *before* clamping (same unit as the pixels);
    /// 0 for a channel with no finite value at all.
    pub raw_min: Rgb,
}

impl Default for SanitizeReport {
    fn default() -> Self {
        SanitizeReport {
            negative_values: 0,
            nonfinite_values: 0,
            raw_min: Rgb::ZERO,
        }
    }
}

impl SanitizeReport {
    /// Total number of channel values that were changed.
    pub fn clamped_values(&self) -> u64 {
        self.negative_values + self.nonfinite_values
    }

    /// Whether the image needed no clamping.
    pub fn is_clean(&self) -> bool {
        self.clamped_values() == 0
    }

    /// The report of several images read as one (e.g. six cube faces): counts add up, the raw
    /// minimum is the smaller per channel.
    pub fn merged(self, other: SanitizeReport) -> SanitizeReport {
        SanitizeReport {
            negative_values: self.negative_values + other.negative_values,
            nonfinite_values: self.nonfinite_values + other.nonfinite_values,
            raw_min: Rgb::new(
                self.raw_min.r.min(other.raw_min.r),
                self.raw_min.g.min(other.raw_min.g),
                self.raw_min.b.min(other.raw_min.b),
            ),
        }
    }
}

/// Partial counts for one chunk of pixels; `min` starts at +Inf ("no finite value yet").
#[derive(Clone, Copy)]
struct Tally {
    negative: u64,
    nonfinite: u64,
    min: [f32; 3],
}

impl Tally {
    const EMPTY: Tally = Tally {
        negative: 0,
        nonfinite: 0,
        min: [f32::INFINITY; 3],
    };

    fn merge(self, o: Tally) -> Tally {
        Tally {
            negative: self.negative + o.negative,
            nonfinite: self.nonfinite + o.nonfinite,
            min: [
                self.min[0].min(o.min[0]),
                self.min[1].min(o.min[1]),
                self.min[2].min(o.min[2]),
            ],
        }
    }
}

/// Pixels per parallel work item.
const CHUNK: usize = 16 * 1024;

/// Replaces every negative, NaN or infinite channel value by 0, in place and in parallel, and
/// reports how many there were.
pub fn sanitize(image: &mut Image<Rgb>) -> SanitizeReport {
    let tally = image
        .pixels_mut()
        .par_chunks_mut(CHUNK)
        .map(|chunk| {
            let mut t = Tally::EMPTY;
            for px in chunk {
                for (c, v) in [&mut px.r, &mut px.g, &mut px.b].into_iter().enumerate() {
                    if !v.is_finite() {
                        t.nonfinite += 1;
                        *v = 0.0;
                    } else {
                        t.min[c] = t.min[c].min(*v);
                        if *v < 0.0 {
                            t.negative += 1;
                            *v = 0.0;
                        }
                    }
                }
            }
            t
        })
        .reduce(|| Tally::EMPTY, Tally::merge);
    let min = tally.min.map(|m| if m.is_finite() { m } else { 0.0 });
    SanitizeReport {
        negative_values: tally.negative,
        nonfinite_values: tally.nonfinite,
        raw_min: Rgb::from_array(min),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merged_reports_add_counts_and_keep_the_smaller_minimum() {
        let a = SanitizeReport {
            negative_values: 2,
            nonfinite_values: 1,
            raw_min: Rgb::new(0.5, -3.0, 0.25),
        };
        let b = SanitizeReport {
            negative_values: 5,
            nonfinite_values: 0,
            raw_min: Rgb::new(0.125, 1.0, 2.0),
        };
        let m = a.merged(b);
        assert_eq!((m.negative_values, m.nonfinite_values), (7, 1));
        // Two clean positive images keep a positive minimum (not the default's 0).
        assert_eq!(m.raw_min, Rgb::new(0.125, -3.0, 0.25));
    }

    #[test]
    fn clamps_and_counts_per_channel_value() {
        let mut img = Image::from_vec(
            3,
            1,
            vec![
                Rgb::new(-1.0, 2.0, f32::NAN),
                Rgb::new(f32::INFINITY, -0.5, 3.0),
                Rgb::new(0.25, f32::NEG_INFINITY, -0.0),
            ],
        )
        .expect("3 pixels");
        let r = sanitize(&mut img);
        assert_eq!(r.negative_values, 2);
        assert_eq!(r.nonfinite_values, 3);
        assert_eq!(r.clamped_values(), 5);
        assert_eq!(r.raw_min, Rgb::new(-1.0, -0.5, -0.0));
        assert!(img.pixels().iter().all(|p| p.is_valid_radiance()));
        assert_eq!(*img.get(1, 0), Rgb::new(0.0, 0.0, 3.0));
    }

    #[test]
    fn counts_merge_across_parallel_chunks() {
        // Bad values in the first, a middle and the last chunk of a multi-chunk image.
        let n = 3 * CHUNK + 17;
        let mut img = Image::filled(n, 1, Rgb::splat(2.0));
        for (i, v) in [
            (0, -5.0),
            (CHUNK + 3, f32::NAN),
            (n - 1, -0.5),
            (n - 2, f32::INFINITY),
        ] {
            img.get_mut(i, 0).g = v;
        }
        let r = sanitize(&mut img);
        assert_eq!((r.negative_values, r.nonfinite_values), (2, 2));
        assert_eq!(r.raw_min, Rgb::new(2.0, -5.0, 2.0));
    }

    #[test]
    fn clean_and_all_nan_images() {
        let mut clean = Image::filled(300, 200, Rgb::new(1.0, 2.0, 3.0));
        let r = sanitize(&mut clean);
        assert!(r.is_clean());
        assert_eq!(r.raw_min, Rgb::new(1.0, 2.0, 3.0));
        let mut nan = Image::filled(2, 2, Rgb::splat(f32::NAN));
        let r = sanitize(&mut nan);
        assert_eq!(r.nonfinite_values, 12);
        assert_eq!(r.raw_min, Rgb::ZERO);
    }
}

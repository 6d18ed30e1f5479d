//! The dominant compact light of a probe (a sun, a lamp, a window): direction, solid angle,
//! colour and intensity, with a confidence. The hybrid model uses it as its first important light
//! and the outdoor pipeline as its sun.
//!
//! Method: start at the brightest pixel (luminance) and grow the 8-connected region of pixels at
//! least [`THRESHOLD_OF_PEAK`] of its luminance (wrapping around in longitude; across a pole row
//! a pixel touches the whole row). The source is that region: its power `sum L dOmega` (RGB), its
//! solid angle `sum dOmega`, its mean radiance, and its direction the luminance-weighted mean of its
//! pixel directions. Cost O(W H).
//!
//! Confidence in [0, 1]: the source's share of the probe's luminance power, scaled down when the
//! source is not compact (solid angle above [`COMPACT_SOLID_ANGLE_SR`]):
//! `share * min(1, COMPACT / solid_angle)`. A clear-sky sun scores near its share of the light
//! (often 0.5 to 0.9); an overcast sky or a uniform room scores near 0.

use ibl_core::glam::DVec3;
use ibl_core::rgb::Rgb64;
use ibl_core::{Image, LatLong, Rgb, valid_radiance};

use crate::ExtractError;

/// A pixel belongs to the source when its luminance is at least this share of the peak's.
pub const THRESHOLD_OF_PEAK: f64 = 0.1;

/// Largest solid angle of a fully "compact" source, sr (a disc of about 5 degrees radius).
pub const COMPACT_SOLID_ANGLE_SR: f64 = 0.025;

/// The dominant compact source of a probe (see the module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct DominantLight {
    /// Unit direction towards the source (world frame).
    pub direction: DVec3,
    /// Solid angle of the source's pixels, sr.
    pub solid_angle_sr: f64,
    /// Mean radiance over the source, RGB, probe units.
    pub radiance: Rgb64,
    /// `sum L dOmega` over the source: the irradiance it gives a surface facing it, RGB (probe
    /// unit x sr).
    pub irradiance: Rgb64,
    /// Share of the probe's luminance power in the source, 0 to 1.
    pub share: f64,
    /// Confidence that this is one dominant compact source, 0 to 1.
    pub confidence: f64,
    /// Number of pixels in the source.
    pub pixels: usize,
}

/// Finds the dominant compact source of a lat-long probe. An error for an empty or black probe.
pub fn dominant_light(probe: &Image<Rgb>) -> Result<DominantLight, ExtractError> {
    let (w, h) = (probe.width(), probe.height());
    if w == 0 || h == 0 {
        return Err(ExtractError::Invalid("the probe has no pixels".into()));
    }
    let ll = LatLong::new(w, h);
    let radiance = |i: usize, j: usize| {
        let p = probe.get(i, j);
        [p.r, p.g, p.b].map(valid_radiance)
    };
    let lum = |v: [f64; 3]| {
        Rgb64 {
            r: v[0],
            g: v[1],
            b: v[2],
        }
        .luminance()
    };
    let mut total = 0.0;
    let (mut peak, mut at) = (0.0f64, (0usize, 0usize));
    for j in 0..h {
        let omega = ll.row_solid_angle(j);
        for i in 0..w {
            let y = lum(radiance(i, j));
            total += y * omega;
            if y > peak {
                (peak, at) = (y, (i, j));
            }
        }
    }
    if !(peak > 0.0 && total > 0.0) {
        return Err(ExtractError::Invalid(
            "the probe is black: there is no light to find".into(),
        ));
    }
    let threshold = THRESHOLD_OF_PEAK * peak;
    let mut inside = vec![false; w * h];
    let mut stack = vec![at];
    inside[at.1 * w + at.0] = true;
    let (mut power, mut solid_angle, mut lum_power, mut centroid) =
        ([0.0f64; 3], 0.0, 0.0, DVec3::ZERO);
    let mut pixels = 0;
    while let Some((i, j)) = stack.pop() {
        let l = radiance(i, j);
        let omega = ll.row_solid_angle(j);
        for c in 0..3 {
            power[c] += l[c] * omega;
        }
        let y = lum(l) * omega;
        lum_power += y;
        solid_angle += omega;
        centroid += ll.pixel_dir64(i, j) * y;
        pixels += 1;
        let mut visit = |ni: usize, nj: usize| {
            let k = nj * w + ni;
            if !inside[k] && lum(radiance(ni, nj)) >= threshold {
                inside[k] = true;
                stack.push((ni, nj));
            }
        };
        for dj in [-1isize, 0, 1] {
            let Some(nj) = j.checked_add_signed(dj).filter(|&v| v < h) else {
                continue;
            };
            if (nj == 0 || nj == h - 1) && nj != j {
                // A pole row: every pixel of it touches the pole.
                for ni in 0..w {
                    visit(ni, nj);
                }
                continue;
            }
            for di in [-1isize, 0, 1] {
                if di != 0 || dj != 0 {
                    visit((i as isize + di).rem_euclid(w as isize) as usize, nj);
                }
            }
        }
    }
    let direction = centroid
        .try_normalize()
        .unwrap_or(ll.pixel_dir64(at.0, at.1));
    let share = (lum_power / total).clamp(0.0, 1.0);
    let compactness = (COMPACT_SOLID_ANGLE_SR / solid_angle).min(1.0);
    Ok(DominantLight {
        direction,
        solid_angle_sr: solid_angle,
        radiance: Rgb64::from_array(power.map(|p| p / solid_angle)),
        irradiance: Rgb64::from_array(power),
        share,
        confidence: share * compactness,
        pixels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sky of radiance 1 with a disc sun of radiance `sun` and angular radius `radius` at `dir`.
    fn sky_with_sun(dir: DVec3, radius: f64, sun: f32) -> Image<Rgb> {
        let (w, h) = (512, 256);
        let ll = LatLong::new(w, h);
        let mut img = Image::filled(w, h, Rgb::new(0.5, 0.7, 1.0));
        for j in 0..h {
            for i in 0..w {
                if ll.pixel_dir64(i, j).dot(dir) > radius.cos() {
                    *img.get_mut(i, j) = Rgb::new(sun, sun * 0.9, sun * 0.8);
                }
            }
        }
        img
    }

    #[test]
    fn finds_a_sun_and_its_power() {
        let dir = DVec3::new(0.4, 0.6, -0.5).normalize();
        let probe = sky_with_sun(dir, 0.05, 20_000.0);
        let sun = dominant_light(&probe).unwrap();
        let got = sun.direction;
        assert!(got.angle_between(dir) < 0.005, "{got} vs {dir}");
        // Power: the disc's pixels times their radiance.
        let ll = LatLong::new(512, 256);
        let mut want = 0.0;
        for j in 0..256 {
            for i in 0..512 {
                if ll.pixel_dir64(i, j).dot(dir) > 0.05f64.cos() {
                    want += 20_000.0 * ll.row_solid_angle(j);
                }
            }
        }
        // Same sum in another order: f64 rounding over ~100 pixels, far below 1e-9 relative.
        assert!((sun.irradiance.r - want).abs() < 1e-9 * want);
        // 20000 times a ratio of equal sums: f64 rounding, below 1e-6 absolute.
        assert!((sun.radiance.r - 20_000.0).abs() < 1e-6);
        assert!(sun.confidence > 0.9, "{sun:?}");
    }

    #[test]
    fn a_uniform_probe_has_no_confident_source() {
        let probe = Image::filled(64, 32, Rgb::new(1.0, 1.0, 1.0));
        let sun = dominant_light(&probe).unwrap();
        assert!(sun.confidence < 0.01, "{sun:?}");
        assert!(dominant_light(&Image::filled(8, 4, Rgb::ZERO)).is_err());
    }

    #[test]
    fn a_source_across_the_seam_and_the_pole_is_one_region() {
        // Straight behind (+Z, the seam at u = 0 / 1) and at the zenith.
        for dir in [DVec3::Z, DVec3::Y] {
            let probe = sky_with_sun(dir, 0.08, 5_000.0);
            let sun = dominant_light(&probe).unwrap();
            assert!(sun.direction.angle_between(dir) < 0.01, "{dir}: {sun:?}");
            assert!(sun.share > 0.5, "{dir}: {sun:?}");
        }
    }
}

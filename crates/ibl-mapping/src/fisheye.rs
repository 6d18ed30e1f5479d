//! Equidistant fisheye lenses: the single fisheye and the dual fisheye of consumer 360 cameras.
//!
//! An equidistant lens maps the angle `alpha` from its optical axis linearly to the radius in the
//! image circle, `r = alpha / (fov / 2)` (CONVENTIONS section 3), so `dOmega = F sin(F r) / r
//! da db` with `F = fov / 2` (the disc machinery of [`crate::disc`] does the geometry).
//!
//! * **Single fisheye**: a square image holding one circle that looks forward (-Z), image up = +Y,
//!   image right = +X. Directions more than `fov / 2` from -Z are not seen (radiance 0 when
//!   converting from it). With fov = 360 it is exactly the angular map.
//! * **Dual fisheye** (Samsung Gear 360 style): a 2:1 frame holding two square halves, each with an
//!   inscribed circle. The left circle looks forward (-Z, right = +X, up = +Y); the right circle
//!   looks backward (+Z) with image right = -X and up = +Y (the camera turned round about +Y).
//!
//! **Blending.** Real lenses see more than 180 degrees (about 195), so the two circles overlap
//! in a band around the z = 0 plane. For a direction whose cosine to a lens axis is `c`, the lens
//! weight is `w(c) = smoothstep((c + c0) / (2 c0))` with `c0 = -cos(fov / 2)` (the overlap is
//! `|c| <= c0`): it is exactly 0 at the lens' rim (`c = cos(fov / 2) = -c0`), 1 where the other
//! lens sees nothing, C1-smooth in between, and the two lens weights add up to 1 (smoothstep is
//! antisymmetric about 1/2). Converting *from* dual fisheye blends the two bilinear look-ups with
//! these weights (a feathered seam). With fov <= 180 there is no overlap: each direction comes from
//! the lens that sees it, weight 1 (and fov < 180 leaves an unseen band, radiance 0).
//!
//! **Counting solid angle.** [`crate::Mapping::texel_solid_angles`] weights each pixel of a dual
//! fisheye by its lens' blend weight, integrated exactly over the pixel: because `w` depends only
//! on the radius in the circle, it is a radial density with cap function
//! `H_w(r) = integral from cos(F r) to 1 of w(c) dc` (closed form: smoothstep integrates to a
//! quartic), handled by the same Green's-theorem clipping as the other discs. Every direction is
//! thus counted once and the total is 4 pi for fov >= 180 (`2 x 2 pi (1 - cos F)` below 180), so
//! that [`crate::power()`] of a dual fisheye equals the power of the environment it shows.

use crate::disc::{Disc, Profile, clipped_solid_angle};
use crate::taps::Taps;
use glam::DVec3;

/// `3x^2 - 2x^3` on [0, 1], clamped outside.
fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// The two lenses of a dual fisheye image and their blend.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DualFisheye {
    /// The forward lens (left half).
    pub front: Disc,
    /// The backward lens (right half).
    pub back: Disc,
    /// Half the field of view, radians.
    half_fov: f64,
    /// `cos(fov / 2)`.
    cos_f: f64,
    /// `-cos(fov / 2)`: the overlap is `|c| <= c0` when positive.
    c0: f64,
}

impl DualFisheye {
    /// The dual fisheye of a `2h x h` image with lenses of `half_fov` radians (in (0, pi]).
    pub(crate) fn new(h: usize, half_fov: f64) -> Self {
        let profile = Profile::Equidistant { half_fov };
        let front = Disc::new(profile, 1.0, -1.0, 0, h, h);
        let back = Disc::new(profile, -1.0, 1.0, h, h, h);
        let cos_f = half_fov.cos();
        DualFisheye {
            front,
            back,
            half_fov,
            cos_f,
            c0: -cos_f,
        }
    }

    /// Blend weight of a lens for a direction at cosine `c` to its axis (see the module note).
    pub(crate) fn weight(&self, c: f64) -> f64 {
        if self.c0 > 0.0 {
            smoothstep((c + self.c0) / (2.0 * self.c0))
        } else if c >= self.cos_f {
            1.0
        } else {
            0.0
        }
    }

    /// `H_w(r)`: the blend-weighted cap of radius `r` of one lens.
    fn weighted_cap(&self, r: f64) -> f64 {
        self.weighted_cap_over_r2(r) * r * r
    }

    /// `H_w(r) / r^2`, finite at 0.
    fn weighted_cap_over_r2(&self, r: f64) -> f64 {
        let alpha = self.half_fov * r;
        let c = alpha.cos();
        if self.c0 <= 0.0 || c >= self.c0 || r < 1e-7 {
            let s = if r < 1e-7 {
                0.5 * self.half_fov
            } else {
                (0.5 * alpha).sin() / r
            };
            2.0 * s * s
        } else {
            let x = ((c + self.c0) / (2.0 * self.c0)).clamp(0.0, 1.0);
            let tail = 0.5 - x.powi(3) + 0.5 * x.powi(4);
            ((1.0 - self.c0) + 2.0 * self.c0 * tail) / (r * r)
        }
    }

    /// The lens of image column `x` (continuous).
    pub(crate) fn lens_at(&self, x: f64) -> &Disc {
        if x < self.back.x0 as f64 {
            &self.front
        } else {
            &self.back
        }
    }

    /// Blend-weighted solid angle of pixel `(i, j)` of the whole image (see the module note).
    pub(crate) fn texel_solid_angle(&self, i: usize, j: usize) -> f64 {
        let lens = if i < self.back.x0 {
            &self.front
        } else {
            &self.back
        };
        let bounds = lens.texel_bounds(i - lens.x0, j);
        clipped_solid_angle(
            bounds,
            |r| self.weighted_cap(r),
            |r| self.weighted_cap_over_r2(r),
            None,
        )
    }

    /// Continuous image coordinates of a unit direction in the lens with the larger weight (the
    /// front lens on a tie); `None` where neither lens sees it.
    pub(crate) fn pixel_of_dir(&self, d: DVec3) -> Option<(f64, f64)> {
        let (wf, wb) = (self.weight(-d.z), self.weight(d.z));
        if wf <= 0.0 && wb <= 0.0 {
            return None;
        }
        let lens = if wf >= wb { &self.front } else { &self.back };
        lens.pixel_of_dir(d)
    }

    /// Taps for unit direction `d`: the two lenses' bilinear taps blended with their weights
    /// (summing to 1); empty where neither lens sees `d`.
    pub(crate) fn taps(&self, stride: usize, d: DVec3) -> Taps {
        let mut taps = Taps::default();
        for (lens, w) in [
            (&self.front, self.weight(-d.z)),
            (&self.back, self.weight(d.z)),
        ] {
            if w <= 0.0 {
                continue;
            }
            if let Some((x, y)) = lens.pixel_of_dir(d) {
                let lens_taps = lens.taps(stride, x, y);
                for (idx, tw) in lens_taps.iter() {
                    taps.push(idx, w * tw);
                }
            }
        }
        taps.normalised()
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may panic
mod tests {
    use std::f64::consts::PI;

    use super::*;

    #[test]
    fn weights_partition_unity_and_vanish_at_the_rim() {
        let dual = DualFisheye::new(64, 195f64.to_radians() / 2.0);
        for k in 0..=100 {
            let c = -1.0 + 2.0 * k as f64 / 100.0;
            assert!((dual.weight(c) + dual.weight(-c) - 1.0).abs() < 1e-12);
        }
        assert!(dual.weight(dual.cos_f).abs() < 1e-12);
        assert_eq!(dual.weight(1.0), 1.0);
    }

    #[test]
    fn weighted_cap_is_the_integral_of_the_weight() {
        for fov in [170.0_f64, 180.0, 195.0, 250.0, 360.0] {
            let dual = DualFisheye::new(64, fov.to_radians() / 2.0);
            for r in [0.05, 0.5, 0.93, 0.99, 1.0] {
                // Midpoint rule on integral_{cos(F r)}^{1} w(c) dc.
                let lo = (dual.half_fov * r).cos();
                let n = 20000;
                let h = (1.0 - lo) / n as f64;
                let num: f64 = (0..n)
                    .map(|k| dual.weight(lo + (k as f64 + 0.5) * h) * h)
                    .sum();
                assert!((num - dual.weighted_cap(r)).abs() < 1e-6, "fov {fov} r {r}");
            }
            if fov >= 180.0 {
                assert!(
                    (2.0 * dual.weighted_cap(1.0) - 2.0).abs() < 1e-12,
                    "fov {fov}"
                );
            }
        }
        let dual = DualFisheye::new(8, PI / 2.0);
        assert!((dual.weighted_cap(1.0) - 1.0).abs() < 1e-12);
    }
}

//! Directional light sets (CONVENTIONS sections 4 and 7; Madsen & Laursen 2006 section 3).
//!
//! A light `i` has a unit direction `w_i` (towards the light, world frame), a radiance `L_i` (linear
//! RGB), a solid angle `A_i` (sr) and `I_i = L_i A_i`, the irradiance it gives a surface facing it.
//! The irradiance of a set at normal `n` is `E(n) = sum_i I_i max(0, n . w_i)`. Irradiance is kept
//! in f64 so that region methods conserve the probe's power to rounding (`sum_i I_i` equals
//! `sum_p L_p dOmega_p`).
//!
//! The serde form of [`Light`] and [`PixelRegion`] is the per-light record of the light-set file
//! (`direction`, `radiance`, `solid_angle`, `irradiance`, `region`; triples as JSON arrays), so
//! `ibl-io` reads and writes these types as they are.

use glam::{DMat3, DVec3};
use ibl_core::Rgb;
use ibl_core::rgb::Rgb64;
use serde::{Deserialize, Serialize};

use crate::Provenance;
use crate::encoding;

/// An axis-aligned block of lat-long pixels: columns `x0..x1`, rows `y0..y1` (half-open).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PixelRegion {
    /// First column.
    pub x0: usize,
    /// First row (row 0 at the top).
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
}

impl PixelRegion {
    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.x1 - self.x0
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.y1 - self.y0
    }
}

/// One directional light.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Light {
    /// Unit direction towards the light, world frame (+Y up, -Z forward).
    #[serde(with = "encoding::dvec3")]
    pub direction: DVec3,
    /// Radiance `L = I / A`, linear RGB (the probe's unit, W sr^-1 m^-2 when calibrated).
    #[serde(with = "encoding::rgb")]
    pub radiance: Rgb,
    /// Solid angle `A` of the source, sr.
    #[serde(rename = "solid_angle")]
    pub solid_angle_sr: f64,
    /// `I = L A` per channel: the irradiance on a surface facing the light (probe unit x sr,
    /// W m^-2 when calibrated).
    #[serde(with = "encoding::rgb64")]
    pub irradiance: Rgb64,
    /// The probe pixels this light stands for (region methods only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub region: Option<PixelRegion>,
    /// How widely the light's power spreads about `direction`: the solid angle (sr) of the
    /// uniform cone with the same half-energy angle ([`crate::spread`]). A sun inside a region of
    /// dim sky spreads far less than the region's `solid_angle`; soft shadows are sized by it
    /// ([`Light::shadow_solid_angle_sr`]). Measured by the methods that have the light's pixels;
    /// `None` where not measured.
    #[serde(default, rename = "spread", skip_serializing_if = "Option::is_none")]
    pub spread_sr: Option<f64>,
    /// The fraction (0 to 1) of the light's power in the core of its spread, the rest spread
    /// as a halo over its source's `solid_angle` ([`crate::spread`], "A core and a halo"): a
    /// sun inside a cluster of sky keeps the sky's share out of the sun's shadow. Measured
    /// with the spread; `None` (all core) where not measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub core_fraction: Option<f64>,
    /// The side of the probe's horizon (`y = 0` in the probe's frame) whose light alone this
    /// light stands for, where its extraction kept the halves apart (irradiance optimisation
    /// with the hemispheres apart, `ibl_extract::fit_hemispheres`): its direction lies on that
    /// side or on the horizon, and soft shadows fold the part of its cones that crosses the
    /// horizon back onto that side (the mirror image in the horizon plane), so that a ground
    /// plane neither hides light from above nor passes light from below. `None`: the light's
    /// cones are taken whole.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<HorizonSide>,
}

/// A side of the probe's horizon ([`Light::side`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum HorizonSide {
    /// `y >= 0` in the probe's frame.
    Above,
    /// `y <= 0` in the probe's frame.
    Below,
}

impl HorizonSide {
    /// The side a unit direction lies on (probe frame; the horizon itself counts as above).
    pub fn of_direction(direction: DVec3) -> HorizonSide {
        if direction.y >= 0.0 {
            HorizonSide::Above
        } else {
            HorizonSide::Below
        }
    }

    /// The number of pixel rows of the upper half of a lat-long image `height` rows high: the
    /// rows whose centre lies above the horizon, and the middle row of an odd height (its
    /// centre on it). Rows `0..upper_rows(h)` are above, the rest below.
    pub fn upper_rows(height: usize) -> usize {
        height.div_ceil(2)
    }

    /// `point` mirrored in the horizon plane (probe frame: `y -> -y`).
    pub fn mirror(point: DVec3) -> DVec3 {
        DVec3::new(point.x, -point.y, point.z)
    }

    /// The unit normal of the horizon plane pointing into this side, probe frame.
    pub fn up(self) -> DVec3 {
        match self {
            HorizonSide::Above => DVec3::Y,
            HorizonSide::Below => DVec3::NEG_Y,
        }
    }
}

/// The two uniform cones about a light's direction that stand for it in soft shadows and in the
/// hybrid's ambient ([`Light::shadow_cones`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowCones {
    /// Solid angle (sr) of the core.
    pub core_sr: f64,
    /// The halo: its solid angle (sr, larger than the core's) and its share of the power in
    /// `(0, 1]`; `None` when the core holds it all.
    pub halo: Option<(f64, f64)>,
}

impl Light {
    /// The solid angle (sr) of the uniform cone that stands for this light in soft shadows and
    /// in the hybrid's ambient: its measured spread where known, but never more than its
    /// source's solid angle (a long thin region spreads one way only, and an isotropic cone of
    /// its spread blurs shadows the other way too: on the bundled apartment scene median cut's
    /// relative MSE rose from 3.0e-3 to 4.8e-3 at 16 lights without the bound, measured with a
    /// first, second-moment spread), else the source's
    /// solid angle.
    pub fn shadow_solid_angle_sr(&self) -> f64 {
        self.spread_sr
            .map_or(self.solid_angle_sr, |s| s.min(self.solid_angle_sr))
    }

    /// The core ([`Light::shadow_solid_angle_sr`]) and, where the light has a measured
    /// [`Light::core_fraction`] below 1 and a source wider than its core, the halo of its
    /// source's solid angle holding the rest of the power.
    pub fn shadow_cones(&self) -> ShadowCones {
        let core_sr = self.shadow_solid_angle_sr();
        let halo = self.core_fraction.and_then(|f| {
            (f.is_finite() && (0.0..1.0).contains(&f) && self.solid_angle_sr > core_sr)
                .then_some((self.solid_angle_sr, 1.0 - f))
        });
        ShadowCones { core_sr, halo }
    }
}

/// A set of directional lights approximating a probe, with what made it.
#[derive(Clone, Debug, PartialEq)]
pub struct LightSet {
    /// The method (with its parameters) and the source probe.
    pub provenance: Provenance,
    /// The lights.
    pub lights: Vec<Light>,
}

impl LightSet {
    /// Irradiance at unit normal `n`, per channel: `sum_i I_i max(0, n . w_i)`. Cost O(N).
    pub fn irradiance_at(&self, n: DVec3) -> [f64; 3] {
        let mut e = [0.0; 3];
        for l in &self.lights {
            let c = n.dot(l.direction).max(0.0);
            for (ec, ic) in e.iter_mut().zip(l.irradiance.to_array()) {
                *ec += ic * c;
            }
        }
        e
    }

    /// Total power of the set per channel, `sum_i I_i` (equals the probe's `sum L dOmega` for
    /// region methods).
    pub fn total_power(&self) -> [f64; 3] {
        let mut p = [0.0; 3];
        for l in &self.lights {
            for (pc, ic) in p.iter_mut().zip(l.irradiance.to_array()) {
                *pc += ic;
            }
        }
        p
    }

    /// The same set with every direction turned by `b_from_a` (an orthogonal matrix taking this
    /// set's frame `a` to frame `b`); regions and provenance are kept. Directions are not
    /// renormalised, so a rotation there and back returns them to rounding.
    pub fn transformed(&self, b_from_a: DMat3) -> LightSet {
        LightSet {
            provenance: self.provenance.clone(),
            lights: self
                .lights
                .iter()
                .map(|l| Light {
                    direction: b_from_a * l.direction,
                    ..*l
                })
                .collect(),
        }
    }

    /// The same set with every radiance and irradiance multiplied by `scale` (an exposure
    /// calibration, e.g. a scene's `radiance_scale`).
    pub fn scaled(&self, scale: f64) -> LightSet {
        LightSet {
            provenance: self.provenance.clone(),
            lights: self
                .lights
                .iter()
                .map(|l| Light {
                    irradiance: l.irradiance.map(|c| c * scale),
                    radiance: l.radiance * scale as f32,
                    ..*l
                })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Extraction, Provenance};

    #[test]
    fn the_horizon_splits_the_rows_at_their_centres_and_directions_at_y_0() {
        // Even heights: half the rows; odd: the middle row (centre on the horizon) goes up.
        assert_eq!(HorizonSide::upper_rows(256), 128);
        assert_eq!(HorizonSide::upper_rows(5), 3);
        assert_eq!(HorizonSide::upper_rows(1), 1);
        assert_eq!(HorizonSide::of_direction(DVec3::X), HorizonSide::Above);
        assert_eq!(
            HorizonSide::of_direction(DVec3::new(0.0, -1e-9, 1.0)),
            HorizonSide::Below
        );
    }

    fn set() -> LightSet {
        LightSet {
            provenance: Provenance::extracted(Extraction::AdaptiveMedianCut),
            lights: vec![
                Light {
                    direction: DVec3::Y,
                    radiance: Rgb::new(1.0, 2.0, 3.0),
                    solid_angle_sr: 0.5,
                    irradiance: Rgb64::new(0.5, 1.0, 1.5),
                    region: None,
                    spread_sr: None,
                    core_fraction: None,
                    side: None,
                },
                Light {
                    direction: DVec3::NEG_Z,
                    radiance: Rgb::splat(4.0),
                    solid_angle_sr: 0.25,
                    irradiance: Rgb64::new(1.0, 1.0, 1.0),
                    region: Some(PixelRegion {
                        x0: 1,
                        y0: 2,
                        x1: 4,
                        y1: 8,
                    }),
                    spread_sr: Some(0.125),
                    core_fraction: None,
                    side: None,
                },
            ],
        }
    }

    #[test]
    fn shadows_take_the_spread_within_the_solid_angle() {
        let mut s = set();
        assert_eq!(s.lights[0].shadow_solid_angle_sr(), 0.5);
        assert_eq!(s.lights[1].shadow_solid_angle_sr(), 0.125);
        s.lights[1].spread_sr = Some(2.0);
        assert_eq!(s.lights[1].shadow_solid_angle_sr(), 0.25);
        // A halo only with a core fraction below 1 and a source wider than the core.
        assert_eq!(s.lights[1].shadow_cones().halo, None);
        s.lights[1].spread_sr = Some(0.125);
        s.lights[1].core_fraction = Some(0.75);
        let cones = s.lights[1].shadow_cones();
        assert_eq!((cones.core_sr, cones.halo), (0.125, Some((0.25, 0.25))));
        s.lights[1].core_fraction = Some(1.0);
        assert_eq!(s.lights[1].shadow_cones().halo, None);
        s.lights[1].core_fraction = Some(0.5);
        s.lights[1].spread_sr = Some(0.5);
        assert_eq!(s.lights[1].shadow_cones().halo, None);
    }

    #[test]
    fn irradiance_is_the_clamped_cosine_sum() {
        let s = set();
        // Facing +Y: the first light fully, the second at 90 degrees (cos 0). Exact in binary.
        assert_eq!(s.irradiance_at(DVec3::Y), [0.5, 1.0, 1.5]);
        assert_eq!(s.irradiance_at(DVec3::NEG_Y), [0.0; 3]);
        assert_eq!(s.total_power(), [1.5, 2.0, 2.5]);
    }

    #[test]
    fn transforms_and_scales_keep_what_they_should() {
        let s = set();
        let turned = s.transformed(DMat3::from_rotation_y(std::f64::consts::FRAC_PI_2));
        // A quarter turn about +Y takes -Z to -X; f64 rounding of sin/cos: below 1e-15.
        assert!((turned.lights[1].direction - DVec3::NEG_X).length() < 1e-15);
        assert_eq!(turned.lights[1].region, s.lights[1].region);
        let scaled = s.scaled(2.0);
        assert_eq!(scaled.lights[0].irradiance, Rgb64::new(1.0, 2.0, 3.0));
        assert_eq!(scaled.lights[0].radiance, Rgb::new(2.0, 4.0, 6.0));
        assert_eq!(scaled.provenance, s.provenance);
    }

    #[test]
    fn regions_have_their_size() {
        let r = PixelRegion {
            x0: 1,
            y0: 2,
            x1: 4,
            y1: 8,
        };
        assert_eq!((r.width(), r.height()), (3, 6));
    }
}

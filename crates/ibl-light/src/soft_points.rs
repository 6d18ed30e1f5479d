//! A soft light as a quadrature: weighted directions spread over its cones, as soft shadows take
//! it ([`Light::shadow_cones`]; a light with a [`Light::side`] folded onto its side of the
//! horizon). What the renderer samples one point at a time, this lays out deterministically, so
//! that the irradiance and the SH of the soft light (not of its axis alone) can be computed where
//! the light set is made (`ibl_extract::fit_hemispheres` re-solves the powers with it) and where
//! the hybrid's ambient is built.

use glam::DVec3;

use crate::directional::{HorizonSide, Light};

/// `count` points of the uniform cone of solid angle `solid_angle_sr` about unit `axis`, equal
/// area each: a Fibonacci spiral over the spherical cap (point `k` at `1 - cos t = (k + 1/2) (1 -
/// cos a) / count`, azimuth `k` times the golden angle), so that a smooth function's mean over
/// them converges like a stratified estimate (about `count^-3/4`), not a random one.
pub fn cone_points(axis: DVec3, solid_angle_sr: f64, count: usize) -> Vec<DVec3> {
    let one_minus_cos = (solid_angle_sr / std::f64::consts::TAU).clamp(0.0, 2.0);
    let reference = if axis.x.abs() < 0.9 {
        DVec3::X
    } else {
        DVec3::Y
    };
    let t1 = axis.cross(reference).normalize();
    let t2 = axis.cross(t1);
    let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    (0..count)
        .map(|k| {
            let z = 1.0 - (k as f64 + 0.5) / count as f64 * one_minus_cos;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = k as f64 * golden;
            z * axis + r * (phi.cos() * t1 + phi.sin() * t2)
        })
        .collect()
}

impl Light {
    /// The light as weighted unit directions (probe frame, weights summing to 1): `count` points
    /// over its core cone (weight: its core's share over `count`) and, where it has a halo,
    /// `count` over the halo ([`Light::shadow_cones`]); a point on the other side of the horizon
    /// from the light's [`Light::side`] is mirrored onto it (`y -> -y`). A light without a cone
    /// (no solid angle) is its direction alone. `I_c sum_p w_p max(0, n . p)` is then its
    /// unshadowed irradiance at `n` as soft shadows render it.
    pub fn soft_points(&self, count: usize) -> Vec<(DVec3, f64)> {
        let axis = self.direction.normalize_or(DVec3::Y);
        let cones = self.shadow_cones();
        let count = count.max(1);
        let mut parts = vec![(cones.core_sr, cones.halo.map_or(1.0, |(_, s)| 1.0 - s))];
        parts.extend(cones.halo);
        let mut points = Vec::with_capacity(2 * count);
        for (solid_angle, share) in parts {
            if !(solid_angle.is_finite() && solid_angle > 0.0) {
                points.push((axis, share));
                continue;
            }
            let w = share / count as f64;
            points.extend(
                cone_points(axis, solid_angle, count)
                    .into_iter()
                    .map(|p| (p, w)),
            );
        }
        if let Some(side) = self.side {
            let up = side.up();
            for (p, _) in &mut points {
                if p.dot(up) < 0.0 {
                    *p = HorizonSide::mirror(*p);
                }
            }
        }
        points
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HorizonSide;
    use ibl_core::Rgb;
    use ibl_core::rgb::Rgb64;

    fn light(direction: DVec3, solid_angle_sr: f64, side: Option<HorizonSide>) -> Light {
        Light {
            direction,
            radiance: Rgb::ONE,
            solid_angle_sr,
            irradiance: Rgb64::new(1.0, 1.0, 1.0),
            region: None,
            spread_sr: None,
            core_fraction: Some(0.75),
            side,
        }
    }

    /// The mean clamped cosine of a uniform cone of half-angle `a` to the normal on its axis is
    /// `(1 + cos a) / 2` (the cone lies above the surface for `a <= 90 degrees`).
    #[test]
    fn cone_points_average_the_cosine_of_the_cap() {
        let a: f64 = 0.4;
        let omega = std::f64::consts::TAU * (1.0 - a.cos());
        let axis = DVec3::new(0.3, 0.8, -0.52).normalize();
        let points = cone_points(axis, omega, 256);
        assert!(points.iter().all(|p| (p.length() - 1.0).abs() < 1e-12));
        assert!(points.iter().all(|p| p.dot(axis) >= a.cos() - 1e-12));
        let mean: f64 = points.iter().map(|p| p.dot(axis)).sum::<f64>() / 256.0;
        // Equal-area strata in cos t: the mean of cos t is exact to rounding.
        assert!((mean - (1.0 + a.cos()) / 2.0).abs() < 1e-12, "{mean}");
    }

    #[test]
    fn a_light_folds_onto_its_side_and_keeps_its_weight() {
        // On the horizon with a 20-degree cone: half of it lies below.
        let a: f64 = 20f64.to_radians();
        let omega = std::f64::consts::TAU * (1.0 - a.cos());
        for side in [HorizonSide::Above, HorizonSide::Below] {
            let l = light(DVec3::X, omega, Some(side));
            let points = l.soft_points(64);
            // No halo (no spread measured): one cone of 64 points.
            assert_eq!(points.len(), 64);
            let total: f64 = points.iter().map(|(_, w)| w).sum();
            assert!((total - 1.0).abs() < 1e-12, "{total}");
            assert!(points.iter().all(|(p, _)| p.dot(side.up()) >= 0.0));
            assert!(points.iter().all(|(p, _)| (p.length() - 1.0).abs() < 1e-12));
        }
        // Without a side about half the points stay below (the spiral's azimuths are not
        // symmetric about the horizon).
        let whole = light(DVec3::X, omega, None).soft_points(64);
        let below = whole.iter().filter(|(p, _)| p.y < 0.0).count();
        assert!((24..=40).contains(&below), "{below}");
    }

    #[test]
    fn a_light_with_a_halo_splits_its_weight_by_its_core_fraction() {
        let mut l = light(DVec3::Y, 0.2, None);
        l.spread_sr = Some(0.01);
        let points = l.soft_points(16);
        assert_eq!(points.len(), 32);
        let core: f64 = points[..16].iter().map(|(_, w)| w).sum();
        let halo: f64 = points[16..].iter().map(|(_, w)| w).sum();
        assert!((core - 0.75).abs() < 1e-12 && (halo - 0.25).abs() < 1e-12);
        // A point light is its direction.
        let point = light(DVec3::Z, 0.0, None).soft_points(16);
        assert_eq!(point, vec![(DVec3::Z, 1.0)]);
    }
}

//! A synthetic lat-long environment for benchmarks, examples and tests: a smooth blue sky above
//! the horizon, a brown checkered ground below it and a small uniform sun disc. Radiance is
//! non-zero everywhere, the sun makes the map high-dynamic-range, and the checker gives the
//! ground texture that resampling and filtering must keep. It is cheap to build at any size, so
//! timings need no file I/O and no bundled probe.

use glam::DVec3;

use crate::{Image, LatLong, Rgb};

/// Parameters of the synthetic sky (world frame of CONVENTIONS section 1, radiance in
/// W sr^-1 m^-2 per channel).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyntheticSky {
    /// Unit direction towards the sun's centre (world frame).
    pub sun_direction: DVec3,
    /// Angular radius of the sun disc, degrees.
    pub sun_radius_deg: f64,
    /// Radiance added to the sky inside the sun disc, the same in every channel.
    pub sun_radiance: f32,
    /// Side of one ground checker square, in texels of the rendered map.
    pub checker_texels: usize,
}

impl Default for SyntheticSky {
    /// A sun 30 degrees up towards -Z and +X, 2 degrees in radius, 1000 above the sky; 8-texel
    /// checkers.
    fn default() -> Self {
        Self {
            sun_direction: DVec3::new(0.3, 0.5, -0.8).normalize(),
            sun_radius_deg: 2.0,
            sun_radiance: 1000.0,
            checker_texels: 8,
        }
    }
}

impl SyntheticSky {
    /// Renders the sky as a `width` x `height` lat-long map, sampled at texel centres (rows in
    /// parallel). Sky: (0.4 + 0.3 y, 0.6 + 0.2 y, 1.0) for direction height y > 0; ground:
    /// (0.2, 0.15, 0.1) or (0.3, 0.25, 0.1) by checker square. O(width x height).
    pub fn render(&self, width: usize, height: usize) -> Image<Rgb> {
        let ll = LatLong::new(width, height);
        let cos_sun = self.sun_radius_deg.to_radians().cos();
        let sun = self.sun_direction.normalize_or_zero();
        let side = self.checker_texels.max(1);
        Image::from_fn_par(width, height, |i, j| {
            let d = ll.pixel_dir64(i, j);
            let sky = if d.y > 0.0 {
                Rgb::new(0.4 + 0.3 * d.y as f32, 0.6 + 0.2 * d.y as f32, 1.0)
            } else {
                let checker = ((i / side + j / side) % 2) as f32;
                Rgb::new(0.2 + 0.1 * checker, 0.15 + 0.1 * checker, 0.1)
            };
            if d.dot(sun) >= cos_sun {
                sky + Rgb::splat(self.sun_radiance)
            } else {
                sky
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sun_sky_and_ground_have_their_radiance() {
        let sky = SyntheticSky::default();
        let map = sky.render(512, 256);
        let ll = LatLong::new(512, 256);
        let (mut sun_texels, mut max) = (0, 0.0f32);
        for j in 0..256 {
            for i in 0..512 {
                let p = map.get(i, j);
                let d = ll.pixel_dir64(i, j);
                max = max.max(p.g);
                if p.g > 100.0 {
                    sun_texels += 1;
                    assert!(d.angle_between(sky.sun_direction).to_degrees() <= 2.0);
                } else if d.y > 0.0 {
                    assert_eq!(p.b, 1.0);
                } else {
                    assert_eq!(p.b, 0.1);
                }
            }
        }
        // A 2-degree disc covers about 3.8e-3 sr; a texel near 30 degrees up about 1.3e-4 sr.
        assert!((20..40).contains(&sun_texels), "{sun_texels} sun texels");
        assert!(max > 1000.0);
    }

    #[test]
    fn checker_squares_alternate() {
        let sky = SyntheticSky {
            checker_texels: 4,
            ..SyntheticSky::default()
        };
        let map = sky.render(64, 32);
        assert_ne!(map.get(0, 31).r, map.get(4, 31).r);
        assert_eq!(map.get(0, 31).r, map.get(3, 31).r);
    }
}

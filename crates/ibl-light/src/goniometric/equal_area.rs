//! The candela table resampled into an equal-area square map for fast look-ups: Grosch 2005
//! (section 4.2) converts the goniometric data to a cube map in a pre-process; we use Clarberg's
//! equal-area octahedral parameterisation (Clarberg 2008, "Fast equal-area mapping of the
//! (hemi)sphere using SIMD") instead, so that every texel covers exactly `4 pi / N^2` sr and
//! the map's flux is a plain sum.
//!
//! Map coordinates `(a, b)` in `[-1, 1]^2` (`a` right, `b` up; texel `(i, j)` of an `N x N` map,
//! row 0 at the top, has its centre at `a = 2 (i + 0.5) / N - 1`, `b = 1 - 2 (j + 0.5) / N`, as
//! CONVENTIONS section 3 lays square images out). With `u = |a|`, `v = |b|`, `s = 1 - (u + v)`,
//! `r = 1 - |s|`, `phi = ((v - u) / r + 1) pi / 4` (`pi / 4` when `r = 0`):
//!
//! `m = (sign(a) r sqrt(2 - r^2) cos phi, sign(b) r sqrt(2 - r^2) sin phi, sign(s) (1 - r^2))`
//!
//! is a unit vector in the map's frame. The map's pole `+m.z` is the light's nadir: light-frame
//! direction `(m.x, -m.z, m.y)`, so the centre of the map looks straight down, the inner diamond
//! `|a| + |b| < 1` is the lower hemisphere and the four corners are the zenith. The Jacobian of
//! the map is the constant `pi` (area 4 onto 4 pi sr).
//!
//! A texel holds the mean of the interpolated table over its solid angle (a `k x k` midpoint rule
//! in map coordinates, which are equal-area, so the sub-samples weigh the same); a look-up is
//! bilinear between texel centres, across the map's outer edges by the octahedral fold (the
//! point `(a, 1 + e)` is `(-a, 1 - e)`, and likewise on the other three edges).

use glam::Vec3;

use super::CandelaTable;

/// The unit light-frame direction at map coordinates `(a, b)` in `[-1, 1]^2` (module doc).
pub fn square_to_direction(a: f32, b: f32) -> Vec3 {
    let (u, v) = (a.abs(), b.abs());
    let s = 1.0 - (u + v);
    let r = 1.0 - s.abs();
    let phi = if r > 0.0 {
        ((v - u) / r + 1.0) * std::f32::consts::FRAC_PI_4
    } else {
        std::f32::consts::FRAC_PI_4
    };
    let radial = r * (2.0 - r * r).max(0.0).sqrt();
    let (sin_phi, cos_phi) = phi.sin_cos();
    let m = Vec3::new(
        radial * cos_phi * a.signum(),
        radial * sin_phi * b.signum(),
        (1.0 - r * r) * s.signum(),
    );
    Vec3::new(m.x, -m.z, m.y)
}

/// The map coordinates `(a, b)` in `[-1, 1]^2` of light-frame direction `d` (any length; the
/// zero vector gives the centre). Inverse of [`square_to_direction`].
pub fn direction_to_square(d: Vec3) -> (f32, f32) {
    let len = d.length();
    if len <= 0.0 || !len.is_finite() {
        return (0.0, 0.0);
    }
    let m = Vec3::new(d.x, d.z, -d.y) / len;
    let (ax, ay) = (m.x.abs(), m.y.abs());
    // r = sqrt(1 - |z|), written as sqrt((x^2 + y^2) / (1 + |z|)) to keep precision at the pole.
    let r = ((ax * ax + ay * ay) / (1.0 + m.z.abs())).sqrt().min(1.0);
    let t = ay.atan2(ax) / std::f32::consts::FRAC_PI_2;
    let v = t * r;
    let u = r - v;
    let (u, v) = if m.z < 0.0 {
        (1.0 - v, 1.0 - u)
    } else {
        (u, v)
    };
    (u.copysign(m.x), v.copysign(m.y))
}

/// The intensity table resampled into an `N x N` equal-area map, cd per texel (module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct EqualAreaMap {
    size: usize,
    texels: Vec<f32>,
}

impl EqualAreaMap {
    /// The largest side [`EqualAreaMap::from_table`] builds (4096^2 texels, 64 MiB).
    pub const MAX_SIZE: usize = 4096;

    /// Resamples `table` into a `size x size` map, each texel the mean of `samples x samples`
    /// interpolated values at the centres of its sub-squares. `size` is clamped to
    /// `1..=MAX_SIZE` and `samples` to `1..=16`.
    pub fn from_table(table: &CandelaTable, size: usize, samples: usize) -> EqualAreaMap {
        let size = size.clamp(1, Self::MAX_SIZE);
        let k = samples.clamp(1, 16);
        let n = size as f32;
        let mut texels = Vec::with_capacity(size * size);
        for j in 0..size {
            for i in 0..size {
                let mut sum = 0.0_f64;
                for sj in 0..k {
                    for si in 0..k {
                        let x = i as f32 + (si as f32 + 0.5) / k as f32;
                        let y = j as f32 + (sj as f32 + 0.5) / k as f32;
                        let d = square_to_direction(2.0 * x / n - 1.0, 1.0 - 2.0 * y / n);
                        sum += f64::from(table.intensity_towards(d));
                    }
                }
                texels.push((sum / (k * k) as f64) as f32);
            }
        }
        EqualAreaMap { size, texels }
    }

    /// The side `N`, texels.
    pub fn size(&self) -> usize {
        self.size
    }

    /// The texels, row-major, row 0 at the top (`b = 1`), cd.
    pub fn texels(&self) -> &[f32] {
        &self.texels
    }

    /// The solid angle of every texel, `4 pi / N^2` sr.
    pub fn texel_solid_angle(&self) -> f64 {
        4.0 * std::f64::consts::PI / (self.size * self.size) as f64
    }

    /// The map's luminous flux, lm: the texels' sum times the texel solid angle.
    pub fn flux(&self) -> f64 {
        self.texels.iter().map(|&c| f64::from(c)).sum::<f64>() * self.texel_solid_angle()
    }

    /// The texel at `(i, j)`, indices one step outside the map folded back across its edges.
    fn fetch(&self, i: isize, j: isize) -> f32 {
        let n = self.size as isize;
        let (mut i, mut j) = (i, j);
        if j < 0 || j >= n {
            j = if j < 0 { -1 - j } else { 2 * n - 1 - j };
            i = n - 1 - i;
        }
        if i < 0 || i >= n {
            i = if i < 0 { -1 - i } else { 2 * n - 1 - i };
            j = n - 1 - j;
        }
        let (i, j) = (i.clamp(0, n - 1) as usize, j.clamp(0, n - 1) as usize);
        self.texels[j * self.size + i]
    }

    /// The intensity, cd, towards light-frame direction `d` (direction of travel, any length):
    /// bilinear between the four nearest texel centres.
    pub fn intensity_towards(&self, d: Vec3) -> f32 {
        let (a, b) = direction_to_square(d);
        let n = self.size as f32;
        let x = (a + 1.0) * 0.5 * n - 0.5;
        let y = (1.0 - b) * 0.5 * n - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (i, j) = (x0 as isize, y0 as isize);
        let top = self.fetch(i, j) * (1.0 - fx) + self.fetch(i + 1, j) * fx;
        let bottom = self.fetch(i, j + 1) * (1.0 - fx) + self.fetch(i + 1, j + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_round_trips_and_puts_the_nadir_in_the_centre() {
        assert!(square_to_direction(0.0, 0.0).abs_diff_eq(-Vec3::Y, 1e-6));
        assert!(square_to_direction(1.0, 1.0).abs_diff_eq(Vec3::Y, 1e-6));
        assert!(square_to_direction(1.0, 0.0).abs_diff_eq(Vec3::X, 1e-6));
        assert!(square_to_direction(0.0, 1.0).abs_diff_eq(Vec3::Z, 1e-6));
        // 1e-5 and 2e-5: f32 rounding of the forward and inverse formulas.
        for j in 0..21 {
            for i in 0..21 {
                let (a, b) = (i as f32 / 10.0 - 1.0, j as f32 / 10.0 - 1.0);
                let d = square_to_direction(a, b);
                assert!((d.length() - 1.0).abs() < 1e-5);
                let back = square_to_direction(direction_to_square(d).0, direction_to_square(d).1);
                // The outer edges fold onto each other, so compare directions, not coordinates.
                assert!(back.abs_diff_eq(d, 2e-5), "({a}, {b}): {d} -> {back}");
            }
        }
    }

    #[test]
    fn texels_cover_equal_solid_angles() {
        // The fraction of the square with |a| + |b| < 1 is one half, and it must map onto the
        // lower hemisphere (2 pi of 4 pi): count directions of a fine grid by hemisphere (an odd
        // side keeps every texel centre off the diamond |a| + |b| = 1, the equator).
        let n = 401;
        let below = (0..n * n)
            .filter(|k| {
                let (i, j) = (k % n, k / n);
                let a = 2.0 * (i as f32 + 0.5) / n as f32 - 1.0;
                let b = 2.0 * (j as f32 + 0.5) / n as f32 - 1.0;
                square_to_direction(a, b).y < 0.0
            })
            .count();
        // Counting texel centres errs only by the texels the equator cuts, which the map's
        // symmetry balances: 1e-3 is loose.
        assert!((below as f64 / (n * n) as f64 - 0.5).abs() < 1e-3);
        // And a cap of polar angle 60 degrees around the nadir (solid angle pi) covers a quarter.
        let cap = (0..n * n)
            .filter(|k| {
                let (i, j) = (k % n, k / n);
                let a = 2.0 * (i as f32 + 0.5) / n as f32 - 1.0;
                let b = 2.0 * (j as f32 + 0.5) / n as f32 - 1.0;
                -square_to_direction(a, b).y > 0.5
            })
            .count();
        // Grid counting errs by the cap boundary's texels, about 4 n of n^2 (1e-2 at n = 401).
        assert!((cap as f64 / (n * n) as f64 - 0.25).abs() < 1e-2, "{cap}");
    }

    #[test]
    fn a_smooth_table_survives_the_map() {
        let v: Vec<f32> = (0..=36).map(|i| i as f32 * 5.0).collect();
        let h: Vec<f32> = (0..=24).map(|i| i as f32 * 15.0).collect();
        let cd: Vec<f32> = h
            .iter()
            .flat_map(|c| {
                v.iter()
                    .map(move |g| 100.0 + 50.0 * g.to_radians().cos() + 20.0 * c.to_radians().sin())
            })
            .collect();
        let t = CandelaTable::new(v, h, cd).unwrap();
        let map = EqualAreaMap::from_table(&t, 64, 4);
        // Midpoint rule on a smooth integrand: 0.1 % at 64^2 texels is loose by an order.
        assert!((map.flux() / t.flux() - 1.0).abs() < 1e-3);
        for k in 0..200 {
            let d = square_to_direction(
                (k as f32 * 0.618).fract() * 2.0 - 1.0,
                (k as f32 * 0.377).fract() * 2.0 - 1.0,
            );
            let (exact, fast) = (t.intensity_towards(d), map.intensity_towards(d));
            // Bilinear look-up of texel means: within 1 % of the peak (170 cd) here.
            assert!((exact - fast).abs() < 1.7, "{d}: {exact} vs {fast}");
        }
    }
}

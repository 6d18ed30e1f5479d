//! The intensity between the table's angles: bilinear interpolation in `(gamma, C)` (degrees) of
//! the candela grid, in the light's photometric frame (module doc of [`super`]).
//!
//! Within a cell `[gamma_i, gamma_i+1] x [C_j, C_j+1]` the interpolant is
//! `I = (1 - s)(1 - t) I_ij + (1 - s) t I_i+1,j + s (1 - t) I_i,j+1 + s t I_i+1,j+1` with `t` and
//! `s` the fractions of the cell in `gamma` and `C`. Outside the vertical range it is 0 (a
//! downlight measured over 0..90 degrees sends nothing up); `C` is periodic with 360 degrees, and
//! a table with one horizontal angle is the same in every plane.

use glam::Vec3;

use super::CandelaTable;

/// The unit direction of travel in the light frame for vertical angle `gamma` (radians from the
/// nadir, -Y) and horizontal angle `c` (radians from +X towards -Z):
/// `(sin gamma cos c, -cos gamma, -sin gamma sin c)`.
pub fn direction_from_angles(gamma: f32, c: f32) -> Vec3 {
    let (sg, cg) = gamma.sin_cos();
    let (sc, cc) = c.sin_cos();
    Vec3::new(sg * cc, -cg, -sg * sc)
}

/// The angles `(gamma, C)` in radians of a light-frame direction (need not be unit length; the
/// zero vector gives `(0, 0)`): `gamma` in `0..=pi` from the nadir, `C` in `0..2 pi`.
pub fn angles_of_direction(d: Vec3) -> (f32, f32) {
    let horizontal = (d.x * d.x + d.z * d.z).sqrt();
    let gamma = horizontal.atan2(-d.y);
    let c = (-d.z).atan2(d.x).rem_euclid(std::f32::consts::TAU);
    (gamma, c)
}

/// The cell of increasing `grid` holding `x` and the fraction of the way across it, with `x`
/// already known to be within `grid[0]..=grid[last]` and `grid` at least two long.
fn cell(grid: &[f32], x: f32) -> (usize, f32) {
    let i = grid.partition_point(|&a| a <= x).clamp(1, grid.len() - 1) - 1;
    let t = ((x - grid[i]) / (grid[i + 1] - grid[i])).clamp(0.0, 1.0);
    (i, t)
}

impl CandelaTable {
    /// The interpolated intensity, cd, at vertical angle `gamma` (radians from the nadir) and
    /// horizontal angle `c` (radians, any value: taken modulo 2 pi). 0 outside the vertical
    /// range and for non-finite angles.
    pub fn intensity(&self, gamma: f32, c: f32) -> f32 {
        self.intensity_deg(gamma.to_degrees(), c.to_degrees())
    }

    /// [`CandelaTable::intensity`] with both angles in degrees.
    pub fn intensity_deg(&self, gamma_deg: f32, c_deg: f32) -> f32 {
        let v = self.vertical_deg();
        let (first, last) = (v[0], v[v.len() - 1]);
        if !(gamma_deg >= first && gamma_deg <= last && c_deg.is_finite()) {
            return 0.0;
        }
        let (i, t) = cell(v, gamma_deg);
        let column = |h: usize| {
            let at = |k: usize| self.values()[h * v.len() + k];
            at(i) + (at(i + 1) - at(i)) * t
        };
        if self.is_rotationally_symmetric() {
            return column(0);
        }
        let (j, s) = cell(self.horizontal_deg(), c_deg.rem_euclid(360.0));
        let (a, b) = (column(j), column(j + 1));
        a + (b - a) * s
    }

    /// The interpolated intensity, cd, towards light-frame direction `d` (direction of travel,
    /// any length; see [`angles_of_direction`]).
    pub fn intensity_towards(&self, d: Vec3) -> f32 {
        let (gamma, c) = angles_of_direction(d);
        self.intensity(gamma, c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> CandelaTable {
        // Two planes' worth of data expanded to a full turn: C = 0, 90, 180, 270, 360.
        let v = vec![0.0, 90.0, 180.0];
        let h = vec![0.0, 90.0, 180.0, 270.0, 360.0];
        let cd = [
            [100.0, 50.0, 0.0],
            [200.0, 60.0, 0.0],
            [100.0, 70.0, 0.0],
            [200.0, 80.0, 0.0],
            [100.0, 50.0, 0.0],
        ];
        CandelaTable::new(v, h, cd.iter().flatten().copied().collect()).unwrap()
    }

    #[test]
    fn the_interpolant_hits_the_nodes_and_is_bilinear_between() {
        let t = table();
        assert_eq!(t.intensity_deg(90.0, 90.0), 60.0);
        assert_eq!(t.intensity_deg(90.0, 360.0), 50.0);
        // Halfway in both angles: the mean of the cell's four corners (1e-4: f32 rounding).
        let mid = t.intensity_deg(45.0, 45.0);
        assert!(
            (mid - (100.0 + 50.0 + 200.0 + 60.0) / 4.0).abs() < 1e-4,
            "{mid}"
        );
        // Periodic in C (1e-3: f32 rounding of 405 and -315 degrees taken modulo 360).
        assert!((t.intensity_deg(45.0, 405.0) - mid).abs() < 1e-3);
        assert!((t.intensity_deg(45.0, -315.0) - mid).abs() < 1e-3);
        assert_eq!(t.intensity_deg(f32::NAN, 0.0), 0.0);
    }

    #[test]
    fn outside_the_vertical_range_is_dark() {
        let t = CandelaTable::new(vec![0.0, 90.0], vec![0.0], vec![10.0, 10.0]).unwrap();
        assert_eq!(t.intensity_deg(90.0, 0.0), 10.0);
        assert_eq!(t.intensity_deg(90.5, 0.0), 0.0);
        assert_eq!(t.intensity_towards(Vec3::Y), 0.0);
        assert_eq!(t.intensity_towards(-Vec3::Y), 10.0);
    }

    #[test]
    fn angles_and_directions_round_trip_in_the_documented_frame() {
        // C = 0 is +X, C = 90 is -Z, gamma = 0 is -Y (CONVENTIONS-style pinned vectors).
        assert!(direction_from_angles(0.0, 0.0).abs_diff_eq(-Vec3::Y, 1e-6));
        let half_pi = std::f32::consts::FRAC_PI_2;
        assert!(direction_from_angles(half_pi, 0.0).abs_diff_eq(Vec3::X, 1e-6));
        assert!(direction_from_angles(half_pi, half_pi).abs_diff_eq(-Vec3::Z, 1e-6));
        // 1e-5 rad: f32 trigonometry and atan2 round trips.
        for (g, c) in [(0.3, 0.2), (1.5, 3.0), (2.9, 6.0)] {
            let (g2, c2) = angles_of_direction(direction_from_angles(g, c));
            assert!(
                (g - g2).abs() < 1e-5 && (c - c2).abs() < 1e-5,
                "{g} {c} -> {g2} {c2}"
            );
        }
    }
}

//! Rotation of SH coefficients by any rotation matrix, every band.
//!
//! If a function is rotated, `f'(d) = f(R^-1 d)`, its coefficients transform band by band,
//! `c'_l = D_l(R) c_l`, with one `(2l+1) x (2l+1)` orthogonal matrix per band. `D_1` is `R` itself
//! read in the basis order `(y, z, x)` of `Y_1-1, Y_10, Y_11`; higher bands follow from it by the
//! recurrence of Ivanic & Ruedenberg (J. Phys. Chem. 1996, 100, 6342; corrections 1998, 102, 9099),
//! which needs no angles (no gimbal lock), costs O(1) per matrix entry (O(L^3) for all bands) and is
//! exact to rounding. Its real-harmonic sign convention is the one of CONVENTIONS section 6 (checked
//! against direct evaluation to l = 30 in the tests).

use ibl_core::glam::DMat3;

use crate::basis::MAX_BANDS;
#[cfg(test)]
use crate::basis::sh_index;

/// The rotation matrices of every band up to `bands` for one rotation.
#[derive(Clone, Debug, PartialEq)]
pub struct ShRotation {
    /// Band `l`'s matrix `D_l`, row-major, `(2l+1)^2` entries, entry `(m, m')` at
    /// `(m + l) (2l + 1) + m' + l`.
    blocks: Vec<Vec<f64>>,
}

impl ShRotation {
    /// The SH rotation for the rotation matrix `rotation` (taking directions `d` to `rotation d`;
    /// it must be orthonormal with determinant +1), for `bands` bands (at most [`MAX_BANDS`]).
    pub fn new(rotation: DMat3, bands: usize) -> ShRotation {
        let bands = bands.min(MAX_BANDS);
        let mut blocks: Vec<Vec<f64>> = Vec::with_capacity(bands);
        if bands == 0 {
            return ShRotation { blocks };
        }
        blocks.push(vec![1.0]);
        if bands == 1 {
            return ShRotation { blocks };
        }
        // Band 1 in the order (y, z, x): entry (i, j) = R[axis(i)][axis(j)], R[row][col].
        let axis = [1usize, 2, 0];
        let mut r1 = vec![0.0; 9];
        for i in 0..3 {
            for j in 0..3 {
                // glam is column-major: col(j)[i] is row i, column j.
                r1[i * 3 + j] = rotation.col(axis[j])[axis[i]];
            }
        }
        blocks.push(r1);
        for l in 2..bands {
            let block = band(&blocks[1], &blocks[l - 1], l);
            blocks.push(block);
        }
        ShRotation { blocks }
    }

    /// Number of bands.
    pub fn bands(&self) -> usize {
        self.blocks.len()
    }

    /// Entry `(m, m')` of band `l`'s matrix.
    pub fn entry(&self, l: usize, m: isize, mp: isize) -> f64 {
        let size = 2 * l + 1;
        let li = l as isize;
        self.blocks[l][(m + li) as usize * size + (mp + li) as usize]
    }

    /// Rotates coefficient vectors (`coeffs[sh_index(l, m)]`, any number of channels per entry)
    /// band by band; a band the rotation was not built for is copied unchanged, so build it with
    /// at least the coefficients' band count. O(L^3).
    pub fn apply<const C: usize>(&self, coeffs: &[[f64; C]]) -> Vec<[f64; C]> {
        let mut out = coeffs.to_vec();
        for l in 0..self.bands() {
            let (first, size) = (l * l, 2 * l + 1);
            if first + size > coeffs.len() {
                break;
            }
            let block = &self.blocks[l];
            for row in 0..size {
                let mut acc = [0.0; C];
                for col in 0..size {
                    let w = block[row * size + col];
                    for (a, v) in acc.iter_mut().zip(&coeffs[first + col]) {
                        *a += w * v;
                    }
                }
                out[first + row] = acc;
            }
        }
        out
    }
}

/// Band `l`'s matrix from band 1's (`r1`) and band `l - 1`'s (`prev`), by Ivanic & Ruedenberg's
/// recurrence (their Table 2, with the 1998 corrections).
fn band(r1: &[f64], prev: &[f64], l: usize) -> Vec<f64> {
    let li = l as isize;
    let size = 2 * l + 1;
    let prev_size = 2 * l - 1;
    let r = |i: isize, j: isize| r1[((i + 1) * 3 + j + 1) as usize];
    let rp = |a: isize, b: isize| prev[((a + li - 1) as usize) * prev_size + (b + li - 1) as usize];
    // P(i, a, b) of the paper.
    let p = |i: isize, a: isize, b: isize| {
        if b == li {
            r(i, 1) * rp(a, li - 1) - r(i, -1) * rp(a, -li + 1)
        } else if b == -li {
            r(i, 1) * rp(a, -li + 1) + r(i, -1) * rp(a, li - 1)
        } else {
            r(i, 0) * rp(a, b)
        }
    };
    let mut out = vec![0.0; size * size];
    for m in -li..=li {
        for mp in -li..=li {
            let d0 = if m == 0 { 1.0 } else { 0.0 };
            let am = m.abs() as f64;
            let lf = l as f64;
            let denom = if mp.abs() < li {
                ((li + mp) * (li - mp)) as f64
            } else {
                (2 * li * (2 * li - 1)) as f64
            };
            let u = (((li + m) * (li - m)) as f64 / denom).sqrt();
            let v =
                0.5 * ((1.0 + d0) * (lf + am - 1.0) * (lf + am) / denom).sqrt() * (1.0 - 2.0 * d0);
            let w = -0.5 * ((lf - am - 1.0) * (lf - am) / denom).sqrt() * (1.0 - d0);
            let mut value = 0.0;
            if u != 0.0 {
                value += u * p(0, m, mp);
            }
            if v != 0.0 {
                let vv = if m == 0 {
                    p(1, 1, mp) + p(-1, -1, mp)
                } else if m > 0 {
                    let d1: f64 = if m == 1 { 1.0 } else { 0.0 };
                    p(1, m - 1, mp) * (1.0 + d1).sqrt() - p(-1, -m + 1, mp) * (1.0 - d1)
                } else {
                    let d1: f64 = if m == -1 { 1.0 } else { 0.0 };
                    p(1, m + 1, mp) * (1.0 - d1) + p(-1, -m - 1, mp) * (1.0 + d1).sqrt()
                };
                value += v * vv;
            }
            if w != 0.0 {
                let ww = if m > 0 {
                    p(1, m + 1, mp) + p(-1, -m - 1, mp)
                } else {
                    p(1, m - 1, mp) - p(-1, -m + 1, mp)
                };
                value += w * ww;
            }
            out[(m + li) as usize * size + (mp + li) as usize] = value;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::basis::basis;
    use ibl_core::glam::DVec3;

    fn rotation(axis: DVec3, angle: f64) -> DMat3 {
        DMat3::from_axis_angle(axis.normalize(), angle)
    }

    /// `Y_lk(R^-1 d) = sum_m D_l[m][k] Y_lm(d)` for every l <= 30, k and several d.
    #[test]
    fn matches_direct_evaluation_to_thirty_bands() {
        let bands = 31;
        for r in [
            rotation(DVec3::new(0.3, 1.0, -0.4), 1.1),
            rotation(DVec3::Z, 2.5),
            rotation(DVec3::new(1.0, 0.2, 0.1), -0.7),
            rotation(DVec3::X, std::f64::consts::PI), // a half turn
        ] {
            let d_rot = ShRotation::new(r, bands);
            for d in [
                DVec3::new(0.2, 0.3, 0.93).normalize(),
                DVec3::new(-0.7, 0.1, -0.2).normalize(),
                DVec3::new(0.0, -1.0, 0.0),
            ] {
                let y = basis(d, bands);
                let y_back = basis(r.transpose() * d, bands);
                for l in 0..bands {
                    let li = l as isize;
                    for k in -li..=li {
                        let sum: f64 = (-li..=li)
                            .map(|m| d_rot.entry(l, m, k) * y[sh_index(l, m)])
                            .sum();
                        let want = y_back[sh_index(l, k)];
                        assert!(
                            (sum - want).abs() < 1e-9 * (1.0 + want.abs()),
                            "l {l} k {k}: {sum} vs {want}"
                        );
                    }
                }
            }
        }
    }
}

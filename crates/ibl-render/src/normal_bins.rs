//! Environment sampling in proportion to radiance times a bound of the cosine, per bin of
//! surface normals: most of a vertex's environment samples then land above its surface, and more
//! of them where the cosine is large (product importance sampling, in the spirit of Clarberg et
//! al. 2005, "Wavelet importance sampling", with a precomputed table in place of the wavelet
//! product).
//!
//! **Bins.** Unit normals (probe frame) are binned on a `B x B` octahedral map (Praun & Hoppe
//! 2003; the fold about the probe's horizontal plane). Bin `b` has an axis `n_b` (its centre's
//! direction) and an angular radius `r_b` that bounds the angle from `n_b` to every normal that
//! falls in it.
//!
//! **Cells.** The W x H probe is cut into at most `64 x 32` cells of whole texels (rows and
//! columns split as evenly as integers allow), each with an axis `w_c` and a radius `r_c`
//! bounding the angle to every direction of its texels.
//!
//! **Bound.** For a normal in bin `b` and a direction in cell `c` the angle between them is at
//! least `a = angle(n_b, w_c) - r_b - r_c` (triangle inequality on the sphere), so
//! `max(0, n . w) <= g(b, c) = cos(max(0, a))`, and `g = 0` where `a >= pi / 2`: no normal of the
//! bin receives light from the cell. Radii are measured on a grid of points over the bin or cell
//! (9 x 9, edges included) and raised by the largest angle between neighbouring points (every
//! point of the region lies within that of a grid point) and `1e-4` rad for rounding.
//!
//! **Sampling.** Bin `b` draws a cell with probability `P_c g(b, c) / Z_b` (`P_c` the cell's
//! `sum lum(L) dOmega`, `Z_b` the sum over cells), then a texel of the cell in proportion to
//! `lum(L) dOmega` (the cell's own distribution), then a direction uniform in solid angle in the
//! texel. The density is `P_b(c) P_c(t) / dOmega_t` per steradian, read from the same
//! cumulative tables that drew it (so the estimator is unbiased to the tables' rounding), and it
//! is positive wherever a surface with a normal in the bin can receive light: multiple importance
//! sampling against the BSDF keeps the estimate unbiased and cuts the variance the probe's dark
//! or hidden directions added. A bin whose `Z_b` is 0 (no light reaches any of its normals) is
//! not offered ([`NormalBins::bin_of`] gives `None`).
//!
//! **Halves.** Each bin also has two clipped distributions, over the cells wholly in the probe's
//! upper half (rows `0..ceil(H / 2)`) and wholly in its lower half (rows `floor(H / 2)..H`), with
//! the same weights `P_c g(b, c)` and the others' set to 0 ([`NormalBins::within`]). A vertex
//! above a real floor that is the whole real geometry draws from the upper one: every direction
//! below the horizon meets the floor (but past its edge) and brings its light through the
//! floor's own bounce, so a sample drawn there is wasted. Leaving directions out of one MIS
//! strategy keeps the estimate unbiased wherever the other (the BSDF's) covers them.
//!
//! Cost: O(W H + B^2 C) to build (`C` cells), O(1) expected per sample and per density.

use std::f64::consts::FRAC_PI_2;

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use crate::sampling::Distribution1D;

/// Bins per side of the octahedral normal map (`B`; `B^2` bins).
pub const BINS_PER_SIDE: usize = 16;

/// Most cells across and down the probe.
const MAX_CELLS: (usize, usize) = (64, 32);

/// Grid points per side measuring a bin's or a cell's radius.
const RADIUS_GRID: usize = 9;

/// Added to every radius for rounding (rad).
const RADIUS_MARGIN: f64 = 1e-4;

/// Which half of the probe's sphere a clipped bin draws from (module notes, "Halves").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Half {
    /// Rows `0..ceil(H / 2)`: directions above the probe's horizontal plane.
    Upper,
    /// Rows `floor(H / 2)..H`: directions below it.
    Lower,
}

/// A texel drawn by [`NormalBins::sample`], with two fresh uniform numbers for the direction
/// inside it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BinnedTexel {
    /// Column.
    pub column: usize,
    /// Row.
    pub row: usize,
    /// Uniform in `[0, 1)`: where in the texel's band of `cos(theta)`.
    pub along_row_band: f32,
    /// Uniform in `[0, 1)`: where in the texel's range of `phi`.
    pub along_columns: f32,
}

/// Per-bin cell distributions and per-cell texel distributions of one probe (module notes).
#[derive(Clone, Debug)]
pub struct NormalBins {
    /// Cell boundaries: cell column `x` spans texel columns `column_start[x]..column_start[x+1]`.
    column_start: Vec<usize>,
    /// Cell boundaries down the rows, likewise.
    row_start: Vec<usize>,
    /// Per texel column, its cell column; per texel row, its cell row (their lengths are the
    /// probe's width and height).
    cell_column: Vec<u16>,
    cell_row: Vec<u16>,
    /// Per cell (row-major), the distribution over its texels (row-major within the cell).
    cells: Vec<Distribution1D>,
    /// Per bin, the distribution over cells; `None` where `Z_b = 0`. Then the same bins clipped
    /// to the upper half's cells, then to the lower half's (ids `B^2 ..` and `2 B^2 ..`; module
    /// notes, "Halves").
    bins: Vec<Option<Distribution1D>>,
}

/// Octahedral coordinates in `[0, 1]^2` of a unit vector (probe frame; the fold about y = 0).
fn octahedral_encode(n: DVec3) -> (f64, f64) {
    let sum = n.x.abs() + n.y.abs() + n.z.abs();
    let (mut u, mut v) = (n.x / sum, n.z / sum);
    if n.y < 0.0 {
        let (fu, fv) = ((1.0 - v.abs()) * u.signum(), (1.0 - u.abs()) * v.signum());
        u = fu;
        v = fv;
    }
    (0.5 * (u + 1.0), 0.5 * (v + 1.0))
}

/// The unit vector at octahedral coordinates `(s, t)` in `[0, 1]^2` (inverse of the encoding).
fn octahedral_decode(s: f64, t: f64) -> DVec3 {
    let (u, v) = (2.0 * s - 1.0, 2.0 * t - 1.0);
    let y = 1.0 - u.abs() - v.abs();
    let (x, z) = if y < 0.0 {
        ((1.0 - v.abs()) * u.signum(), (1.0 - u.abs()) * v.signum())
    } else {
        (u, v)
    };
    DVec3::new(x, y, z).normalize()
}

/// The angle between two unit vectors, well conditioned near 0 and pi.
fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The axis (the direction at the region's centre) and a bounding radius of the region that
/// `point` maps `[0, 1]^2` onto (module notes, "Bins" and "Cells").
fn bounding_cone(point: impl Fn(f64, f64) -> DVec3) -> (DVec3, f64) {
    let axis = point(0.5, 0.5);
    let last = (RADIUS_GRID - 1) as f64;
    let grid: Vec<DVec3> = (0..RADIUS_GRID * RADIUS_GRID)
        .map(|k| {
            point(
                (k % RADIUS_GRID) as f64 / last,
                (k / RADIUS_GRID) as f64 / last,
            )
        })
        .collect();
    let mut radius = 0.0_f64;
    let mut spacing = 0.0_f64;
    for (k, &p) in grid.iter().enumerate() {
        radius = radius.max(angle(axis, p));
        if k % RADIUS_GRID + 1 < RADIUS_GRID {
            spacing = spacing.max(angle(p, grid[k + 1]));
        }
        if k + RADIUS_GRID < grid.len() {
            spacing = spacing.max(angle(p, grid[k + RADIUS_GRID]));
        }
    }
    (axis, radius + spacing + RADIUS_MARGIN)
}

/// `n` cells' boundaries over `len` texels, as even as integers allow.
fn boundaries(len: usize, n: usize) -> Vec<usize> {
    (0..=n).map(|k| k * len / n).collect()
}

impl NormalBins {
    /// The bins of a `width x height` probe whose texel `(i, j)` has sampling weight
    /// `weights[j * width + i]` (`lum(L) dOmega`, non-negative; the probe frame's lat-long,
    /// `docs/CONVENTIONS.md` section 2). O(W H + B^2 C).
    pub fn new(width: usize, height: usize, weights: &[f64]) -> NormalBins {
        debug_assert_eq!(weights.len(), width * height);
        let (cw, ch) = (width.min(MAX_CELLS.0), height.min(MAX_CELLS.1));
        let column_start = boundaries(width, cw);
        let row_start = boundaries(height, ch);
        let cell_of = |starts: &[usize], len: usize| -> Vec<u16> {
            let mut out = vec![0u16; len];
            for (c, range) in starts.windows(2).enumerate() {
                out[range[0]..range[1]].fill(c as u16);
            }
            out
        };
        let cell_column = cell_of(&column_start, width);
        let cell_row = cell_of(&row_start, height);
        let cell_ids: Vec<(usize, usize)> =
            (0..ch).flat_map(|y| (0..cw).map(move |x| (x, y))).collect();
        let cells: Vec<Distribution1D> = cell_ids
            .par_iter()
            .map(|&(x, y)| {
                let columns = column_start[x]..column_start[x + 1];
                Distribution1D::new(
                    (row_start[y]..row_start[y + 1])
                        .flat_map(|j| columns.clone().map(move |i| weights[j * width + i])),
                )
            })
            .collect();
        // Each cell's cone: texel edges in `u = phi / 2 pi + 1/2` and `v = theta / pi`.
        let cell_cones: Vec<(DVec3, f64)> = cell_ids
            .par_iter()
            .map(|&(x, y)| {
                let (u0, u1) = (
                    column_start[x] as f64 / width as f64,
                    column_start[x + 1] as f64 / width as f64,
                );
                let (v0, v1) = (
                    row_start[y] as f64 / height as f64,
                    row_start[y + 1] as f64 / height as f64,
                );
                bounding_cone(|s, t| {
                    ibl_core::LatLong::uv_to_dir64(u0 + s * (u1 - u0), v0 + t * (v1 - v0))
                })
            })
            .collect();
        // The cell rows wholly in each half ("Halves").
        let upper_rows = row_start.partition_point(|&r| r <= height.div_ceil(2)) - 1;
        let lower_from = row_start.partition_point(|&r| r < height / 2);
        let in_half = |cell: usize, half: Half| match half {
            Half::Upper => cell / cw < upper_rows,
            Half::Lower => cell / cw >= lower_from,
        };
        let b = BINS_PER_SIDE as f64;
        let weights_per_bin: Vec<Vec<f64>> = (0..BINS_PER_SIDE * BINS_PER_SIDE)
            .into_par_iter()
            .map(|k| {
                let (bx, by) = ((k % BINS_PER_SIDE) as f64, (k / BINS_PER_SIDE) as f64);
                let (axis, radius) =
                    bounding_cone(|s, t| octahedral_decode((bx + s) / b, (by + t) / b));
                cells
                    .iter()
                    .zip(&cell_cones)
                    .map(|(cell, &(cell_axis, cell_radius))| {
                        let a = angle(axis, cell_axis) - radius - cell_radius;
                        let bound = if a >= FRAC_PI_2 {
                            0.0
                        } else {
                            a.max(0.0).cos()
                        };
                        cell.total() * bound
                    })
                    .collect()
            })
            .collect();
        let family = |half: Option<Half>| {
            weights_per_bin.par_iter().map(move |weights| {
                let bin = Distribution1D::new(weights.iter().enumerate().map(|(c, &w)| {
                    if half.is_none_or(|half| in_half(c, half)) {
                        w
                    } else {
                        0.0
                    }
                }));
                (bin.total() > 0.0).then_some(bin)
            })
        };
        let bins = family(None)
            .chain(family(Some(Half::Upper)))
            .chain(family(Some(Half::Lower)))
            .collect();
        NormalBins {
            column_start,
            row_start,
            cell_column,
            cell_row,
            cells,
            bins,
        }
    }

    /// The bin of the unit normal `n` (probe frame), when it can receive any light; `None` for
    /// a zero or non-finite normal and for a bin no light reaches.
    pub fn bin_of(&self, n: Vec3) -> Option<u16> {
        let n = n.as_dvec3();
        if !(n.is_finite() && n.length_squared() > 0.0) {
            return None;
        }
        let (s, t) = octahedral_encode(n);
        let side = BINS_PER_SIDE as f64;
        // Saturating casts: `s, t` lie in [0, 1].
        let bx = ((s * side) as usize).min(BINS_PER_SIDE - 1);
        let by = ((t * side) as usize).min(BINS_PER_SIDE - 1);
        let k = by * BINS_PER_SIDE + bx;
        self.bins[k].as_ref().map(|_| k as u16)
    }

    /// Bin `bin` ([`NormalBins::bin_of`]) clipped to the cells of `half` (module notes,
    /// "Halves"); `None` when no light of that half reaches the bin's normals.
    pub fn within(&self, bin: u16, half: Half) -> Option<u16> {
        let bins = BINS_PER_SIDE * BINS_PER_SIDE;
        let k = usize::from(bin);
        let clipped = k + bins
            * match half {
                Half::Upper => 1,
                Half::Lower => 2,
            };
        (k < bins && self.bins[clipped].is_some()).then_some(clipped as u16)
    }

    /// A texel drawn by bin `bin` from `u1` (the cell, then the texel's band) and `u2` (the
    /// texel within the cell, then its column range). `None` for a bin [`NormalBins::bin_of`]
    /// never gives.
    pub fn sample(&self, bin: u16, u1: f32, u2: f32) -> Option<BinnedTexel> {
        let cell = self.bins.get(usize::from(bin))?.as_ref()?.sample(u1)?;
        let texel = self.cells[cell.index].sample(u2)?;
        let cw = self.column_start.len() - 1;
        let (x, y) = (cell.index % cw, cell.index / cw);
        let span = self.column_start[x + 1] - self.column_start[x];
        Some(BinnedTexel {
            column: self.column_start[x] + texel.index % span,
            row: self.row_start[y] + texel.index / span,
            along_row_band: cell.remapped,
            along_columns: texel.remapped,
        })
    }

    /// The probability with which bin `bin` draws texel `(column, row)`: `P_b(c) P_c(t)` (divide
    /// by the texel's solid angle for the density per steradian). 0 for a bin never offered.
    #[inline]
    pub fn texel_probability(&self, bin: u16, column: usize, row: usize) -> f32 {
        let Some(Some(bin)) = self.bins.get(usize::from(bin)) else {
            return 0.0;
        };
        let (Some(&x), Some(&y)) = (self.cell_column.get(column), self.cell_row.get(row)) else {
            return 0.0;
        };
        let (x, y) = (usize::from(x), usize::from(y));
        let cw = self.column_start.len() - 1;
        let cell = y * cw + x;
        let span = self.column_start[x + 1] - self.column_start[x];
        let local = (row - self.row_start[y]) * span + (column - self.column_start[x]);
        bin.probability(cell) * self.cells[cell].probability(local)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::PixelRng;

    #[test]
    fn octahedral_map_round_trips() {
        for k in 0..2000 {
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / 2000.0;
            let phi = k as f64 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            let n = DVec3::new(r * phi.cos(), z, r * phi.sin());
            let (s, t) = octahedral_encode(n);
            assert!((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t));
            assert!(angle(octahedral_decode(s, t), n) < 1e-9, "{n}");
        }
    }

    #[test]
    fn bin_radii_cover_their_normals() {
        // Random normals in random bins lie within their bin's radius and map back to it (the
        // bound itself: `tests/sampling.rs`, a positive density wherever light can arrive).
        let (w, h) = (48, 24);
        let bins = NormalBins::new(w, h, &vec![1.0; w * h]);
        let mut rng = PixelRng::new(29, 0, 0);
        let mut next = || f64::from(rng.next_f32());
        let b = BINS_PER_SIDE as f64;
        for _ in 0..20_000 {
            let k = (next() * (BINS_PER_SIDE * BINS_PER_SIDE) as f64) as usize;
            let (bx, by) = ((k % BINS_PER_SIDE) as f64, (k / BINS_PER_SIDE) as f64);
            let (axis, radius) =
                bounding_cone(|s, t| octahedral_decode((bx + s) / b, (by + t) / b));
            let n = octahedral_decode((bx + next()) / b, (by + next()) / b);
            assert!(angle(axis, n) <= radius, "bin {k}");
            assert_eq!(bins.bin_of(n.as_vec3()), Some(k as u16));
        }
    }
}

//! The fitting normals in structure-of-arrays form, and the O(M N) loops of the irradiance fit
//! over them.
//!
//! Why by hand: the compiler may not reorder floating-point sums, so a plain `for` loop summing
//! over normals runs one scalar chain (and the "is this normal lit" test keeps it from
//! vectorising at all). Here the sums run on `wide`'s portable vectors of [`LANES`] f64 (SSE2 on
//! any x86-64, NEON on ARM): every sum keeps one partial sum per lane and the per-normal work is
//! branch-free (masks). Lanes are added in a fixed order and parallel work is split into
//! fixed chunks of [`CHUNK`] normals, so results do not depend on the thread count. The normals
//! are padded to a multiple of [`LANES`] with zero vectors, which face no light and carry zero
//! irradiance, so padding adds nothing to any sum.

use glam::DVec3;
use rayon::prelude::*;
use wide::f64x4;

/// Lanes of the vectors the sums run on.
const LANES: usize = 4;

/// Normals per parallel task (a multiple of [`LANES`]).
const CHUNK: usize = 512;

/// One value per normal and colour channel, structure-of-arrays (padded like [`NormalLanes`]).
pub(crate) type ChannelValues = [Vec<f64>; 3];

/// Unit normals as three coordinate arrays, padded with zero vectors to a multiple of [`LANES`].
pub(crate) struct NormalLanes {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
}

impl NormalLanes {
    /// The normals in lanes.
    pub(crate) fn new(normals: &[DVec3]) -> NormalLanes {
        let padded = normals.len().div_ceil(LANES) * LANES;
        let coordinate = |f: fn(&DVec3) -> f64| {
            let mut v: Vec<f64> = normals.iter().map(f).collect();
            v.resize(padded, 0.0);
            v
        };
        NormalLanes {
            x: coordinate(|n| n.x),
            y: coordinate(|n| n.y),
            z: coordinate(|n| n.z),
        }
    }

    /// Length including padding.
    pub(crate) fn padded_len(&self) -> usize {
        self.x.len()
    }

    /// Per-channel values padded to the normals' padded length with zeros.
    pub(crate) fn pad(&self, values: &[[f64; 3]]) -> ChannelValues {
        [0, 1, 2].map(|c| {
            let mut v: Vec<f64> = values.iter().map(|g| g[c]).collect();
            v.resize(self.padded_len(), 0.0);
            v
        })
    }

    /// The coordinates in blocks of [`LANES`].
    fn blocks(&self) -> [&[[f64; LANES]]; 3] {
        [
            lane_blocks(&self.x),
            lane_blocks(&self.y),
            lane_blocks(&self.z),
        ]
    }

    /// Scaled residuals `r_kc = (sum_i p_ic max(0, n_k . w_i) - g_kc) s_c` and `1/2 |r|^2`.
    /// `target` is padded. O(M N), parallel over fixed chunks of normals.
    pub(crate) fn residuals(
        &self,
        dirs: &[DVec3],
        powers: &[[f64; 3]],
        target: &ChannelValues,
        scale: [f64; 3],
    ) -> (ChannelValues, f64) {
        let len = self.padded_len();
        let mut r: ChannelValues = [vec![0.0; len], vec![0.0; len], vec![0.0; len]];
        let [r0, r1, r2] = &mut r;
        let costs: Vec<f64> = r0
            .par_chunks_mut(CHUNK)
            .zip(r1.par_chunks_mut(CHUNK))
            .zip(r2.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(chunk, ((e0, e1), e2))| {
                let start = chunk * CHUNK;
                let (x, y, z) = (
                    &self.x[start..start + e0.len()],
                    &self.y[start..start + e0.len()],
                    &self.z[start..start + e0.len()],
                );
                for (w, p) in dirs.iter().zip(powers) {
                    for k in 0..e0.len() {
                        let c = (x[k] * w.x + y[k] * w.y + z[k] * w.z).max(0.0);
                        e0[k] += p[0] * c;
                        e1[k] += p[1] * c;
                        e2[k] += p[2] * c;
                    }
                }
                let mut sum = [0.0f64; LANES];
                for (ch, e) in [e0, e1, e2].into_iter().enumerate() {
                    let g = &target[ch][start..start + e.len()];
                    for (block, gb) in e.chunks_exact_mut(LANES).zip(g.chunks_exact(LANES)) {
                        for l in 0..LANES {
                            block[l] = (block[l] - gb[l]) * scale[ch];
                            sum[l] += block[l] * block[l];
                        }
                    }
                }
                sum.iter().sum::<f64>()
            })
            .collect();
        (r, 0.5 * costs.iter().sum::<f64>())
    }

    /// For one light with direction `w`: `S_c = sum_k r_kc n_k` over the normals that face it
    /// (`n_k . w > 0`), per channel. Every feature of the light is a linear function of `n` on
    /// that set (`n.w`, `n.t1`, `n.t2`), so its sum against the residual is one dot product with
    /// `S_c`. O(M).
    pub(crate) fn lit_residual_sums(&self, w: DVec3, r: &ChannelValues) -> [DVec3; 3] {
        let [wx, wy, wz] = w.to_array().map(f64x4::splat);
        let zero = f64x4::ZERO;
        let mut s = [[zero; 3]; 3];
        let [x, y, z] = self.blocks();
        let [r0, r1, r2] = [0, 1, 2].map(|c| lane_blocks(&r[c]));
        for (k, ((xb, yb), zb)) in x.iter().zip(y).zip(z).enumerate() {
            let (xv, yv, zv) = (f64x4::from(*xb), f64x4::from(*yb), f64x4::from(*zb));
            let lit = (xv * wx + yv * wy + zv * wz).simd_gt(zero);
            for (ch, rb) in [&r0[k], &r1[k], &r2[k]].into_iter().enumerate() {
                let rv = f64x4::from(*rb) & lit;
                s[ch][0] += rv * xv;
                s[ch][1] += rv * yv;
                s[ch][2] += rv * zv;
            }
        }
        s.map(|axes| {
            let [x, y, z] = axes.map(|v| v.to_array().iter().sum::<f64>());
            DVec3::new(x, y, z)
        })
    }

    /// Matching-pursuit sums for a candidate direction `w`: `sum_k d_kc phi_k` per channel and
    /// `sum_k phi_k^2`, with `phi_k = max(0, n_k . w)`. O(M).
    pub(crate) fn pursuit_sums(&self, w: DVec3, d: &ChannelValues) -> ([f64; 3], f64) {
        let [wx, wy, wz] = w.to_array().map(f64x4::splat);
        let zero = f64x4::ZERO;
        let mut num = [zero; 3];
        let mut den = zero;
        let [x, y, z] = self.blocks();
        let [d0, d1, d2] = [0, 1, 2].map(|c| lane_blocks(&d[c]));
        for (k, ((xb, yb), zb)) in x.iter().zip(y).zip(z).enumerate() {
            let (xv, yv, zv) = (f64x4::from(*xb), f64x4::from(*yb), f64x4::from(*zb));
            let phi = (xv * wx + yv * wy + zv * wz).max(zero);
            den += phi * phi;
            for (ch, db) in [&d0[k], &d1[k], &d2[k]].into_iter().enumerate() {
                num[ch] += f64x4::from(*db) * phi;
            }
        }
        let total = |v: f64x4| v.to_array().iter().sum::<f64>();
        (num.map(total), total(den))
    }
}

/// A padded array in blocks of [`LANES`] (a remainder, which padding rules out, is ignored).
fn lane_blocks(v: &[f64]) -> &[[f64; LANES]] {
    v.as_chunks::<LANES>().0
}

#[cfg(test)]
mod tests {
    use super::*;
    use ibl_core::fibonacci_normals;

    /// The vector loops agree with the plain per-normal sums they replace (to rounding).
    #[test]
    fn lane_sums_match_plain_sums() {
        let normals = fibonacci_normals(1001); // not a multiple of LANES: padding is exercised
        let lanes = NormalLanes::new(&normals);
        let dirs = [DVec3::new(0.3, 0.9, -0.2).normalize(), DVec3::X];
        let powers = [[1.0, 2.0, 0.5], [0.2, 0.1, 3.0]];
        let target: Vec<[f64; 3]> = normals
            .iter()
            .map(|n| [n.x.abs(), n.y * n.y, 0.5 + n.z])
            .collect();
        let scale = [2.0, 0.5, 1.0];
        let (r, cost) = lanes.residuals(&dirs, &powers, &lanes.pad(&target), scale);
        let mut plain_cost = 0.0;
        for (k, n) in normals.iter().enumerate() {
            for c in 0..3 {
                let e: f64 = dirs
                    .iter()
                    .zip(&powers)
                    .map(|(w, p)| p[c] * n.dot(*w).max(0.0))
                    .sum();
                let want = (e - target[k][c]) * scale[c];
                assert!((r[c][k] - want).abs() < 1e-12);
                plain_cost += 0.5 * want * want;
            }
        }
        assert!((cost - plain_cost).abs() < 1e-9 * plain_cost);
        assert!(r.iter().all(|v| v[1001..].iter().all(|&x| x == 0.0)));

        let w = dirs[0];
        let sums = lanes.lit_residual_sums(w, &r);
        for c in 0..3 {
            let want: DVec3 = normals
                .iter()
                .enumerate()
                .filter(|(_, n)| n.dot(w) > 0.0)
                .map(|(k, n)| *n * r[c][k])
                .sum();
            assert!((sums[c] - want).abs().max_element() < 1e-9);
        }

        let (num, den) = lanes.pursuit_sums(w, &r);
        let want_den: f64 = normals.iter().map(|n| n.dot(w).max(0.0).powi(2)).sum();
        let want_num0: f64 = normals
            .iter()
            .enumerate()
            .map(|(k, n)| r[0][k] * n.dot(w).max(0.0))
            .sum();
        assert!((den - want_den).abs() < 1e-9 * want_den);
        assert!((num[0] - want_num0).abs() < 1e-9);
    }
}

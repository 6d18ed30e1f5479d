//! Exact irradiance of a lat-long probe on a set of surface normals: the ground truth every
//! lighting approximation is measured against (CONVENTIONS sections 4 and 5).
//!
//! ```text
//! E_c(n) = sum_p L_pc * max(0, n . d_p) * dOmega_p
//! ```
//!
//! per channel c, over every pixel p of the probe, with `d_p` the pixel-centre direction
//! (`LatLong::pixel_dir64`, world frame: +Y up, -Z forward, +X right) and `dOmega_p` the exact
//! solid angle of the pixel's row (`LatLong::row_solid_angle`, summing to exactly 4 pi).
//! Radiance that is negative, NaN or infinite counts as 0.
//!
//! Two exact paths compute this same sum. [`irradiance_exact`] (from `ibl_core`, re-exported)
//! organises it by rows and prefix sums, O(H log W) per normal, and is what [`GroundTruth`] uses.
//! [`irradiance_brute_force`] is the literal per-pixel loop, O(M * P) for M normals and P
//! non-black pixels, kept as the reference the row path is tested against (they agree to about
//! 1e-14) and as its benchmark baseline. It is written to vectorise: the pixels become a
//! structure of arrays ([`Emitters`]) of f64 directions and weights `w = L * dOmega`, and each
//! pass over them serves a block of [`NORMAL_BLOCK`] normals at once. Each normal's sum is a
//! fixed sequential loop, so both paths are bit-identical whatever the rayon thread count.
//!
//! [`irradiance_fast`] first reduces the probe to a small lat-long grid of energy-conserving
//! blocks and then runs the brute-force loop over them (64x fewer emitters on a 512 x 256 probe).

use ibl_core::glam::DVec3;
use ibl_core::rgb::Rgb64;
use ibl_core::{
    Image, LatLong, Rgb, channel_means, fibonacci_normals, irradiance_exact,
    valid_radiance as radiance,
};
use rayon::prelude::*;

/// Normals served by one pass over the pixels (lanes of the vectorised inner loop). Two f64
/// lanes fill one SSE2 register; measured on 2 cores, 2 beats 1, 4 and 8 (register spills).
pub const NORMAL_BLOCK: usize = 2;

/// Default grid (width, height) of [`irradiance_fast`]: 64 x 32 blocks, 2048 emitters.
pub const FAST_DEFAULT_SIZE: (usize, usize) = (64, 32);

/// A set of point emitters as a structure of arrays: direction `(dx, dy, dz)` (need not be
/// unit length) and RGB weight `w = L * dOmega` (the irradiance it gives a surface facing it).
///
/// `E(n) = sum_i w_i * max(0, n . d_i)`; the same form serves probe pixels and directional
/// lights (`w_i = I_i = L_i A_i`, CONVENTIONS section 4).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Emitters {
    /// x components of the directions.
    pub dx: Vec<f64>,
    /// y components of the directions.
    pub dy: Vec<f64>,
    /// z components of the directions.
    pub dz: Vec<f64>,
    /// Red weights (`L_r * dOmega`).
    pub wr: Vec<f64>,
    /// Green weights.
    pub wg: Vec<f64>,
    /// Blue weights.
    pub wb: Vec<f64>,
}

impl Emitters {
    /// Number of emitters.
    pub fn len(&self) -> usize {
        self.dx.len()
    }

    /// True when there are no emitters.
    pub fn is_empty(&self) -> bool {
        self.dx.is_empty()
    }

    /// Appends an emitter with direction `d` and weight `w`.
    pub fn push(&mut self, d: DVec3, w: [f64; 3]) {
        self.dx.push(d.x);
        self.dy.push(d.y);
        self.dz.push(d.z);
        self.wr.push(w[0]);
        self.wg.push(w[1]);
        self.wb.push(w[2]);
    }

    /// Every non-black pixel of a lat-long probe, in row-major order: direction through the pixel
    /// centre and weight `L * dOmega` (exact row solid angle). Invalid radiance counts as 0.
    pub fn from_latlong(probe: &Image<Rgb>) -> Self {
        let ll = LatLong::new(probe.width(), probe.height());
        let mut e = Emitters::default();
        for j in 0..probe.height() {
            let omega = ll.row_solid_angle(j);
            for (i, px) in probe.row(j).iter().enumerate() {
                let l = [radiance(px.r), radiance(px.g), radiance(px.b)];
                if l.iter().all(|&v| v == 0.0) {
                    continue;
                }
                e.push(
                    ll.pixel_dir64(i, j),
                    [l[0] * omega, l[1] * omega, l[2] * omega],
                );
            }
        }
        e
    }

    /// The probe reduced to a `width` x `height` lat-long grid of blocks (each at most the
    /// probe's size): a block's weight is the sum of `L * dOmega` over its pixels (so the total
    /// power is conserved exactly) and its direction the luminance-weighted mean of its pixel
    /// directions, *not* renormalised, so that `n . d` equals the block's exact luminance sum
    /// whenever the whole block faces `n`. Blocks with no light are dropped.
    pub fn from_latlong_downsampled(probe: &Image<Rgb>, width: usize, height: usize) -> Self {
        let (w, h) = (probe.width(), probe.height());
        let (bw, bh) = (width.clamp(1, w.max(1)), height.clamp(1, h.max(1)));
        let ll = LatLong::new(w, h);
        // Per block: weighted direction sum, luminance sum, RGB weight sum.
        let mut dir = vec![DVec3::ZERO; bw * bh];
        let mut lum = vec![0.0f64; bw * bh];
        let mut rgb = vec![[0.0f64; 3]; bw * bh];
        for j in 0..h {
            let omega = ll.row_solid_angle(j);
            let row = (j * bh / h) * bw;
            for (i, px) in probe.row(j).iter().enumerate() {
                let l = [radiance(px.r), radiance(px.g), radiance(px.b)];
                if l.iter().all(|&v| v == 0.0) {
                    continue;
                }
                let b = row + i * bw / w;
                let p = [l[0] * omega, l[1] * omega, l[2] * omega];
                // Luminance weights (Rec. 709), or the plain sum if a colour has zero luminance.
                let y = Rgb64 {
                    r: p[0],
                    g: p[1],
                    b: p[2],
                }
                .luminance();
                let y = if y > 0.0 { y } else { p[0] + p[1] + p[2] };
                dir[b] += ll.pixel_dir64(i, j) * y;
                lum[b] += y;
                for c in 0..3 {
                    rgb[b][c] += p[c];
                }
            }
        }
        let mut e = Emitters::default();
        for b in 0..bw * bh {
            if lum[b] > 0.0 {
                e.push(dir[b] / lum[b], rgb[b]);
            }
        }
        e
    }

    /// Irradiance `E(n) = sum_i w_i max(0, n . d_i)` on every normal, data-parallel over blocks of
    /// [`NORMAL_BLOCK`] normals. Cost O(M * P) for M normals and P emitters. Each normal's sum runs
    /// over the emitters in order, so the result is bit-identical whatever the thread count.
    pub fn irradiance(&self, normals: &[DVec3]) -> Vec<[f64; 3]> {
        let mut out = vec![[0.0; 3]; normals.len()];
        out.par_chunks_mut(NORMAL_BLOCK)
            .zip(normals.par_chunks(NORMAL_BLOCK))
            .for_each(|(o, n)| self.irradiance_block(n, o));
        out
    }

    /// Irradiance on up to [`NORMAL_BLOCK`] normals (`out.len() == normals.len()`).
    fn irradiance_block(&self, normals: &[DVec3], out: &mut [[f64; 3]]) {
        // Pad the block with zero normals (their sums stay 0 and are not written back).
        let mut nx = [0.0f64; NORMAL_BLOCK];
        let mut ny = [0.0f64; NORMAL_BLOCK];
        let mut nz = [0.0f64; NORMAL_BLOCK];
        for (k, n) in normals.iter().enumerate().take(NORMAL_BLOCK) {
            nx[k] = n.x;
            ny[k] = n.y;
            nz[k] = n.z;
        }
        let mut ar = [0.0f64; NORMAL_BLOCK];
        let mut ag = [0.0f64; NORMAL_BLOCK];
        let mut ab = [0.0f64; NORMAL_BLOCK];
        // Equal-length slices so that the indexing below needs no bounds checks.
        let p = self.len();
        let (dx, dy, dz) = (&self.dx[..p], &self.dy[..p], &self.dz[..p]);
        let (wr, wg, wb) = (&self.wr[..p], &self.wg[..p], &self.wb[..p]);
        for i in 0..p {
            let (x, y, z) = (dx[i], dy[i], dz[i]);
            let (r, g, b) = (wr[i], wg[i], wb[i]);
            for k in 0..NORMAL_BLOCK {
                let c = nx[k] * x + ny[k] * y + nz[k] * z;
                let c = if c > 0.0 { c } else { 0.0 };
                ar[k] += c * r;
                ag[k] += c * g;
                ab[k] += c * b;
            }
        }
        for (k, o) in out.iter_mut().enumerate().take(NORMAL_BLOCK) {
            *o = [ar[k], ag[k], ab[k]];
        }
    }
}

/// The per-pixel brute-force sum `E_c(n) = sum_p L_pc * max(0, n . d_p) * dOmega_p`, with
/// pixel-centre directions and exact row solid angles, accumulated in f64: the reference that
/// [`irradiance_exact`] (the same sum organised by rows) is checked against, and its benchmark
/// baseline.
///
/// Cost O(M * P) for M normals and P non-black pixels (a 512 x 256 probe on 20000 normals is
/// 2.6e9 multiply-adds per channel: about 1.7 s on 2 cores with the default x86-64 target, see
/// the crate's bench).
/// Data-parallel over normals with rayon; bit-identical whatever the thread count.
pub fn irradiance_brute_force(probe: &Image<Rgb>, normals: &[DVec3]) -> Vec<[f64; 3]> {
    Emitters::from_latlong(probe).irradiance(normals)
}

/// Fast approximation of [`irradiance_exact`]: the probe is reduced to a `size.0` x `size.1`
/// lat-long grid of blocks (use [`FAST_DEFAULT_SIZE`], 64 x 32) that conserve the power
/// `sum L dOmega` exactly, each at its luminance-weighted mean direction
/// ([`Emitters::from_latlong_downsampled`]), then the exact loop runs over the blocks.
/// Cost O(P) + O(M * B) for B <= 2048 blocks: 64x fewer emitters than the exact path at 512 x 256.
///
/// Measured error against the exact path on the five bundled 512 x 256 probes, 20000 Fibonacci
/// normals, 64 x 32 blocks (CONVENTIONS section 5 metrics; asserted by
/// `tests/ground_truth.rs`):
///
/// | probe | mean_err% | max_err% | rel_mean% | rel_max% |
/// |---|---|---|---|---|
/// | apartment | 0.067 | 0.34 | 0.085 | 0.67 |
/// | esplanade | 0.028 | 0.31 | 0.050 | 1.17 |
/// | night | 0.074 | 0.43 | 0.112 | 3.60 |
/// | sky | 0.032 | 0.81 | 0.068 | 2.53 |
/// | sunset | 0.073 | 0.33 | 0.099 | 1.31 |
///
/// Bound (asserted): mean_err% < 0.1 and max_err% < 1.0 on every bundled probe. The error comes
/// from blocks that straddle a normal's horizon (the clamp applies to the block, not its pixels).
pub fn irradiance_fast(
    probe: &Image<Rgb>,
    normals: &[DVec3],
    size: (usize, usize),
) -> Vec<[f64; 3]> {
    Emitters::from_latlong_downsampled(probe, size.0, size.1).irradiance(normals)
}

/// The exact irradiance of a probe on a set of normals, with its channel means.
#[derive(Clone, Debug, PartialEq)]
pub struct GroundTruth {
    /// The normals (unit vectors, world frame).
    pub normals: Vec<DVec3>,
    /// Exact irradiance per normal, RGB.
    pub irradiance: Vec<[f64; 3]>,
    /// Per-channel mean irradiance `mu_c` over the normals (the error metrics' scale).
    pub mean: [f64; 3],
}

impl GroundTruth {
    /// Exact irradiance of a lat-long probe on the given normals ([`irradiance_exact`]).
    pub fn exact(probe: &Image<Rgb>, normals: Vec<DVec3>) -> Self {
        let irradiance = irradiance_exact(probe, &normals);
        let mean = channel_means(&irradiance);
        GroundTruth {
            normals,
            irradiance,
            mean,
        }
    }

    /// Exact irradiance on `m` Fibonacci normals (CONVENTIONS section 5; 20000 by default).
    pub fn fibonacci(probe: &Image<Rgb>, m: usize) -> Self {
        Self::exact(probe, fibonacci_normals(m))
    }

    /// Error of an approximation given on the same normals, in the same order.
    ///
    /// # Panics
    /// If `approx.len()` differs from the number of normals.
    pub fn error_of(&self, approx: &[[f64; 3]]) -> ibl_metrics::IrradianceError {
        ibl_metrics::IrradianceError::between(&self.irradiance, approx)
    }
}

//! Adaptive sampling of the reference mode: the same number of paths as `spp` per pixel, spent
//! where the image is noisy, without bias.
//!
//! Most pixels of a differential render are quiet (a floor far from the objects takes its exact
//! unshadowed light in every sample) while a few (the objects, their contact shadows) carry
//! almost all of the noise. With `n_i` samples a pixel's variance is `sigma_i^2 / n_i`; a sample
//! of it costs `c_i` (its paths' rays: one on a quiet floor, several on an object), and for a
//! fixed cost `sum_i c_i n_i` the sum `sum_i sigma_i^2 / n_i` is least at `n_i ~ sigma_i /
//! sqrt(c_i)` (Lagrange), so the noisy pixels should take more than their share and the quiet
//! ones less, the more so the cheaper they are. Here `sigma_i` is measured relative to the
//! pixel's brightness, `sigma_i^2 = Var(Y) / (mean(Y)^2 + delta^2)` (`Y` a sample's luminance
//! with the objects, the background's where the camera ray escaped; `delta` a tenth of the
//! background's mean luminance, so black pixels do not divide by 0), because relative noise is
//! what the eye and the benchmarks' relative MSE see.
//!
//! **Two passes.** Every pixel first takes a pilot of `n_0 = max(2, spp / 8)` samples (samples
//! `0..n_0` of its stream), from which its `sigma_i^2` and `c_i` (rays per sample) are
//! estimated. It then takes samples `n_0..n_i`, and its value is the mean of all `n_i`.
//!
//! **Unbiased.** A pixel's count must not depend on its own samples: a pixel whose pilot drew a
//! rare bright path would otherwise take more samples and dilute it, and the mean over the
//! renders would fall short. So the pixels are split like a chessboard, and a pixel's count is
//! computed from the pilots of the other colour only: its score `s_i` is the root of the mean
//! `sigma_j^2` over the mean `c_j` of the other colour's pixels in its 5 x 5 neighbourhood (which
//! also smooths the pilot's noisy estimates), and the counts of one colour are normalised over
//! that colour alone with its own (other-colour) scores. Samples of different pixels are
//! independent (each pixel scrambles its own stream), so `E[mean | n_i] = mu_i` and the
//! estimate is unbiased for any allocation rule.
//!
//! **Counts.** Each colour `C` takes the cost of `spp - n_0` further samples per pixel, `(spp -
//! n_0) sum_C c_j` with its pixels' costs `c_j` as the pilots around them measured them: a
//! quarter spread evenly (`(spp - n_0) / 4` each: a rare event that no pilot around a pixel
//! caught is still looked for), three quarters in proportion to `s_i` per unit of cost. Counts
//! are rounded down and capped at `16 spp` (and at the sampler's limit), so a render costs about
//! what `spp` samples everywhere would (the pilots' costs are estimates: the paths traced are
//! reported).

use crate::sampler::SOBOL_MAX_SAMPLES;

/// Share of the further samples spread evenly (module notes, "Counts").
const EVEN_SHARE: f64 = 0.25;

/// Half the side of the neighbourhood whose other-colour pilots score a pixel (5 x 5).
const NEIGHBOURHOOD_RADIUS: usize = 2;

/// Most samples a pixel takes, as a multiple of `spp`.
const MAX_FACTOR: u32 = 16;

/// The pilot's samples per pixel for a mean of `spp` (module notes); `spp` itself (nothing left
/// to allocate) below 4.
pub fn pilot_samples(spp: u32) -> u32 {
    if spp < 4 { spp } else { (spp / 8).max(2) }
}

/// A pixel's pilot: the count, sum and sum of squares of its samples' luminance, and the rays
/// they traced (module notes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PilotMoments {
    /// Samples.
    pub count: u32,
    /// Sum of their luminance.
    pub sum: f64,
    /// Sum of the squares of their luminance.
    pub sum_of_squares: f64,
    /// Rays they traced.
    pub rays: u64,
}

impl PilotMoments {
    /// `Var(Y) / (mean(Y)^2 + delta^2)`: the relative variance of one sample (0 for fewer than
    /// two samples).
    pub fn relative_variance(&self, delta: f64) -> f64 {
        if self.count < 2 {
            return 0.0;
        }
        let n = f64::from(self.count);
        let mean = self.sum / n;
        let variance = ((self.sum_of_squares - self.sum * mean) / (n - 1.0)).max(0.0);
        let relative = variance / (mean * mean + delta * delta);
        if relative.is_finite() { relative } else { 0.0 }
    }

    /// Rays per sample, at least 1 (a sample whose camera ray escaped still costs one).
    pub fn cost(&self) -> f64 {
        (self.rays as f64 / f64::from(self.count.max(1))).max(1.0)
    }
}

/// Each pixel's total samples (pilot included) for a `width x height` image whose pixels'
/// pilots of `pilot` samples measured relative variances `relative_variance` and costs per
/// sample `cost` (row-major; [`PilotMoments`]), for the cost of `spp` samples everywhere
/// (module notes).
pub fn sample_counts(
    relative_variance: &[f64],
    cost: &[f64],
    width: usize,
    height: usize,
    spp: u32,
    pilot: u32,
) -> Vec<u32> {
    debug_assert_eq!(relative_variance.len(), width * height);
    debug_assert_eq!(cost.len(), width * height);
    let cap = spp
        .saturating_mul(MAX_FACTOR)
        .min(SOBOL_MAX_SAMPLES)
        .max(spp);
    let further = f64::from(spp.saturating_sub(pilot));
    // Each pixel's score and cost from the other colour's pilots around it.
    let score = |x: usize, y: usize| -> (f64, f64) {
        let (mut sum, mut costs, mut count) = (0.0, 0.0, 0u32);
        for j in y.saturating_sub(NEIGHBOURHOOD_RADIUS)..(y + NEIGHBOURHOOD_RADIUS + 1).min(height)
        {
            for i in
                x.saturating_sub(NEIGHBOURHOOD_RADIUS)..(x + NEIGHBOURHOOD_RADIUS + 1).min(width)
            {
                if (i + j) % 2 != (x + y) % 2 {
                    sum += relative_variance[j * width + i];
                    costs += cost[j * width + i].max(1.0);
                    count += 1;
                }
            }
        }
        if count == 0 {
            (0.0, 1.0)
        } else {
            let cost = costs / f64::from(count);
            ((sum / f64::from(count) / cost).sqrt(), cost)
        }
    };
    let scores: Vec<(f64, f64)> = (0..width * height)
        .map(|k| score(k % width, k / width))
        .collect();
    let mut counts = vec![pilot; width * height];
    for colour in 0..2 {
        let members = || (0..width * height).filter(move |k| (k % width + k / width) % 2 == colour);
        let size = members().count();
        if size == 0 {
            continue;
        }
        // The colour's cost to share, and its scores' weight in cost.
        let budget: f64 = members().map(|k| scores[k].1).sum::<f64>() * further;
        let weighted: f64 = members().map(|k| scores[k].0 * scores[k].1).sum();
        for k in members() {
            let targeted = if weighted > 0.0 {
                (1.0 - EVEN_SHARE) * budget * scores[k].0 / weighted
            } else {
                (1.0 - EVEN_SHARE) * further
            };
            // Saturating cast: the count is finite and non-negative.
            let extra = (EVEN_SHARE * further + targeted).floor() as u32;
            counts[k] = pilot.saturating_add(extra).min(cap);
        }
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pilot_is_an_eighth_and_small_budgets_are_not_split() {
        assert_eq!(pilot_samples(1), 1);
        assert_eq!(pilot_samples(3), 3);
        assert_eq!(pilot_samples(4), 2);
        assert_eq!(pilot_samples(64), 8);
    }

    #[test]
    fn relative_variance_of_known_samples() {
        // Samples 1, 2, 3: mean 2, variance 1; relative to 2^2 + 0 = 4.
        let m = PilotMoments {
            count: 3,
            sum: 6.0,
            sum_of_squares: 14.0,
            rays: 0,
        };
        assert!((m.relative_variance(0.0) - 0.25).abs() < 1e-12);
        assert_eq!(PilotMoments::default().relative_variance(0.1), 0.0);
    }

    #[test]
    fn noisy_neighbourhoods_take_more_within_the_budget_and_no_pixel_sees_its_own_pilot() {
        let (w, h, spp) = (40, 30, 64);
        let pilot = pilot_samples(spp);
        // A noisy square in a quiet image.
        let variance: Vec<f64> = (0..w * h)
            .map(|k| {
                let (x, y) = (k % w, k / w);
                if (10..20).contains(&x) && (10..20).contains(&y) {
                    4.0
                } else {
                    0.01
                }
            })
            .collect();
        let cost = vec![3.0; w * h];
        let counts = sample_counts(&variance, &cost, w, h, spp, pilot);
        let total: u64 = counts.iter().map(|&n| u64::from(n)).sum();
        assert!(total <= (w * h) as u64 * u64::from(spp));
        // Rounding down loses less than a sample per pixel (1200 here of 76800), the cap at
        // 16 spp what the noisy square would take beyond it.
        assert!(
            total > (w * h) as u64 * u64::from(spp) * 97 / 100,
            "{total}"
        );
        assert!(counts[15 * w + 15] > 4 * spp, "{}", counts[15 * w + 15]);
        // Every pixel keeps at least the pilot and a quarter of its uniform share.
        let least = pilot + (spp - pilot) / 4;
        assert!(
            counts.iter().all(|&n| n + 1 >= least),
            "{:?}",
            counts.iter().min()
        );
        // A pixel's own pilot changes no count of its colour, its own included.
        for k in [0, 15 * w + 15, 15 * w + 16, w * h - 1] {
            let mut changed = variance.clone();
            changed[k] = 1e6;
            let mut dearer = cost.clone();
            dearer[k] = 50.0;
            let again = sample_counts(&changed, &dearer, w, h, spp, pilot);
            for j in 0..w * h {
                if (j % w + j / w) % 2 == (k % w + k / w) % 2 {
                    assert_eq!(again[j], counts[j], "pixel {j} after pixel {k}'s pilot");
                }
            }
        }
        // Nothing to tell apart: every pixel takes spp.
        let even = sample_counts(&vec![0.0; w * h], &cost, w, h, spp, pilot);
        assert!(even.iter().all(|&n| n == spp));
        // Where half the image costs four times as much per sample, equally noisy pixels there
        // take half as many (n ~ sigma / sqrt(c)), and the cost stays that of spp everywhere.
        let costly: Vec<f64> = (0..w * h)
            .map(|k| if k % w < w / 2 { 4.0 } else { 1.0 })
            .collect();
        let counts = sample_counts(&vec![1.0; w * h], &costly, w, h, spp, pilot);
        let (cheap, dear) = (counts[15 * w + 30] - pilot, counts[15 * w + 5] - pilot);
        let targeted = |n: u32| f64::from(n) - 0.25 * f64::from(spp - pilot);
        assert!(
            (targeted(cheap) / targeted(dear) - 2.0).abs() < 0.05,
            "{cheap} {dear}"
        );
        let spent: f64 = counts
            .iter()
            .zip(&costly)
            .map(|(&n, c)| f64::from(n) * c)
            .sum();
        let uniform: f64 = costly.iter().map(|c| c * f64::from(spp)).sum();
        assert!(
            spent <= uniform && spent > 0.98 * uniform,
            "{spent} {uniform}"
        );
    }
}

//! Pearson chi-square tests of every distribution the renderer samples: the two samplers
//! (Owen-scrambled Sobol and independent PCG32), the (0,2)-net property of the Sobol pairs, the
//! cosine hemisphere and uniform cone warps, the discrete distribution, the environment light's
//! importance sampling and the BSDFs' sampling.
//!
//! Method (as in pbrt-v4's `chi2` tests, Jakob's Mitsuba `ChiSquareTest`): draw `n` samples,
//! count them in cells of a fixed partition, and compare with the expected counts `n * P(cell)`,
//! `P` integrated from the density the sampler claims (exactly for the warps, by a midpoint rule
//! fine enough to be exact to well below the counts' own noise for the others). Cells expecting
//! fewer than 5 samples are pooled (the chi-square approximation needs about 5 per cell). The
//! statistic is turned into a tail probability by the Wilson-Hilferty cube-root normal
//! approximation (accurate to a few per cent of the tail probability for 30 or more degrees of
//! freedom, every test here has more); a test fails when that probability is below `1e-4`
//! (z > 3.72). The seeds are fixed, so each test passes or fails the same way on every run: a
//! correct sampler fails one of these about once in 10^4 changes of seed. A sampler whose density
//! is off by `d` (relative) in a region holding a fraction `f` of the samples adds about
//! `n f d^2` to the statistic: with `n = 10^6` a 2 % error over a tenth of the sphere is caught.

#![allow(clippy::unwrap_used)] // tests may panic

use std::f64::consts::PI;

use glam::{Mat3, Vec3};
use ibl_core::{Image, Rgb};
use ibl_render::environment::{EnvironmentLight, SampleRegion};
use ibl_render::material::Bsdf;
use ibl_render::sampler::{SampleStream, SamplerKind};
use ibl_render::sampling::{
    Distribution1D, OrthonormalBasis, PixelRng, UniformCone, sample_cosine_hemisphere,
};
use ibl_scene::Material;

/// Upper tail probability below which a test fails.
const SIGNIFICANCE: f64 = 1e-4;

/// Pearson's statistic of `observed` against `expected` counts, cells expecting fewer than 5
/// pooled (with the next cells until the pool expects 5; a cell the quadrature gives no mass is
/// pooled too, since a texel edge can hide between its points); returns the tail probability,
/// the statistic and the degrees of freedom.
fn chi_square_tail(observed: &[f64], expected: &[f64]) -> (f64, f64, usize) {
    assert_eq!(observed.len(), expected.len());
    let mut cells = Vec::new();
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < 0.0 || !e.is_finite() {
            panic!("expected count {e}");
        }
        pool_o += o;
        pool_e += e;
        if pool_e >= 5.0 {
            cells.push((pool_o, pool_e));
            (pool_o, pool_e) = (0.0, 0.0);
        }
    }
    if pool_e > 0.0 {
        match cells.last_mut() {
            Some(last) => {
                last.0 += pool_o;
                last.1 += pool_e;
            }
            None => cells.push((pool_o, pool_e)),
        }
    }
    let statistic: f64 = cells.iter().map(|&(o, e)| (o - e) * (o - e) / e).sum();
    let dof = cells.len().saturating_sub(1).max(1);
    (upper_tail(statistic, dof as f64), statistic, dof)
}

/// `P(X >= x)` for a chi-square variable of `k` degrees of freedom, by Wilson and Hilferty's
/// (1931) normal approximation of `(X / k)^(1/3)`.
fn upper_tail(x: f64, k: f64) -> f64 {
    let m = 1.0 - 2.0 / (9.0 * k);
    let s = (2.0 / (9.0 * k)).sqrt();
    let z = ((x / k).cbrt() - m) / s;
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}

/// The complementary error function (Abramowitz and Stegun 7.1.26, |error| < 1.5e-7, enough for
/// tail probabilities compared with 1e-4), for `x` of either sign.
fn erfc(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x.abs());
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let e = poly * (-x * x).exp();
    if x >= 0.0 { e } else { 2.0 - e }
}

fn assert_fits(what: &str, observed: &[f64], expected: &[f64]) {
    let (p, statistic, dof) = chi_square_tail(observed, expected);
    assert!(
        p > SIGNIFICANCE,
        "{what}: chi-square {statistic:.1} on {dof} degrees of freedom, tail probability {p:.2e}"
    );
}

/// A cell partition of the sphere about `axis`: `nz` bands uniform in `z = cos(theta)` on
/// `[-1, 1]` times `nphi` sectors, each `4 pi / (nz nphi)` sr.
struct SphereGrid {
    basis: OrthonormalBasis,
    nz: usize,
    nphi: usize,
}

impl SphereGrid {
    fn new(axis: Vec3, nz: usize, nphi: usize) -> Self {
        SphereGrid {
            basis: OrthonormalBasis::from_normal(axis),
            nz,
            nphi,
        }
    }

    fn cells(&self) -> usize {
        self.nz * self.nphi
    }

    fn cell_of(&self, d: Vec3) -> usize {
        let l = self.basis.to_local(d.normalize());
        let z = f64::from(l.z).clamp(-1.0, 1.0);
        let iz = (((z + 1.0) * 0.5 * self.nz as f64) as usize).min(self.nz - 1);
        let phi = f64::from(l.y).atan2(f64::from(l.x)) + PI;
        let ip = ((phi / (2.0 * PI) * self.nphi as f64) as usize).min(self.nphi - 1);
        iz * self.nphi + ip
    }

    /// `integral of pdf` over every cell by the midpoint rule on `sub_z x sub_phi` points per
    /// cell (uniform in solid angle, so each point weighs `cell / (sub_z sub_phi)`).
    fn integrate(&self, sub_z: usize, sub_phi: usize, pdf: impl Fn(Vec3) -> f64) -> Vec<f64> {
        let cell = 4.0 * PI / self.cells() as f64;
        let mut out = vec![0.0; self.cells()];
        for iz in 0..self.nz {
            for ip in 0..self.nphi {
                let mut sum = 0.0;
                for a in 0..sub_z {
                    let z =
                        -1.0 + 2.0 * (iz as f64 + (a as f64 + 0.5) / sub_z as f64) / self.nz as f64;
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    for b in 0..sub_phi {
                        let phi = 2.0 * PI * (ip as f64 + (b as f64 + 0.5) / sub_phi as f64)
                            / self.nphi as f64
                            - PI;
                        let local =
                            Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                        sum += pdf(self.basis.to_world(local));
                    }
                }
                out[iz * self.nphi + ip] = sum * cell / (sub_z * sub_phi) as f64;
            }
        }
        out
    }
}

// ---------------------------------------------------------------------------------------------
// Samplers.

/// Counts of a pair of numbers over a `g x g` grid of `[0, 1)^2`, from `pixels` pixels of
/// `spp` samples, the pair being the `pair`-th draw of each sample's stream.
fn pair_histogram(kind: SamplerKind, pixels: u64, spp: u32, pair: usize, g: usize) -> Vec<f64> {
    let mut counts = vec![0.0; g * g];
    for pixel in 0..pixels {
        for s in 0..spp {
            let mut stream = SampleStream::new(kind, 5, pixel, s);
            for _ in 0..pair {
                stream.next_2d();
            }
            let [a, b] = stream.next_2d();
            let (i, j) = ((a * g as f32) as usize, (b * g as f32) as usize);
            counts[j.min(g - 1) * g + i.min(g - 1)] += 1.0;
        }
    }
    counts
}

#[test]
fn both_samplers_are_uniform_over_pixels_and_pairs() {
    // 4096 pixels x 16 samples per pixel = 65536 points per pair, on a 32 x 32 grid (64 expected
    // per cell). The Sobol points are stratified within each pixel, so their statistic is far
    // below the chi-square's mean; only a skewed density could fail the upper tail.
    let g = 32;
    for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
        for pair in [0, 1, 7] {
            let counts = pair_histogram(kind, 4096, 16, pair, g);
            let total: f64 = counts.iter().sum();
            let expected = vec![total / (g * g) as f64; g * g];
            assert_fits(&format!("{kind:?} pair {pair}"), &counts, &expected);
        }
    }
}

#[test]
fn sobol_pairs_are_independent_of_each_other() {
    // The first coordinates of pairs 0 and 1 of the same sample, jointly: uniform on [0, 1)^2
    // when the per-pair shuffles decorrelate the pairs (the same Sobol dimension in both pairs
    // without them would put every point on the diagonal).
    let g = 32;
    let mut counts = vec![0.0; g * g];
    for pixel in 0..4096u64 {
        for s in 0..16 {
            let mut stream = SampleStream::new(SamplerKind::Sobol, 9, pixel, s);
            let a = stream.next_2d()[0];
            let b = stream.next_2d()[0];
            let (i, j) = ((a * g as f32) as usize, (b * g as f32) as usize);
            counts[j.min(g - 1) * g + i.min(g - 1)] += 1.0;
        }
    }
    let expected = vec![65536.0 / (g * g) as f64; g * g];
    assert_fits("Sobol pairs 0 and 1", &counts, &expected);
}

#[test]
fn sobol_points_of_a_pixel_form_a_zero_m_two_net() {
    // Deterministic: for 2^m samples per pixel, every pair's points put exactly one point in
    // each of the 2^m elementary intervals [a 2^-k, (a + 1) 2^-k) x [b 2^-(m-k), ...), for every
    // k = 0..=m (Owen scrambling and the index shuffle keep Sobol's (0,2)-sequence nets).
    for m in 0..=8u32 {
        let n = 1u32 << m;
        for pixel in [0u64, 1, 77, 123_456] {
            for pair in [0usize, 1, 5] {
                let points: Vec<[f32; 2]> = (0..n)
                    .map(|s| {
                        let mut stream = SampleStream::new(SamplerKind::Sobol, 3, pixel, s);
                        for _ in 0..pair {
                            stream.next_2d();
                        }
                        stream.next_2d()
                    })
                    .collect();
                for k in 0..=m {
                    let (nx, ny) = (1u32 << k, 1u32 << (m - k));
                    let mut seen = vec![false; n as usize];
                    for p in &points {
                        let (i, j) = ((p[0] * nx as f32) as u32, (p[1] * ny as f32) as u32);
                        let cell = (j * nx + i) as usize;
                        assert!(
                            !seen[cell],
                            "m {m}, pixel {pixel}, pair {pair}: two points in interval {cell} of \
                             {nx} x {ny}"
                        );
                        seen[cell] = true;
                    }
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Warps and the discrete distribution.

#[test]
fn cosine_hemisphere_samples_follow_cos_over_pi() {
    // Cells uniform in solid angle about +Z: the expected share of a cell is the integral of
    // cos / pi over it, cos(theta)^2 differences in closed form: (z1^2 - z0^2) / nphi.
    let grid = SphereGrid::new(Vec3::Z, 40, 40);
    let n = 1_000_000;
    let mut rng = PixelRng::new(21, 0, 0);
    let mut counts = vec![0.0; grid.cells()];
    for _ in 0..n {
        counts[grid.cell_of(sample_cosine_hemisphere(rng.next_f32(), rng.next_f32()))] += 1.0;
    }
    let expected: Vec<f64> = (0..grid.cells())
        .map(|c| {
            let iz = c / grid.nphi;
            let z0 = -1.0 + 2.0 * iz as f64 / grid.nz as f64;
            let z1 = z0 + 2.0 / grid.nz as f64;
            let share = (z1.max(0.0).powi(2) - z0.max(0.0).powi(2)) / grid.nphi as f64;
            n as f64 * share
        })
        .collect();
    assert_fits("cosine hemisphere", &counts, &expected);
}

#[test]
fn cone_samples_are_uniform_in_solid_angle() {
    // A 25-degree cone about +Z: cells uniform in 1 - cos(theta) within the cone and in phi, each
    // expecting the same count.
    let cone = UniformCone::from_half_angle(25_f32.to_radians()).unwrap();
    let omc_max = f64::from(1.0 - cone.cos_half_angle());
    let (nt, nphi) = (30, 30);
    let n = 900_000;
    let mut rng = PixelRng::new(22, 0, 0);
    let mut counts = vec![0.0; nt * nphi];
    for _ in 0..n {
        let d = cone.sample(rng.next_f32(), rng.next_f32());
        let omc = 1.0 - f64::from(d.z);
        let it = ((omc / omc_max * nt as f64) as usize).min(nt - 1);
        let phi = f64::from(d.y).atan2(f64::from(d.x)) + PI;
        let ip = ((phi / (2.0 * PI) * nphi as f64) as usize).min(nphi - 1);
        counts[it * nphi + ip] += 1.0;
    }
    let expected = vec![n as f64 / (nt * nphi) as f64; nt * nphi];
    assert_fits("uniform cone", &counts, &expected);
}

#[test]
fn discrete_samples_follow_their_weights() {
    let weights: Vec<f64> = (0..200)
        .map(|k| {
            if k % 7 == 3 {
                0.0
            } else {
                1.0 + (k as f64 * 0.37).sin().abs() * 9.0
            }
        })
        .collect();
    let dist = Distribution1D::new(weights.iter().copied());
    let n = 500_000;
    let mut rng = PixelRng::new(23, 0, 0);
    let mut counts = vec![0.0; weights.len()];
    for _ in 0..n {
        counts[dist.sample(rng.next_f32()).unwrap().index] += 1.0;
    }
    let total: f64 = weights.iter().sum();
    let expected: Vec<f64> = weights.iter().map(|w| n as f64 * w / total).collect();
    assert_fits("discrete distribution", &counts, &expected);
}

// ---------------------------------------------------------------------------------------------
// The environment light and the BSDFs.

/// A 32 x 16 map of pseudo-random radiance with a quarter of the texels black and a sun.
fn random_map() -> Image<Rgb> {
    let mut rng = PixelRng::new(11, 0, 0);
    let mut data: Vec<Rgb> = (0..32 * 16)
        .map(|_| {
            if rng.next_f32() < 0.25 {
                Rgb::ZERO
            } else {
                Rgb::new(rng.next_f32(), rng.next_f32(), rng.next_f32() * 0.1)
            }
        })
        .collect();
    data[3 * 32 + 5] = Rgb::new(8.0, 7.6, 6.0);
    Image::from_vec(32, 16, data).unwrap()
}

#[test]
fn environment_samples_follow_their_density() {
    // Cells (30 bands x 60 sectors about a tilted axis) deliberately not aligned with the texels;
    // the expected share of a cell is the density integrated over it on 32 x 32 points. Only the
    // cells a texel edge crosses are inexact, by at most 1/32 of their share times the density
    // jump across the edge: the sun texel (radiance 8 against about 0.5) holds about 5 % of the
    // samples over some 6 cells, so its edge cells are off by 1 to 2 %, adding a few units to a
    // statistic whose tail starts near 1800 (12x12 points, a 3x larger error, failed).
    let rotation = Mat3::from_rotation_y(0.7) * Mat3::from_rotation_x(-0.4);
    let env = EnvironmentLight::new(random_map(), rotation, 1.0).unwrap();
    let grid = SphereGrid::new(Vec3::new(0.3, 0.9, -0.2).normalize(), 30, 60);
    let n = 1_000_000;
    let mut rng = PixelRng::new(24, 0, 0);
    let mut counts = vec![0.0; grid.cells()];
    for _ in 0..n {
        let s = env.sample(rng.next_f32(), rng.next_f32());
        counts[grid.cell_of(s.direction)] += 1.0;
    }
    let shares = grid.integrate(32, 32, |d| f64::from(env.pdf(d)));
    let expected: Vec<f64> = shares.iter().map(|p| p * n as f64).collect();
    assert_fits("environment importance sampling", &counts, &expected);
}

#[test]
fn half_sphere_and_normal_bin_samples_follow_their_density() {
    // The floor's and the ceiling's regions under a probe turned about its up axis, and two
    // normal bins' (`normal_bins`), on the same tilted cells as above (their expected shares
    // integrated the same way; the cells the horizon crosses are exact there too, the density
    // being 0 below it, and a bin's density is constant per texel, so only texel edges err).
    let env = EnvironmentLight::new(random_map(), Mat3::from_rotation_y(0.7), 1.0).unwrap();
    let grid = SphereGrid::new(Vec3::new(0.3, 0.9, -0.2).normalize(), 30, 60);
    let bins = [
        env.region_for(Vec3::new(0.3, 0.9, -0.2).normalize()),
        env.region_for(Vec3::new(-0.6, 0.1, 0.8).normalize()),
    ];
    for (region, seed) in [
        (SampleRegion::Upper, 25),
        (SampleRegion::Lower, 26),
        (bins[0], 27),
        (bins[1], 28),
    ] {
        let n = 1_000_000;
        let mut rng = PixelRng::new(seed, 0, 0);
        let mut counts = vec![0.0; grid.cells()];
        for _ in 0..n {
            let s = env.sample_in(region, rng.next_f32(), rng.next_f32());
            counts[grid.cell_of(s.direction)] += 1.0;
        }
        let shares = grid.integrate(32, 32, |d| f64::from(env.radiance_and_pdf_in(region, d).1));
        let expected: Vec<f64> = shares.iter().map(|p| p * n as f64).collect();
        assert_fits(
            &format!("{region:?} half importance sampling"),
            &counts,
            &expected,
        );
    }
}

#[test]
fn bsdf_samples_follow_their_density() {
    // Diffuse and glossy (Lambert + Phong of exponents 10 and 200) at normal, oblique and grazing
    // incidence. The returned samples are compared with the density normalised over the sphere
    // (a draw that returns no sample, a Phong direction below the surface, is the mass the density
    // leaves out; `tests/sampling.rs` checks that fraction against the density's integral). Cells:
    // 40 x 40 about the normal, the density integrated on 16 x 16 points per cell (a Phong lobe
    // of exponent 200 is about 0.1 rad wide, 25 integration points across, while a cell is 0.05
    // sr). At normal incidence the exponent-200 lobe lies inside the first band (z > 0.95), where
    // the density goes as z^200: 64 points per cell along z keep the midpoint rule's error there
    // near 1e-3 relative (h^2 f'' / 24 f with h = 0.05 / 64), below the counts' 1.3 % noise.
    let n = Vec3::new(0.2, 0.9, -0.3).normalize();
    let materials = [
        Material::Diffuse {
            albedo: Rgb::new(0.8, 0.5, 0.2),
        },
        Material::Glossy {
            albedo: Rgb::splat(0.3),
            specular: Rgb::splat(0.6),
            exponent: 10.0,
        },
        Material::Glossy {
            albedo: Rgb::splat(0.2),
            specular: Rgb::splat(0.7),
            exponent: 200.0,
        },
    ];
    let basis = OrthonormalBasis::from_normal(n);
    for (m, material) in materials.iter().enumerate() {
        for tilt_deg in [0.0_f32, 50.0, 80.0] {
            let t = tilt_deg.to_radians();
            let wo = basis.to_world(Vec3::new(t.sin(), 0.0, t.cos()));
            let bsdf = Bsdf::new(material, n, n);
            let grid = SphereGrid::new(n, 40, 40);
            let draws = 600_000;
            let mut rng = PixelRng::new(30 + m as u64, 0, 0);
            let mut counts = vec![0.0; grid.cells()];
            let mut returned = 0.0;
            for _ in 0..draws {
                let u = [rng.next_f32(), rng.next_f32(), rng.next_f32()];
                if let Some(s) = bsdf.sample(wo, u) {
                    counts[grid.cell_of(s.wi)] += 1.0;
                    returned += 1.0;
                }
            }
            let shares = grid.integrate(64, 16, |wi| f64::from(bsdf.pdf(wo, wi)));
            let mass: f64 = shares.iter().sum();
            let expected: Vec<f64> = shares.iter().map(|p| p / mass * returned).collect();
            assert_fits(
                &format!("{material:?} at {tilt_deg} degrees"),
                &counts,
                &expected,
            );
        }
    }
}

//! Monte Carlo checks of the sampling building blocks against closed forms: random numbers, bases,
//! hemisphere and cone sampling, the environment light's importance sampling and density, and the
//! BSDFs' white furnace, weights and densities.
//!
//! Statistical checks are z-tests on a fixed seed: the estimate must lie within `K` standard
//! errors of the closed form (K stated per test); deterministic checks state their tolerance.

use std::f64::consts::PI;

use glam::{Mat3, Vec3};
use ibl_core::{Image, LatLong, Rgb};
use ibl_render::environment::{EnvSample, EnvironmentLight, SampleRegion};
use ibl_render::material::Bsdf;
use ibl_render::sampling::{
    OrthonormalBasis, PixelRng, UniformCone, cosine_hemisphere_pdf, power_heuristic,
    sample_cosine_hemisphere,
};
use ibl_scene::Material;

/// Running mean and standard error of a sample of f64 values.
#[derive(Default)]
struct Stats {
    n: f64,
    sum: f64,
    sum_sq: f64,
}

impl Stats {
    fn push(&mut self, x: f64) {
        self.n += 1.0;
        self.sum += x;
        self.sum_sq += x * x;
    }

    fn mean(&self) -> f64 {
        self.sum / self.n
    }

    fn std_error(&self) -> f64 {
        let mean = self.mean();
        ((self.sum_sq / self.n - mean * mean).max(0.0) / (self.n - 1.0)).sqrt()
    }

    /// Asserts `|mean - expected| <= k * std_error + floor`.
    fn assert_near(&self, expected: f64, k: f64, floor: f64, what: &str) {
        let (mean, se) = (self.mean(), self.std_error());
        assert!(
            (mean - expected).abs() <= k * se + floor,
            "{what}: mean {mean} expected {expected} (std error {se}, {k} sigma + {floor})"
        );
    }
}

fn uniform_dir(rng: &mut PixelRng) -> Vec3 {
    UniformCone::SPHERE.sample(rng.next_f32(), rng.next_f32())
}

// ---------------------------------------------------------------------------------------------
// Random numbers, bases, hemisphere and cone.

#[test]
fn pixel_rng_is_deterministic_uniform_and_decorrelated() {
    let first: Vec<f32> = {
        let mut rng = PixelRng::new(7, 1234, 5);
        (0..8).map(|_| rng.next_f32()).collect()
    };
    let again: Vec<f32> = {
        let mut rng = PixelRng::new(7, 1234, 5);
        (0..8).map(|_| rng.next_f32()).collect()
    };
    assert_eq!(first, again);
    for (seed, pixel, sample) in [(8, 1234, 5), (7, 1235, 5), (7, 1234, 6)] {
        let mut rng = PixelRng::new(seed, pixel, sample);
        let other: Vec<f32> = (0..8).map(|_| rng.next_f32()).collect();
        assert_ne!(first, other);
    }
    // First number of each of 100k neighbouring (pixel, sample) streams: uniform moments and no
    // correlation between neighbours (std error of a mean of n uniforms: sqrt(1/12 / n)).
    let mut mean = Stats::default();
    let mut square = Stats::default();
    let mut lag = Stats::default();
    let mut previous = 0.5_f64;
    for pixel in 0..1000_u64 {
        for sample in 0..100_u32 {
            let x = f64::from(PixelRng::new(3, pixel, sample).next_f32());
            assert!((0.0..1.0).contains(&x));
            mean.push(x);
            square.push(x * x);
            lag.push((x - 0.5) * (previous - 0.5));
            previous = x;
        }
    }
    mean.assert_near(0.5, 4.0, 0.0, "mean of first draws");
    square.assert_near(1.0 / 3.0, 4.0, 0.0, "second moment of first draws");
    lag.assert_near(0.0, 4.0, 0.0, "lag-1 covariance across streams");
}

#[test]
fn orthonormal_basis_is_right_handed_and_orthonormal() {
    let mut rng = PixelRng::new(1, 0, 0);
    let mut normals: Vec<Vec3> = (0..10_000).map(|_| uniform_dir(&mut rng)).collect();
    normals.extend([
        Vec3::Z,
        Vec3::NEG_Z,
        Vec3::X,
        Vec3::Y,
        Vec3::new(0.0, 1e-7, -1.0).normalize(),
    ]);
    for n in normals {
        let b = OrthonormalBasis::from_normal(n);
        for (v, what) in [(b.tangent, "tangent"), (b.bitangent, "bitangent")] {
            assert!((v.length() - 1.0).abs() < 1e-5, "{what} of {n} not unit");
            assert!(v.dot(n).abs() < 1e-5, "{what} of {n} not perpendicular");
        }
        assert!(b.tangent.dot(b.bitangent).abs() < 1e-5);
        assert!(
            (b.tangent.cross(b.bitangent) - n).length() < 1e-5,
            "left-handed at {n}"
        );
        let v = Vec3::new(0.3, -0.2, 0.9);
        assert!((b.to_local(b.to_world(v)) - v).length() < 1e-5);
        assert!((b.to_world(Vec3::Z) - n).length() < 1e-6);
    }
}

#[test]
fn cosine_sampling_integrates_cosine_moments() {
    // E[cos / pdf] = integral of cos over the hemisphere = pi (every sample exactly pi), and
    // E[cos^2 / pdf] = 2 pi / 3 (z-test, 4 sigma).
    let mut rng = PixelRng::new(2, 0, 0);
    let mut first = Stats::default();
    let mut second = Stats::default();
    for _ in 0..200_000 {
        let d = sample_cosine_hemisphere(rng.next_f32(), rng.next_f32());
        assert!((d.length() - 1.0).abs() < 1e-5 && d.z >= 0.0);
        let pdf = cosine_hemisphere_pdf(d.z);
        if pdf > 0.0 {
            first.push(f64::from(d.z / pdf));
            second.push(f64::from(d.z * d.z / pdf));
        }
    }
    first.assert_near(PI, 0.0, 1e-5, "integral of cos");
    second.assert_near(2.0 * PI / 3.0, 4.0, 0.0, "integral of cos^2");
}

#[test]
fn cone_sampling_is_uniform_inside_the_cone() {
    let mut rng = PixelRng::new(3, 0, 0);
    // A 10 degree half-angle and the sun's 6.8e-5 sr (0.266 degree half-angle).
    for cone in [
        UniformCone::from_half_angle(10_f32.to_radians()).unwrap(),
        UniformCone::from_solid_angle(6.8e-5).unwrap(),
    ] {
        let cos_max = f64::from(cone.cos_half_angle());
        let half_angle = cos_max.acos();
        assert!((f64::from(cone.pdf()) * f64::from(cone.solid_angle()) - 1.0).abs() < 1e-6);
        // Uniform in solid angle: 1 - cos(theta) is uniform on [0, 1 - cos a], so its mean is half
        // of that and the fraction of samples in the inner half of the solid angle is 1/2.
        let mut one_minus_cos = Stats::default();
        let mut inner = Stats::default();
        for _ in 0..100_000 {
            let d = cone.sample(rng.next_f32(), rng.next_f32());
            assert!((d.length() - 1.0).abs() < 1e-5);
            let theta = f64::from(d.x).hypot(f64::from(d.y)).atan2(f64::from(d.z));
            assert!(
                theta <= half_angle * (1.0 + 1e-3),
                "theta {theta} > {half_angle}"
            );
            let omc = 2.0 * (theta / 2.0).sin().powi(2);
            one_minus_cos.push(omc / (1.0 - cos_max));
            inner.push(f64::from(u8::from(omc < 0.5 * (1.0 - cos_max))));
        }
        one_minus_cos.assert_near(0.5, 4.0, 0.0, "1 - cos(theta) in the cone");
        inner.assert_near(0.5, 4.0, 0.0, "inner half of the cone");
    }
}

#[test]
fn power_heuristic_values() {
    assert_eq!(power_heuristic(1.0, 1.0), 0.5);
    assert!((power_heuristic(2.0, 1.0) - 0.8).abs() < 1e-7);
    assert!((power_heuristic(1.0, 2.0) - 0.2).abs() < 1e-7);
    assert_eq!(power_heuristic(0.0, 3.0), 0.0);
    assert_eq!(power_heuristic(3.0, 0.0), 1.0);
    assert_eq!(power_heuristic(f32::INFINITY, 5.0), 1.0);
    assert_eq!(power_heuristic(1e30, 1e30), 0.5);
    assert_eq!(power_heuristic(f32::NAN, 1.0), 0.0);
}

// ---------------------------------------------------------------------------------------------
// Environment light.

/// A W x H map of pseudo-random radiance with about a quarter of the texels black and one bright
/// texel (a sun) at `(5, 3)`.
fn random_map(width: usize, height: usize) -> Image<Rgb> {
    let mut rng = PixelRng::new(11, 0, 0);
    let mut data: Vec<Rgb> = (0..width * height)
        .map(|_| {
            if rng.next_f32() < 0.25 {
                Rgb::ZERO
            } else {
                Rgb::new(rng.next_f32(), rng.next_f32(), rng.next_f32() * 0.1)
            }
        })
        .collect();
    data[3 * width + 5] = Rgb::new(400.0, 380.0, 300.0);
    Image::from_vec(width, height, data).expect("width x height texels")
}

fn rotation() -> Mat3 {
    Mat3::from_rotation_y(0.7) * Mat3::from_rotation_x(-0.4) * Mat3::from_rotation_z(0.2)
}

#[test]
fn constant_environment_irradiance_is_pi_l() {
    let l = Rgb::new(0.5, 1.0, 2.0);
    let scale = 1.5;
    let env = EnvironmentLight::new(Image::filled(64, 32, l), rotation(), scale).unwrap();
    let mut rng = PixelRng::new(4, 0, 0);
    for normal in [Vec3::Y, Vec3::new(0.3, -0.5, 0.8).normalize()] {
        let mut estimate = [Stats::default(), Stats::default(), Stats::default()];
        for _ in 0..200_000 {
            let s = env.sample(rng.next_f32(), rng.next_f32());
            let w = f64::from(normal.dot(s.direction).max(0.0) / s.pdf_sr);
            for (c, stats) in estimate.iter_mut().enumerate() {
                stats.push(f64::from(s.radiance[c]) * w);
            }
        }
        for (c, stats) in estimate.iter().enumerate() {
            stats.assert_near(
                PI * f64::from(l[c] * scale),
                4.0,
                0.0,
                "irradiance of a constant map",
            );
        }
    }
}

#[test]
fn environment_pdf_integrates_to_one_over_the_sphere() {
    // Stratified quadrature: one jittered point per cell of a grid uniform in solid angle
    // (z = cos(theta) about world +Y, phi), far finer than the texels, each cell 4 pi / (NZ NPHI)
    // sr. Only cells straddling a texel edge contribute error, and jitter makes it unbiased
    // (measured |error| <= 3.5e-4); tolerance 1e-3.
    const NZ: usize = 1024;
    const NPHI: usize = 2048;
    let mut rng = PixelRng::new(13, 0, 0);
    for (map, rotation) in [
        (random_map(32, 16), rotation()),
        (random_map(64, 32), Mat3::IDENTITY),
        (Image::filled(8, 4, Rgb::ZERO), Mat3::IDENTITY),
    ] {
        let env = EnvironmentLight::new(map, rotation, 1.0).unwrap();
        let cell = 4.0 * PI / (NZ * NPHI) as f64;
        // The sphere's density, each half's (module notes of `environment`) and two normal
        // bins' (`normal_bins`; a black map has none: the sphere stands in).
        let regions = [
            SampleRegion::Sphere,
            SampleRegion::Upper,
            SampleRegion::Lower,
            env.region_for(Vec3::new(0.3, 0.9, -0.2).normalize()),
            env.region_for(Vec3::new(-0.8, -0.1, 0.6).normalize()),
        ];
        let mut totals = [0.0_f64; 5];
        for iz in 0..NZ {
            let mut rows = [0.0_f64; 5];
            for ip in 0..NPHI {
                let z = 1.0 - 2.0 * (iz as f64 + f64::from(rng.next_f32())) / NZ as f64;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * PI * (ip as f64 + f64::from(rng.next_f32())) / NPHI as f64;
                let d = Vec3::new((r * phi.cos()) as f32, z as f32, (r * phi.sin()) as f32);
                for (row, region) in rows.iter_mut().zip(regions) {
                    *row += f64::from(env.radiance_and_pdf_in(region, d).1);
                }
            }
            for (total, row) in totals.iter_mut().zip(rows) {
                *total += row * cell;
            }
        }
        for (total, region) in totals.iter().zip(regions) {
            assert!(
                (total - 1.0).abs() < 1e-3,
                "integral of the {region:?} pdf {total}"
            );
        }
    }
}

#[test]
fn environment_samples_agree_with_pdf_and_radiance() {
    let env = EnvironmentLight::new(random_map(64, 32), rotation(), 2.0).unwrap();
    let mut rng = PixelRng::new(5, 0, 0);
    for _ in 0..100_000 {
        let s = env.sample(rng.next_f32(), rng.next_f32());
        assert!((s.direction.length() - 1.0).abs() < 1e-5);
        assert!(s.pdf_sr > 0.0);
        let pdf = env.pdf(s.direction);
        assert!(
            (pdf - s.pdf_sr).abs() <= 1e-6 * s.pdf_sr,
            "pdf {pdf} vs sampled {}",
            s.pdf_sr
        );
        assert_eq!(env.radiance(s.direction), s.radiance);
        assert!(s.radiance.max_channel() > 0.0, "a black texel was sampled");
    }
}

/// A sample's radiance and density are what `radiance_and_pdf_in` reads back for its direction
/// (density within 1e-6 relative: the same tables, f32 directions).
fn assert_reads_back(env: &EnvironmentLight, region: SampleRegion, s: &EnvSample) {
    let (radiance, pdf) = env.radiance_and_pdf_in(region, s.direction);
    assert_eq!(radiance, s.radiance);
    assert!(
        (pdf - s.pdf_sr).abs() <= 1e-6 * s.pdf_sr,
        "{region:?}: pdf {pdf} vs sampled {}",
        s.pdf_sr
    );
}

#[test]
fn half_sphere_regions_sample_their_half_with_their_density() {
    // A floor (+Y) and a ceiling (-Y) under a probe turned about its up axis, on an even and an
    // odd height: the odd one's middle row straddles the horizon and belongs to both halves, so
    // its samples may lie up to that row's height (pi / 31 rad) past the horizon.
    let yaw = Mat3::from_rotation_y(0.7);
    for height in [32, 31] {
        let env = EnvironmentLight::new(random_map(64, height), yaw, 2.0).unwrap();
        let past_horizon = if height % 2 == 1 {
            (PI / height as f64).sin() as f32
        } else {
            1e-6
        };
        for (normal, region) in [
            (Vec3::Y, SampleRegion::Upper),
            (Vec3::NEG_Y, SampleRegion::Lower),
        ] {
            assert_eq!(env.region_for(normal), region);
            let mut rng = PixelRng::new(15, 0, 0);
            for _ in 0..100_000 {
                let s = env.sample_in(region, rng.next_f32(), rng.next_f32());
                assert!(
                    s.direction.dot(normal) > -past_horizon,
                    "{region:?}: {} outside the half",
                    s.direction
                );
                assert!(s.pdf_sr > 0.0);
                assert_reads_back(&env, region, &s);
                // The half holds at most the whole map's weight: its density is at least the
                // sphere's.
                assert!(s.pdf_sr >= env.pdf(s.direction) * (1.0 - 1e-6));
            }
            // The other pole lies outside the half: density 0 there.
            assert_eq!(env.radiance_and_pdf_in(region, -normal).1, 0.0);
        }
    }
}

#[test]
fn normal_bins_sample_with_their_density_wherever_their_normals_receive_light() {
    // Every direction a surface with normal `n` can receive light from (`n . w > 0`, the texel
    // not black) has a positive density in `n`'s bin (the cosine bound of `normal_bins`), and a
    // sample's density is the one `radiance_and_pdf_in` reads back. Random normals, not aligned
    // with the probe, on a turned probe; an odd height and width.
    let env = EnvironmentLight::new(random_map(45, 23), rotation(), 2.0).unwrap();
    let mut rng = PixelRng::new(17, 0, 0);
    let unit = |rng: &mut PixelRng| loop {
        let v = Vec3::new(
            2.0 * rng.next_f32() - 1.0,
            2.0 * rng.next_f32() - 1.0,
            2.0 * rng.next_f32() - 1.0,
        );
        if (0.01..1.0).contains(&v.length_squared()) {
            return v.normalize();
        }
    };
    let mut above = 0usize;
    for _ in 0..500 {
        let normal = unit(&mut rng);
        let region = env.region_for(normal);
        assert!(matches!(region, SampleRegion::Facing(_)), "{normal}");
        for _ in 0..200 {
            let w = unit(&mut rng);
            if normal.dot(w) > 1e-4 && env.radiance(w).max_channel() > 0.0 {
                above += 1;
                assert!(env.radiance_and_pdf_in(region, w).1 > 0.0, "{normal} {w}");
            }
            let s = env.sample_in(region, rng.next_f32(), rng.next_f32());
            assert!(s.pdf_sr > 0.0 && s.radiance.max_channel() > 0.0);
            assert!((s.direction.length() - 1.0).abs() < 1e-5);
            assert_reads_back(&env, region, &s);
        }
    }
    assert!(above > 30_000, "{above}");
}

#[test]
fn only_a_surface_facing_the_probes_poles_exactly_samples_a_half() {
    let env = EnvironmentLight::new(random_map(64, 32), Mat3::from_rotation_y(2.0), 1.0).unwrap();
    assert_eq!(env.region_for(Vec3::Y), SampleRegion::Upper);
    assert_eq!(
        env.region_for(Vec3::new(0.0, 3.0, 0.0)),
        SampleRegion::Upper
    );
    assert_eq!(env.region_for(Vec3::NEG_Y), SampleRegion::Lower);
    // A tilted surface, or a tilted probe: its normal's bin; no normal: the sphere.
    let tilted = Vec3::new(1e-3, 1.0, 0.0).normalize();
    assert!(matches!(env.region_for(tilted), SampleRegion::Facing(_)));
    assert!(matches!(env.region_for(Vec3::X), SampleRegion::Facing(_)));
    assert_eq!(env.region_for(Vec3::ZERO), SampleRegion::Sphere);
    assert_eq!(env.region_for(Vec3::splat(f32::NAN)), SampleRegion::Sphere);
    let tilted_probe = EnvironmentLight::new(random_map(64, 32), rotation(), 1.0).unwrap();
    assert!(matches!(
        tilted_probe.region_for(Vec3::Y),
        SampleRegion::Facing(_)
    ));
    // A black map is sampled uniformly over the sphere in every region.
    let black =
        EnvironmentLight::new(Image::filled(16, 8, Rgb::ZERO), Mat3::IDENTITY, 1.0).unwrap();
    assert_eq!(black.region_for(Vec3::Y), SampleRegion::Sphere);
    let s = black.sample_in(SampleRegion::Upper, 0.3, 0.7);
    assert_eq!(
        black
            .radiance_and_pdf_in(SampleRegion::Upper, s.direction)
            .1,
        s.pdf_sr
    );
}

#[test]
fn one_bright_texel_receives_every_sample() {
    let (width, height) = (64, 32);
    let (bi, bj) = (40, 9);
    let mut map = Image::filled(width, height, Rgb::ZERO);
    *map.get_mut(bi, bj) = Rgb::new(10.0, 20.0, 30.0);
    let env = EnvironmentLight::new(map, Mat3::IDENTITY, 1.0).unwrap();
    let latlong = LatLong::new(width, height);
    let d_omega = latlong.row_solid_angle(bj);
    // The texel's own bounds from CONVENTIONS section 2, in f64.
    let (theta0, theta1) = (
        PI * bj as f64 / height as f64,
        PI * (bj + 1) as f64 / height as f64,
    );
    let (phi0, phi1) = (
        2.0 * PI * (bi as f64 / width as f64 - 0.5),
        2.0 * PI * ((bi + 1) as f64 / width as f64 - 0.5),
    );
    let slack = 1e-5;
    let mut rng = PixelRng::new(6, 0, 0);
    for _ in 0..50_000 {
        let s = env.sample(rng.next_f32(), rng.next_f32());
        let d = s.direction.as_dvec3();
        let theta = d.y.clamp(-1.0, 1.0).acos();
        let phi = d.x.atan2(-d.z);
        assert!(
            theta > theta0 - slack && theta < theta1 + slack,
            "theta {theta}"
        );
        assert!(phi > phi0 - slack && phi < phi1 + slack, "phi {phi}");
        assert_eq!(s.radiance, Rgb::new(10.0, 20.0, 30.0));
        assert!((f64::from(s.pdf_sr) * d_omega - 1.0).abs() < 1e-5);
    }
    // Power: L dOmega of the one texel.
    let power = env.total_power().to_array();
    assert!((power[1] - 20.0 * d_omega).abs() < 1e-9);
}

#[test]
fn rotation_moves_the_bright_texel() {
    // Bright texel straight ahead in the probe (-Z). Yaw +90 degrees (right-hand rule about +Y)
    // takes -Z to -X (CONVENTIONS section 1).
    let (width, height) = (64, 32);
    let mut map = Image::filled(width, height, Rgb::ZERO);
    *map.get_mut(width / 2, height / 2) = Rgb::ONE;
    let world_from_probe = Mat3::from_rotation_y(std::f32::consts::FRAC_PI_2);
    let env = EnvironmentLight::new(map, world_from_probe, 1.0).unwrap();
    let centre = LatLong::new(width, height).pixel_dir(width / 2, height / 2);
    assert_eq!(env.radiance(world_from_probe * centre), Rgb::ONE);
    assert_eq!(env.radiance(centre), Rgb::ZERO);
    let mut rng = PixelRng::new(7, 0, 0);
    let mut mean = Vec3::ZERO;
    for _ in 0..10_000 {
        let s = env.sample(rng.next_f32(), rng.next_f32());
        // The texel spans pi / 32 = 0.098 rad in both angles from its corner at -X: every sample
        // is within its diagonal, 0.139 rad, of -X.
        assert!(
            s.direction.dot(Vec3::NEG_X) > 0.14_f32.cos(),
            "{}",
            s.direction
        );
        mean += s.direction;
    }
    assert!((mean.normalize() - world_from_probe * centre).length() < 1e-2);
}

#[test]
fn black_environment_falls_back_to_uniform_sphere() {
    let env = EnvironmentLight::new(Image::filled(16, 8, Rgb::ONE), Mat3::IDENTITY, 0.0).unwrap();
    let mut rng = PixelRng::new(8, 0, 0);
    let mut y = Stats::default();
    for _ in 0..50_000 {
        let s = env.sample(rng.next_f32(), rng.next_f32());
        assert_eq!(s.radiance, Rgb::ZERO);
        assert!((f64::from(s.pdf_sr) - 0.25 / PI).abs() < 1e-7);
        assert_eq!(env.pdf(s.direction), s.pdf_sr);
        y.push(f64::from(s.direction.y));
    }
    // Uniform sphere: y uniform on [-1, 1], mean 0.
    y.assert_near(0.0, 4.0, 0.0, "mean height of uniform sphere samples");
}

// ---------------------------------------------------------------------------------------------
// BSDFs.

fn glossy(exponent: f32) -> Material {
    Material::Glossy {
        albedo: Rgb::splat(0.5),
        specular: Rgb::splat(0.5),
        exponent,
    }
}

/// White furnace estimate of the directional albedo `integral f cos dwi` for `wo`: the mean of
/// the sample weights (a missing sample counts 0), and the fraction of missing samples.
fn furnace(bsdf: &Bsdf, wo: Vec3, seed: u64) -> (Stats, Stats) {
    let mut rng = PixelRng::new(seed, 0, 0);
    let mut albedo = Stats::default();
    let mut missing = Stats::default();
    for _ in 0..200_000 {
        let u = [rng.next_f32(), rng.next_f32(), rng.next_f32()];
        match bsdf.sample(wo, u) {
            Some(s) => {
                albedo.push(f64::from(s.weight.g));
                missing.push(0.0);
            }
            None => {
                albedo.push(0.0);
                missing.push(1.0);
            }
        }
    }
    (albedo, missing)
}

fn test_normals() -> Vec<Vec3> {
    let mut rng = PixelRng::new(9, 0, 0);
    let mut normals = vec![Vec3::Y, Vec3::Z, Vec3::NEG_Z];
    normals.extend((0..3).map(|_| uniform_dir(&mut rng)));
    normals
}

/// A unit direction at angle `tilt` (radians) from `n`.
fn tilted(n: Vec3, tilt: f32) -> Vec3 {
    let basis = OrthonormalBasis::from_normal(n);
    basis.to_world(Vec3::new(tilt.sin(), 0.0, tilt.cos()))
}

#[test]
fn white_furnace_at_normal_incidence_is_one() {
    // Reflectance 1 in total: the mean weight at wo = n is 1 (3 sigma, plus 1e-5 for rounding).
    let materials = [
        Material::Diffuse { albedo: Rgb::ONE },
        Material::Mirror {
            reflectance: Rgb::ONE,
        },
        glossy(1.0),
        glossy(10.0),
        glossy(100.0),
    ];
    for (k, n) in test_normals().into_iter().enumerate() {
        for (m, material) in materials.iter().enumerate() {
            let bsdf = Bsdf::new(material, n, n);
            let (albedo, _) = furnace(&bsdf, n, (k * 10 + m) as u64);
            albedo.assert_near(1.0, 3.0, 1e-5, &format!("{material:?} at {n}"));
        }
    }
}

#[test]
fn white_furnace_never_exceeds_one() {
    // Away from normal incidence the Phong lobe loses what it would send below the horizon, and
    // the diffuse part stays 1/2: the albedo lies in [1/2, 1] (3 sigma). Diffuse stays exactly 1.
    for (k, n) in test_normals().into_iter().enumerate() {
        for tilt_deg in [20.0_f32, 45.0, 70.0, 85.0] {
            let wo = tilted(n, tilt_deg.to_radians());
            for exponent in [1.0, 10.0, 100.0] {
                let bsdf = Bsdf::new(&glossy(exponent), n, n);
                let (albedo, _) = furnace(&bsdf, wo, k as u64);
                let (mean, se) = (albedo.mean(), albedo.std_error());
                assert!(
                    mean <= 1.0 + 3.0 * se && mean >= 0.5 - 3.0 * se,
                    "e {exponent} tilt {tilt_deg}: albedo {mean} +- {se}"
                );
            }
            let diffuse = Bsdf::new(&Material::Diffuse { albedo: Rgb::ONE }, n, n);
            furnace(&diffuse, wo, 1)
                .0
                .assert_near(1.0, 0.0, 1e-4, "diffuse tilted");
        }
    }
}

#[test]
fn sample_weight_is_eval_cos_over_pdf() {
    let mut rng = PixelRng::new(10, 0, 0);
    let materials = [
        Material::Diffuse {
            albedo: Rgb::new(0.8, 0.5, 0.2),
        },
        Material::Glossy {
            albedo: Rgb::new(0.3, 0.2, 0.1),
            specular: Rgb::new(0.2, 0.4, 0.6),
            exponent: 30.0,
        },
        glossy(1.0),
    ];
    for n in test_normals() {
        for material in &materials {
            let bsdf = Bsdf::new(material, n, n);
            for _ in 0..20_000 {
                let wo = tilted(n, rng.next_f32() * 1.5);
                let u = [rng.next_f32(), rng.next_f32(), rng.next_f32()];
                let Some(s) = bsdf.sample(wo, u) else {
                    continue;
                };
                assert!(!s.is_delta && s.pdf_sr > 0.0);
                assert!((s.wi.length() - 1.0).abs() < 1e-5 && s.wi.dot(n) > 0.0);
                let pdf = bsdf.pdf(wo, s.wi);
                assert!(
                    (pdf - s.pdf_sr).abs() <= 1e-5 * pdf,
                    "pdf {pdf} vs {}",
                    s.pdf_sr
                );
                let expected = bsdf.eval(wo, s.wi) * (s.wi.dot(n) / pdf);
                for c in 0..3 {
                    assert!(
                        (expected[c] - s.weight[c]).abs() <= 1e-4 * expected[c] + 1e-6,
                        "{material:?}: weight {:?} vs f cos / pdf {expected:?}",
                        s.weight
                    );
                }
            }
        }
    }
}

/// `integral pdf(wo, wi) dwi` over the hemisphere about `n` by the midpoint rule on a grid
/// uniform in solid angle (`z = cos(theta)`, `phi`).
fn integrate_pdf(bsdf: &Bsdf, wo: Vec3, n: Vec3) -> f64 {
    const NZ: usize = 1000;
    const NPHI: usize = 1000;
    let basis = OrthonormalBasis::from_normal(n);
    let cell = 2.0 * PI / (NZ * NPHI) as f64;
    let mut total = 0.0;
    for iz in 0..NZ {
        let z = (iz as f64 + 0.5) / NZ as f64;
        let r = (1.0 - z * z).sqrt();
        let mut row = 0.0;
        for ip in 0..NPHI {
            let phi = 2.0 * PI * (ip as f64 + 0.5) / NPHI as f64;
            let local = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
            row += f64::from(bsdf.pdf(wo, basis.to_world(local)));
        }
        total += row * cell;
    }
    total
}

#[test]
fn pdf_integrates_to_the_mass_sampled_above_the_surface() {
    // Diffuse and glossy at normal incidence: 1 (midpoint rule on 1000 x 1000 cells, worst
    // measured 2e-4 at e = 100; tolerance 1e-3). Tilted glossy: 1 minus the Phong mass below the
    // horizon, which equals the fraction of samples `sample` rejects (z-test, 4 sigma + 1e-3).
    let n = Vec3::new(0.2, 0.9, -0.3).normalize();
    let diffuse = Bsdf::new(&Material::Diffuse { albedo: Rgb::ONE }, n, n);
    assert!((integrate_pdf(&diffuse, tilted(n, 0.7), n) - 1.0).abs() < 1e-3);
    for exponent in [1.0, 10.0, 100.0] {
        let bsdf = Bsdf::new(&glossy(exponent), n, n);
        let at_normal = integrate_pdf(&bsdf, n, n);
        assert!((at_normal - 1.0).abs() < 1e-3, "e {exponent}: {at_normal}");
        for tilt_deg in [45.0_f32, 80.0] {
            let wo = tilted(n, tilt_deg.to_radians());
            let integral = integrate_pdf(&bsdf, wo, n);
            let (_, missing) = furnace(&bsdf, wo, 12);
            assert!(integral <= 1.0 + 1e-3);
            missing.assert_near(
                1.0 - integral,
                4.0,
                1e-3,
                &format!("e {exponent} tilt {tilt_deg}: rejected fraction"),
            );
        }
    }
}

//! The prefiltered maps against closed forms and an independent implementation:
//!
//! - a constant environment prefilters to itself at every roughness, for cube and lat-long;
//! - roughness 0 is the input;
//! - the GGX-prefiltered radiance matches a brute-force convolution written independently here
//!   from the Khronos glTF-IBL-Sampler's definition (`filterColor`: the `D (n.l)`-weighted mean
//!   with `n = v`), summed over every texel of a lat-long probe with its exact solid angle;
//! - the filter keeps the map's power;
//! - no seams: across every cube edge neighbouring texels differ as little as neighbours within a
//!   face;
//! - the results do not depend on the thread count.
//!
//! Measured figures are printed (`cargo test -p ibl-mapping --test prefilter -- --nocapture`).

#![allow(clippy::unwrap_used)] // tests may panic

use std::f64::consts::PI;

use ibl_core::glam::{DVec3, Mat3};
use ibl_core::{Image, LatLong, Rgb, SyntheticSky};
use ibl_mapping::ggx::ggx_d;
use ibl_mapping::{
    CubeLayout, DfgLayout, DfgOptions, EngineTarget, Mapping, PrefilterOptions, SpecularOptions,
    join_cube_faces, power, prefilter, resample,
};

fn specular(face_size: usize, target: EngineTarget, latlong: Option<usize>) -> PrefilterOptions {
    PrefilterOptions {
        specular: Some(SpecularOptions {
            face_size,
            target,
            samples: 128,
            latlong_width: latlong,
        }),
        ..Default::default()
    }
}

fn strip(faces: &[Image<Rgb>; 6]) -> Image<Rgb> {
    join_cube_faces(faces, CubeLayout::HorizontalStrip).unwrap()
}

#[test]
fn a_constant_environment_prefilters_to_itself_at_every_roughness() {
    let l = Rgb::new(0.5, 2.0, 7.0);
    let probe = Image::filled(64, 32, l);
    for target in EngineTarget::ALL {
        let out = prefilter(
            &probe,
            Mapping::LatLong,
            &specular(32, target, Some(64)),
            &|_, _| {},
        )
        .unwrap();
        let chain = out.specular.unwrap();
        assert_eq!(chain.cube.len(), target.level_count(32));
        for (m, faces) in chain.cube.iter().enumerate() {
            for face in faces {
                for p in face.pixels() {
                    for c in 0..3 {
                        // f32 sums of 128 equal terms, normalised: measured under 1e-6 relative.
                        assert!(
                            (p[c] / l[c] - 1.0).abs() < 1e-5,
                            "{target:?} level {m}: {p:?}"
                        );
                    }
                }
            }
        }
        for (m, img) in chain.latlong.iter().enumerate() {
            assert_eq!(img.width(), (64 >> m).max(2));
            for p in img.pixels() {
                assert!(
                    (p.g / l.g - 1.0).abs() < 1e-5,
                    "{target:?} lat-long level {m}: {p:?}"
                );
            }
        }
    }
}

#[test]
fn roughness_zero_is_the_input() {
    let sky = SyntheticSky::default().render(128, 64);
    let cube = resample(
        &sky,
        Mapping::LatLong,
        Mapping::Cube(CubeLayout::HorizontalCross),
        128,
        96,
        Mat3::IDENTITY,
        &|_, _| {},
    )
    .unwrap();
    let out = prefilter(
        &cube,
        Mapping::Cube(CubeLayout::HorizontalCross),
        &specular(32, EngineTarget::Khronos, None),
        &|_, _| {},
    )
    .unwrap();
    let chain = out.specular.unwrap();
    assert_eq!(chain.roughness[0], 0.0);
    let faces = ibl_mapping::split_cube_faces(&cube, CubeLayout::HorizontalCross).unwrap();
    assert_eq!(
        chain.cube[0], faces,
        "level 0 must be the input cube bit for bit"
    );
    // A lat-long chain of the input's width starts with the input itself.
    let out = prefilter(
        &sky,
        Mapping::LatLong,
        &specular(32, EngineTarget::Khronos, Some(128)),
        &|_, _| {},
    )
    .unwrap();
    assert_eq!(out.specular.unwrap().latlong[0], sky);
}

/// `LD(n) = sum_p L_p D(h_p) (n.l_p)+ dOmega_p / sum_p D(h_p) (n.l_p)+ dOmega_p` over every
/// texel of a lat-long probe (`h = normalize(n + l)`), the glTF-IBL-Sampler's `filterColor`
/// written as a sum instead of a Monte Carlo estimate.
fn brute_force(probe: &Image<Rgb>, n: DVec3, roughness: f64) -> [f64; 3] {
    let ll = LatLong::new(probe.width(), probe.height());
    let alpha = roughness * roughness;
    let (mut sum, mut weight) = ([0.0f64; 3], 0.0f64);
    for j in 0..probe.height() {
        let omega = ll.row_solid_angle(j);
        for i in 0..probe.width() {
            let l = ll.pixel_dir64(i, j);
            let n_l = n.dot(l);
            if n_l <= 0.0 {
                continue;
            }
            let h = (n + l).normalize();
            let w = ggx_d(n.dot(h), alpha) * n_l * omega;
            let p = probe.get(i, j);
            for c in 0..3 {
                sum[c] += f64::from(p[c]) * w;
            }
            weight += w;
        }
    }
    sum.map(|s| s / weight)
}

#[test]
fn ggx_prefiltering_matches_a_brute_force_convolution() {
    // A smooth sky without the sun (a 2-degree sun would need a finer probe for the brute
    // force at low roughness) and the full synthetic sky at high roughness.
    let sky = SyntheticSky {
        sun_radiance: 0.0,
        ..Default::default()
    }
    .render(256, 128);
    let with_sun = SyntheticSky::default().render(512, 256);
    let normals = ibl_core::fibonacci_normals(40);
    // (probe, roughness, samples, max relative luminance difference): about twice what was
    // measured (printed below). With the sun at moderate roughness the importance samples alias
    // on it (measured 6.7 % max, 1.0 % mean at 512 samples; 3.9 % max at 4096); from
    // about 0.6 up the exact sum over a pyramid level takes over (0.39 % max).
    for (probe, roughness, samples, tolerance) in [
        (&sky, 0.35, 512, 0.006),
        (&sky, 0.7, 512, 0.006),
        (&with_sun, 0.8, 512, 0.008),
        (&with_sun, 0.4, 512, 0.10),
    ] {
        let out = prefilter(
            probe,
            Mapping::LatLong,
            &PrefilterOptions {
                specular: Some(SpecularOptions {
                    face_size: 64,
                    target: EngineTarget::Khronos,
                    samples: 512,
                    latlong_width: None,
                }),
                ..Default::default()
            },
            &|_, _| {},
        )
        .unwrap();
        // The level whose roughness is nearest, re-filtered exactly at `roughness` through the
        // public per-texel path.
        let source = ibl_mapping::SpecularSource::new(&out.specular.unwrap().cube[0]).unwrap();
        let texel = 4.0 * PI / (6.0 * 64.0 * 64.0); // output texels of the 64-pixel faces
        let table = ibl_mapping::specular::GgxFilter::new(&source, roughness, samples, texel);
        let (mut worst, mut mean) = (0.0f64, 0.0f64);
        for n in &normals {
            let ours = table.prefilter(&source, n.as_vec3());
            let truth = brute_force(probe, *n, roughness);
            let lum = |v: [f64; 3]| 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
            let rel = (lum([ours.x.into(), ours.y.into(), ours.z.into()]) - lum(truth)).abs()
                / lum(truth);
            worst = worst.max(rel);
            mean += rel / normals.len() as f64;
        }
        println!(
            "r = {roughness}, {samples} samples: luminance difference to the brute force mean {:.3} %, max {:.3} %",
            100.0 * mean,
            100.0 * worst
        );
        assert!(worst < tolerance, "r = {roughness}: max {worst}");
    }
}

#[test]
fn prefiltering_keeps_the_power() {
    let sky = SyntheticSky::default().render(256, 128);
    let p0 = power(&sky, Mapping::LatLong);
    let out = prefilter(
        &sky,
        Mapping::LatLong,
        &specular(64, EngineTarget::Filament, None),
        &|_, _| {},
    )
    .unwrap();
    for (m, faces) in out.specular.unwrap().cube.iter().enumerate() {
        let p = power(&strip(faces), Mapping::Cube(CubeLayout::HorizontalStrip));
        let worst = (0..3)
            .map(|c| (p[c] / p0[c] - 1.0).abs())
            .fold(0.0, f64::max);
        println!("level {m}: power off by {:.3} %", 100.0 * worst);
        // Level 0 is the energy-conserving resampling (0.5 % bound of CONVENTIONS section 3);
        // the filter adds its Monte Carlo error: measured 0.85 % at most (level 2), bound 2 %.
        assert!(worst < 0.02, "level {m}: {p:?} vs {p0:?}");
    }
}

/// Mean absolute luminance step across cube edges and between edge texels and their inward
/// neighbours, over every edge texel of every face.
fn edge_steps(faces: &[Image<Rgb>; 6]) -> (f64, f64) {
    let s = faces[0].width();
    let img = strip(faces);
    let m = Mapping::Cube(CubeLayout::HorizontalStrip);
    let (w, h) = (img.width(), img.height());
    let lum_at = |x: f64, y: f64| f64::from(img.get(x as usize, y as usize).luminance());
    let (mut across, mut inward, mut count) = (0.0, 0.0, 0);
    for f in 0..6 {
        for k in 0..s {
            for (i, j, di, dj) in [
                (0, k, 1i64, 0i64),
                (s - 1, k, -1, 0),
                (k, 0, 0, 1),
                (k, s - 1, 0, -1),
            ] {
                let (x, y) = ((f * s + i) as f64 + 0.5, j as f64 + 0.5);
                let (xi, yi) = (x + di as f64, y + dj as f64);
                let d = m.pixel_dir(w, h, x, y).unwrap();
                let d_in = m.pixel_dir(w, h, xi, yi).unwrap();
                let (xo, yo) = m.dir_to_pixel(w, h, 2.0 * d - d_in).unwrap();
                let l = lum_at(x, y);
                across += (l - lum_at(xo.min(w as f64 - 0.5), yo.min(h as f64 - 0.5))).abs();
                inward += (l - lum_at(xi, yi)).abs();
                count += 1;
            }
        }
    }
    (across / count as f64, inward / count as f64)
}

#[test]
fn no_seams_across_cube_edges() {
    let sky = SyntheticSky::default().render(512, 256);
    let out = prefilter(
        &sky,
        Mapping::LatLong,
        &specular(64, EngineTarget::Khronos, None),
        &|_, _| {},
    )
    .unwrap();
    for (m, faces) in out.specular.unwrap().cube.iter().enumerate().skip(1) {
        let (across, inward) = edge_steps(faces);
        println!("level {m}: mean step across edges {across:.5}, within faces {inward:.5}");
        // A seam shows as steps across edges larger than steps inside the faces; measured
        // across / within ratios are 0.35 to 0.92 over the levels.
        assert!(
            across <= 1.5 * inward + 1e-6,
            "level {m}: {across} vs {inward}"
        );
    }
}

#[test]
fn the_whole_job_is_deterministic_and_complete() {
    let sky = SyntheticSky::default().render(128, 64);
    let options = PrefilterOptions {
        specular: Some(SpecularOptions {
            face_size: 16,
            target: EngineTarget::Unity,
            samples: 64,
            latlong_width: Some(32),
        }),
        irradiance_face: Some(8),
        dfg: Some(DfgOptions {
            size: 8,
            samples: 64,
            layout: DfgLayout::ScaleBias,
        }),
    };
    let steps = std::sync::Mutex::new(Vec::new());
    let many = prefilter(&sky, Mapping::LatLong, &options, &|d, t| {
        steps.lock().unwrap().push((d, t))
    })
    .unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let one = pool.install(|| prefilter(&sky, Mapping::LatLong, &options, &|_, _| {}).unwrap());
    let chain = many.specular.as_ref().unwrap();
    assert_eq!(chain.cube, one.specular.as_ref().unwrap().cube);
    assert_eq!(chain.latlong, one.specular.as_ref().unwrap().latlong);
    assert_eq!(chain.cube.len(), 5); // 16, 8, 4, 2, 1: Unity's seven levels need a 64 face
    assert_eq!(many.irradiance, one.irradiance);
    let steps = steps.into_inner().unwrap();
    assert_eq!(steps.last(), Some(&(12, 12))); // 5 cube + 5 lat-long levels, irradiance, DFG
    // The irradiance cube holds E / pi: for the synthetic sky, compared with the exact
    // irradiance at one texel's direction.
    let irr = many.irradiance.unwrap();
    let sc = 2.0 * 3.5 / 8.0 - 1.0;
    let d = DVec3::new(sc, 1.0, sc).normalize(); // +Y face texel (3, 3)
    let e = ibl_core::irradiance_exact(&sky, &[d])[0];
    assert!((f64::from(irr[2].get(3, 3).r) - e[0] / PI).abs() < 1e-5 * e[0]);
    assert_eq!(many.dfg.unwrap().texels.len(), 64);
    // Options over the limits are refused before any work.
    let bad = PrefilterOptions {
        specular: Some(SpecularOptions {
            face_size: 48,
            target: EngineTarget::Khronos,
            samples: 64,
            latlong_width: None,
        }),
        ..Default::default()
    };
    assert!(prefilter(&sky, Mapping::LatLong, &bad, &|_, _| {}).is_err());
}

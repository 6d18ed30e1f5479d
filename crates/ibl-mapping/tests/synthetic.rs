//! Resampling and rotation on synthetic environments (no file I/O): constants stay constant,
//! smooth fields land where their directions say, rotations follow `EulerDegrees`, small suns keep
//! their power, results do not depend on the thread count, and bad input gives errors.

#![allow(clippy::unwrap_used)] // tests may panic

use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};

use ibl_core::glam::{DVec3, Mat3};
use ibl_core::{EulerDegrees, FramePreset, Image, LatLong, Rgb};
use ibl_mapping::{
    CubeLayout, Mapping, join_cube_faces, power, resample, rotate, split_cube_faces, try_power,
};

fn quiet(_: usize, _: usize) {}

/// Every mapping with a modest size.
fn targets() -> Vec<(Mapping, usize, usize)> {
    vec![
        (Mapping::LatLong, 128, 64),
        (Mapping::Angular, 96, 96),
        (Mapping::MirrorBall, 128, 128),
        (Mapping::Cube(CubeLayout::HorizontalCross), 128, 96),
        (Mapping::Cube(CubeLayout::VerticalCross), 96, 128),
        (Mapping::Cube(CubeLayout::HorizontalStrip), 192, 32),
        (Mapping::Cube(CubeLayout::VerticalStrip), 32, 192),
        (Mapping::Fisheye { fov_deg: 360.0 }, 96, 96),
        (Mapping::Fisheye { fov_deg: 180.0 }, 64, 64),
        (Mapping::Fisheye { fov_deg: 195.0 }, 64, 64),
        (Mapping::DualFisheye { fov_deg: 195.0 }, 128, 64),
        (Mapping::DualFisheye { fov_deg: 170.0 }, 128, 64),
    ]
}

/// An image of `m` whose every pixel holds `f` at its centre direction; a rim pixel whose centre
/// is just outside the disc holds `f` just inside the rim (as a camera would record), pixels
/// farther out are black.
fn render(m: Mapping, w: usize, h: usize, f: impl Fn(DVec3) -> Rgb + Sync) -> Image<Rgb> {
    Image::from_fn_par(w, h, |i, j| {
        let (x, y) = (i as f64 + 0.5, j as f64 + 0.5);
        // The centre of the disc this pixel belongs to.
        let cx = match m {
            Mapping::DualFisheye { .. } if i < w / 2 => w as f64 / 4.0,
            Mapping::DualFisheye { .. } => 0.75 * w as f64,
            _ => w as f64 / 2.0,
        };
        let cy = h as f64 / 2.0;
        [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]
            .iter()
            .find_map(|t| {
                let scale = (1.0 - t / ((x - cx).hypot(y - cy)).max(1e-9)).max(0.0);
                m.pixel_dir(w, h, cx + (x - cx) * scale, cy + (y - cy) * scale)
            })
            .map_or(Rgb::ZERO, &f)
    })
}

/// A smooth field with a different linear function per channel.
fn field(d: DVec3) -> Rgb {
    Rgb::new(
        (1.0 + 0.5 * d.x) as f32,
        (1.0 + 0.5 * d.y) as f32,
        (1.0 + 0.5 * d.z) as f32,
    )
}

/// Whether all four corners of pixel (i, j) are inside the mapping's domain.
fn interior(m: Mapping, w: usize, h: usize, i: usize, j: usize) -> bool {
    [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
        .iter()
        .all(|(dx, dy)| {
            let (x, y) = (i as f64 + dx, j as f64 + dy);
            // Step a hair inside so that the far edges of cube cells stay in their cell.
            m.pixel_dir(
                w,
                h,
                x.min(w as f64) - dx * 1e-9,
                y.min(h as f64) - dy * 1e-9,
            )
            .is_some()
        })
}

#[test]
fn constant_environment_stays_constant_in_every_mapping() {
    let c = Rgb::new(0.7, 1.3, 2.1);
    let src = Image::filled(128, 64, c);
    for (m, w, h) in targets() {
        let out = resample(&src, Mapping::LatLong, m, w, h, Mat3::IDENTITY, &quiet).unwrap();
        let omega = m.texel_solid_angles(w, h);
        for j in 0..h {
            for i in 0..w {
                let v = *out.get(i, j);
                if *omega.get(i, j) > 0.0 {
                    for k in 0..3 {
                        // A constant environment resamples to the constant: every output texel is a
                        // normalised weighted mean of equal values, exact but for f32 accumulation
                        // over up to a few hundred sub-samples (1e-5 relative); 1e-4.
                        assert!(
                            (v[k] / c[k] - 1.0).abs() < 1e-4,
                            "{} ({i}, {j}) {v:?}",
                            m.name()
                        );
                    }
                } else if m.pixel_dir(w, h, i as f64 + 0.5, j as f64 + 0.5).is_none() {
                    assert_eq!(v, Rgb::ZERO, "{} ({i}, {j}) outside the domain", m.name());
                }
            }
        }
        // And back: a constant image of any mapping that sees the whole sphere gives a constant
        // lat-long map, with a rotation too.
        let sees_all = !matches!(
            m,
            Mapping::Fisheye { fov_deg } | Mapping::DualFisheye { fov_deg } if fov_deg < 180.0
                || matches!(m, Mapping::Fisheye { fov_deg } if fov_deg < 360.0)
        );
        if sees_all {
            let r = EulerDegrees {
                yaw_deg: 31.0,
                pitch_deg: -12.0,
                roll_deg: 5.0,
            }
            .world_from_probe();
            let full = Image::filled(w, h, c);
            let ll = resample(&full, m, Mapping::LatLong, 64, 32, r, &quiet).unwrap();
            for v in ll.pixels() {
                // As above, through a rotation: normalised means of equal values, f32 accumulation
                // only.
                assert!(
                    (v.g / c.g - 1.0).abs() < 1e-4,
                    "{} -> latlong {v:?}",
                    m.name()
                );
            }
        }
    }
}

#[test]
fn fisheye_sees_only_its_field_of_view() {
    let fish = Mapping::Fisheye { fov_deg: 180.0 };
    let img = Image::filled(64, 64, Rgb::ONE);
    let ll = resample(
        &img,
        fish,
        Mapping::LatLong,
        128,
        64,
        Mat3::IDENTITY,
        &quiet,
    )
    .unwrap();
    let grid = LatLong::new(128, 64);
    for j in 0..64 {
        for i in 0..128 {
            let d = grid.pixel_dir64(i, j);
            let v = ll.get(i, j).g;
            if d.z < -0.1 {
                // Inside the fisheye's view the constant comes back as a normalised mean of equal
                // values (f32 accumulation, 1e-5); 1e-4.
                assert!((v - 1.0).abs() < 1e-4, "({i}, {j}) in view");
            } else if d.z > 0.1 {
                assert_eq!(v, 0.0, "({i}, {j}) behind the lens");
            }
        }
    }
    // Power: a hemisphere of radiance 1.
    let p = power(&ll, Mapping::LatLong);
    assert!((p[1] / (2.0 * PI) - 1.0).abs() < 5e-3, "{p:?}");
}

#[test]
fn smooth_fields_land_on_their_directions() {
    // To every mapping: each interior pixel is the footprint mean of a linear field, which is the
    // field at the pixel's centre direction to second order.
    let src = render(Mapping::LatLong, 512, 256, field);
    for (m, w, h) in targets() {
        let out = resample(&src, Mapping::LatLong, m, w, h, Mat3::IDENTITY, &quiet).unwrap();
        let mut checked = 0;
        for j in 0..h {
            for i in 0..w {
                if !interior(m, w, h, i, j) {
                    continue;
                }
                let d = m.pixel_dir(w, h, i as f64 + 0.5, j as f64 + 0.5).unwrap();
                let (got, want) = (*out.get(i, j), field(d));
                for k in 0..3 {
                    // A smooth field (values of order 1) resampled by area averaging: the texel
                    // mean differs from the centre value by the field's curvature times the texel
                    // size squared, about 1e-3 at these sizes; 0.01.
                    assert!(
                        (got[k] - want[k]).abs() < 0.01,
                        "{} ({i}, {j}) {got:?} {want:?}",
                        m.name()
                    );
                }
                checked += 1;
            }
        }
        assert!(checked > w * h / 3, "{}", m.name());
    }
    // From every mapping that sees the sphere back to lat-long.
    for (m, w, h) in targets() {
        if matches!(m, Mapping::Fisheye { fov_deg } if fov_deg < 360.0)
            || matches!(m, Mapping::DualFisheye { fov_deg } if fov_deg < 180.0)
        {
            continue;
        }
        let img = render(m, w * 2, h * 2, field);
        let ll = resample(&img, m, Mapping::LatLong, 128, 64, Mat3::IDENTITY, &quiet).unwrap();
        let grid = LatLong::new(128, 64);
        for j in 0..64 {
            for i in 0..128 {
                let (got, want) = (*ll.get(i, j), field(grid.pixel_dir64(i, j)));
                for k in 0..3 {
                    // Rim texels of the discs hold the field at their (outside) centres: looser.
                    assert!(
                        (got[k] - want[k]).abs() < 0.03,
                        "{} -> ({i}, {j}) {got:?} {want:?}",
                        m.name()
                    );
                }
            }
        }
    }
}

/// The brightest pixel's centre direction.
fn brightest(img: &Image<Rgb>, m: Mapping) -> DVec3 {
    let (w, h) = (img.width(), img.height());
    let k = (0..img.len())
        .max_by(|&a, &b| img.pixels()[a].g.total_cmp(&img.pixels()[b].g))
        .unwrap();
    m.pixel_dir(w, h, (k % w) as f64 + 0.5, (k / w) as f64 + 0.5)
        .unwrap()
}

/// A lat-long map with a sun of `radius_deg` around `dir` on a dim sky.
fn sun_env(w: usize, h: usize, dir: DVec3, radius_deg: f64, radiance: f32) -> Image<Rgb> {
    let cos_r = radius_deg.to_radians().cos();
    let dir = dir.normalize();
    render(Mapping::LatLong, w, h, move |d| {
        let sky = Rgb::new(0.2 + 0.1 * d.y as f32, 0.3, 0.4 - 0.1 * d.y as f32);
        if d.dot(dir) >= cos_r {
            sky + Rgb::splat(radiance)
        } else {
            sky
        }
    })
}

#[test]
fn yaw_90_moves_forward_to_the_left() {
    let yaw = EulerDegrees {
        yaw_deg: 90.0,
        ..Default::default()
    }
    .world_from_probe();
    let pitch = EulerDegrees {
        pitch_deg: 90.0,
        ..Default::default()
    }
    .world_from_probe();
    let src = sun_env(256, 128, DVec3::NEG_Z, 2.0, 1000.0);
    // The sun (2 degrees across) is found at the brightest texel: within one texel of its centre
    // (256 x 128: 1.4 degrees, 0.025 rad); 0.03 rad.
    assert!(brightest(&src, Mapping::LatLong).angle_between(DVec3::NEG_Z) < 0.03);
    let turned = rotate(&src, Mapping::LatLong, yaw, &quiet).unwrap();
    assert!(brightest(&turned, Mapping::LatLong).angle_between(DVec3::NEG_X) < 0.03);
    let tilted = rotate(&src, Mapping::LatLong, pitch, &quiet).unwrap();
    assert!(brightest(&tilted, Mapping::LatLong).angle_between(DVec3::Y) < 0.03);
    // The same through a cube map and while converting.
    let cube = Mapping::Cube(CubeLayout::HorizontalCross);
    let c = resample(&src, Mapping::LatLong, cube, 256, 192, yaw, &quiet).unwrap();
    // One texel of the cube's 64-texel faces is about 0.03 rad at face centre; 0.03 rad.
    assert!(brightest(&c, cube).angle_between(DVec3::NEG_X) < 0.03);
    let c2 = rotate(&c, cube, yaw, &quiet).unwrap();
    assert!(
        brightest(&c2, cube).angle_between(DVec3::Z) < 0.03,
        "two quarter turns: behind"
    );
    // A frame preset (a reflection) is accepted: `paper` maps ours to itself for images.
    let m = FramePreset::Threejs.world_from_latlong_image();
    let t = rotate(&src, Mapping::LatLong, m, &quiet).unwrap();
    assert!(brightest(&t, Mapping::LatLong).angle_between(m.as_dmat3() * DVec3::NEG_Z) < 0.03);
}

fn max_power_error(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3)
        .map(|c| (b[c] / a[c] - 1.0).abs())
        .fold(0.0, f64::max)
}

#[test]
fn rotation_round_trip_keeps_power() {
    let r = EulerDegrees {
        yaw_deg: 37.0,
        pitch_deg: 23.0,
        roll_deg: -11.0,
    }
    .world_from_probe();
    for (m, w, h) in [
        (Mapping::LatLong, 256, 128),
        (Mapping::Cube(CubeLayout::VerticalCross), 192, 256),
        (Mapping::Angular, 256, 256),
    ] {
        let ll = sun_env(512, 256, DVec3::new(0.3, 0.4, -0.8), 0.6, 20000.0);
        let src = resample(&ll, Mapping::LatLong, m, w, h, Mat3::IDENTITY, &quiet).unwrap();
        let p0 = power(&src, m);
        let there = rotate(&src, m, r, &quiet).unwrap();
        let back = rotate(&there, m, r.transpose(), &quiet).unwrap();
        let (e1, e2) = (
            max_power_error(p0, power(&there, m)),
            max_power_error(p0, power(&back, m)),
        );
        println!(
            "rotation round trip {}: {:.4} % then {:.4} %",
            m.name(),
            100.0 * e1,
            100.0 * e2
        );
        assert!(e1 < 5e-3 && e2 < 5e-3, "{}: {e1} {e2}", m.name());
    }
}

#[test]
fn small_suns_keep_their_power_through_every_mapping() {
    // 256 x 128 lat-long (0.7 degree texels), suns of 0.25 to 1 degree carrying most of the
    // power, at assorted directions (not within 10 degrees of -Z for the mirror ball: its rim is
    // that single direction, see `disc`).
    let dirs = [
        DVec3::new(0.3, 0.5, -0.8),
        DVec3::new(-0.7, 0.1, 0.2),
        DVec3::new(0.05, 0.99, 0.1),
        DVec3::new(0.6, -0.3, 0.7),
        DVec3::new(0.01, 0.02, -1.0),
    ];
    let mut worst: f64 = 0.0;
    for (k, dir) in dirs.iter().enumerate() {
        let radius = [0.25, 0.5, 1.0][k % 3];
        let src = sun_env(256, 128, *dir, radius, 50000.0);
        let p0 = power(&src, Mapping::LatLong);
        for (m, _, _) in targets() {
            if matches!(m, Mapping::Fisheye { fov_deg } if fov_deg < 360.0)
                || matches!(m, Mapping::DualFisheye { fov_deg } if fov_deg < 180.0)
                || (m == Mapping::MirrorBall && dir.normalize().z < -0.98)
            {
                continue;
            }
            let (w, h) = m.default_size_for(Mapping::LatLong, 256, 128);
            let mid = resample(&src, Mapping::LatLong, m, w, h, Mat3::IDENTITY, &quiet).unwrap();
            let back =
                resample(&mid, m, Mapping::LatLong, 256, 128, Mat3::IDENTITY, &quiet).unwrap();
            let (e1, e2) = (
                max_power_error(p0, power(&mid, m)),
                max_power_error(p0, power(&back, Mapping::LatLong)),
            );
            worst = worst.max(e1).max(e2);
            assert!(e1 < 5e-3 && e2 < 5e-3, "{} sun {k}: {e1} {e2}", m.name());
        }
    }
    println!("small suns: worst power error {:.4} %", 100.0 * worst);
}

#[test]
fn result_does_not_depend_on_the_thread_count() {
    let src = sun_env(256, 128, DVec3::new(0.2, 0.3, -0.9), 1.0, 5000.0);
    let r = EulerDegrees {
        yaw_deg: 10.0,
        pitch_deg: 5.0,
        roll_deg: 2.0,
    }
    .world_from_probe();
    let run = |threads: usize, to: Mapping, w: usize, h: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let out = resample(&src, Mapping::LatLong, to, w, h, r, &quiet).unwrap();
            (power(&out, to), out)
        })
    };
    for (m, w, h) in [
        (Mapping::Cube(CubeLayout::HorizontalCross), 128, 96),
        (Mapping::DualFisheye { fov_deg: 195.0 }, 128, 64),
        (Mapping::MirrorBall, 128, 128),
    ] {
        let (p1, a) = run(1, m, w, h);
        for threads in [2, 3] {
            let (p, b) = run(threads, m, w, h);
            assert!(a == b && p == p1, "{} with {threads} threads", m.name());
        }
    }
}

#[test]
fn dual_fisheye_seam_is_feathered() {
    // Front lens all 1, back lens all 3: the overlap blends smoothly with weights that fall to
    // 0 at each rim, 2 exactly on the z = 0 plane.
    let dual = Mapping::DualFisheye { fov_deg: 200.0 };
    let img = Image::from_fn_par(
        256,
        128,
        |i, _| if i < 128 { Rgb::ONE } else { Rgb::splat(3.0) },
    );
    let ll = resample(
        &img,
        dual,
        Mapping::LatLong,
        720,
        360,
        Mat3::IDENTITY,
        &quiet,
    )
    .unwrap();
    let row = 180; // the horizon, where the whole band is
    let grid = LatLong::new(720, 360);
    let mut last = None;
    // Along the horizon from forward (u = 0.5) to behind (u = 1): 1, rising smoothly, 3.
    for i in 360..720 {
        let d = grid.pixel_dir64(i, row);
        let v = f64::from(ll.get(i, row).g);
        let half = 100f64.to_radians();
        let c_front = -d.z;
        if c_front > -half.cos() + 1e-2 && c_front > half.cos().abs() + 1e-2 {
            // Away from the overlap only one lens contributes: the constant 1 (front) or 3 (back)
            // as a normalised mean, f32 accumulation (1e-5); 1e-3.
            assert!((v - 1.0).abs() < 1e-3, "{i}: front only");
        }
        if -c_front > half.cos().abs() + 1e-2 {
            assert!((v - 3.0).abs() < 1e-3, "{i}: back only");
        }
        if let Some(prev) = last {
            // The feathered blend is monotonic in the angle: consecutive samples may only fall by
            // f32 noise (1e-5); 1e-4.
            assert!(v >= prev - 1e-4, "monotonic at {i}");
            // The blend spreads 1 -> 3 over the overlap (about 180 columns): a step of about 0.02
            // per column, far below 0.1 (a hard seam would jump by 2).
            assert!(v - prev < 0.1, "no jump at {i}");
        }
        last = Some(v);
    }
    // Near the plane z = 0 (u = 0.75, +X) the lenses weigh about the same: the pixel holds the
    // blend at its direction, w_front = smoothstep((c + c0) / (2 c0)), c0 = -cos(100 degrees).
    let d = grid.pixel_dir64(540, row);
    let c0 = -(100f64.to_radians().cos());
    let x = ((-d.z + c0) / (2.0 * c0)).clamp(0.0, 1.0);
    let w_front = x * x * (3.0 - 2.0 * x);
    let expect = w_front + 3.0 * (1.0 - w_front);
    let v = f64::from(ll.get(540, row).g);
    // The blend weight at column 540 from the smoothstep formula: the resampled value is a
    // normalised mean of the blend over the texel (curvature error of order 1e-4); 1e-3. It is
    // about half way, 2 +- 0.05.
    assert!(
        (v - expect).abs() < 1e-3 && (v - 2.0).abs() < 0.05,
        "{v} vs {expect}"
    );
    // Power counts the overlap once: a constant 1 in both lenses has power 4 pi.
    let ones = Image::filled(256, 128, Rgb::ONE);
    assert!((power(&ones, dual)[0] / (4.0 * PI) - 1.0).abs() < 1e-9);
}

#[test]
fn cube_layouts_hold_the_same_faces() {
    let src = render(Mapping::LatLong, 256, 128, field);
    let h = Mapping::Cube(CubeLayout::HorizontalCross);
    let cross = resample(&src, Mapping::LatLong, h, 256, 192, Mat3::IDENTITY, &quiet).unwrap();
    let faces = split_cube_faces(&cross, CubeLayout::HorizontalCross).unwrap();
    for layout in CubeLayout::ALL {
        let other = join_cube_faces(&faces, layout).unwrap();
        assert_eq!(split_cube_faces(&other, layout).unwrap(), faces);
        let m = Mapping::Cube(layout);
        let a = resample(&cross, h, Mapping::LatLong, 128, 64, Mat3::IDENTITY, &quiet).unwrap();
        let b = resample(&other, m, Mapping::LatLong, 128, 64, Mat3::IDENTITY, &quiet).unwrap();
        assert_eq!(a, b, "{layout:?}");
        // The same face texels in another layout: the same power sum, in another order of f64 sums
        // (1e-15 relative of a power of order 1); 1e-12.
        assert!((power(&cross, h)[0] - power(&other, m)[0]).abs() < 1e-12);
    }
}

#[test]
fn progress_is_reported_per_row() {
    let src = Image::filled(64, 32, Rgb::ONE);
    let calls = AtomicUsize::new(0);
    let last = AtomicUsize::new(0);
    let progress = |done: usize, total: usize| {
        assert_eq!(total, 48);
        calls.fetch_add(1, Ordering::Relaxed);
        last.fetch_max(done, Ordering::Relaxed);
    };
    let cube = Mapping::Cube(CubeLayout::HorizontalCross);
    resample(
        &src,
        Mapping::LatLong,
        cube,
        64,
        48,
        Mat3::IDENTITY,
        &progress,
    )
    .unwrap();
    assert_eq!(calls.load(Ordering::Relaxed), 48);
    assert_eq!(last.load(Ordering::Relaxed), 48);
}

#[test]
fn bad_input_gives_errors_not_panics() {
    let ll = Image::filled(64, 32, Rgb::ONE);
    let id = Mat3::IDENTITY;
    let cube = Mapping::Cube(CubeLayout::HorizontalCross);
    assert!(
        resample(&ll, cube, Mapping::LatLong, 64, 32, id, &quiet).is_err(),
        "source shape"
    );
    assert!(
        resample(&ll, Mapping::LatLong, cube, 64, 47, id, &quiet).is_err(),
        "output shape"
    );
    assert!(resample(&ll, Mapping::LatLong, Mapping::Angular, 0, 0, id, &quiet).is_err());
    for fov in [0.0, -10.0, 360.5, f32::NAN, f32::INFINITY] {
        let m = Mapping::Fisheye { fov_deg: fov };
        assert!(
            resample(&ll, Mapping::LatLong, m, 32, 32, id, &quiet).is_err(),
            "fov {fov}"
        );
        assert!(m.check_shape(32, 32).is_err());
        assert!(m.pixel_dir(32, 32, 16.0, 16.0).is_none());
        let d = Mapping::DualFisheye { fov_deg: fov };
        assert!(
            resample(&ll, d, Mapping::LatLong, 64, 32, id, &quiet).is_err(),
            "dual fov {fov}"
        );
    }
    let skew = Mat3::from_cols_array(&[1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    assert!(rotate(&ll, Mapping::LatLong, skew, &quiet).is_err());
    assert!(rotate(&ll, Mapping::LatLong, Mat3::ZERO, &quiet).is_err());
    let empty = Image::filled(0, 0, Rgb::ONE);
    assert!(resample(&empty, Mapping::LatLong, Mapping::LatLong, 8, 4, id, &quiet).is_err());
    assert!(try_power(&empty, Mapping::LatLong).is_err());
    assert!(power(&ll, Mapping::Angular)[0].is_nan());
    assert!(split_cube_faces(&ll, CubeLayout::VerticalCross).is_err());
    let mut faces = split_cube_faces(
        &Image::filled(32, 24, Rgb::ONE),
        CubeLayout::HorizontalCross,
    )
    .unwrap();
    faces[3] = Image::filled(8, 7, Rgb::ONE);
    assert!(join_cube_faces(&faces, CubeLayout::HorizontalStrip).is_err());
    // Tiny images work.
    for (m, w, h) in [
        (Mapping::LatLong, 1, 1),
        (Mapping::Angular, 1, 1),
        (cube, 4, 3),
    ] {
        let out = resample(&ll, Mapping::LatLong, m, w, h, id, &quiet).unwrap();
        assert!(out.pixels().iter().all(|c| c.is_valid_radiance()));
        let back = resample(&out, m, Mapping::LatLong, 8, 4, id, &quiet).unwrap();
        // A constant through a 1 x 1 / 4 x 3 map and back: normalised means of equal values, f32
        // accumulation (1e-6); 1e-4.
        assert!(
            back.pixels().iter().all(|c| (c.g - 1.0).abs() < 1e-4),
            "{}",
            m.name()
        );
    }
}

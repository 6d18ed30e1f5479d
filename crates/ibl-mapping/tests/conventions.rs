//! Pins the mappings to docs/CONVENTIONS.md sections 1-4: the lat-long test vectors, the angular
//! map and mirror ball formulas, texel solid angles, seams and poles, cube face orientation and
//! cross layouts, fisheye orientation.

#![allow(clippy::unwrap_used)] // tests may panic

use std::f64::consts::{FRAC_1_SQRT_2, PI};

use ibl_core::glam::DVec3;
use ibl_core::{Image, Rgb};
use ibl_mapping::{CUBE_FACE_NAMES, CubeLayout, Mapping, split_cube_faces};

/// Whether `a` and `b` agree to `tol` in every component. The tolerances used: 1e-12 where a
/// formula of CONVENTIONS is evaluated in f64 through a few trigonometric functions (each exact
/// to an ulp or two of 1, 2.2e-16, so 1e-12 is a margin of a few thousand), 1e-4 for the
/// four-digit test vectors the document prints.
fn close(a: DVec3, b: DVec3, tol: f64) -> bool {
    (a - b).abs().max_element() <= tol
}

fn all_mappings() -> Vec<(Mapping, usize, usize)> {
    vec![
        (Mapping::LatLong, 512, 256),
        (Mapping::Angular, 257, 257),
        (Mapping::MirrorBall, 256, 256),
        (Mapping::Cube(CubeLayout::HorizontalCross), 256, 192),
        (Mapping::Cube(CubeLayout::VerticalCross), 192, 256),
        (Mapping::Cube(CubeLayout::HorizontalStrip), 384, 64),
        (Mapping::Cube(CubeLayout::VerticalStrip), 64, 384),
        (Mapping::Fisheye { fov_deg: 360.0 }, 200, 200),
        (Mapping::DualFisheye { fov_deg: 195.0 }, 400, 200),
    ]
}

// ---- Section 2: lat-long --------------------------------------------------------------------

#[test]
fn latlong_test_vectors() {
    let ll = Mapping::LatLong;
    // Pixel (256, 128) of 512 x 256: u = 0.500977, v = 0.501953.
    let d = ll.pixel_dir(512, 256, 256.5, 128.5).unwrap();
    assert!(close(d, DVec3::new(0.0061, -0.0061, -1.0), 1e-4), "{d}");
    assert!(d.x > 0.0 && d.y < 0.0, "right of and below forward");
    // Centre of the top row: approximately +Y.
    let d = ll.pixel_dir(512, 256, 256.5, 0.5).unwrap();
    assert!(d.y > 0.9999 && close(d, DVec3::Y, 0.01), "{d}");
    // u = 0.75, v = 0.5 (continuous): exactly +X.
    let d = ll.pixel_dir(512, 256, 384.0, 128.0).unwrap();
    assert!(close(d, DVec3::X, 1e-12), "{d}");
    // u = 0 or 1, v = 0.5: exactly +Z (behind).
    for x in [0.0, 512.0] {
        let d = ll.pixel_dir(512, 256, x, 128.0).unwrap();
        assert!(close(d, DVec3::Z, 1e-12), "{x}: {d}");
    }
    // u = 0.5 forward, u = 0.25 left.
    assert!(close(
        ll.pixel_dir(512, 256, 256.0, 128.0).unwrap(),
        DVec3::NEG_Z,
        1e-12
    ));
    assert!(close(
        ll.pixel_dir(512, 256, 128.0, 128.0).unwrap(),
        DVec3::NEG_X,
        1e-12
    ));
}

#[test]
fn latlong_inverse_matches_the_formula() {
    let ll = Mapping::LatLong;
    let (x, y) = ll.dir_to_pixel(512, 256, DVec3::X).unwrap();
    // Pixel coordinates of an exact direction: u W and v H in f64 through atan2 and acos, a few
    // ulps of 512 (1e-13); 1e-9.
    assert!((x - 384.0).abs() < 1e-9 && (y - 128.0).abs() < 1e-9);
    let (x, y) = ll
        .dir_to_pixel(512, 256, DVec3::new(0.0, 0.0, -3.0))
        .unwrap();
    // As above: f64 rounding of coordinates of order 256.
    assert!((x - 256.0).abs() < 1e-9 && (y - 128.0).abs() < 1e-9);
    assert!(ll.dir_to_pixel(512, 256, DVec3::ZERO).is_none());
    assert!(
        ll.dir_to_pixel(512, 256, DVec3::new(f64::NAN, 0.0, 1.0))
            .is_none()
    );
}

#[test]
fn latlong_seam_is_continuous() {
    let ll = Mapping::LatLong;
    // +Z sits exactly on the seam: u = 0 or 1.
    let (x, y) = ll.dir_to_pixel(512, 256, DVec3::Z).unwrap();
    assert!((x == 0.0 || x == 512.0) && (y - 128.0).abs() < 1e-9, "{x}");
    for j in [1, 60, 128, 200, 254] {
        let yc = j as f64 + 0.5;
        let first = ll.pixel_dir(512, 256, 0.5, yc).unwrap();
        let last = ll.pixel_dir(512, 256, 511.5, yc).unwrap();
        let neighbour = ll.pixel_dir(512, 256, 1.5, yc).unwrap();
        // Across the seam the step equals an ordinary one-pixel step.
        let across = first.angle_between(last);
        let along = first.angle_between(neighbour);
        assert!(
            (across - along).abs() < 1e-12 && across < 2.0 * PI / 512.0 + 1e-12,
            "row {j}"
        );
        // Both sides of the seam at exactly u = 0 and u = 1 are the same direction.
        let a = ll.pixel_dir(512, 256, 0.0, yc).unwrap();
        let b = ll.pixel_dir(512, 256, 512.0, yc).unwrap();
        assert!(close(a, b, 1e-12));
    }
}

#[test]
fn latlong_poles() {
    let ll = Mapping::LatLong;
    for x in [0.0, 0.5, 100.25, 256.0, 511.5, 512.0] {
        assert!(
            close(ll.pixel_dir(512, 256, x, 0.0).unwrap(), DVec3::Y, 1e-12),
            "top {x}"
        );
        assert!(
            close(
                ll.pixel_dir(512, 256, x, 256.0).unwrap(),
                DVec3::NEG_Y,
                1e-12
            ),
            "bottom {x}"
        );
    }
    for pole in [DVec3::Y, DVec3::NEG_Y] {
        let (x, y) = ll.dir_to_pixel(512, 256, pole).unwrap();
        assert!(x.is_finite() && (0.0..=512.0).contains(&x));
        // The poles map to the top and bottom edges exactly but for acos rounding: 1e-9 pixel.
        assert!((y - if pole.y > 0.0 { 0.0 } else { 256.0 }).abs() < 1e-9);
    }
}

// ---- Section 3: angular map and mirror ball -------------------------------------------------

/// Disc coordinates of pixel centre (i, j) in a W x H image (CONVENTIONS section 3).
fn disc_ab(i: usize, j: usize, w: usize, h: usize) -> (f64, f64) {
    (
        2.0 * (i as f64 + 0.5) / w as f64 - 1.0,
        1.0 - 2.0 * (j as f64 + 0.5) / h as f64,
    )
}

#[test]
fn angular_map_formula() {
    let m = Mapping::Angular;
    let n = 64;
    for j in 0..n {
        for i in 0..n {
            let (a, b) = disc_ab(i, j, n, n);
            let r = (a * a + b * b).sqrt();
            let got = m.pixel_dir(n, n, i as f64 + 0.5, j as f64 + 0.5);
            if r > 1.0 {
                assert!(got.is_none());
                continue;
            }
            // Written exactly as CONVENTIONS section 3 states it.
            let theta_a = b.atan2(a);
            let phi_a = PI * r;
            let expect = DVec3::new(
                phi_a.sin() * theta_a.cos(),
                phi_a.sin() * theta_a.sin(),
                -phi_a.cos(),
            );
            assert!(close(got.unwrap(), expect, 1e-12), "({i}, {j})");
        }
    }
    let at = |a: f64, b: f64| {
        m.pixel_dir(n, n, (a + 1.0) * n as f64 / 2.0, (1.0 - b) * n as f64 / 2.0)
            .unwrap()
    };
    assert!(close(at(0.0, 0.0), DVec3::NEG_Z, 1e-12), "centre = forward");
    for (a, b) in [(1.0, 0.0), (0.0, -1.0), (-FRAC_1_SQRT_2, FRAC_1_SQRT_2)] {
        assert!(close(at(a, b), DVec3::Z, 1e-12), "rim = behind");
    }
    assert!(close(at(0.5, 0.0), DVec3::X, 1e-12), "half way right = +X");
    assert!(close(at(0.0, 0.5), DVec3::Y, 1e-12), "half way up = +Y");
    assert!(close(
        at(-0.25, 0.0),
        DVec3::new(-FRAC_1_SQRT_2, 0.0, -FRAC_1_SQRT_2),
        1e-12
    ));
    // Hand-computed: pixel (2, 1) of a 4 x 4 map, a = b = 0.25.
    let d = m.pixel_dir(4, 4, 2.5, 1.5).unwrap();
    assert!(
        close(d, DVec3::new(0.633_581, 0.633_581, -0.444_016), 1e-6),
        "{d}"
    );
}

#[test]
fn mirror_ball_formula() {
    let m = Mapping::MirrorBall;
    let n = 64;
    for j in 0..n {
        for i in 0..n {
            let (a, b) = disc_ab(i, j, n, n);
            let got = m.pixel_dir(n, n, i as f64 + 0.5, j as f64 + 0.5);
            if a * a + b * b > 1.0 {
                assert!(got.is_none());
                continue;
            }
            // n = (a, b, sqrt(1 - a^2 - b^2)), i = (0, 0, -1), d = i - 2 (i.n) n.
            let normal = DVec3::new(a, b, (1.0 - a * a - b * b).sqrt());
            let view = DVec3::NEG_Z;
            let expect = view - 2.0 * view.dot(normal) * normal;
            assert!(close(got.unwrap(), expect, 1e-12), "({i}, {j})");
        }
    }
    let at = |a: f64, b: f64| {
        m.pixel_dir(n, n, (a + 1.0) * n as f64 / 2.0, (1.0 - b) * n as f64 / 2.0)
            .unwrap()
    };
    assert!(
        close(at(0.0, 0.0), DVec3::Z, 1e-12),
        "centre = towards the camera"
    );
    for (a, b) in [(1.0, 0.0), (0.0, 1.0), (-0.6, -0.8)] {
        assert!(
            close(at(a, b), DVec3::NEG_Z, 1e-12),
            "rim = hidden behind the ball"
        );
    }
    // Hand-computed: a = sqrt(1/2) reflects the view ray to +X; a = 0.5 gives (sqrt 3 / 2, 0, 1/2).
    assert!(close(at(FRAC_1_SQRT_2, 0.0), DVec3::X, 1e-12));
    assert!(close(
        at(0.5, 0.0),
        DVec3::new(0.75_f64.sqrt(), 0.0, 0.5),
        1e-12
    ));
    assert!(close(at(0.0, -FRAC_1_SQRT_2), DVec3::NEG_Y, 1e-12));
}

#[test]
fn mirror_ball_is_equal_area() {
    // dOmega = 4 da db: every pixel fully inside the disc has solid angle 16 / (W H).
    let n = 100;
    let omega = Mapping::MirrorBall.texel_solid_angles(n, n);
    let inner = *omega.get(50, 50);
    assert!((inner - 16.0 / (n * n) as f64).abs() < 1e-15);
    // Equal-area by construction: every inner texel's solid angle is the same closed form, to f64
    // rounding (1e-18 for values of 1.6e-3); 1e-15.
    assert!((*omega.get(30, 70) - inner).abs() < 1e-15);
    // Angular: dOmega = pi sin(pi r) / r da db, checked at a pixel centre by a fine midpoint sum.
    let omega = Mapping::Angular.texel_solid_angles(n, n);
    let (a, b) = disc_ab(70, 40, n, n);
    let r = (a * a + b * b).sqrt();
    let approx = PI * (PI * r).sin() / r * 4.0 / (n * n) as f64;
    // The exact texel integral against a one-point midpoint rule: they differ by the variation of
    // sin(pi r) / r across one texel (second order in the texel size 0.02 of the disc), far under
    // 1e-3.
    assert!((*omega.get(70, 40) / approx - 1.0).abs() < 1e-3);
}

// ---- Fisheye ----------------------------------------------------------------------------------

#[test]
fn fisheye_orientation() {
    let n = 64;
    let m = Mapping::Fisheye { fov_deg: 180.0 };
    let at = |a: f64, b: f64| {
        m.pixel_dir(n, n, (a + 1.0) * 32.0, (1.0 - b) * 32.0)
            .unwrap()
    };
    assert!(close(at(0.0, 0.0), DVec3::NEG_Z, 1e-12), "looks forward");
    assert!(
        close(at(1.0, 0.0), DVec3::X, 1e-12),
        "right rim = +X (90 degrees)"
    );
    assert!(close(at(0.0, 1.0), DVec3::Y, 1e-12), "top rim = +Y");
    assert!(close(
        at(0.5, 0.0),
        DVec3::new(FRAC_1_SQRT_2, 0.0, -FRAC_1_SQRT_2),
        1e-12
    ));
    assert!(
        m.dir_to_pixel(n, n, DVec3::Z).is_none(),
        "180 degrees does not see behind"
    );
    // Equidistant: r = theta / (fov / 2).
    let wide = Mapping::Fisheye { fov_deg: 200.0 };
    let d = wide.pixel_dir(n, n, 64.0, 32.0).unwrap();
    assert!((d.angle_between(DVec3::NEG_Z) - 100f64.to_radians()).abs() < 1e-12);
    // 360 degrees is the angular map.
    let full = Mapping::Fisheye { fov_deg: 360.0 };
    for (x, y) in [(10.5, 20.5), (32.0, 32.0), (50.25, 13.5)] {
        assert!(close(
            full.pixel_dir(n, n, x, y).unwrap(),
            Mapping::Angular.pixel_dir(n, n, x, y).unwrap(),
            1e-12
        ));
    }
}

#[test]
fn dual_fisheye_orientation() {
    let m = Mapping::DualFisheye { fov_deg: 180.0 };
    let (w, h) = (128, 64);
    // Left circle (x in [0, 64)): forward, right = +X. Right circle: backward, right = -X.
    let left = |a: f64, b: f64| {
        m.pixel_dir(w, h, (a + 1.0) * 32.0, (1.0 - b) * 32.0)
            .unwrap()
    };
    let right = |a: f64, b: f64| {
        m.pixel_dir(w, h, 64.0 + (a + 1.0) * 32.0, (1.0 - b) * 32.0)
            .unwrap()
    };
    assert!(close(left(0.0, 0.0), DVec3::NEG_Z, 1e-12));
    assert!(close(right(0.0, 0.0), DVec3::Z, 1e-12));
    assert!(close(left(1.0, 0.0), DVec3::X, 1e-12));
    assert!(close(right(1.0, 0.0), DVec3::NEG_X, 1e-12));
    assert!(close(left(0.0, 1.0), DVec3::Y, 1e-12));
    assert!(close(right(0.0, 1.0), DVec3::Y, 1e-12));
    // The rims meet: the right edge of the left circle and the left edge of the right one both
    // look at +X.
    assert!(close(right(-1.0, 0.0), DVec3::X, 1e-12));
    // Inverse picks the lens that faces the direction.
    let (x, _) = m.dir_to_pixel(w, h, DVec3::new(0.1, 0.2, -1.0)).unwrap();
    assert!(x < 64.0);
    let (x, _) = m.dir_to_pixel(w, h, DVec3::new(0.1, 0.2, 1.0)).unwrap();
    assert!(x >= 64.0);
}

// ---- Section 4: solid angles ------------------------------------------------------------------

#[test]
fn latlong_row_solid_angles_sum_to_4pi() {
    for (w, h) in [(512, 256), (2048, 1024), (7, 3), (1, 1)] {
        let omega = Mapping::LatLong.texel_solid_angles(w, h);
        let sum: f64 = omega.pixels().iter().sum();
        // Exact row solid angles summed over every row: 4 pi to f64 rounding (1e-13); 1e-9.
        assert!((sum - 4.0 * PI).abs() < 1e-9, "{w} x {h}: {sum}");
        // Exact row formula of CONVENTIONS section 4.
        let j = h / 3;
        let exact = (2.0 * PI / w as f64)
            * ((PI * j as f64 / h as f64).cos() - (PI * (j + 1) as f64 / h as f64).cos());
        assert!((*omega.get(0, j) - exact).abs() < 1e-15);
    }
}

/// Tolerance: every mapping's texel solid angles sum to the covered solid angle within 1e-9
/// relative (they are exact closed forms; the disc ones clip pixels to the rim exactly).
#[test]
fn texel_solid_angles_sum_to_4pi() {
    let mut cases = all_mappings();
    cases.extend([
        (Mapping::Angular, 1, 1),
        (Mapping::MirrorBall, 2, 2),
        (Mapping::MirrorBall, 1001, 1001),
        (Mapping::Cube(CubeLayout::HorizontalCross), 4, 3),
        (Mapping::DualFisheye { fov_deg: 180.0 }, 202, 101),
        (Mapping::DualFisheye { fov_deg: 360.0 }, 64, 32),
    ]);
    for (m, w, h) in cases {
        let omega = m.texel_solid_angles(w, h);
        assert_eq!((omega.width(), omega.height()), (w, h));
        let sum: f64 = omega.pixels().iter().sum();
        // Exact closed forms (rows, cube corners, disc texels clipped by Green's theorem): 4 pi to
        // f64 rounding over up to a million texels (1e-12 relative); 1e-9.
        assert!(
            (sum / (4.0 * PI) - 1.0).abs() < 1e-9,
            "{} {w} x {h}: {sum}",
            m.name()
        );
        assert!(omega.pixels().iter().all(|&o| o >= 0.0 && o.is_finite()));
    }
    // A fisheye under 360 degrees covers a cap of 2 pi (1 - cos(fov / 2)).
    for fov in [90.0_f32, 180.0, 195.0] {
        let half = f64::from(fov).to_radians() / 2.0;
        let cap = 2.0 * PI * (1.0 - half.cos());
        let single: f64 = Mapping::Fisheye { fov_deg: fov }
            .texel_solid_angles(300, 300)
            .pixels()
            .iter()
            .sum();
        // As above for a fisheye's cap.
        assert!(
            (single / cap - 1.0).abs() < 1e-9,
            "fisheye {fov}: {single} vs {cap}"
        );
    }
    // Dual fisheye under 180 degrees: two caps, the band between them unseen.
    let half = 170f64.to_radians() / 2.0;
    let dual: f64 = Mapping::DualFisheye { fov_deg: 170.0 }
        .texel_solid_angles(200, 100)
        .pixels()
        .iter()
        .sum();
    // As above for two caps.
    assert!((dual / (4.0 * PI * (1.0 - half.cos())) - 1.0).abs() < 1e-9);
    // Outside the disc and in unused cross cells: 0.
    assert_eq!(*Mapping::Angular.texel_solid_angles(64, 64).get(0, 0), 0.0);
    assert_eq!(
        *Mapping::Cube(CubeLayout::HorizontalCross)
            .texel_solid_angles(64, 48)
            .get(0, 0),
        0.0
    );
    // A shape that does not fit gives zeros, not a panic.
    let bad = Mapping::Cube(CubeLayout::HorizontalCross).texel_solid_angles(10, 10);
    assert!(bad.pixels().iter().all(|&o| o == 0.0));
}

// ---- Cube maps ----------------------------------------------------------------------------------

/// The OpenGL cube-map table: direction of face coordinates (sc, tc) in [-1, 1].
fn gl_face_dir(face: usize, sc: f64, tc: f64) -> DVec3 {
    let d = match face {
        0 => DVec3::new(1.0, -tc, -sc),
        1 => DVec3::new(-1.0, -tc, sc),
        2 => DVec3::new(sc, 1.0, tc),
        3 => DVec3::new(sc, -1.0, -tc),
        4 => DVec3::new(sc, -tc, 1.0),
        _ => DVec3::new(-sc, -tc, -1.0),
    };
    d.normalize()
}

const AXES: [DVec3; 6] = [
    DVec3::X,
    DVec3::NEG_X,
    DVec3::Y,
    DVec3::NEG_Y,
    DVec3::Z,
    DVec3::NEG_Z,
];

#[test]
fn cube_faces_follow_the_gl_table() {
    let s = 16;
    for layout in CubeLayout::ALL {
        let m = Mapping::Cube(layout);
        let (cols, rows) = layout.grid();
        let (w, h) = (cols * s, rows * s);
        // An image whose pixels hold their own directions, split into faces.
        let img = Image::from_fn_par(w, h, |i, j| {
            let d = m
                .pixel_dir(w, h, i as f64 + 0.5, j as f64 + 0.5)
                .unwrap_or(DVec3::ZERO);
            Rgb::new(d.x as f32, d.y as f32, d.z as f32)
        });
        let faces = split_cube_faces(&img, layout).unwrap();
        for (f, face) in faces.iter().enumerate() {
            for (i, j) in [(0, 0), (s - 1, 0), (3, 11), (s / 2, s / 2)] {
                let sc = 2.0 * (i as f64 + 0.5) / s as f64 - 1.0;
                let tc = 2.0 * (j as f64 + 0.5) / s as f64 - 1.0;
                let c = face.get(i, j);
                let got = DVec3::new(c.r.into(), c.g.into(), c.b.into());
                assert!(
                    close(got, gl_face_dir(f, sc, tc), 1e-6),
                    "{layout:?} {} ({i}, {j})",
                    CUBE_FACE_NAMES[f]
                );
            }
            // Face centre = its axis; top-left corner of +X is (1, 1, 1)/sqrt 3 (s = t = 0).
            let (col, row, rot) = layout.cell(f);
            let centre = m
                .pixel_dir(
                    w,
                    h,
                    (col as f64 + 0.5) * s as f64,
                    (row as f64 + 0.5) * s as f64,
                )
                .unwrap();
            assert!(close(centre, AXES[f], 1e-12), "{layout:?} face {f}");
            // (The cell's far corner belongs to the next cell: step just inside.)
            let corner = if rot {
                (
                    (s * (col + 1)) as f64 - 1e-12,
                    (s * (row + 1)) as f64 - 1e-12,
                )
            } else {
                ((s * col) as f64, (s * row) as f64)
            };
            let d = m.pixel_dir(w, h, corner.0, corner.1).unwrap();
            assert!(
                close(d, gl_face_dir(f, -1.0, -1.0), 1e-12),
                "{layout:?} face {f} corner"
            );
        }
        // Inverse: each axis lands at its face centre.
        for (f, axis) in AXES.iter().enumerate() {
            let (col, row, _) = layout.cell(f);
            let (x, y) = m.dir_to_pixel(w, h, *axis).unwrap();
            assert!((x - (col as f64 + 0.5) * s as f64).abs() < 1e-9);
            // A face centre's pixel coordinates: f64 rounding of s (c + 0.5) (1e-13); 1e-9.
            assert!((y - (row as f64 + 0.5) * s as f64).abs() < 1e-9);
        }
    }
}

#[test]
fn cube_layout_cells() {
    let hc = CubeLayout::HorizontalCross;
    // +X (2,1), -X (0,1), +Y (1,0), -Y (1,2), +Z (1,1), -Z (3,1).
    let cells: Vec<_> = (0..6).map(|f| hc.cell(f)).collect();
    assert_eq!(
        cells,
        vec![
            (2, 1, false),
            (0, 1, false),
            (1, 0, false),
            (1, 2, false),
            (1, 1, false),
            (3, 1, false)
        ]
    );
    assert_eq!(CubeLayout::VerticalCross.cell(5), (1, 3, true));
    assert_eq!(CubeLayout::HorizontalStrip.cell(3), (3, 0, false));
    assert_eq!(CubeLayout::VerticalStrip.cell(3), (0, 3, false));
    let m = Mapping::Cube(hc);
    assert!(m.pixel_dir(64, 48, 8.0, 8.0).is_none(), "unused cell");
    assert!(m.pixel_dir(64, 48, 56.0, 40.0).is_none(), "unused cell");
}

/// Every pair of cells that touch in a layout must show the same directions along the shared
/// edge: the cross folds into a cube.
#[test]
fn cube_edges_match_across_the_layouts() {
    let s = 32;
    for layout in CubeLayout::ALL {
        if matches!(
            layout,
            CubeLayout::HorizontalStrip | CubeLayout::VerticalStrip
        ) {
            // Not a net: its neighbours +X|-X, +Y|-Y, +Z|-Z are opposite faces.
            continue;
        }
        let m = Mapping::Cube(layout);
        let (cols, rows) = layout.grid();
        let (w, h) = (cols * s, rows * s);
        let used =
            |c: usize, r: usize| (0..6).any(|f| layout.cell(f).0 == c && layout.cell(f).1 == r);
        let mut shared_edges = 0;
        let eps = 1e-9;
        for r in 0..rows {
            for c in 0..cols {
                if !used(c, r) {
                    continue;
                }
                // Right neighbour.
                if c + 1 < cols && used(c + 1, r) {
                    let x = ((c + 1) * s) as f64;
                    for k in 0..s {
                        let y = (r * s) as f64 + k as f64 + 0.5;
                        let a = m.pixel_dir(w, h, x - eps, y).unwrap();
                        let b = m.pixel_dir(w, h, x + eps, y).unwrap();
                        // Across a cell edge the directions are continuous: the two sides are 2 eps
                        // = 2e-9 pixel apart, a few 1e-11 rad on these faces; 1e-6 rad still flags
                        // any fold mistake (which jumps by a right angle).
                        assert!(
                            a.angle_between(b) < 1e-6,
                            "{layout:?} ({c},{r})|({},{r}) k={k}",
                            c + 1
                        );
                    }
                    shared_edges += 1;
                }
                // Neighbour below.
                if r + 1 < rows && used(c, r + 1) {
                    let y = ((r + 1) * s) as f64;
                    for k in 0..s {
                        let x = (c * s) as f64 + k as f64 + 0.5;
                        let a = m.pixel_dir(w, h, x, y - eps).unwrap();
                        let b = m.pixel_dir(w, h, x, y + eps).unwrap();
                        // As above across the edge below.
                        assert!(
                            a.angle_between(b) < 1e-6,
                            "{layout:?} ({c},{r}) over ({c},{})",
                            r + 1
                        );
                    }
                    shared_edges += 1;
                }
            }
        }
        // -X|+Z|+X|-Z (or -X|+Z|+X), +Y over +Z, +Z over -Y (and -Y over -Z in the vertical one).
        assert_eq!(shared_edges, 5, "{layout:?}");
    }
}

#[test]
fn cube_cross_wraps_around_the_horizon() {
    // The middle row of the horizontal cross continues from -Z (right end) to -X (left end).
    let m = Mapping::Cube(CubeLayout::HorizontalCross);
    let s = 32.0;
    for k in 0..32 {
        let y = s + k as f64 + 0.5;
        let right_end = m.pixel_dir(128, 96, 128.0, y).unwrap();
        let left_end = m.pixel_dir(128, 96, 0.0, y).unwrap();
        // The cross's row closes on itself: both ends show the same direction but for f64 rounding
        // (1e-15 rad); 1e-9.
        assert!(right_end.angle_between(left_end) < 1e-9);
    }
}

// ---- Every mapping: inverse and domain --------------------------------------------------------

#[test]
fn pixel_dir_and_dir_to_pixel_are_inverse() {
    for (m, w, h) in all_mappings() {
        let mut n = 0;
        for j in (0..h).step_by(7) {
            for i in (0..w).step_by(5) {
                let (x, y) = (i as f64 + 0.5, j as f64 + 0.5);
                let Some(d) = m.pixel_dir(w, h, x, y) else {
                    continue;
                };
                // Every pixel direction is a normalised f64 vector: unit to a few ulps.
                assert!((d.length() - 1.0).abs() < 1e-12);
                let (x2, y2) = m.dir_to_pixel(w, h, d).unwrap();
                let d2 = m.pixel_dir(w, h, x2, y2).unwrap();
                // pixel_dir(dir_to_pixel(d)) = d up to f64 rounding of the forward and inverse
                // formulas (1e-14); 1e-12.
                assert!((d - d2).length() < 1e-12, "{} ({i}, {j})", m.name());
                n += 1;
            }
        }
        assert!(n > 100, "{}", m.name());
        // Outside the image: None, never a panic.
        for (x, y) in [
            (-0.1, 1.0),
            (1.0, -0.1),
            (w as f64 + 0.1, 1.0),
            (f64::NAN, 1.0),
        ] {
            assert!(m.pixel_dir(w, h, x, y).is_none(), "{} ({x}, {y})", m.name());
        }
        assert!(m.pixel_dir(0, 0, 0.0, 0.0).is_none());
    }
}

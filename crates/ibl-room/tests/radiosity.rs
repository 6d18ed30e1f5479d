//! Form factors against closed forms, the furnace room against `B = E / (1 - rho)`, and the
//! reflectance estimate on a room whose probe is made from the forward radiosity solution (the
//! inverse must give back the reflectances it was made with).

use glam::{Mat3, Vec3};
use ibl_core::{Image, Rgb};
use ibl_room::depth_map::NO_PATCH;
use ibl_room::radiosity::{PatchRadiosity, solve_radiosity};
use ibl_room::reflectance::{HiddenRadiosity, PatchRole};
use ibl_room::{
    AnalysisSettings, EstimationSettings, FormFactorSettings, FormFactors, ProbeDepthMap, Room,
    RoomDescription, analyse_room,
};

fn room(text: &str, probe: Vec3) -> Room {
    let description: RoomDescription = toml::from_str(text).expect("test room parses");
    Room::new(&description, probe, Mat3::IDENTITY).expect("test room is valid")
}

fn no_progress(_: usize, _: usize) {}

/// Parallel, directly opposed `a x b` rectangles at distance `c` (Howell's catalogue, C-11).
fn parallel_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (x1, y1) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    2.0 / (std::f64::consts::PI * x * y)
        * (((1.0 + x * x) * (1.0 + y * y) / (1.0 + x * x + y * y))
            .sqrt()
            .ln()
            + x * y1 * (x / y1).atan()
            + y * x1 * (y / x1).atan()
            - x * x.atan()
            - y * y.atan())
}

/// Perpendicular rectangles sharing an edge of length `l`, widths `w` (emitter) and `h`
/// (Howell's catalogue, C-14).
fn perpendicular_rectangles(w: f64, h: f64, l: f64) -> f64 {
    let (w, h) = (w / l, h / l);
    let s = (w * w + h * h).sqrt();
    let a = (1.0 + w * w) * (1.0 + h * h) / (1.0 + w * w + h * h);
    let b = (w * w * (1.0 + w * w + h * h) / ((1.0 + w * w) * (w * w + h * h))).powf(w * w);
    let c = (h * h * (1.0 + h * h + w * w) / ((1.0 + h * h) * (h * h + w * w))).powf(h * h);
    1.0 / (std::f64::consts::PI * w)
        * (w * (1.0 / w).atan() + h * (1.0 / h).atan() - s * (1.0 / s).atan()
            + 0.25 * (a * b * c).ln())
}

#[test]
fn form_factors_match_closed_forms() {
    let rays = FormFactorSettings {
        rays_per_patch: 16384,
        seed: 3,
    };
    // Plain Monte Carlo with K rays has standard error sqrt(F (1 - F) / K) = 0.0031 at F = 0.2;
    // the doubly stratified estimate is well inside 2 sigma of that (measured errors below
    // 0.0015).
    let sigma = (0.2f64 * 0.8 / 16384.0).sqrt();
    let parallel = room(
        r#"
        patch_area_m2 = 2.0
        group = [{ name = "a" }]
        rectangle = [
          { group = "a", corner = [0, 0, 0], edge_u = [1, 0, 0], edge_v = [0, 0, -1] },
          { group = "a", corner = [0, 1, 0], edge_u = [0, 0, -1], edge_v = [1, 0, 0] },
        ]
        "#,
        Vec3::new(0.5, 0.5, -0.5),
    );
    let ff = FormFactors::compute(&parallel, &rays, &no_progress).expect("form factors");
    let exact = parallel_rectangles(1.0, 1.0, 1.0);
    assert!((exact - 0.19982).abs() < 1e-4, "{exact}");
    for (e, s) in [(0, 1), (1, 0)] {
        let f = f64::from(ff.get(e, s));
        assert!(
            (f - exact).abs() < 2.0 * sigma,
            "F_{e}{s} = {f}, exact {exact}"
        );
        // The rest of the rays escape (an open model).
        assert!((f64::from(ff.escaped[e]) + f - 1.0).abs() < 1e-5);
    }
    let perpendicular = room(
        r#"
        patch_area_m2 = 4.0
        group = [{ name = "a" }]
        rectangle = [
          { group = "a", corner = [0, 0, 0], edge_u = [1, 0, 0], edge_v = [0, 0, -1.5] },
          { group = "a", corner = [0, 0, 0], edge_u = [0, 0, -1.5], edge_v = [0, 0.7, 0] },
        ]
        "#,
        Vec3::new(0.5, 0.5, -0.5),
    );
    let ff = FormFactors::compute(&perpendicular, &rays, &no_progress).expect("form factors");
    // Floor 1 m wide (along x) and the wall 0.7 m high share the 1.5 m edge along z.
    let exact = perpendicular_rectangles(1.0, 0.7, 1.5);
    let f = f64::from(ff.get(0, 1));
    assert!((f - exact).abs() < 2.0 * sigma, "F = {f}, exact {exact}");
    // Reciprocity A_1 F_12 = A_2 F_21 (both estimates independent: 3 sigma of their sum).
    let back = f64::from(ff.get(1, 0)) * 0.7 * 1.5;
    assert!(
        (f * 1.5 - back).abs() < 3.0 * sigma * 1.5,
        "{} vs {back}",
        f * 1.5
    );
}

const CLOSED_BOX: &str = r#"
    patch_area_m2 = 0.25
    group = [{ name = "white" }]
    box = [{ min = [-1.5, 0, -2], max = [1.5, 2.5, 2], facing = "inward", group = "white" }]
"#;

#[test]
fn furnace_room_radiosity_is_emission_over_one_minus_rho() {
    let closed = room(CLOSED_BOX, Vec3::new(0.0, 1.2, 0.0));
    let ff = FormFactors::compute(
        &closed,
        &FormFactorSettings {
            rays_per_patch: 256,
            seed: 1,
        },
        &no_progress,
    )
    .expect("form factors");
    // Closed: every ray meets a front side, so every row sums to 1 up to f32 rounding of the
    // sum of count / K terms (K = 256: exact in binary; 1e-6 allows the summation order).
    for e in 0..ff.len() {
        assert!(
            (ff.row_sum(e) - 1.0).abs() < 1e-6,
            "row {e}: {}",
            ff.row_sum(e)
        );
        assert_eq!(ff.escaped[e], 0.0);
        assert_eq!(ff.back[e], 0.0);
    }
    let rho = Rgb::new(0.3, 0.6, 0.9);
    let emission = Rgb::new(1.0, 2.0, 0.5);
    let system = vec![
        PatchRadiosity::Unknown {
            emission,
            reflectance: rho,
        };
        ff.len()
    ];
    let tolerance = 1e-6;
    let solution =
        solve_radiosity(&ff, &system, &vec![Rgb::ZERO; ff.len()], tolerance, 1000).expect("solve");
    let exact = Rgb::new(
        emission.r / (1.0 - rho.r),
        emission.g / (1.0 - rho.g),
        emission.b / (1.0 - rho.b),
    );
    // Jacobi stops when a sweep changed B by at most tol * max B; the remaining error is at most
    // that change times rho / (1 - rho) = 9 for rho = 0.9; plus f32 rounding of ~300 sweeps.
    let bound = tolerance * exact.max_channel() * 9.0 + 1e-4;
    for b in &solution.radiosity {
        assert!(
            (*b - exact).map(f32::abs).max_channel() < bound,
            "{b:?} vs {exact:?}"
        );
    }
    assert!(solution.sweeps < 1000);
}

/// A closed room lit by a light-source ceiling panel, with a box that hides part of the floor;
/// the probe image is made from the forward radiosity solution (each pixel the radiance `B / pi`
/// of the patch it sees), so the inverse must return the reflectances it was made with.
#[test]
fn estimate_inverts_the_forward_solution() {
    let text = r#"
        patch_area_m2 = 0.12
        group = [
          { name = "wall" }, { name = "floor" }, { name = "ceiling" }, { name = "crate" },
          { name = "lamp", kind = "light" },
        ]
        [[box]]
        min = [-2, 0, -2]
        max = [2, 2.5, 1.5]
        facing = "inward"
        group = "wall"
        face_groups = { "-y" = "floor", "+y" = "ceiling" }
        openings = [{ face = "+y", min = [-0.5, -0.6], max = [0.5, 0.4], fill = "lamp" }]
        [[box]]
        min = [0.6, 0, -1.6]
        max = [1.6, 1.0, -0.6]
        group = "crate"
        omit = ["-y"]
    "#;
    let probe = Vec3::new(-0.4, 1.3, 0.6);
    let room = room(text, probe);
    let truth = [
        Rgb::new(0.7, 0.65, 0.6),
        Rgb::new(0.4, 0.3, 0.2),
        Rgb::new(0.8, 0.8, 0.8),
        Rgb::new(0.2, 0.5, 0.3),
    ];
    let lamp = Rgb::new(30.0, 28.0, 25.0);
    let settings = AnalysisSettings {
        form_factors: FormFactorSettings {
            rays_per_patch: 1024,
            seed: 2,
        },
        ..AnalysisSettings::default()
    };
    let ff = FormFactors::compute(&room, &settings.form_factors, &no_progress).expect("ff");
    let system: Vec<PatchRadiosity> = room
        .patches
        .iter()
        .map(|p| match p.group {
            4 => PatchRadiosity::Known(lamp),
            g => PatchRadiosity::Unknown {
                emission: Rgb::ZERO,
                reflectance: truth[g as usize],
            },
        })
        .collect();
    let forward =
        solve_radiosity(&ff, &system, &vec![Rgb::ZERO; ff.len()], 1e-7, 2000).expect("forward");
    let (w, h) = (512, 256);
    let depth = ProbeDepthMap::new(&room, w, h).expect("depth");
    let image = Image::from_fn_par(w, h, |x, y| {
        let s = depth.sample(x, y);
        if s.patch == NO_PATCH {
            Rgb::ZERO
        } else {
            forward.radiosity[s.patch as usize] / std::f32::consts::PI
        }
    });
    for hidden in [HiddenRadiosity::Solved, HiddenRadiosity::Gathered] {
        let settings = AnalysisSettings {
            estimation: EstimationSettings {
                tolerance: 1e-4,
                max_iterations: 40,
                hidden,
                ..EstimationSettings::default()
            },
            ..settings
        };
        let analysis = analyse_room(&room, &image, &settings, &|_, _, _| ()).expect("analysis");
        let estimate = &analysis.estimate;
        assert!(estimate.converged, "{hidden:?}");
        assert!(
            estimate.patches.iter().any(|p| p.role == PatchRole::Hidden),
            "the crate hides part of the floor"
        );
        for (g, t) in truth.iter().enumerate() {
            let r = Rgb::from_array(estimate.groups[g].reflectance.expect("surface"));
            // The same form factors made the image, so B / E is exact on every seen patch once
            // the hidden radiosity has converged to the forward solution's: measured 2e-5;
            // 1e-3 leaves room for the forward solve's 1e-7 and the estimate's 1e-4 tolerance.
            assert!(
                (r - *t).map(f32::abs).max_channel() < 1e-3,
                "{hidden:?} {}: {r:?} vs {t:?}",
                room.groups[g].name
            );
        }
    }
}

//! Material changes with colour bleeding by delta radiosity (Grosch 2005, section 4.3): the `k`
//! bounces converge to the forward radiosity solve of the changed room, and the prediction is
//! checked against iblkit's own path tracer on a synthetic room whose wall changes colour.

mod common;

use common::{PROBE, SIDE_VIEW, mean, noise_of_mean, relative_mse, render_halves, window_room};
use glam::{Mat3, Vec3};
use ibl_core::{Image, Rgb};
use ibl_room::depth_map::NO_PATCH;
use ibl_room::radiosity::{PatchRadiosity, solve_radiosity};
use ibl_room::reflectance::PatchRole;
use ibl_room::{
    AnalysisSettings, GroupKind, MaterialChange, ProbeDepthMap, Room, RoomDescription,
    analyse_room, change_materials,
};

/// A closed room lit by a ceiling lamp, a crate hiding part of the floor (the room of
/// `tests/radiosity.rs`' inverse check).
const LAMP_ROOM: &str = r#"
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

fn forward(
    room: &Room,
    ff: &ibl_room::FormFactors,
    albedo: &[Rgb],
    lamp: Rgb,
) -> ibl_room::radiosity::RadiositySolution {
    let system: Vec<PatchRadiosity> = room
        .patches
        .iter()
        .map(|p| match albedo.get(p.group as usize) {
            Some(&a) => PatchRadiosity::Unknown {
                emission: Rgb::ZERO,
                reflectance: a,
            },
            None => PatchRadiosity::Known(lamp),
        })
        .collect();
    solve_radiosity(ff, &system, &vec![Rgb::ZERO; ff.len()], 1e-7, 4000).expect("forward")
}

#[test]
fn bounces_converge_to_the_forward_solve_of_the_changed_room() {
    let description: RoomDescription = toml::from_str(LAMP_ROOM).expect("room parses");
    let room = Room::new(&description, Vec3::new(-0.4, 1.3, 0.6), Mat3::IDENTITY).expect("room");
    let truth = [
        Rgb::new(0.7, 0.65, 0.6),
        Rgb::new(0.4, 0.3, 0.2),
        Rgb::new(0.8, 0.8, 0.8),
        Rgb::new(0.2, 0.5, 0.3),
    ];
    let lamp = Rgb::new(30.0, 28.0, 25.0);
    let settings = AnalysisSettings::default();
    let ff = ibl_room::FormFactors::compute(&room, &settings.form_factors, &|_, _| ())
        .expect("form factors");
    let before = forward(&room, &ff, &truth, lamp);
    // The probe the forward solution makes: the estimate then reproduces it (tests/radiosity.rs).
    let (w, h) = (512, 256);
    let depth = ProbeDepthMap::new(&room, w, h).expect("depth");
    let probe = Image::from_fn_par(w, h, |x, y| match depth.sample(x, y).patch {
        NO_PATCH => Rgb::ZERO,
        p => before.radiosity[p as usize] / std::f32::consts::PI,
    });
    let analysis = analyse_room(&room, &probe, &settings, &|_, _, _| ()).expect("analysis");
    let estimate = &analysis.estimate;
    assert!(estimate.patches.iter().any(|p| p.role == PatchRole::Hidden));
    // The floor turns blue-green and the crate red.
    let changes = [
        MaterialChange {
            group: 1,
            reflectance: Rgb::new(0.1, 0.5, 0.7),
        },
        MaterialChange {
            group: 3,
            reflectance: Rgb::new(0.8, 0.15, 0.1),
        },
    ];
    let mut changed = truth;
    changed[1] = changes[0].reflectance;
    changed[3] = changes[1].reflectance;
    let after = forward(&room, &analysis.form_factors, &changed, lamp);
    // Largest error of a surface patch of `role` in any channel, relative to its largest channel.
    let error = |b: &[Rgb], role: PatchRole| -> f32 {
        (0..room.patches.len())
            .filter(|&k| estimate.patches[k].role == role)
            .map(|k| {
                (b[k] - after.radiosity[k]).map(f32::abs).max_channel()
                    / after.radiosity[k].max_channel().max(1e-6)
            })
            .fold(0.0f32, f32::max)
    };
    let mut errors = Vec::new();
    for bounces in [0, 1, 2, 3, 200] {
        let edit = change_materials(&room, estimate, &analysis.form_factors, &changes, bounces)
            .expect("edit");
        errors.push((
            bounces,
            error(&edit.radiosity, PatchRole::Seen),
            error(&edit.radiosity, PatchRole::Hidden),
            edit.last_bounce_relative,
        ));
        if bounces == 0 {
            // EQ6 on the changed groups' seen patches: B' = (rho' / rho) B exactly.
            for (k, p) in room.patches.iter().enumerate() {
                let Some(c) = changes.iter().find(|c| c.group == p.group as usize) else {
                    assert_eq!(edit.radiosity[k], estimate.patches[k].radiosity);
                    continue;
                };
                let rho = Rgb::from_array(estimate.groups[c.group].reflectance.expect("surface"));
                for ch in 0..3 {
                    let want = c.reflectance[ch] / rho[ch] * estimate.patches[k].radiosity[ch];
                    assert!((edit.radiosity[k][ch] - want).abs() <= 1e-6 * want.max(1.0));
                }
            }
        }
    }
    println!(
        "bounces, largest relative error against the forward solve (seen, hidden patches), last \
         bounce: {errors:?}"
    );
    // Each bounce shrinks the error by about the largest new reflectance (0.8); 200 bounces
    // leave 0.8^200. What stays is where the estimate's radiosity misses the forward solution's:
    // nothing on seen patches (`rho = B / E` there by construction), on hidden ones the hidden
    // solve's stop, a sweep's change under 1e-5 of the largest radiosity (the lamp, 30), left
    // error up to rho / (1 - rho) = 4 times that: 1.2e-3 absolute, 1e-3 of a hidden patch's
    // radiosity; seen patches err only through the hidden ones' light. Measured: seen 4.3e-5,
    // hidden 9.5e-4. Bounds: 3e-4 and 3e-3.
    let (_, seen, hidden, _) = errors[4];
    assert!(seen < 3e-4 && hidden < 3e-3, "{errors:?}");
    // The series shrinks monotonically.
    assert!(
        errors
            .windows(2)
            .all(|p| p[1].1 < p[0].1 && p[1].2 < p[0].2),
        "{errors:?}"
    );
}

/// Bounces of the predictions compared: none (EQ6 alone), Grosch's one, three, and 50 (within
/// 0.85^50 = 3e-4 of converged for the room's largest reflectance).
const BOUNCES: [u32; 4] = [0, 1, 3, 50];

/// The figures of one class of patches: the prediction's relative MSE against the path-traced
/// changed room for each of [`BOUNCES`], and the render's own noise on the same patches.
#[derive(Debug)]
struct Validation {
    patches: usize,
    relative_mse: Vec<f64>,
    noise: f64,
}

/// The classes compared.
#[derive(Debug)]
struct Validations {
    /// The changed wall, where the probe sees it.
    changed: Validation,
    /// The other surfaces the probe sees.
    seen: Validation,
    /// The other surfaces the probe does not see, as the side view sees them.
    hidden: Validation,
    /// The same hidden surfaces before the change: the estimate `rho E / pi` against the side
    /// view of the unchanged room (what the prediction starts from; one entry).
    hidden_before: Validation,
}

/// Renders the window room before and after its +x wall turns red, predicts the change from
/// the before probe by the estimate and delta radiosity, and compares patch radiances: the
/// changed wall and the other surfaces as the probe sees them, and the surfaces hidden from the
/// probe as the side view sees them (`width` pixels wide panoramas, `spp` samples per pixel).
fn validate(width: u32, spp: u32) -> Validations {
    let (room, side, albedo) = window_room();
    let accent = room.group_index("accent").expect("accent");
    let red = Rgb::new(0.85, 0.2, 0.1);
    let mut changed = albedo.clone();
    changed[accent] = red;
    let before = mean(&render_halves(&room, &albedo, &[], PROBE, width, spp));
    let before_side = render_halves(&room, &albedo, &[], SIDE_VIEW, width, spp);
    let after = render_halves(&room, &changed, &[], PROBE, width, spp);
    let after_side = render_halves(&room, &changed, &[], SIDE_VIEW, width, spp);
    let analysis = analyse_room(&room, &before, &AnalysisSettings::default(), &|_, _, _| ())
        .expect("analysis");
    let estimate = &analysis.estimate;
    let change = [MaterialChange {
        group: accent,
        reflectance: red,
    }];
    let edits: Vec<Vec<Rgb>> = BOUNCES
        .iter()
        .map(|&k| {
            change_materials(&room, estimate, &analysis.form_factors, &change, k)
                .expect("edit")
                .radiosity
        })
        .collect();
    let unchanged: Vec<Vec<Rgb>> = vec![estimate.patches.iter().map(|p| p.radiosity).collect()];
    let observe = |view: &Room, image: &Image<Rgb>| {
        let depth = ProbeDepthMap::new(view, image.width(), image.height()).expect("depth");
        ibl_room::observe(
            view,
            &depth,
            image,
            &ibl_room::ObservationSettings::default(),
        )
        .expect("observe")
    };
    // Each prediction's radiance B / pi against the patches' mean radiance in `view`'s render.
    let measure = |view: &Room,
                   halves: &[Image<Rgb>; 2],
                   predictions: &[Vec<Rgb>],
                   keep: &dyn Fn(usize) -> bool| {
        let truth = observe(view, &mean(halves));
        let [a, b] = halves.each_ref().map(|h| observe(view, h));
        let patches: Vec<usize> = (0..room.patches.len())
            .filter(|&p| truth.is_seen(p) && keep(p))
            .collect();
        let errors = predictions
            .iter()
            .map(|radiosity| {
                let pairs: Vec<(Rgb, Rgb)> = patches
                    .iter()
                    .map(|&p| {
                        (
                            radiosity[p] / std::f32::consts::PI,
                            truth.patches[p].radiance,
                        )
                    })
                    .collect();
                relative_mse(&pairs)
            })
            .collect();
        let radiance = |o: &ibl_room::observation::Observations| -> Vec<Rgb> {
            o.patches.iter().map(|p| p.radiance).collect()
        };
        Validation {
            patches: patches.len(),
            relative_mse: errors,
            noise: noise_of_mean([&radiance(&a), &radiance(&b)], &radiance(&truth), &patches),
        }
    };
    let group = |p: usize| room.patches[p].group as usize;
    let other = |p: usize| group(p) != accent && room.groups[group(p)].kind == GroupKind::Surface;
    let role = |p: usize| estimate.patches[p].role;
    let hidden = |p: usize| other(p) && role(p) == PatchRole::Hidden;
    Validations {
        changed: measure(&room, &after, &edits, &|p| {
            group(p) == accent && role(p) == PatchRole::Seen
        }),
        seen: measure(&room, &after, &edits, &|p| {
            other(p) && role(p) == PatchRole::Seen
        }),
        hidden: measure(&side, &after_side, &edits, &hidden),
        hidden_before: measure(&side, &before_side, &unchanged, &hidden),
    }
}

fn check(v: &Validations) {
    println!("{v:#?}");
    for (name, class) in [("seen", &v.seen), ("hidden", &v.hidden)] {
        let [none, one, three, _] = class.relative_mse[..] else {
            panic!("one error per bounce count");
        };
        assert!(class.patches >= 30, "{name}: {class:?}");
        // The reference resolves a 3 % error only if its own noise is well below it (measured
        // 0.4 and 0.5 % in the main tier, 0.04 and 0.05 % in the slow one).
        assert!(class.noise < 0.01, "{name}: {class:?}");
        // Issue 17's target for a material change with colour bleeding at k bounces: 3 %.
        assert!(three <= 0.03, "{name}: {class:?}");
        // Bleeding must matter here (a red wall beside white ones): one bounce removes at least
        // half of the error of leaving the other surfaces unchanged.
        assert!(one < 0.5 * none && three <= one, "{name}: {class:?}");
    }
    // The changed wall: EQ6 scales its own radiance by rho' / rho; the first bounce adds nothing
    // to it (a plane does not see itself), the second brings its light back from the others.
    // Within the same 3 % at three bounces (measured 0.22 %, 0.03 % in the slow tier).
    assert!(v.changed.relative_mse[2] <= 0.03, "{:?}", v.changed);
    // What the prediction on hidden surfaces misses is mostly the estimate's error there before
    // any change: the bounces add at most 1 % to it (measured 1.84 % after against 1.45 % before
    // in the main tier, 1.94 % against 1.89 % in the slow one).
    assert!(
        v.hidden.relative_mse[2] <= v.hidden_before.relative_mse[0] + 0.01,
        "{:?} {:?}",
        v.hidden,
        v.hidden_before
    );
}

#[test]
fn wall_colour_change_against_the_path_tracer() {
    // 128 x 64, 32 samples per pixel: about 3 s of rendering in the test profile.
    check(&validate(128, 32));
}

#[test]
#[ignore = "slow tier: about a minute of rendering"]
fn wall_colour_change_against_the_path_tracer_low_noise() {
    // 256 x 128, 256 samples per pixel: 32 times the samples, the noise 1/32 of the main tier's.
    check(&validate(256, 256));
}

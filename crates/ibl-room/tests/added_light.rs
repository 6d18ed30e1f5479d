//! New goniometric lights in the room (Grosch 2005, section 4.2), checked against iblkit's own
//! path tracer: the window room of `tests/material_change.rs` gets a real IES downlight
//! (`assets/photometry/ies`) beside the crate, whose shadow falls on the floor the probe does
//! not see. The prediction starts from the path-traced probe of the room without the light
//! (the estimate of section 3.2, then EQ5 per point with shadow rays, then `k` bounces by delta
//! radiosity) and is compared with the path-traced room with the light: patch radiances as the
//! probe sees them, and the surfaces hidden from the probe as a second viewpoint sees them
//! through the novel-view renderer (section 4.4).

mod common;

use common::{PROBE, SIDE_VIEW, mean, noise_of_mean, relative_mse, render_halves, window_room};
use glam::{Mat3, Vec3};
use ibl_core::{Image, Rgb};
use ibl_light::{GoniometricLight, intensity_per_candela_for};
use ibl_room::reflectance::PatchRole;
use ibl_room::room_radiance::RoomRadiance;
use ibl_room::{
    AnalysisSettings, GroupKind, HoleFill, LightAdditionSettings, NovelViewSettings,
    ObservationSettings, ProbeDepthMap, Room, add_lights, analyse_room, render_novel_view,
};
use ibl_scene::Camera;

/// The downlight: `overhead.ies` from the bundled photometry, 0.6 m below the ceiling over the
/// floor between the crate and the +x wall (which the probe does not see), tilted 20 degrees
/// towards the crate about the z axis; warm white, its peak intensity 60 probe units per sr
/// (on the floor below it about three times the window's light there).
fn downlight() -> GoniometricLight {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../assets/photometry/ies/overhead.ies"
    );
    let file = ibl_io::photometry::read_photometry(std::path::Path::new(path)).expect("ies");
    let table = file.table().clone();
    let peak = table.peak();
    GoniometricLight {
        position: Vec3::new(1.6, 1.9, -0.2),
        world_from_light: Mat3::from_rotation_z(-20f32.to_radians()),
        table,
        intensity_per_candela: intensity_per_candela_for(Rgb::new(1.0, 0.86, 0.7), peak / 60.0),
    }
}

/// Bounces of the predictions compared: direct light only, one (the default), three.
const BOUNCES: [u32; 3] = [0, 1, 3];

/// One class of patches: the prediction's relative MSE against the path-traced room with the
/// light for each of [`BOUNCES`], the error of leaving the light out, and the render's own noise.
#[derive(Debug)]
struct Validation {
    patches: usize,
    relative_mse: Vec<f64>,
    without_light: f64,
    noise: f64,
}

#[derive(Debug)]
struct Validations {
    /// Surfaces the probe sees, in the probe's view.
    seen: Validation,
    /// Surfaces the probe does not see, in the side view.
    hidden: Validation,
    /// The same hidden surfaces before the light: the estimate `rho E / pi` against the side view
    /// of the unlit room (what the prediction starts from).
    hidden_before: f64,
}

fn validate(width: u32, spp: u32) -> Validations {
    let (room, side, albedo) = window_room();
    let light = [downlight()];
    let before = mean(&render_halves(&room, &albedo, &[], PROBE, width, spp));
    let before_side = mean(&render_halves(&room, &albedo, &[], SIDE_VIEW, width, spp));
    let after = render_halves(&room, &albedo, &light, PROBE, width, spp);
    let after_side = render_halves(&room, &albedo, &light, SIDE_VIEW, width, spp);
    let analysis = analyse_room(&room, &before, &AnalysisSettings::default(), &|_, _, _| ())
        .expect("analysis");
    let estimate = &analysis.estimate;
    let reflectance: Vec<Rgb> = estimate.patches.iter().map(|p| p.reflectance).collect();
    let additions: Vec<_> = BOUNCES
        .iter()
        .map(|&bounces| {
            let settings = LightAdditionSettings {
                bounces,
                ..LightAdditionSettings::default()
            };
            add_lights(
                &room,
                &reflectance,
                &analysis.form_factors,
                light.to_vec(),
                &settings,
            )
            .expect("lights")
        })
        .collect();
    let (w, h) = (before.width(), before.height());
    // The probe's view: the unlit probe plus the lights' radiance at each pixel's point.
    let probe_views: Vec<Image<Rgb>> = additions
        .iter()
        .map(|a| {
            a.panorama(&room, &analysis.depth, &before)
                .expect("panorama")
        })
        .collect();
    // The side view through the novel-view renderer, the probe's texture where it saw.
    let side_camera = Camera::Panorama {
        position: SIDE_VIEW,
        world_from_probe: Mat3::IDENTITY,
    };
    let side_view = |field: &RoomRadiance| {
        render_novel_view(
            field,
            &side_camera,
            w as u32,
            h as u32,
            HoleFill::Estimate,
            &NovelViewSettings {
                samples_per_axis: 2,
            },
        )
        .expect("view")
        .image
    };
    let field = || RoomRadiance::new(&room, &analysis.depth, &before, estimate).expect("field");
    let side_unlit = side_view(&field());
    let side_views: Vec<Image<Rgb>> = additions
        .iter()
        .map(|a| side_view(&field().with_added_light(a)))
        .collect();

    let radiances = |view: &Room, image: &Image<Rgb>| -> (Vec<Rgb>, Vec<bool>) {
        let depth = ProbeDepthMap::new(view, image.width(), image.height()).expect("depth");
        let o = ibl_room::observe(view, &depth, image, &ObservationSettings::default())
            .expect("observe");
        let seen = (0..view.patches.len()).map(|p| o.is_seen(p)).collect();
        (o.patches.iter().map(|p| p.radiance).collect(), seen)
    };
    let surface = |p: usize| room.groups[room.patches[p].group as usize].kind == GroupKind::Surface;
    let role = |p: usize| estimate.patches[p].role;
    let measure = |view: &Room,
                   halves: &[Image<Rgb>; 2],
                   predictions: &[Image<Rgb>],
                   unlit: &Image<Rgb>,
                   keep: &dyn Fn(usize) -> bool| {
        let (truth, seen) = radiances(view, &mean(halves));
        let [a, b] = halves.each_ref().map(|h| radiances(view, h).0);
        let patches: Vec<usize> = (0..room.patches.len())
            .filter(|&p| seen[p] && keep(p))
            .collect();
        let error = |image: &Image<Rgb>| {
            let predicted = radiances(view, image).0;
            let pairs: Vec<(Rgb, Rgb)> =
                patches.iter().map(|&p| (predicted[p], truth[p])).collect();
            relative_mse(&pairs)
        };
        Validation {
            patches: patches.len(),
            relative_mse: predictions.iter().map(error).collect(),
            without_light: error(unlit),
            noise: noise_of_mean([&a, &b], &truth, &patches),
        }
    };
    let hidden = |p: usize| surface(p) && role(p) == PatchRole::Hidden;
    let (before_truth, before_seen) = radiances(&side, &before_side);
    let (before_predicted, _) = radiances(&side, &side_unlit);
    let hidden_patches: Vec<usize> = (0..room.patches.len())
        .filter(|&p| before_seen[p] && hidden(p))
        .collect();
    let pairs: Vec<(Rgb, Rgb)> = hidden_patches
        .iter()
        .map(|&p| (before_predicted[p], before_truth[p]))
        .collect();
    Validations {
        seen: measure(&room, &after, &probe_views, &before, &|p| {
            surface(p) && role(p) == PatchRole::Seen
        }),
        hidden: measure(&side, &after_side, &side_views, &side_unlit, &hidden),
        hidden_before: relative_mse(&pairs),
    }
}

fn check(v: &Validations) {
    println!("{v:#?}");
    for (name, class) in [("seen", &v.seen), ("hidden", &v.hidden)] {
        let [direct, one, three] = class.relative_mse[..] else {
            panic!("one error per bounce count");
        };
        assert!(class.patches >= 30, "{name}: {class:?}");
        // The reference resolves a 3 % error only if its own noise is well below it (measured
        // 0.23 and 0.20 % in the main tier).
        assert!(class.noise < 0.01, "{name}: {class:?}");
        // The light matters: leaving it out errs at least five times as much as adding it with
        // one bounce (measured 9.0 and 9.8 times).
        assert!(class.without_light > 5.0 * one, "{name}: {class:?}");
        // Issue 17's target for an added IES light: 3 %, met at the default one bounce
        // (measured 0.86 % seen, 2.2 % hidden; direct light alone 2.6 % and 6.6 %).
        assert!(one <= 0.03, "{name}: {class:?}");
        // The bounces converge (three: 0.16 % and 0.99 %).
        assert!(three < one && one < direct, "{name}: {class:?}");
    }
    // On hidden surfaces the prediction also carries the estimate's own error there before any
    // light (the group's reflectance, the hidden solve; 2.3 %): the light adds nothing to it.
    assert!(
        v.hidden.relative_mse[2] <= v.hidden_before,
        "{:?} before {}",
        v.hidden,
        v.hidden_before
    );
}

#[test]
fn an_ies_downlight_against_the_path_tracer() {
    // 128 x 64, 32 samples per pixel, as the material change's validation.
    check(&validate(128, 32));
}

#[test]
#[ignore = "slow tier: about a minute of rendering"]
fn an_ies_downlight_against_the_path_tracer_low_noise() {
    // 256 x 128, 256 samples per pixel.
    check(&validate(256, 256));
}

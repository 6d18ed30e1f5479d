//! Virtual objects in the room (Grosch 2005, section 4.1), checked against iblkit's own path
//! tracer: a diffuse sphere on the floor of the window room of `tests/material_change.rs`, in
//! front of the window, so that its shadow falls towards the probe. iblkit's differential path
//! tracer renders the room with and without it (the same paths where they do not meet it); the
//! display starts from the render without it (the estimate, 32 important patches, the
//! irradiance volume) and composites the sphere and its shadow into that probe, in Grosch's fast
//! and improved modes. Relative MSE per pixel over the pixels the sphere changes (itself and
//! its shadow), and over the whole view.

mod common;

use common::{PROBE, mean, relative_mse, render_with_objects, window_room};
use glam::Vec3;
use ibl_core::{Image, LatLong, Rgb};
use ibl_room::room_radiance::RoomRadiance;
use ibl_room::{
    AnalysisSettings, DisplayMode, ObjectDisplay, ObjectDisplaySettings, RoomVolume,
    VolumeSettings, analyse_room, important_patches,
};
use ibl_scene::{GeometryLayer, Material, PlacedMesh};

const CENTRE: Vec3 = Vec3::new(-0.5, 0.35, -0.45);
const RADIUS: f32 = 0.35;

fn sphere(material: Material) -> GeometryLayer {
    let mut mesh = ibl_scene::primitives::sphere(CENTRE, RADIUS, 4);
    mesh.material_names = vec!["sphere".into()];
    GeometryLayer::new(vec![PlacedMesh {
        name: "sphere".into(),
        mesh,
        materials: vec![material],
    }])
}

/// One display's errors.
#[derive(Debug)]
struct Errors {
    /// Over the sphere and its neighbourhood (relative MSE).
    changed: f64,
    /// Over the sphere's own pixels.
    object: f64,
    /// Over the neighbourhood's real pixels (its shadow).
    shadow: f64,
    /// Over the whole view.
    view: f64,
}

#[derive(Debug)]
struct Validation {
    /// 2 x 2 blocks compared.
    changed_blocks: usize,
    object_blocks: usize,
    fast: Errors,
    improved: Errors,
    /// The probe without the sphere against the truth with it, over the changed pixels.
    without_object: f64,
    /// The truth's own noise over the changed pixels (two halves).
    noise: f64,
}

fn validate(material: Material, width: u32, spp: u32) -> Validation {
    let (room, _, albedo) = window_room();
    let objects = sphere(material);
    let halves = render_with_objects(&room, &albedo, &[], &objects, PROBE, width, spp);
    let with_halves = [
        halves[0].with_objects.clone(),
        halves[1].with_objects.clone(),
    ];
    let truth = mean(&with_halves);
    let before = mean(&[
        halves[0].without_objects.clone(),
        halves[1].without_objects.clone(),
    ]);
    let coverage = Image::from_fn_par(truth.width(), truth.height(), |i, j| {
        (halves[0].object_coverage.get(i, j) + halves[1].object_coverage.get(i, j)) * 0.5
    });
    let analysis = analyse_room(&room, &before, &AnalysisSettings::default(), &|_, _, _| ())
        .expect("analysis");
    let estimate = &analysis.estimate;
    let important = important_patches(&room, estimate, 32);
    let field = RoomRadiance::new(&room, &analysis.depth, &before, estimate).expect("field");
    let volume: RoomVolume =
        RoomVolume::build(&field, &important, &VolumeSettings::default()).expect("volume");
    let reflectance: Vec<Rgb> = estimate.patches.iter().map(|p| p.reflectance).collect();
    let display = |mode| {
        let settings = ObjectDisplaySettings {
            mode,
            ..ObjectDisplaySettings::default()
        };
        ObjectDisplay::new(
            &field,
            &volume,
            &important,
            &reflectance,
            &objects,
            settings,
        )
        .expect("display")
        .panorama(&before)
        .expect("panorama")
        .image
    };
    let fast = display(DisplayMode::Fast);
    let improved = display(DisplayMode::Improved);
    // The pixels the sphere changes: those that show it, and those whose real point (by the
    // probe's depth map) lies within three radii of its centre, where its shadow and its
    // occlusion fall (a region fixed by the geometry, not by either picture).
    let (w, h) = (truth.width(), truth.height());
    let latlong = LatLong::new(w, h);
    let near = Image::from_fn_par(w, h, |i, j| {
        let d = room.world_from_probe * latlong.pixel_dir(i, j);
        let point = room.probe_position + d * analysis.depth.sample(i, j).distance_m;
        *coverage.get(i, j) > 0.0 || (point - CENTRE).length() < 3.0 * RADIUS
    });
    // Compared on 2 x 2 blocks: a quarter of the reference's per-pixel variance.
    let blocks = |image: &Image<Rgb>| {
        Image::from_fn_par(w / 2, h / 2, |i, j| {
            (*image.get(2 * i, 2 * j)
                + *image.get(2 * i + 1, 2 * j)
                + *image.get(2 * i, 2 * j + 1)
                + *image.get(2 * i + 1, 2 * j + 1))
                * 0.25
        })
    };
    let any = |mask: &dyn Fn(usize, usize) -> bool, i: usize, j: usize| {
        mask(2 * i, 2 * j)
            || mask(2 * i + 1, 2 * j)
            || mask(2 * i, 2 * j + 1)
            || mask(2 * i + 1, 2 * j + 1)
    };
    let (truth, before, fast, improved) = (
        blocks(&truth),
        blocks(&before),
        blocks(&fast),
        blocks(&improved),
    );
    let with_halves = [blocks(&with_halves[0]), blocks(&with_halves[1])];
    let shows = |i: usize, j: usize| *coverage.get(i, j) > 0.0;
    let coverage = Image::from_fn_par(
        w / 2,
        h / 2,
        |i, j| if any(&shows, i, j) { 1.0f32 } else { 0.0 },
    );
    let changed: Vec<(usize, usize)> = (0..h / 2)
        .flat_map(|j| (0..w / 2).map(move |i| (i, j)))
        .filter(|&(i, j)| any(&|x, y| *near.get(x, y), i, j))
        .collect();
    let on_object = |&(i, j): &(usize, usize)| *coverage.get(i, j) > 0.0;
    let error = |image: &Image<Rgb>, pixels: &mut dyn Iterator<Item = (usize, usize)>| {
        let pairs: Vec<(Rgb, Rgb)> = pixels
            .map(|(i, j)| (*image.get(i, j), *truth.get(i, j)))
            .collect();
        relative_mse(&pairs)
    };
    let all = |image: &Image<Rgb>| Errors {
        changed: error(image, &mut changed.iter().copied()),
        object: error(image, &mut changed.iter().copied().filter(on_object)),
        shadow: error(
            image,
            &mut changed.iter().copied().filter(|p| !on_object(p)),
        ),
        view: error(
            image,
            &mut (0..h / 2).flat_map(|j| (0..w / 2).map(move |i| (i, j))),
        ),
    };
    let noise: Vec<(Rgb, Rgb)> = changed
        .iter()
        .map(|&(i, j)| {
            let d = (*with_halves[0].get(i, j) - *with_halves[1].get(i, j)) * 0.5;
            (*truth.get(i, j) + d, *truth.get(i, j))
        })
        .collect();
    Validation {
        changed_blocks: changed.len(),
        object_blocks: changed.iter().filter(|p| on_object(p)).count(),
        fast: all(&fast),
        improved: all(&improved),
        without_object: error(&before, &mut changed.iter().copied()),
        noise: relative_mse(&noise),
    }
}

const DIFFUSE: Material = Material::Diffuse {
    albedo: Rgb::new(0.7, 0.5, 0.3),
};
const MIRROR: Material = Material::Mirror {
    reflectance: Rgb::new(0.9, 0.9, 0.9),
};

fn check(diffuse: &Validation, mirror: &Validation) {
    println!("diffuse {diffuse:#?}\nmirror {mirror:#?}");
    for v in [diffuse, mirror] {
        assert!(v.object_blocks >= 30 && v.changed_blocks >= 150, "{v:?}");
        // The reference resolves a 2 % error only if its own noise is below it.
        assert!(v.noise < 0.015, "{v:?}");
        // Leaving the object out is far off (the region is where it matters).
        assert!(v.without_object > 0.1, "{v:?}");
    }
    // Issue 17's target for an inserted object, 2 %, met by the improved display over the
    // sphere and its neighbourhood (measured 0.72 %; the sphere alone 1.9 %, its shadow 0.43 %).
    let d = &diffuse.improved;
    assert!(
        d.changed <= 0.02 && d.object <= 0.03 && d.shadow <= 0.01,
        "{diffuse:?}"
    );
    // Over the whole view the sphere is a small part (0.15 %).
    assert!(d.view <= 0.005, "{diffuse:?}");
    // The fast display, Grosch's approximation, is about ten times further off (6.7 %): no
    // shadow of the important light on the sphere, none of the unimportant light anywhere.
    let f = &diffuse.fast;
    assert!(
        f.changed > 3.0 * d.changed && f.changed < 0.2,
        "{diffuse:?}"
    );
    // A mirror reflects the room as the probe saw it, less the sphere's shadow where its rays
    // land: the same bound (measured 0.73 %; the sphere alone 2.0 %).
    assert!(mirror.improved.changed <= 0.02, "{mirror:?}");
}

#[test]
fn a_sphere_on_the_floor_against_the_path_tracer() {
    // 128 x 64, 64 samples per pixel, compared on 64 x 32 blocks.
    check(&validate(DIFFUSE, 128, 64), &validate(MIRROR, 128, 64));
}

#[test]
#[ignore = "slow tier: about a minute of rendering"]
fn a_sphere_on_the_floor_against_the_path_tracer_low_noise() {
    // 256 x 128, 256 samples per pixel: a sixteenth of the main tier's per-block variance.
    check(&validate(DIFFUSE, 256, 256), &validate(MIRROR, 256, 256));
}

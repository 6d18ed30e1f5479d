//! `ibl room render` (issue 17, part 6): the edits file's checks, and the apartment room after
//! its bundled edits: the floor's pixels scale by `rho' / rho`, the walls turn redder by colour
//! bleeding and darker (less light off the floor), the moved camera's view shows the change.

#![allow(clippy::unwrap_used)] // tests may panic

use std::path::{Path, PathBuf};

use ibl_core::{Image, Rgb};
use ibl_pipeline::Silent;
use ibl_pipeline::room_estimate::{SamplingOptions, estimate_room};
use ibl_pipeline::room_render::{RoomEdits, render_edits};

fn apartment() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/rooms/apartment")
}

fn refused(text: &str, needle: &str) {
    let e = RoomEdits::parse(text, Path::new("e.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("e.toml") && e.contains(needle), "{e}");
}

#[test]
fn bad_edits_are_refused_with_the_file_and_the_problem() {
    refused("version = 2\n", "version 2");
    refused("version = 1\ncolour = 3\n", "colour");
    refused(
        "version = 1\n[[material]]\ngroup = \"floor\"\nreflectance = [1.2, 0, 0]\n",
        "not in [0, 1]",
    );
    refused(
        "version = 1\n[[material]]\ngroup = \"floor\"\nreflectance = [0.1, 0, 0]\n\
         [[material]]\ngroup = \"floor\"\nreflectance = [0.2, 0, 0]\n",
        "changed twice",
    );
    refused(
        "version = 1\n[view]\nposition = [0, 1, 0]\nlook_at = [0, 1, 0]\n",
        "look_at must differ",
    );
    refused(
        "version = 1\n[view]\nposition = [0, 1, 0]\nlook_at = [1, 1, 0]\nfill = \"paint\"\n",
        "fill `paint`",
    );
    refused(
        "version = 1\n[view]\nposition = [0, 1, 0]\nlook_at = [1, 1, 0]\nsize = [0, 10]\n",
        "size 0 x 10",
    );
    let light = "version = 1\n[[light]]\nfile = \"a.ies\"\nposition = [0, 2, 0]\n";
    refused(
        &format!("{light}nits_per_unit = 1.0\npeak_intensity = 3.0\n"),
        "not both",
    );
    refused(&format!("{light}colour = [0, 0, 0]\n"), "not black");
    refused(&format!("{light}peak_intensity = -3.0\n"), "positive");
    refused(
        "version = 1\n[[light]]\nfile = \"a.ies\"\nposition = [0, nan, 0]\n",
        "finite",
    );
    // The light's file is resolved against the edits file's folder and read on request; a
    // missing one is an error naming it.
    let edits = RoomEdits::parse(light, &apartment().join("e.toml")).unwrap();
    assert_eq!(edits.lights[0].file, apartment().join("a.ies"));
    let e = edits.load_lights().unwrap_err().to_string();
    assert!(e.contains("a.ies"), "{e}");
    let ok = RoomEdits::read(&apartment().join("edits.toml")).unwrap();
    assert_eq!(ok.materials.len(), 1);
    assert!(ok.view.is_none());
    assert!(
        RoomEdits::read(&apartment().join("edits-view.toml"))
            .unwrap()
            .view
            .is_some()
    );
}

/// Mean of `after / before` per channel over the pixels where `mask` holds.
fn mean_ratio(
    before: &Image<Rgb>,
    after: &Image<Rgb>,
    mask: impl Fn(usize, usize) -> bool,
) -> [f64; 3] {
    let (mut sum, mut n) = ([0.0f64; 3], 0usize);
    for j in 0..before.height() {
        for i in 0..before.width() {
            let (b, a) = (before.get(i, j).to_array(), after.get(i, j).to_array());
            if mask(i, j) && b.iter().all(|&v| v > 1e-4) {
                for c in 0..3 {
                    sum[c] += f64::from(a[c] / b[c]);
                }
                n += 1;
            }
        }
    }
    assert!(n > 100, "{n} pixels");
    sum.map(|s| s / n as f64)
}

#[test]
fn the_apartment_floor_turns_red_and_bleeds_onto_the_walls() {
    let room = apartment().join("room.toml");
    let estimated = estimate_room(&room, &SamplingOptions::default(), &Silent).unwrap();
    let edits = RoomEdits::read(&apartment().join("edits.toml")).unwrap();
    let pictures = render_edits(&estimated, &edits, &edits.load().unwrap(), &room).unwrap();
    assert_eq!(pictures.before, estimated.probe, "before is the probe");
    let r = &estimated.input.room;
    let floor = r.groups.iter().position(|g| g.name == "floor").unwrap();
    let wall = r.groups.iter().position(|g| g.name == "wall").unwrap();
    let depth = &estimated.analysis.depth;
    let group_of = |i: usize, j: usize| {
        let p = depth.sample(i, j).patch as usize;
        r.patches.get(p).map(|patch| patch.group as usize)
    };
    let rho = estimated.analysis.estimate.groups[floor]
        .reflectance
        .unwrap();
    let new = pictures.report.materials[0].after;
    let floor_ratio = mean_ratio(&pictures.before, &pictures.after, |i, j| {
        group_of(i, j) == Some(floor)
    });
    // B' / B = (rho' / rho) (E' / E), and with one bounce of bleeding the floor's own
    // irradiance is unchanged (the bounce goes from the floor to the rest of the room; it
    // would come back at the second), so the ratio is rho' / rho to f32 rounding.
    for c in 0..3 {
        let expected = f64::from(new[c] / rho[c]);
        assert!(
            (floor_ratio[c] / expected - 1.0).abs() < 1e-3,
            "floor channel {c}: {:.3} against rho'/rho {expected:.3}",
            floor_ratio[c]
        );
    }
    eprintln!(
        "floor after/before {floor_ratio:.3?} against rho'/rho {:.3?}",
        [0, 1, 2].map(|c| new[c] / rho[c])
    );
    // The walls: a little darker (less light off the floor), redder than green and blue.
    let wall_ratio = mean_ratio(&pictures.before, &pictures.after, |i, j| {
        group_of(i, j) == Some(wall)
    });
    assert!(
        wall_ratio.iter().all(|&x| (0.7..=1.01).contains(&x)),
        "walls change little: {wall_ratio:?}"
    );
    assert!(
        wall_ratio[0] > wall_ratio[1] && wall_ratio[0] > wall_ratio[2],
        "walls turn redder: {wall_ratio:?}"
    );
    eprintln!("walls after/before {wall_ratio:.3?}");
    assert!(pictures.report.bounces == 1 && pictures.report.last_bounce_relative > 0.0);

    // The moved camera shows the same change.
    let edits = RoomEdits::read(&apartment().join("edits-view.toml")).unwrap();
    let view = render_edits(&estimated, &edits, &edits.load().unwrap(), &room).unwrap();
    assert_eq!((view.after.width(), view.after.height()), (480, 360));
    let bottom = mean_ratio(&view.before, &view.after, |_, j| j > 330);
    assert!(
        bottom[0] > 2.0 * bottom[2],
        "the floor at the view's bottom is redder: {bottom:?}"
    );
    assert!(view.report.filled_fraction.is_some());
}

#[test]
fn the_apartment_gets_the_downlight_pool_eq5_predicts() {
    let room = apartment().join("room.toml");
    let estimated = estimate_room(&room, &SamplingOptions::default(), &Silent).unwrap();
    let edits = RoomEdits::read(&apartment().join("edits-light.toml")).unwrap();
    let assets = edits.load().unwrap();
    let lights = &assets.lights;
    let pictures = render_edits(&estimated, &edits, &assets, &room).unwrap();
    assert_eq!(pictures.before, estimated.probe, "before is the probe");
    let row = &pictures.report.lights[0];
    // The table's flux is its exact integral (ibl-light), and the scale puts its peak at the
    // asked 40 probe units per sr.
    assert!((row.flux_lm - lights[0].light.table.flux()).abs() < 1e-9);
    assert!((row.peak_intensity - 40.0).abs() < 1e-3, "{row:?}");
    // A light only adds: no pixel darkens (beyond f32 rounding).
    for (b, a) in pictures.before.pixels().iter().zip(pictures.after.pixels()) {
        for c in 0..3 {
            assert!(a[c] >= b[c] - 1e-6 * b[c].abs().max(1.0), "{b:?} -> {a:?}");
        }
    }
    // The floor right below the light: EQ5 at the nadir, `E = I(0) / h^2`, reflected as
    // `rho E / pi` with the floor patch's estimated reflectance, plus the patch's share of the
    // light's first bounce (off the lit +x wall 0.48 m away and the floor around: 14 % of the
    // direct light there, validated against the path tracer in ibl-room's tests/added_light.rs).
    // The pixel's footprint (about 2 cm on the floor) changes E by under 0.1 %.
    let r = &estimated.input.room;
    let light = &lights[0].light;
    let below = glam::Vec3::new(light.position.x, 0.0, light.position.z);
    let to = r.world_from_probe.transpose() * (below - r.probe_position);
    let (i, j) = ibl_core::LatLong::new(pictures.after.width(), pictures.after.height())
        .dir_to_pixel(to.normalize().as_dvec3());
    let patch = estimated.analysis.depth.sample(i, j).patch as usize;
    assert_eq!(r.groups[r.patches[patch].group as usize].name, "floor");
    let reflectance: Vec<Rgb> = estimated
        .analysis
        .estimate
        .patches
        .iter()
        .map(|p| p.reflectance)
        .collect();
    let addition = ibl_room::add_lights(
        r,
        &reflectance,
        &estimated.analysis.form_factors,
        vec![light.clone()],
        &ibl_room::LightAdditionSettings::default(),
    )
    .unwrap();
    let indirect = addition.indirect_radiosity[patch] / std::f32::consts::PI;
    let e = light.intensity_towards(-glam::Vec3::Y) / (light.position.y * light.position.y);
    let added = *pictures.after.get(i, j) - *pictures.before.get(i, j);
    for c in 0..3 {
        let direct = reflectance[patch][c] * e[c] / std::f32::consts::PI;
        eprintln!(
            "channel {c}: added {:.4} = rho E / pi {direct:.4} + indirect {:.4}",
            added[c], indirect[c]
        );
        assert!(
            ((added[c] - indirect[c]) / direct - 1.0).abs() < 1e-3,
            "channel {c}: {added:?} against {direct} + {indirect:?}"
        );
        assert!(
            indirect[c] > 0.0 && indirect[c] < 0.2 * direct,
            "{indirect:?}"
        );
    }
    // The pool is seen: the light adds more than the window gives the floor there.
    assert!(added.g > pictures.before.get(i, j).g, "{added:?}");
}

#[test]
fn the_apartment_gets_the_bunny_and_its_shadow() {
    let room = apartment().join("room.toml");
    let estimated = estimate_room(&room, &SamplingOptions::default(), &Silent).unwrap();
    let edits = RoomEdits::read(&apartment().join("edits-object.toml")).unwrap();
    let assets = edits.load().unwrap();
    let pictures = render_edits(&estimated, &edits, &assets, &room).unwrap();
    let row = pictures.report.objects.as_ref().unwrap();
    assert_eq!(
        (row.names.clone(), row.display),
        (vec!["bunny".to_string()], "improved")
    );
    let (w, h) = (pictures.after.width(), pictures.after.height());
    // Where the bunny stands: its direction from the probe, and the pixels around it change.
    let r = &estimated.input.room;
    let feet = glam::Vec3::new(1.45, 0.1, -0.75);
    let to = r.world_from_probe.transpose() * (feet - r.probe_position);
    let (i, j) = ibl_core::LatLong::new(w, h).dir_to_pixel(to.normalize().as_dvec3());
    let change = |x: usize, y: usize| {
        let (b, a) = (pictures.before.get(x, y).g, pictures.after.get(x, y).g);
        (a - b).abs() / b.max(1e-3)
    };
    let near = (j.saturating_sub(6)..(j + 6).min(h))
        .flat_map(|y| (i.saturating_sub(6)..(i + 6).min(w)).map(move |x| (x, y)))
        .filter(|&(x, y)| change(x, y) > 0.2)
        .count();
    assert!(
        near > 20,
        "{near} pixels around the bunny changed by over 20 %"
    );
    // The ceiling's top rows, far from it, keep their radiance within 1 %.
    for y in 0..8 {
        for x in 0..w {
            assert!(
                change(x, y) < 0.01,
                "pixel ({x}, {y}) changed {}",
                change(x, y)
            );
        }
    }
    let e = RoomEdits::parse("version = 1\ndisplay = \"best\"\n", Path::new("e.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("display `best`"), "{e}");
    // A bad object is named with its field, from the scene-file checks.
    let bad = RoomEdits::parse(
        "version = 1\n[[object]]\nshape = \"sphere\"\n",
        &apartment().join("e.toml"),
    )
    .unwrap();
    let e = bad.load().unwrap_err().to_string();
    assert!(e.contains("object[0]") && e.contains("radius"), "{e}");
}

#[test]
fn the_bunny_under_a_new_light_from_a_moved_camera() {
    let room = apartment().join("room.toml");
    let estimated = estimate_room(&room, &SamplingOptions::default(), &Silent).unwrap();
    // The bunny of edits-object.toml seen from 1.3 m away, with and without a downlight 1.4 m
    // above it.
    let bunny = "[[object]]\nshape = \"mesh\"\nfile = \"../../models/bunny.glb\"\nscale = 0.25\n\
                 rotate_deg = [-60.0, 0.0, 0.0]\ntranslate = [1.45, 0.223, -0.75]\n\
                 material = { kind = \"diffuse\", albedo = [0.75, 0.75, 0.75] }\n";
    let light = "[[light]]\nfile = \"../../photometry/ies/umbrella.ies\"\n\
                 position = [1.45, 1.6, -0.75]\npeak_intensity = 20.0\n";
    let view = "[view]\nposition = [0.6, 1.0, 0.1]\nlook_at = [1.45, 0.25, -0.75]\n\
                vertical_fov_deg = 40.0\nsize = [96, 72]\nfill = \"estimate\"\n\
                samples_per_axis = 1\n";
    let render = |parts: &[&str]| {
        let text = format!("version = 1\n{}", parts.concat());
        let edits = RoomEdits::parse(&text, &apartment().join("e.toml")).unwrap();
        let assets = edits.load().unwrap();
        render_edits(&estimated, &edits, &assets, &room).unwrap()
    };
    let (plain, dark, lit) = (
        render(&[view]),
        render(&[bunny, view]),
        render(&[bunny, light, view]),
    );
    assert_eq!((lit.after.width(), lit.after.height()), (96, 72));
    assert!(plain.report.objects.is_none() && lit.report.objects.is_some());
    // The view's centre shows the bunny instead of the floor, and the light above it makes it
    // brighter there.
    let centre = |image: &Image<Rgb>| {
        let mut sum = 0.0f32;
        for y in 30..42 {
            for x in 42..54 {
                sum += image.get(x, y).g;
            }
        }
        sum / 144.0
    };
    let (p, d, l) = (
        centre(&plain.after),
        centre(&dark.after),
        centre(&lit.after),
    );
    eprintln!("view centre: floor {p:.3}, bunny {d:.3}, bunny under the light {l:.3}");
    assert!(
        (d - p).abs() > 0.05 * p,
        "the bunny {d} against the floor {p}"
    );
    assert!(
        l > 1.5 * d,
        "the bunny lit {l} against {d} without the light"
    );
}

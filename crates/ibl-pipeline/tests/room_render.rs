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
    let pictures = render_edits(&estimated, &edits, &room).unwrap();
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
    let new = pictures.materials[0].after;
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
    assert!(pictures.bounces == 1 && pictures.last_bounce_relative > 0.0);

    // The moved camera shows the same change.
    let edits = RoomEdits::read(&apartment().join("edits-view.toml")).unwrap();
    let view = render_edits(&estimated, &edits, &room).unwrap();
    assert_eq!((view.after.width(), view.after.height()), (480, 360));
    let bottom = mean_ratio(&view.before, &view.after, |_, j| j > 330);
    assert!(
        bottom[0] > 2.0 * bottom[2],
        "the floor at the view's bottom is redder: {bottom:?}"
    );
    assert!(view.filled_fraction.is_some());
}

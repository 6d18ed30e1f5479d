//! Colour bleeding after a material change (Grosch 2005, section 4.3) on the worked example room
//! (`assets/rooms/apartment`, 2554 patches, 1.41 M stored form factors): the floor's reflectance
//! changed, its delta radiosity shot through the form factors once (the default) and three
//! times, and the probe re-rendered with the new radiance; then a new light (section 4.2, the
//! demo's `edits-light.toml` downlight): its patch means and one bounce, and the panorama with a
//! shadow ray per pixel. Setup (the analysis, about 1 s) is not timed. Issue 17's target: the
//! update under 50 ms on the CPU (Grosch: 0.3 to 1.0 s).
//!
//! `cargo bench -p ibl-room --bench material_change -- --warm-up-time 1 --measurement-time 5`

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use ibl_core::Rgb;
use ibl_light::{GoniometricLight, intensity_per_candela_for};
use ibl_room::{
    AnalysisSettings, LightAdditionSettings, MaterialChange, Room, RoomFile, add_lights,
    analyse_room, change_materials,
};

fn bench(c: &mut Criterion) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/rooms/apartment");
    let text = std::fs::read_to_string(dir.join("room.toml")).expect("room file");
    let file = RoomFile::from_toml(&text).expect("room file parses");
    let room = Room::from_file(&file).expect("room");
    let probe = ibl_io::read_image(&dir.join(&file.probe.file))
        .expect("probe")
        .image;
    let analysis =
        analyse_room(&room, &probe, &AnalysisSettings::default(), &|_, _, _| ()).expect("analysis");
    let floor = room.group_index("floor").expect("floor group");
    let change = [MaterialChange {
        group: floor,
        reflectance: Rgb::new(0.25, 0.3, 0.45),
    }];
    let (estimate, ff) = (&analysis.estimate, &analysis.form_factors);
    let mut group = c.benchmark_group(format!(
        "apartment {} patches, {} form factors",
        room.patches.len(),
        ff.entries()
    ));
    for bounces in [1, 3] {
        group.bench_function(format!("floor changed, {bounces} bounce(s)"), |b| {
            b.iter(|| change_materials(&room, estimate, ff, &change, bounces).expect("edit"))
        });
    }
    let edit = change_materials(&room, estimate, ff, &change, 1).expect("edit");
    group.bench_function(
        format!(
            "panorama re-rendered ({} x {})",
            probe.width(),
            probe.height()
        ),
        |b| b.iter(|| edit.panorama(&analysis.depth, &probe).expect("panorama")),
    );
    // The demo's downlight (assets/rooms/apartment/edits-light.toml).
    let ies = dir.join("../../photometry/ies/umbrella.ies");
    let table = ibl_io::photometry::read_photometry(&ies)
        .expect("ies")
        .table()
        .clone();
    let peak = table.peak();
    let light = GoniometricLight {
        position: glam::Vec3::new(2.25, 2.9, 0.9),
        world_from_light: glam::Mat3::IDENTITY,
        table,
        intensity_per_candela: intensity_per_candela_for(Rgb::new(1.0, 0.78, 0.56), peak / 40.0),
    };
    let reflectance: Vec<Rgb> = estimate.patches.iter().map(|p| p.reflectance).collect();
    let settings = LightAdditionSettings::default();
    group.bench_function(
        "new IES light: patch means (4 x 4 points) and 1 bounce",
        |b| {
            b.iter(|| {
                add_lights(&room, &reflectance, ff, vec![light.clone()], &settings).expect("light")
            })
        },
    );
    let addition =
        add_lights(&room, &reflectance, ff, vec![light.clone()], &settings).expect("light");
    group.bench_function(
        format!(
            "new IES light: panorama with its shadow rays ({} x {})",
            probe.width(),
            probe.height()
        ),
        |b| {
            b.iter(|| {
                addition
                    .panorama(&room, &analysis.depth, &probe)
                    .expect("panorama")
            })
        },
    );
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! Colour bleeding after a material change (Grosch 2005, section 4.3) on the worked example room
//! (`assets/rooms/apartment`, 2554 patches, 1.41 M stored form factors): the floor's reflectance
//! changed, its delta radiosity shot through the form factors once (the default) and three
//! times, and the probe re-rendered with the new radiance. Setup (the analysis, about 1 s) is
//! not timed. Issue 17's target: the update under 50 ms on the CPU (Grosch: 0.3 to 1.0 s).
//!
//! `cargo bench -p ibl-room --bench material_change -- --warm-up-time 1 --measurement-time 5`

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use ibl_core::Rgb;
use ibl_room::{AnalysisSettings, MaterialChange, Room, RoomFile, analyse_room, change_materials};

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
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

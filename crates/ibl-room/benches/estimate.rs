//! Reflectance estimation of the synthetic room (`assets/rooms/synthetic`, 2295 patches of at
//! most 0.05 m^2, a 1024 x 512 probe): the whole of Grosch 2005 section 3.2 (depth map, probe
//! radiosity, form factors by ray casting with 900 rays per patch, the iteration), and its
//! stages alone. Issue 16's target: the whole under 2 s on 2 cores.
//!
//! `cargo bench -p ibl-room --bench estimate -- --warm-up-time 1 --measurement-time 10`

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use ibl_room::{
    AnalysisSettings, FormFactors, ProbeDepthMap, Room, RoomFile, analyse_room,
    estimate_reflectance, observe,
};

fn bench(c: &mut Criterion) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/rooms/synthetic");
    let text = std::fs::read_to_string(dir.join("room.toml")).expect("room file");
    let file = RoomFile::from_toml(&text).expect("room file parses");
    let room = Room::from_file(&file).expect("room");
    let probe = ibl_io::read_image(&dir.join(&file.probe.file))
        .expect("probe")
        .image;
    let settings = AnalysisSettings::default();
    let mut group = c.benchmark_group(format!("room {} patches", room.patches.len()));
    group.sample_size(10);
    group.bench_function(
        "analyse (depth map + observe + form factors + estimate)",
        |b| b.iter(|| analyse_room(&room, &probe, &settings, &|_, _, _| ()).expect("analysis")),
    );
    group.bench_function("form factors", |b| {
        b.iter(|| FormFactors::compute(&room, &settings.form_factors, &|_, _| ()).expect("ff"))
    });
    let depth = ProbeDepthMap::new(&room, probe.width(), probe.height()).expect("depth");
    group.bench_function("depth map", |b| {
        b.iter(|| ProbeDepthMap::new(&room, probe.width(), probe.height()).expect("depth"))
    });
    let observations = observe(&room, &depth, &probe, &settings.observation).expect("observe");
    group.bench_function("observe", |b| {
        b.iter(|| observe(&room, &depth, &probe, &settings.observation).expect("observe"))
    });
    let ff = FormFactors::compute(&room, &settings.form_factors, &|_, _| ()).expect("ff");
    group.bench_function("estimate (iteration only)", |b| {
        b.iter(|| {
            estimate_reflectance(&room, &observations, &ff, &settings.estimation).expect("estimate")
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

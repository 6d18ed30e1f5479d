//! The room's irradiance volume (Grosch 2005, section 4.1) on the synthetic room
//! (`assets/rooms/synthetic`, grid 0.5 m: 11 x 7 x 9 key points, 1024 rays each): building it,
//! and 1000 look-ups at random positions with the plain validity rule and with the visibility
//! test (eight occlusion rays), SH L2 against the ambient cube. Setup (the analysis) not timed.
//!
//! `cargo bench -p ibl-room --bench irradiance_volume -- --warm-up-time 1 --measurement-time 5`

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use ibl_room::ambient_cube::AmbientCube;
use ibl_room::irradiance_volume::GatheredIrradiance;
use ibl_room::{
    AnalysisSettings, ImportantLights, KeyPointVisibility, Room, RoomFile, RoomRadiance,
    RoomVolume, VolumeSettings, analyse_room, important_patches,
};
use ibl_sh::{IrradianceL2, LeakControl, VolumeLayer};
use rand::{Rng, SeedableRng};

fn bench_basis<P: GatheredIrradiance>(
    c: &mut Criterion,
    name: &str,
    radiance: &RoomRadiance,
    important: &ImportantLights,
    positions: &[Vec3],
) {
    let room = radiance.room();
    let settings = VolumeSettings::default();
    let mut group = c.benchmark_group(format!("volume {name}"));
    group.sample_size(10);
    group.bench_function("build", |b| {
        b.iter(|| RoomVolume::<P>::build(radiance, important, &settings).expect("volume"))
    });
    let volume = RoomVolume::<P>::build(radiance, important, &settings).expect("volume");
    for visibility in [KeyPointVisibility::Any, KeyPointVisibility::Unoccluded] {
        group.bench_function(format!("1000 look-ups + irradiance, {visibility:?}"), |b| {
            b.iter(|| {
                let mut sum = 0.0f32;
                for &p in positions {
                    if let Some(e) = volume.sample(
                        room,
                        p,
                        VolumeLayer::UnimportantLight,
                        LeakControl::ValidOnly,
                        visibility,
                    ) {
                        sum += e.irradiance(Vec3::Y)[1];
                    }
                }
                sum
            })
        });
    }
    group.finish();
}

fn bench(c: &mut Criterion) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/rooms/synthetic");
    let text = std::fs::read_to_string(dir.join("room.toml")).expect("room file");
    let file = RoomFile::from_toml(&text).expect("room file parses");
    let room = Room::from_file(&file).expect("room");
    let probe = ibl_io::read_image(&dir.join(&file.probe.file))
        .expect("probe")
        .image;
    let analysis =
        analyse_room(&room, &probe, &AnalysisSettings::default(), &|_, _, _| ()).expect("analysis");
    let important = important_patches(&room, &analysis.estimate, 32);
    let radiance =
        RoomRadiance::new(&room, &analysis.depth, &probe, &analysis.estimate).expect("radiance");
    let (low, high) = room.bounds().expect("bounds");
    let mut rng = rand_pcg::Pcg32::seed_from_u64(1);
    let positions: Vec<Vec3> = (0..1000)
        .map(|_| low + (high - low) * Vec3::new(rng.random(), rng.random(), rng.random()))
        .collect();
    bench_basis::<IrradianceL2>(c, "SH L2", &radiance, &important, &positions);
    bench_basis::<AmbientCube>(c, "ambient cube", &radiance, &important, &positions);
}

criterion_group!(benches, bench);
criterion_main!(benches);

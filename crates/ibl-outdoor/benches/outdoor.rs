//! The per-frame cost of the outdoor loop (issue 18's speed target: estimation, relighting a
//! 512 x 256 map and refreshing the volume at 30 frames per second or more on 2 cores; the paper
//! ran at 10 fps on an Athlon XP 1.53 GHz with a GeForce3).
//!
//! Setup (not timed): the synthetic courtyard, a 512 x 256 probe rendered at 4 spp (its noise
//! does not matter for speed), 500 sample sites in 160 x 120 frames, a volume of 8 x 2 x 8 key
//! points with 32 x 16 directions each. Timed: `process` of one frame (sun position, sample
//! read-out, robust fit, relit map, volume refresh) with the frame times 1/30 s apart, so the sun
//! moves as in a video and the shadow and sky caches are re-made when it passes their thresholds;
//! and its parts on their own.
//!
//! Run: `cargo bench -p ibl-outdoor --bench outdoor`.

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Mat3;
use ibl_core::{Image, Rgb};
use ibl_outdoor::courtyard::Courtyard;
use ibl_outdoor::estimate::{EstimatorOptions, estimate};
use ibl_outdoor::synthetic::SyntheticDay;
use ibl_outdoor::tracking::SkyTracker;
use ibl_outdoor::{
    CameraSetup, CaptureSource, KeyPointRelighter, MapGather, MapSettings, OutdoorSystem,
    ProbeCapture, Relighter, SampleSettings, SampleSites, SkyModel, SystemSettings, VolumeRefresh,
    VolumeSettings,
};
use ibl_sh::VolumeGrid;

struct Setup {
    day: SyntheticDay,
    yard: Courtyard,
    probe: Image<Rgb>,
    frame: Image<Rgb>,
    grid: VolumeGrid,
}

fn setup() -> Setup {
    let day = SyntheticDay {
        probe_width: 512,
        probe_spp: 4,
        ..SyntheticDay::standard()
    };
    let yard = Courtyard::new(day.frame_size);
    let truth = day.frame_truth(0).expect("truth");
    let probe = day.render_probe(&yard, &truth, 1).expect("probe");
    let frame = day
        .render_frame(&yard, &day.frame_truth(6).expect("truth"), 2)
        .expect("frame");
    let grid = VolumeGrid::covering(
        yard.volume_box.0.as_dvec3(),
        yard.volume_box.1.as_dvec3(),
        3.0,
    )
    .expect("grid");
    Setup {
        day,
        yard,
        probe,
        frame,
        grid,
    }
}

fn system(s: &Setup, refresh: VolumeRefresh) -> OutdoorSystem {
    let frame_size = (s.day.frame_size.0 as usize, s.day.frame_size.1 as usize);
    let settings = SystemSettings {
        maps: MapSettings {
            transfer_rays: 64,
            ..MapSettings::default()
        },
        samples: SampleSettings {
            transfer_rays: 256,
            ..SampleSettings::default()
        },
        volume: Some(VolumeSettings {
            grid: s.grid,
            directions_width: 32,
            refresh,
        }),
        ..SystemSettings::default()
    };
    OutdoorSystem::new(
        s.yard.layer.clone(),
        s.day.location,
        &ProbeCapture {
            radiance: s.probe.clone(),
            position: s.yard.probe_position,
            world_from_probe: Mat3::IDENTITY,
            time: s.day.frame_time(0),
            lighting: CaptureSource::Measured,
        },
        &CameraSetup {
            camera: s.yard.camera,
            frame_size,
            mask: s.yard.diffuse_mask(frame_size),
        },
        settings,
    )
    .expect("system")
}

fn bench(c: &mut Criterion) {
    let s = setup();
    let mut group = c.benchmark_group("outdoor");
    group.sample_size(30);
    for (name, refresh) in [
        ("frame_from_map", VolumeRefresh::FromMap),
        ("frame_key_points", VolumeRefresh::KeyPoints),
    ] {
        let mut sys = system(&s, refresh);
        let start = s.day.frame_time(6);
        let mut k = 0u64;
        group.bench_function(name, |b| {
            b.iter(|| {
                k += 1;
                sys.process(start.plus_seconds(k as f64 / 30.0), &s.frame)
                    .expect("frame")
            })
        });
    }
    // The parts on their own, caches warm.
    let sys = system(&s, VolumeRefresh::FromMap);
    let sun = s.day.sun_direction(s.day.frame_time(6)).expect("sun");
    let mut sky = SkyTracker::new(SkyModel::Preetham { turbidity: 3.0 }, 4, 0.0175);
    sky.update(sun).expect("sky");
    let mut relighter = Relighter::new(sys.maps(), 0.0044);
    relighter
        .update(sys.layer(), sys.maps(), &sky, sun)
        .expect("relighter");
    let mut sites: SampleSites = sys.sites().clone();
    sites.update(sys.layer(), &sky, sun).expect("sites");
    let options = EstimatorOptions::default();
    group.bench_function("estimate_500_samples", |b| {
        b.iter(|| {
            let obs = sites
                .observations(&s.frame, sun, &relighter)
                .expect("observations");
            estimate(&obs, &options).expect("estimate")
        })
    });
    // What a frame that re-casts the shadows adds: the probe's footprint shadow rays and the
    // responses with their interreflection bounces (once per 0.25 degrees of sun, a minute).
    let mut moved = 0u32;
    group.bench_function("relighter_recast", |b| {
        b.iter(|| {
            moved += 1;
            let turned = glam::Quat::from_rotation_y((0.3 * moved as f32).to_radians()) * sun;
            let mut fresh = Relighter::new(sys.maps(), 0.0044);
            fresh
                .update(sys.layer(), sys.maps(), &sky, turned)
                .expect("relighter")
        })
    });
    let (pa, pd) = (Rgb::new(0.15, 0.2, 0.3), Rgb::new(1.5, 1.4, 1.2));
    let mut relit = Image::filled(0, 0, Rgb::ZERO);
    group.bench_function("relight_512x256", |b| {
        b.iter(|| {
            relighter
                .relight_into(sys.maps(), sun, pa, pd, &mut relit)
                .expect("relight")
        })
    });
    let mut gather = MapGather::new(sys.layer(), sys.maps(), s.grid, 32).expect("gather");
    let mut volume = gather.empty_volume();
    group.bench_function("volume_from_map", |b| {
        b.iter(|| {
            gather
                .refresh(&relit, &sky, pa, &mut volume)
                .expect("refresh")
        })
    });
    let mut keys = KeyPointRelighter::new();
    keys.update(&mut gather, sys.maps(), &relighter, &sky, sun)
        .expect("keys");
    group.bench_function("volume_key_points", |b| {
        b.iter(|| keys.refresh(pa, pd, &mut volume).expect("refresh"))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

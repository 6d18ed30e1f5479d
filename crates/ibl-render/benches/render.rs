//! Renderer benchmarks on the bundled bunny scenes (`assets/scenes/`):
//! - `rays/bunny-reference`: path-traced reference of the outdoor bunny view, 160 x 120, 4 spp,
//!   4 bounces; throughput in rays (closest-hit and shadow queries) per second;
//! - `differential/1280x640-64-lights`: the whole panorama at 1280 x 640 with 64 median-cut lights
//!   and hard shadows, 1 spp, direct light (both passes of differential rendering), the issue's
//!   "under 2 s on 2 cores" target.
//!
//! Run: `cargo bench -p ibl-render --bench render`.

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use ibl_extract::{ExtractOptions, extract};
use ibl_light::Method;
use ibl_render::lighting::Lighting;
use ibl_render::{RenderSettings, SamplerKind, render};
use ibl_scene::description::CompositeRule;
use ibl_scene::{Camera, Scene, ShadowKind};

fn scene(name: &str) -> Scene {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../assets/scenes/{name}.toml"));
    ibl_io::read_scene(&path).expect("bundled scene").scene
}

fn bench_rays(c: &mut Criterion) {
    let scene = scene("bunny-sky");
    let lighting = Lighting::reference(&scene).expect("lighting");
    let settings = RenderSettings {
        composite: CompositeRule::Difference,
        width: Some(160),
        spp: 4,
        bounces: 4,
        seed: 1,
        sampler: SamplerKind::Sobol,
        adaptive: None,
        adaptive_sampling: false,
    };
    let rays = render(&scene, &lighting, &settings, &|_, _| {})
        .expect("render")
        .stats
        .rays;
    let mut group = c.benchmark_group("rays");
    group.sample_size(10);
    group.throughput(Throughput::Elements(rays));
    group.bench_function("bunny-reference", |b| {
        b.iter(|| black_box(render(&scene, &lighting, &settings, &|_, _| {}).expect("render")))
    });
    group.finish();
}

fn bench_differential(c: &mut Criterion) {
    let mut scene = scene("bunny-sky");
    scene.camera = Camera::Panorama {
        position: scene.probe.position,
        world_from_probe: scene.probe.world_from_probe,
    };
    let lights = extract(
        &scene.probe.radiance,
        Method::MedianCut,
        64,
        &ExtractOptions::default(),
    )
    .expect("lights");
    let lighting = Lighting::lights(&scene, &lights, ShadowKind::Hard).expect("lighting");
    let settings = RenderSettings {
        composite: CompositeRule::Difference,
        width: Some(1280),
        spp: 1,
        bounces: 1,
        seed: 1,
        sampler: SamplerKind::Sobol,
        adaptive: None,
        adaptive_sampling: false,
    };
    let mut group = c.benchmark_group("differential");
    group.sample_size(10);
    group.bench_function("1280x640-64-lights", |b| {
        b.iter(|| black_box(render(&scene, &lighting, &settings, &|_, _| {}).expect("render")))
    });
    group.finish();
}

criterion_group!(benches, bench_rays, bench_differential);
criterion_main!(benches);

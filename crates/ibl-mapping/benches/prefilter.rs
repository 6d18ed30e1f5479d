//! Prefiltering: a 256-pixel-face cube with its full GGX mip chain (the glTF-IBL-Sampler's
//! 8 levels, and Filament's 5), 256 samples per texel, from a synthetic 1024 x 512 sky with a
//! sun; and the 128 x 128 DFG table. The probe is built before timing; the timings include
//! resampling the probe to the cube and building the pyramid.
//!
//! Run: `cargo bench -p ibl-mapping --bench prefilter -- --warm-up-time 1 --measurement-time 10`.

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use ibl_core::SyntheticSky;
use ibl_mapping::{
    DfgLayout, DfgOptions, EngineTarget, Mapping, PrefilterOptions, SpecularOptions, prefilter,
};

fn bench(c: &mut Criterion) {
    let sky = SyntheticSky::default().render(1024, 512);
    let mut g = c.benchmark_group("prefilter");
    g.sample_size(10);
    for target in [EngineTarget::Khronos, EngineTarget::Filament] {
        let options = PrefilterOptions {
            specular: Some(SpecularOptions {
                face_size: 256,
                target,
                samples: 256,
                latlong_width: None,
            }),
            ..Default::default()
        };
        g.bench_function(format!("cube_256_full_chain_{}", target.name()), |b| {
            b.iter(|| {
                prefilter(black_box(&sky), Mapping::LatLong, &options, &|_, _| {})
                    .expect("prefilters")
            })
        });
    }
    let dfg = PrefilterOptions {
        dfg: Some(DfgOptions {
            size: 128,
            samples: 1024,
            layout: DfgLayout::ScaleBias,
        }),
        ..Default::default()
    };
    g.bench_function("dfg_128_1024_samples", |b| {
        b.iter(|| {
            prefilter(black_box(&sky), Mapping::LatLong, &dfg, &|_, _| {}).expect("prefilters")
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

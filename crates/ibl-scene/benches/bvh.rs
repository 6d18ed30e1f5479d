//! BVH build and query speed on a procedural 100000-triangle bumpy sphere (a 200 x 250 lat-long
//! grid, radius `1 + 0.08 sin(7 theta) sin(9 phi)`), built before the query timings:
//! - build (parallel over subtrees);
//! - closest hit of 100000 random rays (origins uniform in `[-2, 2]^3`, aimed at uniform points
//!   of `[-1, 1]^3`: mostly hits);
//! - occlusion of the same rays (`t_max = inf`);
//! - shadow rays: 100000 rays leaving surface points (`t_min = 1e-4`) in uniform directions, about
//!   half of them blocked by the bumps or the far side.
//!
//! Queries run on one thread; throughput is in rays per second.
//!
//! Run: `cargo bench -p ibl-scene --bench bvh -- --warm-up-time 1 --measurement-time 3`.

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::f32::consts::PI;
use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use ibl_scene::{Bvh, Ray};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

const RAYS: usize = 100_000;

fn bumpy_sphere(rows: usize, columns: usize) -> Vec<[Vec3; 3]> {
    let point = |i: usize, j: usize| {
        let theta = PI * i as f32 / rows as f32;
        let phi = 2.0 * PI * j as f32 / columns as f32;
        let r = 1.0 + 0.08 * (7.0 * theta).sin() * (9.0 * phi).sin();
        r * Vec3::new(
            theta.sin() * phi.sin(),
            theta.cos(),
            -theta.sin() * phi.cos(),
        )
    };
    let mut tris = Vec::with_capacity(2 * rows * columns);
    for i in 0..rows {
        for j in 0..columns {
            let (a, b) = (point(i, j), point(i, j + 1));
            let (c, d) = (point(i + 1, j + 1), point(i + 1, j));
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    tris
}

fn unit(rng: &mut Pcg64) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let l = v.length();
        if l > 1e-3 && l <= 1.0 {
            return v / l;
        }
    }
}

fn bench(c: &mut Criterion) {
    let tris = bumpy_sphere(200, 250);
    assert_eq!(tris.len(), 100_000);
    let bvh = Bvh::new(&tris);
    let mut rng = Pcg64::seed_from_u64(1);
    let rays: Vec<Ray> = (0..RAYS)
        .map(|_| {
            let o = Vec3::new(
                rng.random_range(-2.0..2.0),
                rng.random_range(-2.0..2.0),
                rng.random_range(-2.0..2.0),
            );
            let target = Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            Ray::new(o, (target - o).normalize())
        })
        .collect();
    let shadow: Vec<Ray> = rays
        .iter()
        .filter_map(|r| bvh.closest_hit(r, 0.0, f32::INFINITY).map(|h| r.at(h.t)))
        .cycle()
        .take(RAYS)
        .map(|p| Ray::new(p, unit(&mut rng)))
        .collect();
    let hits = rays
        .iter()
        .filter(|r| bvh.closest_hit(r, 0.0, f32::INFINITY).is_some())
        .count();
    let blocked = shadow
        .iter()
        .filter(|r| bvh.occluded(r, 1e-4, f32::INFINITY))
        .count();
    println!(
        "bumpy sphere: {} triangles, {} nodes, depth {}; {hits} of {RAYS} random rays hit, \
         {blocked} of {RAYS} shadow rays blocked",
        bvh.triangle_count(),
        bvh.node_count(),
        bvh.depth()
    );

    let mut g = c.benchmark_group("bvh_build");
    g.sample_size(10);
    g.throughput(Throughput::Elements(tris.len() as u64));
    g.bench_function("bumpy_sphere_100k", |b| {
        b.iter(|| Bvh::new(black_box(&tris)))
    });
    g.finish();

    let mut g = c.benchmark_group("bvh_query_100k_rays");
    g.sample_size(10);
    g.throughput(Throughput::Elements(RAYS as u64));
    g.bench_function("closest_hit", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| bvh.closest_hit(black_box(r), 0.0, f32::INFINITY).is_some())
                .count()
        })
    });
    g.bench_function("occluded", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| bvh.occluded(black_box(r), 0.0, f32::INFINITY))
                .count()
        })
    });
    g.bench_function("occluded_shadow_rays", |b| {
        b.iter(|| {
            shadow
                .iter()
                .filter(|r| bvh.occluded(black_box(r), 1e-4, f32::INFINITY))
                .count()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! The BVH against brute force and on the cases that break ray tracers: back faces, parallel rays,
//! rays leaving a surface, empty and degenerate inputs, and a closed cube that must not leak.

use glam::{Affine3A, EulerRot, Quat, Vec3};
use ibl_scene::{Bvh, Hit, Ray};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn random_unit(rng: &mut Pcg64) -> Vec3 {
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

/// Random triangles with corners in a unit cube placed in `[0, 11]^3` (edges up to sqrt 3).
fn soup(n: usize, rng: &mut Pcg64) -> Vec<[Vec3; 3]> {
    (0..n)
        .map(|_| {
            let c = Vec3::new(
                rng.random_range(0.0..10.0),
                rng.random_range(0.0..10.0),
                rng.random_range(0.0..10.0),
            );
            let mut corner = || c + Vec3::new(rng.random(), rng.random(), rng.random());
            [corner(), corner(), corner()]
        })
        .collect()
}

/// Brute force: every triangle on its own (a one-triangle hierarchy is a single leaf, so this is
/// the bare triangle test), closest `t`, ties to the smallest index. Returns the index with the hit
/// (whose `triangle` is 0, the index within its own one-triangle slice).
fn brute_closest(singles: &[Bvh], ray: &Ray, t_min: f32, t_max: f32) -> Option<(usize, Hit)> {
    let mut best: Option<(usize, Hit)> = None;
    for (i, single) in singles.iter().enumerate() {
        if let Some(h) = single.closest_hit(ray, t_min, t_max)
            && best.is_none_or(|(_, b)| h.t < b.t)
        {
            best = Some((i, h));
        }
    }
    best
}

/// Independent f64 ray-plane distance of a triangle.
fn plane_t(tri: [Vec3; 3], ray: &Ray) -> f64 {
    let [a, b, c] = tri.map(|p| p.as_dvec3());
    let n = (b - a).cross(c - a);
    let o = ray.origin.as_dvec3();
    (a - o).dot(n) / ray.direction.as_dvec3().dot(n)
}

#[test]
fn random_soup_matches_brute_force() {
    let mut rng = Pcg64::seed_from_u64(2024);
    let tris = soup(2000, &mut rng);
    let bvh = Bvh::new(&tris);
    assert_eq!(bvh.triangle_count(), 2000);
    let singles: Vec<Bvh> = tris
        .iter()
        .map(|t| Bvh::new(std::slice::from_ref(t)))
        .collect();
    let (mut hits, mut occluded) = (0, 0);
    for r in 0..10_000 {
        let origin = Vec3::new(
            rng.random_range(-2.0..13.0),
            rng.random_range(-2.0..13.0),
            rng.random_range(-2.0..13.0),
        );
        let ray = Ray::new(origin, random_unit(&mut rng));
        let t_min = if r % 2 == 0 {
            0.0
        } else {
            rng.random_range(0.0..3.0)
        };
        let t_max = if r % 3 == 0 {
            f32::INFINITY
        } else {
            rng.random_range(3.0..15.0)
        };
        let fast = bvh.closest_hit(&ray, t_min, t_max);
        let brute = brute_closest(&singles, &ray, t_min, t_max);
        match (fast, brute) {
            (None, None) => {}
            (Some(f), Some((i, b))) => {
                hits += 1;
                assert_eq!(f.triangle as usize, i, "ray {r}: closest triangle");
                assert_eq!(f.t, b.t, "ray {r}: same triangle test, same t");
                assert_eq!((f.u, f.v), (b.u, b.v), "ray {r}: barycentrics");
                let tri = tris[i];
                let exact = plane_t(tri, &ray);
                // The f32 Moller-Trumbore t against the plane intersection in f64: f32 rounding of
                // a few products and one division, a few ulps (1e-6 relative); 1e-5, floored for t
                // near 0.
                assert!(
                    (f64::from(f.t) - exact).abs() <= 1e-5 * exact.abs().max(1e-3),
                    "ray {r}: t {} against f64 {exact}",
                    f.t
                );
                let p = tri[0] + f.u * (tri[1] - tri[0]) + f.v * (tri[2] - tri[0]);
                // The hit point from barycentrics against the ray's point at t: f32 rounding of
                // coordinates of order 10, 1e-5; 1e-4.
                assert!((p - ray.at(f.t)).length() < 1e-4, "ray {r}: barycentrics");
                assert!(f.u >= 0.0 && f.v >= 0.0 && f.u + f.v <= 1.0 + 1e-6);
            }
            (f, b) => panic!("ray {r}: bvh {f:?}, brute force {b:?}"),
        }
        let any = bvh.occluded(&ray, t_min, t_max);
        let brute_any = singles.iter().any(|s| s.occluded(&ray, t_min, t_max));
        assert_eq!(any, brute_any, "ray {r}: occluded");
        assert_eq!(
            any,
            fast.is_some(),
            "ray {r}: occluded iff a closest hit exists"
        );
        occluded += usize::from(any);
    }
    // Both outcomes are well represented.
    assert!(hits > 1000 && hits < 9000, "{hits} hits of 10000");
    assert_eq!(hits, occluded);
}

#[test]
fn closest_hit_ties_go_to_the_smallest_index_whatever_the_order() {
    // Two copies of one triangle hit at exactly t = 5, at random places in shuffled soups: the
    // answer is always the earlier copy, wherever the tree puts them.
    let mut rng = Pcg64::seed_from_u64(5);
    let copy = [
        Vec3::new(-1.0, -1.0, -5.0),
        Vec3::new(3.0, -1.0, -5.0),
        Vec3::new(-1.0, 3.0, -5.0),
    ];
    for _ in 0..20 {
        let mut tris = soup(300, &mut rng);
        let first = rng.random_range(0..=tris.len());
        tris.insert(first, copy);
        let second = rng.random_range(0..=tris.len());
        tris.insert(second, copy);
        let earlier = if second <= first { second } else { first };
        let bvh = Bvh::new(&tris);
        let ray = Ray::new(Vec3::ZERO, Vec3::NEG_Z);
        let hit = bvh.closest_hit(&ray, 0.0, f32::INFINITY).unwrap();
        assert_eq!(hit.triangle as usize, earlier);
        assert_eq!(hit.t, 5.0);
    }
}

#[test]
fn back_faces_are_hit() {
    // Counter-clockwise seen from +Z: the front faces +Z.
    let tri = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 0.0),
    ];
    let bvh = Bvh::new(&[tri]);
    for (z, d) in [(3.0, Vec3::NEG_Z), (-3.0, Vec3::Z)] {
        let ray = Ray::new(Vec3::new(0.5, 0.25, z), d);
        let hit = bvh.closest_hit(&ray, 0.0, f32::INFINITY).unwrap();
        // t = 3 exactly in f32 for an axis-aligned ray and plane; 1e-6 allows one rounding of the
        // division.
        assert!((hit.t - 3.0).abs() < 1e-6);
        // Point (0.5, 0.25) = 0.25 * corner 1 + 0.125 * corner 2.
        assert!(
            (hit.u - 0.25).abs() < 1e-6 && (hit.v - 0.125).abs() < 1e-6,
            "{hit:?}"
        );
        assert!(bvh.occluded(&ray, 0.0, f32::INFINITY));
        assert!(!bvh.occluded(&ray, 0.0, 3.0), "t_max is exclusive");
    }
}

#[test]
fn rays_parallel_to_a_triangle_miss_it() {
    let tri = [
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, -1.0),
        Vec3::new(0.0, 0.0, 1.0),
    ];
    let bvh = Bvh::new(&[tri]);
    for origin in [
        Vec3::new(-5.0, 0.0, 0.0),
        Vec3::new(-5.0, 0.1, 0.0),
        Vec3::new(-5.0, -1e-3, 0.2),
    ] {
        let ray = Ray::new(origin, Vec3::X);
        assert_eq!(bvh.closest_hit(&ray, 0.0, f32::INFINITY), None, "{origin}");
        assert!(!bvh.occluded(&ray, 0.0, f32::INFINITY));
    }
    // Tilted plane, ray offset from it along its normal.
    let n = Vec3::new(0.3, 0.8, -0.2).normalize();
    let e1 = n.any_orthonormal_vector();
    let e2 = n.cross(e1);
    let tilted = [Vec3::ZERO, e1 * 2.0, e2 * 2.0];
    let bvh = Bvh::new(&[tilted]);
    let ray = Ray::new(n * 0.01 - (e1 + e2) * 3.0, (e1 + e2).normalize());
    assert_eq!(bvh.closest_hit(&ray, 0.0, f32::INFINITY), None);
}

#[test]
fn rays_leaving_a_surface_skip_it_with_t_min() {
    // Two parallel floors 1 apart; a ray leaves a point of the lower one.
    let floor = |y: f32| {
        [
            [
                Vec3::new(-5.0, y, -5.0),
                Vec3::new(5.0, y, -5.0),
                Vec3::new(5.0, y, 5.0),
            ],
            [
                Vec3::new(-5.0, y, -5.0),
                Vec3::new(5.0, y, 5.0),
                Vec3::new(-5.0, y, 5.0),
            ],
        ]
    };
    let tris: Vec<[Vec3; 3]> = floor(0.0).into_iter().chain(floor(1.0)).collect();
    let bvh = Bvh::new(&tris);
    let mut rng = Pcg64::seed_from_u64(9);
    for _ in 0..1000 {
        let p = Vec3::new(
            rng.random_range(-3.0..3.0),
            0.0,
            rng.random_range(-3.0..3.0),
        );
        let mut d = random_unit(&mut rng);
        d.y = d.y.abs().max(0.2);
        let d = d.normalize();
        let ray = Ray::new(p, d);
        let hit = bvh.closest_hit(&ray, 1e-4, f32::INFINITY);
        let expected_t = 1.0 / d.y;
        if (p + d * expected_t).abs().max_element() < 5.0 {
            let h = hit.expect("the upper floor is hit");
            assert!(h.triangle >= 2, "never the start surface: {h:?}");
            // Unit floor spacing: t = 1 / d.y, f32 rounding of the intersection (1e-7 relative);
            // 1e-5.
            assert!((h.t - expected_t).abs() <= 1e-5 * expected_t);
        } else {
            assert_eq!(hit, None, "past the upper floor's edge the ray escapes");
        }
        // Going down through the lower floor from just above it: hit at ~0 is skipped by t_min.
        let down = Ray::new(p + Vec3::Y * 1e-6, -d);
        assert!(!bvh.occluded(&down, 1e-4, f32::INFINITY));
        assert!(bvh.occluded(&down, 0.0, f32::INFINITY));
    }
}

#[test]
fn empty_bvh_hits_nothing() {
    let bvh = Bvh::new(&[]);
    let ray = Ray::new(Vec3::ZERO, Vec3::NEG_Z);
    assert_eq!(bvh.closest_hit(&ray, 0.0, f32::INFINITY), None);
    assert!(!bvh.occluded(&ray, f32::NEG_INFINITY, f32::INFINITY));
    assert_eq!(bvh.bounds(), None);
    assert_eq!(
        (bvh.triangle_count(), bvh.node_count(), bvh.depth()),
        (0, 0, 0)
    );
}

#[test]
fn single_triangle() {
    let tri = [
        Vec3::new(1.0, 0.0, -2.0),
        Vec3::new(0.0, 1.0, -2.0),
        Vec3::new(0.0, 0.0, -3.0),
    ];
    let bvh = Bvh::new(&[tri]);
    assert_eq!(
        (bvh.triangle_count(), bvh.node_count(), bvh.depth()),
        (1, 1, 1)
    );
    assert_eq!(
        bvh.bounds(),
        Some((Vec3::new(0.0, 0.0, -3.0), Vec3::new(1.0, 1.0, -2.0)))
    );
    // The plane is x + y - z = 3; the ray along -Z through (0.25, 0.25) meets it at z = -2.5,
    // barycentrics: 0.25 of corner 0, 0.25 of corner 1, 0.5 of corner 2.
    let ray = Ray::new(Vec3::new(0.25, 0.25, 0.0), Vec3::NEG_Z);
    let hit = bvh.closest_hit(&ray, 0.0, f32::INFINITY).unwrap();
    assert_eq!(hit.triangle, 0);
    assert!((hit.t - 2.5).abs() < 1e-6);
    // Barycentrics 0.25 and 0.5 of a plane through exact corners: f32 rounding (6e-8); 1e-6.
    assert!(
        (hit.u - 0.25).abs() < 1e-6 && (hit.v - 0.5).abs() < 1e-6,
        "{hit:?}"
    );
    assert_eq!(bvh.closest_hit(&ray, 0.0, 2.5), None);
    assert_eq!(bvh.closest_hit(&ray, 2.5, 10.0), None);
    let miss = Ray::new(Vec3::new(0.75, 0.5, 0.0), Vec3::NEG_Z);
    assert_eq!(bvh.closest_hit(&miss, 0.0, f32::INFINITY), None);
    assert!(!bvh.occluded(&miss, 0.0, f32::INFINITY));
    // A NaN direction hits nothing and does not panic.
    let nan = Ray::new(Vec3::ZERO, Vec3::new(f32::NAN, 0.0, -1.0));
    assert_eq!(bvh.closest_hit(&nan, 0.0, f32::INFINITY), None);
}

#[test]
fn many_identical_triangles_do_not_overflow_the_stack() {
    let tri = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let tris = vec![tri; 10_000];
    let bvh = Bvh::new(&tris);
    assert_eq!(bvh.triangle_count(), 10_000);
    // Median splits halve the count: ceil(log2(10000 / 4)) + 1 = 13 levels.
    assert!(bvh.depth() <= 14, "depth {}", bvh.depth());
    let mut rng = Pcg64::seed_from_u64(1);
    for _ in 0..200 {
        let origin = Vec3::new(
            rng.random_range(-0.3..0.3),
            rng.random_range(-0.3..0.3),
            2.0,
        );
        let ray = Ray::new(origin, Vec3::NEG_Z);
        let hit = bvh.closest_hit(&ray, 0.0, f32::INFINITY).unwrap();
        assert_eq!(hit.triangle, 0, "ties go to the smallest index");
        assert_eq!(hit.t, 2.0);
        assert!(bvh.occluded(&ray, 0.0, f32::INFINITY));
        let side = Ray::new(Vec3::new(-3.0, origin.y, 0.0), Vec3::X);
        assert!(!bvh.occluded(&side, 0.0, f32::INFINITY), "in-plane ray");
    }
}

/// The 12 triangles of the cube `[-1, 1]^3`, each face split along one diagonal.
fn cube() -> Vec<[Vec3; 3]> {
    let mut tris = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let corner = |a: f32, b: f32| {
                let mut p = [0.0; 3];
                p[axis] = sign;
                p[(axis + 1) % 3] = a;
                p[(axis + 2) % 3] = b;
                Vec3::from_array(p)
            };
            let (p00, p10, p11, p01) = (
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
            );
            tris.push([p00, p10, p11]);
            tris.push([p00, p11, p01]);
        }
    }
    tris
}

#[test]
fn closed_cube_is_watertight_from_inside() {
    // The axis-aligned cube (flat boxes, rays exactly along its edges and diagonals) and the
    // same cube turned and moved (shared edges in general position).
    let turned = Affine3A::from_rotation_translation(
        Quat::from_euler(EulerRot::YXZ, 0.7, -0.4, 1.9),
        Vec3::new(3.0, -2.0, 5.0),
    );
    let mut rng = Pcg64::seed_from_u64(12);
    for world_from_cube in [Affine3A::IDENTITY, turned] {
        let place = |p: Vec3| world_from_cube.transform_point3(p);
        let cube_from_world = world_from_cube.inverse();
        // Shared corners map to bit-identical floats: the same input gives the same output.
        let tris: Vec<[Vec3; 3]> = cube().iter().map(|t| t.map(place)).collect();
        let bvh = Bvh::new(&tris);
        let corners: Vec<Vec3> = (0..8)
            .map(|i| {
                place(Vec3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                ))
            })
            .collect();
        // Targets on every edge (cube edges and the face diagonals the triangles share).
        let mut targets = corners.clone();
        for t in &tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                for s in 1..32 {
                    targets.push(a.lerp(b, s as f32 / 32.0));
                }
                for _ in 0..32 {
                    targets.push(a.lerp(b, rng.random()));
                }
            }
        }
        let mut origins: Vec<Vec3> = [
            Vec3::ZERO,
            Vec3::splat(0.5),
            Vec3::new(-0.999, 0.999, 0.0),
            Vec3::splat(1e-7),
        ]
        .into_iter()
        .map(place)
        .collect();
        origins.extend((0..60).map(|_| {
            place(Vec3::new(
                rng.random_range(-0.99..0.99),
                rng.random_range(-0.99..0.99),
                rng.random_range(-0.99..0.99),
            ))
        }));
        let mut rays = 0;
        let mut check = |ray: Ray| {
            let hit = bvh.closest_hit(&ray, 0.0, f32::INFINITY);
            let hit = hit.unwrap_or_else(|| panic!("escaped: {ray:?}"));
            let p = cube_from_world.transform_point3(ray.at(hit.t));
            // Hits of a transformed unit cube lie on its faces: in the cube frame |p|_max = 1 to
            // f32 rounding of the transform and t (1e-6); 1e-5.
            assert!(
                (p.abs().max_element() - 1.0).abs() < 1e-5,
                "{ray:?} hit {p} (cube frame)"
            );
            assert!(
                bvh.occluded(&ray, 0.0, f32::INFINITY),
                "escaped any-hit: {ray:?}"
            );
            rays += 1;
        };
        for &o in &origins {
            for &t in &targets {
                check(Ray::new(o, (t - o).normalize()));
            }
            for _ in 0..2000 {
                check(Ray::new(o, random_unit(&mut rng)));
            }
            let axes = [
                Vec3::X,
                Vec3::NEG_X,
                Vec3::Y,
                Vec3::NEG_Y,
                Vec3::Z,
                Vec3::NEG_Z,
            ];
            for d in axes {
                check(Ray::new(o, world_from_cube.transform_vector3(d)));
            }
        }
        assert!(rays > 250_000, "{rays}");
        // From the centre towards the corners: the hit is the corner, at distance sqrt 3.
        let centre = place(Vec3::ZERO);
        for &c in &corners {
            let ray = Ray::new(centre, (c - centre).normalize());
            let hit = bvh.closest_hit(&ray, 0.0, f32::INFINITY).unwrap();
            // From the centre to a corner: sqrt 3 in f32, one rounding of the transform and t (1e-7
            // relative); 1e-5.
            assert!((hit.t - 3.0f32.sqrt()).abs() < 1e-5, "{hit:?}");
        }
    }
}

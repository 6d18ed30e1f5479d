//! Goniometric point lights in the renderer (Grosch 2005 section 4.2): on a ground plane under a
//! black sky, a downlight's direct light is EQ5 times the diffuse BRDF at every pixel, the
//! sphere between the light and the ground casts its shadow, and the lights mode gives the same
//! direct light as the reference.

#![allow(clippy::unwrap_used)] // tests may panic

use glam::{Mat3, Vec3};
use ibl_core::{Image, Rgb};
use ibl_light::{CandelaTable, GoniometricLight};
use ibl_render::lighting::LightList;
use ibl_render::sampler::SampleStream;
use ibl_render::{Illumination, Lighting, RenderSettings, SamplerKind, render};
use ibl_scene::description::{CompositeRule, SceneDescription};
use ibl_scene::{Scene, ShadowKind};

const W: u32 = 48;
const H: u32 = 36;
const ALBEDO: f32 = 0.5;
const LIGHT: Vec3 = Vec3::new(0.0, 2.0, 0.0);
const SPHERE: Vec3 = Vec3::new(0.0, 1.0, 0.0);
const RADIUS: f32 = 0.3;

/// The ground, a sphere on the light's axis, a camera looking down past the light; black probe.
fn scene() -> Scene {
    let toml = format!(
        r#"
version = 1
[probe]
file = "black.exr"
[camera]
position = [3.0, 3.5, 3.0]
look_at = [0.0, 0.0, 0.0]
vertical_fov_deg = 50.0
image_size_px = [{W}, {H}]
[[local]]
name = "ground"
shape = "plane"
size = [40.0, 40.0]
albedo = [{ALBEDO}, {ALBEDO}, {ALBEDO}]
[[object]]
shape = "sphere"
center = [{}, {}, {}]
radius = {RADIUS}
material = {{ kind = "diffuse", albedo = [0.7, 0.7, 0.7] }}
"#,
        SPHERE.x, SPHERE.y, SPHERE.z
    );
    let description = SceneDescription::from_toml(&toml).unwrap();
    let locals = vec![None; description.local.len()];
    let objects = vec![None; description.object.len()];
    Scene::assemble(
        &description,
        Image::filled(16, 8, Rgb::ZERO),
        None,
        locals,
        objects,
    )
    .unwrap()
}

/// 1000 cd straight down, falling as `cos gamma` to 0 at 90 degrees (a Lambertian downlight),
/// dark above; red-tinted per candela so the colour path is checked too.
fn downlight() -> GoniometricLight {
    let vertical: Vec<f32> = (0..=18).map(|k| k as f32 * 10.0).collect();
    let candela = vertical
        .iter()
        .map(|g| 1000.0 * g.to_radians().cos().max(0.0))
        .collect();
    GoniometricLight {
        position: LIGHT,
        world_from_light: Mat3::IDENTITY,
        table: CandelaTable::new(vertical, vec![0.0], candela).unwrap(),
        intensity_per_candela: Rgb::new(1.0, 0.8, 0.6),
    }
}

fn settings(composite: CompositeRule, bounces: u32) -> RenderSettings {
    RenderSettings {
        composite,
        width: Some(W),
        spp: 4,
        bounces,
        seed: 1,
        sampler: SamplerKind::Sobol,
        adaptive: None,
        adaptive_sampling: false,
    }
}

/// The ground point of sample `s` of pixel `(x, y)`: the renderer's own jitter (the first pair of
/// the pixel sample's stream), `None` when the ray misses the ground or meets the sphere first.
fn sample_point(scene: &Scene, x: u32, y: u32, s: u32) -> Option<Vec3> {
    let index = u64::from(y) * u64::from(W) + u64::from(x);
    let [jx, jy] = SampleStream::new(SamplerKind::Sobol, 1, index, s).next_2d();
    let ray = scene.camera.ray(x as f32 + jx, y as f32 + jy, W, H);
    let oc = ray.origin - SPHERE;
    let b = oc.dot(ray.direction);
    // The sphere is a mesh in the scene: a ray within 2 cm of it may meet it or not.
    if b * b - (oc.length_squared() - (RADIUS + 0.02).powi(2)) > 0.0 {
        return None;
    }
    let t = -ray.origin.y / ray.direction.y;
    (t > 0.0).then(|| ray.origin + ray.direction * t)
}

/// EQ5 with the table's `cos gamma` law: `I = 1000 cos gamma`, `E = I cos theta_e / d^2`.
fn expected_irradiance(p: Vec3) -> f32 {
    let to_light = LIGHT - p;
    let d2 = to_light.length_squared();
    let cos = to_light.y / d2.sqrt();
    1000.0 * cos * cos / d2
}

/// How far the segment from ground point `p` to the light passes from the sphere's centre.
fn miss_distance(p: Vec3) -> f32 {
    let (d, ab) = (LIGHT - p, SPHERE - p);
    let t = (ab.dot(d) / d.length_squared()).clamp(0.0, 1.0);
    (p + d * t - SPHERE).length()
}

#[test]
fn the_ground_gets_eq5_and_the_sphere_shadows_it() {
    let scene = scene();
    let lighting = Lighting::reference(&scene)
        .unwrap()
        .with_luminaires(vec![downlight()]);
    // One vertex: direct light only, so each sample's value is exact.
    let out = render(
        &scene,
        &lighting,
        &settings(CompositeRule::Difference, 1),
        &|_, _| (),
    )
    .unwrap();
    let image = &out.with_objects;
    let (mut lit, mut shadowed) = (0, 0);
    let mut worst = 0.0f32;
    for y in 0..H {
        for x in 0..W {
            // Each of the pixel's samples on the ground, lit or in the sphere's shadow; pixels
            // with a sample on the sphere or within 2 cm of the shadow's edge (the sphere is a
            // mesh) are left out.
            let Some(points) = (0..4)
                .map(|s| sample_point(&scene, x, y, s))
                .collect::<Option<Vec<Vec3>>>()
            else {
                continue;
            };
            if points
                .iter()
                .any(|&p| (miss_distance(p) - RADIUS).abs() < 0.02)
            {
                continue;
            }
            let e: f32 = points
                .iter()
                .map(|&p| {
                    if miss_distance(p) < RADIUS {
                        0.0
                    } else {
                        expected_irradiance(p)
                    }
                })
                .sum::<f32>()
                / 4.0;
            let got = *image.get(x as usize, y as usize);
            if points.iter().all(|&p| miss_distance(p) < RADIUS) {
                assert_eq!(got, Rgb::ZERO, "pixel ({x}, {y}) must be in shadow");
                shadowed += 1;
                continue;
            }
            let want = Rgb::new(1.0, 0.8, 0.6) * (ALBEDO / std::f32::consts::PI * e);
            for c in 0..3 {
                // The table is sampled every 10 degrees and interpolated linearly; `cos` between
                // samples departs from its chord by at most 1 - cos(5 deg) = 0.4 % (relative, up
                // to 60 degrees from the nadir, beyond which the pool is dim): 0.5 %, plus the
                // renderer's offset of the shadow ray's origin (sub-micrometre).
                let rel = (got[c] - want[c]).abs() / want[c].max(1e-3);
                worst = worst.max(rel);
                assert!(rel < 0.005, "pixel ({x}, {y}): {got:?} against {want:?}");
            }
            lit += 1;
        }
    }
    println!("lit {lit}, shadowed {shadowed}, worst relative error {worst:.5}");
    assert!(lit > 300 && shadowed > 20, "lit {lit}, shadowed {shadowed}");
}

#[test]
fn lights_mode_gives_the_reference_direct_light() {
    let scene = scene();
    let reference = Lighting::reference(&scene)
        .unwrap()
        .with_luminaires(vec![downlight()]);
    // The lights mode with no directional lights: the downlight alone.
    let mut lights = reference.clone();
    lights.illumination = Illumination::Lights(LightList {
        lights: Vec::new(),
        shadows: ShadowKind::Hard,
    });
    let a = render(
        &scene,
        &reference,
        &settings(CompositeRule::Difference, 1),
        &|_, _| (),
    )
    .unwrap();
    let b = render(
        &scene,
        &lights,
        &settings(CompositeRule::Difference, 1),
        &|_, _| (),
    )
    .unwrap();
    // Both shade the first vertex with the same shadow rays and no random numbers for the
    // point light; the black probe adds nothing. Equal to f32 summation order.
    for (p, q) in a.with_objects.pixels().iter().zip(b.with_objects.pixels()) {
        for c in 0..3 {
            assert!((p[c] - q[c]).abs() <= 1e-5 * p[c].max(1.0), "{p:?} {q:?}");
        }
    }
}

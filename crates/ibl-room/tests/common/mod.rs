//! The synthetic window room the manipulations are validated in against iblkit's own path
//! tracer (material changes, new lights), and the path-traced panoramas and error measure the
//! validations share.

// Each test binary that includes this module uses a part of it.
#![allow(dead_code)]

use glam::{Mat3, Vec3};
use ibl_core::{Image, Rgb};
use ibl_light::GoniometricLight;
use ibl_room::{GroupKind, Room};

/// A 4 x 2.5 x 3 m room lit by a uniform sky through a large window in its -z wall, the +x wall
/// a group of its own (the one that changes), a crate hiding its far side and part of the floor
/// from the probe. Albedos in `measured_reflectance`.
pub const WINDOW_ROOM: &str = r#"
    patch_area_m2 = 0.1
    group = [
      { name = "wall", measured_reflectance = [0.7, 0.68, 0.64] },
      { name = "accent", measured_reflectance = [0.7, 0.7, 0.7] },
      { name = "floor", measured_reflectance = [0.45, 0.35, 0.25] },
      { name = "ceiling", measured_reflectance = [0.85, 0.85, 0.83] },
      { name = "crate", measured_reflectance = [0.3, 0.5, 0.4] },
      { name = "window", kind = "light" },
    ]
    [[box]]
    min = [-2, 0, -1.5]
    max = [2, 2.5, 1.5]
    facing = "inward"
    group = "wall"
    face_groups = { "-y" = "floor", "+y" = "ceiling", "+x" = "accent" }
    openings = [{ face = "-z", min = [-1.8, 0.3], max = [1.8, 2.3], fill = "window" }]
    [[box]]
    min = [0.6, 0, -0.9]
    max = [1.4, 0.8, -0.1]
    group = "crate"
    omit = ["-y"]
"#;

/// Radiance of the sky outside the window (probe units).
pub const SKY: Rgb = Rgb::new(9.0, 9.5, 10.0);

/// Where the probe is, and a second viewpoint beside the crate that sees what the probe does not
/// (the crate's +x side, the floor behind it).
pub const PROBE: Vec3 = Vec3::new(-0.6, 1.2, 0.6);
pub const SIDE_VIEW: Vec3 = Vec3::new(1.75, 1.0, 0.4);

/// The window room placed for the probe and for the side view, and each group's albedo (its
/// `measured_reflectance`; 0 for the window).
pub fn window_room() -> (Room, Room, Vec<Rgb>) {
    let description: ibl_room::RoomDescription = toml::from_str(WINDOW_ROOM).expect("room parses");
    let room = Room::new(&description, PROBE, Mat3::IDENTITY).expect("room");
    let side = Room::new(&description, SIDE_VIEW, Mat3::IDENTITY).expect("room");
    let albedo = room
        .groups
        .iter()
        .map(|g| g.measured_reflectance.unwrap_or(Rgb::ZERO))
        .collect();
    (room, side, albedo)
}

/// Two path-traced panoramas of `room` with `albedo` per surface group and the point lights
/// `luminaires`, from `position` (seeds 1 and 2, `spp / 2` each; the window open to the sky).
pub fn render_halves(
    room: &Room,
    albedo: &[Rgb],
    luminaires: &[GoniometricLight],
    position: Vec3,
    width: u32,
    spp: u32,
) -> [Image<Rgb>; 2] {
    let empty = ibl_scene::GeometryLayer::empty();
    render_with_objects(room, albedo, luminaires, &empty, position, width, spp)
        .map(|out| out.with_objects)
}

/// As [`render_halves`], with `objects` as the virtual layer: each half's images with and
/// without them (differential rendering: a path that never meets an object is the same in both).
pub fn render_with_objects(
    room: &Room,
    albedo: &[Rgb],
    luminaires: &[GoniometricLight],
    objects: &ibl_scene::GeometryLayer,
    position: Vec3,
    width: u32,
    spp: u32,
) -> [ibl_render::RenderOutput; 2] {
    use ibl_render::{Lighting, RenderSettings, SamplerKind, render};
    use ibl_scene::description::{CompositeRule, LightingDescription, RenderDescription};
    use ibl_scene::{Background, Camera, GeometryLayer, Material, Probe, Scene};
    let meshes = room.placed_meshes(|g| {
        let k = room.group_index(&g.name)?;
        (g.kind == GroupKind::Surface).then(|| Material::Diffuse { albedo: albedo[k] })
    });
    let scene = Scene {
        real: GeometryLayer::new(meshes),
        virtual_objects: objects.clone(),
        probe: Probe {
            radiance: Image::filled(64, 32, SKY),
            world_from_probe: Mat3::IDENTITY,
            position,
        },
        background: Background::Panorama,
        camera: Camera::Panorama {
            position,
            world_from_probe: Mat3::IDENTITY,
        },
        render: RenderDescription::default(),
        lighting: LightingDescription::default(),
        luminaires: Vec::new(),
    };
    let lighting = Lighting::reference(&scene)
        .expect("lighting")
        .with_luminaires(luminaires.to_vec());
    [1u64, 2].map(|seed| {
        let settings = RenderSettings {
            composite: CompositeRule::Difference,
            width: Some(width),
            spp: spp / 2,
            bounces: 64,
            seed,
            sampler: SamplerKind::Sobol,
            adaptive: None,
            adaptive_sampling: false,
        };
        render(&scene, &lighting, &settings, &|_, _| ()).expect("render")
    })
}

/// The mean of two halves: the render at the full sample count.
pub fn mean(halves: &[Image<Rgb>; 2]) -> Image<Rgb> {
    let [a, b] = halves;
    Image::from_fn_par(a.width(), a.height(), |x, y| {
        (*a.get(x, y) + *b.get(x, y)) * 0.5
    })
}

/// Relative MSE `mean_c (a - b)^2 / (b^2 + 0.01)` (ibl-metrics' form) over `(prediction, truth)`
/// pairs of patch radiances.
pub fn relative_mse(pairs: &[(Rgb, Rgb)]) -> f64 {
    let mut sum = 0.0f64;
    for (a, b) in pairs {
        for c in 0..3 {
            let (a, b) = (f64::from(a[c]), f64::from(b[c]));
            sum += (a - b).powi(2) / (b * b + ibl_metrics::RELATIVE_MSE_EPSILON);
        }
    }
    sum / (3.0 * pairs.len().max(1) as f64)
}

/// The relative MSE of the mean of two halves against the truth it estimates: a quarter of the
/// variance of their difference, per patch, `patches` the patch radiances each half gives.
pub fn noise_of_mean(halves: [&[Rgb]; 2], truth: &[Rgb], patches: &[usize]) -> f64 {
    let pairs: Vec<(Rgb, Rgb)> = patches
        .iter()
        .map(|&p| {
            let d = (halves[0][p] - halves[1][p]) * 0.5;
            (truth[p] + d, truth[p])
        })
        .collect();
    relative_mse(&pairs)
}

//! Renders the probe of a synthetic room with iblkit's own path tracer: the room's surface groups
//! with their `measured_reflectance` as Lambertian albedos, its light groups (windows) left open
//! to a uniform sky of radiance `SKY` outside, the panorama camera at the probe. Two independent
//! halves (seeds 1 and 2) are averaged; their difference gives the noise that is written beside
//! the image (`render.json`): per group, the standard error of the mean radiance over the pixels
//! the estimate uses.
//!
//! ```sh
//! cargo run --release -p ibl-room --example render_synthetic_room -- \
//!     [assets/rooms/synthetic/room.toml] [--spp 256] [--width 1024]
//! ```

use std::path::{Path, PathBuf};

use ibl_core::{Image, Rgb};
use ibl_io::{ExrCompression, ExrOptions, ExrPrecision, WriteOptions, write_image};
use ibl_render::{Lighting, RenderSettings, render};
use ibl_room::{GroupKind, ObservationSettings, ProbeDepthMap, Room, RoomFile, observe};
use ibl_scene::description::{CompositeRule, LightingDescription, RenderDescription};
use ibl_scene::{Background, Camera, GeometryLayer, Material, Probe, Scene};

/// Radiance of the sky seen through the window (probe units).
const SKY: Rgb = Rgb::new(9.0, 9.5, 10.0);

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut room_path = PathBuf::from("assets/rooms/synthetic/room.toml");
    let (mut spp, mut width) = (256u32, 1024u32);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--spp" => spp = args.next().ok_or("--spp needs a value")?.parse()?,
            "--width" => width = args.next().ok_or("--width needs a value")?.parse()?,
            other => room_path = PathBuf::from(other),
        }
    }
    let text = std::fs::read_to_string(&room_path)?;
    let file = RoomFile::from_toml(&text).map_err(|e| format!("{}: {e}", room_path.display()))?;
    let room = Room::from_file(&file)?;
    let meshes = room.placed_meshes(|g| match g.kind {
        GroupKind::Surface => Some(Material::Diffuse {
            albedo: g.measured_reflectance.unwrap_or(Rgb::splat(0.5)),
        }),
        GroupKind::Light => None,
    });
    let scene = Scene {
        real: GeometryLayer::new(meshes),
        virtual_objects: GeometryLayer::empty(),
        probe: Probe {
            radiance: Image::filled(64, 32, SKY),
            world_from_probe: room.world_from_probe,
            position: room.probe_position,
        },
        background: Background::Panorama,
        camera: Camera::Panorama {
            position: room.probe_position,
            world_from_probe: room.world_from_probe,
        },
        render: RenderDescription::default(),
        lighting: LightingDescription::default(),
        luminaires: Vec::new(),
    };
    let lighting = Lighting::reference(&scene)?;
    let half = (spp / 2).max(1);
    let start = std::time::Instant::now();
    let mut halves = Vec::new();
    for seed in [1u64, 2] {
        let settings = RenderSettings {
            composite: CompositeRule::Difference,
            width: Some(width),
            spp: half,
            bounces: 64,
            seed,
            sampler: ibl_render::SamplerKind::Sobol,
            adaptive: None,
            adaptive_sampling: false,
        };
        let out = render(&scene, &lighting, &settings, &|done, total| {
            if done % 64 == 0 || done == total {
                eprint!("\rseed {seed}: row {done}/{total}");
            }
        })?;
        eprintln!();
        halves.push(out.with_objects);
    }
    let seconds = start.elapsed().as_secs_f64();
    let (a, b) = (&halves[0], &halves[1]);
    let mean = Image::from_vec(
        a.width(),
        a.height(),
        a.pixels()
            .iter()
            .zip(b.pixels())
            .map(|(&x, &y)| (x + y) * 0.5)
            .collect(),
    )?;
    let folder = room_path.parent().unwrap_or(Path::new("."));
    let probe_path = folder.join(&file.probe.file);
    let options = WriteOptions {
        exr: ExrOptions {
            precision: ExrPrecision::Half,
            compression: ExrCompression::Zip,
        },
        ..WriteOptions::default()
    };
    write_image(&probe_path, &mean, &options)?;
    // Noise: the mean of the two halves has, per pixel, the variance of (a - b) / 2. Per group,
    // over the pixels the estimate uses, the standard error of the mean radiance is the standard
    // deviation of the half difference of the group's mean, estimated from pixel differences.
    let depth = ProbeDepthMap::new(&room, mean.width(), mean.height())?;
    let obs_a = observe(&room, &depth, a, &ObservationSettings::default())?;
    let obs_b = observe(&room, &depth, b, &ObservationSettings::default())?;
    let obs = observe(&room, &depth, &mean, &ObservationSettings::default())?;
    let mut groups = Vec::new();
    for (g, group) in room.groups.iter().enumerate() {
        let members: Vec<usize> = (0..room.patches.len())
            .filter(|&p| room.patches[p].group as usize == g && obs.is_seen(p))
            .collect();
        // Relative RMS of the patch means' half differences: the noise of one patch's L.
        let (mut sq, mut count, mut level) = (0.0f64, 0usize, 0.0f64);
        for &p in &members {
            let (la, lb) = (obs_a.patches[p].radiance, obs_b.patches[p].radiance);
            let m = (la + lb) * 0.5;
            if m.luminance() > 0.0 {
                let d = f64::from(((la - lb) * 0.5).luminance() / m.luminance());
                sq += d * d;
                count += 1;
                level += f64::from(m.luminance());
            }
        }
        let patch_noise = if count > 0 {
            (sq / count as f64).sqrt()
        } else {
            0.0
        };
        groups.push(serde_json::json!({
            "group": group.name,
            "seen_patches": members.len(),
            "mean_luminance": if count > 0 { level / count as f64 } else { 0.0 },
            "patch_radiance_relative_standard_error": patch_noise,
            "group_radiance_relative_standard_error": patch_noise / (count.max(1) as f64).sqrt(),
        }));
    }
    let pixel_noise = {
        let (mut sq, mut n) = (0.0f64, 0usize);
        for (&x, &y) in a.pixels().iter().zip(b.pixels()) {
            let m = ((x + y) * 0.5).luminance();
            if m > 0.0 {
                let d = f64::from(((x - y) * 0.5).luminance() / m);
                sq += d * d;
                n += 1;
            }
        }
        (sq / n.max(1) as f64).sqrt()
    };
    let report = serde_json::json!({
        "command": format!(
            "cargo run --release -p ibl-room --example render_synthetic_room -- {} --spp {spp} --width {width}",
            room_path.display()
        ),
        "size": [mean.width(), mean.height()],
        "spp": half * 2,
        "bounces": 64,
        "sky_radiance": SKY.to_array(),
        "seconds": seconds,
        "pixel_luminance_relative_standard_error": pixel_noise,
        "groups": groups,
    });
    let json_path = folder.join("render.json");
    std::fs::write(&json_path, serde_json::to_string_pretty(&report)? + "\n")?;
    eprintln!(
        "wrote {} and {} in {seconds:.1} s (pixel noise {:.1} %)",
        probe_path.display(),
        json_path.display(),
        100.0 * pixel_noise
    );
    Ok(())
}

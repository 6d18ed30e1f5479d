//! The room's irradiance volume (Grosch 2005, section 4.1): gathering checked on a room of
//! uniform radiance, validity inside furniture, the interpolation error against direct gathering
//! on the synthetic room of `docs/ROOMS.md` (and, in the slow tier, SH L2 against the ambient
//! cube and grid spacings), and leak control behind a partition.

use std::path::PathBuf;

use glam::{Mat3, Vec3};
use ibl_core::{Image, Rgb};
use ibl_room::ambient_cube::AmbientCube;
use ibl_room::depth_map::NO_PATCH;
use ibl_room::description::Facing;
use ibl_room::radiosity::{PatchRadiosity, solve_radiosity};
use ibl_room::{
    AnalysisSettings, FormFactors, KeyPointVisibility, ProbeDepthMap, Room, RoomAnalysis,
    RoomDescription, RoomFile, RoomRadiance, RoomVolume, VolumeError, VolumeErrorSettings,
    VolumeSettings, analyse_room, important_patches, volume_error,
};
use ibl_sh::{IrradianceL2, LeakControl, VolumeLayer};

fn synthetic() -> (RoomFile, Room, Image<Rgb>) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/rooms/synthetic");
    let text = std::fs::read_to_string(dir.join("room.toml")).expect("room file");
    let file = RoomFile::from_toml(&text).expect("room file parses");
    let room = Room::from_file(&file).expect("room");
    let probe = ibl_io::read_image(&dir.join(&file.probe.file))
        .expect("probe")
        .image;
    (file, room, probe)
}

fn analyse(room: &Room, probe: &Image<Rgb>) -> RoomAnalysis {
    analyse_room(room, probe, &AnalysisSettings::default(), &|_, _, _| ()).expect("analysis")
}

fn summary(name: &str, e: &VolumeError) -> String {
    format!(
        "{name}: {} positions ({} near a surface, {} rejected, {} failed); all light: mean {:.2} \
         % p95 {:.2} % max {:.2} % near {:.2} % at the point {:.2} %; unimportant: mean {:.2} % \
         p95 {:.2} % max {:.2} % near {:.2} % at the point {:.2} %",
        e.points,
        e.near_points,
        e.rejected,
        e.failed,
        e.all_light.mean_err_pct,
        e.all_light.p95_err_pct,
        e.all_light.max_err_pct,
        e.all_light.near_mean_err_pct,
        e.all_light.at_point_mean_err_pct,
        e.unimportant.mean_err_pct,
        e.unimportant.p95_err_pct,
        e.unimportant.max_err_pct,
        e.unimportant.near_mean_err_pct,
        e.unimportant.at_point_mean_err_pct,
    )
}

/// 100 positions, 2048 reference rays: the main tier's measurement (on the synthetic room the
/// slow tier's 200 positions and 4096 rays give 5.4 % and 4.7 % where this gives 5.7 % and 5.7 %:
/// other positions, the same picture).
const FAST: VolumeErrorSettings = VolumeErrorSettings {
    points: 100,
    normals: 64,
    rays: 2048,
    seed: 1,
    leak: LeakControl::ValidOnly,
    visibility: KeyPointVisibility::Unoccluded,
    region: None,
};

#[test]
fn synthetic_room_volume_interpolates_direct_gathering() {
    let (file, room, probe) = synthetic();
    let analysis = analyse(&room, &probe);
    let important = important_patches(&room, &analysis.estimate, 32);
    let radiance =
        RoomRadiance::new(&room, &analysis.depth, &probe, &analysis.estimate).expect("radiance");
    let volume: RoomVolume<IrradianceL2> =
        RoomVolume::build(&radiance, &important, &VolumeSettings::default()).expect("volume");
    // Validity: a key point inside a furniture box is invalid, one in the open (more than 5 cm
    // from every box) valid.
    let grid = *volume.volume().grid();
    let furniture: Vec<_> = file
        .room
        .boxes
        .iter()
        .filter(|b| b.facing == Facing::Outward)
        .collect();
    for k in 0..grid.len() {
        let p = grid.position(k).as_vec3();
        let inside = furniture
            .iter()
            .any(|b| p.cmpgt(Vec3::from(b.min)).all() && p.cmplt(Vec3::from(b.max)).all());
        let clear = furniture.iter().all(|b| {
            let margin = Vec3::splat(0.05);
            !(p.cmpgt(Vec3::from(b.min) - margin).all()
                && p.cmplt(Vec3::from(b.max) + margin).all())
        });
        if inside {
            assert!(!volume.volume().is_valid(k), "key point {p} inside a box");
        } else if clear {
            assert!(volume.volume().is_valid(k), "key point {p} in the open");
        }
    }
    assert!(volume.invalid_points > 0);
    let error = volume_error(&radiance, &important, &volume, &FAST).expect("error");
    println!(
        "grid {:?}, {} invalid key points; {}",
        grid.counts,
        volume.invalid_points,
        summary("SH L2, 0.5 m", &error)
    );
    // Measured (100 positions): all light 5.7 % mean, SH L2 alone 2.5 % at the point;
    // unimportant light 5.7 % and 1.2 %. Bounds: 1.5 x the measured means. Grosch's assumption
    // (the unimportant light varies slowly) holds at the point: its representation error is half
    // the all-light one (the window's sharp edge is left out). Look-ups that find no corner
    // (walled off from all eight): measured 0 (1 in 200 in the slow tier), at most 2 allowed.
    assert!(
        error.points == FAST.points && error.failed <= 2,
        "{error:?}"
    );
    assert!(error.all_light.mean_err_pct < 8.5, "{error:?}");
    assert!(error.unimportant.mean_err_pct < 8.5, "{error:?}");
    assert!(error.all_light.at_point_mean_err_pct < 4.0, "{error:?}");
    assert!(
        error.unimportant.at_point_mean_err_pct < error.all_light.at_point_mean_err_pct,
        "{error:?}"
    );
}

/// A 4 x 2.5 x 3 m room split by a partition from floor to ceiling (x = 0.10 to 0.16 m, a 1 m
/// doorway at z > 0.5), lit by a ceiling lamp on the left (x < 0) side; the probe on the left.
const PARTITIONED: &str = r#"
    patch_area_m2 = 0.1
    group = [
      { name = "wall" }, { name = "floor" }, { name = "ceiling" }, { name = "partition" },
      { name = "lamp", kind = "light" },
    ]
    [[box]]
    min = [-2, 0, -1.5]
    max = [2, 2.5, 1.5]
    facing = "inward"
    group = "wall"
    face_groups = { "-y" = "floor", "+y" = "ceiling" }
    openings = [{ face = "+y", min = [-1.6, -1.0], max = [-0.6, 0.0], fill = "lamp" }]
    [[box]]
    min = [0.1, 0, -1.5]
    max = [0.16, 2.5, 0.5]
    group = "partition"
    omit = ["-y", "+y", "-z"]
"#;

fn partitioned_room() -> Room {
    let description: RoomDescription = toml::from_str(PARTITIONED).expect("room parses");
    Room::new(&description, Vec3::new(-1.0, 1.3, 0.0), Mat3::IDENTITY).expect("room")
}

/// The probe the forward radiosity solution makes (every pixel its patch's `B / pi`).
fn forward_probe(room: &Room, ff: &FormFactors, albedo: &[Rgb], lamp: Rgb) -> Image<Rgb> {
    let system: Vec<PatchRadiosity> = room
        .patches
        .iter()
        .map(|p| match albedo.get(p.group as usize) {
            Some(&a) => PatchRadiosity::Unknown {
                emission: Rgb::ZERO,
                reflectance: a,
            },
            None => PatchRadiosity::Known(lamp),
        })
        .collect();
    let forward =
        solve_radiosity(ff, &system, &vec![Rgb::ZERO; ff.len()], 1e-6, 2000).expect("forward");
    let depth = ProbeDepthMap::new(room, 256, 128).expect("depth");
    Image::from_fn_par(256, 128, |x, y| match depth.sample(x, y).patch {
        NO_PATCH => Rgb::ZERO,
        p => forward.radiosity[p as usize] / std::f32::consts::PI,
    })
}

#[test]
fn uniform_radiance_gives_pi_l_at_every_valid_key_point() {
    let room = partitioned_room();
    // A probe of radiance 1 everywhere: every seen patch has B = pi, and the estimate fills
    // the hidden ones (behind the partition) with rho E = pi as well (rho = 1).
    let probe = Image::filled(256, 128, Rgb::ONE);
    let analysis = analyse(&room, &probe);
    let important = important_patches(&room, &analysis.estimate, 8);
    let radiance =
        RoomRadiance::new(&room, &analysis.depth, &probe, &analysis.estimate).expect("radiance");
    let volume: RoomVolume<IrradianceL2> =
        RoomVolume::build(&radiance, &important, &VolumeSettings::default()).expect("volume");
    let layer = volume.volume().layer(VolumeLayer::AllLight).expect("layer");
    let mut deviation: Vec<f32> = layer
        .iter()
        .enumerate()
        .filter(|&(k, _)| volume.volume().is_valid(k))
        .map(|(_, key)| {
            [Vec3::X, Vec3::NEG_Y, Vec3::Z, Vec3::new(0.6, 0.8, 0.0)]
                .iter()
                .flat_map(|&n| key.irradiance(n))
                .map(|e| (e / std::f32::consts::PI - 1.0).abs())
                .fold(0.0f32, f32::max)
        })
        .collect();
    deviation.sort_by(f32::total_cmp);
    let p95 = deviation[deviation.len() * 95 / 100];
    let worst = deviation[deviation.len() - 1];
    println!(
        "uniform room: relative deviation from pi L: 95 % of key points {p95:.2e}, worst {worst:.2e}"
    );
    // 1024 Fibonacci rays integrate a constant's L1 and L2 coefficients to ~1e-4, and the seen
    // patches have radiance 1 exactly. Hidden patches (behind the partition) are 1 within the
    // estimate's convergence (0.002 in rho), except those the partition's foot half covers: part
    // of their form-factor rays meet its inside, so their E, and rho E / pi, fall short (measured
    // 1.6e-2 at the floor corner behind it; 95th percentile 6.8e-3). Bounds: 2x the measured.
    assert!(p95 < 1.4e-2 && worst < 3.2e-2, "{p95} {worst}");
    assert_eq!(
        volume.invalid_points, 0,
        "no key point lies inside the partition"
    );
}

#[test]
fn visibility_weights_stop_light_leaking_through_a_partition() {
    let room = partitioned_room();
    let ff = FormFactors::compute(&room, &AnalysisSettings::default().form_factors, &|_, _| ())
        .expect("form factors");
    let albedo = [
        Rgb::new(0.7, 0.7, 0.7),
        Rgb::new(0.4, 0.3, 0.2),
        Rgb::new(0.8, 0.8, 0.8),
        Rgb::new(0.6, 0.6, 0.6),
    ];
    let probe = forward_probe(&room, &ff, &albedo, Rgb::new(30.0, 28.0, 25.0));
    let analysis = analyse(&room, &probe);
    let important = important_patches(&room, &analysis.estimate, 8);
    let radiance =
        RoomRadiance::new(&room, &analysis.depth, &probe, &analysis.estimate).expect("radiance");
    let volume: RoomVolume<IrradianceL2> =
        RoomVolume::build(&radiance, &important, &VolumeSettings::default()).expect("volume");
    // Positions behind the partition on the dark side, between it and the next key-point
    // plane (x = 0.4875): their cells' x = 0 corners are on the lit side.
    let behind = VolumeErrorSettings {
        region: Some([Vec3::new(0.17, 0.3, -1.4), Vec3::new(0.45, 2.2, 0.2)]),
        ..FAST
    };
    let leaking = volume_error(
        &radiance,
        &important,
        &volume,
        &VolumeErrorSettings {
            visibility: KeyPointVisibility::Any,
            ..behind
        },
    )
    .expect("error");
    let guarded = volume_error(&radiance, &important, &volume, &behind).expect("error");
    println!(
        "{}",
        summary("behind the partition, validity only", &leaking)
    );
    println!("{}", summary("behind the partition, visibility", &guarded));
    // Measured: validity only 45 % (the lit side's corners carry the lamp's light through the
    // partition), visibility 19 %: what is left is the dark side's corners read 0.03 to 0.32 m
    // away, beside a surface (the irradiance facing the partition changes fastest there). The
    // leak must be more than halved, and the rest under 25 % (1.3 x the measured).
    assert_eq!(guarded.failed, 0, "{guarded:?}");
    assert!(
        guarded.all_light.mean_err_pct * 2.0 < leaking.all_light.mean_err_pct,
        "{guarded:?} {leaking:?}"
    );
    assert!(guarded.all_light.mean_err_pct < 25.0, "{guarded:?}");
}

/// The figures of `docs/ROOMS.md` section 8: SH L2 and the ambient cube, three grid spacings,
/// with and without the visibility test, 200 positions and 4096 reference rays.
#[test]
#[ignore = "slow tier: 10 to 30 s in the test profile"]
fn synthetic_room_volume_sh_against_ambient_cube() {
    let (_, room, probe) = synthetic();
    let analysis = analyse(&room, &probe);
    let important = important_patches(&room, &analysis.estimate, 32);
    let radiance =
        RoomRadiance::new(&room, &analysis.depth, &probe, &analysis.estimate).expect("radiance");
    let measure = VolumeErrorSettings::default();
    let mut table = Vec::new();
    for spacing_m in [0.25, 0.5, 1.0] {
        let settings = VolumeSettings {
            spacing_m,
            ..VolumeSettings::default()
        };
        let sh: RoomVolume<IrradianceL2> =
            RoomVolume::build(&radiance, &important, &settings).expect("volume");
        let e = volume_error(&radiance, &important, &sh, &measure).expect("error");
        table.push(summary(&format!("SH L2, {spacing_m} m"), &e));
        if spacing_m == 0.5 {
            let any = volume_error(
                &radiance,
                &important,
                &sh,
                &VolumeErrorSettings {
                    visibility: KeyPointVisibility::Any,
                    ..measure
                },
            )
            .expect("error");
            table.push(summary("SH L2, 0.5 m, validity only", &any));
            let cube: RoomVolume<AmbientCube> =
                RoomVolume::build(&radiance, &important, &settings).expect("volume");
            let c = volume_error(&radiance, &important, &cube, &measure).expect("error");
            table.push(summary("ambient cube, 0.5 m", &c));
            // The representation alone: the cube loses several times what SH L2 does.
            assert!(c.all_light.at_point_mean_err_pct > 2.0 * e.all_light.at_point_mean_err_pct);
            assert!(c.all_light.mean_err_pct > e.all_light.mean_err_pct);
        }
    }
    for line in &table {
        println!("{line}");
    }
}

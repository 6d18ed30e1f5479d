//! The synthetic day of docs/OUTDOOR.md, all 16 frames, with its figures, plot and pictures.
//!
//! ```sh
//! cargo run --release -p ibl-outdoor --example synthetic_day -- OUT_DIR [BOUNCES] [SAMPLES]
//! ```
//!
//! `BOUNCES` (default 1) is the path length of the renders: 1 is direct light only (the model's
//! own assumption), 3 adds two bounces of interreflection, which the model ignores. `SAMPLES`
//! (default 1500) is the number of sample sites. Writes `day.csv`, `day.json`, `estimates.svg`,
//! `summary.txt`, the offline maps and, for a few frames, the frame, the relit map and the
//! path-traced probe as PNG.

use std::path::{Path, PathBuf};

use glam::{Mat3, Vec3};
use ibl_core::{Image, Rgb};
use ibl_io::tonemap::auto_exposure_stops;
use ibl_io::{Display, ToneCurve, WriteOptions, write_atomically, write_image};
use ibl_outdoor::courtyard::Courtyard;
use ibl_outdoor::plot::{SeriesPoint, estimates_svg};
use ibl_outdoor::synthetic::{SyntheticDay, Weather, map_error};
use ibl_outdoor::{
    CameraSetup, CaptureSource, MapSettings, OutdoorSystem, ProbeCapture, SampleSettings, SkyModel,
    SystemSettings, VolumeRefresh, VolumeSettings,
};
use ibl_sh::VolumeGrid;

fn png(dir: &Path, name: &str, image: &Image<Rgb>, exposure: Option<f32>) {
    let stops = exposure.unwrap_or_else(|| auto_exposure_stops(image));
    let options = WriteOptions {
        display: Display {
            exposure_stops: stops,
            curve: ToneCurve::Reinhard,
        },
        ..WriteOptions::default()
    };
    write_image(&dir.join(name), image, &options).expect("write a PNG");
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = PathBuf::from(
        args.get(1)
            .map(String::as_str)
            .unwrap_or("target/outdoor-day"),
    );
    let bounces: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let samples: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1500);
    std::fs::create_dir_all(&out).expect("create the output folder");
    let day = SyntheticDay {
        bounces,
        ..SyntheticDay::standard()
    };
    let yard = Courtyard::new(day.frame_size);
    let capture = day.frame_truth(0).expect("truth");
    let probe = day.render_probe(&yard, &capture, 1).expect("probe");
    let frame_size = (day.frame_size.0 as usize, day.frame_size.1 as usize);
    let grid = VolumeGrid::covering(
        yard.volume_box.0.as_dvec3(),
        yard.volume_box.1.as_dvec3(),
        3.0,
    )
    .expect("grid");
    let settings = SystemSettings {
        maps: MapSettings {
            sky_model: SkyModel::Preetham {
                turbidity: day.turbidity,
            },
            ..MapSettings::default()
        },
        samples: SampleSettings {
            count: samples,
            ..SampleSettings::default()
        },
        volume: Some(VolumeSettings {
            grid,
            directions_width: 32,
            refresh: VolumeRefresh::FromMap,
        }),
        ..SystemSettings::default()
    };
    let mut system = OutdoorSystem::new(
        yard.layer.clone(),
        day.location,
        &ProbeCapture {
            radiance: probe.clone(),
            position: yard.probe_position,
            world_from_probe: Mat3::IDENTITY,
            time: day.frame_time(0),
            lighting: CaptureSource::Measured,
        },
        &CameraSetup {
            camera: yard.camera,
            frame_size,
            mask: yard.diffuse_mask(frame_size),
        },
        settings,
    )
    .expect("system");
    let maps = system.maps();
    png(&out, "probe_0930.png", &probe, None);
    png(&out, "albedo.png", &maps.albedo_map(), Some(0.0));
    png(
        &out,
        "normals.png",
        &maps
            .normal_map()
            .map(|n| Rgb::new(0.5 + 0.5 * n.r, 0.5 + 0.5 * n.g, 0.5 + 0.5 * n.b)),
        Some(0.0),
    );
    png(
        &out,
        "weighted_ambient.png",
        &maps.weighted_ambient_map().map(|&c| Rgb::splat(c)),
        Some(0.0),
    );
    let sun0 = Vec3::from_array(capture.parameters.sun_direction);
    png(
        &out,
        "shadow_0930.png",
        &maps
            .shadow_map(system.layer(), sun0)
            .map(|&s| Rgb::splat(s)),
        Some(0.0),
    );

    let mut csv = String::from(
        "frame,local_time,weather,true_sun_r,true_sun_g,true_sun_b,true_sky_r,true_sky_g,true_sky_b,sun_r,sun_g,sun_b,sky_r,sky_g,sky_b,sun_std_g,sky_std_g,sunlit_inliers,inliers,sky_condition,relit_error_percent\n",
    );
    let mut summary = format!("bounces {bounces}, sample sites {samples}\n");
    let mut points = Vec::new();
    let mut rows = Vec::new();
    let (mut worst_clear, mut worst_cloud, mut worst_overcast) = (0.0f32, 0.0f32, 0.0f32);
    let exposure = auto_exposure_stops(&probe);
    for k in 0..day.frame_count() {
        let truth = day.frame_truth(k).expect("truth");
        let frame = day
            .render_frame(&yard, &truth, 100 + k as u64)
            .expect("frame");
        let result = system.process(day.frame_time(k), &frame).expect("process");
        let (e, t) = (result.estimate, truth.parameters);
        let minutes = 9 * 60 + 30 + 30 * k;
        let hour = minutes as f64 / 60.0;
        let relit_error = if k % 3 == 0 || k == 10 {
            let truth_probe = day
                .render_probe(&yard, &truth, 1000 + k as u64)
                .expect("probe");
            let sun = Vec3::from_array(t.sun_direction);
            let err = map_error(system.relit_map(), &truth_probe, sun, 4);
            let name = format!("{:02}{:02}", minutes / 60, minutes % 60);
            png(&out, &format!("frame_{name}.png"), &frame, Some(exposure));
            png(
                &out,
                &format!("relit_{name}.png"),
                system.relit_map(),
                Some(exposure),
            );
            png(
                &out,
                &format!("pathtraced_{name}.png"),
                &truth_probe,
                Some(exposure),
            );
            Some(err)
        } else {
            None
        };
        for c in 0..3 {
            let sun_err = if t.sun[c] > 0.0 {
                (e.sun[c] / t.sun[c] - 1.0).abs()
            } else {
                0.0
            };
            let sky_err = (e.sky[c] / t.sky[c] - 1.0).abs();
            match truth.weather {
                Weather::Clear => worst_clear = worst_clear.max(sun_err).max(sky_err),
                Weather::Cloud { .. } => worst_cloud = worst_cloud.max(sun_err).max(sky_err),
                Weather::Overcast => {
                    worst_overcast = worst_overcast.max(e.sun[c] / truth.clear_sun[c])
                }
            }
        }
        let weather = match truth.weather {
            Weather::Clear => "clear".to_string(),
            Weather::Cloud { sun_factor } => format!("cloud x{sun_factor}"),
            Weather::Overcast => "overcast".to_string(),
        };
        csv.push_str(&format!(
            "{k},{:02}:{:02},{weather},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:?},{}\n",
            minutes / 60,
            minutes % 60,
            t.sun[0],
            t.sun[1],
            t.sun[2],
            t.sky[0],
            t.sky[1],
            t.sky[2],
            e.sun[0],
            e.sun[1],
            e.sun[2],
            e.sky[0],
            e.sky[1],
            e.sky[2],
            e.sun_std[1],
            e.sky_std[1],
            e.sunlit_inliers,
            e.inliers,
            result.sky_condition,
            relit_error.map_or(String::new(), |v| format!("{v:.2}")),
        ));
        let sun_cell = |c: usize| {
            if t.sun[c] > 0.0 {
                100.0 * (e.sun[c] / t.sun[c] - 1.0)
            } else {
                100.0 * e.sun[c] / truth.clear_sun[c]
            }
        };
        let line = format!(
            "{:02}:{:02} {weather:10} P_d {} {:6.2} {:6.2} {:6.2} %  P_a err {:6.2} {:6.2} {:6.2} %{}\n",
            minutes / 60,
            minutes % 60,
            if t.sun[0] > 0.0 {
                "err     "
            } else {
                "/ clear "
            },
            sun_cell(0),
            sun_cell(1),
            sun_cell(2),
            100.0 * (e.sky[0] / t.sky[0] - 1.0),
            100.0 * (e.sky[1] / t.sky[1] - 1.0),
            100.0 * (e.sky[2] / t.sky[2] - 1.0),
            relit_error.map_or(String::new(), |v| format!("  relit map {v:.2} %")),
        );
        print!("{line}");
        summary.push_str(&line);
        points.push(SeriesPoint {
            hour,
            sun: e.sun,
            sky: e.sky,
            truth: Some((t.sun, t.sky)),
            label: weather,
        });
        rows.push(serde_json::json!({ "frame": k, "truth": t, "result": result, "relit_error_percent": relit_error }));
    }
    let tail = format!(
        "worst clear-frame error {:.2} %, worst cloud-frame error {:.2} %, worst overcast P_d {:.2} % of the clear sun\n",
        100.0 * worst_clear,
        100.0 * worst_cloud,
        100.0 * worst_overcast
    );
    print!("{tail}");
    summary.push_str(&tail);
    let title = format!(
        "Synthetic day, Aalborg 20 April 2024 (renders with {bounces} bounce(s)): estimates (lines) and truth (dots)"
    );
    let svg = estimates_svg(&points, &title, (1100, 700)).expect("plot");
    write_atomically(&out.join("estimates.svg"), svg.as_bytes()).expect("write");
    write_atomically(&out.join("day.csv"), csv.as_bytes()).expect("write");
    write_atomically(&out.join("summary.txt"), summary.as_bytes()).expect("write");
    let json = serde_json::to_string_pretty(&rows).expect("json");
    write_atomically(&out.join("day.json"), json.as_bytes()).expect("write");
}

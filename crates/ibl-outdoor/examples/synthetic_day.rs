//! The synthetic day of docs/OUTDOOR.md, all 16 frames, with its figures, plot and pictures.
//!
//! ```sh
//! cargo run --release -p ibl-outdoor --example synthetic_day -- OUT_DIR [BOUNCES] [SAMPLES] [MODELS]
//! ```
//!
//! `BOUNCES` (default 1) is the path length of the renders: 1 is direct light only (the paper's
//! model's own assumption), 3 adds two bounces of interreflection. `SAMPLES` (default 1500) is
//! the number of sample sites. `MODELS` (default `paper`) says which models run on the same
//! renders: `paper` (no interreflections, the paper's model), `bounce` (the bounce transfer of
//! [`ibl_outdoor::interreflection`], 4 bounces, 64 rays per point) or `both`. Writes, per model
//! `M`, `M/day.csv`, `M/day.json`, `M/estimates.svg`, `M/summary.txt`, `M/`'s offline maps and, for
//! a few frames, the frame, the relit map and the path-traced probe as PNG.

use std::path::{Path, PathBuf};

use glam::{Mat3, Vec3};
use ibl_core::tonemap::{Display, ToneCurve, auto_exposure_stops};
use ibl_core::{Image, Rgb};
use ibl_io::{WriteOptions, write_atomically, write_image};
use ibl_outdoor::courtyard::Courtyard;
use ibl_outdoor::plot::{SeriesPoint, estimates_svg};
use ibl_outdoor::synthetic::{SyntheticDay, Weather, map_error};
use ibl_outdoor::{
    CameraSetup, CaptureSource, Interreflection, MapSettings, OutdoorSystem, ProbeCapture,
    SampleSettings, SkyModel, SystemSettings, VolumeRefresh, VolumeSettings,
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
    let models: Vec<(&str, Interreflection)> = match args.get(4).map_or("paper", String::as_str) {
        "paper" => vec![("paper", Interreflection::Off)],
        "bounce" => vec![("bounce", MapSettings::default().interreflection)],
        "both" => vec![
            ("paper", Interreflection::Off),
            ("bounce", MapSettings::default().interreflection),
        ],
        other => {
            eprintln!("MODELS must be paper, bounce or both; got {other}");
            std::process::exit(2);
        }
    };
    let day = SyntheticDay {
        bounces,
        ..SyntheticDay::standard()
    };
    let yard = Courtyard::new(day.frame_size);
    let capture = day.frame_truth(0).expect("truth");
    let probe = day.render_probe(&yard, &capture, 1).expect("probe");
    let frame_size = (day.frame_size.0 as usize, day.frame_size.1 as usize);
    let mut runs: Vec<Run> = Vec::new();
    for (label, interreflection) in models {
        let dir = out.join(label);
        std::fs::create_dir_all(&dir).expect("create the output folder");
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
                interreflection,
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
        let system = OutdoorSystem::new(
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
        png(&dir, "albedo.png", &maps.albedo_map(), Some(0.0));
        png(
            &dir,
            "normals.png",
            &maps
                .normal_map()
                .map(|n| Rgb::new(0.5 + 0.5 * n.r, 0.5 + 0.5 * n.g, 0.5 + 0.5 * n.b)),
            Some(0.0),
        );
        png(
            &dir,
            "weighted_ambient.png",
            &maps.weighted_ambient_map().map(|&c| Rgb::splat(c)),
            Some(0.0),
        );
        let sun0 = Vec3::from_array(capture.parameters.sun_direction);
        png(
            &dir,
            "shadow_0930.png",
            &maps
                .shadow_map(system.layer(), sun0)
                .map(|&s| Rgb::splat(s)),
            Some(0.0),
        );
        runs.push(Run::new(label, dir, system, bounces, samples));
    }
    std::fs::create_dir_all(&out).expect("create the output folder");
    png(&out, "probe_0930.png", &probe, None);
    let exposure = auto_exposure_stops(&probe);
    for k in 0..day.frame_count() {
        let truth = day.frame_truth(k).expect("truth");
        let frame = day
            .render_frame(&yard, &truth, 100 + k as u64)
            .expect("frame");
        let minutes = 9 * 60 + 30 + 30 * k;
        let name = format!("{:02}{:02}", minutes / 60, minutes % 60);
        let truth_probe = (k % 3 == 0 || k == 10).then(|| {
            let p = day
                .render_probe(&yard, &truth, 1000 + k as u64)
                .expect("probe");
            png(&out, &format!("frame_{name}.png"), &frame, Some(exposure));
            png(&out, &format!("pathtraced_{name}.png"), &p, Some(exposure));
            p
        });
        for run in &mut runs {
            run.frame(&day, k, &frame, truth_probe.as_ref(), exposure);
        }
    }
    for run in runs {
        run.finish();
    }
}

/// One model's system and what it has recorded over the day.
struct Run {
    label: &'static str,
    dir: PathBuf,
    system: OutdoorSystem,
    bounces: u32,
    csv: String,
    summary: String,
    points: Vec<SeriesPoint>,
    rows: Vec<serde_json::Value>,
    worst: [f32; 3],
}

impl Run {
    fn new(
        label: &'static str,
        dir: PathBuf,
        system: OutdoorSystem,
        bounces: u32,
        samples: usize,
    ) -> Run {
        Run {
            label,
            dir,
            system,
            bounces,
            csv: String::from(
                "frame,local_time,weather,true_sun_r,true_sun_g,true_sun_b,true_sky_r,true_sky_g,true_sky_b,sun_r,sun_g,sun_b,sky_r,sky_g,sky_b,sun_std_g,sky_std_g,sunlit_inliers,inliers,sky_condition,relit_error_percent\n",
            ),
            summary: format!("model {label}, render bounces {bounces}, sample sites {samples}\n"),
            points: Vec::new(),
            rows: Vec::new(),
            worst: [0.0; 3],
        }
    }

    fn frame(
        &mut self,
        day: &SyntheticDay,
        k: usize,
        frame: &Image<Rgb>,
        truth_probe: Option<&Image<Rgb>>,
        exposure: f32,
    ) {
        let truth = day.frame_truth(k).expect("truth");
        let result = self
            .system
            .process(day.frame_time(k), frame)
            .expect("process");
        let (e, t) = (result.estimate, truth.parameters);
        let minutes = 9 * 60 + 30 + 30 * k;
        let hour = minutes as f64 / 60.0;
        let relit_error = truth_probe.map(|truth_probe| {
            let sun = Vec3::from_array(t.sun_direction);
            let name = format!("{:02}{:02}", minutes / 60, minutes % 60);
            png(
                &self.dir,
                &format!("relit_{name}.png"),
                self.system.relit_map(),
                Some(exposure),
            );
            map_error(self.system.relit_map(), truth_probe, sun, 4)
        });
        for c in 0..3 {
            let sun_err = if t.sun[c] > 0.0 {
                (e.sun[c] / t.sun[c] - 1.0).abs()
            } else {
                0.0
            };
            let sky_err = (e.sky[c] / t.sky[c] - 1.0).abs();
            let w = &mut self.worst;
            match truth.weather {
                Weather::Clear => w[0] = w[0].max(sun_err).max(sky_err),
                Weather::Cloud { .. } => w[1] = w[1].max(sun_err).max(sky_err),
                Weather::Overcast => w[2] = w[2].max(e.sun[c] / truth.clear_sun[c]),
            }
        }
        let weather = match truth.weather {
            Weather::Clear => "clear".to_string(),
            Weather::Cloud { sun_factor } => format!("cloud x{sun_factor}"),
            Weather::Overcast => "overcast".to_string(),
        };
        self.csv.push_str(&format!(
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
            "[{}] {:02}:{:02} {weather:10} P_d {} {:6.2} {:6.2} {:6.2} %  P_a err {:6.2} {:6.2} {:6.2} %{}\n",
            self.label,
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
        self.summary.push_str(&line);
        self.points.push(SeriesPoint {
            hour,
            sun: e.sun,
            sky: e.sky,
            truth: Some((t.sun, t.sky)),
            label: weather,
        });
        self.rows.push(serde_json::json!({ "frame": k, "truth": t, "result": result, "relit_error_percent": relit_error }));
    }

    fn finish(mut self) {
        let tail = format!(
            "[{}] worst clear-frame error {:.2} %, worst cloud-frame error {:.2} %, worst overcast P_d {:.2} % of the clear sun\n",
            self.label,
            100.0 * self.worst[0],
            100.0 * self.worst[1],
            100.0 * self.worst[2]
        );
        print!("{tail}");
        self.summary.push_str(&tail);
        let model = match self.label {
            "paper" => "the paper's model",
            _ => "with the bounce transfer",
        };
        let title = format!(
            "Synthetic day, Aalborg 20 April 2024 (renders with {} bounce(s), {model}): estimates (lines) and truth (dots)",
            self.bounces
        );
        let svg = estimates_svg(&self.points, &title, (1100, 700)).expect("plot");
        let dir = &self.dir;
        write_atomically(&dir.join("estimates.svg"), svg.as_bytes()).expect("write");
        write_atomically(&dir.join("day.csv"), self.csv.as_bytes()).expect("write");
        write_atomically(&dir.join("summary.txt"), self.summary.as_bytes()).expect("write");
        let json = serde_json::to_string_pretty(&self.rows).expect("json");
        write_atomically(&dir.join("day.json"), json.as_bytes()).expect("write");
    }
}

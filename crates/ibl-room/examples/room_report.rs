//! The room workflow of `docs/ROOMS.md` end to end, until the `ibl room` commands exist:
//!
//! ```sh
//! # marks -> calibration (vanishing points), scale, shapes by constraints -> room file
//! cargo run --release -p ibl-room --example room_report -- reconstruct MARKS.json ROOM.toml
//! # room file + probe -> reflectance estimate, Table-1 report, important patches, pictures
//! cargo run --release -p ibl-room --example room_report -- analyse ROOM.toml OUT_DIR [--important N]
//! ```
//!
//! `reconstruct` also prints the calibration and, for comparison, the automatic Manhattan
//! proposal on the probe. `analyse` writes `report.md`, `report.json`, `rho-panorama.png`
//! (patches coloured by reflectance, hidden ones hatched), `overlay.png` (the model's edges over
//! the tone-mapped probe) and `cutaway.png` (the room from above, coloured by reflectance).

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use ibl_io::tonemap::{Display, ToneCurve, auto_exposure_stops, to_srgb8};
use ibl_room::picture::{reflectance_cutaway, reflectance_panorama, room_overlay};
use ibl_room::{
    AnalysisSettings, ManhattanSettings, MarksFile, Room, RoomFile, RoomReport, analyse_room,
    calibrate, important_patches, line_observations, probe_height, propose_manhattan_frame,
    reconstruct,
};
use ibl_scene::Camera;

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

fn write_png(path: &Path, image: &ibl_core::Image<[u8; 3]>) -> Result<()> {
    ibl_io::write_atomically(path, &ibl_io::ldr::encode_png(image)?)?;
    println!("wrote {}", path.display());
    Ok(())
}

fn reconstruct_room(marks_path: &Path, room_path: &Path) -> Result<()> {
    let marks = MarksFile::from_json(&std::fs::read_to_string(marks_path)?)
        .map_err(|e| format!("{}: {e}", marks_path.display()))?;
    let calibration = calibrate(&line_observations(&marks))?;
    let scale = probe_height(&marks, calibration.world_from_probe())?;
    println!("{}", serde_json::to_string_pretty(&calibration)?);
    println!("{}", serde_json::to_string_pretty(&scale)?);
    let marks_dir = marks_path.parent().unwrap_or(Path::new("."));
    let room_dir = room_path.parent().unwrap_or(Path::new("."));
    let probe_file = marks
        .probe
        .as_ref()
        .map(|p| p.file.clone())
        .ok_or("the marks file names no probe")?;
    // The room file names the probe relative to itself.
    let probe_abs = marks_dir.join(&probe_file);
    let relative = pathdiff(&probe_abs, room_dir);
    let file = reconstruct(&marks, &calibration, &scale, &relative)?;
    let header = format!(
        "# Made from {} by\n#   cargo run --release -p ibl-room --example room_report -- reconstruct {} {}\n\
         # Calibration: {} lines, RMS residual {:.3} deg; probe {:.3} m above the floor.\n",
        marks_path.display(),
        marks_path.display(),
        room_path.display(),
        line_observations(&marks).len(),
        calibration.rms_residual_deg,
        scale.probe_height_m
    );
    std::fs::write(room_path, header + &file.to_toml()?)?;
    println!("wrote {}", room_path.display());
    let probe = ibl_io::read_image(&probe_abs)?.image;
    let proposal = propose_manhattan_frame(&probe, &ManhattanSettings::default())?;
    let m = proposal.world_from_probe;
    let auto = glam::DMat3::from_cols_array(&[
        m[0][0], m[1][0], m[2][0], m[0][1], m[1][1], m[2][1], m[0][2], m[1][2], m[2][2],
    ]);
    let d = auto.transpose() * calibration.world_from_probe();
    let skew = glam::DVec3::new(
        d.y_axis.z - d.z_axis.y,
        d.z_axis.x - d.x_axis.z,
        d.x_axis.y - d.y_axis.x,
    );
    let angle = (0.5 * skew.length())
        .atan2(0.5 * (d.x_axis.x + d.y_axis.y + d.z_axis.z - 1.0))
        .to_degrees();
    println!(
        "automatic proposal: rotation {:?} deg, {} segments, inliers {:?}, residual {:.3} deg; \
         {angle:.3} deg from the marked calibration",
        proposal.rotation_deg, proposal.segments, proposal.inliers, proposal.rms_residual_deg
    );
    Ok(())
}

/// `target` relative to `base` when both are relative paths under one root (good enough for the
/// repository's own layout), else `target` as given.
fn pathdiff(target: &Path, base: &Path) -> String {
    let t: Vec<_> = target.components().collect();
    let b: Vec<_> = base.components().collect();
    let common = t.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &t[common..] {
        out.push(c);
    }
    out.to_string_lossy().into_owned()
}

fn analyse(room_path: &Path, out: &Path, important: usize) -> Result<()> {
    let file = RoomFile::from_toml(&std::fs::read_to_string(room_path)?)
        .map_err(|e| format!("{}: {e}", room_path.display()))?;
    let room = Room::from_file(&file)?;
    let probe_path = room_path
        .parent()
        .unwrap_or(Path::new("."))
        .join(&file.probe.file);
    let probe = ibl_io::read_image(&probe_path)?.image;
    let probe = probe.map(|&l| l * file.probe.radiance_scale);
    let start = std::time::Instant::now();
    let analysis = analyse_room(&room, &probe, &AnalysisSettings::default(), &|_, _, _| ())?;
    let seconds = start.elapsed().as_secs_f64();
    let lights = important_patches(&room, &analysis.estimate, important);
    let report = RoomReport::new(&room, &analysis, Some(&lights));
    std::fs::create_dir_all(out)?;
    std::fs::write(out.join("report.md"), report.to_markdown())?;
    std::fs::write(out.join("report.json"), report.to_json()?)?;
    println!("{}\nanalysis took {seconds:.2} s", report.to_markdown());
    write_png(
        &out.join("rho-panorama.png"),
        &reflectance_panorama(&analysis.depth, &analysis.estimate),
    )?;
    let display = Display {
        exposure_stops: auto_exposure_stops(&probe),
        curve: ToneCurve::Reinhard,
    };
    write_png(
        &out.join("overlay.png"),
        &room_overlay(&analysis.depth, &to_srgb8(&probe, &display), [255, 220, 0]),
    )?;
    let (lo, hi) = room.bounds().ok_or("empty room")?;
    let centre = 0.5 * (lo + hi);
    let size = (hi - lo).length();
    let eye = Vec3::new(
        centre.x + 0.35 * size,
        hi.y + 0.9 * size,
        centre.z + 0.6 * size,
    );
    let camera = Camera::look_at(
        eye,
        Vec3::new(centre.x, lo.y, centre.z),
        Vec3::Y,
        Vec2::splat(Camera::focal_from_vertical_fov(45.0, 600)),
        Vec2::new(400.0, 300.0),
        (800, 600),
    );
    write_png(
        &out.join("cutaway.png"),
        &reflectance_cutaway(&room, &analysis.estimate, &camera, 800, 600),
    )?;
    Ok(())
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("reconstruct") if args.len() == 3 => {
            reconstruct_room(Path::new(&args[1]), Path::new(&args[2]))
        }
        Some("analyse") if args.len() >= 3 => {
            let important = match args.get(3).map(String::as_str) {
                Some("--important") => args.get(4).ok_or("--important needs N")?.parse()?,
                _ => 32,
            };
            analyse(Path::new(&args[1]), Path::new(&args[2]), important)
        }
        _ => Err("usage: room_report reconstruct MARKS.json ROOM.toml | analyse ROOM.toml OUT_DIR [--important N]".into()),
    }
}

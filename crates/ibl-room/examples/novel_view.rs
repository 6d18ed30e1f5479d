//! A room seen from a moved camera (Grosch 2005, section 4.4; `docs/ROOMS.md`, "Camera
//! movement"): the room file's probe is analysed (section 3.2), then a pinhole view from `--at`
//! looking at `--look` is made from it, the surfaces the probe did not see filled by the estimate
//! `rho E / pi` and by the estimate modulated with the seen texture (`fill_texture`).
//!
//! ```sh
//! cargo run --release -p ibl-room --example novel_view -- ROOM.toml OUT_DIR \
//!     --at X,Y,Z --look X,Y,Z [--size 400x400] [--fov 70] [--samples 2] [--aperiodic]
//! ```
//!
//! Writes `OUT_DIR/novel-view.png`: the flat fill, the textured fill and the filled pixels in
//! red over the flat fill, side by side (the exposure chosen on the flat view), and prints the
//! filled fraction, the modulated faces and the time of each step.

use std::path::PathBuf;
use std::time::Instant;

use glam::{Vec2, Vec3};
use ibl_core::tonemap::{Display, ToneCurve, auto_exposure_stops};
use ibl_core::{Image, Rgb};
use ibl_room::{
    AnalysisSettings, FillTexture, FillTextureSettings, HoleFill, NovelViewSettings, Room,
    RoomFile, RoomRadiance, analyse_room, render_novel_view,
};
use ibl_scene::Camera;

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

fn vec3(text: &str) -> Result<Vec3> {
    let v: Vec<f32> = text
        .split(',')
        .map(str::parse)
        .collect::<std::result::Result<_, _>>()?;
    match v[..] {
        [x, y, z] => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("`{text}`: expected X,Y,Z").into()),
    }
}

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let mut positional = Vec::new();
    let (mut at, mut look) = (None, None);
    let (mut width, mut height, mut fov_deg, mut samples) = (400u32, 400u32, 70.0f32, 2u32);
    let mut texture_settings = FillTextureSettings::default();
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--at" => at = Some(vec3(&value()?)?),
            "--look" => look = Some(vec3(&value()?)?),
            "--size" => {
                let v = value()?;
                let (w, h) = v.split_once('x').ok_or("--size WxH")?;
                (width, height) = (w.parse()?, h.parse()?);
            }
            "--fov" => fov_deg = value()?.parse()?,
            "--samples" => samples = value()?.parse()?,
            "--aperiodic" => texture_settings.aperiodic = true,
            _ => positional.push(PathBuf::from(a)),
        }
    }
    let [room_path, out] = &positional[..] else {
        return Err("usage: novel_view ROOM.toml OUT_DIR --at X,Y,Z --look X,Y,Z".into());
    };
    let (at, look) = (at.ok_or("--at X,Y,Z")?, look.ok_or("--look X,Y,Z")?);
    let text = std::fs::read_to_string(room_path)?;
    let file = RoomFile::from_toml(&text).map_err(|e| format!("{}: {e}", room_path.display()))?;
    let room = Room::from_file(&file)?;
    let folder = room_path.parent().unwrap_or(std::path::Path::new("."));
    let probe = ibl_io::read_image(&folder.join(&file.probe.file))?.image;

    let start = Instant::now();
    let analysis = analyse_room(&room, &probe, &AnalysisSettings::default(), &|_, _, _| ())?;
    let analysed = start.elapsed();
    let start = Instant::now();
    let texture = FillTexture::new(
        &room,
        &analysis.depth,
        &probe,
        &analysis.estimate,
        &texture_settings,
    )?;
    let textured_in = start.elapsed();
    let radiance = RoomRadiance::new(&room, &analysis.depth, &probe, &analysis.estimate)?;
    let f = Camera::focal_from_vertical_fov(fov_deg, height);
    let camera = Camera::look_at(
        at,
        look,
        Vec3::Y,
        Vec2::splat(f),
        Vec2::new(width as f32, height as f32) * 0.5,
        (width, height),
    );
    let settings = NovelViewSettings {
        samples_per_axis: samples,
    };
    let start = Instant::now();
    let flat = render_novel_view(
        &radiance,
        &camera,
        width,
        height,
        HoleFill::Estimate,
        &settings,
    )?;
    let flat_in = start.elapsed();
    let start = Instant::now();
    let textured = render_novel_view(
        &radiance,
        &camera,
        width,
        height,
        HoleFill::Textured(&texture),
        &settings,
    )?;
    let view_in = start.elapsed();

    let pixels = (width * height) as f64;
    let filled: f64 = flat.filled.pixels().iter().map(|&f| f64::from(f)).sum();
    let missed: f64 = flat.missed.pixels().iter().map(|&f| f64::from(f)).sum();
    println!(
        "camera {at} ({:.2} m from the probe) looking at {look}: {width} x {height}, {} rays a \
         pixel; {:.2} % filled, {:.2} % missed",
        (at - room.probe_position).length(),
        samples * samples,
        100.0 * filled / pixels,
        100.0 * missed / pixels,
    );
    for a in texture.analysis.iter().filter(|a| a.modulated) {
        println!(
            "modulated: {} ({} seen, {} hidden, {} sourced texels of {:.1} cm; period {:?} m)",
            room.faces[a.face as usize].name,
            a.seen_texels,
            a.hidden_texels,
            a.sourced_texels,
            100.0 * a.texel_m,
            a.period_m,
        );
    }
    println!(
        "time: analysis {:.2} s, fill texture {:.1} ms, view {:.1} ms flat, {:.1} ms textured",
        analysed.as_secs_f64(),
        textured_in.as_secs_f64() * 1e3,
        flat_in.as_secs_f64() * 1e3,
        view_in.as_secs_f64() * 1e3,
    );

    let (w, h) = (width as usize, height as usize);
    let strip = Image::from_fn_par(w * 3, h, |x, y| {
        let i = x % w;
        match x / w {
            0 => *flat.image.get(i, y),
            1 => *textured.image.get(i, y),
            _ => {
                let f = *flat.filled.get(i, y);
                let red = Rgb::new(flat.image.get(i, y).luminance().max(0.05) * 2.0, 0.0, 0.0);
                *flat.image.get(i, y) * (1.0 - 0.6 * f) + red * (0.6 * f)
            }
        }
    });
    std::fs::create_dir_all(out)?;
    let path = out.join("novel-view.png");
    let options = ibl_io::WriteOptions {
        display: Display {
            exposure_stops: auto_exposure_stops(&flat.image),
            curve: ToneCurve::AcesFilmic,
        },
        ..ibl_io::WriteOptions::default()
    };
    ibl_io::write_image(&path, &strip, &options)?;
    println!("wrote {}", path.display());
    Ok(())
}

//! The demo's work on one probe: its statistics and tone-mapped preview, the probe in every
//! mapping (EXR plus preview) with the power a round trip back to lat-long keeps, its exact and
//! SH9 irradiance maps with SH9's error, and its dominant light.

use std::path::Path;

use ibl_core::FramePreset;
use ibl_core::glam::Mat3;
use ibl_core::tonemap::{Display, ToneCurve, auto_exposure_stops};
use ibl_io::WriteOptions;
use ibl_mapping::{CubeLayout, Mapping};
use serde::Serialize;

use crate::demo_paths::relative;
use crate::envmap_files::{self, EnvMapping};
use crate::error::Result;
use crate::info::{Info, describe};

/// The mappings the demo shows each probe in, with their file stems.
pub fn demo_mappings() -> Vec<(&'static str, EnvMapping)> {
    vec![
        ("angular", EnvMapping::Single(Mapping::Angular)),
        ("mirror-ball", EnvMapping::Single(Mapping::MirrorBall)),
        (
            "cube-hcross",
            EnvMapping::Single(Mapping::Cube(CubeLayout::HorizontalCross)),
        ),
        (
            "cube-vcross",
            EnvMapping::Single(Mapping::Cube(CubeLayout::VerticalCross)),
        ),
        (
            "cube-strip",
            EnvMapping::Single(Mapping::Cube(CubeLayout::HorizontalStrip)),
        ),
        ("cube-faces", EnvMapping::CubeFaces),
        (
            "fisheye-180",
            EnvMapping::Single(Mapping::Fisheye { fov_deg: 180.0 }),
        ),
        (
            "dual-fisheye-200",
            EnvMapping::Single(Mapping::DualFisheye { fov_deg: 200.0 }),
        ),
    ]
}

/// One mapping of one probe in the summary.
#[derive(Clone, Debug, Serialize)]
pub struct MappingResult {
    /// The mapping's name.
    pub mapping: String,
    /// Its EXR file(s), relative to the demo folder.
    pub files: Vec<String>,
    /// Its preview, relative to the demo folder.
    pub preview: String,
    /// Relative change of total power (mean over channels) after converting back to lat-long,
    /// percent; `None` for mappings that do not cover the whole sphere.
    pub round_trip_power_change_pct: Option<f64>,
}

/// A probe's irradiance maps (exact and SH9) and its dominant light.
#[derive(Clone, Debug, Serialize)]
pub struct IrradianceResult {
    /// Preview of the exact irradiance map, relative to the demo folder.
    pub exact_preview: String,
    /// Preview of the SH9 irradiance map, relative to the demo folder.
    pub sh9_preview: String,
    /// SH9 against the exact ground truth on 20000 normals, per cent of the mean irradiance.
    pub sh9_mean_err_pct: f64,
    /// The largest SH9 error, per cent of the mean irradiance.
    pub sh9_max_err_pct: f64,
    /// The dominant light (CONVENTIONS frame) and the confidence that it is one compact source.
    pub sun_direction: [f64; 3],
    /// Confidence that the dominant light is one compact source, 0 to 1.
    pub sun_confidence: f64,
}

/// One probe in the summary.
#[derive(Clone, Debug, Serialize)]
pub struct ProbeResult {
    /// The probe's name (its file stem).
    pub name: String,
    /// Its statistics.
    pub info: Info,
    /// Its tone-mapped preview, relative to the demo folder.
    pub preview: String,
    /// The probe in every mapping.
    pub mappings: Vec<MappingResult>,
    /// Its irradiance maps and dominant light.
    pub irradiance: IrradianceResult,
}

/// The demo's work on one probe, into `out/<name>/`; `step` is called after the preview, each
/// mapping and the irradiance maps.
pub fn demo_probe(
    path: &Path,
    name: &str,
    out: &Path,
    mappings: &[(&'static str, EnvMapping)],
    step: &mut dyn FnMut(),
) -> Result<ProbeResult> {
    let env = envmap_files::load(path, Some(EnvMapping::Single(Mapping::LatLong)))?;
    let info = describe(&env, false, FramePreset::Gltf, &path.display().to_string());
    let dir = out.join(name);
    ibl_io::create_dir_all(&dir)?;
    let display = Display {
        exposure_stops: auto_exposure_stops(&env.image),
        curve: ToneCurve::Reinhard,
    };
    let preview_opts = WriteOptions {
        display,
        ..Default::default()
    };
    let preview = dir.join("latlong.png");
    ibl_io::write_image(&preview, &env.image, &preview_opts)?;
    // Serialising plain data to a string cannot fail.
    let info_json = serde_json::to_string_pretty(&info).unwrap_or_default();
    ibl_io::write_atomically(&dir.join("info.json"), info_json.as_bytes())?;
    step();

    let power_before = ibl_mapping::power(&env.image, Mapping::LatLong);
    let inputs = [path];
    let mut results = Vec::new();
    for (stem, to) in mappings {
        let m = to.in_memory();
        let (w, h) = m.default_size_for(Mapping::LatLong, env.image.width(), env.image.height());
        let converted = ibl_mapping::resample(
            &env.image,
            Mapping::LatLong,
            m,
            w,
            h,
            Mat3::IDENTITY,
            &|_, _| {},
        )?;
        let files = envmap_files::save(
            &dir.join(format!("{stem}.exr")),
            &converted,
            *to,
            &WriteOptions::default(),
            &inputs,
        )?;
        let preview_path = dir.join(format!("{stem}.png"));
        ibl_io::write_image(&preview_path, &converted, &preview_opts)?;
        let covers_sphere = !matches!(m, Mapping::Fisheye { fov_deg } if fov_deg < 360.0);
        let change = if covers_sphere {
            let back = ibl_mapping::resample(
                &converted,
                m,
                Mapping::LatLong,
                env.image.width(),
                env.image.height(),
                Mat3::IDENTITY,
                &|_, _| {},
            )?;
            let after = ibl_mapping::power(&back, Mapping::LatLong);
            Some(relative_change_pct(&power_before, &after))
        } else {
            None
        };
        results.push(MappingResult {
            mapping: to.name(),
            files: files.iter().map(|p| relative(out, p)).collect(),
            preview: relative(out, &preview_path),
            round_trip_power_change_pct: change,
        });
        step();
    }
    let irradiance = demo_irradiance(&env.image, &dir, out, path)?;
    step();
    Ok(ProbeResult {
        name: name.to_string(),
        info,
        preview: relative(out, &preview),
        mappings: results,
        irradiance,
    })
}

/// Width of the demo's irradiance maps (irradiance is smooth).
const IRRADIANCE_MAP_WIDTH: usize = 256;

/// The exact and SH9 irradiance maps of a probe (EXR and a preview each, both previews at the
/// exact map's exposure so they compare), SH9's error and the dominant light.
fn demo_irradiance(
    image: &ibl_core::Image<ibl_core::Rgb>,
    dir: &Path,
    out: &Path,
    input: &Path,
) -> Result<IrradianceResult> {
    let (w, h) = Mapping::LatLong.size_for_width(IRRADIANCE_MAP_WIDTH);
    let ll = ibl_core::LatLong::new(w, h);
    let dirs: Vec<ibl_core::glam::DVec3> = (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| ll.pixel_dir64(i, j))
        .collect();
    let sh9 = ibl_sh::project_latlong(image, 3)?.irradiance(ibl_sh::Window::None);
    let to_image = |e: Vec<[f64; 3]>| {
        let mut img = ibl_core::Image::filled(w, h, ibl_core::Rgb::ZERO);
        for (k, v) in e.into_iter().enumerate() {
            *img.get_mut(k % w, k / w) = ibl_core::Rgb::new(v[0] as f32, v[1] as f32, v[2] as f32);
        }
        img
    };
    let rows = ibl_core::RowIrradiance::new(image);
    let exact = to_image(rows.irradiance(&dirs));
    let approx = to_image(sh9.eval_many(&dirs));
    let display = Display {
        exposure_stops: auto_exposure_stops(&exact),
        curve: ToneCurve::Reinhard,
    };
    let preview_opts = WriteOptions {
        display,
        ..Default::default()
    };
    let mut previews = Vec::new();
    for (stem, img) in [("irradiance-exact", &exact), ("irradiance-sh9", &approx)] {
        envmap_files::save(
            &dir.join(format!("{stem}.exr")),
            img,
            EnvMapping::Single(Mapping::LatLong),
            &WriteOptions::default(),
            &[input],
        )?;
        let p = dir.join(format!("{stem}.png"));
        ibl_io::write_image(&p, img, &preview_opts)?;
        previews.push(relative(out, &p));
    }
    let normals = ibl_core::fibonacci_normals(ibl_core::fibonacci::DEFAULT_NORMAL_COUNT);
    let truth = rows.irradiance(&normals);
    let err = ibl_metrics::IrradianceError::between(&truth, &sh9.eval_many(&normals));
    let sun = ibl_extract::dominant_light(image)?;
    Ok(IrradianceResult {
        exact_preview: previews[0].clone(),
        sh9_preview: previews[1].clone(),
        sh9_mean_err_pct: err.mean_err_pct,
        sh9_max_err_pct: err.max_err_pct,
        sun_direction: sun.direction.to_array(),
        sun_confidence: sun.confidence,
    })
}

fn relative_change_pct(before: &[f64; 3], after: &[f64; 3]) -> f64 {
    let mut sum = 0.0;
    for c in 0..3 {
        if before[c] > 0.0 {
            sum += (after[c] - before[c]) / before[c];
        }
    }
    100.0 * sum / 3.0
}

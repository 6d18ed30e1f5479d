//! `ibl demo`: the main job on the bundled probes, with no arguments needed.
//!
//! It describes every bundled probe, writes a tone-mapped preview, shows each probe in every
//! mapping (EXR plus preview), converts each back to lat-long and reports how much power the round
//! trip kept, and writes its irradiance map exact and as SH9 with SH9's error and the probe's
//! dominant light. Then it runs the comparison of `ibl eval` on the same probes (every extraction
//! method, SH9 alone and LightGen lights with an SH9 ambient, N = 1 to 128, 20000 scoring normals)
//! into `eval/`, and renders the example scenes (`renders/`, see [`super::demo_render`]).
//! Everything lands in one folder with
//! an `index.html` to look at and a `summary.json` for scripts.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use ibl_core::FramePreset;
use ibl_core::glam::Mat3;
use ibl_core::rgb::Rgb64;
use ibl_io::{Display, ToneCurve, WriteOptions};
use ibl_mapping::{CubeLayout, Mapping};
use serde::Serialize;

use crate::cmd::{demo_render, demo_view, eval, info};
use crate::envmap_files::{self, MappingArg};
use crate::failure::usage;
use crate::progress;

/// Arguments of `ibl demo`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl demo                       writes ./demo-out (open demo-out/index.html)
  ibl demo --out /tmp/ibl-demo
  ibl demo --probes my-probes/   every .exr/.hdr lat-long probe in a folder")]
pub struct DemoArgs {
    /// Folder for all outputs (created if missing).
    #[arg(long, default_value = "demo-out", value_name = "DIR")]
    pub out: PathBuf,
    /// Folder of lat-long probes to use (default: the bundled `assets/probes`).
    #[arg(long, value_name = "DIR")]
    pub probes: Option<PathBuf>,
    /// Folder of scene files to render (default: the bundled `assets/scenes`).
    #[arg(long, value_name = "DIR")]
    pub scenes: Option<PathBuf>,
}

/// Light counts of the demo's comparison: the powers of two 1 to 128. `ibl eval` also sweeps 256 by
/// default; the demo leaves it out because irradiance optimisation alone needs about 35 s per
/// probe there (release build, 2 cores), three minutes for the five bundled probes, against about
/// 15 s per probe for all of 1 to 128.
const DEMO_EVAL_COUNTS: [usize; 8] = [1, 2, 4, 8, 16, 32, 64, 128];

/// The demo's comparison: every light method, SH9 alone and LightGen lights with an SH9 ambient.
fn demo_methods() -> Vec<ibl_extract::ModelSpec> {
    let mut methods: Vec<ibl_extract::ModelSpec> = ibl_extract::Method::ALL
        .map(ibl_extract::ModelSpec::from)
        .to_vec();
    methods.push(ibl_extract::ModelSpec::Sh { bands: 3 });
    methods.push(ibl_extract::ModelSpec::Hybrid {
        lights: ibl_extract::LightSource::Method(ibl_extract::Method::LightGen),
        bands: 3,
    });
    methods
}

/// The mappings the demo shows each probe in, with their file stems.
fn demo_mappings() -> Vec<(&'static str, MappingArg)> {
    vec![
        ("angular", MappingArg::Single(Mapping::Angular)),
        ("mirror-ball", MappingArg::Single(Mapping::MirrorBall)),
        (
            "cube-hcross",
            MappingArg::Single(Mapping::Cube(CubeLayout::HorizontalCross)),
        ),
        (
            "cube-vcross",
            MappingArg::Single(Mapping::Cube(CubeLayout::VerticalCross)),
        ),
        (
            "cube-strip",
            MappingArg::Single(Mapping::Cube(CubeLayout::HorizontalStrip)),
        ),
        ("cube-faces", MappingArg::CubeFaces),
        (
            "fisheye-180",
            MappingArg::Single(Mapping::Fisheye { fov_deg: 180.0 }),
        ),
        (
            "dual-fisheye-200",
            MappingArg::Single(Mapping::DualFisheye { fov_deg: 200.0 }),
        ),
    ]
}

/// One mapping of one probe in the summary.
#[derive(Serialize)]
struct MappingResult {
    mapping: String,
    files: Vec<String>,
    preview: String,
    /// Relative change of total power (mean over channels) after converting back to lat-long,
    /// percent; `None` for mappings that do not cover the whole sphere.
    round_trip_power_change_pct: Option<f64>,
}

/// A probe's irradiance maps (exact and SH9) and its dominant light.
#[derive(Serialize)]
struct IrradianceResult {
    exact_preview: String,
    sh9_preview: String,
    /// SH9 against the exact ground truth on 20000 normals, per cent of the mean irradiance.
    sh9_mean_err_pct: f64,
    sh9_max_err_pct: f64,
    /// The dominant light (CONVENTIONS frame) and the confidence that it is one compact source.
    sun_direction: [f64; 3],
    sun_confidence: f64,
}

/// One probe in the summary.
#[derive(Serialize)]
struct ProbeResult {
    name: String,
    info: info::Info,
    preview: String,
    mappings: Vec<MappingResult>,
    irradiance: IrradianceResult,
}

/// The bundled `assets` folder: beside the binary's source tree, else in the current folder.
pub fn assets_dir() -> PathBuf {
    let built_in = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    if built_in.is_dir() {
        built_in
    } else {
        PathBuf::from("assets")
    }
}

/// The bundled probes, `assets/probes`.
fn default_probe_dir() -> PathBuf {
    assets_dir().join("probes")
}

/// Lat-long probes in a folder: `.exr` files (or `.hdr` where no `.exr` of that name exists).
fn list_probes(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let entries =
        std::fs::read_dir(dir).with_context(|| format!("{}: cannot list probes", dir.display()))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            matches!(
                ibl_io::ImageFormat::from_path(p),
                Some(ibl_io::ImageFormat::Exr | ibl_io::ImageFormat::Hdr)
            )
        })
        .collect();
    files.sort();
    let exr_stems: Vec<PathBuf> = files
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")))
        .map(|p| p.with_extension(""))
        .collect();
    files.retain(|p| {
        p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
            || !exr_stems.contains(&p.with_extension(""))
    });
    if files.is_empty() {
        return Err(usage(format!(
            "{}: no .exr or .hdr probes found",
            dir.display()
        )));
    }
    Ok(files)
}

/// Runs `ibl demo`.
pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    let probe_dir = args.probes.clone().unwrap_or_else(default_probe_dir);
    let probes = list_probes(&probe_dir)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("{}: cannot create output folder", args.out.display()))?;
    let mappings = demo_mappings();
    // Per probe: the preview, each mapping, the irradiance maps.
    let bar = progress::bar("demo", (probes.len() * (mappings.len() + 2)) as u64);
    let mut results = Vec::new();
    for path in &probes {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        bar.set_message(name.clone());
        let result = demo_probe(path, &name, &args.out, &mappings, &bar)
            .with_context(|| format!("demo on {}", path.display()))?;
        results.push(result);
    }
    bar.finish_and_clear();
    let settings = eval::EvalSettings::new(
        demo_methods(),
        DEMO_EVAL_COUNTS.to_vec(),
        ibl_core::fibonacci::DEFAULT_NORMAL_COUNT,
        ibl_extract::ExtractOptions::default().seed,
        None,
    )?;
    let report = eval::evaluate(&probes, &settings, &args.out.join(EVAL_DIR))
        .context("comparing the light extraction methods")?;
    let scene_dir = args
        .scenes
        .clone()
        .unwrap_or_else(demo_render::default_scene_dir);
    let renders = demo_render::demo_renders(&scene_dir, &args.out)?;
    let views = demo_view::demo_views(&scene_dir, &args.out)?;
    write_summary(&args.out, &results, &report, &renders, &views)?;
    print_summary(&args.out, &results);
    println!();
    eval::print_lights_needed(&report);
    println!(
        "  {}/{EVAL_DIR}/report.md    the comparison: tables, plots, spheres, overlays",
        args.out.display()
    );
    println!(
        "  {}/{}/report.md the example scenes rendered, lights scored against the reference",
        args.out.display(),
        demo_render::RENDER_DIR
    );
    match &views.skipped {
        None => println!(
            "  {}/{}/             the example scenes in the real-time viewer, with timings",
            args.out.display(),
            demo_view::VIEW_DIR
        ),
        Some(why) => println!("  viewer frames skipped: {why}"),
    }
    Ok(())
}

/// Sub-folder of the comparison report.
const EVAL_DIR: &str = "eval";

fn demo_probe(
    path: &Path,
    name: &str,
    out: &Path,
    mappings: &[(&'static str, MappingArg)],
    bar: &indicatif::ProgressBar,
) -> anyhow::Result<ProbeResult> {
    let env = envmap_files::load(path, Some(MappingArg::Single(Mapping::LatLong)))?;
    let info = info::describe(&env, false, FramePreset::Gltf, &path.display().to_string());
    let dir = out.join(name);
    std::fs::create_dir_all(&dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    let display = Display {
        exposure_stops: ibl_io::tonemap::auto_exposure_stops(&env.image),
        curve: ToneCurve::Reinhard,
    };
    let preview_opts = WriteOptions {
        display,
        ..Default::default()
    };
    let preview = dir.join("latlong.png");
    ibl_io::write_image(&preview, &env.image, &preview_opts)?;
    std::fs::write(dir.join("info.json"), serde_json::to_string_pretty(&info)?)
        .with_context(|| format!("{}: cannot write info.json", dir.display()))?;
    bar.inc(1);

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
        bar.inc(1);
    }
    let irradiance = demo_irradiance(&env.image, &dir, out, path)?;
    bar.inc(1);
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
) -> anyhow::Result<IrradianceResult> {
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
        exposure_stops: ibl_io::tonemap::auto_exposure_stops(&exact),
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
            MappingArg::Single(Mapping::LatLong),
            &WriteOptions::default(),
            &[input],
        )?;
        let p = dir.join(format!("{stem}.png"));
        ibl_io::write_image(&p, img, &preview_opts)?;
        previews.push(relative(out, &p));
    }
    let normals = ibl_core::fibonacci_normals(ibl_core::fibonacci::DEFAULT_NORMAL_COUNT);
    let truth = rows.irradiance(&normals);
    let err = ibl_core::IrradianceError::between(&truth, &sh9.eval_many(&normals));
    let sun = ibl_extract::dominant_light(image)?;
    Ok(IrradianceResult {
        exact_preview: previews[0].clone(),
        sh9_preview: previews[1].clone(),
        sh9_mean_err_pct: err.mean_err_pct,
        sh9_max_err_pct: err.max_err_pct,
        sun_direction: sun.direction,
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

/// `p` relative to `base` (for links in `index.html`).
pub fn relative(base: &Path, p: &Path) -> String {
    p.strip_prefix(base).unwrap_or(p).display().to_string()
}

/// The comparison section of `index.html`: links, the average plot and the lights-needed table.
fn eval_html(report: &ibl_eval::Report) -> String {
    let largest = report.counts.iter().copied().max().unwrap_or(0);
    let counts: Vec<String> = report.counts.iter().map(usize::to_string).collect();
    let f = &report.files;
    let mut html = format!(
        "<h1 id=eval>Light extraction methods compared</h1><p>Every method at N = {}, scored on {} \
         Fibonacci normals against the exact irradiance (Madsen &amp; Laursen 2006, section 5): \
         <a href=\"{EVAL_DIR}/{}\">report.md</a> &middot; <a href=\"{EVAL_DIR}/{}\">report.json</a> \
         &middot; <a href=\"{EVAL_DIR}/{}\">report.csv</a>. Fitted methods: {}.</p>",
        counts.join(", "),
        report.normals,
        f.markdown,
        f.json,
        f.csv,
        report.fit_normals_note
    );
    html.push_str(
        "<table><tr><th>lights needed (average)</th><th>mean_err &le; 1 %</th>\
         <th>mean_err &le; 5 %</th><th>max_err &le; 1 %</th><th>max_err &le; 5 %</th></tr>",
    );
    for x in ibl_eval::LightsNeeded::average(report) {
        let [a, b, c, d] = x.cells(largest).map(|c| c.replace('>', "&gt;"));
        let _ = write!(
            html,
            "<tr><td>{}</td><td>{a}</td><td>{b}</td><td>{c}</td><td>{d}</td></tr>",
            x.method
        );
    }
    html.push_str("</table>");
    for p in &f.plots {
        let _ = write!(
            html,
            "<figure><a href=\"{EVAL_DIR}/{svg}\"><img class=wide src=\"{EVAL_DIR}/{png}\"></a>\
             <figcaption>{}</figcaption></figure>",
            p.probe.as_deref().unwrap_or("average over the probes"),
            svg = p.svg,
            png = p.png
        );
    }
    for x in &f.figures {
        for (what, path) in [("spheres", &x.sphere), ("overlay", &x.overlay)] {
            if let Some(path) = path {
                let _ = write!(
                    html,
                    "<figure><a href=\"{EVAL_DIR}/{path}\"><img src=\"{EVAL_DIR}/{path}\"></a>\
                     <figcaption>{} {} N={} {what}</figcaption></figure>",
                    x.probe, x.method, x.n
                );
            }
        }
    }
    html
}

fn write_summary(
    out: &Path,
    results: &[ProbeResult],
    report: &ibl_eval::Report,
    renders: &[demo_render::SceneResult],
    views: &demo_view::ViewSection,
) -> anyhow::Result<()> {
    #[derive(Serialize)]
    struct Summary<'a> {
        probes: &'a [ProbeResult],
        renders: &'a [demo_render::SceneResult],
        views: &'a demo_view::ViewSection,
    }
    let json = serde_json::to_string_pretty(&Summary {
        probes: results,
        renders,
        views,
    })?;
    std::fs::write(out.join("summary.json"), json)
        .with_context(|| format!("{}: cannot write summary.json", out.display()))?;
    let mut html = String::from(
        "<!doctype html><meta charset=utf-8><title>iblkit demo</title>\
         <style>body{font-family:sans-serif;background:#222;color:#ddd}img{max-height:220px;margin:4px;border:1px solid #444}\
         figure{display:inline-block;margin:4px}figcaption{font-size:12px}td,th{padding:2px 8px;text-align:right}\
         img.wide{max-height:none;width:640px}a{color:#9cf}</style>\
         <h1>iblkit demo</h1>",
    );
    let _ = write!(
        html,
        "<p>Every probe in every mapping below; then <a href=\"#eval\">the light extraction \
         methods compared</a> (<a href=\"{EVAL_DIR}/{}\">report.md</a>).</p>",
        report.files.markdown
    );
    for r in results {
        let i = &r.info;
        let _ = write!(
            html,
            "<h2>{}</h2><p>{} x {} {} &middot; power {:.4e} {:.4e} {:.4e} &middot; dynamic range {:.1} stops \
             &middot; brightest ({:+.3}, {:+.3}, {:+.3}) &middot; {} negative / {} NaN-Inf values clamped</p>",
            r.name,
            i.width,
            i.height,
            i.format,
            i.power[0],
            i.power[1],
            i.power[2],
            i.dynamic_range.stops,
            i.brightest.direction[0],
            i.brightest.direction[1],
            i.brightest.direction[2],
            i.negative_values,
            i.nonfinite_values
        );
        let _ = write!(
            html,
            "<figure><img src=\"{}\"><figcaption>latlong</figcaption></figure>",
            r.preview
        );
        let irr = &r.irradiance;
        let _ = write!(
            html,
            "<figure><img src=\"{}\"><figcaption>irradiance, exact</figcaption></figure>\
             <figure><img src=\"{}\"><figcaption>irradiance, SH9 (mean {:.2} %, max {:.1} %; \
             sun confidence {:.2})</figcaption></figure>",
            irr.exact_preview,
            irr.sh9_preview,
            irr.sh9_mean_err_pct,
            irr.sh9_max_err_pct,
            irr.sun_confidence
        );
        for m in &r.mappings {
            let change = m
                .round_trip_power_change_pct
                .map(|c| format!(" (round trip {c:+.3} % power)"))
                .unwrap_or_default();
            let _ = write!(
                html,
                "<figure><img src=\"{}\"><figcaption>{}{change}</figcaption></figure>",
                m.preview, m.mapping
            );
        }
    }
    html.push_str(&eval_html(report));
    html.push_str(&demo_render::renders_html(renders));
    html.push_str(&demo_view::views_html(views));
    std::fs::write(out.join("index.html"), html)
        .with_context(|| format!("{}: cannot write index.html", out.display()))?;
    Ok(())
}

fn print_summary(out: &Path, results: &[ProbeResult]) {
    println!(
        "{:<12} {:>9} {:>8} {:>12}  round-trip power change per mapping (%)",
        "probe", "size", "stops", "luminance"
    );
    for r in results {
        let i = &r.info;
        let [pr, pg, pb] = i.power;
        let power_lum = Rgb64 {
            r: pr,
            g: pg,
            b: pb,
        }
        .luminance();
        let changes: Vec<String> = r
            .mappings
            .iter()
            .filter_map(|m| {
                m.round_trip_power_change_pct
                    .map(|c| format!("{} {c:+.3}", m.mapping))
            })
            .collect();
        println!(
            "{:<12} {:>9} {:>8.1} {:>12.4e}  {}",
            r.name,
            format!("{}x{}", i.width, i.height),
            i.dynamic_range.stops,
            power_lum,
            changes.join(", ")
        );
    }
    println!();
    println!("outputs in {}/", out.display());
    println!(
        "  {}/index.html     every probe in every mapping, tone-mapped",
        out.display()
    );
    println!("  {}/summary.json   the same as data", out.display());
    println!(
        "  {}/<probe>/       info.json, latlong.png, <mapping>.exr and .png",
        out.display()
    );
}

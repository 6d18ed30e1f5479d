//! The comparison sweep and its outputs (`ibl_eval::{sweep, report, plot, sphere_image}`): the
//! `report.json` schema, the CSV and markdown text, the SVG and PNG charts and the sphere figure,
//! on a small synthetic probe (all in memory, fast) and on the bundled `sky` probe, with median
//! cut (a power-of-two-only method, so N = 3 must give a `skipped` row).

#![allow(clippy::unwrap_used)] // tests may panic

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use ibl_core::{Image, LatLong, Rgb, RowIrradiance};
use ibl_eval::sweep::Stage;
use ibl_eval::{
    ErrorChart, PLOT_SIZE, ProbeInput, Report, SphereField, SphereFigure, Status, SweepOptions,
    SweepProgress, render_png, render_svg, sweep,
};
use ibl_extract::ExtractOptions;
use ibl_light::Method;

/// A 64 x 32 lat-long probe: a dim sky gradient, a dark ground and a bright 2 x 2 "sun".
fn synthetic_probe() -> Image<Rgb> {
    let ll = LatLong::new(64, 32);
    Image::from_fn_par(64, 32, |i, j| {
        let d = ll.pixel_dir64(i, j);
        if (20..22).contains(&i) && (8..10).contains(&j) {
            Rgb::new(400.0, 380.0, 300.0)
        } else if d.y > 0.0 {
            Rgb::new(0.4, 0.6, 1.0 + d.y as f32)
        } else {
            Rgb::new(0.2, 0.15, 0.1)
        }
    })
}

fn options(counts: Vec<usize>, keep: Option<usize>) -> SweepOptions {
    SweepOptions {
        methods: vec![Method::MedianCut.into()],
        counts,
        normals: 2000,
        extract: ExtractOptions::default(),
        keep_sets_at: keep,
    }
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn run_synthetic() -> (ibl_eval::Sweep, Vec<SweepProgress>) {
    let probe = synthetic_probe();
    let input = ProbeInput {
        name: "synthetic",
        sha256: "00",
        image: &probe,
    };
    let seen = Mutex::new(Vec::new());
    let record = |p: SweepProgress| seen.lock().unwrap().push(p);
    let s = sweep(&[input], &options(vec![1, 2, 3, 4], Some(4)), &record).unwrap();
    (s, seen.into_inner().unwrap())
}

#[test]
fn report_json_has_every_field_and_a_skipped_row() {
    let (s, _) = run_synthetic();
    let v = serde_json::to_value(&s.report).unwrap();
    assert_eq!(v["format"], "iblkit.eval/1");
    assert!(v["tool_version"].is_string());
    assert_eq!(v["normals"], 2000);
    assert!(v["fit_normals_note"].as_str().unwrap().contains("normals"));
    for k in [
        "mean_err_pct",
        "max_err_pct",
        "rel_mean_err_pct",
        "rel_max_err_pct",
    ] {
        assert!(v["metrics"][k].is_string(), "{k}");
    }
    let p = &v["probes"][0];
    assert_eq!(p["name"], "synthetic");
    assert_eq!(p["sha256"], "00");
    assert_eq!(
        (p["width"].as_u64(), p["height"].as_u64()),
        (Some(64), Some(32))
    );
    assert!(p["ground_truth_seconds"].as_f64().unwrap() >= 0.0);
    let rows = p["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4);
    for r in rows {
        for k in [
            "method",
            "n",
            "lights",
            "mean_err_pct",
            "max_err_pct",
            "rel_mean_err_pct",
            "rel_max_err_pct",
            "seconds",
            "status",
            "parameters",
        ] {
            assert!(r.get(k).is_some(), "row lacks {k}: {r}");
        }
        if r["n"] == 3 {
            assert_eq!(r["status"], "skipped");
            assert!(r["reason"].as_str().unwrap().contains("power of two"));
            assert!(r["mean_err_pct"].is_null());
        } else {
            assert_eq!(r["status"], "ok", "{r}");
            assert!(r.get("reason").is_none());
            assert!(r["mean_err_pct"].as_f64().unwrap() > 0.0);
            assert_eq!(r["lights"], r["n"]);
            assert!(r["parameters"]["splits"].is_number());
            // Median cut is a region method: power is conserved to rounding.
            assert!(r["power_change_pct"].as_f64().unwrap().abs() < 1e-9, "{r}");
        }
    }
    // Averages exist where every probe ran: N = 1, 2, 4 (not 3).
    let ns: Vec<u64> = v["averages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["n"].as_u64().unwrap())
        .collect();
    assert_eq!(ns, vec![1, 2, 4]);
    // More lights, less error (median cut on this probe).
    let err = |n: usize| {
        s.report.probes[0]
            .rows
            .iter()
            .find(|r| r.n == n)
            .unwrap()
            .mean_err_pct
            .unwrap()
    };
    assert!(err(4) < err(1), "{} vs {}", err(4), err(1));
    // The report reads back.
    let back: Report = serde_json::from_value(v).unwrap();
    assert_eq!(back, s.report);
}

#[test]
fn progress_counts_every_step_and_sets_are_kept_at_the_figure_n() {
    let (s, seen) = run_synthetic();
    let total = 1 + 4;
    assert_eq!(seen.len(), total + 1);
    assert_eq!(seen[0].stage, Stage::GroundTruth);
    let last = seen.last().unwrap();
    assert_eq!(
        (last.done, last.total, last.stage),
        (total, total, Stage::Finished)
    );
    assert!(seen.windows(2).all(|w| w[0].done <= w[1].done));
    assert_eq!(s.sets.len(), 1);
    assert_eq!(
        (s.sets[0].n, s.sets[0].method),
        (4, Method::MedianCut.into())
    );
    assert_eq!(s.sets[0].set.lights.len(), 4);
}

#[test]
fn csv_and_markdown_cover_every_row() {
    let (s, _) = run_synthetic();
    let csv = ibl_eval::report::csv(&s.report);
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], ibl_eval::report::CSV_HEADER);
    assert_eq!(lines.len(), 1 + 4);
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("synthetic,median-cut,3,,") && l.ends_with(",skipped"))
    );
    for l in &lines[1..] {
        assert_eq!(l.split(',').count(), 10, "{l}");
    }
    let md = ibl_eval::report::markdown(&s.report);
    assert!(md.contains("median-cut"));
    assert!(md.contains("mean_err <= 1 %") && md.contains("max_err <= 5 %"));
    assert!(md.contains(&s.report.fit_normals_note));
    assert!(md.contains("skipped"));
}

#[test]
fn charts_render_as_svg_and_png() {
    let (s, _) = run_synthetic();
    for chart in [
        ErrorChart::average(&s.report),
        ErrorChart::for_probe(&s.report, 0).unwrap(),
    ] {
        let svg = render_svg(&chart, PLOT_SIZE).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..40]);
        assert!(svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("median-cut"));
        let png = render_png(&chart, PLOT_SIZE).unwrap();
        assert_eq!(
            (png.width(), png.height()),
            (PLOT_SIZE.0 as usize, PLOT_SIZE.1 as usize)
        );
        // Something besides the white background was drawn.
        assert!(png.pixels().iter().filter(|p| **p != [255; 3]).count() > 5000);
        assert!(ibl_io::ldr::encode_png(&png).is_ok());
    }
    assert!(ErrorChart::for_probe(&s.report, 1).is_none());
}

#[test]
fn chart_with_no_data_still_renders() {
    let (mut s, _) = run_synthetic();
    for r in &mut s.report.probes[0].rows {
        r.status = Status::Failed;
    }
    s.report.averages.clear();
    let chart = ErrorChart::for_probe(&s.report, 0).unwrap();
    assert!(render_svg(&chart, PLOT_SIZE).unwrap().contains("no data"));
    assert!(render_png(&chart, (400, 300)).is_ok());
}

#[test]
fn sphere_figure_of_the_kept_set() {
    let (s, _) = run_synthetic();
    let probe = synthetic_probe();
    let truth = SphereField::ground_truth(&RowIrradiance::new(&probe), 64);
    let approx = SphereField::of_light_set(&s.sets[0].set, 64);
    let labels = SphereFigure {
        title: "synthetic".into(),
        subtitle: "median cut".into(),
        approx_label: "median-cut, N = 4".into(),
        error_range_pct: 10.0,
    };
    let img = ibl_eval::sphere_image::figure(
        &truth,
        &approx,
        s.report.probes[0].mean_irradiance,
        &labels,
    )
    .unwrap();
    assert!(img.width() > 3 * 64 && img.height() > 2 * 64);
    let small = SphereField::ground_truth(&RowIrradiance::new(&probe), 32);
    assert!(ibl_eval::sphere_image::figure(&truth, &small, [1.0; 3], &labels).is_err());
}

#[test]
fn bundled_sky_probe_with_median_cut() {
    let path = repo().join("assets/probes/sky.exr");
    let probe = ibl_io::read_image(&path).unwrap().image;
    let sha = ibl_io::light_file::sha256_file(&path).unwrap();
    let input = ProbeInput {
        name: "sky",
        sha256: &sha,
        image: &probe,
    };
    let s = sweep(&[input], &options(vec![1, 3, 16], Some(16)), &|_| {}).unwrap();
    let p = &s.report.probes[0];
    assert_eq!((p.width, p.height, p.sha256.len()), (512, 256, 64));
    let status: Vec<Status> = p.rows.iter().map(|r| r.status).collect();
    assert_eq!(status, vec![Status::Ok, Status::Skipped, Status::Ok]);
    let e16 = p.rows[2].mean_err_pct.unwrap();
    let e1 = p.rows[0].mean_err_pct.unwrap();
    assert!(e16 < e1 && e16 < 10.0, "median cut 16 on sky: {e16} %");
    assert_eq!(s.sets.len(), 1);
    let md = ibl_eval::report::markdown(&s.report);
    assert!(md.contains("| sky | median-cut |"));
}

#[test]
fn unusable_options_are_refused() {
    let probe = synthetic_probe();
    let input = ProbeInput {
        name: "p",
        sha256: "",
        image: &probe,
    };
    let mut o = options(vec![1], None);
    o.normals = 0;
    assert!(sweep(&[input], &o, &|_| {}).is_err());
    assert!(sweep(&[input], &options(vec![0], None), &|_| {}).is_err());
    assert!(sweep(&[], &options(vec![1], None), &|_| {}).is_err());
}

#[test]
fn fast_paths_are_scored_against_the_ground_truth() {
    let (s, _) = run_synthetic();
    let paths = &s.report.probes[0].fast_paths;
    let names: Vec<&str> = paths.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["blocks-64x32", "sh3", "sh9", "sh21"]);
    // More bands, less error; every path is scored with finite numbers.
    assert!(paths[1].mean_err_pct > paths[2].mean_err_pct);
    assert!(paths[2].mean_err_pct > paths[3].mean_err_pct);
    assert!(
        paths
            .iter()
            .all(|p| p.max_err_pct.is_finite() && p.seconds >= 0.0)
    );
    let md = ibl_eval::report::markdown(&s.report);
    assert!(md.contains("## Fast irradiance paths against the exact ground truth"));
    assert!(md.contains("| sh3 |"));
}

#[test]
fn markdown_counts_converged_fits() {
    let probe = synthetic_probe();
    let input = ProbeInput {
        name: "synthetic",
        sha256: "00",
        image: &probe,
    };
    let mut o = options(vec![1, 2], None);
    o.methods = vec![Method::IrradianceOptimization.into()];
    let s = sweep(&[input], &o, &|_| {}).unwrap();
    let md = ibl_eval::report::markdown(&s.report);
    assert!(
        md.contains("- Fitted runs that met their convergence test: 2 of 2."),
        "{md}"
    );
}

//! Light sets judged by the images they render (Madsen & Laursen 2006, section 5, where the
//! methods are compared on renders with shadows as well as on irradiance): for one scene, the
//! path-traced reference, then for every method and light count N a render in the `lights` mode,
//! each scored against the reference by relative MSE (mean of `(a - b)^2 / (b^2 + 0.01)` over
//! pixels and channels) and by FLIP ([`ibl_metrics::flip()`]).
//!
//! What is compared is the rendered local scene *with* the objects (ground, object and its
//! shadow, background where the camera sees no geometry), so every approximation is judged on
//! the light it puts on the real surfaces too. Both renders use the same number of bounces, so
//! with one bounce (the default) the study isolates what a light set gets wrong about direct
//! light and shadows. The reference's own Monte Carlo noise is measured by a second reference
//! with another seed: its relative MSE against the first (divided by two: each has that much
//! variance) is the floor under which no approximation can be judged (FLIP: the two references'
//! FLIP, as is).
//!
//! Cost: the reference (`W H spp_ref` paths) plus, per method and N, the extraction and
//! `W H spp` paths of `N` shadow rays each.

use std::time::Instant;

use ibl_core::{Image, Rgb};
use ibl_extract::{ExtractError, ExtractOptions, ModelSpec, build_model};
use ibl_metrics::{DifferenceError, FlipOptions, ImageDifference, flip};
use ibl_render::lighting::Lighting;
use ibl_render::{RenderError, RenderOutput, RenderSettings, render};
use ibl_scene::description::CompositeRule;
use ibl_scene::{Scene, ShadowKind};
use serde::Serialize;

use crate::plot::{Curve, CurvePoint, ErrorChart};

/// What to render and compare.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderStudySettings {
    /// Light models to compare (light methods or `sun`).
    pub methods: Vec<ModelSpec>,
    /// Light counts N (a method skips the counts it cannot make, e.g. median cut off powers of 2).
    pub counts: Vec<usize>,
    /// Output width (`None`: the scene's camera size).
    pub width: Option<u32>,
    /// Samples per pixel of the reference.
    pub reference_spp: u32,
    /// Samples per pixel of the light renders.
    pub lights_spp: u32,
    /// Surface vertices per path, the same in every render.
    pub bounces: u32,
    /// Shadows of the light renders.
    pub shadows: ShadowKind,
    /// Seed of every render and extraction.
    pub seed: u64,
}

/// One light render against the reference.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RenderStudyRow {
    /// Method name.
    pub method: String,
    /// Light count asked for.
    pub n: usize,
    /// Relative MSE against the reference.
    pub relative_mse: f64,
    /// RMSE against the reference (probe radiance units).
    pub rmse: f64,
    /// Mean FLIP against the reference, in `[0, 1]`.
    pub flip: f64,
    /// Seconds to extract the lights.
    pub seconds_extract: f64,
    /// Seconds to render.
    pub seconds_render: f64,
}

/// The whole study of one scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RenderStudy {
    /// Scene name.
    pub scene: String,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Samples per pixel of the reference and of the light renders.
    pub reference_spp: u32,
    /// Samples per pixel of the light renders.
    pub lights_spp: u32,
    /// Bounces of every render.
    pub bounces: u32,
    /// Shadows of the light renders.
    pub shadows: String,
    /// Seconds to render the reference.
    pub seconds_reference: f64,
    /// The reference's own noise: half the relative MSE between two references of different
    /// seeds.
    pub noise_floor_relative_mse: f64,
    /// Mean FLIP between the two references: what noise alone scores.
    pub noise_floor_flip: f64,
    /// One row per method and N that ran, methods in order, N increasing.
    pub rows: Vec<RenderStudyRow>,
    /// `(method, n, reason)` of the runs that could not be made.
    pub skipped: Vec<(String, usize, String)>,
}

/// The images of a study, kept for display: the reference and every light render.
#[derive(Clone, Debug)]
pub struct RenderStudyImages {
    /// The reference render.
    pub reference: RenderOutput,
    /// `(method, n, render)` in the order of [`RenderStudy::rows`].
    pub lights: Vec<(String, usize, RenderOutput)>,
}

fn settings(s: &RenderStudySettings, spp: u32, seed: u64) -> RenderSettings {
    RenderSettings {
        composite: CompositeRule::Difference,
        width: s.width,
        spp,
        bounces: s.bounces,
        seed,
    }
}

/// Why a study could not run, by cause.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A render failed (a setting out of range, a probe that cannot light).
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The lights could not be extracted.
    #[error("extracting the lights: {0}")]
    Extract(#[from] ExtractError),
    /// Two renders could not be compared (they differ in size).
    #[error("scoring a render: {0}")]
    Score(#[from] DifferenceError),
}

impl StudyError {
    /// Whether the scene or the settings are at fault (every cause is: the study has no internal
    /// failure of its own).
    pub fn is_bad_input(&self) -> bool {
        match self {
            StudyError::Render(e) => e.is_bad_input(),
            StudyError::Extract(e) => e.is_bad_input(),
            StudyError::Score(e) => e.is_bad_input(),
        }
    }
}

fn score(test: &Image<Rgb>, reference: &Image<Rgb>) -> Result<(f64, f64, f64), DifferenceError> {
    let d = ImageDifference::between(test, reference, None)?;
    let f = flip(test, reference, &FlipOptions::default())?;
    Ok((d.relative_mse, d.rmse, f.mean()))
}

/// Runs the study on `scene`; `progress(done, total)` counts renders.
pub fn render_study(
    scene: &Scene,
    name: &str,
    s: &RenderStudySettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(RenderStudy, RenderStudyImages), StudyError> {
    let runs: Vec<(ModelSpec, usize)> = s
        .methods
        .iter()
        .flat_map(|&m| s.counts.iter().map(move |&n| (m, n)))
        .collect();
    let total = runs.len() + 2;
    let no_rows = |_: usize, _: usize| {};
    let reference_lighting = Lighting::reference(scene).map_err(RenderError::from)?;
    let started = Instant::now();
    let reference = render(
        scene,
        &reference_lighting,
        &settings(s, s.reference_spp, s.seed),
        &no_rows,
    )?;
    let seconds_reference = started.elapsed().as_secs_f64();
    progress(1, total);
    let second = render(
        scene,
        &reference_lighting,
        &settings(s, s.reference_spp, s.seed.wrapping_add(0x9e37_79b9)),
        &no_rows,
    )?;
    let (noise_relative_mse, _, noise_flip) = score(&second.with_objects, &reference.with_objects)?;
    progress(2, total);

    let mut rows = Vec::new();
    let mut skipped = Vec::new();
    let mut images = Vec::new();
    for (k, &(spec, n)) in runs.iter().enumerate() {
        let method = spec.to_string();
        if !spec.accepts(n) {
            skipped.push((method, n, format!("{spec} cannot make {n} lights")));
            progress(k + 3, total);
            continue;
        }
        let started = Instant::now();
        let options = ExtractOptions { seed: s.seed };
        let (model, _) = build_model(&scene.probe.radiance, spec, n, &options)?;
        let seconds_extract = started.elapsed().as_secs_f64();
        let Some(set) = model.lights() else {
            skipped.push((method, n, "not a light model".into()));
            progress(k + 3, total);
            continue;
        };
        let lighting = Lighting::lights(scene, set, s.shadows).map_err(RenderError::from)?;
        let started = Instant::now();
        let out = render(
            scene,
            &lighting,
            &settings(s, s.lights_spp, s.seed),
            &no_rows,
        )?;
        let seconds_render = started.elapsed().as_secs_f64();
        let (relative_mse, rmse, flip) = score(&out.with_objects, &reference.with_objects)?;
        rows.push(RenderStudyRow {
            method: method.clone(),
            n,
            relative_mse,
            rmse,
            flip,
            seconds_extract,
            seconds_render,
        });
        images.push((method, n, out));
        progress(k + 3, total);
    }
    let study = RenderStudy {
        scene: name.to_string(),
        width: reference.stats.width,
        height: reference.stats.height,
        reference_spp: s.reference_spp,
        lights_spp: s.lights_spp,
        bounces: s.bounces,
        shadows: s.shadows.name().to_string(),
        seconds_reference,
        noise_floor_relative_mse: noise_relative_mse / 2.0,
        noise_floor_flip: noise_flip,
        rows,
        skipped,
    };
    Ok((
        study,
        RenderStudyImages {
            reference,
            lights: images,
        },
    ))
}

impl RenderStudy {
    /// The study as a Markdown section: settings, the noise floor, then one table row per N
    /// with each method's relative MSE and FLIP.
    pub fn markdown(&self) -> String {
        let mut methods: Vec<&str> = Vec::new();
        for r in &self.rows {
            if !methods.contains(&r.method.as_str()) {
                methods.push(&r.method);
            }
        }
        let mut counts: Vec<usize> = self.rows.iter().map(|r| r.n).collect();
        counts.sort_unstable();
        counts.dedup();
        let mut md = format!(
            "### {}: light renders against the path-traced reference\n\n\
             {} x {} pixels; reference {} spp, light renders {} spp, {} bounce(s), {} shadows; \
             reference rendered in {:.1} s. Its own noise (half the relative MSE of two references \
             with different seeds; their FLIP): **{:.2e} / {:.3}**, the floor of the table.\n\n\
             Relative MSE / mean FLIP of the rendered scene with the object against the reference \
             (lower is better):\n\n| N |",
            self.scene,
            self.width,
            self.height,
            self.reference_spp,
            self.lights_spp,
            self.bounces,
            self.shadows,
            self.seconds_reference,
            self.noise_floor_relative_mse,
            self.noise_floor_flip
        );
        for m in &methods {
            md.push_str(&format!(" {m} |"));
        }
        md.push_str("\n|---:|");
        md.push_str(&"---:|".repeat(methods.len()));
        md.push('\n');
        for n in counts {
            md.push_str(&format!("| {n} |"));
            for m in &methods {
                match self.rows.iter().find(|r| r.method == *m && r.n == n) {
                    Some(r) => md.push_str(&format!(" {:.2e} / {:.3} |", r.relative_mse, r.flip)),
                    None => md.push_str(" - |"),
                }
            }
            md.push('\n');
        }
        md
    }

    /// The chart of relative MSE (left) and FLIP (right) against N, one curve per method.
    pub fn chart(&self) -> ErrorChart {
        let mut methods: Vec<String> = Vec::new();
        for r in &self.rows {
            if !methods.contains(&r.method) {
                methods.push(r.method.clone());
            }
        }
        let mut counts: Vec<usize> = self.rows.iter().map(|r| r.n).collect();
        counts.sort_unstable();
        counts.dedup();
        let floor = Curve {
            method: "reference noise".to_string(),
            points: counts
                .iter()
                .map(|&n| CurvePoint {
                    n,
                    mean_err_pct: Some(self.noise_floor_relative_mse),
                    max_err_pct: Some(self.noise_floor_flip),
                })
                .collect(),
        };
        let curves = methods
            .into_iter()
            .map(|m| Curve {
                points: counts
                    .iter()
                    .map(|&n| {
                        let row = self.rows.iter().find(|r| r.method == m && r.n == n);
                        CurvePoint {
                            n,
                            mean_err_pct: row.map(|r| r.relative_mse),
                            max_err_pct: row.map(|r| r.flip),
                        }
                    })
                    .collect(),
                method: m,
            })
            .chain(std::iter::once(floor))
            .collect();
        ErrorChart {
            title: format!("{}: light renders vs the path-traced reference", self.scene),
            subtitle: format!(
                "{} x {}, {} bounce(s), {} shadows; reference noise: two references of different seeds",
                self.width, self.height, self.bounces, self.shadows
            ),
            curves,
            panel_captions: [
                "relative MSE against the reference".to_string(),
                "mean FLIP against the reference".to_string(),
            ],
            thresholds: (Vec::new(), String::new()),
        }
    }
}

//! Light sets judged by the images they render (Madsen & Laursen 2006, section 5, where the
//! methods are compared on renders with shadows as well as on irradiance): for one scene, the
//! path-traced reference, then for every run (a lighting model, a light count N and a shadow
//! kind) a render in the `lights` mode (or `hybrid`, for a `METHOD+shB` model), each scored
//! against the reference by relative MSE (mean of `(a - b)^2 / (b^2 + 0.01)` over pixels and
//! channels) and by FLIP ([`ibl_metrics::flip()`]), with its time.
//!
//! What is compared is the rendered local scene *with* the objects (ground, object and its
//! shadow, background where the camera sees no geometry), so every approximation is judged on
//! the light it puts on the real surfaces too. Both renders use the same number of bounces, so
//! with one bounce (the default) the study isolates what a light set gets wrong about direct
//! light and shadows (the lights and hybrid modes are direct light only). The reference's own
//! Monte Carlo noise is measured by a second reference with another seed: its relative MSE
//! against the first, divided by two (each has that much variance), is the floor under which no
//! approximation can be judged; an approximation's score is its bias squared plus its own noise
//! plus that floor, so "within 3x the floor" leaves twice the reference's variance for the rest.
//! FLIP's floor is the two references' FLIP, as is.
//!
//! Cost: the two references (`W H spp_ref` paths each) plus, per run, the extraction and
//! `W H spp` samples of `N` shadow rays each (plus the hybrid's occlusion rays).

use std::time::Instant;

use ibl_core::{Image, Rgb};
use ibl_extract::{ExtractError, ExtractOptions, Model, ModelSpec, build_model};
use ibl_metrics::{DifferenceError, FlipOptions, ImageDifference, flip};
use ibl_render::lighting::Lighting;
use ibl_render::{RenderError, RenderOutput, RenderSettings, SamplerKind, render};
use ibl_scene::description::CompositeRule;
use ibl_scene::{Scene, ShadowKind};
use serde::Serialize;

use crate::plot::{Curve, CurvePoint, ErrorChart};

/// One light render of a study: a model, a light count and a shadow kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StudyRun {
    /// The lighting model: lights (the `lights` mode) or lights plus SH (the `hybrid` mode).
    pub spec: ModelSpec,
    /// Light count asked for.
    pub n: usize,
    /// Shadows of the lights.
    pub shadows: ShadowKind,
}

/// What to render and compare.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderStudySettings {
    /// The light renders, in the order of the report.
    pub runs: Vec<StudyRun>,
    /// Output width (`None`: the scene's camera size).
    pub width: Option<u32>,
    /// Samples per pixel of the reference.
    pub reference_spp: u32,
    /// Samples per pixel of the light renders (antialiasing and soft-shadow samples).
    pub lights_spp: u32,
    /// Adaptive antialiasing of the light renders (`ibl_render::adaptive`): the contrast above
    /// which a pixel takes all `lights_spp`, or `None` for all of them everywhere.
    pub lights_adaptive: Option<f32>,
    /// Surface vertices per path, the same in every render.
    pub bounces: u32,
    /// Random numbers of every render.
    pub sampler: SamplerKind,
    /// Occlusion rays per shading point of the hybrid renders.
    pub occlusion_rays: u32,
    /// Seed of every render and extraction.
    pub seed: u64,
}

impl RenderStudySettings {
    /// Every model of `specs` at every count of `counts` with `shadows`, models in order, N
    /// increasing (a model skips the counts it cannot make, e.g. median cut off powers of 2).
    pub fn grid(specs: &[ModelSpec], counts: &[usize], shadows: ShadowKind) -> Vec<StudyRun> {
        specs
            .iter()
            .flat_map(|&spec| counts.iter().map(move |&n| StudyRun { spec, n, shadows }))
            .collect()
    }
}

/// One light render against the reference.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RenderStudyRow {
    /// Model name (`median-cut`, `median-cut+sh3`, ...).
    pub method: String,
    /// `lights` or `hybrid`.
    pub mode: String,
    /// Light count asked for.
    pub n: usize,
    /// Lights the method made (median cut cannot split one-texel regions).
    pub lights: usize,
    /// `hard` or `soft`.
    pub shadows: String,
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

impl RenderStudyRow {
    /// The column label of the row's model and shadows, e.g. `median-cut` or
    /// `median-cut (hard)` (soft shadows are the default and go unsaid).
    pub fn label(&self) -> String {
        label(&self.method, &self.shadows)
    }
}

fn label(method: &str, shadows: &str) -> String {
    if shadows == ShadowKind::Soft.name() {
        method.to_string()
    } else {
        format!("{method} ({shadows})")
    }
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
    /// Samples per pixel of the reference.
    pub reference_spp: u32,
    /// Samples per pixel of the light renders (the most a pixel takes).
    pub lights_spp: u32,
    /// Adaptive antialiasing's contrast threshold of the light renders (`None`: off).
    pub lights_adaptive: Option<f32>,
    /// Bounces of every render.
    pub bounces: u32,
    /// Random numbers of every render.
    pub sampler: String,
    /// Seconds to render the reference.
    pub seconds_reference: f64,
    /// The reference's own noise: half the relative MSE between two references of different
    /// seeds.
    pub noise_floor_relative_mse: f64,
    /// Mean FLIP between the two references: what noise alone scores.
    pub noise_floor_flip: f64,
    /// One row per run that was made, in the order of the settings.
    pub rows: Vec<RenderStudyRow>,
    /// `(method, n, reason)` of the runs that could not be made.
    pub skipped: Vec<(String, usize, String)>,
}

/// The images of a study, kept for display: the reference and every light render.
#[derive(Clone, Debug)]
pub struct RenderStudyImages {
    /// The reference render.
    pub reference: RenderOutput,
    /// `(label, n, render)` in the order of [`RenderStudy::rows`].
    pub lights: Vec<(String, usize, RenderOutput)>,
}

fn settings(s: &RenderStudySettings, spp: u32, seed: u64, adaptive: Option<f32>) -> RenderSettings {
    RenderSettings {
        composite: CompositeRule::Difference,
        width: s.width,
        spp,
        bounces: s.bounces,
        seed,
        sampler: s.sampler,
        adaptive,
        adaptive_sampling: false,
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

/// The lighting of one run's model: the lights mode for a light set, the hybrid mode for lights
/// plus SH; `None` for a model without lights.
fn run_lighting(
    scene: &Scene,
    model: &Model,
    shadows: ShadowKind,
    occlusion_rays: u32,
) -> Result<Option<(Lighting, &'static str, usize)>, RenderError> {
    Ok(match model {
        Model::Lights(set) => Some((
            Lighting::lights(scene, set, shadows)?,
            "lights",
            set.lights.len(),
        )),
        Model::Hybrid(h) => Some((
            Lighting::hybrid(scene, &h.lights, &h.ambient, shadows, occlusion_rays)?,
            "hybrid",
            h.lights.lights.len(),
        )),
        Model::Sh(_) => None,
    })
}

/// Runs the study on `scene`; `progress(done, total)` counts renders.
pub fn render_study(
    scene: &Scene,
    name: &str,
    s: &RenderStudySettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(RenderStudy, RenderStudyImages), StudyError> {
    let total = s.runs.len() + 2;
    let no_rows = |_: usize, _: usize| {};
    let reference_lighting = Lighting::reference(scene).map_err(RenderError::from)?;
    let started = Instant::now();
    let reference = render(
        scene,
        &reference_lighting,
        &settings(s, s.reference_spp, s.seed, None),
        &no_rows,
    )?;
    let seconds_reference = started.elapsed().as_secs_f64();
    progress(1, total);
    let second = render(
        scene,
        &reference_lighting,
        &settings(s, s.reference_spp, s.seed.wrapping_add(0x9e37_79b9), None),
        &no_rows,
    )?;
    let (noise_relative_mse, _, noise_flip) = score(&second.with_objects, &reference.with_objects)?;
    progress(2, total);

    let mut rows = Vec::new();
    let mut skipped = Vec::new();
    let mut images = Vec::new();
    for (k, run) in s.runs.iter().enumerate() {
        let method = run.spec.to_string();
        if !run.spec.accepts(run.n) {
            let why = format!("{} cannot make {} lights", run.spec, run.n);
            skipped.push((method, run.n, why));
            progress(k + 3, total);
            continue;
        }
        let started = Instant::now();
        let options = ExtractOptions::for_rendering(s.seed);
        let (model, _) = build_model(&scene.probe.radiance, run.spec, run.n, &options)?;
        let seconds_extract = started.elapsed().as_secs_f64();
        let Some((lighting, mode, lights)) =
            run_lighting(scene, &model, run.shadows, s.occlusion_rays)?
        else {
            skipped.push((method, run.n, "not a light model".into()));
            progress(k + 3, total);
            continue;
        };
        let started = Instant::now();
        let out = render(
            scene,
            &lighting,
            &settings(s, s.lights_spp, s.seed, s.lights_adaptive),
            &no_rows,
        )?;
        let seconds_render = started.elapsed().as_secs_f64();
        let (relative_mse, rmse, flip) = score(&out.with_objects, &reference.with_objects)?;
        let row = RenderStudyRow {
            method,
            mode: mode.to_string(),
            n: run.n,
            lights,
            shadows: run.shadows.name().to_string(),
            relative_mse,
            rmse,
            flip,
            seconds_extract,
            seconds_render,
        };
        images.push((row.label(), run.n, out));
        rows.push(row);
        progress(k + 3, total);
    }
    let study = RenderStudy {
        scene: name.to_string(),
        width: reference.stats.width,
        height: reference.stats.height,
        reference_spp: s.reference_spp,
        lights_spp: s.lights_spp,
        lights_adaptive: s.lights_adaptive,
        bounces: s.bounces,
        sampler: s.sampler.name().to_string(),
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
    /// The row of `label` (as [`RenderStudyRow::label`]) at `n`, if it was made.
    pub fn row(&self, label: &str, n: usize) -> Option<&RenderStudyRow> {
        self.rows.iter().find(|r| r.n == n && r.label() == label)
    }

    /// Column labels in the order of the rows.
    fn labels(&self) -> Vec<String> {
        let mut labels: Vec<String> = Vec::new();
        for r in &self.rows {
            let l = r.label();
            if !labels.contains(&l) {
                labels.push(l);
            }
        }
        labels
    }

    /// The light counts of the rows, increasing.
    fn counts(&self) -> Vec<usize> {
        let mut counts: Vec<usize> = self.rows.iter().map(|r| r.n).collect();
        counts.sort_unstable();
        counts.dedup();
        counts
    }

    /// The study as a Markdown section: settings, the noise floor, one table row per N with
    /// each model's relative MSE (and its ratio to the floor) and FLIP, then the times.
    pub fn markdown(&self) -> String {
        let labels = self.labels();
        let counts = self.counts();
        let mut md = format!(
            "### {}: light renders against the path-traced reference\n\n\
             {} x {} pixels; reference {} spp, light renders {} spp{} ({} sampler), {} bounce(s); \
             soft shadows unless marked; reference rendered in {:.2} s. Its own noise (half the \
             relative MSE of two references with different seeds; their FLIP): \
             **{:.2e} / {:.3}**, the floor of the table.\n\n\
             Relative MSE (x the floor) / mean FLIP of the rendered scene with the object \
             against the reference (lower is better):\n\n| N |",
            self.scene,
            self.width,
            self.height,
            self.reference_spp,
            self.lights_spp,
            match self.lights_adaptive {
                Some(c) => format!(" at most, adaptive (contrast {c})"),
                None => String::new(),
            },
            self.sampler,
            self.bounces,
            self.seconds_reference,
            self.noise_floor_relative_mse,
            self.noise_floor_flip
        );
        for l in &labels {
            md.push_str(&format!(" {l} |"));
        }
        md.push_str("\n|---:|");
        md.push_str(&"---:|".repeat(labels.len()));
        md.push('\n');
        let floor = self.noise_floor_relative_mse.max(f64::MIN_POSITIVE);
        for &n in &counts {
            md.push_str(&format!("| {n} |"));
            for l in &labels {
                match self.row(l, n) {
                    Some(r) => md.push_str(&format!(
                        " {:.2e} ({:.1}x) / {:.3} |",
                        r.relative_mse,
                        r.relative_mse / floor,
                        r.flip
                    )),
                    None => md.push_str(" - |"),
                }
            }
            md.push('\n');
        }
        md.push_str("\nSeconds to render (extraction excluded):\n\n| N |");
        for l in &labels {
            md.push_str(&format!(" {l} |"));
        }
        md.push_str("\n|---:|");
        md.push_str(&"---:|".repeat(labels.len()));
        md.push('\n');
        for &n in &counts {
            md.push_str(&format!("| {n} |"));
            for l in &labels {
                match self.row(l, n) {
                    Some(r) => md.push_str(&format!(" {:.2} |", r.seconds_render)),
                    None => md.push_str(" - |"),
                }
            }
            md.push('\n');
        }
        md
    }

    /// The chart of relative MSE (left) and FLIP (right) against N, one curve per model and
    /// shadow kind, and the reference's noise.
    pub fn chart(&self) -> ErrorChart {
        let counts = self.counts();
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
        let curves = self
            .labels()
            .into_iter()
            .map(|l| Curve {
                points: counts
                    .iter()
                    .map(|&n| {
                        let row = self.row(&l, n);
                        CurvePoint {
                            n,
                            mean_err_pct: row.map(|r| r.relative_mse),
                            max_err_pct: row.map(|r| r.flip),
                        }
                    })
                    .collect(),
                method: l,
            })
            .chain(std::iter::once(floor))
            .collect();
        ErrorChart {
            title: format!("{}: light renders vs the path-traced reference", self.scene),
            subtitle: format!(
                "{} x {}, {} bounce(s), {} spp ({}); reference noise: two references of different seeds",
                self.width, self.height, self.bounces, self.lights_spp, self.sampler
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

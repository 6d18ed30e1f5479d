//! The render driver and differential rendering (Debevec 1998, section 5; Grosch 2005 section
//! 4.1): every pixel sample is traced through the scene with the virtual objects and, where that
//! path touched them, again without them, with the same random numbers.
//!
//! For a pixel of background `B` with `n` samples, of which the `k` whose primary ray met a
//! virtual object gave radiance `O_s`, and the others gave `W_s` with and `V_s` without the
//! objects, the composite is
//!
//! ```text
//! C = B (n - k) / n + (sum_s O_s + sum_s (W_s - V_s)) / n
//! ```
//!
//! (the `difference` rule; the `ratio` rule replaces the second sum by `B (n - k) / n * (sum_s
//! W_s / sum_s V_s - 1)`, see [`CompositeRule`]): the object's own pixels from the render,
//! everything else the background plus the change the objects make (shadows, reflected light), antialiased by the sample split along the edges. A
//! path that never touched the virtual layer has `W_s = V_s` exactly (see [`crate::tracer`]), so an
//! empty scene, or any pixel the objects do not affect, composites to `B` bit for bit (`B * 1.0 +
//! 0.0`). Negative results (a modelled shadow darker than the photographed surface) clamp to 0.
//!
//! Every pixel sample draws from its own stream `(seed, pixel, sample)` ([`crate::sampler`]:
//! Owen-scrambled Sobol by default, so the pixel's samples are stratified in the pixel and in
//! every later pair of dimensions), rows run in parallel with rayon, and each pixel sums its
//! samples in order: the image depends on the seed only, never on the thread count. Cost:
//! O(W H n) paths (see [`crate::tracer`] per path).

use std::ops::Range;
use std::sync::atomic::{AtomicUsize, Ordering};

use ibl_core::{Image, Rgb};
use ibl_scene::description::CompositeRule;
use ibl_scene::{RenderMode, Scene};
use rayon::prelude::*;
use serde::Serialize;

use crate::RenderError;
use crate::adaptive::{CoarseGrid, FirstSample, needs_refinement};
use crate::background::background_image;
use crate::lighting::{Illumination, Lighting};
use crate::sample_allocation::{PilotMoments, pilot_samples, sample_counts};
use crate::sampler::{SOBOL_MAX_SAMPLES, SampleStream, SamplerKind};
use crate::tracer::{KnownVisibility, Layers, LightVisibility, PrimaryHit, ShadowHints, Tracer};

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// How the objects' effect on real surfaces joins the background.
    pub composite: CompositeRule,
    /// Output width in pixels (`None`: the background's own width).
    pub width: Option<u32>,
    /// Samples per pixel, at least 1 (at most `2^16` with the Sobol sampler).
    pub spp: u32,
    /// Surface vertices per path, at least 1 (1 = direct light only). The lights and hybrid
    /// modes end a path at its first diffuse or glossy vertex; this bounds their mirror chains.
    pub bounces: u32,
    /// Seed of every random number.
    pub seed: u64,
    /// Which random numbers the samples draw.
    pub sampler: SamplerKind,
    /// Adaptive antialiasing ([`crate::adaptive`]): `Some(c)` gives every pixel one sample first
    /// and all `spp` only where its neighbourhood shows a contrast above `c` or a silhouette;
    /// `None` gives every pixel `spp`. Ignored by the reference mode, which stays unbiased.
    pub adaptive: Option<f32>,
    /// Adaptive sampling of the reference mode ([`crate::sample_allocation`]): the paths of
    /// `spp` per pixel spent where the pilot pass finds noise, still unbiased. Ignored by the
    /// lights and hybrid modes.
    pub adaptive_sampling: bool,
}

impl RenderSettings {
    /// The settings a scene file asks for when rendering in `mode`: `[render]`'s width, bounces,
    /// seed, composite rule and sampler, and its `spp` for the reference or `[lighting]`'s `spp`
    /// (antialiasing samples) for the lights and hybrid modes.
    pub fn for_scene(scene: &Scene, mode: RenderMode) -> RenderSettings {
        let r = &scene.render;
        RenderSettings {
            composite: r.composite,
            width: r.width,
            spp: match mode {
                RenderMode::Reference => r.spp,
                RenderMode::Lights | RenderMode::Hybrid => scene.lighting.spp,
            },
            bounces: r.bounces,
            seed: r.seed,
            sampler: r.sampler,
            adaptive_sampling: mode == RenderMode::Reference && r.adaptive_sampling,
            adaptive: match mode {
                RenderMode::Reference => None,
                RenderMode::Lights | RenderMode::Hybrid => scene
                    .lighting
                    .adaptive
                    .then_some(scene.lighting.adaptive_contrast),
            },
        }
    }
}

/// What a render counted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RenderStats {
    /// Output width, pixels.
    pub width: u32,
    /// Output height, pixels.
    pub height: u32,
    /// Samples per pixel (the most a pixel takes, with adaptive antialiasing).
    pub spp: u32,
    /// Pixels that took all `spp` samples: every pixel without adaptive antialiasing, those
    /// whose first samples showed contrast with it; with adaptive sampling, those that took
    /// more than `spp`.
    pub refined_pixels: u64,
    /// Paths traced with the objects.
    pub paths: u64,
    /// Paths traced again without the objects (they touched a virtual object).
    pub paths_without_objects: u64,
    /// Rays traced (closest-hit and shadow queries, both passes).
    pub rays: u64,
    /// Fraction of pixel samples whose primary ray met a virtual object.
    pub object_coverage: f64,
}

/// The images of a render, all `width x height`, linear radiance.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// Background plus the objects' effect, the objects themselves on top: the final image.
    pub composite: Image<Rgb>,
    /// The local scene with the virtual objects (background where the camera sees no geometry).
    pub with_objects: Image<Rgb>,
    /// The local scene without the virtual objects.
    pub without_objects: Image<Rgb>,
    /// The background at the output size.
    pub background: Image<Rgb>,
    /// Per pixel, the fraction of samples whose primary ray met a virtual object (alpha).
    pub object_coverage: Image<f32>,
    /// Counters.
    pub stats: RenderStats,
}

/// One pixel's sums.
#[derive(Clone, Copy, Default)]
struct PixelSums {
    /// Samples taken.
    samples: u32,
    /// What blocked each light at the first sample's camera hit (adaptive antialiasing).
    first_visibility: LightVisibility,
    object: Rgb,
    /// Sums over the samples whose primary ray met real geometry, with and without the objects
    /// (the ratio rule).
    real_with: Rgb,
    real_without: Rgb,
    difference: Rgb,
    with: Rgb,
    without: Rgb,
    object_samples: u32,
    background_samples: u32,
    paths_without: u64,
    rays: u64,
    /// Sum and sum of squares of the traced samples' luminance with the objects (adaptive
    /// sampling's pilot; background samples are added when it is read).
    luminance: f64,
    luminance_squares: f64,
}

/// Renders `scene` under `lighting` and composites it into the background. `progress(rows_done,
/// rows_total)` is called after each row, from worker threads.
pub fn render(
    scene: &Scene,
    lighting: &Lighting,
    settings: &RenderSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<RenderOutput, RenderError> {
    if settings.spp == 0 {
        return Err(RenderError::Parameter(
            "samples per pixel must be at least 1".into(),
        ));
    }
    if settings.sampler == SamplerKind::Sobol && settings.spp > SOBOL_MAX_SAMPLES {
        return Err(RenderError::Parameter(format!(
            "the sobol sampler takes at most {SOBOL_MAX_SAMPLES} samples per pixel ({} asked)",
            settings.spp
        )));
    }
    let default_width = match &scene.background {
        ibl_scene::Background::Panorama => scene.probe.radiance.width() as u32,
        ibl_scene::Background::Photo(photo) => photo.width() as u32,
    };
    let (width, height) = scene.camera.output_size(settings.width, default_width);
    if width as usize * height as usize > MAX_PIXELS {
        return Err(RenderError::Parameter(format!(
            "{width} x {height} is more than {MAX_PIXELS} pixels"
        )));
    }
    let background = background_image(scene, width, height);
    let tracer = Tracer::new(scene, lighting, settings.bounces);
    let (w, h) = (width as usize, height as usize);
    let sampler = PixelSampler {
        tracer: &tracer,
        scene,
        settings,
        width,
        height,
    };
    // Adaptive antialiasing: only the light modes, and only when a pixel has more than one
    // sample to save.
    let adaptive = settings.adaptive.filter(|_| {
        settings.spp > 1 && !matches!(lighting.illumination, Illumination::Environment)
    });
    let rows_done = AtomicUsize::new(0);
    // Adaptive sampling: only the reference, and only when the pilot leaves samples to share.
    let pilot = pilot_samples(settings.spp);
    let allocate = settings.adaptive_sampling
        && pilot < settings.spp
        && matches!(lighting.illumination, Illumination::Environment);
    let passes = if adaptive.is_some() || allocate { 2 } else { 1 };
    let row_done = || progress(rows_done.fetch_add(1, Ordering::Relaxed) + 1, passes * h);
    let sums: Vec<PixelSums> = match adaptive {
        None if allocate => {
            // Pass 1: the pilot; pass 2: each pixel up to its count (crate::sample_allocation).
            let known = &KnownVisibility::NONE;
            let mut sums = per_pixel(w, h, &row_done, |x, y, hints| {
                sampler.samples(x, y, 0..pilot, hints, known)
            });
            let delta = 0.1 * mean_luminance(&background);
            let pilots: Vec<PilotMoments> = sums
                .par_iter()
                .zip(background.pixels().par_iter())
                .map(|(sums, b)| sums.pilot(*b))
                .collect();
            let variance: Vec<f64> = pilots.iter().map(|p| p.relative_variance(delta)).collect();
            let cost: Vec<f64> = pilots.iter().map(PilotMoments::cost).collect();
            let counts = sample_counts(&variance, &cost, w, h, settings.spp, pilot);
            sums.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
                let mut hints = ShadowHints::default();
                for (x, pixel) in row.iter_mut().enumerate() {
                    let samples = pilot..counts[y * w + x];
                    sampler.add_samples(pixel, x, y, samples, &mut hints, known);
                }
                row_done();
            });
            sums
        }
        None => per_pixel(w, h, &row_done, |x, y, hints| {
            sampler.samples(x, y, 0..settings.spp, hints, &KnownVisibility::NONE)
        }),
        Some(contrast) => {
            // Pass 1: sample 0 of every pixel, the coarse grid's first (every light traced),
            // then the pixels between, which take the lights their coarse neighbours agree on;
            // pass 2: samples 1.. where the first samples of the pixel's neighbourhood differ
            // (crate::adaptive).
            let grid = CoarseGrid::new(w, h);
            let (cw, ch) = grid.size();
            let coarse: Vec<FirstSample> = per_pixel(cw, ch, &|| {}, |i, j, hints| {
                let known = &KnownVisibility::NONE;
                let pixel = sampler.samples(2 * i, 2 * j, 0..1, hints, known);
                pixel.first_sample()
            });
            let mut sums: Vec<PixelSums> = per_pixel(w, h, &row_done, |x, y, hints| {
                let known = if CoarseGrid::is_coarse(x, y) {
                    KnownVisibility::NONE
                } else {
                    grid.known(&coarse, x, y)
                };
                sampler.samples(x, y, 0..1, hints, &known)
            });
            let first: Vec<FirstSample> = sums.par_iter().map(PixelSums::first_sample).collect();
            sums.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
                let mut hints = ShadowHints::default();
                for (x, pixel) in row.iter_mut().enumerate() {
                    if let Some(known) = needs_refinement(&first, w, h, x, y, contrast) {
                        sampler.add_samples(pixel, x, y, 1..settings.spp, &mut hints, &known);
                    }
                }
                row_done();
            });
            sums
        }
    };
    let mut stats = RenderStats {
        width,
        height,
        spp: settings.spp,
        ..RenderStats::default()
    };
    let mut object_samples = 0u64;
    for sums in &sums {
        object_samples += u64::from(sums.object_samples);
        stats.paths += u64::from(sums.samples);
        stats.refined_pixels += u64::from(if allocate {
            sums.samples > settings.spp
        } else {
            sums.samples == settings.spp
        });
        stats.paths_without_objects += sums.paths_without;
        stats.rays += sums.rays;
    }
    stats.object_coverage = object_samples as f64 / stats.paths.max(1) as f64;
    // The output layers, each pixel from its sums and its background, in parallel.
    let layer = |f: &(dyn Fn(&PixelSums, Rgb) -> Rgb + Sync)| -> Vec<Rgb> {
        sums.par_iter()
            .zip(background.pixels().par_iter())
            .map(|(sums, &b)| f(sums, b))
            .collect()
    };
    let composite = layer(&|sums, b| sums.composite(b, settings.composite));
    let with_objects =
        layer(&|sums, b| (sums.with + b * sums.background_samples as f32) / sums.samples as f32);
    let without_objects =
        layer(&|sums, b| (sums.without + b * sums.background_samples as f32) / sums.samples as f32);
    let coverage: Vec<f32> = sums
        .par_iter()
        .map(|sums| sums.object_samples as f32 / sums.samples as f32)
        .collect();
    let image =
        |data| Image::from_vec(w, h, data).map_err(|e| RenderError::Parameter(e.to_string()));
    Ok(RenderOutput {
        composite: image(composite)?,
        with_objects: image(with_objects)?,
        without_objects: image(without_objects)?,
        background,
        object_coverage: Image::from_vec(w, h, coverage)
            .map_err(|e| RenderError::Parameter(e.to_string()))?,
        stats,
    })
}

/// The mean luminance of `image` (0 for an empty one), in f64.
fn mean_luminance(image: &Image<Rgb>) -> f64 {
    let pixels = image.pixels();
    let sum: f64 = pixels.par_iter().map(|p| f64::from(p.luminance())).sum();
    sum / pixels.len().max(1) as f64
}

/// Largest output, pixels (a 16384 x 8192 panorama).
pub const MAX_PIXELS: usize = 16384 * 8192;

/// `f(x, y, hints)` for every pixel of a `w x h` grid, row-major, in parallel: written in
/// place (no per-row vectors to join), `hints` one shadow cache per rayon job, `row_done` after
/// each row's last pixel.
fn per_pixel<T: Send>(
    w: usize,
    h: usize,
    row_done: &(dyn Fn() + Sync),
    f: impl Fn(usize, usize, &mut ShadowHints) -> T + Sync,
) -> Vec<T> {
    (0..w * h)
        .into_par_iter()
        .with_min_len(w.max(1))
        .map_init(ShadowHints::default, |hints, i| {
            let (x, y) = (i % w, i / w);
            let value = f(x, y, hints);
            if x + 1 == w {
                row_done();
            }
            value
        })
        .collect()
}

impl PixelSums {
    /// The composited pixel over background `b` by `rule` (module notes), clamped at 0.
    fn composite(&self, b: Rgb, rule: CompositeRule) -> Rgb {
        let n = self.samples as f32;
        let other = self.samples - self.object_samples;
        let c = match rule {
            CompositeRule::Difference => {
                b * (other as f32 / n) + (self.object + self.difference) / n
            }
            CompositeRule::Ratio => {
                let ratio = |w: f32, v: f32, d: f32, b: f32| {
                    if d == 0.0 {
                        b
                    } else if v > 0.0 {
                        b * (w / v)
                    } else {
                        b + d / other.max(1) as f32
                    }
                };
                let real = Rgb::new(
                    ratio(
                        self.real_with.r,
                        self.real_without.r,
                        self.difference.r,
                        b.r,
                    ),
                    ratio(
                        self.real_with.g,
                        self.real_without.g,
                        self.difference.g,
                        b.g,
                    ),
                    ratio(
                        self.real_with.b,
                        self.real_without.b,
                        self.difference.b,
                        b.b,
                    ),
                );
                real * (other as f32 / n) + self.object / n
            }
        };
        c.map(|v| v.max(0.0))
    }

    /// The luminance moments of the pixel's samples over background `b` (adaptive sampling).
    fn pilot(&self, b: Rgb) -> PilotMoments {
        let background = f64::from(b.luminance());
        let escaped = f64::from(self.background_samples);
        PilotMoments {
            count: self.samples,
            sum: self.luminance + escaped * background,
            sum_of_squares: self.luminance_squares + escaped * background * background,
            rays: self.rays,
        }
    }

    /// What the pixel's one sample saw (adaptive antialiasing's first pass).
    fn first_sample(&self) -> FirstSample {
        let primary = if self.object_samples > 0 {
            PrimaryHit::Virtual
        } else if self.background_samples > 0 {
            PrimaryHit::Background
        } else {
            PrimaryHit::Real
        };
        FirstSample {
            primary,
            with: self.with,
            without: self.without,
            visibility: self.first_visibility,
        }
    }
}

/// Traces the samples of pixels: everything a pixel's samples share.
struct PixelSampler<'a> {
    tracer: &'a Tracer<'a>,
    scene: &'a Scene,
    settings: &'a RenderSettings,
    width: u32,
    height: u32,
}

impl PixelSampler<'_> {
    /// The sums of samples `samples` of pixel `(x, y)`, taking the shadow answers `known`.
    fn samples(
        &self,
        x: usize,
        y: usize,
        samples: Range<u32>,
        hints: &mut ShadowHints,
        known: &KnownVisibility,
    ) -> PixelSums {
        let mut sums = PixelSums::default();
        self.add_samples(&mut sums, x, y, samples, hints, known);
        sums
    }

    /// Adds samples `samples` of pixel `(x, y)` to `sums`, in order (`hints`: the thread's
    /// shadow cache, [`ShadowHints`]; `known`: shadow answers to take instead of tracing).
    fn add_samples(
        &self,
        sums: &mut PixelSums,
        x: usize,
        y: usize,
        samples: Range<u32>,
        hints: &mut ShadowHints,
        known: &KnownVisibility,
    ) {
        let (tracer, settings) = (self.tracer, self.settings);
        let index = (y as u64) * u64::from(self.width) + x as u64;
        // One stream for the pixel, restarted at each sample (it keeps the pixel's pair keys
        // where there are several samples, [`SampleStream::keeping_keys`]); a pass without the
        // objects restarts it after the pixel jitter, so it draws exactly the numbers the pass
        // with them drew.
        let (kind, seed, start) = (settings.sampler, settings.seed, samples.start);
        let mut rng = if samples.len() > 1 {
            SampleStream::keeping_keys(kind, seed, index, start)
        } else {
            SampleStream::new(kind, seed, index, start)
        };
        let after_jitter = |rng: &mut SampleStream, s: u32| {
            rng.restart(s);
            rng.skip_2d();
        };
        for s in samples {
            sums.samples += 1;
            rng.restart(s);
            let [jx, jy] = rng.next_2d();
            let ray = self
                .scene
                .camera
                .ray(x as f32 + jx, y as f32 + jy, self.width, self.height);
            let with = tracer.trace(ray, Layers::WithObjects, &mut rng, hints, known);
            if sums.samples == 1 {
                sums.first_visibility = with.visibility;
            }
            if with.primary != PrimaryHit::Background {
                let y = f64::from(with.radiance.luminance());
                sums.luminance += y;
                sums.luminance_squares += y * y;
            }
            sums.rays += with.rays;
            match with.primary {
                PrimaryHit::Virtual => {
                    sums.object += with.radiance;
                    sums.with += with.radiance;
                    sums.object_samples += 1;
                    // The same camera ray without the objects, for the "without" layer.
                    let without = tracer.trace(
                        ray,
                        Layers::RealOnly,
                        {
                            after_jitter(&mut rng, s);
                            &mut rng
                        },
                        hints,
                        &KnownVisibility::NONE,
                    );
                    sums.without += without.radiance;
                    sums.rays += without.rays;
                    sums.paths_without += 1;
                }
                PrimaryHit::Background => sums.background_samples += 1,
                PrimaryHit::Real => {
                    sums.with += with.radiance;
                    let without = if with.touched_virtual {
                        // The lights and hybrid modes usually evaluated the path without the
                        // objects in the same walk; otherwise it is walked again through the real
                        // layer.
                        match with.without_objects {
                            Some(radiance) => radiance,
                            None => {
                                let again = tracer.trace(
                                    ray,
                                    Layers::RealOnly,
                                    {
                                        after_jitter(&mut rng, s);
                                        &mut rng
                                    },
                                    hints,
                                    &KnownVisibility::NONE,
                                );
                                sums.rays += again.rays;
                                sums.paths_without += 1;
                                again.radiance
                            }
                        }
                    } else {
                        // The same path without the objects: bit for bit this one, less the new
                        // lights' share (the goniometric lights, absent without the objects; the
                        // lights and hybrid modes evaluated it in the walk).
                        with.without_objects
                            .unwrap_or(with.radiance - with.new_light)
                    };
                    sums.without += without;
                    sums.difference += with.radiance - without;
                    sums.real_with += with.radiance;
                    sums.real_without += without;
                }
            }
        }
    }
}

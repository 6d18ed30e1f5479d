//! What lights a render (`ibl render`, the demo, the viewer): the mode and, for the `lights` and
//! `hybrid` modes, where the directional lights come from: extracted from the scene's probe by a
//! method (or the dominant light), or read from a light file. The scene file's `[render] mode` and
//! `[lighting]` table give the plan; a front end overrides fields of it.
//!
//! Light-file rule: a light file holds directions in its own frame preset (turned into iblkit's
//! by `ibl_io::light_file::read_light_set`) and radiance in the units of the probe *file* it was
//! extracted from, so the scene's `radiance_scale` (which the scene applies to its probe) is
//! applied to the file's lights too; lights extracted here come from the already scaled probe.
//!
//! An area-light file of a room's important patches is read as directional lights seen from the
//! probe's centre (far field: `I = L A cos / r^2` per patch), in the probe's frame.
//!
//! Lights are in the probe's frame; `ibl_render::Lighting` turns them by `world_from_probe`.

use std::path::Path;

use ibl_extract::{ExtractOptions, Hybrid, ModelSpec, build_model};
use ibl_light::{LightSet, LightSource, Method};
use ibl_render::Lighting;
use ibl_scene::{AmbientBands, RenderMode, Scene, ShadowKind};
use ibl_sh::Window;

use crate::error::{Context, PipelineError, Result};

/// The lighting a render asks for.
#[derive(Clone, Debug, PartialEq)]
pub struct LightingPlan {
    /// The mode.
    pub mode: RenderMode,
    /// Where extracted lights come from: a method or the dominant light.
    pub source: LightSource,
    /// Number of lights to extract.
    pub lights: usize,
    /// Lights given ready-made (a light file, in the probe's frame, already scaled): used
    /// instead of extracting.
    pub given: Option<LightSet>,
    /// Hard or soft shadows.
    pub shadows: ShadowKind,
    /// SH bands the hybrid ambient's occlusion rays read ([`LightingPlan::ray_bands`]).
    pub ambient_bands: AmbientBands,
    /// Occlusion rays per shading point of the hybrid ambient.
    pub occlusion_rays: u32,
    /// Seed of the extraction (clustering restarts).
    pub seed: u64,
}

impl LightingPlan {
    /// The plan of a scene file's `[render]` mode and `[lighting]` table (a light file it names
    /// is read by [`LightingPlan::with_light_file`]).
    pub fn from_scene(scene: &Scene) -> LightingPlan {
        let l = &scene.lighting;
        LightingPlan {
            mode: scene.render.mode,
            source: l.method,
            lights: l.lights as usize,
            given: None,
            shadows: l.shadows,
            ambient_bands: l.ambient_bands,
            occlusion_rays: l.ao_samples,
            seed: scene.render.seed,
        }
    }

    /// `n` median-cut lights in `mode` with hard shadows, the rest from the scene (the demo's
    /// showcase renders).
    pub fn median_cut(scene: &Scene, mode: RenderMode, n: usize) -> LightingPlan {
        LightingPlan {
            mode,
            source: LightSource::Method(Method::MedianCut),
            lights: n,
            shadows: ShadowKind::Hard,
            ..LightingPlan::from_scene(scene)
        }
    }

    /// Uses the lights of the light file `path` (see the module doc), with the probe's
    /// `radiance_scale` applied.
    /// An area-light file (`iblkit.area-lights/1`, `ibl room lights`) is read as directional
    /// lights seen from the probe's centre (`AreaLightsFile::distant_lights`): the scene's origin
    /// stands where the probe stood in the room.
    pub fn with_light_file(self, path: &Path, radiance_scale: f32) -> Result<LightingPlan> {
        let set = ibl_io::area_light_file::read_scene_lights(path)?;
        Ok(LightingPlan {
            given: Some(set.scaled(f64::from(radiance_scale))),
            ..self
        })
    }

    /// The SH bands the hybrid ambient's occlusion rays read in a render of `spp` samples per
    /// pixel: `ambient_bands` resolved for `spp` samples of `occlusion_rays` rays
    /// ([`AmbientBands::resolve`]; with `auto` the bands follow the rays a pixel traces).
    pub fn ray_bands(&self, spp: u32) -> usize {
        self.ambient_bands.resolve(spp, self.occlusion_rays)
    }

    /// Builds the lighting of a render of `spp` samples per pixel; also returns the light set
    /// used (none for the reference). Extraction runs on the scene's probe (radiance scale
    /// applied), in the probe frame.
    pub fn build(&self, scene: &Scene, spp: u32) -> Result<(Lighting, Option<LightSet>)> {
        if self.mode == RenderMode::Reference {
            return Ok((Lighting::reference(scene).map_err(render_error)?, None));
        }
        let set = match &self.given {
            Some(set) => set.clone(),
            None => {
                let options = ExtractOptions::for_rendering(self.seed);
                let spec = ModelSpec::Lights(self.source);
                let (model, _) = build_model(&scene.probe.radiance, spec, self.lights, &options)
                    .context("extracting the lights")?;
                model.lights().cloned().ok_or_else(|| {
                    PipelineError::parameter(format!("'{}' made no lights", self.source))
                })?
            }
        };
        let lighting = match self.mode {
            RenderMode::Lights => Lighting::lights(scene, &set, self.shadows),
            RenderMode::Hybrid | RenderMode::Reference => {
                let hybrid = Hybrid::from_probe(
                    &scene.probe.radiance,
                    set.clone(),
                    self.ray_bands(spp),
                    Window::None,
                )
                .context("the hybrid ambient")?;
                Lighting::hybrid(
                    scene,
                    &hybrid.lights,
                    &hybrid.ambient,
                    self.shadows,
                    self.occlusion_rays,
                )
            }
        }
        .map_err(render_error)?;
        Ok((lighting, Some(set)))
    }
}

fn render_error(e: ibl_render::environment::EnvironmentError) -> PipelineError {
    ibl_render::RenderError::from(e).into()
}

//! What lights a render, per mode (Madsen & Laursen 2006 section 5; Grosch 2005 section 4.1):
//!
//! - **reference**: the whole probe as an environment light, importance-sampled
//!   ([`EnvironmentLight`]), combined with BSDF sampling by multiple importance sampling;
//! - **lights**: a [`LightSet`] of directional lights, each with hard shadows (one shadow ray along
//!   its direction) or soft shadows (shadow rays spread uniformly over a cone of the light's own
//!   solid angle `A_i`, half-angle `acos(1 - A_i / 2 pi)`);
//! - **hybrid**: the important lights with shadows plus an SH ambient (the probe minus the lights,
//!   `ibl_extract::Hybrid`) whose irradiance is attenuated by ambient occlusion.
//!
//! In every mode the environment is still what a perfect mirror reflects and what the camera sees
//! where it sees no geometry; only diffuse and glossy reflection use the approximation. Lights come
//! from the probe in its own frame and are rotated by `world_from_probe` here, as is the ambient.

use glam::{DMat3, Vec3};
use ibl_core::Rgb;
use ibl_extract::{Hybrid, LightSet};
use ibl_scene::{Scene, ShadowKind};
use ibl_sh::IrradianceSh;

use crate::environment::{EnvironmentError, EnvironmentLight};
use crate::sampling::{Distribution1D, UniformCone};

/// One directional light, world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Unit direction towards the light.
    pub direction: Vec3,
    /// `I = L A`: irradiance on a surface facing the light, per channel.
    pub irradiance: Rgb,
    /// The cone of the light's solid angle (soft shadows), `None` for a point-like light.
    pub cone: Option<UniformCone>,
}

/// The directional part of the `lights` and `hybrid` modes.
#[derive(Clone, Debug)]
pub struct LightList {
    /// The lights.
    pub lights: Vec<DirectionalLight>,
    /// Hard or soft shadows.
    pub shadows: ShadowKind,
    /// Picks one light in proportion to its luminous irradiance (secondary vertices).
    pub choice: Distribution1D,
}

/// The ambient of the `hybrid` mode.
#[derive(Clone, Debug)]
pub struct Ambient {
    /// Irradiance of the ambient radiance, world frame.
    pub irradiance: IrradianceSh,
    /// Occlusion rays per shading point.
    pub occlusion_rays: u32,
}

/// How diffuse and glossy surfaces are lit.
#[derive(Clone, Debug)]
pub enum Illumination {
    /// The full environment (reference).
    Environment,
    /// Directional lights.
    Lights(LightList),
    /// Directional lights plus an occluded SH ambient.
    Hybrid(LightList, Ambient),
}

/// Everything that emits light in a render.
#[derive(Clone, Debug)]
pub struct Lighting {
    /// The probe as an environment (always: mirrors and the background see it).
    pub environment: EnvironmentLight,
    /// What diffuse and glossy surfaces are lit by.
    pub illumination: Illumination,
}

impl Lighting {
    /// The environment of `scene`'s probe.
    fn environment(scene: &Scene) -> Result<EnvironmentLight, EnvironmentError> {
        EnvironmentLight::new(
            scene.probe.radiance.clone(),
            scene.probe.world_from_probe,
            1.0,
        )
    }

    /// Reference lighting: the full probe.
    pub fn reference(scene: &Scene) -> Result<Lighting, EnvironmentError> {
        Ok(Lighting {
            environment: Self::environment(scene)?,
            illumination: Illumination::Environment,
        })
    }

    /// `lights` mode: `set` is in the probe's frame (as `ibl lights` writes it with `--frame ours`).
    pub fn lights(
        scene: &Scene,
        set: &LightSet,
        shadows: ShadowKind,
    ) -> Result<Lighting, EnvironmentError> {
        Ok(Lighting {
            environment: Self::environment(scene)?,
            illumination: Illumination::Lights(light_list(scene, set, shadows)),
        })
    }

    /// `hybrid` mode: `hybrid` (lights + SH ambient) is in the probe's frame.
    pub fn hybrid(
        scene: &Scene,
        hybrid: &Hybrid,
        window: ibl_sh::Window,
        shadows: ShadowKind,
        occlusion_rays: u32,
    ) -> Result<Lighting, EnvironmentError> {
        let rotation = scene.probe.world_from_probe.as_dmat3();
        Ok(Lighting {
            environment: Self::environment(scene)?,
            illumination: Illumination::Hybrid(
                light_list(scene, &hybrid.lights, shadows),
                Ambient {
                    irradiance: hybrid.ambient.rotated(rotation).irradiance(window),
                    occlusion_rays: occlusion_rays.max(1),
                },
            ),
        })
    }
}

fn light_list(scene: &Scene, set: &LightSet, shadows: ShadowKind) -> LightList {
    let rotation: DMat3 = scene.probe.world_from_probe.as_dmat3();
    let lights: Vec<DirectionalLight> = set
        .lights
        .iter()
        .filter(|l| l.irradiance.iter().any(|&c| c > 0.0))
        .map(|l| DirectionalLight {
            direction: (rotation * l.dir()).normalize().as_vec3(),
            irradiance: Rgb::new(
                l.irradiance[0] as f32,
                l.irradiance[1] as f32,
                l.irradiance[2] as f32,
            ),
            cone: UniformCone::from_solid_angle(l.solid_angle_sr as f32),
        })
        .collect();
    let choice = Distribution1D::new(lights.iter().map(|l| f64::from(l.irradiance.luminance())));
    LightList {
        lights,
        shadows,
        choice,
    }
}

/// The lighting a render asks for: the mode and, for `lights` and `hybrid`, where the lights
/// come from (the scene's `[lighting]` table with any command-line overrides applied).
#[derive(Clone, Debug, PartialEq)]
pub struct LightingPlan {
    /// The mode.
    pub mode: ibl_scene::RenderMode,
    /// Extraction model name: a method (`median-cut`, ...) or `sun` (the dominant light).
    pub method: String,
    /// Number of lights to extract.
    pub lights: usize,
    /// Lights given ready-made (a light file, in the probe's frame): used instead of extracting.
    pub given: Option<LightSet>,
    /// Hard or soft shadows.
    pub shadows: ShadowKind,
    /// SH bands of the hybrid ambient.
    pub ambient_bands: usize,
    /// Occlusion rays per shading point of the hybrid ambient.
    pub occlusion_rays: u32,
    /// Seed of the extraction (clustering restarts).
    pub seed: u64,
}

impl LightingPlan {
    /// The plan of a scene file's `[render]` mode and `[lighting]` table.
    pub fn from_scene(scene: &Scene) -> LightingPlan {
        let l = &scene.lighting;
        LightingPlan {
            mode: scene.render.mode,
            method: l.method.clone(),
            lights: l.lights as usize,
            given: None,
            shadows: l.shadows,
            ambient_bands: l.ambient_bands as usize,
            occlusion_rays: l.ao_samples,
            seed: scene.render.seed,
        }
    }

    /// Builds the lighting; also returns the light set used (none for the reference). Extraction
    /// runs on the scene's probe (radiance scale applied), in the probe frame.
    pub fn build(&self, scene: &Scene) -> Result<(Lighting, Option<LightSet>), crate::RenderError> {
        use ibl_extract::{ExtractOptions, ModelSpec, build_model};
        use ibl_scene::RenderMode;
        if self.mode == RenderMode::Reference {
            return Ok((Lighting::reference(scene)?, None));
        }
        let set = match &self.given {
            Some(set) => set.clone(),
            None => {
                let spec: ModelSpec = self.method.parse()?;
                if !matches!(spec, ModelSpec::Lights(_)) {
                    return Err(crate::RenderError::Parameter(format!(
                        "lighting method '{}' is not a light-extraction method (give the method; \
                         the hybrid mode adds the SH ambient itself)",
                        self.method
                    )));
                }
                let options = ExtractOptions { seed: self.seed };
                let (model, _) = build_model(&scene.probe.radiance, spec, self.lights, &options)?;
                model.lights().cloned().ok_or_else(|| {
                    crate::RenderError::Parameter(format!("'{}' made no lights", self.method))
                })?
            }
        };
        let lighting = match self.mode {
            RenderMode::Lights => Lighting::lights(scene, &set, self.shadows)?,
            _ => {
                let hybrid = Hybrid::from_probe(
                    &scene.probe.radiance,
                    set.clone(),
                    self.ambient_bands,
                    ibl_sh::Window::None,
                )?;
                Lighting::hybrid(
                    scene,
                    &hybrid,
                    ibl_sh::Window::None,
                    self.shadows,
                    self.occlusion_rays,
                )?
            }
        };
        Ok((lighting, Some(set)))
    }
}

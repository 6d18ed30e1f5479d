//! What lights a render, per mode (Madsen & Laursen 2006 section 5; Grosch 2005 section 4.1):
//!
//! - **reference**: the whole probe as an environment light, importance-sampled
//!   ([`EnvironmentLight`]), combined with BSDF sampling by multiple importance sampling;
//! - **lights**: a [`LightSet`] of directional lights, each with hard shadows (one shadow ray along
//!   its direction) or soft shadows (shadow rays spread uniformly over a cone of the light's own
//!   solid angle `A_i`, half-angle `acos(1 - A_i / 2 pi)`);
//! - **hybrid**: the important lights with shadows plus an SH ambient (the probe minus the lights,
//!   as `ibl_extract::Hybrid` makes it) whose irradiance is attenuated by ambient occlusion.
//!
//! In every mode the environment is still what a perfect mirror reflects and what the camera sees
//! where it sees no geometry; only diffuse and glossy reflection use the approximation. Lights come
//! from the probe in its own frame and are rotated by `world_from_probe` here, as is the ambient.

use glam::{DMat3, Vec3};
use ibl_core::Rgb;
use ibl_light::LightSet;
use ibl_scene::{Scene, ShadowKind};
use ibl_sh::{IrradianceSh, RadianceSh};

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

    /// `hybrid` mode: the lights `set` and the `ambient` radiance (the probe minus the lights, in
    /// SH) are in the probe's frame.
    pub fn hybrid(
        scene: &Scene,
        set: &LightSet,
        ambient: &RadianceSh,
        window: ibl_sh::Window,
        shadows: ShadowKind,
        occlusion_rays: u32,
    ) -> Result<Lighting, EnvironmentError> {
        let rotation = scene.probe.world_from_probe.as_dmat3();
        Ok(Lighting {
            environment: Self::environment(scene)?,
            illumination: Illumination::Hybrid(
                light_list(scene, set, shadows),
                Ambient {
                    irradiance: ambient.rotated(rotation).irradiance(window),
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
        .filter(|l| l.irradiance.any_positive())
        .map(|l| DirectionalLight {
            direction: (rotation * l.direction).normalize().as_vec3(),
            irradiance: Rgb::new(
                l.irradiance.r as f32,
                l.irradiance.g as f32,
                l.irradiance.b as f32,
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

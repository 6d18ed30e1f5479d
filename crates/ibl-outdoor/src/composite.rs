//! Each frame's virtual objects, rendered and composited into the camera frame (Jensen, Andersen
//! & Madsen 2006, section 5, "rendering"): lit by the estimated sun as a directional light with
//! shadows and by the estimated sky as an occluded ambient, and put into the frame by differential
//! rendering (Debevec 1998) over the scene model.
//!
//! **Light.** The sun is one directional light of irradiance `pi P_d` (the estimate's `P_d`)
//! from the SPA direction, a uniform cone of the sun's 0.533-degree disc (soft shadows, traced
//! by the CPU renderer's `lights` mode). The ambient is the sky the frame was estimated with: the
//! tracker's sky shape times `P_a`, expanded to SH (world frame) and seen through the renderer's
//! occlusion rays (`hybrid` mode, `albedo mean_k V(w_k) L_sky(w_k)`): the model's buildings and
//! the objects themselves block it. That is the paper's model `P = d (c P_a + s max(0, n . l)
//! P_d)` evaluated on the virtual surfaces by ray casting, with `c` and `s` computed for the
//! object rather than read from maps. Light the buildings reflect onto the object is not
//! included (the model's interreflection transfer covers the real surfaces only); the relit map
//! is the environment the renderer's mirrors and glossy lobes see.
//!
//! **Shadows both ways.** The renderer traces every shadow and occlusion ray through the real
//! model and the objects: the objects' shadows fall on the model (the sun's and the ambient's),
//! the model's shadows fall on the objects. A real surface already in the buildings' shadow has
//! no sun in either pass of the differential render, so the object only takes away its sky
//! there: the paper's rule "virtual shadows only where the real scene is not already in shadow"
//! holds by construction, with no shadow map to mask.
//!
//! **Composite.** The ratio rule by default, `frame * with / without` on real surfaces (the
//! model's albedos cancel, so only the geometry must be right), or the difference rule
//! `frame + with - without` ([`CompositeRule`], docs/RENDERING.md); the objects themselves are
//! drawn over the frame. Cost: one `hybrid` render at the frame's size, O(W H spp (1 + k) log T)
//! ray casts for `k` occlusion rays and `T` triangles.

use glam::{Mat3, Vec3};
use ibl_core::{Image, Rgb};
use ibl_render::environment::EnvironmentLight;
use ibl_render::lighting::{Ambient, DirectionalLight, LightList};
use ibl_render::sampling::{OrthonormalBasis, UniformCone};
use ibl_render::{Illumination, Lighting, RenderOutput, RenderSettings, render};
use ibl_scene::description::{CompositeRule, LightingDescription, RenderDescription, SamplerKind};
use ibl_scene::{Background, Camera, GeometryLayer, Probe, Scene, ShadowKind};
use ibl_sh::{RadianceSh, project_latlong};

use crate::OutdoorError;
use crate::relight::SunLight;
use crate::shadow::SUN_ANGULAR_RADIUS;
use crate::sky::SkyShape;

/// Lat-long size the sky ambient is projected from (enough for 8 bands: 16 texels per band
/// along the equator).
const AMBIENT_MAP_SIZE: (usize, usize) = (128, 64);

/// How a frame is rendered and composited.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompositeSettings {
    /// Samples per pixel (antialiasing and the sun's soft shadow), at least 1.
    pub spp: u32,
    /// Occlusion rays per shading point for the sky ambient, at least 1.
    pub occlusion_rays: u32,
    /// SH bands of the sky ambient (1 to 16; the sky's horizon is sharp, so more bands ring less
    /// below it).
    pub ambient_bands: usize,
    /// How the objects' effect enters the frame.
    pub rule: CompositeRule,
    /// Random seed of the render (the same seed gives the same image).
    pub seed: u64,
}

impl Default for CompositeSettings {
    /// 16 spp, 8 occlusion rays, 8 bands, the ratio rule.
    fn default() -> Self {
        CompositeSettings {
            spp: 16,
            occlusion_rays: 8,
            ambient_bands: 8,
            rule: CompositeRule::Ratio,
            seed: 1,
        }
    }
}

/// What a frame's composite is rendered from: the model, the objects and the camera, fixed over
/// the sequence.
#[derive(Clone, Debug)]
pub struct FrameCompositor {
    /// The scene model (real layer) and the virtual objects, the camera and the probe's place.
    scene: Scene,
    settings: CompositeSettings,
}

/// One frame's lighting, as the estimation gave it.
#[derive(Clone, Copy, Debug)]
pub struct FrameLighting<'a> {
    /// The sun as a directional light (`pi P_d`, world direction).
    pub sun: SunLight,
    /// The sky shape the frame was estimated with (world frame, normalised).
    pub sky_shape: &'a SkyShape,
    /// The sky's `P_a`, RGB.
    pub sky: Rgb,
    /// The relit environment map (lat-long, probe frame, the sun left out).
    pub relit_map: &'a Image<Rgb>,
}

impl FrameCompositor {
    /// The compositor of `objects` into frames of `camera`, over the model `real`; the relit
    /// maps are in the probe's frame (`world_from_probe`) at `probe_position` (world, metres).
    pub fn new(
        real: GeometryLayer,
        objects: GeometryLayer,
        camera: Camera,
        probe_position: Vec3,
        world_from_probe: Mat3,
        settings: CompositeSettings,
    ) -> Result<FrameCompositor, OutdoorError> {
        if settings.spp == 0 || settings.occlusion_rays == 0 {
            return Err(OutdoorError::Parameter(
                "the composite needs at least 1 sample per pixel and 1 occlusion ray".into(),
            ));
        }
        if !(1..=ibl_render::lighting::MAX_AMBIENT_BANDS).contains(&settings.ambient_bands) {
            return Err(OutdoorError::Parameter(format!(
                "ambient SH bands must be 1 to {}; got {}",
                ibl_render::lighting::MAX_AMBIENT_BANDS,
                settings.ambient_bands
            )));
        }
        Ok(FrameCompositor {
            scene: Scene {
                real,
                virtual_objects: objects,
                probe: Probe {
                    radiance: Image::filled(0, 0, Rgb::ZERO),
                    world_from_probe,
                    position: probe_position,
                },
                background: Background::Panorama,
                camera,
                render: RenderDescription::default(),
                lighting: LightingDescription::default(),
                luminaires: Vec::new(),
            },
            settings,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &CompositeSettings {
        &self.settings
    }

    /// Renders the objects under `lighting` and composites them into `frame` (linear radiance,
    /// the camera's frame, any size of the camera's aspect): `composite` is the result,
    /// `with_objects` and `without_objects` the model's two renders, `object_coverage` the
    /// objects' alpha.
    pub fn composite(
        &self,
        frame: &Image<Rgb>,
        lighting: &FrameLighting,
    ) -> Result<RenderOutput, OutdoorError> {
        if frame.width() == 0 || frame.height() == 0 {
            return Err(OutdoorError::Parameter("the frame is empty".into()));
        }
        let mut scene = self.scene.clone();
        scene.background = Background::Photo(frame.clone());
        scene.probe.radiance = lighting.relit_map.clone();
        // The hybrid mode draws no environment samples: no normal bins (most of the build).
        let environment = EnvironmentLight::without_normal_bins(
            lighting.relit_map.clone(),
            scene.probe.world_from_probe,
            1.0,
        )
        .map_err(|e| OutdoorError::Parameter(format!("the relit map cannot light: {e}")))?;
        let sky = sky_ambient(
            lighting.sky_shape,
            lighting.sky,
            self.settings.ambient_bands,
        )?;
        let lights = LightList {
            lights: sun_light(&lighting.sun).into_iter().collect(),
            shadows: ShadowKind::Soft,
        };
        let illumination =
            Illumination::Hybrid(lights, Ambient::new(&sky, self.settings.occlusion_rays));
        let settings = RenderSettings {
            composite: self.settings.rule,
            width: Some(frame.width() as u32),
            spp: self.settings.spp,
            bounces: 1,
            seed: self.settings.seed,
            sampler: SamplerKind::Sobol,
            adaptive: None,
            adaptive_sampling: false,
        };
        Ok(render(
            &scene,
            &Lighting {
                environment,
                illumination,
                luminaires: Vec::new(),
            },
            &settings,
            &|_, _| {},
        )?)
    }
}

/// The sun as the renderer's light: a uniform cone of the sun's disc; `None` when the estimate
/// has no sun (overcast) or its direction is not a unit vector.
pub fn sun_light(sun: &SunLight) -> Option<DirectionalLight> {
    let irradiance = Rgb::from_array(sun.irradiance);
    let direction = Vec3::from_array(sun.direction);
    let positive = irradiance.max_channel() > 0.0; // false for NaN too
    if !positive || !direction.is_normalized() {
        return None;
    }
    Some(DirectionalLight {
        direction,
        irradiance,
        cone: UniformCone::from_half_angle(SUN_ANGULAR_RADIUS as f32),
        halo: None,
        frame: OrthonormalBasis::from_normal(direction),
        fold: None,
    })
}

/// The sky's radiance `P_a shape(w)` (zero below the horizon) as `bands` SH bands, world frame.
pub fn sky_ambient(shape: &SkyShape, sky: Rgb, bands: usize) -> Result<RadianceSh, OutdoorError> {
    let (w, h) = AMBIENT_MAP_SIZE;
    let mut map = shape.latlong(w, h, Mat3::IDENTITY);
    for px in map.pixels_mut() {
        *px = *px * sky;
    }
    project_latlong(&map, bands)
        .map_err(|e| OutdoorError::Numerical(format!("projecting the sky ambient: {e}")))
}

//! One light path per call: the radiance arriving at the camera along a primary ray, in one of
//! the three lighting modes, through the scene with or without its virtual objects.
//!
//! The estimator is a unidirectional path tracer (Kajiya 1986) with next-event estimation:
//! - **reference**: at each diffuse or glossy vertex one environment sample (importance-sampled
//!   by texel power) and the BSDF sample that continues the path are combined by the power
//!   heuristic (Veach 1997, multiple importance sampling); an escaping BSDF sample adds the probe's
//!   radiance with the complementary weight. Mirrors are delta: escaping mirror rays add the probe
//!   unweighted.
//! - **lights**: at the first vertex every light is evaluated with its own shadow ray (no noise
//!   from light choice); at later vertices one light is picked in proportion to its luminance.
//!   Escaping rays add the probe only after a mirror (the lights stand for the rest of it).
//! - **hybrid**: as lights, plus the ambient's irradiance times `albedo / pi` times the fraction
//!   of cosine-distributed occlusion rays that escape; the path then stops at diffuse and glossy
//!   vertices (the ambient already holds the indirect light), and continues through mirrors.
//!
//! Paths stop after `bounces` surface vertices, with Russian roulette from the fourth vertex on
//! (survival probability = the throughput's largest channel, at most 0.95).
//!
//! **Differential rendering support.** Every query first asks the real layer and then, in the
//! pass *with* objects, the virtual layer; [`PathRecord::touched_virtual`] says whether a virtual
//! triangle changed any answer (closer hit, or a blocked shadow ray). A path that never touched
//! the virtual layer took exactly the same steps as it would without it, so the caller can reuse
//! its value for the pass without objects, bit for bit.
//!
//! Cost per sample: O(bounces x (1 + lights at the first vertex) x log T) ray-BVH work.

use glam::Vec3;
use ibl_core::Rgb;
use ibl_scene::{Hit, Ray, Scene, ShadowKind, SurfacePoint};

use crate::lighting::{Ambient, Illumination, LightList, Lighting};
use crate::material::Bsdf;
use crate::sampling::{OrthonormalBasis, PixelRng, power_heuristic, sample_cosine_hemisphere};

/// Which layers a path may meet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layers {
    /// Real and virtual geometry (the render "with" the objects).
    WithObjects,
    /// Real geometry only (the render "without" the objects).
    RealOnly,
}

/// What the primary ray met first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrimaryHit {
    /// Nothing: the camera sees the background.
    Background,
    /// Real (local) geometry.
    Real,
    /// A virtual object.
    Virtual,
}

/// The result of one path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathRecord {
    /// Radiance along the primary ray (probe units).
    pub radiance: Rgb,
    /// What the primary ray met first.
    pub primary: PrimaryHit,
    /// Whether a virtual triangle changed any query of this path.
    pub touched_virtual: bool,
    /// Rays traced (closest-hit and shadow queries).
    pub rays: u64,
}

/// Traces paths through one scene under one lighting.
pub struct Tracer<'a> {
    scene: &'a Scene,
    lighting: &'a Lighting,
    bounces: u32,
    /// Offset of secondary ray origins along the geometric normal (scene-scaled).
    epsilon: f32,
}

/// Vertex count from which Russian roulette may end a path.
const ROULETTE_FROM: u32 = 3;

/// The query state of one path.
struct PathState {
    layers: Layers,
    touched_virtual: bool,
    rays: u64,
}

impl<'a> Tracer<'a> {
    /// A tracer for `scene` lit by `lighting`, paths of at most `bounces` surface vertices.
    pub fn new(scene: &'a Scene, lighting: &'a Lighting, bounces: u32) -> Tracer<'a> {
        let extent = [scene.real.bvh.bounds(), scene.virtual_objects.bvh.bounds()]
            .into_iter()
            .flatten()
            .map(|(lo, hi)| lo.abs().max(hi.abs()).max_element())
            .fold(scene.probe.position.abs().max_element(), f32::max);
        Tracer {
            scene,
            lighting,
            bounces: bounces.max(1),
            epsilon: 1e-4 * extent.max(1.0),
        }
    }

    /// Radiance along `ray` through `layers`, random numbers from `rng`.
    pub fn trace(&self, ray: Ray, layers: Layers, rng: &mut PixelRng) -> PathRecord {
        let mut state = PathState {
            layers,
            touched_virtual: false,
            rays: 0,
        };
        let mut radiance = Rgb::ZERO;
        let mut throughput = Rgb::ONE;
        let mut ray = ray;
        let mut primary = PrimaryHit::Background;
        // Density of the BSDF sample that made `ray` (None: camera ray or mirror).
        let mut bsdf_pdf: Option<f32> = None;
        let mut vertex = 0u32;
        loop {
            let Some((surface, is_virtual)) = self.closest(&ray, &mut state) else {
                radiance += throughput * self.escaped(ray.direction, bsdf_pdf);
                break;
            };
            if vertex == 0 {
                primary = if is_virtual {
                    PrimaryHit::Virtual
                } else {
                    PrimaryHit::Real
                };
            }
            if vertex >= self.bounces {
                break;
            }
            vertex += 1;
            let wo = -ray.direction;
            let bsdf = Bsdf::new(
                &surface.material,
                surface.shading_normal,
                surface.geometric_normal,
            );
            if !bsdf.is_delta() {
                radiance += throughput * self.direct(&surface, &bsdf, wo, vertex, rng, &mut state);
                if matches!(self.lighting.illumination, Illumination::Hybrid(..)) {
                    break;
                }
                // At the last vertex only the reference continues: its escaping BSDF sample is
                // the MIS partner of the environment sample. The lights stand for the rest.
                if vertex >= self.bounces
                    && !matches!(self.lighting.illumination, Illumination::Environment)
                {
                    break;
                }
            }
            let u = [rng.next_f32(), rng.next_f32(), rng.next_f32()];
            let Some(sample) = bsdf.sample(wo, u) else {
                break;
            };
            throughput = throughput * sample.weight;
            bsdf_pdf = (!sample.is_delta).then_some(sample.pdf_sr);
            if vertex >= ROULETTE_FROM {
                let survive = throughput.max_channel().min(0.95);
                if survive <= 0.0 || rng.next_f32() >= survive {
                    break;
                }
                throughput = throughput / survive;
            }
            ray = Ray::new(self.offset(&surface, sample.wi), sample.wi);
        }
        PathRecord {
            radiance,
            primary,
            touched_virtual: state.touched_virtual,
            rays: state.rays,
        }
    }

    /// Radiance added by a ray that left the scene; `bsdf_pdf` is the density of the BSDF sample
    /// that made it (`None` for the camera ray or a mirror bounce).
    fn escaped(&self, direction: Vec3, bsdf_pdf: Option<f32>) -> Rgb {
        let env = &self.lighting.environment;
        match (&self.lighting.illumination, bsdf_pdf) {
            // The camera, or a mirror: the probe itself in every mode.
            (_, None) => env.radiance(direction),
            (Illumination::Environment, Some(pdf)) => {
                env.radiance(direction) * power_heuristic(pdf, env.pdf(direction))
            }
            // The lights (and the ambient) stand for the probe.
            (Illumination::Lights(_) | Illumination::Hybrid(..), Some(_)) => Rgb::ZERO,
        }
    }

    /// Light arriving directly at a diffuse or glossy vertex and reflected towards `wo`.
    fn direct(
        &self,
        surface: &SurfacePoint,
        bsdf: &Bsdf,
        wo: Vec3,
        vertex: u32,
        rng: &mut PixelRng,
        state: &mut PathState,
    ) -> Rgb {
        match &self.lighting.illumination {
            Illumination::Environment => self.environment_sample(surface, bsdf, wo, rng, state),
            Illumination::Lights(list) => self.lights(list, surface, bsdf, wo, vertex, rng, state),
            Illumination::Hybrid(list, ambient) => {
                self.lights(list, surface, bsdf, wo, vertex, rng, state)
                    + self.ambient(ambient, surface, rng, state)
            }
        }
    }

    /// One environment sample, MIS-weighted against BSDF sampling.
    fn environment_sample(
        &self,
        surface: &SurfacePoint,
        bsdf: &Bsdf,
        wo: Vec3,
        rng: &mut PixelRng,
        state: &mut PathState,
    ) -> Rgb {
        let env = &self.lighting.environment;
        let sample = env.sample(rng.next_f32(), rng.next_f32());
        let wi = sample.direction;
        if sample.pdf_sr <= 0.0 {
            return Rgb::ZERO;
        }
        let Some(f_cos) = self.unblocked_reflection(surface, bsdf, wo, wi, state) else {
            return Rgb::ZERO;
        };
        let weight = power_heuristic(sample.pdf_sr, bsdf.pdf(wo, wi));
        f_cos * sample.radiance * (weight / sample.pdf_sr)
    }

    /// Directional lights: all of them at the first vertex, one chosen by power later.
    #[allow(clippy::too_many_arguments)]
    fn lights(
        &self,
        list: &LightList,
        surface: &SurfacePoint,
        bsdf: &Bsdf,
        wo: Vec3,
        vertex: u32,
        rng: &mut PixelRng,
        state: &mut PathState,
    ) -> Rgb {
        if list.lights.is_empty() {
            return Rgb::ZERO;
        }
        let mut sum = Rgb::ZERO;
        if vertex == 1 {
            for light in &list.lights {
                sum += self.one_light(list.shadows, light, surface, bsdf, wo, rng, state);
            }
        } else if let Some(choice) = list.choice.sample(rng.next_f32()) {
            let light = &list.lights[choice.index];
            sum += self.one_light(list.shadows, light, surface, bsdf, wo, rng, state)
                / choice.probability;
        }
        sum
    }

    #[allow(clippy::too_many_arguments)]
    fn one_light(
        &self,
        shadows: ShadowKind,
        light: &crate::lighting::DirectionalLight,
        surface: &SurfacePoint,
        bsdf: &Bsdf,
        wo: Vec3,
        rng: &mut PixelRng,
        state: &mut PathState,
    ) -> Rgb {
        let wi = match (shadows, light.cone) {
            (ShadowKind::Soft, Some(cone)) => {
                let local = cone.sample(rng.next_f32(), rng.next_f32());
                OrthonormalBasis::from_normal(light.direction).to_world(local)
            }
            _ => light.direction,
        };
        self.unblocked_reflection(surface, bsdf, wo, wi, state)
            .map_or(Rgb::ZERO, |f_cos| f_cos * light.irradiance)
    }

    /// `f(wo, wi) cos(theta_i)` for light arriving from `wi`, or `None` when the surface cannot
    /// reflect it (below the shading or geometric surface, a zero BSDF) or something blocks it.
    fn unblocked_reflection(
        &self,
        surface: &SurfacePoint,
        bsdf: &Bsdf,
        wo: Vec3,
        wi: Vec3,
        state: &mut PathState,
    ) -> Option<Rgb> {
        let cos = surface.shading_normal.dot(wi);
        if cos <= 0.0 || surface.geometric_normal.dot(wi) <= 0.0 {
            return None;
        }
        let f = bsdf.eval(wo, wi);
        if f.max_channel() <= 0.0 || self.occluded(surface, wi, state) {
            return None;
        }
        Some(f * cos)
    }

    /// The hybrid ambient: `albedo / pi * E_ambient(n) * visibility`, visibility the fraction of
    /// cosine-distributed rays that escape.
    fn ambient(
        &self,
        ambient: &Ambient,
        surface: &SurfacePoint,
        rng: &mut PixelRng,
        state: &mut PathState,
    ) -> Rgb {
        let albedo = surface.material.diffuse_albedo();
        if albedo.max_channel() <= 0.0 {
            return Rgb::ZERO;
        }
        let e = ambient
            .irradiance
            .irradiance(surface.shading_normal.as_dvec3());
        let irradiance = Rgb::new(
            e[0].max(0.0) as f32,
            e[1].max(0.0) as f32,
            e[2].max(0.0) as f32,
        );
        let basis = OrthonormalBasis::from_normal(surface.shading_normal);
        let mut open = 0u32;
        for _ in 0..ambient.occlusion_rays {
            let wi = basis.to_world(sample_cosine_hemisphere(rng.next_f32(), rng.next_f32()));
            if surface.geometric_normal.dot(wi) > 0.0 && !self.occluded(surface, wi, state) {
                open += 1;
            }
        }
        let visibility = open as f32 / ambient.occlusion_rays as f32;
        albedo * irradiance * (visibility / std::f32::consts::PI)
    }

    /// The origin of a ray leaving `surface` along `wi`, moved off the surface on `wi`'s side.
    fn offset(&self, surface: &SurfacePoint, wi: Vec3) -> Vec3 {
        let side = if surface.geometric_normal.dot(wi) >= 0.0 {
            1.0
        } else {
            -1.0
        };
        surface.position + surface.geometric_normal * (side * self.epsilon)
    }

    /// Closest hit through the active layers; `true` when it is virtual.
    fn closest(&self, ray: &Ray, state: &mut PathState) -> Option<(SurfacePoint, bool)> {
        state.rays += 1;
        let real = self.scene.real.bvh.closest_hit(ray, 0.0, f32::INFINITY);
        if state.layers == Layers::WithObjects {
            let limit = real.map_or(f32::INFINITY, |h: Hit| h.t);
            if let Some(hit) = self.scene.virtual_objects.bvh.closest_hit(ray, 0.0, limit) {
                state.touched_virtual = true;
                let surface =
                    self.scene
                        .virtual_objects
                        .surface_point(&hit, ray.origin, ray.direction);
                return Some((surface, true));
            }
        }
        real.map(|hit| {
            (
                self.scene
                    .real
                    .surface_point(&hit, ray.origin, ray.direction),
                false,
            )
        })
    }

    /// Whether anything blocks the direction `wi` from `surface` (to infinity: the lights and
    /// the environment are distant).
    fn occluded(&self, surface: &SurfacePoint, wi: Vec3, state: &mut PathState) -> bool {
        state.rays += 1;
        let ray = Ray::new(self.offset(surface, wi), wi);
        if self.scene.real.bvh.occluded(&ray, 0.0, f32::INFINITY) {
            return true;
        }
        if state.layers == Layers::WithObjects
            && self
                .scene
                .virtual_objects
                .bvh
                .occluded(&ray, 0.0, f32::INFINITY)
        {
            state.touched_virtual = true;
            return true;
        }
        false
    }
}

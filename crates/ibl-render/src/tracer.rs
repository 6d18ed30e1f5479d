//! One light path per call: the radiance arriving at the camera along a primary ray, in one of
//! the three lighting modes, through the scene with or without its virtual objects.
//!
//! - **reference**: a unidirectional path tracer (Kajiya 1986) with next-event estimation. At each
//!   diffuse or glossy vertex one environment sample (importance-sampled by texel power, from the
//!   probe's upper or lower half alone where the surface faces one of its poles exactly, a floor
//!   or a ceiling, else from its normal's bin, radiance times a bound of the cosine:
//!   [`crate::environment::EnvironmentLight::region_for`], clipped to the half above the floor
//!   on a virtual object standing on a real floor that is all the real geometry) and the BSDF
//!   sample that continues the path are combined by the power heuristic (Veach 1997, multiple
//!   importance sampling); an escaping BSDF sample adds the probe's radiance with the
//!   complementary weight. A diffuse
//!   floor in a scene whose real geometry is one plane takes its exact unshadowed light instead
//!   and subtracts what the two samples find blocked (`EnvironmentStrategy`, a control
//!   variate). Mirrors are delta: escaping mirror rays add the probe unweighted. Paths stop after
//!   `bounces` surface vertices, with Russian roulette from the fourth vertex on (survival
//!   probability = the throughput's largest channel, at most 0.95). Unbiased: the judge of every
//!   approximation.
//! - **lights**: deterministic direct light. At the first diffuse or glossy vertex (after any
//!   mirror bounces, which are followed exactly) every light is evaluated with its own shadow ray:
//!   along its direction (hard) or towards a point of its cone drawn from one 2-D sample of the
//!   pixel sample's stream (soft; the Sobol stream stratifies each light's cone points across the
//!   pixel's samples, and the cone's unshadowed light is exact: `Tracer::lights`). The path then
//!   ends: there is no indirect light, and no noise but the antialiasing and the soft shadows'
//!   visibility samples. Escaping rays add the probe only after a mirror.
//! - **hybrid**: as lights, plus the ambient radiance `L_a` seen through `k` cosine-distributed
//!   occlusion rays: `albedo * mean_k V(w_k) L_a(w_k)` (directional occlusion,
//!   [`crate::lighting`]).
//!
//! In every mode the lighting's goniometric point lights ([`Lighting::luminaires`]) are added at
//! each vertex that takes direct light (every vertex of the reference, the one vertex of the
//! other modes), each through a shadow ray that stops at the light. They are new lights: the
//! walk without the objects ([`Layers::RealOnly`]) has none of them, and a path's share of them
//! is [`PathRecord::new_light`], so that on real surfaces the composite adds their light to the
//! background.
//!
//! Ray origins leave a surface by its hit point's error bound (pbrt-v4 section 6.8.6): the point
//! moves along the geometric normal by `d = |n| . err` (`err` the per-axis bound of
//! [`SurfacePoint::position_error`]) to the side the ray leaves on, and each coordinate is
//! rounded one ulp further away; with the BVH's conservative `t > delta_t` test no ray can hit the
//! surface it leaves, and the offset is set by the hit's own coordinates (about `4e-7` of their
//! magnitude), never by the size of the scene.
//!
//! **Differential rendering support.** Every query first asks the real layer and then, in the
//! pass *with* objects, the virtual layer; [`PathRecord::touched_virtual`] says whether a virtual
//! triangle changed any answer (closer hit, or a blocked shadow ray). A path that never touched
//! the virtual layer took exactly the same steps as it would without it, so the caller can reuse
//! its value for the pass without objects, bit for bit. In the lights and hybrid modes a path
//! that reaches its one diffuse or glossy vertex without a virtual closest hit also evaluates
//! that vertex without the objects in the same walk ([`PathRecord::without_objects`]): each
//! shadow and occlusion ray is open, blocked by the real layer (dark in both) or blocked by the
//! virtual layer only (dark with the objects), so one set of rays gives both values, bit for bit
//! what a second walk through the real layer alone would give (the same random numbers, the same
//! sums in the same order). Only a path whose closest hit changed (the camera sees the object, or
//! a mirror reflects it) is walked again.
//!
//! Cost per sample: reference O(bounces log T) ray-BVH work; lights O(N log T) for N lights,
//! hybrid O((N + k) log T).

use glam::Vec3;
use ibl_core::Rgb;
use ibl_scene::bvh::OccluderHint;
use ibl_scene::{Hit, Ray, Scene, ShadowKind, SurfacePoint};
use rayon::prelude::*;

use crate::environment::{EnvironmentLight, SampleRegion};
use crate::lighting::{Ambient, Illumination, LightList, Lighting, RayRole};
use crate::material::Bsdf;
use crate::normal_bins::Half;
use crate::sampler::SampleStream;
use crate::sampling::{LightShading, OrthonormalBasis, power_heuristic, sample_cosine_hemisphere};

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
    /// The radiance of the same path without the objects, when this walk could tell it (the
    /// lights and hybrid modes, for a path through [`Layers::WithObjects`] that met no virtual
    /// surface): then no second walk is needed, even when [`PathRecord::touched_virtual`].
    pub without_objects: Option<Rgb>,
    /// The share of `radiance` that came from the lighting's goniometric lights: new lights,
    /// absent from the scene without the objects (a path that never touched the virtual layer
    /// is, without the objects, `radiance - new_light`).
    pub new_light: Rgb,
    /// What blocked each of the first [`VISIBILITY_LIGHTS`] lights' shadow rays at the shaded
    /// vertex, when the camera ray's own hit was shaded (no mirror before it) in the lights or
    /// hybrid mode with the objects; empty otherwise.
    pub visibility: LightVisibility,
}

/// How many lights of a light list [`LightVisibility`] follows (one bit each).
pub const VISIBILITY_LIGHTS: usize = 64;

/// Per light of a light list (bit `i` for light `i < 64`), whether its shadow ray from one
/// vertex was traced, and what blocked it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LightVisibility {
    /// The lights whose shadow ray was traced (or known).
    pub tested: u64,
    /// Of those, the ones the real layer blocked.
    pub real: u64,
    /// Of those, the ones only the virtual layer blocked.
    pub virtual_only: u64,
}

impl LightVisibility {
    /// No light.
    pub const NONE: LightVisibility = LightVisibility {
        tested: 0,
        real: 0,
        virtual_only: 0,
    };

    fn record(&mut self, index: usize, occlusion: Occlusion) {
        if index < VISIBILITY_LIGHTS {
            let bit = 1u64 << index;
            self.tested |= bit;
            match occlusion {
                Occlusion::Open => {}
                Occlusion::Real => self.real |= bit,
                Occlusion::Virtual => self.virtual_only |= bit,
            }
        }
    }

    /// What blocked light `index`, when its bit is in `tested`.
    fn occlusion(&self, index: usize) -> Option<Occlusion> {
        let bit = 1u64
            .checked_shl(index as u32)
            .filter(|_| index < VISIBILITY_LIGHTS)?;
        let occlusion = if self.real & bit != 0 {
            Occlusion::Real
        } else if self.virtual_only & bit != 0 {
            Occlusion::Virtual
        } else {
            Occlusion::Open
        };
        (self.tested & bit != 0).then_some(occlusion)
    }
}

/// Shadow answers a path may take instead of tracing (adaptive antialiasing, [`crate::adaptive`]):
/// where every first sample of one kind of surface around a pixel found a light's ray blocked
/// the same way, the pixel's samples that meet that kind of surface take that answer for that
/// light. Used only at a camera ray's own hit, with the objects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KnownVisibility {
    /// The answers for a camera ray that meets a real surface.
    pub real: LightVisibility,
    /// The answers for a camera ray that meets a virtual object.
    pub virtual_object: LightVisibility,
}

impl KnownVisibility {
    /// Nothing known: every ray is traced.
    pub const NONE: KnownVisibility = KnownVisibility {
        real: LightVisibility::NONE,
        virtual_object: LightVisibility::NONE,
    };

    /// The answers for a camera ray that met `primary`.
    fn for_hit(&self, primary: PrimaryHit) -> LightVisibility {
        match primary {
            PrimaryHit::Real => self.real,
            PrimaryHit::Virtual => self.virtual_object,
            PrimaryHit::Background => LightVisibility::NONE,
        }
    }
}

/// Whether a ray towards a distant light is blocked, and by which layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Occlusion {
    /// Nothing blocks it.
    Open,
    /// The virtual objects block it, the real layer does not.
    Virtual,
    /// The real layer blocks it (with or without the objects).
    Real,
}

/// A diffuse or glossy vertex being shaded.
struct Vertex<'a> {
    surface: &'a SurfacePoint,
    bsdf: &'a Bsdf,
    /// Unit direction towards the camera (the previous vertex).
    wo: Vec3,
    /// The BSDF's one value when it is diffuse ([`Bsdf::lambertian`]), read once per vertex.
    lambertian: Option<Rgb>,
}

/// How one vertex's environment sample and the BSDF sample leaving it share the probe's light
/// (multiple importance sampling, Veach 1997 section 9.2).
#[derive(Clone, Copy, Debug, PartialEq)]
struct EnvironmentStrategy {
    /// Where the environment sample is drawn from.
    region: SampleRegion,
    /// A control variate (Glasserman 2004, section 4.1) for a diffuse floor or ceiling (its
    /// shading normal its geometric one) in a scene whose real geometry is one plane, so that
    /// only the virtual objects can shadow it: `f E_half`, the vertex's exact unshadowed light
    /// from the probe ([`EnvironmentLight::half_irradiance`]). The vertex then takes it and
    /// subtracts what its two MIS-weighted samples find blocked: the environment sample's
    /// `w_L f L cos / p_L` where its shadow ray is blocked, the BSDF sample's `w_B f L cos /
    /// p_B` where it meets a surface (its escape adds nothing). Since the weights sum to 1,
    /// `E[sum_s w_s f L cos / p_s] = f E_half`, so the expectation is the shadowed light; with
    /// nothing in the way every sample gives the exact value in every channel, where plain MIS
    /// adds the noise of the texels' colours and of the two densities. In a shadow the
    /// estimate is as noisy as before and may fall below 0 (a blocked texel of another colour
    /// than the mean takes off more than its share in one channel), which is why closed
    /// scenes, mostly in shadow, keep plain MIS.
    unshadowed: Option<Rgb>,
}

impl EnvironmentStrategy {
    /// The strategy at `surface` (on a virtual object when `is_virtual`), seen from a vertex
    /// whose BSDF value is `lambertian` ([`Bsdf::lambertian`]); `real_plane` when the real
    /// geometry is one plane. A virtual vertex off that plane draws from its normal's bin
    /// clipped to the half on its side ([`RealPlane::open_half`]): the other half meets the
    /// plane (but past its edge, which the BSDF sample alone covers), and its light arrives
    /// through the plane's own bounce.
    fn at(
        env: &EnvironmentLight,
        surface: &SurfacePoint,
        lambertian: Option<Rgb>,
        real_plane: Option<&RealPlane>,
        is_virtual: bool,
    ) -> Self {
        let mut region = env.region_for(surface.geometric_normal);
        if let Some(half) = real_plane
            .filter(|_| is_virtual)
            .and_then(|plane| plane.open_half(env, surface.position))
        {
            region = env.within_half(region, half);
        }
        let flat = surface.shading_normal == surface.geometric_normal;
        let unshadowed = match (lambertian, env.half_irradiance(region)) {
            (Some(f), Some(irradiance)) if flat && real_plane.is_some() => Some(f * irradiance),
            _ => None,
        };
        EnvironmentStrategy { region, unshadowed }
    }
}

/// Light arriving at a vertex, with the objects and (when the walk can tell) without them.
#[derive(Clone, Copy, Debug)]
struct LayeredLight {
    with: Rgb,
    without: Option<Rgb>,
}

impl<'a> Vertex<'a> {
    fn new(surface: &'a SurfacePoint, bsdf: &'a Bsdf, wo: Vec3) -> Vertex<'a> {
        Vertex {
            surface,
            bsdf,
            wo,
            lambertian: bsdf.lambertian(wo),
        }
    }

    /// `f(wo, wi) cos(theta_i)` for light arriving from `wi`, or `None` when the surface cannot
    /// reflect it (below the shading or geometric surface, or a zero BSDF).
    #[inline]
    fn reflection(&self, wi: Vec3) -> Option<Rgb> {
        let surface = self.surface;
        let cos = surface.shading_normal.dot(wi);
        if cos <= 0.0 || surface.geometric_normal.dot(wi) <= 0.0 {
            return None;
        }
        let f = self
            .lambertian
            .unwrap_or_else(|| self.bsdf.eval(self.wo, wi));
        (f.max_channel() > 0.0).then(|| f * cos)
    }
}

impl LayeredLight {
    /// No light yet, in the layers a walk in `state` can evaluate at its vertex: without the
    /// objects too while it goes through both layers and no virtual triangle has changed any of
    /// its queries so far (decided once per vertex, before its shadow rays).
    fn none(state: &PathState) -> LayeredLight {
        LayeredLight {
            with: Rgb::ZERO,
            without: (state.layers == Layers::WithObjects && !state.touched_virtual)
                .then_some(Rgb::ZERO),
        }
    }

    /// Adds the light of a new source (a goniometric light) to the layer with the objects when
    /// the ray is open: the scene without the objects has no such light.
    #[inline]
    fn add_new(&mut self, occlusion: Occlusion, value: Rgb) {
        if occlusion == Occlusion::Open {
            self.with += value;
        }
    }

    /// Adds `value` to every layer.
    #[inline]
    fn add_all(&mut self, value: Rgb) {
        self.with += value;
        if let Some(without) = &mut self.without {
            *without += value;
        }
    }

    /// Adds `value` to the layers in which a ray blocked as `occlusion` is blocked (the
    /// complement of [`LayeredLight::add`]).
    #[inline]
    fn add_blocked(&mut self, occlusion: Occlusion, value: Rgb) {
        if occlusion != Occlusion::Open {
            self.with += value;
        }
        if let Some(without) = &mut self.without
            && occlusion == Occlusion::Real
        {
            *without += value;
        }
    }

    /// Adds `value` to the layers in which a ray blocked as `occlusion` is open.
    #[inline]
    fn add(&mut self, occlusion: Occlusion, value: Rgb) {
        if occlusion == Occlusion::Open {
            self.with += value;
        }
        if let Some(without) = &mut self.without
            && occlusion != Occlusion::Real
        {
            *without += value;
        }
    }
}

impl std::ops::Add for LayeredLight {
    type Output = LayeredLight;
    fn add(self, other: LayeredLight) -> LayeredLight {
        LayeredLight {
            with: self.with + other.with,
            without: self.without.zip(other.without).map(|(a, b)| a + b),
        }
    }
}

/// Traces paths through one scene under one lighting.
pub struct Tracer<'a> {
    scene: &'a Scene,
    lighting: &'a Lighting,
    bounces: u32,
    /// Per light of the lighting's light list, its cones' shading tables (soft shadows only).
    cone_shading: Vec<Option<LightShading>>,
    /// The plane of the real triangles when they all lie in one (a ground): then no ray leaving
    /// a real surface towards its geometric normal's side can meet the real layer.
    real_plane: Option<RealPlane>,
}

/// The one plane all real triangles lie in ([`flat_plane`]).
#[derive(Clone, Copy, Debug)]
struct RealPlane {
    /// A point of the plane (world, m).
    point: Vec3,
    /// Its unit normal (world; either side).
    normal: Vec3,
    /// How far from the plane a real triangle's corner may lie (m, [`flat_plane`]'s tolerance).
    tolerance: f32,
}

impl RealPlane {
    /// Which side of the plane `position` lies on, `1` on the normal's, `-1` on the other, when
    /// it lies farther from it than any real triangle does and than any ray origin's offset
    /// from its surface point (twice [`flat_plane`]'s tolerance, at least `1e-6` of the
    /// position's coordinates: an offset is about `4e-7` of them); else `0`. A ray from there
    /// heading away from the plane (or along it) cannot meet the real layer.
    fn side_of(&self, position: Vec3) -> f32 {
        let distance = self.normal.dot(position - self.point);
        let margin = (2.0 * self.tolerance).max(1e-6 * position.abs().max_element());
        if distance > margin {
            1.0
        } else if distance < -margin {
            -1.0
        } else {
            0.0
        }
    }

    /// The probe half ([`EnvironmentLight::half_facing`]) on `position`'s side of the plane,
    /// away from it: where a ray from there can leave without meeting the plane (up to its
    /// edge). `None` on the plane, or where the normal is not the probe's vertical axis.
    fn open_half(&self, env: &EnvironmentLight, position: Vec3) -> Option<Half> {
        let side = self.normal.dot(position - self.point);
        if side > 0.0 {
            env.half_facing(self.normal)
        } else if side < 0.0 {
            env.half_facing(-self.normal)
        } else {
            None
        }
    }
}

/// Vertex count from which Russian roulette may end a path.
const ROULETTE_FROM: u32 = 3;

/// The query state of one path.
struct PathState<'h> {
    layers: Layers,
    touched_virtual: bool,
    rays: u64,
    hints: &'h mut ShadowHints,
    /// Answers to take instead of tracing, at the vertex being shaded (emptied elsewhere).
    known: LightVisibility,
    /// The answers at the vertex being shaded (camera hits only).
    seen: LightVisibility,
    /// The vertex being shaded lies on a flat real layer ([`Tracer`]'s `real_plane`): its
    /// rays, which all leave towards the geometric normal's side, skip the real layer.
    on_flat_real: bool,
    /// The vertex being shaded is virtual and lies clear of the one real plane: `1` on its
    /// normal's side, `-1` on the other, `0` otherwise (no such plane, a real vertex, or too
    /// close to tell; [`RealPlane::side_of`]). Its rays heading away from the plane skip the
    /// real layer.
    real_side: f32,
}

/// Per light, the triangles of the real and the virtual layer that last blocked its shadow ray
/// ([`ibl_scene::bvh::Bvh::occluded_by`]): kept by the caller across the samples and pixels one
/// thread traces, so that a shadow's neighbouring rays test their likely blocker first. Only a
/// speed-up: every answer is the same with any hints.
#[derive(Clone, Debug, Default)]
pub struct ShadowHints {
    /// `[real, virtual]` per light of the light list.
    lights: Vec<[OccluderHint; 2]>,
}

impl ShadowHints {
    /// The hints of light `index`, made on first use.
    fn light(&mut self, index: usize) -> &mut [OccluderHint; 2] {
        if index >= self.lights.len() {
            self.lights.resize(index + 1, [OccluderHint::NONE; 2]);
        }
        &mut self.lights[index]
    }
}

impl<'a> Tracer<'a> {
    /// A tracer for `scene` lit by `lighting`, paths of at most `bounces` surface vertices (the
    /// lights and hybrid modes end at the first diffuse or glossy one).
    pub fn new(scene: &'a Scene, lighting: &'a Lighting, bounces: u32) -> Tracer<'a> {
        let cone_shading = match &lighting.illumination {
            Illumination::Lights(list) | Illumination::Hybrid(list, _)
                if list.shadows == ShadowKind::Soft =>
            {
                // Tabulated in parallel: 513 closed forms per cone.
                list.lights
                    .par_iter()
                    .map(|l| l.cone.map(|core| LightShading::new(core, l.halo)))
                    .collect()
            }
            _ => Vec::new(),
        };
        Tracer {
            scene,
            lighting,
            bounces: bounces.max(1),
            cone_shading,
            real_plane: flat_plane(&scene.real.triangles),
        }
    }

    /// Radiance along `ray` through `layers`, random numbers from `stream`; `hints` speed up
    /// the lights' shadow rays (keep one per thread; the result does not depend on it).
    ///
    /// `known` gives shadow answers the path takes instead of tracing at the camera ray's own
    /// hit, for the kind of surface it meets ([`KnownVisibility::NONE`]: none).
    pub fn trace(
        &self,
        ray: Ray,
        layers: Layers,
        stream: &mut SampleStream,
        hints: &mut ShadowHints,
        known: &KnownVisibility,
    ) -> PathRecord {
        let mut state = PathState {
            layers,
            touched_virtual: false,
            rays: 0,
            hints,
            known: LightVisibility::default(),
            seen: LightVisibility::default(),
            on_flat_real: false,
            real_side: 0.0,
        };
        let mut radiance = Rgb::ZERO;
        let mut throughput = Rgb::ONE;
        let mut ray = ray;
        let mut primary = PrimaryHit::Background;
        // Density of the BSDF sample that made `ray` (None: camera ray or mirror), and how its
        // vertex's environment sample (its MIS partner) was drawn.
        let mut bsdf_pdf: Option<(f32, EnvironmentStrategy)> = None;
        let mut strategy = EnvironmentStrategy {
            region: SampleRegion::Sphere,
            unshadowed: None,
        };
        let mut vertex = 0u32;
        let mut without_objects = None;
        let mut new_light = Rgb::ZERO;
        loop {
            let Some((surface, is_virtual)) = self.closest(&ray, &mut state) else {
                radiance += throughput * self.escaped(ray.direction, bsdf_pdf);
                break;
            };
            if let Some((pdf, strategy)) = bsdf_pdf
                && strategy.unshadowed.is_some()
            {
                // A blocked BSDF sample of a control-variate vertex takes its share of the
                // probe's light back off ([`EnvironmentStrategy::unshadowed`]).
                radiance =
                    radiance - throughput * self.bsdf_share(ray.direction, pdf, strategy.region);
            }
            state.on_flat_real = self.real_plane.is_some() && !is_virtual;
            state.real_side = match &self.real_plane {
                Some(plane) if is_virtual => plane.side_of(surface.position),
                _ => 0.0,
            };
            if vertex == 0 {
                primary = if is_virtual {
                    PrimaryHit::Virtual
                } else {
                    PrimaryHit::Real
                };
                if layers == Layers::WithObjects {
                    state.known = known.for_hit(primary);
                }
            } else {
                state.known = LightVisibility::default();
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
                match &self.lighting.illumination {
                    Illumination::Environment => {
                        let vertex = Vertex::new(&surface, &bsdf, wo);
                        strategy = EnvironmentStrategy::at(
                            &self.lighting.environment,
                            &surface,
                            vertex.lambertian,
                            self.real_plane.as_ref(),
                            is_virtual,
                        );
                        if let Some(unshadowed) = strategy.unshadowed
                            && state.layers == Layers::RealOnly
                            && state.on_flat_real
                        {
                            // Without the objects nothing shadows a vertex on the one real
                            // plane (its rays skip the plane, and the luminaires are new
                            // lights): the control variate is its exact light, and its BSDF
                            // sample can only escape, adding nothing. The walk ends here, with
                            // the value the samples would have given.
                            radiance += throughput * unshadowed;
                            break;
                        }
                        let none = LayeredLight::none(&state);
                        let luminaires = self.luminaires(&vertex, &mut state, none);
                        new_light += throughput * luminaires.with;
                        radiance += throughput
                            * (self.environment_sample(&vertex, strategy, stream, &mut state)
                                + luminaires.with);
                    }
                    Illumination::Lights(list) => {
                        let none = LayeredLight::none(&state);
                        let vertex = Vertex::new(&surface, &bsdf, wo);
                        let lamps = self.luminaires(&vertex, &mut state, none);
                        new_light += throughput * lamps.with;
                        let direct = self.lights(list, &vertex, stream, &mut state, none) + lamps;
                        without_objects = direct
                            .without
                            .map(|w| radiance + throughput * w.map(|v| v.max(0.0)));
                        radiance += throughput * direct.with.map(|v| v.max(0.0));
                        break;
                    }
                    Illumination::Hybrid(list, ambient) => {
                        let none = LayeredLight::none(&state);
                        let vertex = Vertex::new(&surface, &bsdf, wo);
                        let lamps = self.luminaires(&vertex, &mut state, none);
                        new_light += throughput * lamps.with;
                        let direct = self.lights(list, &vertex, stream, &mut state, none)
                            + lamps
                            + self.ambient(ambient, &surface, stream, &mut state, none);
                        without_objects = direct
                            .without
                            .map(|w| radiance + throughput * w.map(|v| v.max(0.0)));
                        radiance += throughput * direct.with.map(|v| v.max(0.0));
                        break;
                    }
                }
            }
            // At the last vertex the reference still draws the BSDF sample: escaping, it is the
            // MIS partner of the environment sample.
            // A diffuse or mirror BSDF has no lobe to choose: its number is skipped, not drawn
            // (the same later numbers, one Sobol pair's hashing less per vertex).
            let lobe = if bsdf.chooses_lobe() {
                stream.next_1d()
            } else {
                stream.skip_1d();
                0.0
            };
            let [u1, u2] = stream.next_2d();
            let Some(sample) = bsdf.sample(wo, [lobe, u1, u2]) else {
                break;
            };
            throughput = throughput * sample.weight;
            bsdf_pdf = (!sample.is_delta).then_some((sample.pdf_sr, strategy));
            if vertex >= ROULETTE_FROM {
                let survive = throughput.max_channel().min(0.95);
                if survive <= 0.0 || stream.next_1d() >= survive {
                    break;
                }
                throughput = throughput / survive;
            }
            ray = Ray::new(offset_origin(&surface, sample.wi), sample.wi);
        }
        PathRecord {
            radiance,
            primary,
            touched_virtual: state.touched_virtual,
            rays: state.rays,
            without_objects,
            new_light,
            visibility: if vertex == 1 && layers == Layers::WithObjects {
                state.seen
            } else {
                LightVisibility::default()
            },
        }
    }

    /// Radiance added by a ray that left the scene; `bsdf_pdf` is the density of the BSDF sample
    /// that made it and how its vertex's environment sample was drawn (`None` for the camera
    /// ray or a mirror bounce).
    fn escaped(&self, direction: Vec3, bsdf_pdf: Option<(f32, EnvironmentStrategy)>) -> Rgb {
        let env = &self.lighting.environment;
        match (&self.lighting.illumination, bsdf_pdf) {
            // The camera, or a mirror: the probe itself in every mode.
            (_, None) => env.radiance(direction),
            // Already in the vertex's unshadowed light.
            (Illumination::Environment, Some((_, strategy))) if strategy.unshadowed.is_some() => {
                Rgb::ZERO
            }
            (Illumination::Environment, Some((pdf, strategy))) => {
                self.bsdf_share(direction, pdf, strategy.region)
            }
            // The lights (and the ambient) stand for the probe; their paths end at the first
            // diffuse or glossy vertex, so this arm is only reached by a BSDF sample there.
            (Illumination::Lights(_) | Illumination::Hybrid(..), Some(_)) => Rgb::ZERO,
        }
    }

    /// The probe's light along `direction`, MIS-weighted for a BSDF sample of density `pdf`
    /// whose vertex drew its environment sample from `region`: what the sample adds when it
    /// escapes, or, at a control-variate vertex ([`EnvironmentStrategy::unshadowed`]), what it
    /// takes off when it meets a surface.
    fn bsdf_share(&self, direction: Vec3, pdf: f32, region: SampleRegion) -> Rgb {
        let (radiance, env_pdf) = self
            .lighting
            .environment
            .radiance_and_pdf_in(region, direction);
        radiance * power_heuristic(pdf, env_pdf)
    }

    /// One environment sample from the strategy's region (the half a floor or ceiling can see,
    /// else the normal's bin: [`crate::environment::EnvironmentLight::region_for`]),
    /// MIS-weighted against BSDF sampling ([`EnvironmentStrategy`]).
    fn environment_sample(
        &self,
        vertex: &Vertex,
        strategy: EnvironmentStrategy,
        stream: &mut SampleStream,
        state: &mut PathState,
    ) -> Rgb {
        let env = &self.lighting.environment;
        let [u1, u2] = stream.next_2d();
        let drawn = env.direction_in(strategy.region, u1, u2);
        let wi = drawn.direction;
        // Plain MIS needs the sample's density before its shadow ray; a control-variate vertex
        // reads the texel only where the ray is blocked (most of its samples are open and add
        // nothing), which spares a cache miss into the probe per floor vertex.
        let sample = strategy
            .unshadowed
            .is_none()
            .then(|| env.texel_of_draw(drawn));
        let possible = sample.is_none_or(|s| s.pdf_sr > 0.0);
        let reflection = possible.then(|| vertex.reflection(wi)).flatten();
        // Plain MIS adds the sample's light where its shadow ray is open; the control variate
        // ([`EnvironmentStrategy::unshadowed`]) takes it off where the ray is blocked. A sample
        // that could not light the vertex (zero density, below the surface) does neither.
        let light = match reflection {
            Some(f_cos)
                if (self.occlusion(above(vertex.surface), wi, state) == Occlusion::Open)
                    != strategy.unshadowed.is_some() =>
            {
                let sample = sample.unwrap_or_else(|| env.texel_of_draw(drawn));
                if sample.pdf_sr > 0.0 {
                    let weight = power_heuristic(sample.pdf_sr, vertex.bsdf.pdf(vertex.wo, wi));
                    f_cos * sample.radiance * (weight / sample.pdf_sr)
                } else {
                    Rgb::ZERO
                }
            }
            _ => Rgb::ZERO,
        };
        match strategy.unshadowed {
            Some(unshadowed) => unshadowed - light,
            None => light,
        }
    }

    /// Every light, each with its own shadow ray (all from one origin above the surface: a
    /// light below the geometric surface sends none).
    ///
    /// A hard light adds `f(w_o, l) cos(theta_l) I` where its ray along `l` is open. A soft light
    /// (a cone of uniform radiance `L`, `I = L A`) adds `f I (mean_cone(max(0, n . w)) - c_s
    /// (1 - V(w_s)))`: its unshadowed light exact
    /// ([`crate::sampling::UniformCone::mean_clamped_cosine`], through [`LightShading`], also
    /// where the horizon cuts the cone),
    /// less what the cone point `w_s` (uniform in the cone) finds blocked, `c_s = max(0, n .
    /// w_s)` (a light with a halo: `mean_cone` is its two cones' share-weighted mean, and one
    /// point in each cone takes off its share). Since `E[c_s] = mean_cone(max(0, n . w))` this is a control variate: its
    /// expectation is the cone's shadowed light `f L int_cone max(0, n . w) V(w) dw` (for a
    /// diffuse surface exactly; a glossy lobe is read at the axis, [`cone_bsdf`]), the same as
    /// `f I c_s V(w_s)` per point, but where the ray is open it is the exact unshadowed value,
    /// the same in every sample, so a pixel's samples differ only where a cone is partly or
    /// wholly hidden, which is what adaptive antialiasing ([`crate::adaptive`]) looks for. A
    /// cone point below the shading surface adds nothing (`c_s = 0`) and sends no ray; one above
    /// it but below the geometric surface is blocked by the surface itself. A light whose answer
    /// is known for the whole cone (adaptive antialiasing's agreeing neighbours) adds its exact
    /// light where open and nothing where blocked, with no cone point. A light folded onto its
    /// side of the horizon ([`crate::lighting::DirectionalLight::fold`]) has no closed form:
    /// it adds `f I c_s V(w_s)` for its mirrored cone point (per cone, by share), unbiased and
    /// never negative (the per-sample light is clamped at zero, which a control variate's
    /// negative corrections would bias), and is never lent by its neighbours.
    fn lights(
        &self,
        list: &LightList,
        vertex: &Vertex,
        stream: &mut SampleStream,
        state: &mut PathState,
        mut sum: LayeredLight,
    ) -> LayeredLight {
        let origin = above(vertex.surface);
        let surface = vertex.surface;
        for (index, light) in list.lights.iter().enumerate() {
            match (list.shadows, light.cone) {
                (ShadowKind::Soft, Some(core)) => {
                    let axis = light.direction;
                    let cos_beta = surface.shading_normal.dot(axis);
                    let mean_cos = match &self.cone_shading.get(index) {
                        Some(Some(table)) => table.mean_clamped_cosine(cos_beta),
                        _ => light.mean_clamped_cosine(cos_beta),
                    };
                    let f = cone_bsdf(vertex, axis, cos_beta);
                    // A light with a halo draws a cone point in each of its two cones.
                    let points = if light.halo.is_some() { 2 } else { 1 };
                    // A folded light's mirrored points may face a surface its whole cones do
                    // not face.
                    if (mean_cos <= 0.0 && light.fold.is_none()) || f.max_channel() <= 0.0 {
                        (0..points).for_each(|_| stream.skip_2d());
                        continue;
                    }
                    let light_value = f * light.irradiance;
                    let halo = light.halo;
                    // A folded light's unshadowed value is not its cones' mean cosine, so its
                    // neighbourhood's answer cannot stand for it.
                    let known = state
                        .known
                        .occlusion(index)
                        .filter(|_| light.fold.is_none());
                    if let Some(occlusion) =
                        known.filter(|&o| halo.is_none() || o == Occlusion::Open)
                    {
                        // Known from the neighbourhood for the whole cone: its exact light where
                        // it is open, nothing where it is blocked; no cone point is needed. A
                        // light with a halo is lent only "open": its record says open only where
                        // both its rays were.
                        (0..points).for_each(|_| stream.skip_2d());
                        let occlusion = self.known_occlusion(index, occlusion, state);
                        sum.add(occlusion, light_value * mean_cos);
                        continue;
                    }
                    // The unshadowed cone, exact, in every layer; then what the cone point's
                    // ray finds blocked is taken off where it is blocked. A light with a halo
                    // sends one ray into each cone, each taking off its cone's share (two rays,
                    // not one into a cone chosen by its share: a halo holding 4 % of a sun
                    // would otherwise take off the whole sun 4 % of the time, speckles at 4
                    // samples a pixel); its record for the neighbourhood is "open" where both
                    // rays were, else the first blocked one's answer.
                    // A light folded onto its side of the horizon has no closed-form unshadowed
                    // value: each of its (mirrored) cone points adds its own light where open,
                    // unbiased and never negative, at the price of noise on open surfaces.
                    let folded = light.fold.is_some();
                    if !folded {
                        sum.add_all(light_value * mean_cos);
                    }
                    let core_share = halo.map_or(1.0, |(_, share)| 1.0 - share);
                    let cones = std::iter::once((core, core_share)).chain(halo);
                    let mut record = None;
                    for (cone, share) in cones {
                        let [u1, u2] = stream.next_2d();
                        let sampled = light.frame.to_world(cone.sample(u1, u2));
                        let point = light.folded(sampled).unwrap_or(sampled);
                        let cos = surface.shading_normal.dot(point);
                        if cos <= 0.0 {
                            // Below the shading surface the cone adds nothing: nothing to take
                            // off.
                            continue;
                        }
                        let occlusion = if surface.geometric_normal.dot(point) <= 0.0 {
                            // Above the shading surface but below the geometric one: the
                            // surface itself hides it (as in `Vertex::reflection`), in every
                            // layer.
                            Occlusion::Real
                        } else if halo.is_some() {
                            let occlusion =
                                self.traced_light_occlusion(origin, point, index, state);
                            if record.is_none() || record == Some(Occlusion::Open) {
                                record = Some(occlusion);
                            }
                            occlusion
                        } else {
                            self.light_occlusion(origin, point, index, state)
                        };
                        if folded {
                            sum.add(occlusion, light_value * (share * cos));
                        } else {
                            sum.add_blocked(occlusion, light_value * (share * -cos));
                        }
                    }
                    if let Some(occlusion) = record {
                        state.seen.record(index, occlusion);
                    }
                }
                _ => {
                    let wi = light.direction;
                    if let Some(f_cos) = vertex.reflection(wi) {
                        let occlusion = self.light_occlusion(origin, wi, index, state);
                        sum.add(occlusion, f_cos * light.irradiance);
                    }
                }
            }
        }
        sum
    }

    /// Every goniometric point light (Grosch 2005 EQ5 times the BSDF): `f cos(theta_i) I(-w_i) /
    /// d^2`, `w_i` the unit direction to the light and `d` its distance, with a shadow ray that
    /// stops at the light (a light below the geometric surface sends none). They are new light
    /// sources (Grosch 2005 section 4.2): the scene without the objects, whose light the
    /// background already shows, has none of theirs, so on real surfaces the composite adds
    /// their light.
    fn luminaires(
        &self,
        vertex: &Vertex,
        state: &mut PathState,
        mut sum: LayeredLight,
    ) -> LayeredLight {
        if self.lighting.luminaires.is_empty() || state.layers == Layers::RealOnly {
            return sum;
        }
        let origin = above(vertex.surface);
        for light in &self.lighting.luminaires {
            let to_light = light.position - origin;
            let d2 = to_light.length_squared();
            if !(d2 > 0.0 && d2.is_finite()) {
                continue;
            }
            let distance = d2.sqrt();
            let wi = to_light / distance;
            let Some(f_cos) = vertex.reflection(wi) else {
                continue;
            };
            let intensity = light.intensity_towards(-wi);
            if intensity.max_channel() <= 0.0 {
                continue;
            }
            let occlusion = self.occlusion_within(origin, wi, distance, state);
            sum.add_new(occlusion, f_cos * intensity / d2);
        }
        sum
    }

    /// The hybrid ambient, `albedo E[V(w) L_a(w)]` over cosine-distributed `w`. Without halves
    /// the unoccluded part is exact: `albedo (E_a(n) / pi - mean_k (1 - V(w_k)) L_a(w_k))`,
    /// `E_a` the ambient's SH irradiance ([`Ambient::irradiance`]), since `E[L_a(w)] = E_a(n) /
    /// pi` under the cosine density: the same expectation as `mean_k V(w_k) L_a(w_k)` (a
    /// control variate), but where no occlusion ray is blocked there is no noise at all. Split
    /// at the horizon (module notes of `lighting`, "The ambient at the horizon"), it starts from
    /// the upper half's irradiance `E_up(n)` ([`Ambient::starting_irradiance`]), takes off what
    /// blocked rays above the horizon read and adds what open rays below it read:
    /// `albedo (E_up(n) / pi - mean_k [w_k up] (1 - V) L_up(w_k) + mean_k [w_k down] V
    /// L_down(w_k))`, the same expectation again, and no noise where the sky is open and the
    /// ground is closed. Only the rays that count evaluate `L_a`. A direction below the
    /// geometric surface is blocked by it.
    fn ambient(
        &self,
        ambient: &Ambient,
        surface: &SurfacePoint,
        stream: &mut SampleStream,
        state: &mut PathState,
        none: LayeredLight,
    ) -> LayeredLight {
        let albedo = surface.material.diffuse_albedo();
        if albedo.max_channel() <= 0.0 {
            return none;
        }
        let basis = OrthonormalBasis::from_normal(surface.shading_normal);
        let origin = above(surface);
        // The ambient light the rays find blocked (rays whose light the estimate starts
        // with) and open (rays whose light it starts without), in each layer.
        let mut hidden = none;
        let mut found = none;
        // The rays of one vertex are stratified together (`SampleStream::pairs`).
        for [u1, u2] in stream.pairs(ambient.occlusion_rays) {
            let wi = basis.to_world(sample_cosine_hemisphere(u1, u2));
            let occlusion = if surface.geometric_normal.dot(wi) > 0.0 {
                self.occlusion(origin, wi, state)
            } else {
                Occlusion::Real
            };
            match ambient.ray_role(wi) {
                RayRole::TakenOffWhereBlocked if occlusion != Occlusion::Open => {
                    hidden.add_blocked(occlusion, ambient.radiance(wi));
                }
                RayRole::AddedWhereOpen if occlusion != Occlusion::Real => {
                    found.add(occlusion, ambient.radiance(wi));
                }
                _ => {}
            }
        }
        let start =
            ambient.starting_irradiance(surface.shading_normal) * std::f32::consts::FRAC_1_PI;
        let k = ambient.occlusion_rays as f32;
        let light = |hidden: Rgb, found: Rgb| albedo * (start + (found - hidden) / k);
        LayeredLight {
            with: light(hidden.with, found.with),
            without: hidden.without.zip(found.without).map(|(h, f)| light(h, f)),
        }
    }

    /// Whether a ray along `direction` from the vertex being shaded cannot meet the real layer,
    /// which is one plane, and so skips it: the vertex lies on that plane
    /// ([`PathState::on_flat_real`]; it cannot meet it again, [`flat_plane`]: a floor's BSDF
    /// ray, 6 % of a bunny-on-a-floor render's instructions were its two triangle tests), or
    /// the ray heads away from it from an object clear of it ([`PathState::real_side`]: an
    /// object's rays upwards from above a floor, all of its environment samples and half of its
    /// BSDF samples; 1 %).
    #[inline]
    fn skips_real_layer(&self, direction: Vec3, state: &PathState) -> bool {
        state.on_flat_real
            || (state.real_side != 0.0
                && self
                    .real_plane
                    .is_some_and(|plane| state.real_side * plane.normal.dot(direction) >= 0.0))
    }

    /// Closest hit through the active layers; `true` when it is virtual. The real layer is
    /// skipped where the ray cannot meet it ([`Tracer::skips_real_layer`]).
    fn closest(&self, ray: &Ray, state: &mut PathState) -> Option<(SurfacePoint, bool)> {
        state.rays += 1;
        let real = if self.skips_real_layer(ray.direction, state) {
            None
        } else {
            self.scene.real.bvh.closest_hit(ray, 0.0, f32::INFINITY)
        };
        if state.layers == Layers::WithObjects {
            let limit = real.map_or(f32::INFINITY, |h: Hit| h.t);
            if let Some(hit) = self.scene.virtual_objects.bvh.closest_hit(ray, 0.0, limit) {
                state.touched_virtual = true;
                let surface = self
                    .scene
                    .virtual_objects
                    .surface_point(&hit, ray.direction);
                return Some((surface, true));
            }
        }
        real.map(|hit| (self.scene.real.surface_point(&hit, ray.direction), false))
    }

    /// What blocks the direction `wi` from `origin` (a point just above a surface, [`above`]),
    /// to infinity: the lights and the environment are distant.
    fn occlusion(&self, origin: Vec3, wi: Vec3, state: &mut PathState) -> Occlusion {
        self.occlusion_within(origin, wi, f32::INFINITY, state)
    }

    /// [`Tracer::occlusion`] for a ray towards light `index` of the light list: the known answer
    /// where there is one, else traced with each layer's blocker of that light's previous ray
    /// tested first; recorded in the path's visibility.
    fn light_occlusion(
        &self,
        origin: Vec3,
        wi: Vec3,
        index: usize,
        state: &mut PathState,
    ) -> Occlusion {
        if let Some(occlusion) = state.known.occlusion(index) {
            return self.known_occlusion(index, occlusion, state);
        }
        let occlusion = self.traced_light_occlusion(origin, wi, index, state);
        state.seen.record(index, occlusion);
        occlusion
    }

    /// What blocks light `index`'s shadow ray from `origin` along `wi`, traced (with the light's
    /// shadow-cache hints), neither lent by the neighbourhood nor recorded for it.
    fn traced_light_occlusion(
        &self,
        origin: Vec3,
        wi: Vec3,
        index: usize,
        state: &mut PathState,
    ) -> Occlusion {
        let mut hints = *state.hints.light(index);
        let occlusion = self.blocked(origin, wi, f32::INFINITY, &mut hints, state);
        *state.hints.light(index) = hints;
        occlusion
    }

    /// Takes `occlusion`, known for light `index` without tracing, as its shadow ray's answer.
    fn known_occlusion(
        &self,
        index: usize,
        occlusion: Occlusion,
        state: &mut PathState,
    ) -> Occlusion {
        if occlusion == Occlusion::Virtual {
            state.touched_virtual = true;
        }
        state.seen.record(index, occlusion);
        occlusion
    }

    /// What blocks the segment from `origin` along the unit `wi` to distance `t_max` (a point
    /// light there: what lies beyond it does not shadow).
    fn occlusion_within(
        &self,
        origin: Vec3,
        wi: Vec3,
        t_max: f32,
        state: &mut PathState,
    ) -> Occlusion {
        self.blocked(origin, wi, t_max, &mut [OccluderHint::NONE; 2], state)
    }

    /// One shadow ray: the real layer (unless the ray cannot meet it,
    /// [`Tracer::skips_real_layer`]), then, in the walk
    /// with the objects, the virtual layer, each testing its triangle in `hints` (`[real,
    /// virtual]`) first and leaving its blocker there.
    fn blocked(
        &self,
        origin: Vec3,
        wi: Vec3,
        t_max: f32,
        hints: &mut [OccluderHint; 2],
        state: &mut PathState,
    ) -> Occlusion {
        state.rays += 1;
        let ray = Ray::new(origin, wi);
        let [real, virtual_layer] = hints;
        if !self.skips_real_layer(wi, state)
            && self.scene.real.bvh.occluded_by(&ray, 0.0, t_max, real)
        {
            return Occlusion::Real;
        }
        if state.layers == Layers::WithObjects
            && self
                .scene
                .virtual_objects
                .bvh
                .occluded_by(&ray, 0.0, t_max, virtual_layer)
        {
            state.touched_virtual = true;
            return Occlusion::Virtual;
        }
        Occlusion::Open
    }
}

/// The plane all of `triangles` lie in, to 1e-6 of their extent (`None` when they do not, when
/// there are none or all are degenerate): the plane of the first triangle with an area, every
/// corner checked against it. A ray leaving such a layer's surface on the side it leaves cannot
/// meet the layer again (the intersection test would reject the hit at `t = 0` anyway); the
/// tolerance is far below the rays' origin offsets' effect on anything but grazing rays.
fn flat_plane(triangles: &[[Vec3; 3]]) -> Option<RealPlane> {
    let (normal, corner) = triangles.iter().find_map(|[a, b, c]| {
        let n = (*b - *a).cross(*c - *a);
        (n.length_squared() > 0.0).then(|| (n.normalize(), *a))
    })?;
    let extent = triangles
        .iter()
        .flatten()
        .map(|p| p.abs().max_element())
        .fold(0.0f32, f32::max);
    let tolerance = 1e-6 * extent.max(f32::MIN_POSITIVE);
    triangles
        .iter()
        .flatten()
        .all(|p| normal.dot(*p - corner).abs() <= tolerance)
        .then_some(RealPlane {
            point: corner,
            normal,
            tolerance,
        })
}

/// How far above the shading horizon [`cone_bsdf`] reads a lobe whose cone axis is below it
/// (the cosine of the direction it reads to the normal).
const HORIZON_LIFT: f32 = 0.05;

/// The BSDF a soft light's cone about `axis` (at `cos_beta` to the shading normal) is shaded
/// with: at the axis, or, when the axis is below the horizon while part of the cone is above,
/// just above the horizon towards the light (a diffuse lobe is the same everywhere above; the
/// part of the cone below adds nothing, through the cone's clamped cosine).
fn cone_bsdf(vertex: &Vertex, axis: Vec3, cos_beta: f32) -> Rgb {
    if let Some(f) = vertex.lambertian {
        return f;
    }
    let f = vertex.bsdf.eval(vertex.wo, axis);
    if f.max_channel() > 0.0 {
        return f;
    }
    let n = vertex.surface.shading_normal;
    let lifted = (axis + n * (HORIZON_LIFT - cos_beta)).normalize_or(n);
    let f = vertex.bsdf.eval(vertex.wo, lifted);
    if f.max_channel() > 0.0 {
        f
    } else {
        vertex.bsdf.eval(vertex.wo, n)
    }
}

/// The origin of every ray that leaves `surface` on its geometric normal's side (shadow and
/// occlusion rays, which are only traced there): [`offset_origin`] along that normal.
fn above(surface: &SurfacePoint) -> Vec3 {
    offset_origin(surface, surface.geometric_normal)
}

/// The origin of a ray leaving `surface` along `wi`: the hit point moved along the geometric
/// normal, to `wi`'s side, by `|n| . err`, then every coordinate rounded one ulp away from the
/// surface (pbrt-v4 `OffsetRayOrigin`, section 6.8.6).
pub fn offset_origin(surface: &SurfacePoint, wi: Vec3) -> Vec3 {
    let n = surface.geometric_normal;
    let distance = n.abs().dot(surface.position_error);
    let offset = if n.dot(wi) >= 0.0 {
        n * distance
    } else {
        n * -distance
    };
    let p = surface.position + offset;
    let away = |p: f32, o: f32| {
        if o > 0.0 {
            p.next_up()
        } else if o < 0.0 {
            p.next_down()
        } else {
            p
        }
    };
    Vec3::new(
        away(p.x, offset.x),
        away(p.y, offset.y),
        away(p.z, offset.z),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ground_is_flat_and_a_box_is_not() {
        let quad = [
            [
                Vec3::new(-20.0, -1.0, -20.0),
                Vec3::new(20.0, -1.0, -20.0),
                Vec3::new(20.0, -1.0, 20.0),
            ],
            [
                Vec3::new(-20.0, -1.0, -20.0),
                Vec3::new(20.0, -1.0, 20.0),
                Vec3::new(-20.0, -1.0, 20.0),
            ],
        ];
        let plane = flat_plane(&quad).expect("flat");
        assert_eq!(plane.normal.abs(), Vec3::Y);
        assert_eq!(plane.point.y, -1.0);
        // A tilted plane through rounding.
        let tilt = glam::Quat::from_rotation_x(0.3);
        let tilted: Vec<[Vec3; 3]> = quad.iter().map(|t| t.map(|p| tilt * p)).collect();
        assert!(flat_plane(&tilted).is_some());
        let mut bent = quad;
        bent[1][2].y = -0.99;
        assert!(flat_plane(&bent).is_none());
        assert!(flat_plane(&[]).is_none());
        assert!(flat_plane(&[[Vec3::ZERO; 3]]).is_none());

        // Sides: clear of the plane by more than twice the tolerance (2 x 1e-6 x 20 m), or
        // undecided.
        let up = plane.normal.y;
        assert_eq!(plane.side_of(Vec3::new(0.3, -0.5, 2.0)), up);
        assert_eq!(plane.side_of(Vec3::new(0.3, -1.5, 2.0)), -up);
        assert_eq!(plane.side_of(Vec3::new(0.3, -1.0 + 1e-5, 2.0)), 0.0);
        assert_eq!(plane.side_of(Vec3::new(0.3, -1.0 - 1e-5, 2.0)), 0.0);
        assert_eq!(plane.side_of(Vec3::new(0.3, -1.0 + 1e-4, 2.0)), up);
    }
}

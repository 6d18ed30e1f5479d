//! What lights a render, per mode (Madsen & Laursen 2006 section 5; Grosch 2005 section 4.1):
//!
//! - **reference**: the whole probe as an environment light, importance-sampled
//!   ([`EnvironmentLight`]), combined with BSDF sampling by multiple importance sampling;
//! - **lights**: a [`LightSet`] of directional lights, each with hard shadows (one shadow ray along
//!   its direction) or soft shadows (the light is a cone of uniform radiance of its own solid
//!   angle `A_i`, half-angle `acos(1 - A_i / 2 pi)`: a window is not a point), evaluated at the
//!   first diffuse or glossy surface a camera ray (or its mirror reflections) meets: deterministic
//!   direct light, one shadow ray per light per pixel sample;
//! - **hybrid**: the lights as above plus an SH ambient radiance `L_a`, the probe minus what the
//!   lights carry ([`Ambient`]), seen through cosine-distributed occlusion rays.
//!
//! **The hybrid's ambient.** `ibl_extract::Hybrid` subtracts each light as a point source,
//! `L_a,lm = L_lm - sum_i I_i Y_lm(w_i)`, which is right for hard shadows. A soft light is a cone,
//! whose projection is its point projection times the cap's zonal factor
//! `g_l = (P_{l-1}(c) - P_{l+1}(c)) / ((2l + 1)(1 - c))`, `c = cos(half-angle)` (the mean of
//! `P_l` over the cap, by `int_c^1 P_l = (P_{l-1}(c) - P_{l+1}(c)) / (2l + 1)` and the addition
//! theorem; `g_0 = 1`, `g_l -> 1` for a point): so with soft shadows the ambient gets back
//! `sum_i I_i (1 - g_l) Y_lm(w_i)`, and lights plus ambient carry exactly the probe's low bands
//! whatever the shadow kind. Where the lights cover the probe (median cut) the ambient is the
//! small, signed low-band difference between the probe and the lights; where they do not (the
//! `sun` method) it is the rest of the sky. Either way it is shadowed per direction
//! ("directional occlusion"): a diffuse vertex adds `albedo * mean_k V(w_k) L_a(w_k)` over `k`
//! cosine-distributed directions `w_k` (`f cos / pdf = albedo`), so an occluder darkens only the
//! part of the ambient it hides. The former scheme, `albedo E_a(n) / pi` times the fraction of
//! open rays, clamped `E_a` at 0 where the signed difference is negative and darkened every
//! direction alike: near-black patches on the bunny. The vertex's light (lights plus ambient) is
//! clamped at 0 per channel.
//!
//! **Goniometric lights** (Grosch 2005 section 4.2, new light sources): in every mode the
//! lighting may also hold point lights with measured intensity distributions
//! ([`Lighting::luminaires`], `ibl_light::GoniometricLight`, positioned in the world frame: a
//! scene file's `[[luminaire]]` entries, `Scene::luminaires`, and any added by
//! [`Lighting::with_luminaires`]). A
//! diffuse or glossy vertex adds `f cos(theta_i) I(-w_i) / d^2` for each (EQ5 times the BSDF),
//! with one shadow ray to the light's position: a delta light, so it is exact and noise-free, and
//! neither the camera nor a BSDF sample can meet it. In the reference every path vertex adds it
//! (next-event estimation: the light's indirect share comes from the later vertices); in the
//! lights and hybrid modes only the one vertex they shade.
//!
//! In every mode the environment is still what a perfect mirror reflects and what the camera sees
//! where it sees no geometry; only diffuse and glossy reflection use the approximation. Lights come
//! from the probe in its own frame and are rotated by `world_from_probe` here, as is the ambient.

use std::f64::consts::TAU;

use glam::{DMat3, DVec3, Vec3};
use ibl_core::Rgb;
use ibl_light::{GoniometricLight, LightSet};
use ibl_scene::{Scene, ShadowKind};
use ibl_sh::{IrradianceSh, RadianceSh, Window, basis, eval_basis};

use crate::environment::{EnvironmentError, EnvironmentLight};
use crate::sampling::{OrthonormalBasis, UniformCone};

/// One directional light, world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Unit direction towards the light.
    pub direction: Vec3,
    /// `I = L A`: irradiance on a surface facing the light, per channel.
    pub irradiance: Rgb,
    /// The cone of the light's solid angle (soft shadows), `None` for a point-like light: its
    /// core ([`ibl_light::Light::shadow_cones`]).
    pub cone: Option<UniformCone>,
    /// The halo around the core and its share of the light in `(0, 1]`, where the light has one
    /// (a sun held with sky around it: [`ibl_light::spread`], "A core and a halo"). Soft shadows
    /// and the hybrid's ambient take the light as the two cones, weighted by their shares.
    pub halo: Option<(UniformCone, f32)>,
    /// The basis about `direction` in which the cone is sampled.
    pub frame: OrthonormalBasis,
}

impl DirectionalLight {
    /// The mean clamped cosine of the light's cones (shares as weights) to a normal at
    /// `cos_beta` from its direction ([`UniformCone::mean_clamped_cosine`]); `cos_beta`
    /// clamped at 0 without a cone.
    pub fn mean_clamped_cosine(&self, cos_beta: f32) -> f32 {
        match (self.cone, self.halo) {
            (Some(core), Some((halo, share))) => {
                (1.0 - share) * core.mean_clamped_cosine(cos_beta)
                    + share * halo.mean_clamped_cosine(cos_beta)
            }
            (Some(core), None) => core.mean_clamped_cosine(cos_beta),
            (None, _) => cos_beta.max(0.0),
        }
    }
}

/// The directional part of the `lights` and `hybrid` modes.
#[derive(Clone, Debug)]
pub struct LightList {
    /// The lights.
    pub lights: Vec<DirectionalLight>,
    /// Hard or soft shadows.
    pub shadows: ShadowKind,
}

/// Largest SH band count of the hybrid ambient (`[lighting] ambient_bands`).
pub const MAX_AMBIENT_BANDS: usize = 16;

/// The ambient of the `hybrid` mode: an SH radiance, world frame, seen through occlusion rays.
#[derive(Clone, Debug)]
pub struct Ambient {
    /// The ambient radiance (probe units, world frame), cut to at most [`MAX_AMBIENT_BANDS`]
    /// bands.
    sh: RadianceSh,
    /// Its irradiance (the Lambert convolution of `sh`, no window): what the ambient gives a
    /// surface that nothing occludes.
    irradiance: IrradianceSh,
    /// Occlusion rays per shading point, at least 1.
    pub occlusion_rays: u32,
}

impl Ambient {
    /// The ambient of radiance `radiance` (world frame; its bands are cut to
    /// [`MAX_AMBIENT_BANDS`]) with `occlusion_rays` rays per shading point (at least 1).
    pub fn new(radiance: &RadianceSh, occlusion_rays: u32) -> Ambient {
        let sh = radiance.truncated(MAX_AMBIENT_BANDS);
        Ambient {
            irradiance: sh.irradiance(Window::None),
            sh,
            occlusion_rays: occlusion_rays.max(1),
        }
    }

    /// The ambient radiance as SH coefficients (world frame, probe units, `bands^2` terms).
    pub fn radiance_sh(&self) -> &RadianceSh {
        &self.sh
    }

    /// The ambient radiance arriving from the unit world direction `dir` (may be negative:
    /// the ambient is a difference). O(bands^2).
    pub fn radiance(&self, dir: Vec3) -> Rgb {
        evaluate(self.sh.bands(), self.sh.coefficients(), dir)
    }

    /// The ambient irradiance on an unoccluded surface of unit normal `n` (world frame; may be
    /// negative), `int max(0, n . w) L_a(w) dw` (Ramamoorthi and Hanrahan 2001). O(bands^2).
    pub fn irradiance(&self, n: Vec3) -> Rgb {
        evaluate(self.irradiance.bands(), self.irradiance.coefficients(), n)
    }
}

/// An SH expansion of `bands` bands with RGB coefficients `coefficients`, at the unit direction
/// `dir`, without allocating. O(bands^2).
fn evaluate(bands: usize, coefficients: &[[f64; 3]], dir: Vec3) -> Rgb {
    let mut y = [0.0f64; MAX_AMBIENT_BANDS * MAX_AMBIENT_BANDS];
    let n = bands * bands;
    eval_basis(dir.as_dvec3(), bands, &mut y[..n]);
    let mut sum = [0.0f64; 3];
    for (c, yk) in coefficients.iter().zip(&y[..n]) {
        for k in 0..3 {
            sum[k] += c[k] * yk;
        }
    }
    Rgb::new(sum[0] as f32, sum[1] as f32, sum[2] as f32)
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
    /// Goniometric point lights added to the scene (world frame, the probe's radiance unit per
    /// sr), lighting diffuse and glossy surfaces in every mode: the scene's own
    /// (`Scene::luminaires`) and any added.
    pub luminaires: Vec<GoniometricLight>,
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
            luminaires: scene.luminaires.clone(),
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
            luminaires: scene.luminaires.clone(),
        })
    }

    /// `hybrid` mode: the lights `set` and the `ambient` radiance (the probe minus the lights as
    /// point sources, as `ibl_extract::Hybrid` makes it) are in the probe's frame; with soft
    /// shadows the ambient gives back what the cones spread (see the module notes).
    pub fn hybrid(
        scene: &Scene,
        set: &LightSet,
        ambient: &RadianceSh,
        shadows: ShadowKind,
        occlusion_rays: u32,
    ) -> Result<Lighting, EnvironmentError> {
        let rotation = scene.probe.world_from_probe.as_dmat3();
        let ambient = match shadows {
            ShadowKind::Hard => ambient.clone(),
            ShadowKind::Soft => with_cones_spread(ambient, set),
        };
        Ok(Lighting {
            environment: Self::environment(scene)?,
            illumination: Illumination::Hybrid(
                light_list(scene, set, shadows),
                Ambient::new(&ambient.rotated(rotation), occlusion_rays),
            ),
            luminaires: scene.luminaires.clone(),
        })
    }

    /// The same lighting with the goniometric point lights `luminaires` added.
    pub fn with_luminaires(mut self, luminaires: Vec<GoniometricLight>) -> Lighting {
        self.luminaires.extend(luminaires);
        self
    }
}

/// `ambient + sum_i I_i (1 - g_l(c_i)) Y_lm(w_i)`: a point-subtracted ambient turned into the
/// ambient of the same lights as uniform cones (module notes; a light with a halo as its two
/// cones, `g_l` the share-weighted mean of theirs), probe frame.
fn with_cones_spread(ambient: &RadianceSh, lights: &LightSet) -> RadianceSh {
    let bands = ambient.bands();
    let mut coefficients = ambient.coefficients().to_vec();
    for light in &lights.lights {
        let cones = light.shadow_cones();
        let a = cones.core_sr;
        if !(a.is_finite() && a > 0.0) {
            continue;
        }
        let mut factors = cap_zonal_factors((a / TAU).min(2.0), bands);
        if let Some((halo_sr, share)) = cones.halo {
            // The light as its two cones: each cap's factors weighted by its share.
            let halo = cap_zonal_factors((halo_sr / TAU).min(2.0), bands);
            for (g, h) in factors.iter_mut().zip(halo) {
                *g = (1.0 - share) * *g + share * h;
            }
        }
        let y = basis(light.direction, bands);
        let power = [light.irradiance.r, light.irradiance.g, light.irradiance.b];
        for (l, g) in factors.iter().enumerate() {
            let spread = 1.0 - g;
            for k in l * l..(l + 1) * (l + 1) {
                for (v, power) in coefficients[k].iter_mut().zip(power) {
                    *v += power * spread * y[k];
                }
            }
        }
    }
    // The coefficient count is unchanged, so this cannot fail.
    RadianceSh::new(bands, coefficients).unwrap_or_else(|_| ambient.clone())
}

/// The mean of the Legendre polynomial `P_l` over a spherical cap whose half-angle has cosine
/// `c = 1 - one_minus_c` (`one_minus_c` in `(0, 2]`; the cap's solid angle is `2 pi one_minus_c`),
/// for `l < bands`: `g_0 = 1`, `g_l = (P_{l-1}(c) - P_{l+1}(c)) / ((2l + 1)(1 - c))`. Caps
/// narrower than `1 - c = 1e-9` count as points (`g_l = 1`; the first-order term is
/// `l (l + 1) (1 - c) / 4`, below 7e-8 for 16 bands). f64; the difference of Legendre values
/// loses about `1e-16 / (1 - c)` relative, below 1e-7 for every cap that is not a point.
pub fn cap_zonal_factors(one_minus_c: f64, bands: usize) -> Vec<f64> {
    if one_minus_c < 1e-9 {
        return vec![1.0; bands];
    }
    let c = 1.0 - one_minus_c;
    // P_0 .. P_bands at c (Bonnet's recursion).
    let mut p = vec![1.0, c];
    for l in 1..bands {
        let next = ((2 * l + 1) as f64 * c * p[l] - l as f64 * p[l - 1]) / (l + 1) as f64;
        p.push(next);
    }
    (0..bands)
        .map(|l| {
            if l == 0 {
                1.0
            } else {
                (p[l - 1] - p[l + 1]) / ((2 * l + 1) as f64 * one_minus_c)
            }
        })
        .collect()
}

fn light_list(scene: &Scene, set: &LightSet, shadows: ShadowKind) -> LightList {
    LightList::from_set(set, scene.probe.world_from_probe.as_dmat3(), shadows)
}

impl LightList {
    /// The renderer's lights of `set` (its frame turned to the world by `world_from_set`): black
    /// lights dropped, each with the cone of its shadow solid angle (soft shadows): its spread
    /// where the extraction measured it, else its solid angle `A_i`
    /// ([`ibl_light::Light::shadow_solid_angle_sr`]), and its halo where it has one
    /// ([`ibl_light::Light::shadow_cones`]).
    pub fn from_set(set: &LightSet, world_from_set: DMat3, shadows: ShadowKind) -> LightList {
        let lights: Vec<DirectionalLight> = set
            .lights
            .iter()
            .filter(|l| l.irradiance.any_positive())
            .map(|l| {
                let direction = (world_from_set * l.direction)
                    .normalize_or(DVec3::Y)
                    .as_vec3();
                let cones = l.shadow_cones();
                DirectionalLight {
                    direction,
                    irradiance: Rgb::new(
                        l.irradiance.r as f32,
                        l.irradiance.g as f32,
                        l.irradiance.b as f32,
                    ),
                    cone: UniformCone::from_solid_angle(cones.core_sr as f32),
                    halo: cones.halo.and_then(|(sr, share)| {
                        UniformCone::from_solid_angle(sr as f32).map(|c| (c, share as f32))
                    }),
                    frame: OrthonormalBasis::from_normal(direction),
                }
            })
            .collect();
        LightList { lights, shadows }
    }
}

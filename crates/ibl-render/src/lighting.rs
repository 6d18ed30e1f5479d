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
//! **The ambient's two band counts.** The occlusion rays read the ambient in the scene's
//! `ambient_bands` (`auto`: 3 to 7, below), but a surface nothing occludes gets its irradiance in
//! [`MAX_AMBIENT_BANDS`] (16): the probe less the lights is carried on to 16 bands
//! (`with_finer_bands`: the probe projected again, the lights taken off as points), and the
//! irradiance of the bands above the rays' is tabulated over normals ([`NormalTable`]). So on an
//! open surface lights plus ambient are the probe's irradiance but for the Lambert kernel's
//! bands above 15, where N lights alone have content in every band (a point light's
//! `max(0, n . w)`: bands 4, 6, 8 ... at `A_l / A_0` = 4 %, 1.6 %, 0.8 % ... of its power, which
//! the 5-band ambient left in: on bunny-apartment's floor 16 LightGen lights plus the ambient
//! were 0.7 to 1.1 % too dark). The rays keep the lower bands: a band-limited difference read
//! over the part of the sphere an occluder hides rings, and more bands there lose more than they
//! gain (bunny-apartment, LightGen's 16 lights plus ambient, converged, in multiples of the
//! reference's noise floor: 3.74x with 5 bands for both, 3.41x with 9 for both, 2.25x with 16
//! for the open surface and 5 for the rays; BENCHMARKS.md, "The hybrid's open surfaces in every
//! band").
//!
//! **The ambient at the horizon.** The probe less the lights jumps at the horizon: a ground's
//! pixels meet the sky's there, and lights held on one side of it (irradiance optimisation's,
//! folded onto their side) leave the other side's residual untouched. A band-limited expansion
//! of a jump rings on both sides of it, and a surface above a ground plane reads that ringing
//! through every ray the ground blocks. So the rays read each half of the horizon from its own
//! expansion ([`horizon_halves`]): the half mirrored across the horizon onto the other (`r(w)`
//! on its side, `r(w')` on the other, `w'` the mirror image), continuous where the whole jumps,
//! so its bands converge without the jump's ringing. The estimate starts from the upper half's
//! irradiance alone, `E_up(n)` (the probe's upper rows less the lights' points above the
//! horizon, 16 bands, tabulated as above), takes off what blocked rays above the horizon read
//! and adds what open rays below it read: a surface over a ground that hides exactly the lower
//! half (the usual case: the probe was taken above a floor) then gets no noise and no ringing
//! from below, and the open sky none from above. The same expectation as before, with every
//! band read where it converges; with the jump gone, bands up to 6 pay for the rays
//! (`ambient_bands` 5 -> 7; converged, on the render study's two scenes, every method's hybrid
//! as good as before or better, BENCHMARKS.md "The ambient at the horizon").
//!
//! **How many bands the rays read.** More bands carry more of what the lights miss where an
//! occluder hides part of the sky, but make each ray read a rougher function, so a pixel's
//! few rays scatter more: a bias traded for noise, whose best count depends on the rays a pixel
//! traces. Measured on the render study's two scenes, it grows by about one band each time they
//! double (3 bands at 4 samples of 4 rays, 5 at 16 samples, 7 at 64, nothing more beyond 7 at
//! 256), so `ambient_bands = "auto"` (the default, `ibl_scene::AmbientBands::resolve`) gives
//! `log2(spp rays) - 1` within 3..=7. The rays of one vertex are drawn stratified together
//! (`SampleStream::pairs`: one scrambled Sobol net across the pixel's samples and rays, not one
//! net per ray), which lowers their noise at equal rays (docs/RENDERING.md, "How many bands
//! the rays read").
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
use ibl_core::{Image, LatLong, Rgb};
use ibl_light::{GoniometricLight, HorizonSide, LightSet};
use ibl_scene::{Scene, ShadowKind};
use ibl_sh::{
    IrradianceSh, RadianceSh, Window, basis, eval_basis, project_latlong, subtract_point_sources,
};

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
    /// Where the light stands for one side of the probe's horizon only
    /// ([`ibl_light::Light::side`]) and its widest cone crosses the horizon: the unit normal
    /// of the horizon plane pointing into its side, world frame. Soft shadows then mirror a cone
    /// point on the other side into this one ([`DirectionalLight::folded`]). `None`: the cones
    /// are taken whole.
    pub fold: Option<Vec3>,
}

impl DirectionalLight {
    /// The cone point `point` (unit, world frame) as the light's soft shadows take it: mirrored
    /// in the horizon plane onto the light's side where it has a [`DirectionalLight::fold`] and
    /// the point lies on the other side; `None` where it is not moved.
    pub fn folded(&self, point: Vec3) -> Option<Vec3> {
        let up = self.fold?;
        let height = point.dot(up);
        (height < 0.0).then(|| point - 2.0 * height * up)
    }

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
pub const MAX_AMBIENT_BANDS: usize = ibl_scene::description::MAX_AMBIENT_BANDS as usize;

/// The ambient of the `hybrid` mode: an SH radiance, world frame, seen through occlusion rays.
#[derive(Clone, Debug)]
pub struct Ambient {
    /// The ambient radiance the occlusion rays read (probe units, world frame), cut to at most
    /// [`MAX_AMBIENT_BANDS`] bands.
    sh: RadianceSh,
    /// Its irradiance (the Lambert convolution of `sh`, no window): with `finer`, what the
    /// ambient gives a surface that nothing occludes.
    irradiance: IrradianceSh,
    /// The irradiance of the ambient's bands above `sh`'s, where it has more
    /// ([`Ambient::with_ray_bands`]), tabulated over normals.
    finer: Option<NormalTable>,
    /// Occlusion rays per shading point, at least 1.
    pub occlusion_rays: u32,
    /// What the rays read on either side of the probe's horizon, where the ambient has
    /// halves ([`Ambient::with_horizon_halves`]).
    halves: Option<HorizonHalves>,
}

/// The hybrid ambient split at the probe's horizon (module notes, "The ambient at the
/// horizon"), world frame.
#[derive(Clone, Debug)]
struct HorizonHalves {
    /// The unit normal of the horizon plane pointing up, world frame.
    up: Vec3,
    /// What rays above the horizon read: the upper half's mirror extension (`r(w)` above the
    /// horizon, `r(w')` below it, `w'` the mirror image of `w`), in the rays' bands.
    above: RadianceSh,
    /// What rays below the horizon read: the lower half's mirror extension.
    below: RadianceSh,
    /// The upper half alone (zero below the horizon): its irradiance is where the estimate
    /// starts.
    upper: Box<Ambient>,
}

/// How an occlusion ray enters the hybrid ambient's estimate ([`Ambient::ray_role`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayRole {
    /// The ray's radiance is taken off where the ray is blocked: the estimate starts from this
    /// direction's light.
    TakenOffWhereBlocked,
    /// The ray's radiance is added where the ray is open: the estimate starts without it.
    AddedWhereOpen,
}

/// The probe less the lights as [`horizon_halves`] splits it at the horizon, probe frame.
#[derive(Clone, Debug)]
pub struct HorizonResidual {
    /// The upper half's mirror extension.
    pub above: RadianceSh,
    /// The lower half's mirror extension.
    pub below: RadianceSh,
    /// The upper half, zero below the horizon.
    pub upper: RadianceSh,
}

impl Ambient {
    /// The ambient of radiance `radiance` (world frame; its bands are cut to
    /// [`MAX_AMBIENT_BANDS`]) with `occlusion_rays` rays per shading point (at least 1).
    pub fn new(radiance: &RadianceSh, occlusion_rays: u32) -> Ambient {
        Ambient::with_ray_bands(radiance, MAX_AMBIENT_BANDS, occlusion_rays)
    }

    /// The ambient of radiance `radiance` (world frame, cut to [`MAX_AMBIENT_BANDS`]) whose
    /// occlusion rays read only its first `ray_bands` bands (at least 1), while a surface
    /// that nothing occludes gets the irradiance of all of them (the bands above `ray_bands`
    /// tabulated over normals, [`NormalTable`]). See the module notes, "The ambient's two
    /// band counts".
    pub fn with_ray_bands(radiance: &RadianceSh, ray_bands: usize, occlusion_rays: u32) -> Ambient {
        let full = radiance.truncated(MAX_AMBIENT_BANDS);
        let sh = full.truncated(ray_bands);
        let finer = (full.bands() > sh.bands())
            .then(|| {
                let mut high = full.coefficients().to_vec();
                high[..sh.coefficients().len()].fill([0.0; 3]);
                // Same count, finite values: cannot fail.
                RadianceSh::new(full.bands(), high).ok()
            })
            .flatten()
            .map(|high| NormalTable::new(&high.irradiance(Window::None)));
        Ambient {
            irradiance: sh.irradiance(Window::None),
            sh,
            finer,
            occlusion_rays: occlusion_rays.max(1),
            halves: None,
        }
    }

    /// The same ambient split at the horizon plane of unit normal `up` (world frame; module
    /// notes, "The ambient at the horizon"): `halves` ([`horizon_halves`], turned to the world
    /// frame) say what the rays read on either side and where the estimate starts. The
    /// irradiance of an open surface ([`Ambient::irradiance`]) is unchanged.
    pub fn with_horizon_halves(mut self, up: Vec3, halves: &HorizonResidual) -> Ambient {
        let bands = self.sh.bands();
        self.halves = Some(HorizonHalves {
            up,
            above: halves.above.truncated(bands),
            below: halves.below.truncated(bands),
            upper: Box::new(Ambient::with_ray_bands(&halves.upper, bands, 1)),
        });
        self
    }

    /// How an occlusion ray in the unit world direction `dir` enters the estimate: without
    /// halves every ray is [`RayRole::TakenOffWhereBlocked`]; with them, those below the
    /// horizon are [`RayRole::AddedWhereOpen`].
    pub fn ray_role(&self, dir: Vec3) -> RayRole {
        match &self.halves {
            Some(h) if dir.dot(h.up) < 0.0 => RayRole::AddedWhereOpen,
            _ => RayRole::TakenOffWhereBlocked,
        }
    }

    /// The irradiance (world frame, unit normal `n`) the estimate starts from: the ambient's
    /// whole irradiance ([`Ambient::irradiance`]) without halves, its upper half's with them.
    pub fn starting_irradiance(&self, n: Vec3) -> Rgb {
        match &self.halves {
            Some(h) => h.upper.irradiance(n),
            None => self.irradiance(n),
        }
    }

    /// The ambient radiance as SH coefficients (world frame, probe units, `bands^2` terms).
    pub fn radiance_sh(&self) -> &RadianceSh {
        &self.sh
    }

    /// The ambient radiance the occlusion rays read from the unit world direction `dir` (may
    /// be negative: the ambient is a difference): with halves, the mirror extension of the
    /// half `dir` lies in ([`Ambient::with_horizon_halves`]). O(bands^2).
    pub fn radiance(&self, dir: Vec3) -> Rgb {
        let sh = match &self.halves {
            Some(h) if dir.dot(h.up) < 0.0 => &h.below,
            Some(h) => &h.above,
            None => &self.sh,
        };
        evaluate(sh.bands(), sh.coefficients(), dir)
    }

    /// The ambient irradiance on an unoccluded surface of unit normal `n` (world frame; may be
    /// negative), `int max(0, n . w) L_a(w) dw` (Ramamoorthi and Hanrahan 2001): the rays'
    /// bands exactly, O(bands^2), plus the finer bands' table where there is one.
    pub fn irradiance(&self, n: Vec3) -> Rgb {
        let low = evaluate(self.irradiance.bands(), self.irradiance.coefficients(), n);
        match &self.finer {
            Some(table) => low + table.at(n),
            None => low,
        }
    }
}

/// An RGB function of the unit normal tabulated on a lat-long grid of normals
/// ([`NormalTable::WIDTH`] x [`NormalTable::HEIGHT`], texel centres, CONVENTIONS section 2) and
/// read bilinearly: the hybrid ambient's irradiance in its bands above the rays', which
/// evaluated per shading point would cost O(16^2) terms (a hybrid render of bunny-apartment at
/// 320 px took 27 % longer so; the table takes about 26 ms to fill on 2 cores). Those bands
/// carry a small part of the irradiance (the Lambert kernel passes even band `l` at about
/// `l^-2.5`, odd bands above 1 not at all), and the grid resolves the finest of them, band 14 (a
/// 25.7-degree period), with 18 texels a period: a test measures the bilinear error at 0.5 % of
/// that part's largest value.
#[derive(Clone, Debug)]
pub struct NormalTable {
    texels: Vec<Rgb>,
}

impl NormalTable {
    /// Columns of the grid.
    pub const WIDTH: usize = 256;
    /// Rows of the grid.
    pub const HEIGHT: usize = 128;

    /// The table of `irradiance` at every texel's centre direction.
    pub fn new(irradiance: &IrradianceSh) -> NormalTable {
        let grid = LatLong::new(Self::WIDTH, Self::HEIGHT);
        let dirs: Vec<DVec3> = (0..Self::HEIGHT)
            .flat_map(|j| (0..Self::WIDTH).map(move |i| grid.pixel_dir64(i, j)))
            .collect();
        let texels = irradiance
            .eval_many(&dirs)
            .into_iter()
            .map(|[r, g, b]| Rgb::new(r as f32, g as f32, b as f32))
            .collect();
        NormalTable { texels }
    }

    /// The tabulated value at the unit normal `n`, bilinear between the four nearest texel
    /// centres (columns wrap, rows clamp at the poles).
    pub fn at(&self, n: Vec3) -> Rgb {
        let (u, v) = LatLong::dir_to_uv(n.as_dvec3());
        let (w, h) = (Self::WIDTH, Self::HEIGHT);
        let x = u * w as f64 - 0.5;
        let y = (v * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
        let (x0, y0) = (x.floor(), y.floor());
        let (tx, ty) = ((x - x0) as f32, (y - y0) as f32);
        let i0 = (x0 as i64).rem_euclid(w as i64) as usize;
        let i1 = (i0 + 1) % w;
        let j0 = (y0 as usize).min(h - 1);
        let j1 = (j0 + 1).min(h - 1);
        let t = |i: usize, j: usize| self.texels[j * w + i];
        let top = t(i0, j0) * (1.0 - tx) + t(i1, j0) * tx;
        let bottom = t(i0, j1) * (1.0 - tx) + t(i1, j1) * tx;
        top * (1.0 - ty) + bottom * ty
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
    /// The environment of `scene`'s probe; with its normal bins only for the reference, whose
    /// surfaces draw environment samples ([`EnvironmentLight::without_normal_bins`]).
    fn environment(scene: &Scene, sampled: bool) -> Result<EnvironmentLight, EnvironmentError> {
        EnvironmentLight::build(
            scene.probe.radiance.clone(),
            scene.probe.world_from_probe,
            1.0,
            sampled,
        )
    }

    /// Reference lighting: the full probe.
    pub fn reference(scene: &Scene) -> Result<Lighting, EnvironmentError> {
        Ok(Lighting {
            environment: Self::environment(scene, true)?,
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
            environment: Self::environment(scene, false)?,
            illumination: Illumination::Lights(light_list(scene, set, shadows)),
            luminaires: scene.luminaires.clone(),
        })
    }

    /// `hybrid` mode: the lights `set` and the `ambient` radiance (the probe minus the lights as
    /// point sources, as `ibl_extract::Hybrid` makes it) are in the probe's frame; with soft
    /// shadows the ambient gives back what the cones spread (see the module notes). The
    /// occlusion rays read `ambient`'s bands; an open surface gets the ambient carried on to
    /// [`MAX_AMBIENT_BANDS`] (module notes, "The ambient's two band counts"): a projection of
    /// the scene's probe, O(W H) for a W x H probe, about 15 ms at 512 x 256.
    pub fn hybrid(
        scene: &Scene,
        set: &LightSet,
        ambient: &RadianceSh,
        shadows: ShadowKind,
        occlusion_rays: u32,
    ) -> Result<Lighting, EnvironmentError> {
        let rotation = scene.probe.world_from_probe.as_dmat3();
        let ray_bands = ambient.bands();
        let full = with_finer_bands(&scene.probe.radiance, set, ambient);
        let full = match shadows {
            ShadowKind::Hard => full,
            ShadowKind::Soft => with_cones_spread(&full, set),
        };
        let mut ambient =
            Ambient::with_ray_bands(&full.rotated(rotation), ray_bands, occlusion_rays);
        if let Some(halves) = horizon_halves(&scene.probe.radiance, set, shadows, ray_bands) {
            let up = (rotation * DVec3::Y).normalize_or(DVec3::Y).as_vec3();
            ambient = ambient.with_horizon_halves(up, &halves.rotated(rotation));
        }
        Ok(Lighting {
            environment: Self::environment(scene, false)?,
            illumination: Illumination::Hybrid(light_list(scene, set, shadows), ambient),
            luminaires: scene.luminaires.clone(),
        })
    }

    /// The same lighting with the goniometric point lights `luminaires` added.
    pub fn with_luminaires(mut self, luminaires: Vec<GoniometricLight>) -> Lighting {
        self.luminaires.extend(luminaires);
        self
    }
}

/// The ambient `ambient` (probe frame: the probe less the lights `lights` as points, in its
/// bands) carried on to [`MAX_AMBIENT_BANDS`] bands: the probe's projection less the same
/// points in the bands above `ambient`'s, `ambient`'s own coefficients below. `ambient` itself
/// where it has them all, or where the probe cannot be projected. O(W H 16^2) for a W x H
/// probe.
fn with_finer_bands(probe: &Image<Rgb>, lights: &LightSet, ambient: &RadianceSh) -> RadianceSh {
    let bands = MAX_AMBIENT_BANDS;
    if ambient.bands() >= bands {
        return ambient.clone();
    }
    let Ok(projected) = project_latlong(probe, bands) else {
        return ambient.clone();
    };
    let mut coefficients = projected.coefficients().to_vec();
    subtract_point_sources(
        &mut coefficients,
        bands,
        lights
            .lights
            .iter()
            .map(|l| (l.direction, l.irradiance.to_array())),
    );
    coefficients[..ambient.coefficients().len()].copy_from_slice(ambient.coefficients());
    RadianceSh::new(bands, coefficients).unwrap_or_else(|_| ambient.clone())
}

/// The probe less the lights (probe frame) split at the probe's horizon (module notes, "The
/// ambient at the horizon"): each half's mirror extension in `ray_bands` bands and the upper half
/// alone in [`MAX_AMBIENT_BANDS`]. A half of the probe is projected with the other half's rows
/// zero or mirrored about the equator (exact on the lat-long grid; the middle row of an odd
/// height counts as above, as `ibl_extract::hemispheres` takes it); each light is taken off as
/// points, its direction with hard shadows and its soft-shadow cone points with soft ones
/// ([`ibl_light::Light::soft_points`], folded onto its side where it has one), each point in
/// the half of its light's side or else the half it lies in (the horizon counting as above),
/// with its mirror image in a mirror extension. `None` where the probe cannot be projected.
pub fn horizon_halves(
    probe: &Image<Rgb>,
    lights: &LightSet,
    shadows: ShadowKind,
    ray_bands: usize,
) -> Option<HorizonResidual> {
    let (w, h) = (probe.width(), probe.height());
    let upper_rows = HorizonSide::upper_rows(h);
    let points: Vec<(HorizonSide, DVec3, [f64; 3])> = lights
        .lights
        .iter()
        .flat_map(|light| {
            let power = light.irradiance.to_array();
            let points = match shadows {
                ShadowKind::Hard => vec![(light.direction, 1.0)],
                ShadowKind::Soft => light.soft_points(SH_POINTS_PER_CONE),
            };
            points.into_iter().map(move |(p, weight)| {
                let side = light.side.unwrap_or(HorizonSide::of_direction(p));
                (side, p, power.map(|v| v * weight))
            })
        })
        .collect();
    let part = |side: HorizonSide, mirrored: bool, bands: usize| -> Option<RadianceSh> {
        let image = Image::from_fn_par(w, h, |i, j| {
            if (j < upper_rows) == (side == HorizonSide::Above) {
                *probe.get(i, j)
            } else if mirrored {
                *probe.get(i, h - 1 - j)
            } else {
                Rgb::ZERO
            }
        });
        let mut coefficients = project_latlong(&image, bands).ok()?.coefficients().to_vec();
        let mine = points.iter().filter(|(s, _, _)| *s == side);
        let taken = mine.flat_map(|&(_, p, value)| {
            std::iter::once((p, value)).chain(mirrored.then_some((HorizonSide::mirror(p), value)))
        });
        subtract_point_sources(&mut coefficients, bands, taken);
        RadianceSh::new(bands, coefficients).ok()
    };
    Some(HorizonResidual {
        above: part(HorizonSide::Above, true, ray_bands)?,
        below: part(HorizonSide::Below, true, ray_bands)?,
        upper: part(HorizonSide::Above, false, MAX_AMBIENT_BANDS)?,
    })
}

impl HorizonResidual {
    /// The three parts turned by `rotation`.
    pub fn rotated(&self, rotation: DMat3) -> HorizonResidual {
        HorizonResidual {
            above: self.above.rotated(rotation),
            below: self.below.rotated(rotation),
            upper: self.upper.rotated(rotation),
        }
    }
}

/// Quadrature points per cone for the SH of a light's soft-shadow cones taken as points (a
/// light folded onto its side of the horizon, and the halves of [`horizon_halves`];
/// [`ibl_light::Light::soft_points`]): spiral points about 3 degrees apart in a 30-degree cone,
/// where band 15 (the most either reads) varies over about 24 degrees.
const SH_POINTS_PER_CONE: usize = 256;

/// `ambient + sum_i I_i (1 - g_l(c_i)) Y_lm(w_i)`: a point-subtracted ambient turned into the
/// ambient of the same lights as uniform cones (module notes; a light with a halo as its two
/// cones, `g_l` the share-weighted mean of theirs; a light with a side of the horizon as its
/// cones folded onto it, by quadrature), probe frame.
fn with_cones_spread(ambient: &RadianceSh, lights: &LightSet) -> RadianceSh {
    let bands = ambient.bands();
    let mut coefficients = ambient.coefficients().to_vec();
    for light in &lights.lights {
        if light.side.is_some() {
            // A light folded onto its side of the horizon is not a uniform cone: its spread
            // `Y(w) - sum_p w_p Y(p)` by quadrature over its folded cones.
            let power = [light.irradiance.r, light.irradiance.g, light.irradiance.b];
            let mut spread = basis(light.direction, bands);
            for (p, w) in light.soft_points(SH_POINTS_PER_CONE) {
                for (s, y) in spread.iter_mut().zip(basis(p, bands)) {
                    *s -= w * y;
                }
            }
            for (k, s) in spread.iter().enumerate() {
                for (v, power) in coefficients[k].iter_mut().zip(power) {
                    *v += power * s;
                }
            }
            continue;
        }
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

/// Whether the uniform cone of solid angle `solid_angle_sr` about unit `axis` reaches below the
/// plane of unit normal `up` (its half-angle exceeds the axis's elevation above the plane).
fn crosses_plane(axis: DVec3, up: DVec3, solid_angle_sr: f64) -> bool {
    if !(solid_angle_sr.is_finite() && solid_angle_sr > 0.0) {
        return false;
    }
    let cos_half = (1.0 - solid_angle_sr / TAU).max(-1.0);
    let half = cos_half.acos();
    let elevation = axis.dot(up).clamp(-1.0, 1.0).asin();
    half > elevation
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
                    fold: l.side.and_then(|side| {
                        let up = (world_from_set * side.up()).normalize_or(DVec3::Y);
                        let widest = cones.halo.map_or(cones.core_sr, |(sr, _)| sr);
                        crosses_plane(direction.as_dvec3(), up, widest).then(|| up.as_vec3())
                    }),
                }
            })
            .collect();
        LightList { lights, shadows }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // tests may panic

    use super::*;

    /// The irradiance of a radiance with coefficients of one size in every band from 5 to 15
    /// (pseudo-random signs and sizes), the rest zero: the part of a hybrid's ambient the
    /// table holds, with far more in its finest bands than a probe has.
    fn high_bands_irradiance() -> IrradianceSh {
        let bands = MAX_AMBIENT_BANDS;
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let coefficients = (0..bands * bands)
            .map(|k| {
                if k < 25 {
                    return [0.0; 3];
                }
                [0.0; 3].map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
                })
            })
            .collect();
        RadianceSh::new(bands, coefficients)
            .unwrap()
            .irradiance(Window::None)
    }

    #[test]
    fn the_normal_table_reads_the_irradiance_within_its_bilinear_bound() {
        // Bands 5 to 15 on a 256 x 128 grid: the finest even band (14, a 25.7-degree period)
        // has 18 texels a period, where linear interpolation errs by at most `(pi / 18)^2 / 2`
        // = 1.5 % of that band's amplitude; the coarser bands, which the Lambert kernel passes
        // far more of, much less. Measured: 0.51 % of the largest value over 5000 normals (2.0 %
        // on a 128 x 64 grid). Tolerance 1 %; the part the table holds is itself a few per cent
        // of an ambient's irradiance.
        let sh = high_bands_irradiance();
        let table = NormalTable::new(&sh);
        let normals = ibl_core::fibonacci_normals(5000);
        let exact: Vec<[f64; 3]> = sh.eval_many(&normals);
        let largest = exact
            .iter()
            .flat_map(|e| e.iter().map(|v| v.abs()))
            .fold(0.0, f64::max);
        let worst = normals
            .iter()
            .zip(&exact)
            .map(|(n, e)| {
                let t = table.at(n.as_vec3());
                (f64::from(t.r) - e[0])
                    .abs()
                    .max((f64::from(t.g) - e[1]).abs())
                    .max((f64::from(t.b) - e[2]).abs())
            })
            .fold(0.0, f64::max);
        assert!(
            worst < 0.01 * largest,
            "worst {worst:.3e}, largest {largest:.3e}"
        );
    }

    #[test]
    fn an_ambient_with_fewer_ray_bands_keeps_its_irradiance_and_cuts_its_rays() {
        // The rays read the first `ray_bands` bands exactly; an open surface gets every band,
        // within the table's bound (above) on the bands above the rays'.
        let mut coefficients = high_bands_irradiance().coefficients().to_vec();
        coefficients[0] = [2.0, 1.5, 1.0];
        coefficients[2] = [0.5, 0.4, 0.3];
        let radiance = RadianceSh::new(MAX_AMBIENT_BANDS, coefficients).unwrap();
        let split = Ambient::with_ray_bands(&radiance, 5, 4);
        let whole = Ambient::new(&radiance, 4);
        let five = Ambient::new(&radiance.truncated(5), 4);
        for n in ibl_core::fibonacci_normals(300) {
            let n = n.as_vec3();
            assert_eq!(split.radiance(n), five.radiance(n));
            let (a, b) = (split.irradiance(n), whole.irradiance(n));
            assert!(
                (a.r - b.r).abs() < 0.02 && (a.g - b.g).abs() < 0.02,
                "{a:?} {b:?}"
            );
        }
        assert_eq!(split.radiance_sh().bands(), 5);
    }
}

//! New light sources in the room (Grosch 2005, section 4.2): goniometric point lights (IES or
//! EULUMDAT files, `ibl_light::GoniometricLight`) placed and turned by the user, lighting the
//! real surfaces of the reconstructed room.
//!
//! 1. **Direct light** (EQ5): a surface point `x` with normal `n` receives `E(x) = I(theta, phi)
//!    cos theta_e / d^2` from each light it sees, the shadow a ray from `x` to the light's
//!    position (the paper's shadow-volume mask). A diffuse surface of reflectance `rho` reflects
//!    `rho E / pi` more radiance: what the paper's fragment program adds to the texture. Here it
//!    is evaluated per point, at whatever resolution the picture asks for
//!    ([`LightAddition::radiance_at`]), so the pools and shadows are sharp.
//! 2. **Their indirect light** (beyond the paper, which shows direct light only): the light's
//!    radiosity `dB_0 = rho E_p` (each patch's mean direct irradiance `E_p` over `s x s`
//!    stratified points) is shot through the room's form factors like a material change's delta
//!    radiosity ([`crate::material_change`]): `dB_(j+1) = rho F dB_j`, `k` bounces (one by
//!    default), `B' = B + rho E + dB_1 + ... + dB_k`. The indirect part is constant per patch
//!    (the form factors' resolution); `k` bounces leave at most `max(rho)^(k+1) / (1 - max(rho))`
//!    of the light's radiosity unsent.
//!
//! **Reflectances** are the caller's per patch: the estimate's (`B / E` where the probe saw, the
//! group's where it did not), or a material edit's ([`crate::MaterialEdit::reflectance`]) when
//! both manipulations apply. Light patches (windows, lamps) have `rho = 0` there, so they neither
//! reflect the new light nor pass it on.
//!
//! **Units.** A light's intensity is in the probe's radiance unit per sr
//! (`GoniometricLight::intensity_per_candela`, CONVENTIONS section 6), so `E` is in the probe's
//! unit of irradiance and `rho E` of radiosity; positions in metres, world frame.
//!
//! Cost: `patches x s^2 x lights` shadow rays for the patch means, `k` passes over the form
//! factors, one shadow ray per light per displayed point.

use glam::Vec3;
use ibl_core::{Image, LatLong, Rgb};
use ibl_light::GoniometricLight;
use rayon::prelude::*;

use crate::depth_map::ProbeDepthMap;
use crate::form_factors::FormFactors;
use crate::material_change::MAX_BOUNCES;
use crate::{Room, RoomError};

/// Shadow rays start this far from the surface and stop this far before the light, metres (as
/// the form factors' offset: well above f32 rounding at room scale, far below any feature).
const SHADOW_OFFSET_M: f32 = 1e-4;

/// Most stratified points per patch side accepted.
pub const MAX_SAMPLES_PER_AXIS: u32 = 16;

/// How the added lights are evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightAdditionSettings {
    /// Stratified points per patch side for each patch's mean direct irradiance (`s x s` points,
    /// each with its own shadow rays): what the bounces shoot.
    pub samples_per_axis: u32,
    /// Bounces of the lights' indirect light through the form factors (0: direct light only).
    pub bounces: u32,
}

impl Default for LightAdditionSettings {
    /// 4 x 4 points per patch, one bounce (Grosch's default for delta radiosity, section 4.3).
    fn default() -> Self {
        LightAdditionSettings {
            samples_per_axis: 4,
            bounces: 1,
        }
    }
}

/// The room with new lights added.
#[derive(Clone, Debug)]
pub struct LightAddition {
    /// The lights, world frame.
    pub lights: Vec<GoniometricLight>,
    /// Per patch, the reflectance that reflects their light.
    pub reflectance: Vec<Rgb>,
    /// Per patch, the mean direct irradiance from the lights, shadowed (probe units).
    pub direct_irradiance: Vec<Rgb>,
    /// Per patch, the radiosity their light adds after its first reflection: `dB_1 + ... + dB_k`.
    pub indirect_radiosity: Vec<Rgb>,
    /// Bounces made.
    pub bounces: u32,
    /// The last bounce's largest change of any patch's radiosity in any channel, relative to the
    /// largest radiosity the lights add: what another bounce would still add, roughly.
    pub last_bounce_relative: f32,
}

/// Adds `lights` to `room`, whose patches reflect with `reflectance` (one per patch, clamped to
/// [0, 1]) and exchange light through `form_factors`. Errors: sizes that do not match, a light
/// whose position or intensity is not finite, settings out of range.
pub fn add_lights(
    room: &Room,
    reflectance: &[Rgb],
    form_factors: &FormFactors,
    lights: Vec<GoniometricLight>,
    settings: &LightAdditionSettings,
) -> Result<LightAddition, RoomError> {
    let n = room.patches.len();
    if reflectance.len() != n || form_factors.len() != n {
        return Err(RoomError::Parameter(format!(
            "{} reflectances and {} form-factor rows for a room of {n} patches",
            reflectance.len(),
            form_factors.len()
        )));
    }
    if settings.bounces > MAX_BOUNCES {
        return Err(RoomError::Parameter(format!(
            "{} bounces of the new lights' light (at most {MAX_BOUNCES})",
            settings.bounces
        )));
    }
    let s = settings.samples_per_axis;
    if s == 0 || s > MAX_SAMPLES_PER_AXIS {
        return Err(RoomError::Parameter(format!(
            "{s} points per patch side (1 to {MAX_SAMPLES_PER_AXIS})"
        )));
    }
    for (k, light) in lights.iter().enumerate() {
        if !light.position.is_finite() || !light.intensity_per_candela.is_valid_radiance() {
            return Err(RoomError::invalid(
                format!("lights[{k}]"),
                format!(
                    "position {:?} and intensity per candela {:?} must be finite (and the \
                     intensity not negative)",
                    light.position, light.intensity_per_candela
                ),
            ));
        }
    }
    let reflectance: Vec<Rgb> = reflectance
        .iter()
        .map(|r| {
            r.map(|v| {
                if v.is_finite() {
                    v.clamp(0.0, 1.0)
                } else {
                    0.0
                }
            })
        })
        .collect();
    let mut addition = LightAddition {
        lights,
        direct_irradiance: Vec::new(),
        indirect_radiosity: vec![Rgb::ZERO; n],
        reflectance,
        bounces: settings.bounces,
        last_bounce_relative: 0.0,
    };
    let inv = 1.0 / s as f32;
    addition.direct_irradiance = (0..n)
        .into_par_iter()
        .map(|p| {
            let patch = &room.patches[p];
            if addition.reflectance[p].max_channel() <= 0.0 {
                return Rgb::ZERO;
            }
            let mut sum = Rgb::ZERO;
            for i in 0..s {
                for j in 0..s {
                    let point = patch
                        .shape
                        .point((i as f32 + 0.5) * inv, (j as f32 + 0.5) * inv);
                    sum += addition.irradiance_at(room, point, patch.normal);
                }
            }
            sum * (inv * inv)
        })
        .collect();
    // dB_0 = rho E, then dB_(j+1) = rho F dB_j (the shot as a gather, as material changes).
    let mut delta: Vec<Rgb> = addition
        .direct_irradiance
        .iter()
        .zip(&addition.reflectance)
        .map(|(&e, &rho)| rho * e)
        .collect();
    let scale = delta.iter().map(|d| d.max_channel()).fold(0.0f32, f32::max);
    let mut last = scale;
    for _ in 0..settings.bounces {
        delta = form_factors
            .gather(&delta)
            .into_par_iter()
            .zip(addition.reflectance.par_iter())
            .map(|(e, &rho)| rho * e)
            .collect();
        last = 0.0;
        for (b, d) in addition.indirect_radiosity.iter_mut().zip(&delta) {
            *b += *d;
            last = last.max(d.max_channel());
        }
    }
    let total = addition
        .added_radiosity()
        .iter()
        .map(|b| b.max_channel())
        .fold(0.0f32, f32::max);
    addition.last_bounce_relative = if total > 0.0 && settings.bounces > 0 {
        last / total
    } else {
        0.0
    };
    Ok(addition)
}

impl LightAddition {
    /// EQ5 summed over the lights that world `point` (on a surface with unit `normal`, lit on its
    /// front) sees: `sum I cos theta_e / d^2`, each with a shadow ray through the room.
    pub fn irradiance_at(&self, room: &Room, point: Vec3, normal: Vec3) -> Rgb {
        let origin = point + normal * SHADOW_OFFSET_M;
        let mut sum = Rgb::ZERO;
        for light in &self.lights {
            let e = light.irradiance_at(point, normal);
            if e.max_channel() <= 0.0 {
                continue;
            }
            let to_light = light.position - origin;
            let distance = to_light.length();
            if distance <= SHADOW_OFFSET_M {
                continue;
            }
            let direction = to_light / distance;
            if !room.occluded(origin, direction, 0.0, distance - SHADOW_OFFSET_M) {
                sum += e;
            }
        }
        sum
    }

    /// The radiance the lights add at world `point` of patch `patch`: `rho E(x) / pi` of the
    /// direct light at the point plus the patch's indirect radiance `dB / pi`.
    pub fn radiance_at(&self, room: &Room, patch: usize, point: Vec3) -> Rgb {
        let (Some(p), Some(&rho)) = (room.patches.get(patch), self.reflectance.get(patch)) else {
            return Rgb::ZERO;
        };
        let direct = if rho.max_channel() > 0.0 {
            rho * self.irradiance_at(room, point, p.normal)
        } else {
            Rgb::ZERO
        };
        (direct + self.indirect_radiosity[patch]) / std::f32::consts::PI
    }

    /// Per patch, the radiosity the lights add: `rho E_p + dB_1 + ... + dB_k`.
    pub fn added_radiosity(&self) -> Vec<Rgb> {
        self.direct_irradiance
            .iter()
            .zip(&self.reflectance)
            .zip(&self.indirect_radiosity)
            .map(|((&e, &rho), &b)| rho * e + b)
            .collect()
    }

    /// `base` (a lat-long panorama from the probe position, the size of `depth`) with the lights'
    /// radiance added at the point each pixel shows ([`Self::radiance_at`]); pixels showing no
    /// patch (the model's gaps) are left as they are.
    pub fn panorama(
        &self,
        room: &Room,
        depth: &ProbeDepthMap,
        base: &Image<Rgb>,
    ) -> Result<Image<Rgb>, RoomError> {
        if base.width() != depth.width() || base.height() != depth.height() {
            return Err(RoomError::Parameter(format!(
                "the picture is {} x {} but the depth map {} x {}",
                base.width(),
                base.height(),
                depth.width(),
                depth.height()
            )));
        }
        let latlong = LatLong::new(base.width(), base.height());
        Ok(Image::from_fn_par(base.width(), base.height(), |i, j| {
            let observed = *base.get(i, j);
            let sample = depth.sample(i, j);
            let patch = sample.patch as usize;
            if patch >= room.patches.len() || !sample.distance_m.is_finite() {
                return observed;
            }
            let direction = room.world_from_probe * latlong.pixel_dir(i, j);
            let point = room.probe_position + direction * sample.distance_m;
            observed + self.radiance_at(room, patch, point)
        }))
    }
}

//! A synthetic day in the courtyard, rendered by the project's own path tracer (`ibl-render`,
//! reference mode): the probe at the start and a fixed camera's frames over several hours with
//! the SPA sun, clouds that dim the sun and an overcast stretch, each with its true `P_d`, `P_a`.
//!
//! **Light.** The world is lit by a distant environment map (`environment_width x /2`, default
//! 1024 x 512) holding the sky and the sun:
//! - clear sky: the Preetham sky of turbidity `T` scaled to the true `P_a` (its horizontal
//!   irradiance is `pi P_a`, [`crate::sky`]); sun: a disc of 0.533 degrees (angular radius
//!   0.2666 degrees) at the SPA direction, each texel near it weighted by its covered fraction (8 x
//!   8 sub-texels), the disc's radiance set so the texels' total irradiance `sum L dOmega` is
//!   exactly `E_sun = pi P_d`. The clear-sky sun is `P_d = K exp(-tau m)` per channel with the
//!   Kasten & Young (1989) air mass `m`, `K = 2`, `tau = (0.12, 0.16, 0.24)` (a warmer sun when
//!   low), and the sky `P_a = (0.10, 0.13, 0.19) (0.6 + 0.6 cos z)`: the sky gives 10 to 20 % of
//!   a horizontal surface's light, as on a clear day.
//! - a cloud in front of the sun: the same sky, the sun times `sun_factor`;
//! - overcast: no sun, the CIE overcast sky with `P_a = (0.30, 0.30, 0.31) (0.4 + 0.6 cos z)`.
//!
//! Nothing comes from below the horizon (the 400 m ground covers it).
//!
//! **Renders** (`Lighting::reference`, the MIS path tracer): the probe is the panorama from the
//! probe centre (its sky pixels are the environment resampled with energy conservation, so the
//! sun's power in the probe is exact); frames are the pinhole camera's. `bounces = 1` is direct
//! light only, exactly the paper's model with the Preetham sky shape (no interreflection);
//! larger values add the light the model ignores. Pixel noise falls as `1 / sqrt(spp)`.

use std::f64::consts::PI;

use glam::{DVec3, Mat3, Vec3};
use ibl_core::{Image, LatLong, Rgb};
use ibl_render::{Lighting, RenderOutput, RenderSettings, render};
use ibl_scene::description::{CompositeRule, LightingDescription, RenderDescription, SamplerKind};
use ibl_scene::{Background, Camera, GeometryLayer, Probe, Scene};
use serde::Serialize;

use crate::OutdoorError;
use crate::courtyard::Courtyard;
use crate::maps::LightingParameters;
use crate::shadow::SUN_ANGULAR_RADIUS;
use crate::sky::{SkyModel, SkyShape};
use crate::sun::{DeltaT, Location, Timestamp};

/// The weather of a frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Weather {
    /// A clear sky and sun.
    Clear,
    /// A cloud in front of the sun: the sun times `sun_factor`, the sky unchanged.
    Cloud {
        /// Fraction of the clear sun that gets through.
        sun_factor: f32,
    },
    /// Overcast: no sun, the CIE overcast sky.
    Overcast,
}

/// The true lighting of one instant.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TrueLighting {
    /// `P_d` and `P_a` as the renderer has them, and the sun direction.
    pub parameters: LightingParameters,
    /// `P_d` of the clear sun at the same time (the reference of the overcast figure).
    pub clear_sun: [f32; 3],
    /// The weather.
    pub weather: Weather,
}

impl TrueLighting {
    /// The sky model the renderer used.
    pub fn sky_model(&self, turbidity: f64) -> SkyModel {
        match self.weather {
            Weather::Overcast => SkyModel::CieOvercast,
            _ => SkyModel::Preetham { turbidity },
        }
    }
}

/// How the day is made.
#[derive(Clone, Debug, PartialEq)]
pub struct SyntheticDay {
    /// The site (its north, UTC offset and atmosphere included).
    pub location: Location,
    /// Local time of the first frame (the probe is taken then).
    pub start: Timestamp,
    /// Seconds between frames.
    pub frame_interval_s: f64,
    /// Weather of each frame (its length is the frame count).
    pub weather: Vec<Weather>,
    /// Turbidity of the clear sky.
    pub turbidity: f64,
    /// Probe width (height = width / 2).
    pub probe_width: u32,
    /// Frame size.
    pub frame_size: (u32, u32),
    /// Environment-map width of the renders.
    pub environment_width: u32,
    /// Samples per pixel of the probe.
    pub probe_spp: u32,
    /// Samples per pixel of a frame.
    pub frame_spp: u32,
    /// Surface vertices per path (1 = direct light only).
    pub bounces: u32,
    /// Seed of the renders.
    pub seed: u64,
}

impl SyntheticDay {
    /// The documented day: Aalborg (57.05 N, 9.92 E, the paper's city) on 20 April 2024 at UTC+2,
    /// frames every 30 minutes from 09:30 to 17:00 (16 frames); a cloud at 11:00 (sun x 0.3) and
    /// 11:30 (x 0.6), overcast from 14:00 to 15:00 (3 frames); turbidity 3; small renders for CI
    /// (probe 256 x 128 at 32 spp, frames 160 x 120 at 16 spp, direct light only).
    pub fn standard() -> SyntheticDay {
        let location = Location {
            utc_offset_hours: 2.0,
            elevation_m: 5.0,
            ..Location::new(57.05, 9.92)
        };
        let start = Timestamp::from_local(2024, 4, 20, 9, 30, 0.0, 2.0).expect("a valid date");
        let mut weather = vec![Weather::Clear; 16];
        weather[3] = Weather::Cloud { sun_factor: 0.3 };
        weather[4] = Weather::Cloud { sun_factor: 0.6 };
        for w in &mut weather[9..12] {
            *w = Weather::Overcast;
        }
        SyntheticDay {
            location,
            start,
            frame_interval_s: 1800.0,
            weather,
            turbidity: 3.0,
            probe_width: 256,
            frame_size: (160, 120),
            environment_width: 1024,
            probe_spp: 64,
            frame_spp: 48,
            bounces: 1,
            seed: 1,
        }
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.weather.len()
    }

    /// The instant of frame `k`.
    pub fn frame_time(&self, k: usize) -> Timestamp {
        self.start.plus_seconds(k as f64 * self.frame_interval_s)
    }

    /// The sun direction at `time` (Delta T estimated).
    pub fn sun_direction(&self, time: Timestamp) -> Result<Vec3, OutdoorError> {
        self.location.sun_direction(time, DeltaT::Estimated)
    }

    /// The true lighting at `time` in `weather`.
    pub fn truth(&self, time: Timestamp, weather: Weather) -> Result<TrueLighting, OutdoorError> {
        let sun = self.sun_direction(time)?;
        if sun.y <= 0.02 {
            return Err(OutdoorError::Parameter(format!(
                "the sun is below 1 degree of elevation at this time ({sun})"
            )));
        }
        let cos_z = f64::from(sun.y);
        let z_deg = cos_z.acos().to_degrees();
        // Kasten & Young 1989 relative air mass.
        let air_mass = 1.0 / (cos_z + 0.50572 * (96.07995 - z_deg).powf(-1.6364));
        let clear_sun = [0.12, 0.16, 0.24].map(|tau: f64| (2.0 * (-tau * air_mass).exp()) as f32);
        let (sun_p, sky_p) = match weather {
            Weather::Clear => (
                clear_sun,
                [0.10, 0.13, 0.19].map(|v: f64| (v * (0.6 + 0.6 * cos_z)) as f32),
            ),
            Weather::Cloud { sun_factor } => (
                clear_sun.map(|v| v * sun_factor),
                [0.10, 0.13, 0.19].map(|v: f64| (v * (0.6 + 0.6 * cos_z)) as f32),
            ),
            Weather::Overcast => (
                [0.0; 3],
                [0.30, 0.30, 0.31].map(|v: f64| (v * (0.4 + 0.6 * cos_z)) as f32),
            ),
        };
        Ok(TrueLighting {
            parameters: LightingParameters {
                sun: sun_p,
                sky: sky_p,
                sun_direction: sun.to_array(),
            },
            clear_sun,
            weather,
        })
    }

    /// The true lighting of frame `k`.
    pub fn frame_truth(&self, k: usize) -> Result<TrueLighting, OutdoorError> {
        let weather = *self.weather.get(k).ok_or_else(|| {
            OutdoorError::Parameter(format!("frame {k} of {}", self.frame_count()))
        })?;
        self.truth(self.frame_time(k), weather)
    }

    /// The environment map (sky and sun) of `truth`, world frame.
    pub fn environment(&self, truth: &TrueLighting) -> Result<Image<Rgb>, OutdoorError> {
        let w = self.environment_width.max(16) as usize & !1;
        let h = w / 2;
        let sun = Vec3::from_array(truth.parameters.sun_direction);
        let shape = SkyShape::new(truth.sky_model(self.turbidity), sun, 1)?;
        let pa = Rgb::from_array(truth.parameters.sky);
        let mut map = shape.latlong(w, h, Mat3::IDENTITY);
        for px in map.pixels_mut() {
            *px = *px * pa;
        }
        let pd = Rgb::from_array(truth.parameters.sun);
        if pd.max_channel() > 0.0 {
            add_sun_disc(&mut map, sun.as_dvec3(), pd * std::f32::consts::PI);
        }
        Ok(map)
    }

    fn scene(
        &self,
        layer: &GeometryLayer,
        objects: &GeometryLayer,
        environment: Image<Rgb>,
        camera: Camera,
        probe: Vec3,
    ) -> Scene {
        Scene {
            real: layer.clone(),
            virtual_objects: objects.clone(),
            probe: Probe {
                radiance: environment,
                world_from_probe: Mat3::IDENTITY,
                position: probe,
            },
            background: Background::Panorama,
            camera,
            render: RenderDescription::default(),
            lighting: LightingDescription::default(),
            luminaires: Vec::new(),
        }
    }

    fn settings(&self, width: u32, spp: u32, seed: u64) -> RenderSettings {
        RenderSettings {
            composite: CompositeRule::Difference,
            width: Some(width),
            spp,
            bounces: self.bounces,
            seed,
            // Independent numbers: the truths' stated noise (docs/OUTDOOR.md) was measured with
            // them, and their error is an unbiased standard error per pixel.
            sampler: SamplerKind::Independent,
            adaptive: None,
            adaptive_sampling: false,
        }
    }

    /// The path-traced probe (lat-long, world frame) at the probe position under `truth`.
    pub fn render_probe(
        &self,
        yard: &Courtyard,
        truth: &TrueLighting,
        seed: u64,
    ) -> Result<Image<Rgb>, OutdoorError> {
        let camera = Camera::Panorama {
            position: yard.probe_position,
            world_from_probe: Mat3::IDENTITY,
        };
        let scene = self.scene(
            &yard.layer,
            &GeometryLayer::empty(),
            self.environment(truth)?,
            camera,
            yard.probe_position,
        );
        let lighting = Lighting::reference(&scene).map_err(ibl_render::RenderError::from)?;
        let out = render(
            &scene,
            &lighting,
            &self.settings(self.probe_width, self.probe_spp, seed),
            &|_, _| {},
        )?;
        Ok(out.with_objects)
    }

    /// The path-traced frame of the yard's camera under `truth`.
    pub fn render_frame(
        &self,
        yard: &Courtyard,
        truth: &TrueLighting,
        seed: u64,
    ) -> Result<Image<Rgb>, OutdoorError> {
        let out =
            self.render_frame_with(yard, &GeometryLayer::empty(), truth, self.frame_spp, seed)?;
        Ok(out.with_objects)
    }

    /// The path-traced frame of the yard's camera under `truth` with virtual `objects` standing
    /// in the yard, at `spp` samples per pixel: `with_objects` is the truth of a composite,
    /// `without_objects` the real frame (the same paths wherever the objects change nothing, so
    /// the two differ only where the objects matter).
    pub fn render_frame_with(
        &self,
        yard: &Courtyard,
        objects: &GeometryLayer,
        truth: &TrueLighting,
        spp: u32,
        seed: u64,
    ) -> Result<RenderOutput, OutdoorError> {
        let scene = self.scene(
            &yard.layer,
            objects,
            self.environment(truth)?,
            yard.camera,
            yard.probe_position,
        );
        let lighting = Lighting::reference(&scene).map_err(ibl_render::RenderError::from)?;
        Ok(render(
            &scene,
            &lighting,
            &self.settings(self.frame_size.0, spp, seed),
            &|_, _| {},
        )?)
    }
}

/// The relit-map figure of the validation: the mean absolute error of `got` against `want`
/// (lat-long maps of the same size) over `block x block` texel blocks, each block's radiance
/// weighted by its exact solid angle, in per cent of the weighted mean of `want`, averaged over
/// the channels; blocks with a texel within 3 degrees of `sun` are left out (the sun is a
/// directional light, not part of the relit map). Blocks average away the renders' per-pixel
/// noise (by `block` for independent noise).
pub fn map_error(got: &Image<Rgb>, want: &Image<Rgb>, sun: Vec3, block: usize) -> f64 {
    let (w, h) = (want.width(), want.height());
    let grid = LatLong::new(w, h);
    let omega = grid.row_solid_angles();
    let block = block.max(1);
    let near_sun = 3f32.to_radians().cos();
    let (mut err, mut sum) = ([0.0f64; 3], [0.0f64; 3]);
    for bj in 0..h / block {
        for bi in 0..w / block {
            let (mut g, mut t, mut near) = ([0.0f64; 3], [0.0f64; 3], false);
            for (j, &omega_j) in omega.iter().enumerate().skip(bj * block).take(block) {
                for i in bi * block..(bi + 1) * block {
                    near |= grid.pixel_dir(i, j).dot(sun) > near_sun;
                    let (a, b) = (got.get(i, j).to_array(), want.get(i, j).to_array());
                    for c in 0..3 {
                        g[c] += f64::from(a[c]) * omega_j;
                        t[c] += f64::from(b[c]) * omega_j;
                    }
                }
            }
            if !near {
                for c in 0..3 {
                    err[c] += (g[c] - t[c]).abs();
                    sum[c] += t[c];
                }
            }
        }
    }
    100.0 * (0..3).map(|c| err[c] / sum[c].max(1e-30)).sum::<f64>() / 3.0
}

/// Adds a sun disc of irradiance `irradiance` (normal to it) towards `sun` to a lat-long map.
fn add_sun_disc(map: &mut Image<Rgb>, sun: DVec3, irradiance: Rgb) {
    let (w, h) = (map.width(), map.height());
    let grid = LatLong::new(w, h);
    let omega = grid.row_solid_angles();
    let cos_r = SUN_ANGULAR_RADIUS.cos();
    let (su, sv) = LatLong::dir_to_uv(sun);
    // Texels within 1 degree (plus a texel) of the centre; columns widen towards the poles.
    let margin = 1f64.to_radians() + PI / h as f64;
    let j0 = ((sv * h as f64) - margin / PI * h as f64).floor().max(0.0) as usize;
    let j1 = (((sv * h as f64) + margin / PI * h as f64).ceil() as usize).min(h);
    let sin_theta = (1.0 - sun.y * sun.y).sqrt().max(1e-3);
    let half_cols = ((margin / sin_theta) / (2.0 * PI) * w as f64).ceil() as i64 + 1;
    let centre_col = (su * w as f64).floor() as i64;
    let sub = 8;
    let mut covered: Vec<(usize, usize, f64)> = Vec::new();
    for j in j0..j1 {
        for di in -half_cols..=half_cols {
            let i = (centre_col + di).rem_euclid(w as i64) as usize;
            let mut inside = 0;
            for a in 0..sub {
                for b in 0..sub {
                    let u = (i as f64 + (a as f64 + 0.5) / sub as f64) / w as f64;
                    let v = (j as f64 + (b as f64 + 0.5) / sub as f64) / h as f64;
                    if LatLong::uv_to_dir64(u, v).dot(sun) >= cos_r {
                        inside += 1;
                    }
                }
            }
            if inside > 0 {
                covered.push((i, j, inside as f64 / (sub * sub) as f64));
            }
        }
    }
    let total: f64 = covered.iter().map(|&(_, j, f)| f * omega[j]).sum();
    if total.is_nan() || total <= 0.0 {
        return;
    }
    for (i, j, f) in covered {
        let add = irradiance * (f / total) as f32;
        *map.get_mut(i, j) = *map.get(i, j) + add;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_environment_holds_the_true_sun_and_sky() {
        let day = SyntheticDay {
            environment_width: 512,
            ..SyntheticDay::standard()
        };
        let truth = day.frame_truth(6).unwrap();
        let env = day.environment(&truth).unwrap();
        let grid = LatLong::new(env.width(), env.height());
        let omega = grid.row_solid_angles();
        let sun = Vec3::from_array(truth.parameters.sun_direction);
        // Horizontal irradiance of the sky alone (away from the sun) and of the sun alone.
        let mut sky_e = [0.0f64; 3];
        let mut sun_e = [0.0f64; 3];
        let shape = SkyShape::new(SkyModel::Preetham { turbidity: 3.0 }, sun, 1).unwrap();
        let pa = Rgb::from_array(truth.parameters.sky);
        for (j, &omega_j) in omega.iter().enumerate() {
            for i in 0..env.width() {
                let d = grid.pixel_dir(i, j);
                let l = env.get(i, j).to_array();
                let sky = (shape.radiance(d) * pa).to_array();
                for c in 0..3 {
                    sky_e[c] += f64::from(sky[c]) * f64::from(d.y.max(0.0)) * omega_j;
                    sun_e[c] += f64::from(l[c] - sky[c]) * omega_j;
                }
            }
        }
        for c in 0..3 {
            // The sky's horizontal irradiance is pi P_a (the map's own midpoint rule against the
            // shape's: 2e-4), the sun's total pi P_d (to f32 rounding of the texel sums).
            let want_sky = PI * f64::from(truth.parameters.sky[c]);
            assert!((sky_e[c] / want_sky - 1.0).abs() < 2e-3, "{sky_e:?}");
            let want_sun = PI * f64::from(truth.parameters.sun[c]);
            assert!(
                (sun_e[c] / want_sun - 1.0).abs() < 1e-3,
                "{sun_e:?} {want_sun}"
            );
        }
        // Overcast has no sun; clouds dim it.
        assert_eq!(day.frame_truth(10).unwrap().parameters.sun, [0.0; 3]);
        let cloud = day.frame_truth(3).unwrap();
        assert!((cloud.parameters.sun[0] / cloud.clear_sun[0] - 0.3).abs() < 1e-6);
    }
}

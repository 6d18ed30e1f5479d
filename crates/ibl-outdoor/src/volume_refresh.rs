//! Refreshing an irradiance volume from the frame's lighting, two ways (Jensen, Andersen & Madsen
//! 2006, sections 3.3 and 6).
//!
//! **Offline** (the paper's pre-calculation, "which pixels of the environment map are used in
//! which key point"): from every key point of an [`IrradianceVolume`] grid, rays through the
//! pixel centres of a small lat-long (default 32 x 16) are cast into the model. A ray that meets
//! a surface takes the probe pixel in the direction of that point from the probe centre (the
//! probe mapped onto the model, as the paper does); one that leaves the scene above the horizon
//! sees the sky model directly (the same in every position); below the horizon, nothing. Each
//! direction `w` of solid angle `dOmega` adds `Y_k(w) dOmega A_l` (Lambert factor of its band) to
//! its pixel's weights for SH coefficient `k`: L2 irradiance is linear in the pixels. A key point
//! from which more than a quarter of the rays meet back faces is inside something and invalid.
//!
//! **(a) From the relit map** ([`MapGather::refresh`]): `E_k = sum_pixels L_relit w_k + P_a
//! sky_k`, with `sky_k = sum_{sky rays} shape(w) Y_k dOmega A_l` re-made when the sky shape
//! changes. Cost O(key points x distinct pixels x 27) per frame.
//!
//! **(b) Relighting the key points directly** ([`KeyPointRelighter`], the optimisation the
//! paper suggests): the relit pixel is linear in the two estimates, `L = a P_a + b P_d` with `a =
//! d c_shape` (or the sky shape, or `L_probe / P_a,0` for pixels without albedo) and `b = d s
//! max(0, n . l)`, so each key point's irradiance is `E = P_a A + P_d B` with two fixed RGB SH
//! sets `A`, `B` gathered once per sun move (shadow or shape change). Per frame that is 54
//! multiply-adds per key point, whatever the map size; it equals (a) up to rounding.

use glam::Vec3;
use ibl_core::{Image, LatLong, Rgb};
use ibl_scene::{GeometryLayer, Ray};
use ibl_sh::{
    IrradianceL2, IrradianceVolume, VolumeGrid, VolumeLayer, VolumeLayers, eval_basis,
    lambert_factor,
};
use rayon::prelude::*;

use crate::OutdoorError;
use crate::maps::ProbeMaps;
use crate::relight::Relighter;
use crate::tracking::SkyTracker;

/// L2 weights of one direction or pixel: `Y_k(w) dOmega A_l`.
type Weights = [f32; 9];

/// One key point's gather list.
#[derive(Clone, Debug, Default)]
struct KeyGather {
    /// `(row-major probe pixel, weights)`, one entry per distinct pixel.
    pixels: Vec<(u32, Weights)>,
    /// Directions that see the sky, with their weights.
    sky: Vec<(Vec3, Weights)>,
}

/// The precomputed pixel-to-key-point weights.
#[derive(Clone, Debug)]
pub struct MapGather {
    grid: VolumeGrid,
    valid: Vec<bool>,
    keys: Vec<KeyGather>,
    /// Per key point, `sum_{sky rays} shape(w) w_k` (RGB per coefficient).
    sky_parts: Vec<IrradianceL2>,
    sky_generation: u64,
    directions: usize,
}

fn weights(w: Vec3, d_omega: f32) -> Weights {
    let mut y = [0.0f64; 9];
    eval_basis(w.as_dvec3(), 3, &mut y);
    let mut out = [0.0f32; 9];
    for (k, o) in out.iter_mut().enumerate() {
        let l = if k == 0 {
            0
        } else if k < 4 {
            1
        } else {
            2
        };
        *o = (y[k] * lambert_factor(l)) as f32 * d_omega;
    }
    out
}

impl MapGather {
    /// Casts `width x width/2` rays from every key point of `grid` into `layer` and maps them to
    /// the pixels of `maps`' probe.
    pub fn new(
        layer: &GeometryLayer,
        maps: &ProbeMaps,
        grid: VolumeGrid,
        width: usize,
    ) -> Result<MapGather, OutdoorError> {
        if !(4..=512).contains(&width) {
            return Err(OutdoorError::Parameter(format!(
                "key-point map width must be 4 to 512; got {width}"
            )));
        }
        let height = width / 2;
        let dirs = LatLong::new(width, height);
        let solid: Vec<f32> = dirs.row_solid_angles().iter().map(|&v| v as f32).collect();
        let projection = maps.projection();
        let (pw, _) = maps.size();
        let per_key: Vec<(bool, KeyGather)> = (0..grid.len())
            .into_par_iter()
            .map(|index| {
                let origin = grid.position(index).as_vec3();
                let mut pixels: std::collections::BTreeMap<u32, Weights> = Default::default();
                let mut sky = Vec::new();
                let mut back = 0usize;
                for (j, &d_omega) in solid.iter().enumerate() {
                    for i in 0..width {
                        let w = dirs.pixel_dir(i, j);
                        let wts = weights(w, d_omega);
                        let ray = Ray::new(origin, w);
                        match layer.bvh.closest_hit(&ray, 0.0, f32::INFINITY) {
                            Some(hit) => {
                                let s = &layer.surfaces[hit.triangle as usize];
                                if s.geometric_normal.dot(w) > 0.0 {
                                    back += 1;
                                }
                                let point = ray.at(hit.t);
                                let d = (point - projection.position).normalize_or(Vec3::Y);
                                let (pi, pj) = projection.pixel_towards(d);
                                let entry = pixels.entry((pj * pw + pi) as u32).or_insert([0.0; 9]);
                                for (e, v) in entry.iter_mut().zip(wts) {
                                    *e += v;
                                }
                            }
                            None if w.y > 0.0 => sky.push((w, wts)),
                            None => {}
                        }
                    }
                }
                let valid = back * 4 <= width * height;
                (
                    valid,
                    KeyGather {
                        pixels: pixels.into_iter().collect(),
                        sky,
                    },
                )
            })
            .collect();
        let valid = per_key.iter().map(|k| k.0).collect();
        let keys = per_key.into_iter().map(|k| k.1).collect();
        Ok(MapGather {
            grid,
            valid,
            keys,
            sky_parts: vec![IrradianceL2::ZERO; grid.len()],
            sky_generation: 0,
            directions: width * height,
        })
    }

    /// A volume for this grid with the validity found (one layer, zero irradiance).
    pub fn empty_volume(&self) -> IrradianceVolume {
        let mut v = IrradianceVolume::new(self.grid, VolumeLayers::AllLight);
        for (i, &ok) in self.valid.iter().enumerate() {
            v.set_valid(i, ok);
        }
        v
    }

    /// Rays cast per key point.
    pub fn directions(&self) -> usize {
        self.directions
    }

    /// Distinct probe pixels gathered, over all key points.
    pub fn entries(&self) -> usize {
        self.keys.iter().map(|k| k.pixels.len()).sum()
    }

    fn update_sky(&mut self, sky: &SkyTracker) -> Result<(), OutdoorError> {
        if self.sky_generation == sky.generation() {
            return Ok(());
        }
        let shape = sky.shape()?;
        self.sky_parts = self
            .keys
            .par_iter()
            .map(|k| {
                let mut out = IrradianceL2::ZERO;
                for (w, wts) in &k.sky {
                    let l = shape.radiance(*w).to_array();
                    for (c, v) in out.coefficients.iter_mut().zip(wts) {
                        for ch in 0..3 {
                            c[ch] += l[ch] * v;
                        }
                    }
                }
                out
            })
            .collect();
        self.sky_generation = sky.generation();
        Ok(())
    }

    /// (a): writes every key point's irradiance from the relit map `relit` and `P_a = sky`.
    pub fn refresh(
        &mut self,
        relit: &Image<Rgb>,
        sky_tracker: &SkyTracker,
        sky: Rgb,
        volume: &mut IrradianceVolume,
    ) -> Result<(), OutdoorError> {
        self.update_sky(sky_tracker)?;
        if volume.grid() != &self.grid {
            return Err(OutdoorError::Parameter(
                "the volume's grid is not the one the weights were made for".into(),
            ));
        }
        let pixels = relit.pixels();
        let pa = sky.to_array();
        let out = volume
            .layer_mut(VolumeLayer::AllLight)
            .map_err(|e| OutdoorError::Parameter(e.to_string()))?;
        out.par_iter_mut()
            .zip(self.keys.par_iter().zip(&self.sky_parts))
            .for_each(|(o, (key, sky_part))| {
                let mut acc = [[0.0f32; 3]; 9];
                for (p, wts) in &key.pixels {
                    let l = pixels[*p as usize].to_array();
                    for (a, v) in acc.iter_mut().zip(wts) {
                        a[0] += l[0] * v;
                        a[1] += l[1] * v;
                        a[2] += l[2] * v;
                    }
                }
                for (a, s) in acc.iter_mut().zip(&sky_part.coefficients) {
                    for ch in 0..3 {
                        a[ch] += pa[ch] * s[ch];
                    }
                }
                o.coefficients = acc;
            });
        Ok(())
    }
}

/// (b): each key point's irradiance as `P_a A + P_d B` (see the module doc).
#[derive(Clone, Debug)]
pub struct KeyPointRelighter {
    sky_response: Vec<IrradianceL2>,
    sun_response: Vec<IrradianceL2>,
    /// The relighter state the responses were gathered for: (sky generation, shadow casts).
    made_for: Option<(u64, u32)>,
}

impl Default for KeyPointRelighter {
    fn default() -> Self {
        Self::new()
    }
}

impl KeyPointRelighter {
    /// No responses yet.
    pub fn new() -> KeyPointRelighter {
        KeyPointRelighter {
            sky_response: Vec::new(),
            sun_response: Vec::new(),
            made_for: None,
        }
    }

    /// Re-gathers the responses when the relighter's shadows or sky shape changed (the sun moved
    /// past their thresholds); returns whether it did. In between, `B` keeps the cosines of the
    /// last gather: the sun moves less than the shadow threshold (0.25 degrees) meanwhile, which
    /// changes a cosine by less than 0.0044. `relighter` must be updated for `sun`.
    pub fn update(
        &mut self,
        gather: &mut MapGather,
        maps: &ProbeMaps,
        relighter: &Relighter,
        sky: &SkyTracker,
        sun: Vec3,
    ) -> Result<bool, OutdoorError> {
        let Some(state) = relighter.made_for() else {
            return Err(OutdoorError::Parameter(
                "the relighter was not updated for these maps".into(),
            ));
        };
        if self.made_for == Some(state) {
            return Ok(false);
        }
        gather.update_sky(sky)?;
        let (w, h) = maps.size();
        let responses = relighter.pixel_responses();
        if responses.len() != w * h {
            return Err(OutdoorError::Parameter(
                "the relighter was not updated for these maps".into(),
            ));
        }
        // Per pixel: the response to unit P_a and to unit P_d.
        let response = |p: usize| -> (Rgb, Rgb) {
            let r = &responses[p];
            (r.sky, r.sun_response(sun))
        };
        let gathered: Vec<(IrradianceL2, IrradianceL2)> = gather
            .keys
            .par_iter()
            .zip(&gather.sky_parts)
            .map(|(key, sky_part)| {
                let mut a = *sky_part;
                let mut b = IrradianceL2::ZERO;
                for (p, wts) in &key.pixels {
                    let (ra, rb) = response(*p as usize);
                    let (ra, rb) = (ra.to_array(), rb.to_array());
                    for (k, v) in wts.iter().enumerate() {
                        for ch in 0..3 {
                            a.coefficients[k][ch] += ra[ch] * v;
                            b.coefficients[k][ch] += rb[ch] * v;
                        }
                    }
                }
                (a, b)
            })
            .collect();
        self.sky_response = gathered.iter().map(|g| g.0).collect();
        self.sun_response = gathered.iter().map(|g| g.1).collect();
        self.made_for = Some(state);
        Ok(true)
    }

    /// Writes `P_a A + P_d B` into every key point of `volume`.
    pub fn refresh(
        &self,
        sky: Rgb,
        sun: Rgb,
        volume: &mut IrradianceVolume,
    ) -> Result<(), OutdoorError> {
        let out = volume
            .layer_mut(VolumeLayer::AllLight)
            .map_err(|e| OutdoorError::Parameter(e.to_string()))?;
        if out.len() != self.sky_response.len() {
            return Err(OutdoorError::Parameter(
                "the key-point responses were not gathered for this volume".into(),
            ));
        }
        let (pa, pd) = (sky.to_array(), sun.to_array());
        for ((o, a), b) in out
            .iter_mut()
            .zip(&self.sky_response)
            .zip(&self.sun_response)
        {
            for k in 0..9 {
                for ch in 0..3 {
                    o.coefficients[k][ch] =
                        pa[ch] * a.coefficients[k][ch] + pd[ch] * b.coefficients[k][ch];
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::maps::{CaptureSource, LightingParameters, MapSettings};
    use crate::sky::SkyModel;
    use glam::{DVec3, Mat3};
    use ibl_scene::{Material, PlacedMesh, primitives};
    use ibl_sh::LeakControl;

    /// An open ground of albedo 1 under a uniform sky `P_a`, no sun at capture: the probe sees
    /// `P_a` everywhere, the albedo map is 1, and with `P_d = 0` the relit world is the constant
    /// `P_a`, whose irradiance is `pi P_a` for every normal.
    fn open_ground() -> (GeometryLayer, ProbeMaps, Vec3) {
        let layer = GeometryLayer::new(vec![PlacedMesh {
            name: "ground".into(),
            mesh: primitives::plane(Vec3::ZERO, Vec3::Y, [200.0, 200.0]),
            materials: vec![Material::Diffuse { albedo: Rgb::ONE }],
        }]);
        let pa0 = Rgb::new(0.2, 0.3, 0.4);
        let probe = Image::filled(64, 32, pa0);
        let sun = Vec3::new(0.3, 0.8, 0.4).normalize();
        let maps = ProbeMaps::build(
            &layer,
            &probe,
            Vec3::new(0.0, 1.0, 0.0),
            Mat3::IDENTITY,
            sun,
            CaptureSource::Given(LightingParameters {
                sun: [0.0; 3],
                sky: pa0.to_array(),
                sun_direction: sun.to_array(),
            }),
            MapSettings {
                sky_model: SkyModel::Uniform,
                transfer_bands: 3,
                transfer_rays: 64,
                ..MapSettings::default()
            },
        )
        .unwrap();
        (layer, maps, sun)
    }

    #[test]
    fn a_constant_world_gives_pi_l_and_both_refreshes_agree() {
        let (layer, maps, sun) = open_ground();
        let mut sky = SkyTracker::new(SkyModel::Uniform, 3, 0.01);
        sky.update(sun).unwrap();
        let mut relighter = Relighter::new(&maps, 0.004);
        relighter.update(&layer, &maps, &sky, sun).unwrap();
        let grid =
            VolumeGrid::new(DVec3::new(-3.0, 1.0, -3.0), DVec3::splat(6.0), [2, 1, 2]).unwrap();
        let mut gather = MapGather::new(&layer, &maps, grid, 32).unwrap();
        let mut volume = gather.empty_volume();
        let pa = Rgb::new(0.5, 0.6, 0.7);
        let relit = relighter.relight(&maps, sun, pa, Rgb::ZERO).unwrap();
        gather.refresh(&relit, &sky, pa, &mut volume).unwrap();
        for n in [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ] {
            let e = volume
                .sample(
                    Vec3::new(0.0, 1.0, 0.0),
                    VolumeLayer::AllLight,
                    LeakControl::ValidOnly,
                )
                .unwrap()
                .unwrap()
                .irradiance(n);
            for (c, v) in e.iter().enumerate() {
                let want = std::f32::consts::PI * pa.to_array()[c];
                // Y_lm sampled at texel centres over exact texel solid angles: band 2's m = 0
                // term of a constant does not sum to exactly 0 at 32 x 16 (measured 2.0e-3 of
                // the irradiance on +-Y, 1.0e-3 on the horizontal axes), margin 2x.
                assert!((v / want - 1.0).abs() < 4e-3, "{n}: {v} vs {want}");
            }
        }
        // With a sun, (b) equals (a) to f32 rounding.
        let pd = Rgb::new(1.5, 1.4, 1.2);
        let relit = relighter.relight(&maps, sun, pa, pd).unwrap();
        gather.refresh(&relit, &sky, pa, &mut volume).unwrap();
        let from_map = volume.layer(VolumeLayer::AllLight).unwrap().to_vec();
        let mut keys = KeyPointRelighter::new();
        assert!(
            keys.update(&mut gather, &maps, &relighter, &sky, sun)
                .unwrap()
        );
        assert!(
            !keys
                .update(&mut gather, &maps, &relighter, &sky, sun)
                .unwrap()
        );
        keys.refresh(pa, pd, &mut volume).unwrap();
        let direct = volume.layer(VolumeLayer::AllLight).unwrap();
        for (a, b) in from_map.iter().zip(direct) {
            let scale = a.coefficients[0].iter().fold(0.0f32, |m, v| m.max(v.abs()));
            for (x, y) in a.coefficients.iter().zip(&b.coefficients) {
                for c in 0..3 {
                    // Sums of ~2000 f32 terms in another order: 1e-5 of the largest coefficient.
                    assert!((x[c] - y[c]).abs() <= 1e-5 * scale, "{x:?} {y:?}");
                }
            }
        }
    }
}

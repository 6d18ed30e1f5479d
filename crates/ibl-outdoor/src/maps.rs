//! The offline maps in the probe's lat-long (Jensen, Andersen & Madsen 2006, section 4.1): the
//! normal map, the weighted-ambient map (with the sky transfer vectors behind it), the shadow map
//! of a sun direction and the albedo map by inverse rendering of the probe with its own sun and
//! sky at capture time.
//!
//! Every map is indexed by the probe's surface pixels: those whose centre ray (see
//! [`crate::view`]) meets the scene model. **Albedo** inverts the per-pixel model at capture time
//! `0`:
//!
//! ```text
//! d = P_probe / (c_shape,0 P_a,0 + s_0 max(0, n . l_0) P_d,0)        per channel
//! ```
//!
//! where `P_a,0` and `P_d,0` are the capture lighting, given, or measured from the probe itself
//! ([`CaptureSource::Measured`]): `P_a,0` is the ratio estimate `sum L w / sum shape w` over the
//! probe's sky pixels (those whose four neighbours are sky too, farther than 10 degrees from the
//! sun), `w = dOmega max(0, d_y)`, so that it is the equivalent uniform sky of CONVENTIONS; `P_d,0`
//! is the sun's irradiance over pi, `sum (L - P_a,0 shape) dOmega / pi` over the sky pixels within
//! 3 degrees (at least 3 pixels) of the SPA sun direction. A pixel whose denominator is below 2 %
//! of `P_a,0` (it sees almost no sky and no sun) has no albedo: its relit value is its captured
//! radiance scaled with the sky ([`crate::relight`]). Albedos above 1 are kept (they flag light
//! the model does not have, such as interreflections) but samples use only albedos in `(0, 1]`.
//!
//! The sun term `s_0 max(0, n . l_0)` is the mean over the pixel's footprint, a grid of
//! `footprint_side^2` sub-pixel rays whose shadow rays spread over the sun's disc
//! ([`crate::tracking::PointLighting`], [`crate::shadow`]): a probe pixel across a shadow edge,
//! in a penumbra, or a grazing ground pixel that spans metres, is partly sunlit, and a binary
//! value at its centre would give it a wrong albedo (measured on the synthetic day: the relit
//! map's error against the path-traced probe, with the true lighting, fell from 5.0 % to 3.2 %
//! at 12:30 with a 2 x 2 footprint). Only **pure** pixels, whose footprint stays on one plane,
//! are inverted this way; a pixel across the skyline or a geometric edge takes its albedo from
//! pure neighbours ([`crate::footprint`]).
//!
//! With [`Interreflection::Bounces`] the denominator also holds the light the other surfaces
//! reflect onto the point, read from the probe itself ([`crate::interreflection`]): `d = P /
//! (c_shape,0 P_a,0 + k_0 P_d,0 + sum_r G_r P_r)`, so the albedo no longer absorbs the
//! interreflections of capture time.
//!
//! **Normal map**: the unit normal of each surface pixel, facing the probe, as RGB = XYZ (the
//! paper renders it in two passes with coloured principal lights; ray casting gives it directly).
//! **Shadow map**: [`crate::shadow`] at the surface pixels (at their centres, binary, as the
//! paper's). **Weighted ambient**: [`crate::transfer`].

use std::f64::consts::PI;

use glam::{Mat3, Vec3};
use ibl_core::{Image, LatLong, Rgb};
use ibl_scene::GeometryLayer;
use serde::Serialize;

use crate::OutdoorError;
use crate::footprint::ProbeFootprints;
use crate::interreflection::{BounceGather, BounceSource, Interreflection};
use crate::shadow::sun_visibility;
use crate::sky::{SkyModel, SkyShape};
use crate::tracking::{PointLighting, SkyTracker};
use crate::transfer::{AmbientTransfer, SurfacePoint};
use crate::view::ProbeProjection;

/// The sun and sky parameters at one instant, with the sun's direction.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LightingParameters {
    /// `P_d` (the sun's normal irradiance over pi), RGB.
    pub sun: [f32; 3],
    /// `P_a` (the equivalent uniform sky radiance), RGB.
    pub sky: [f32; 3],
    /// Unit world direction towards the sun.
    pub sun_direction: [f32; 3],
}

/// Where the capture lighting comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CaptureSource {
    /// Measured from the probe's own sky and sun pixels (see the module doc).
    Measured,
    /// Given (e.g. metered at capture); its `sun_direction` must be the capture sun.
    Given(LightingParameters),
}

/// How the offline maps are made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapSettings {
    /// Sky model of the per-frame model (`Uniform` is the paper's).
    pub sky_model: SkyModel,
    /// SH bands of the sky transfer vectors and shapes (1 to 8).
    pub transfer_bands: usize,
    /// Cosine rays per surface pixel for the transfer vectors.
    pub transfer_rays: u32,
    /// Sub-pixel rays per side of each pixel's footprint for the sun term and the detection
    /// of mixed pixels (4: sixteen shadow rays per pixel; 1: the paper's one binary value at
    /// the pixel centre).
    pub footprint_side: usize,
    /// Light reflected between the model's surfaces ([`crate::interreflection`]).
    pub interreflection: Interreflection,
    /// Seed of the ray jitter.
    pub seed: u64,
}

impl Default for MapSettings {
    fn default() -> Self {
        MapSettings {
            sky_model: SkyModel::Preetham { turbidity: 3.0 },
            transfer_bands: 8,
            transfer_rays: 256,
            footprint_side: 4,
            interreflection: Interreflection::Bounces {
                bounces: 4,
                rays: 64,
            },
            seed: 1,
        }
    }
}

/// The offline maps of one probe.
#[derive(Clone, Debug)]
pub struct ProbeMaps {
    projection: ProbeProjection,
    settings: MapSettings,
    /// Row-major pixel index of each surface point.
    pixels: Vec<usize>,
    /// Per pixel, its surface point (`u32::MAX`: sky).
    point_of_pixel: Vec<u32>,
    points: Vec<SurfacePoint>,
    transfer: AmbientTransfer,
    albedo: Vec<Option<Rgb>>,
    footprints: ProbeFootprints,
    bounce: Option<BounceGather>,
    capture: LightingParameters,
    capture_sun_terms: Vec<f32>,
    probe: Image<Rgb>,
}

/// Angle from the sun beyond which sky pixels measure `P_a,0`, radians (10 degrees).
const SKY_FIT_SUN_CLEARANCE: f64 = 10.0 * PI / 180.0;
/// Radius of the cap that measures the sun, radians (3 degrees).
const SUN_CAP_RADIUS: f64 = 3.0 * PI / 180.0;
/// Smallest albedo denominator, as a fraction of `P_a,0`.
const MIN_DENOMINATOR: f32 = 0.02;

impl ProbeMaps {
    /// Builds every map for the lat-long `probe` (radiance, its own frame) taken at `position`
    /// with `world_from_probe`, the scene model `layer`, the sun towards `capture_sun` (unit,
    /// world) at capture time and the capture lighting from `source`. Cost: the transfer
    /// vectors, `transfer_rays` rays per surface pixel.
    pub fn build(
        layer: &GeometryLayer,
        probe: &Image<Rgb>,
        position: Vec3,
        world_from_probe: Mat3,
        capture_sun: Vec3,
        source: CaptureSource,
        settings: MapSettings,
    ) -> Result<ProbeMaps, OutdoorError> {
        let (w, h) = (probe.width(), probe.height());
        if w < 8 || w != 2 * h {
            return Err(OutdoorError::Parameter(format!(
                "the probe must be a lat-long of at least 8 x 4 pixels with width = 2 x height; got {w} x {h}"
            )));
        }
        if !(capture_sun.is_finite() && (capture_sun.length() - 1.0).abs() < 1e-3) {
            return Err(OutdoorError::Parameter(format!(
                "the capture sun direction {capture_sun} is not a unit vector"
            )));
        }
        let projection = ProbeProjection::new(layer, position, world_from_probe, w);
        let pixels = projection.view.surface_pixels();
        let mut point_of_pixel = vec![u32::MAX; w * h];
        let points: Vec<SurfacePoint> = pixels
            .iter()
            .enumerate()
            .map(|(k, &p)| {
                point_of_pixel[p] = k as u32;
                let hit = projection.view.hits()[p].expect("surface pixel");
                SurfacePoint {
                    position: hit.position,
                    normal: hit.normal,
                }
            })
            .collect();
        let transfer = AmbientTransfer::compute(
            layer,
            &points,
            settings.transfer_bands,
            settings.transfer_rays,
            settings.seed,
        )?;
        let shape = SkyShape::new(settings.sky_model, capture_sun, settings.transfer_bands)?;
        let capture = match source {
            CaptureSource::Given(p) => p,
            CaptureSource::Measured => {
                measure_capture(probe, &projection, &point_of_pixel, capture_sun, &shape)?
            }
        };
        settings.interreflection.validate()?;
        let side = settings.footprint_side.clamp(1, 8);
        let footprints = ProbeFootprints::build(layer, &projection, &pixels, &points, side);
        let mut capture_lighting = PointLighting::new(0.0, footprints.sub_points(), side * side);
        let mut capture_sky = SkyTracker::new(settings.sky_model, settings.transfer_bands, 0.0);
        capture_sky.update(capture_sun)?;
        capture_lighting.update(layer, &points, &transfer, &capture_sky, capture_sun)?;
        let capture_sun_terms: Vec<f32> = (0..points.len())
            .map(|k| capture_lighting.sun_term(k, capture_sun))
            .collect();
        let bounce = match settings.interreflection {
            Interreflection::Off => None,
            Interreflection::Bounces { rays, .. } => Some(BounceGather::build(
                layer,
                &points,
                rays,
                settings.seed ^ 0xB0B0,
                |y| bounce_source(&projection, &point_of_pixel, &footprints, y),
            )?),
        };
        // The light other surfaces reflect onto each point at capture time, from the probe.
        let observed: Vec<Rgb> = pixels.iter().map(|&p| probe.pixels()[p]).collect();
        let capture_bounce = bounce.as_ref().map(|g| g.gather_all(&observed));
        let (pa, pd) = (Rgb::from_array(capture.sky), Rgb::from_array(capture.sun));
        let albedo = (0..points.len())
            .map(|k| {
                let c = capture_lighting.sky_terms()[k];
                let sun_term = capture_sun_terms[k];
                let indirect = capture_bounce.as_ref().map_or(Rgb::ZERO, |b| b[k]);
                let denominator = c * pa + pd * sun_term + indirect;
                let ok = (0..3).all(|ch| denominator[ch] > MIN_DENOMINATOR * pa[ch]);
                ok.then(|| {
                    Rgb::new(
                        observed[k].r / denominator.r,
                        observed[k].g / denominator.g,
                        observed[k].b / denominator.b,
                    )
                })
            })
            .collect();
        Ok(ProbeMaps {
            projection,
            settings,
            pixels,
            point_of_pixel,
            points,
            transfer,
            albedo,
            footprints,
            bounce,
            capture,
            capture_sun_terms,
            probe: probe.clone(),
        })
    }

    /// The probe's view and projective mapping.
    pub fn projection(&self) -> &ProbeProjection {
        &self.projection
    }

    /// The settings the maps were made with.
    pub fn settings(&self) -> &MapSettings {
        &self.settings
    }

    /// Map width and height.
    pub fn size(&self) -> (usize, usize) {
        (self.projection.view.width(), self.projection.view.height())
    }

    /// The surface points, in surface-pixel order.
    pub fn points(&self) -> &[SurfacePoint] {
        &self.points
    }

    /// Row-major pixel index of each surface point.
    pub fn surface_pixels(&self) -> &[usize] {
        &self.pixels
    }

    /// The surface point of row-major pixel `p` (`None`: sky).
    pub fn point_of_pixel(&self, p: usize) -> Option<usize> {
        let k = self.point_of_pixel[p];
        (k != u32::MAX).then_some(k as usize)
    }

    /// The sky transfer vectors of the surface points.
    pub fn transfer(&self) -> &AmbientTransfer {
        &self.transfer
    }

    /// Albedo of each surface point (`None` where it could not be found).
    pub fn albedo(&self) -> &[Option<Rgb>] {
        &self.albedo
    }

    /// The capture lighting used for the albedo.
    pub fn capture(&self) -> LightingParameters {
        self.capture
    }

    /// The sun term `k` of each surface point at capture time (its footprint's mean of `s max(0,
    /// n . l_0)`).
    pub fn capture_sun_terms(&self) -> &[f32] {
        &self.capture_sun_terms
    }

    /// Each surface pixel's footprint: its sub-rays, whether it is mixed, its donors.
    pub fn footprints(&self) -> &ProbeFootprints {
        &self.footprints
    }

    /// The bounce gather of the surface points (`None` when interreflection is off).
    pub fn bounce(&self) -> Option<&BounceGather> {
        self.bounce.as_ref()
    }

    /// Where a ray that met the world point `y` takes its radiance from (see
    /// [`crate::interreflection`]): the surface point of the probe pixel that saw `y`, or of the
    /// pixel in its direction when the probe did not, handed to its pure donor when mixed.
    pub fn bounce_source(&self, y: Vec3) -> BounceSource {
        bounce_source(&self.projection, &self.point_of_pixel, &self.footprints, y)
    }

    /// The probe image.
    pub fn probe(&self) -> &Image<Rgb> {
        &self.probe
    }

    fn image_of<T: Clone + Send + Sync>(&self, sky: T, f: impl Fn(usize) -> T + Sync) -> Image<T> {
        let (w, h) = self.size();
        Image::from_fn_par(w, h, |i, j| match self.point_of_pixel(j * w + i) {
            Some(k) => f(k),
            None => sky.clone(),
        })
    }

    /// The normal map: unit normals as RGB = XYZ, sky black.
    pub fn normal_map(&self) -> Image<Rgb> {
        self.image_of(Rgb::ZERO, |k| {
            Rgb::from_array(self.points[k].normal.to_array())
        })
    }

    /// The weighted-ambient map `c` (sky: 1, it sees itself).
    pub fn weighted_ambient_map(&self) -> Image<f32> {
        self.image_of(1.0, |k| self.transfer.weighted_ambient(k))
    }

    /// The bound on the standard error of each pixel's `c` (sky: 0).
    pub fn weighted_ambient_error_map(&self) -> Image<f32> {
        self.image_of(0.0, |k| self.transfer.standard_error(k))
    }

    /// The albedo map (sky and unknown pixels black); a mixed pixel shows its centre donor's.
    pub fn albedo_map(&self) -> Image<Rgb> {
        self.image_of(Rgb::ZERO, |k| {
            self.albedo[self.footprints.centre_donor(k)].unwrap_or(Rgb::ZERO)
        })
    }

    /// The map of mixed pixels (1: the footprint leaves the centre's plane; sky 0).
    pub fn mixed_map(&self) -> Image<f32> {
        self.image_of(0.0, |k| f32::from(u8::from(self.footprints.is_mixed(k))))
    }

    /// The binary shadow map for a sun towards `sun` (sky: 1).
    pub fn shadow_map(&self, layer: &GeometryLayer, sun: Vec3) -> Image<f32> {
        let centres: Vec<Option<SurfacePoint>> = self.points.iter().copied().map(Some).collect();
        let s = sun_visibility(layer, &centres, sun, 1);
        self.image_of(1.0, |k| s[k])
    }
}

/// See [`ProbeMaps::bounce_source`].
fn bounce_source(
    projection: &ProbeProjection,
    point_of_pixel: &[u32],
    footprints: &ProbeFootprints,
    y: Vec3,
) -> BounceSource {
    let w = projection.view.width();
    let (seen, (i, j)) = match projection.pixel_of(y) {
        Some(ij) => (true, ij),
        None => (
            false,
            projection.pixel_towards((y - projection.position).normalize_or(Vec3::Y)),
        ),
    };
    match point_of_pixel[j * w + i] {
        u32::MAX => BounceSource::Lost,
        k => {
            let source = footprints.centre_donor(k as usize) as u32;
            if seen {
                BounceSource::Seen(source)
            } else {
                BounceSource::Unseen(source)
            }
        }
    }
}

/// The capture lighting from the probe's own sky and sun pixels (see the module doc).
fn measure_capture(
    probe: &Image<Rgb>,
    projection: &ProbeProjection,
    point_of_pixel: &[u32],
    sun: Vec3,
    shape: &SkyShape,
) -> Result<LightingParameters, OutdoorError> {
    let (w, h) = (probe.width(), probe.height());
    let grid = LatLong::new(w, h);
    let omega = grid.row_solid_angles();
    let sky = |i: usize, j: usize| point_of_pixel[j * w + i] == u32::MAX;
    let sun64 = sun.as_dvec3();
    let rotation = projection.world_from_probe;
    let mut num = [0.0f64; 3];
    let mut den = [0.0f64; 3];
    for (j, &omega_j) in omega.iter().enumerate().take(h - 1).skip(1) {
        for i in 0..w {
            let neighbours = [
                (i, j - 1),
                (i, j + 1),
                ((i + 1) % w, j),
                ((i + w - 1) % w, j),
            ];
            if !sky(i, j) || neighbours.iter().any(|&(a, b)| !sky(a, b)) {
                continue;
            }
            let d = rotation * grid.pixel_dir(i, j);
            if d.y <= 0.0 || d.as_dvec3().dot(sun64).clamp(-1.0, 1.0).acos() < SKY_FIT_SUN_CLEARANCE
            {
                continue;
            }
            let weight = omega_j * f64::from(d.y);
            let l = probe.get(i, j).to_array();
            let s = shape.radiance(d).to_array();
            for c in 0..3 {
                num[c] += f64::from(l[c]) * weight;
                den[c] += f64::from(s[c]) * weight;
            }
        }
    }
    if den.iter().any(|&v| v.is_nan() || v <= 0.0) {
        return Err(OutdoorError::Parameter(
            "the probe shows no open sky to measure the sky parameter from".into(),
        ));
    }
    let pa = [0, 1, 2].map(|c| num[c] / den[c]);
    let (si, sj) = projection.pixel_towards(sun);
    if !sky(si, sj) {
        return Err(OutdoorError::Parameter(
            "the model hides the sun from the probe at capture time, so the probe cannot measure \
             it: give the capture lighting instead"
                .into(),
        ));
    }
    let cap = SUN_CAP_RADIUS.max(3.0 * PI / h as f64);
    let mut e_sun = [0.0f64; 3];
    for (j, &omega_j) in omega.iter().enumerate() {
        for i in 0..w {
            let d = rotation * grid.pixel_dir(i, j);
            if !sky(i, j) || d.as_dvec3().dot(sun64).clamp(-1.0, 1.0).acos() > cap {
                continue;
            }
            let l = probe.get(i, j).to_array();
            let s = shape.radiance(d).to_array();
            for c in 0..3 {
                e_sun[c] += (f64::from(l[c]) - pa[c] * f64::from(s[c])) * omega_j;
            }
        }
    }
    Ok(LightingParameters {
        sun: e_sun.map(|e| (e.max(0.0) / PI) as f32),
        sky: pa.map(|v| v as f32),
        sun_direction: sun.to_array(),
    })
}

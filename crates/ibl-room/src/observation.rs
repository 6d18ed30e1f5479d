//! What the probe shows of each patch (Grosch 2005, section 3.2): its mean radiance `L` over the
//! probe pixels that see it (depth test), hence its radiosity `B = pi L`, and the fraction of its
//! area the probe sees.
//!
//! A pixel of the depth map belongs to the patch its centre's ray meets first (front side). Its
//! radiance is used only when every pixel within `edge_margin_px` (in the lat-long grid,
//! wrapping across the seam) meets the **same face**: a pixel on a face's edge mixes two
//! surfaces (a bright window and the wall beside it), and a real model is off by a pixel or two
//! there anyway. Edges between patches of one face are harmless (radiosity is continuous
//! across them) and keep their pixels.
//!
//! The mean is **area-weighted**: pixel `(i, j)` covers `dA = dOmega_j d^2 / cos(theta)` of the
//! patch (`dOmega_j` the exact lat-long texel solid angle, `d` the depth, `theta` the angle
//! between the ray and the patch normal, its cosine floored at 0.05), so `L` estimates the
//! patch's area average: what the form-factor sums of radiosity assume. The seen fraction is the
//! sum of `dA` over every pixel meeting the patch (edge pixels included), divided by its area
//! and capped at 1.

use ibl_core::rgb::Rgb64;
use ibl_core::{Image, LatLong, Rgb};

use crate::depth_map::{NO_PATCH, ProbeDepthMap};
use crate::{Room, RoomError};

/// How probe pixels are assigned to patches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObservationSettings {
    /// Pixels within this many pixels of a face edge are not used for radiance (0 keeps all).
    pub edge_margin_px: u32,
    /// A patch counts as seen when at least this fraction of its area is seen ...
    pub min_seen_fraction: f32,
    /// ... and at least this many pixels away from edges see it.
    pub min_pixels: u32,
}

impl Default for ObservationSettings {
    fn default() -> Self {
        ObservationSettings {
            edge_margin_px: 1,
            min_seen_fraction: 0.25,
            min_pixels: 4,
        }
    }
}

/// What the probe shows of one patch.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PatchObservation {
    /// Area-weighted mean radiance of the pixels away from edges (zero when there are none).
    pub radiance: Rgb,
    /// Pixels away from edges that see the patch.
    pub pixels: u32,
    /// Fraction of the patch's area the probe sees, in [0, 1].
    pub seen_fraction: f32,
}

impl PatchObservation {
    /// Radiosity `B = pi L`.
    pub fn radiosity(&self) -> Rgb {
        self.radiance * std::f32::consts::PI
    }
}

/// The probe's view of every patch.
#[derive(Clone, Debug, PartialEq)]
pub struct Observations {
    /// One per patch, in the room's order.
    pub patches: Vec<PatchObservation>,
    /// The settings used.
    pub settings: ObservationSettings,
    /// Pixels meeting a patch but dropped for being near a face edge.
    pub edge_pixels: usize,
}

impl Observations {
    /// Whether patch `p` counts as seen under the settings.
    pub fn is_seen(&self, p: usize) -> bool {
        let o = &self.patches[p];
        o.seen_fraction >= self.settings.min_seen_fraction && o.pixels >= self.settings.min_pixels
    }
}

/// Assigns the probe's pixels to patches. `probe` is the lat-long radiance the depth map was made
/// for (same size); invalid radiance is an error (`ibl-io` clamps it when reading).
pub fn observe(
    room: &Room,
    depth: &ProbeDepthMap,
    probe: &Image<Rgb>,
    settings: &ObservationSettings,
) -> Result<Observations, RoomError> {
    let (w, h) = (depth.width(), depth.height());
    if probe.width() != w || probe.height() != h {
        return Err(RoomError::Parameter(format!(
            "the probe is {} x {} but the depth map {w} x {h}",
            probe.width(),
            probe.height()
        )));
    }
    if let Some(k) = probe.pixels().iter().position(|l| !l.is_valid_radiance()) {
        return Err(RoomError::Parameter(format!(
            "probe pixel ({}, {}) holds an invalid radiance",
            k % w,
            k / w
        )));
    }
    if !(0.0..=1.0).contains(&settings.min_seen_fraction) {
        return Err(RoomError::Parameter(format!(
            "min_seen_fraction {} is not in [0, 1]",
            settings.min_seen_fraction
        )));
    }
    let latlong = LatLong::new(w, h);
    let solid_angles = latlong.row_solid_angles();
    let margin = settings.edge_margin_px as i64;
    let n = room.patches.len();
    let mut sums = vec![Rgb64::ZERO; n];
    let mut clean_area = vec![0.0f64; n];
    let mut seen_area = vec![0.0f64; n];
    let mut pixels = vec![0u32; n];
    let mut edge_pixels = 0usize;
    let world_from_probe = room.world_from_probe.as_dmat3();
    for (j, &solid_angle) in solid_angles.iter().enumerate() {
        for i in 0..w {
            let s = depth.sample(i, j);
            if s.patch == NO_PATCH {
                continue;
            }
            let p = s.patch as usize;
            let d = world_from_probe * latlong.pixel_dir64(i, j);
            let cos = (-d.dot(room.patches[p].normal.as_dvec3())).max(0.05);
            let area = solid_angle * f64::from(s.distance_m).powi(2) / cos;
            seen_area[p] += area;
            let clean = (-margin..=margin).all(|dj| {
                let jj = (j as i64 + dj).clamp(0, h as i64 - 1) as usize;
                (-margin..=margin).all(|di| {
                    let ii = (i as i64 + di).rem_euclid(w as i64) as usize;
                    depth.sample(ii, jj).face == s.face
                })
            });
            if clean {
                sums[p].add_weighted(*probe.get(i, j), area);
                clean_area[p] += area;
                pixels[p] += 1;
            } else {
                edge_pixels += 1;
            }
        }
    }
    let patches = (0..n)
        .map(|p| {
            let radiance = if clean_area[p] > 0.0 {
                let m = sums[p].to_array().map(|c| (c / clean_area[p]) as f32);
                Rgb::from_array(m)
            } else {
                Rgb::ZERO
            };
            PatchObservation {
                radiance,
                pixels: pixels[p],
                seen_fraction: (seen_area[p] / f64::from(room.patches[p].area_m2)).min(1.0) as f32,
            }
        })
        .collect();
    Ok(Observations {
        patches,
        settings: *settings,
        edge_pixels,
    })
}

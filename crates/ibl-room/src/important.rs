//! The important light patches (Grosch 2005, section 3.3): the `N` patches of highest luminous
//! flux `phi = B A`, "like in progressive refinement radiosity" (Cohen et al. 1988), as area
//! lights; everything else is the "unimportant" light (section 4.1 keeps it in an irradiance
//! volume, the important patches get shadows).
//!
//! Flux is ranked by luminance (`0.2126 R + 0.7152 G + 0.0722 B` of `B`, times the area), over
//! every patch: light sources and lit surfaces alike (a sunlit floor patch can outshine a lamp).
//! Ties go to the lower patch index, so the selection is deterministic. An area patch light
//! radiates Lambertian radiance `L = B / pi` from its front side: a receiver at distance `d`
//! gets `dE = L A cos(t_light) cos(t_receiver) / d^2` from it while `d` is large against the
//! patch. (The shared `ibl-light` crate of issue 14 will carry this type; it stays small here
//! until then.)

use glam::Vec3;
use ibl_core::Rgb;
use serde::Serialize;

use crate::Room;
use crate::reflectance::Estimate;

/// A patch as an area light (Grosch's important light), world frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AreaPatchLight {
    /// The room's patch index.
    pub patch: u32,
    /// Centroid, metres.
    pub position: [f32; 3],
    /// Unit front normal (the side it radiates to).
    pub normal: [f32; 3],
    /// Area, m^2.
    pub area_m2: f32,
    /// Lambertian radiance `B / pi`, probe units.
    pub radiance: [f32; 3],
    /// Corners in order around the patch (3 or 4), metres: for soft shadows.
    pub corners: Vec<[f32; 3]>,
}

impl AreaPatchLight {
    /// Flux `phi = B A = pi L A` per channel.
    pub fn flux(&self) -> Rgb {
        Rgb::from_array(self.radiance) * (std::f32::consts::PI * self.area_m2)
    }
}

/// The split of the room's light into important patches and the rest.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImportantLights {
    /// The important patches, largest luminous flux first.
    pub important: Vec<AreaPatchLight>,
    /// Indices of the other patches (the unimportant light), in room order.
    pub unimportant: Vec<u32>,
    /// Fraction of the room's total luminous flux the important patches carry.
    pub important_flux_fraction: f64,
}

/// The `n` patches of highest luminous flux under the estimate's radiosity.
pub fn important_patches(room: &Room, estimate: &Estimate, n: usize) -> ImportantLights {
    let flux: Vec<f64> = room
        .patches
        .iter()
        .zip(&estimate.patches)
        .map(|(p, e)| f64::from(e.radiosity.luminance()) * f64::from(p.area_m2))
        .collect();
    let mut order: Vec<usize> = (0..flux.len()).collect();
    order.sort_by(|&a, &b| flux[b].total_cmp(&flux[a]).then(a.cmp(&b)));
    let chosen: Vec<usize> = order.iter().copied().take(n).collect();
    let total: f64 = flux.iter().sum();
    let important_flux: f64 = chosen.iter().map(|&p| flux[p]).sum();
    let mut is_important = vec![false; flux.len()];
    for &p in &chosen {
        is_important[p] = true;
    }
    let important = chosen
        .iter()
        .map(|&p| {
            let patch = &room.patches[p];
            AreaPatchLight {
                patch: p as u32,
                position: patch.centroid.to_array(),
                normal: patch.normal.to_array(),
                area_m2: patch.area_m2,
                radiance: (estimate.patches[p].radiosity / std::f32::consts::PI).to_array(),
                corners: patch
                    .shape
                    .corners()
                    .iter()
                    .map(|c: &Vec3| c.to_array())
                    .collect(),
            }
        })
        .collect();
    ImportantLights {
        important,
        unimportant: (0..flux.len() as u32)
            .filter(|&p| !is_important[p as usize])
            .collect(),
        important_flux_fraction: if total > 0.0 {
            important_flux / total
        } else {
            0.0
        },
    }
}

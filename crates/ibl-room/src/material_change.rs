//! Material changes (Grosch 2005, section 4.3): the user sets a surface group's diffuse
//! reflectance from `rho` to `rho'`.
//!
//! 1. **The direct change** (EQ6, `L' = rho' E / pi = (rho' / rho) L`): every patch of the group
//!    has its radiosity scaled by `rho'_c / rho_c` per channel (the group's estimated `rho`), so
//!    the probe's texture on it keeps its detail. A channel whose `rho_c` is 0 has no ratio; there
//!    the patch takes `rho'_c E`.
//! 2. **Colour bleeding by delta radiosity** ("we calculate delta radiosities `dB = B' - B` for
//!    all patches with a changed material and send them to all other patches"): the change
//!    `dB_0` of step 1 is shot through the form factors, `dE = F dB_0`, and reflected, `dB_1 =
//!    rho dE`; one bounce by default (the paper's "good results in most cases"), `k` on request,
//!    `dB_(j+1) = rho F dB_j`. The result is `B' = B + dB_0 + ... + dB_k`.
//!
//! **Why it converges to the changed room's radiosity.** With the estimate's radiosity `B = e +
//! rho F B` (light patches held, `rho` 0 for them), the changed room's `B'' = e + rho' F B''`
//! differs by `D = B'' - B = (rho' - rho) F B + rho' F D = (rho' - rho) E + rho' F D`: the series
//! `D = sum_j (rho' F)^j dB_0` with `dB_0 = (rho' - rho) E` (step 1 on seen patches, where `rho E
//! = B`). So `k` bounces are the first `k + 1` terms of the solution the forward solve
//! ([`crate::radiosity`]) finds for the new reflectances; the remaining error shrinks like
//! `max(rho')^k`.
//!
//! **Reflectances.** Each surface patch reflects with its own estimated reflectance (`B / E` for
//! seen patches, the group's for hidden ones: the estimate's model of the room), clamped to
//! [0, 1]; a changed patch with `rho_p (rho' / rho)` per channel (or `rho'` where `rho_c` is 0).
//! Light patches (windows, lamps) reflect nothing and keep their radiosity.
//!
//! **Shooting as a gather.** Sending `dB_s` from patch `s` to patch `r` deposits `dE_r = F_rs
//! dB_s` (reciprocity, `A_s F_sr = A_r F_rs`); summing it over each receiver's own row of the
//! form-factor matrix uses the same numbers as the forward solve and the estimate (ray-cast form
//! factors are reciprocal only on average) and runs rows in parallel, deterministically. Cost per
//! bounce: one pass over the stored form factors (1.4 M entries for the worked example room: 0.78
//! ms for the whole one-bounce update on 2 cores, `benches/material_change.rs`).
//!
//! **Display.** A pixel of the probe showing patch `p` is scaled by `B'_p / B_p` per channel
//! ([`MaterialEdit::radiance_scale`], the paper's float texture of `rho' / rho` generalised to
//! the bleeding), or given `B'_p / pi` where `B_p` is 0 ([`MaterialEdit::pixel_radiance`],
//! [`MaterialEdit::panorama`]). Radiosity in the probe's radiance units times pi.

use ibl_core::{Image, Rgb};
use rayon::prelude::*;

use crate::depth_map::ProbeDepthMap;
use crate::description::GroupKind;
use crate::form_factors::FormFactors;
use crate::reflectance::Estimate;
use crate::{Room, RoomError};

/// One group's new reflectance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialChange {
    /// The surface group's index in the room.
    pub group: usize,
    /// Its new diffuse reflectance per channel, in [0, 1].
    pub reflectance: Rgb,
}

/// Most bounces of colour bleeding accepted.
pub const MAX_BOUNCES: u32 = 10_000;

/// The room after material changes.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialEdit {
    /// Per patch, the reflectance the bleeding used (changed patches: the new one).
    pub reflectance: Vec<Rgb>,
    /// Per patch, the estimate's radiosity before the change.
    pub before: Vec<Rgb>,
    /// Per patch, the radiosity after the direct change alone (EQ6, no bleeding).
    pub direct: Vec<Rgb>,
    /// Per patch, the radiosity after the direct change and the bounces of bleeding.
    pub radiosity: Vec<Rgb>,
    /// Per patch and channel, `B' / B` (1 where `B` is 0): the factor on the probe's pixels.
    pub radiance_scale: Vec<Rgb>,
    /// Bounces of bleeding made.
    pub bounces: u32,
    /// The last bounce's largest change of any patch's radiosity in any channel, relative to the
    /// largest new radiosity: what another bounce would still add, roughly.
    pub last_bounce_relative: f32,
}

/// Applies `changes` to the room of `estimate` (its radiosity, irradiance and reflectances)
/// with `bounces` bounces of colour bleeding through `form_factors`. Errors: a group that is not
/// a surface or appears twice, a reflectance outside [0, 1], sizes that do not match.
pub fn change_materials(
    room: &Room,
    estimate: &Estimate,
    form_factors: &FormFactors,
    changes: &[MaterialChange],
    bounces: u32,
) -> Result<MaterialEdit, RoomError> {
    let n = room.patches.len();
    if estimate.patches.len() != n || form_factors.len() != n {
        return Err(RoomError::Parameter(format!(
            "an estimate of {} patches and {} form-factor rows for a room of {n}",
            estimate.patches.len(),
            form_factors.len()
        )));
    }
    if bounces > MAX_BOUNCES {
        return Err(RoomError::Parameter(format!(
            "{bounces} bounces of colour bleeding (at most {MAX_BOUNCES})"
        )));
    }
    // Per group: (old group reflectance, new reflectance) for the changed ones.
    let mut changed: Vec<Option<(Rgb, Rgb)>> = vec![None; room.groups.len()];
    for (k, c) in changes.iter().enumerate() {
        let field = format!("changes[{k}]");
        let group = room
            .groups
            .get(c.group)
            .ok_or_else(|| RoomError::invalid(&field, format!("no group {}", c.group)))?;
        if group.kind != GroupKind::Surface {
            return Err(RoomError::invalid(
                &field,
                format!("group `{}` is a light and has no reflectance", group.name),
            ));
        }
        if !c
            .reflectance
            .to_array()
            .iter()
            .all(|v| (0.0..=1.0).contains(v))
        {
            return Err(RoomError::invalid(
                &field,
                format!("reflectance {:?} is not in [0, 1]", c.reflectance),
            ));
        }
        if changed[c.group].is_some() {
            return Err(RoomError::invalid(
                &field,
                format!("group `{}` is changed twice", group.name),
            ));
        }
        let old = estimate.groups[c.group]
            .reflectance
            .map(Rgb::from_array)
            .unwrap_or(Rgb::ZERO);
        changed[c.group] = Some((old, c.reflectance));
    }
    let mut reflectance = Vec::with_capacity(n);
    let mut delta = Vec::with_capacity(n);
    for (patch, pe) in room.patches.iter().zip(&estimate.patches) {
        let own = if room.groups[patch.group as usize].kind == GroupKind::Light {
            Rgb::ZERO
        } else {
            pe.reflectance.map(|v| v.clamp(0.0, 1.0))
        };
        match changed[patch.group as usize] {
            None => {
                reflectance.push(own);
                delta.push(Rgb::ZERO);
            }
            Some((old, new)) => {
                let (mut rho, mut d) = ([0.0f32; 3], [0.0f32; 3]);
                for c in 0..3 {
                    (rho[c], d[c]) = if old[c] > 0.0 {
                        // EQ6: B' = (rho' / rho) B.
                        let ratio = new[c] / old[c];
                        (
                            (own[c] * ratio).clamp(0.0, 1.0),
                            (ratio - 1.0) * pe.radiosity[c],
                        )
                    } else {
                        (new[c], new[c] * pe.irradiance[c] - pe.radiosity[c])
                    };
                }
                reflectance.push(Rgb::from_array(rho));
                delta.push(Rgb::from_array(d));
            }
        }
    }
    let direct: Vec<Rgb> = estimate
        .patches
        .iter()
        .zip(&delta)
        .map(|(pe, &d)| pe.radiosity + d)
        .collect();
    let mut radiosity = direct.clone();
    let mut last_change = delta.iter().map(|d| max_abs(*d)).fold(0.0f32, f32::max);
    for _ in 0..bounces {
        // dB_(j+1) = rho F dB_j (the shot as a gather over each receiver's row).
        delta = form_factors
            .gather(&delta)
            .into_par_iter()
            .zip(reflectance.par_iter())
            .map(|(e, &rho)| rho * e)
            .collect();
        last_change = 0.0;
        for (b, d) in radiosity.iter_mut().zip(&delta) {
            *b += *d;
            last_change = last_change.max(max_abs(*d));
        }
    }
    let scale = radiosity
        .iter()
        .map(|b| b.max_channel())
        .fold(0.0f32, f32::max);
    let before: Vec<Rgb> = estimate.patches.iter().map(|pe| pe.radiosity).collect();
    let radiance_scale = before
        .iter()
        .zip(&radiosity)
        .map(|(old, new)| {
            Rgb::from_array(std::array::from_fn(|c| {
                if old[c] > 0.0 { new[c] / old[c] } else { 1.0 }
            }))
        })
        .collect();
    Ok(MaterialEdit {
        reflectance,
        before,
        direct,
        radiosity,
        radiance_scale,
        bounces,
        last_bounce_relative: if scale > 0.0 {
            last_change / scale
        } else {
            0.0
        },
    })
}

fn max_abs(v: Rgb) -> f32 {
    v.map(f32::abs).max_channel()
}

impl MaterialEdit {
    /// The new radiance of a probe pixel that showed `observed` on patch `patch`: scaled by
    /// `B' / B` per channel where the old radiosity was positive, else `B' / pi`.
    pub fn pixel_radiance(&self, patch: usize, observed: Rgb) -> Rgb {
        let (old, new, scale) = (
            self.before[patch],
            self.radiosity[patch],
            self.radiance_scale[patch],
        );
        Rgb::from_array(std::array::from_fn(|c| {
            if old[c] > 0.0 {
                observed[c] * scale[c]
            } else {
                new[c] / std::f32::consts::PI
            }
        }))
    }

    /// The probe re-rendered after the edit: every pixel whose depth-map patch is known is given
    /// [`Self::pixel_radiance`]; the others (the model's gaps) keep the probe's radiance. `probe`
    /// and `depth` are the same size (the probe the estimate was made from and its depth map).
    pub fn panorama(
        &self,
        depth: &ProbeDepthMap,
        probe: &Image<Rgb>,
    ) -> Result<Image<Rgb>, RoomError> {
        if probe.width() != depth.width() || probe.height() != depth.height() {
            return Err(RoomError::Parameter(format!(
                "the probe is {} x {} but the depth map {} x {}",
                probe.width(),
                probe.height(),
                depth.width(),
                depth.height()
            )));
        }
        Ok(Image::from_fn_par(probe.width(), probe.height(), |i, j| {
            let observed = *probe.get(i, j);
            // `depth_map::NO_PATCH` (a gap) is never a patch index.
            match depth.sample(i, j).patch as usize {
                p if p < self.radiosity.len() => self.pixel_radiance(p, observed),
                _ => observed,
            }
        }))
    }
}

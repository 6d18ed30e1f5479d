//! The radiosity equation on a room's patches, solved forward (Goral et al. 1984; Grosch 2005,
//! EQ1 and EQ2): `B_e = E_emit,e + rho_e sum_s F_es B_s` per channel, for the patches whose
//! radiosity is unknown, with the others held at known values.
//!
//! Jacobi iteration: every sweep gathers `E = F B` from the previous sweep's radiosity (rows in
//! parallel, each summed in order, so the result does not depend on the thread count) and
//! updates the unknowns; only the unknowns' rows are gathered until the last sweep. With reflectances below 1 and form-factor rows summing to at most 1 the
//! error shrinks at least by the largest reflectance per sweep. It stops when no unknown changed
//! by more than `tolerance` times the largest radiosity. Used for the furnace check (closed room,
//! uniform emission: `B = E / (1 - rho)`), for the hidden patches of the reflectance estimate
//! (section 3.2, step 4) and, later, for delta radiosity after material changes (section 4.3).

use ibl_core::Rgb;
use rayon::prelude::*;

use crate::RoomError;
use crate::form_factors::FormFactors;

/// What is known of one patch's radiosity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PatchRadiosity {
    /// Held at this radiosity (seen by the probe, or a light source).
    Known(Rgb),
    /// `B = emission + reflectance * E`, to be solved for.
    Unknown {
        /// Emitted radiosity, same units as `B`.
        emission: Rgb,
        /// Diffuse reflectance per channel, in [0, 1].
        reflectance: Rgb,
    },
}

/// A solved radiosity system.
#[derive(Clone, Debug, PartialEq)]
pub struct RadiositySolution {
    /// Radiosity per patch.
    pub radiosity: Vec<Rgb>,
    /// Irradiance per patch gathered from `radiosity` (`E = F B`).
    pub irradiance: Vec<Rgb>,
    /// Jacobi sweeps made.
    pub sweeps: u32,
    /// Largest change of an unknown in the last sweep, relative to the largest radiosity.
    pub last_change: f32,
}

/// Solves the system from `initial` radiosity (one per patch; known patches take their value).
pub fn solve_radiosity(
    form_factors: &FormFactors,
    patches: &[PatchRadiosity],
    initial: &[Rgb],
    tolerance: f32,
    max_sweeps: u32,
) -> Result<RadiositySolution, RoomError> {
    let n = form_factors.len();
    if patches.len() != n || initial.len() != n {
        return Err(RoomError::Parameter(format!(
            "{} patch states and {} initial values for {n} form-factor rows",
            patches.len(),
            initial.len()
        )));
    }
    if !(tolerance > 0.0 && tolerance.is_finite()) || max_sweeps == 0 {
        return Err(RoomError::Parameter(
            "the radiosity tolerance must be positive and at least one sweep allowed".into(),
        ));
    }
    let mut b: Vec<Rgb> = patches
        .iter()
        .zip(initial)
        .map(|(p, &b0)| match *p {
            PatchRadiosity::Known(k) => k,
            PatchRadiosity::Unknown { .. } => b0,
        })
        .collect();
    // Only the unknowns' rows are gathered per sweep (hidden patches are a small part of a room).
    let unknown: Vec<usize> = (0..n)
        .filter(|&k| matches!(patches[k], PatchRadiosity::Unknown { .. }))
        .collect();
    let scale_known = b
        .iter()
        .zip(patches)
        .filter(|(_, p)| matches!(p, PatchRadiosity::Known(_)))
        .map(|(v, _)| v.max_channel())
        .fold(0.0f32, f32::max);
    let mut sweeps = 0;
    let mut last_change = 0.0f32;
    while sweeps < max_sweeps && !unknown.is_empty() {
        sweeps += 1;
        let gathered: Vec<Rgb> = unknown
            .par_iter()
            .map(|&k| form_factors.gather_one(k, &b))
            .collect();
        let mut change = 0.0f32;
        let mut scale = scale_known;
        for (&k, e) in unknown.iter().zip(gathered) {
            if let PatchRadiosity::Unknown {
                emission,
                reflectance,
            } = patches[k]
            {
                let new = emission + reflectance * e;
                change = change.max((new - b[k]).map(f32::abs).max_channel());
                b[k] = new;
            }
            scale = scale.max(b[k].max_channel());
        }
        last_change = if scale > 0.0 { change / scale } else { 0.0 };
        if last_change <= tolerance {
            break;
        }
    }
    let e = form_factors.gather(&b);
    Ok(RadiositySolution {
        radiosity: b,
        irradiance: e,
        sweeps,
        last_change,
    })
}

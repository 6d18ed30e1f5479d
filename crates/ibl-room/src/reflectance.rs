//! Reflectance estimation from the probe (Grosch 2005, section 3.2): `rho = B / E` (EQ1) with
//! `B = pi L` from the probe and `E_e = sum_s B_s F_es` (EQ2, EQ3), per channel, averaged per
//! material group, with the hidden-region iteration:
//!
//! 1. reflectance estimates `rho_e = B_e / E_e` for every patch the probe sees;
//! 2. one average per material group;
//! 3. the averages copied to every hidden patch (not seen by the probe);
//! 4. the hidden patches' irradiance from EQ2 and their radiosity estimate `B = rho E`
//!    (radiance `L = rho E / pi`);
//! 5. back to 1 until no group's reflectance changes by more than the tolerance in any channel.
//!
//! In the first pass the hidden patches are dark (`B = 0`): they are what the probe cannot show,
//! so the seen patches' irradiance is underestimated and their reflectance overestimated, as in
//! the paper's Table 1 (wall 0.98 in the first iteration, 0.91 in the second). Step 4 can be
//! taken literally, one gather per pass ([`HiddenRadiosity::Gathered`]), or solved to convergence
//! among the hidden patches with the seen ones held ([`HiddenRadiosity::Solved`], the default):
//! light bouncing between hidden patches (under a table, behind a cupboard) then counts in full
//! at once, so the outer loop only has to settle the group averages (measured on the synthetic
//! room of `docs/ROOMS.md`: three passes instead of five or more).
//!
//! Light-source groups (windows, lamps) keep the radiosity the probe shows; a light patch the
//! probe does not see takes its group's area-weighted mean. A surface group no patch of which is
//! seen takes the area-weighted mean reflectance of the groups that were estimated (and is
//! reported as not estimated). Reflectances are reported as computed (a value above 1 says the
//! model misses light); they are clamped to [0, 1] only where they make hidden radiosity.

use ibl_core::Rgb;
use serde::Serialize;

use crate::description::GroupKind;
use crate::form_factors::FormFactors;
use crate::observation::Observations;
use crate::radiosity::{PatchRadiosity, solve_radiosity};
use crate::{Room, RoomError};

/// How step 4 fills the hidden patches.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HiddenRadiosity {
    /// One gather per pass, `B_h = rho_g E_h` (the paper read literally).
    Gathered,
    /// The hidden patches' radiosity equation solved with the seen ones held.
    #[default]
    Solved,
}

/// How a group's reflectance is averaged over its seen patches (step 2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GroupAverage {
    /// The mean of the seen patches' `B / E`, each counting once (the paper).
    PatchMean,
    /// The ratio `sum_p w_p B_p / sum_p w_p E_p` over the seen patches, `w_p` the area the probe
    /// sees of each: noise in a patch's `E` (form-factor sampling) averages out before the
    /// division instead of biasing every `B / E` upwards (`1 / E` is convex: measured +1 % on
    /// the synthetic room with 900 rays per patch).
    #[default]
    SeenAreaRatio,
}

/// Settings of the estimate.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EstimationSettings {
    /// Converged when no group's reflectance changes by more than this in any channel.
    pub tolerance: f32,
    /// Passes of steps 1 to 4 at most.
    pub max_iterations: u32,
    /// How step 4 works.
    pub hidden: HiddenRadiosity,
    /// How step 2 averages.
    pub average: GroupAverage,
}

impl Default for EstimationSettings {
    fn default() -> Self {
        EstimationSettings {
            tolerance: 0.002,
            max_iterations: 10,
            hidden: HiddenRadiosity::Solved,
            average: GroupAverage::SeenAreaRatio,
        }
    }
}

/// The role of a patch in the estimate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PatchRole {
    /// A surface the probe sees: `rho = B / E` with `B` from the probe.
    Seen,
    /// A surface the probe does not see: `rho` from its group, `B = rho E`.
    Hidden,
    /// A light source: `B` from the probe.
    Light,
}

/// The estimate of one patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchEstimate {
    /// Its role.
    pub role: PatchRole,
    /// Radiosity `B`, probe radiance units times pi (W m^-2 in relative units).
    pub radiosity: Rgb,
    /// Irradiance `E = sum_s B_s F_es`, same units.
    pub irradiance: Rgb,
    /// Reflectance: `B / E` for seen patches, the group's for hidden ones, zero for lights.
    pub reflectance: Rgb,
    /// Fraction of its area the probe sees.
    pub seen_fraction: f32,
}

/// The estimate of one material group.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GroupEstimate {
    /// Name.
    pub name: String,
    /// Surface or light.
    pub kind: GroupKind,
    /// Patches in the group.
    pub patches: usize,
    /// Patches the probe sees (lights: seen light patches).
    pub seen_patches: usize,
    /// Total area, m^2.
    pub area_m2: f32,
    /// Fraction of the group's area the probe sees.
    pub seen_area_fraction: f32,
    /// Final reflectance (surfaces), linear RGB.
    pub reflectance: Option<[f32; 3]>,
    /// Whether the reflectance comes from the group's own seen patches (else the mean of the
    /// estimated groups).
    pub estimated: bool,
    /// Area-weighted mean radiosity, linear RGB.
    pub mean_radiosity: [f32; 3],
    /// Reflectance measured by other means, when the description gives one.
    pub measured_reflectance: Option<[f32; 3]>,
}

/// One pass of steps 1 and 2.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IterationRecord {
    /// Per group (room order): the reflectance after this pass (`None` for lights).
    pub reflectance: Vec<Option<[f32; 3]>>,
    /// Largest change of any group's reflectance in any channel since the previous pass
    /// (infinite for the first).
    pub max_change: f32,
}

/// The whole estimate.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// Per patch, room order.
    pub patches: Vec<PatchEstimate>,
    /// Per group, room order.
    pub groups: Vec<GroupEstimate>,
    /// Every pass, in order.
    pub iterations: Vec<IterationRecord>,
    /// Whether the last pass changed every reflectance by less than the tolerance.
    pub converged: bool,
    /// The settings used.
    pub settings: EstimationSettings,
}

/// Relative tolerance of the hidden-radiosity solve of [`HiddenRadiosity::Solved`].
const HIDDEN_SOLVE_TOLERANCE: f32 = 1e-5;
/// Jacobi sweeps allowed for it (reflectances up to 0.95 reach 1e-5 in about 225).
const HIDDEN_SOLVE_SWEEPS: u32 = 500;

/// Runs steps 1 to 5 on `room` with what the probe shows (`observations`) and the form factors.
pub fn estimate_reflectance(
    room: &Room,
    observations: &Observations,
    form_factors: &FormFactors,
    settings: &EstimationSettings,
) -> Result<Estimate, RoomError> {
    let n = room.patches.len();
    if observations.patches.len() != n || form_factors.len() != n {
        return Err(RoomError::Parameter(format!(
            "{} observations and {} form-factor rows for {n} patches",
            observations.patches.len(),
            form_factors.len()
        )));
    }
    if !(settings.tolerance > 0.0 && settings.tolerance.is_finite()) || settings.max_iterations == 0
    {
        return Err(RoomError::Parameter(
            "the tolerance must be positive and at least one iteration allowed".into(),
        ));
    }
    let groups = room.groups.len();
    let role: Vec<PatchRole> = (0..n)
        .map(|p| {
            let g = room.patches[p].group as usize;
            match (room.groups[g].kind, observations.is_seen(p)) {
                (GroupKind::Light, _) => PatchRole::Light,
                (GroupKind::Surface, true) => PatchRole::Seen,
                (GroupKind::Surface, false) => PatchRole::Hidden,
            }
        })
        .collect();
    // Radiosity: seen surfaces and seen lights from the probe, unseen lights from their group.
    let mut b: Vec<Rgb> = (0..n)
        .map(|p| match role[p] {
            PatchRole::Seen => observations.patches[p].radiosity(),
            PatchRole::Light if observations.is_seen(p) => observations.patches[p].radiosity(),
            _ => Rgb::ZERO,
        })
        .collect();
    for g in 0..groups {
        if room.groups[g].kind != GroupKind::Light {
            continue;
        }
        let members: Vec<usize> = (0..n)
            .filter(|&p| room.patches[p].group as usize == g)
            .collect();
        let seen: Vec<usize> = members
            .iter()
            .copied()
            .filter(|&p| observations.is_seen(p))
            .collect();
        if seen.is_empty() {
            if members.is_empty() {
                continue;
            }
            return Err(RoomError::Unobservable(format!(
                "light group `{}`: the probe sees none of its {} patches, so its radiosity is unknown",
                room.groups[g].name,
                members.len()
            )));
        }
        let mean = area_mean(room, &seen, |p| b[p], |_| 1.0);
        for &p in &members {
            if !observations.is_seen(p) {
                b[p] = mean;
            }
        }
    }
    let mut iterations: Vec<IterationRecord> = Vec::new();
    let mut group_rho: Vec<Option<Rgb>> = vec![None; groups];
    let mut estimated = vec![false; groups];
    let mut converged = false;
    let mut e = form_factors.gather(&b);
    for pass in 0..settings.max_iterations {
        // Steps 1 and 2.
        let (rho, own) = group_reflectances(room, observations, &role, &b, &e, settings.average)?;
        let change = if pass == 0 {
            f32::INFINITY
        } else {
            (0..groups)
                .filter_map(|g| match (rho[g], group_rho[g]) {
                    (Some(a), Some(p)) => Some((a - p).map(f32::abs).max_channel()),
                    _ => None,
                })
                .fold(0.0f32, f32::max)
        };
        iterations.push(IterationRecord {
            reflectance: rho.iter().map(|r| r.map(Rgb::to_array)).collect(),
            max_change: change,
        });
        group_rho = rho;
        estimated = own;
        if change < settings.tolerance {
            converged = true;
            break;
        }
        if pass + 1 == settings.max_iterations {
            break;
        }
        // Steps 3 and 4.
        let clamped = |p: usize| {
            group_rho[room.patches[p].group as usize]
                .unwrap_or(Rgb::ZERO)
                .map(|c| c.clamp(0.0, 1.0))
        };
        match settings.hidden {
            HiddenRadiosity::Gathered => {
                for p in 0..n {
                    if role[p] == PatchRole::Hidden {
                        b[p] = clamped(p) * e[p];
                    }
                }
                e = form_factors.gather(&b);
            }
            HiddenRadiosity::Solved => {
                let system: Vec<PatchRadiosity> = (0..n)
                    .map(|p| match role[p] {
                        PatchRole::Hidden => PatchRadiosity::Unknown {
                            emission: Rgb::ZERO,
                            reflectance: clamped(p),
                        },
                        _ => PatchRadiosity::Known(b[p]),
                    })
                    .collect();
                let solution = solve_radiosity(
                    form_factors,
                    &system,
                    &b,
                    HIDDEN_SOLVE_TOLERANCE,
                    HIDDEN_SOLVE_SWEEPS,
                )?;
                b = solution.radiosity;
                e = solution.irradiance;
            }
        }
    }
    let patches: Vec<PatchEstimate> = (0..n)
        .map(|p| {
            let g = room.patches[p].group as usize;
            let reflectance = match role[p] {
                PatchRole::Seen => ratio(b[p], e[p]).unwrap_or(Rgb::ZERO),
                PatchRole::Hidden => group_rho[g].unwrap_or(Rgb::ZERO),
                PatchRole::Light => Rgb::ZERO,
            };
            PatchEstimate {
                role: role[p],
                radiosity: b[p],
                irradiance: e[p],
                reflectance,
                seen_fraction: observations.patches[p].seen_fraction,
            }
        })
        .collect();
    let group_estimates = (0..groups)
        .map(|g| {
            let members: Vec<usize> = (0..n)
                .filter(|&p| room.patches[p].group as usize == g)
                .collect();
            let area: f32 = members.iter().map(|&p| room.patches[p].area_m2).sum();
            let seen_area: f32 = members
                .iter()
                .map(|&p| room.patches[p].area_m2 * observations.patches[p].seen_fraction)
                .sum();
            GroupEstimate {
                name: room.groups[g].name.clone(),
                kind: room.groups[g].kind,
                patches: members.len(),
                seen_patches: members.iter().filter(|&&p| observations.is_seen(p)).count(),
                area_m2: area,
                seen_area_fraction: if area > 0.0 { seen_area / area } else { 0.0 },
                reflectance: group_rho[g].map(Rgb::to_array),
                estimated: estimated[g],
                mean_radiosity: area_mean(room, &members, |p| b[p], |_| 1.0).to_array(),
                measured_reflectance: room.groups[g].measured_reflectance.map(Rgb::to_array),
            }
        })
        .collect();
    Ok(Estimate {
        patches,
        groups: group_estimates,
        iterations,
        converged,
        settings: *settings,
    })
}

/// `b / e` per channel, or `None` where the irradiance vanishes in a channel.
fn ratio(b: Rgb, e: Rgb) -> Option<Rgb> {
    if e.r > 0.0 && e.g > 0.0 && e.b > 0.0 {
        Some(Rgb::new(b.r / e.r, b.g / e.g, b.b / e.b))
    } else {
        None
    }
}

/// Area-weighted mean of `value` over `patches`, each weighted also by `weight`.
fn area_mean(
    room: &Room,
    patches: &[usize],
    value: impl Fn(usize) -> Rgb,
    weight: impl Fn(usize) -> f32,
) -> Rgb {
    let mut sum = [0.0f64; 3];
    let mut total = 0.0f64;
    for &p in patches {
        let w = f64::from(room.patches[p].area_m2 * weight(p));
        let v = value(p);
        sum[0] += w * f64::from(v.r);
        sum[1] += w * f64::from(v.g);
        sum[2] += w * f64::from(v.b);
        total += w;
    }
    if total > 0.0 {
        Rgb::new(
            (sum[0] / total) as f32,
            (sum[1] / total) as f32,
            (sum[2] / total) as f32,
        )
    } else {
        Rgb::ZERO
    }
}

/// Steps 1 and 2: per group, the average of `B / E` over its seen patches, and whether it had
/// any; groups without take the area-weighted mean of the estimated ones.
fn group_reflectances(
    room: &Room,
    observations: &Observations,
    role: &[PatchRole],
    b: &[Rgb],
    e: &[Rgb],
    average: GroupAverage,
) -> Result<(Vec<Option<Rgb>>, Vec<bool>), RoomError> {
    let groups = room.groups.len();
    // Per group: numerator and denominator sums per channel, and the total weight.
    let mut top = vec![[0.0f64; 3]; groups];
    let mut bottom = vec![[0.0f64; 3]; groups];
    let mut weight = vec![0.0f64; groups];
    for p in 0..role.len() {
        if role[p] != PatchRole::Seen {
            continue;
        }
        let Some(rho) = ratio(b[p], e[p]) else {
            continue;
        };
        let g = room.patches[p].group as usize;
        match average {
            GroupAverage::PatchMean => {
                for (c, r) in rho.to_array().iter().enumerate() {
                    top[g][c] += f64::from(*r);
                    bottom[g][c] += 1.0;
                }
                weight[g] += 1.0;
            }
            GroupAverage::SeenAreaRatio => {
                let w = f64::from(room.patches[p].area_m2 * observations.patches[p].seen_fraction);
                for c in 0..3 {
                    top[g][c] += w * f64::from(b[p][c]);
                    bottom[g][c] += w * f64::from(e[p][c]);
                }
                weight[g] += w;
            }
        }
    }
    let own: Vec<bool> = (0..groups)
        .map(|g| room.groups[g].kind == GroupKind::Surface && weight[g] > 0.0)
        .collect();
    let mut rho: Vec<Option<Rgb>> = (0..groups)
        .map(|g| {
            own[g].then(|| {
                Rgb::new(
                    (top[g][0] / bottom[g][0]) as f32,
                    (top[g][1] / bottom[g][1]) as f32,
                    (top[g][2] / bottom[g][2]) as f32,
                )
            })
        })
        .collect();
    let area = |g: usize| -> f32 {
        room.patches
            .iter()
            .filter(|p| p.group as usize == g)
            .map(|p| p.area_m2)
            .sum()
    };
    let (mut fallback, mut total) = ([0.0f64; 3], 0.0f64);
    for g in (0..groups).filter(|&g| own[g]) {
        let a = f64::from(area(g));
        let r = rho[g].unwrap_or(Rgb::ZERO);
        fallback[0] += a * f64::from(r.r);
        fallback[1] += a * f64::from(r.g);
        fallback[2] += a * f64::from(r.b);
        total += a;
    }
    let surfaces_without =
        (0..groups).any(|g| room.groups[g].kind == GroupKind::Surface && !own[g]);
    if surfaces_without {
        if total <= 0.0 {
            return Err(RoomError::Unobservable(
                "the probe sees no surface patch with irradiance: no reflectance can be estimated"
                    .into(),
            ));
        }
        let f = Rgb::new(
            (fallback[0] / total) as f32,
            (fallback[1] / total) as f32,
            (fallback[2] / total) as f32,
        );
        for g in 0..groups {
            if room.groups[g].kind == GroupKind::Surface && !own[g] {
                rho[g] = Some(f);
            }
        }
    }
    Ok((rho, own))
}

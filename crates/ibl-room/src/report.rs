//! The reflectance report, per group and iteration like Grosch 2005's Table 1: as JSON (for
//! scripts) and Markdown (for people), returned as strings; the front ends write them.
//!
//! Per group: kind, patches seen of all, the seen share of its area, the reflectance (R G B)
//! after every pass of steps 1 to 4, the final value and, where the room gives one, the measured
//! reflectance and the largest per-channel difference from it. Then the form-factor and
//! observation figures that tell whether the model is closed and the probe fits it, and the
//! important patches when they were selected.

use serde::Serialize;

use crate::analysis::RoomAnalysis;
use crate::important::ImportantLights;
use crate::reflectance::{EstimationSettings, GroupEstimate, PatchRole};
use crate::{Room, RoomError};

/// The report's format tag.
pub const REPORT_FORMAT: &str = "iblkit.room-report/1";

/// Form-factor figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FormFactorSummary {
    /// Rays cast per patch.
    pub rays_per_patch: u32,
    /// Stored non-zero form factors.
    pub entries: usize,
    /// Mean of `sum_s F_es` over the patches (1 in a closed room).
    pub mean_row_sum: f64,
    /// Smallest row sum.
    pub min_row_sum: f64,
    /// Mean fraction of rays that met nothing (an open model).
    pub mean_escaped: f64,
    /// Mean fraction of rays that met a back side (a gap in the model).
    pub mean_back: f64,
}

/// How the probe fitted the model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ObservationSummary {
    /// Probe size, pixels.
    pub probe_size: [usize; 2],
    /// Surface patches the probe sees.
    pub seen_patches: usize,
    /// Surface patches it does not see.
    pub hidden_patches: usize,
    /// Light-source patches.
    pub light_patches: usize,
    /// Pixels dropped for lying near a face edge.
    pub edge_pixels: usize,
    /// Pixels whose ray met a back side.
    pub back_pixels: usize,
    /// Pixels whose ray met nothing.
    pub empty_pixels: usize,
}

/// The whole report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RoomReport {
    /// [`REPORT_FORMAT`].
    pub format: String,
    /// Patches in the room.
    pub patches: usize,
    /// Largest patch area, m^2.
    pub patch_area_m2: f32,
    /// Per group.
    pub groups: Vec<GroupEstimate>,
    /// Group names in the order of the iterations' values.
    pub iteration_groups: Vec<String>,
    /// Per pass, per group: the reflectance after the pass (`None` for lights).
    pub iterations: Vec<Vec<Option<[f32; 3]>>>,
    /// Per pass: the largest change since the previous one (`None` for the first).
    pub iteration_changes: Vec<Option<f32>>,
    /// Whether the iteration converged.
    pub converged: bool,
    /// Estimation settings.
    pub settings: EstimationSettings,
    /// Form factors.
    pub form_factors: FormFactorSummary,
    /// Observation.
    pub observation: ObservationSummary,
    /// The important light patches, when selected.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub important: Option<ImportantLights>,
}

impl RoomReport {
    /// The report of an analysis (and of its important patches, if any).
    pub fn new(
        room: &Room,
        analysis: &RoomAnalysis,
        important: Option<&ImportantLights>,
    ) -> RoomReport {
        let ff = &analysis.form_factors;
        let n = ff.len().max(1) as f64;
        let sums: Vec<f64> = (0..ff.len()).map(|e| f64::from(ff.row_sum(e))).collect();
        let estimate = &analysis.estimate;
        let count = |r: PatchRole| estimate.patches.iter().filter(|p| p.role == r).count();
        RoomReport {
            format: REPORT_FORMAT.into(),
            patches: room.patches.len(),
            patch_area_m2: room.patch_area_m2,
            groups: estimate.groups.clone(),
            iteration_groups: room.groups.iter().map(|g| g.name.clone()).collect(),
            iterations: estimate
                .iterations
                .iter()
                .map(|i| i.reflectance.clone())
                .collect(),
            iteration_changes: estimate
                .iterations
                .iter()
                .map(|i| i.max_change.is_finite().then_some(i.max_change))
                .collect(),
            converged: estimate.converged,
            settings: estimate.settings,
            form_factors: FormFactorSummary {
                rays_per_patch: ff.rays_per_patch,
                entries: ff.entries(),
                mean_row_sum: sums.iter().sum::<f64>() / n,
                min_row_sum: sums.iter().copied().fold(f64::INFINITY, f64::min),
                mean_escaped: ff.escaped.iter().map(|&v| f64::from(v)).sum::<f64>() / n,
                mean_back: ff.back.iter().map(|&v| f64::from(v)).sum::<f64>() / n,
            },
            observation: ObservationSummary {
                probe_size: [analysis.depth.width(), analysis.depth.height()],
                seen_patches: count(PatchRole::Seen),
                hidden_patches: count(PatchRole::Hidden),
                light_patches: count(PatchRole::Light),
                edge_pixels: analysis.observations.edge_pixels,
                back_pixels: analysis.depth.back_pixels,
                empty_pixels: analysis.depth.empty_pixels,
            },
            important: important.cloned(),
        }
    }

    /// The report as pretty-printed JSON.
    pub fn to_json(&self) -> Result<String, RoomError> {
        serde_json::to_string_pretty(self)
            .map(|s| s + "\n")
            .map_err(|e| RoomError::Numerical(format!("writing JSON: {e}")))
    }

    /// The report as Markdown: Table 1 (reflectance per group and iteration), then the figures.
    pub fn to_markdown(&self) -> String {
        let rgb = |v: [f32; 3]| format!("{:.3} {:.3} {:.3}", v[0], v[1], v[2]);
        let mut md = String::new();
        md.push_str("| group | kind | seen patches | seen area |");
        for k in 1..=self.iterations.len() {
            md.push_str(&format!(" iteration {k} |"));
        }
        md.push_str(" final | measured | max error |\n|---|---|---|---|");
        md.push_str(&"---|".repeat(self.iterations.len() + 3));
        md.push('\n');
        for (g, group) in self.groups.iter().enumerate() {
            md.push_str(&format!(
                "| {} | {} | {} / {} | {:.0} % |",
                group.name,
                group.kind.name(),
                group.seen_patches,
                group.patches,
                100.0 * group.seen_area_fraction
            ));
            for it in &self.iterations {
                match it.get(g).copied().flatten() {
                    Some(v) => md.push_str(&format!(" {} |", rgb(v))),
                    None => md.push_str(" - |"),
                }
            }
            let fin = match group.reflectance {
                Some(v) if group.estimated => rgb(v),
                Some(v) => format!("{} (not seen)", rgb(v)),
                None => format!("B = {}", rgb(group.mean_radiosity)),
            };
            let (measured, error) = match (group.measured_reflectance, group.reflectance) {
                (Some(m), Some(r)) => (
                    rgb(m),
                    format!(
                        "{:.3}",
                        (0..3).map(|c| (r[c] - m[c]).abs()).fold(0.0f32, f32::max)
                    ),
                ),
                (Some(m), None) => (rgb(m), "-".into()),
                _ => ("-".into(), "-".into()),
            };
            md.push_str(&format!(" {fin} | {measured} | {error} |\n"));
        }
        let changes: Vec<String> = self
            .iteration_changes
            .iter()
            .map(|c| c.map_or("-".into(), |c| format!("{c:.4}")))
            .collect();
        md.push_str(&format!(
            "\n{} after {} iterations (tolerance {}; largest change per iteration: {}).\n",
            if self.converged {
                "Converged"
            } else {
                "Not converged"
            },
            self.iterations.len(),
            self.settings.tolerance,
            changes.join(", ")
        ));
        let f = &self.form_factors;
        let o = &self.observation;
        md.push_str(&format!(
            "\n{} patches of at most {} m^2; {} seen, {} hidden, {} light. Form factors: {} rays \
             per patch, {} entries, row sums {:.4} on average (smallest {:.4}), {:.2} % of rays \
             escaped, {:.2} % met a back side. Probe {} x {}: {} pixels dropped at face edges, \
             {} saw a back side, {} saw nothing.\n",
            self.patches,
            self.patch_area_m2,
            o.seen_patches,
            o.hidden_patches,
            o.light_patches,
            f.rays_per_patch,
            f.entries,
            f.mean_row_sum,
            f.min_row_sum,
            100.0 * f.mean_escaped,
            100.0 * f.mean_back,
            o.probe_size[0],
            o.probe_size[1],
            o.edge_pixels,
            o.back_pixels,
            o.empty_pixels
        ));
        if let Some(imp) = &self.important {
            md.push_str(&format!(
                "\n{} important patches carry {:.1} % of the luminous flux:\n\n| patch | position (m) | area (m^2) | radiance |\n|---|---|---|---|\n",
                imp.important.len(),
                100.0 * imp.important_flux_fraction
            ));
            for l in &imp.important {
                md.push_str(&format!(
                    "| {} | {:.2} {:.2} {:.2} | {:.3} | {} |\n",
                    l.patch,
                    l.position[0],
                    l.position[1],
                    l.position[2],
                    l.area_m2,
                    rgb(l.radiance)
                ));
            }
        }
        md
    }
}

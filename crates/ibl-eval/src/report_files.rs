//! The files of a report folder as `report.json` lists them (paths relative to it): the report
//! in three forms, the plots and the figures. A leaf module, so that the sweep (which carries the
//! list in its [`crate::Report`]) and the report text do not import each other.

use serde::{Deserialize, Serialize};

/// One error-vs-N plot, as SVG and PNG (paths relative to `report.json`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlotFiles {
    /// The probe plotted, or `None` for the average over probes.
    pub probe: Option<String>,
    /// The SVG file.
    pub svg: String,
    /// The PNG file.
    pub png: String,
}

/// The figures of one method at one N on one probe (paths relative to `report.json`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FigureFiles {
    /// Probe name.
    pub probe: String,
    /// Method name.
    pub method: String,
    /// Light count.
    pub n: usize,
    /// Irradiance spheres: ground truth, approximation and error map (Figure 4 of the paper).
    pub sphere: Option<String>,
    /// The lights drawn over the probe.
    pub overlay: Option<String>,
}

/// Every file of a report, relative to the folder of `report.json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ReportFiles {
    /// `report.json`.
    pub json: String,
    /// `report.csv`.
    pub csv: String,
    /// `report.md`.
    pub markdown: String,
    /// Error-vs-N plots: the average first, then one per probe.
    pub plots: Vec<PlotFiles>,
    /// Spheres and overlays at the figure N.
    pub figures: Vec<FigureFiles>,
}

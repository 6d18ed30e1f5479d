//! Evaluation of lighting approximations against the exact irradiance of a probe (CONVENTIONS
//! sections 4 and 5, after Madsen & Laursen 2006, section 5).
//!
//! * [`ground_truth`]: the exact irradiance `E(n) = sum_p L_p max(0, n . d_p) dOmega_p` of a
//!   lat-long probe on a set of normals (normally 20000 Fibonacci normals), plus a fast,
//!   energy-conserving approximation of it for interactive use;
//! * the error of an approximation against that ground truth (`mean_err%`, `max_err%`, and the
//!   per-normal relative `rel_mean%`, `rel_max%`) is `ibl_metrics::irradiance_error`'s;
//! * [`mod@sweep`]: the comparison of section 5: every extraction method at every light count N on
//!   every probe, timed and scored, as the serde data of `report.json` (`iblkit.eval/1`);
//! * [`report`]: that report as CSV and as a markdown summary (lights needed for 1 % and 5 %);
//! * [`plot`]: error-vs-N charts (the paper's Figure 6) as SVG and RGB images;
//! * [`sphere_image`]: irradiance spheres and error maps (the paper's Figure 4);
//! * [`overlay`]: light sets drawn over their probe;
//! * [`colour_scale`]: the viridis scale and error maps in false colour (the image metrics
//!   themselves, RMSE, relative MSE and FLIP, are `ibl-metrics`');
//! * [`report_files`]: the files of a report folder as the report lists them;
//! * [`mod@render_study`]: light sets judged by their renders against the path-traced reference;
//! * [`response_plot`]: camera response curves as charts.
//!
//! Nothing here reads or writes files: outputs are strings and 8-bit images in memory.
//!
//! Sums are f64 (the FLIP map is f32 per pixel) and everything is deterministic: results are
//! bit-identical whatever the rayon thread count.

pub mod colour_scale;
pub mod ground_truth;
pub mod overlay;
pub mod plot;
pub mod render_study;
pub mod report;
pub mod report_files;
pub mod response_plot;
pub mod sphere_image;
pub mod sweep;

pub use colour_scale::{MASKED_OUT_COLOUR, false_colour, viridis};
pub use ground_truth::{
    Emitters, FAST_DEFAULT_SIZE, GroundTruth, irradiance_brute_force, irradiance_fast,
};
pub use ibl_core::{RowIrradiance, channel_means, irradiance_exact};
pub use plot::{ErrorChart, PLOT_SIZE, PlotError, render_png, render_svg};
pub use render_study::{
    RenderStudy, RenderStudyImages, RenderStudyRow, RenderStudySettings, StudyError, render_study,
};
pub use report::LightsNeeded;
pub use report_files::{FigureFiles, PlotFiles, ReportFiles};
pub use sphere_image::{SphereField, SphereFigure};
pub use sweep::{
    FastPathRow, ProbeInput, REPORT_FORMAT, Report, Row, Status, Sweep, SweepOptions,
    SweepProgress, fast_paths, sweep,
};

//! Sections a front end adds to the demo page. The pipeline sits below every front end and cannot
//! reach the GPU crate, so the viewer's headless frames (issue 15) arrive through this trait: the
//! `ibl` command passes the viewer's implementation to [`crate::demo::demo`], which calls it after
//! the renders and puts what it returns on `index.html` and into `summary.json`.

use std::path::Path;

use serde::Serialize;

use crate::progress::Progress;

/// One section of the demo page made by a front end.
#[derive(Clone, Debug, Serialize)]
pub struct PageSection {
    /// The HTML anchor (`index.html#id`).
    pub id: String,
    /// The heading.
    pub title: String,
    /// The body, HTML; paths relative to the demo's output folder.
    pub html: String,
    /// The same as data, for `summary.json`.
    pub data: serde_json::Value,
}

/// A front end's part of the demo. It never fails the demo: what it could not make (no GPU
/// adapter, say) it reports in its section.
pub trait DemoSection {
    /// Makes the section from the demo's scene files in `scenes` and its outdoor sequence
    /// `outdoor` (a scene with an `[outdoor]` table, when the demo runs one), writing its files
    /// under the demo's output folder `out`.
    fn section(
        &self,
        scenes: &Path,
        outdoor: Option<&Path>,
        out: &Path,
        progress: &dyn Progress,
    ) -> PageSection;
}

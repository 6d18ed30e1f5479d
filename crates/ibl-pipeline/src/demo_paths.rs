//! Where the demo's outputs go inside its folder, and how pages link to them: the sub-folders of
//! the comparison and the renders, and paths relative to the folder. A leaf module shared by the
//! demo's jobs and its page.

use std::path::Path;

/// Sub-folder of the comparison report.
pub const EVAL_DIR: &str = "eval";

/// Sub-folder of the renders.
pub const RENDER_DIR: &str = "renders";

/// Sub-folder of the reconstructed room.
pub const ROOM_DIR: &str = "room";

/// Sub-folder of the outdoor sequence.
pub const OUTDOOR_DIR: &str = "outdoor";

/// `p` relative to `base` (for links in `index.html`).
pub fn relative(base: &Path, p: &Path) -> String {
    p.strip_prefix(base).unwrap_or(p).display().to_string()
}

//! Progress bars (indicatif) for work that can take over a second. Bars draw on stderr and hide
//! themselves when stderr is not a terminal, so scripts and `--json` output stay clean.

use indicatif::{ProgressBar, ProgressStyle};

/// A bar counting `total` steps of a task called `label`, with time left.
pub fn bar(label: &str, total: u64) -> ProgressBar {
    let bar = ProgressBar::new(total);
    if let Ok(style) =
        ProgressStyle::with_template("{msg:>24} [{bar:32}] {pos}/{len} {elapsed_precise} eta {eta}")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(label.to_string());
    bar
}

/// A callback `(done, total)` for library functions that report rows finished, updating `bar`.
pub fn rows_callback(bar: &ProgressBar) -> impl Fn(usize, usize) + Sync + '_ {
    move |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    }
}

//! The command line's [`Progress`]: indicatif bars (or spinners for tasks of unknown length) on
//! stderr for work that can take over a second, hidden when stderr is not a terminal so scripts
//! and `--json` output stay clean; notes go to stderr above any bar.

use std::sync::Mutex;
use std::time::Duration;

use ibl_pipeline::Progress;
use indicatif::{ProgressBar, ProgressStyle};

/// Bars for the tasks a job reports, one at a time.
#[derive(Default)]
pub struct Bars {
    current: Mutex<Option<ProgressBar>>,
}

/// A bar counting `total` steps of a task called `label`, with time left.
fn bar(label: &str, total: u64) -> ProgressBar {
    let bar = ProgressBar::new(total);
    if let Ok(style) =
        ProgressStyle::with_template("{msg:>24} [{bar:32}] {pos}/{len} {elapsed_precise} eta {eta}")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(label.to_string());
    bar
}

impl Bars {
    fn with(&self, f: impl FnOnce(&ProgressBar)) {
        if let Ok(current) = self.current.lock()
            && let Some(bar) = current.as_ref()
        {
            f(bar);
        }
    }
}

impl Progress for Bars {
    fn begin(&self, label: &str, total: u64) {
        let new = if total == 0 {
            let spinner = ProgressBar::new_spinner();
            spinner.set_message(label.to_string());
            spinner.enable_steady_tick(Duration::from_millis(120));
            spinner
        } else {
            bar(label, total)
        };
        if let Ok(mut current) = self.current.lock()
            && let Some(old) = current.replace(new)
        {
            old.finish_and_clear();
        }
    }

    fn update(&self, done: u64, total: u64, detail: Option<&str>) {
        self.with(|bar| {
            bar.set_length(total);
            bar.set_position(done);
            if let Some(detail) = detail {
                bar.set_message(detail.to_string());
            }
        });
    }

    fn end(&self) {
        if let Ok(mut current) = self.current.lock()
            && let Some(bar) = current.take()
        {
            bar.finish_and_clear();
        }
    }

    fn note(&self, text: &str) {
        let mut shown = false;
        self.with(|bar| {
            bar.suspend(|| eprintln!("{text}"));
            shown = true;
        });
        if !shown {
            eprintln!("{text}");
        }
    }
}

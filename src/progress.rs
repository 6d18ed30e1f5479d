//! The command line's [`Progress`]. On a terminal: indicatif bars (or spinners for tasks of
//! unknown length) on stderr, notes printed above them. Elsewhere (a log, CI, a pipe; issue 13):
//! one plain line at most every few seconds, `stage: done/total, elapsed`, as cargo does, so a
//! long `demo`, `eval`, `render` or `capture` is never silent for minutes; a short job prints
//! nothing. `IBL_PROGRESS_SECONDS` sets the interval (0: a line on every update).

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::Duration;

use ibl_pipeline::Progress;
use ibl_pipeline::progress_lines::TimedLines;
use indicatif::{ProgressBar, ProgressStyle};

/// Default seconds between two progress lines when stderr is not a terminal.
const LINE_INTERVAL_S: f64 = 3.0;

/// Bars on a terminal, timed lines elsewhere, for the tasks a job reports, one at a time.
pub enum Bars {
    /// stderr is a terminal.
    Terminal(Mutex<Option<ProgressBar>>),
    /// stderr is a file or a pipe.
    Lines(TimedLines),
}

impl Default for Bars {
    fn default() -> Self {
        if std::io::stderr().is_terminal() {
            Bars::Terminal(Mutex::new(None))
        } else {
            let seconds = std::env::var("IBL_PROGRESS_SECONDS")
                .ok()
                .and_then(|v| v.parse::<f64>().ok())
                .filter(|v| v.is_finite() && *v >= 0.0)
                .unwrap_or(LINE_INTERVAL_S);
            Bars::Lines(TimedLines::new(Duration::from_secs_f64(seconds), |line| {
                eprintln!("{line}")
            }))
        }
    }
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
    fn with_bar(&self, f: impl FnOnce(&ProgressBar)) {
        if let Bars::Terminal(current) = self
            && let Ok(current) = current.lock()
            && let Some(bar) = current.as_ref()
        {
            f(bar);
        }
    }
}

impl Progress for Bars {
    fn begin(&self, label: &str, total: u64) {
        match self {
            Bars::Terminal(current) => {
                let new = if total == 0 {
                    let spinner = ProgressBar::new_spinner();
                    spinner.set_message(label.to_string());
                    spinner.enable_steady_tick(Duration::from_millis(120));
                    spinner
                } else {
                    bar(label, total)
                };
                if let Ok(mut current) = current.lock()
                    && let Some(old) = current.replace(new)
                {
                    old.finish_and_clear();
                }
            }
            Bars::Lines(lines) => lines.begin(label, total),
        }
    }

    fn update(&self, done: u64, total: u64, detail: Option<&str>) {
        match self {
            Bars::Terminal(_) => self.with_bar(|bar| {
                bar.set_length(total);
                bar.set_position(done);
                if let Some(detail) = detail {
                    bar.set_message(detail.to_string());
                }
            }),
            Bars::Lines(lines) => lines.update(done, total, detail),
        }
    }

    fn end(&self) {
        match self {
            Bars::Terminal(current) => {
                if let Ok(mut current) = current.lock()
                    && let Some(bar) = current.take()
                {
                    bar.finish_and_clear();
                }
            }
            Bars::Lines(lines) => lines.end(),
        }
    }

    fn note(&self, text: &str) {
        let mut shown = false;
        self.with_bar(|bar| {
            bar.suspend(|| eprintln!("{text}"));
            shown = true;
        });
        if !shown {
            eprintln!("{text}");
        }
    }
}

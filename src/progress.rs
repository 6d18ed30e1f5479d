//! The command line's [`Progress`]. On a terminal: indicatif bars (or spinners for tasks of
//! unknown length) on stderr, notes printed above them. Elsewhere (a log, CI, a pipe; issue 13):
//! one plain line at most every few seconds, `stage: done/total, elapsed`, as cargo does, so a
//! long `demo`, `eval`, `render` or `capture` is never silent for minutes; a short job prints
//! nothing. `IBL_PROGRESS_SECONDS` sets the interval (0: a line on every update).

use std::io::IsTerminal;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use ibl_pipeline::Progress;
use indicatif::{ProgressBar, ProgressStyle};

/// Default seconds between two progress lines when stderr is not a terminal.
const LINE_INTERVAL_S: f64 = 3.0;

/// Bars on a terminal, timed lines elsewhere, for the tasks a job reports, one at a time.
pub enum Bars {
    /// stderr is a terminal.
    Terminal(Mutex<Option<ProgressBar>>),
    /// stderr is a file or a pipe; a ticker thread prints for tasks that report no steps.
    Lines(Arc<Mutex<LineState>>),
}

/// The task being reported as lines.
pub struct LineState {
    label: String,
    active: bool,
    done: u64,
    total: u64,
    detail: Option<String>,
    started: Instant,
    last_line: Instant,
    interval: Duration,
    lines: usize,
}

impl LineState {
    /// Prints the progress line if the interval has passed since the last one.
    fn maybe_print(&mut self) {
        let now = Instant::now();
        if !self.active || now.duration_since(self.last_line) < self.interval {
            return;
        }
        self.last_line = now;
        self.lines += 1;
        let elapsed = now.duration_since(self.started).as_secs_f64();
        let what = self
            .detail
            .as_ref()
            .map(|d| format!(" ({d})"))
            .unwrap_or_default();
        if self.total > 0 {
            eprintln!(
                "{}: {}/{}{what}, {elapsed:.1} s",
                self.label, self.done, self.total
            );
        } else {
            eprintln!("{}: running{what}, {elapsed:.1} s", self.label);
        }
    }
}

/// Prints for tasks that go quiet (a long extraction reports no steps) until the process ends.
fn start_ticker(state: &Arc<Mutex<LineState>>, interval: Duration) {
    let state = Arc::clone(state);
    let nap = interval.clamp(Duration::from_millis(50), Duration::from_millis(500));
    std::thread::spawn(move || {
        loop {
            std::thread::sleep(nap);
            match state.lock() {
                Ok(mut s) => s.maybe_print(),
                Err(_) => return,
            }
        }
    });
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
            let now = Instant::now();
            let interval = Duration::from_secs_f64(seconds);
            let state = Arc::new(Mutex::new(LineState {
                label: String::new(),
                active: false,
                done: 0,
                total: 0,
                detail: None,
                started: now,
                last_line: now,
                interval,
                lines: 0,
            }));
            start_ticker(&state, interval);
            Bars::Lines(state)
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
            Bars::Lines(state) => {
                if let Ok(mut s) = state.lock() {
                    let now = Instant::now();
                    s.label = label.to_string();
                    s.active = true;
                    s.done = 0;
                    s.total = total;
                    s.detail = None;
                    s.started = now;
                    s.last_line = now;
                    s.lines = 0;
                }
            }
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
            Bars::Lines(state) => {
                if let Ok(mut s) = state.lock() {
                    s.done = done;
                    s.total = total;
                    if let Some(d) = detail {
                        s.detail = Some(d.to_string());
                    }
                    s.maybe_print();
                }
            }
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
            Bars::Lines(state) => {
                // A task that printed progress says when it is over.
                if let Ok(mut s) = state.lock() {
                    s.active = false;
                    if s.lines > 0 {
                        let elapsed = s.started.elapsed().as_secs_f64();
                        eprintln!("{}: done, {elapsed:.1} s", s.label);
                    }
                }
            }
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

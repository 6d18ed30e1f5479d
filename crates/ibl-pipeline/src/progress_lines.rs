//! A [`Progress`] as timed plain lines, for front ends whose output is not a terminal (a log, CI,
//! a pipe, a notebook): `stage: done/total (detail), elapsed` at most once per interval, as cargo
//! does, and `stage: done, elapsed` at the end of a task that printed, so a long job is never
//! silent for minutes while a short one prints nothing. A ticker thread covers tasks that report
//! no steps. The lines go to a sink the front end gives (the CLI: stderr); this crate never
//! prints.

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::Progress;

/// Where the lines go.
type Sink = Arc<dyn Fn(&str) + Send + Sync>;

/// The task being reported.
struct LineState {
    label: String,
    active: bool,
    done: u64,
    total: u64,
    detail: Option<String>,
    started: Instant,
    last_line: Instant,
    interval: Duration,
    lines: usize,
    sink: Sink,
}

impl LineState {
    /// Writes the progress line if the interval has passed since the last one.
    fn maybe_write(&mut self) {
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
        let line = if self.total > 0 {
            format!(
                "{}: {}/{}{what}, {elapsed:.1} s",
                self.label, self.done, self.total
            )
        } else {
            format!("{}: running{what}, {elapsed:.1} s", self.label)
        };
        (self.sink)(&line);
    }
}

/// Timed progress lines (see the module notes), one task at a time.
pub struct TimedLines {
    state: Arc<Mutex<LineState>>,
}

impl TimedLines {
    /// Lines at most every `interval` (zero: on every update), written to `sink`; starts the
    /// ticker thread, which ends with the process.
    pub fn new(interval: Duration, sink: impl Fn(&str) + Send + Sync + 'static) -> TimedLines {
        let now = Instant::now();
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
            sink: Arc::new(sink),
        }));
        let ticker = Arc::clone(&state);
        let nap = interval.clamp(Duration::from_millis(50), Duration::from_millis(500));
        std::thread::spawn(move || {
            loop {
                std::thread::sleep(nap);
                match ticker.lock() {
                    Ok(mut s) => s.maybe_write(),
                    Err(_) => return,
                }
            }
        });
        TimedLines { state }
    }
}

impl Progress for TimedLines {
    fn begin(&self, label: &str, total: u64) {
        if let Ok(mut s) = self.state.lock() {
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

    fn update(&self, done: u64, total: u64, detail: Option<&str>) {
        if let Ok(mut s) = self.state.lock() {
            s.done = done;
            s.total = total;
            if let Some(d) = detail {
                s.detail = Some(d.to_string());
            }
            s.maybe_write();
        }
    }

    fn end(&self) {
        // A task that printed progress says when it is over.
        if let Ok(mut s) = self.state.lock() {
            s.active = false;
            if s.lines > 0 {
                let line = format!(
                    "{}: done, {:.1} s",
                    s.label,
                    s.started.elapsed().as_secs_f64()
                );
                (s.sink)(&line);
            }
        }
    }

    fn note(&self, text: &str) {
        if let Ok(s) = self.state.lock() {
            (s.sink)(text);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_every_update_at_zero_interval_and_says_when_done() {
        let lines = Arc::new(Mutex::new(Vec::<String>::new()));
        let sink = Arc::clone(&lines);
        let p = TimedLines::new(Duration::ZERO, move |l| {
            sink.lock().unwrap().push(l.to_string())
        });
        p.begin("extract", 4);
        p.update(1, 4, Some("level 1"));
        p.end();
        p.note("wrote x.json");
        let lines = lines.lock().unwrap();
        assert!(
            lines[0].starts_with("extract: 1/4 (level 1), "),
            "{lines:?}"
        );
        assert!(lines.iter().any(|l| l.starts_with("extract: done, ")));
        assert_eq!(lines.last().unwrap(), "wrote x.json");
    }
}

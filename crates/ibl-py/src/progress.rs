//! Progress through a Python callable: `progress(label, done, total)` is called when a task
//! begins (`done = 0`), at most every 0.1 s while it runs, and when it ends (`done = total`);
//! notes (what `ibl` prints on stderr) go to `progress("note: ...", 0, 0)`. The callable runs
//! with the GIL taken back for the call only; an exception it raises is kept and raised when the
//! iblkit call returns (the work itself is not interrupted mid-loop).

use std::sync::Mutex;
use std::time::{Duration, Instant};

use ibl_pipeline::Progress;
use pyo3::prelude::*;

/// Updates closer together than this are dropped.
const INTERVAL: Duration = Duration::from_millis(100);

/// A [`Progress`] that calls a Python callable (or nothing, when none was given).
pub struct PyProgress {
    callable: Option<Py<PyAny>>,
    state: Mutex<State>,
}

struct State {
    label: String,
    total: u64,
    done: u64,
    last: Option<Instant>,
    error: Option<PyErr>,
}

impl PyProgress {
    /// Progress to `callable` (`None`: silent).
    pub fn new(callable: Option<Py<PyAny>>) -> PyProgress {
        PyProgress {
            callable,
            state: Mutex::new(State {
                label: String::new(),
                total: 0,
                done: 0,
                last: None,
                error: None,
            }),
        }
    }

    fn call(&self, label: &str, done: u64, total: u64) {
        let Some(callable) = &self.callable else {
            return;
        };
        let result = Python::attach(|py| callable.call1(py, (label, done, total)).map(drop));
        if let Err(e) = result
            && let Ok(mut state) = self.state.lock()
        {
            state.error.get_or_insert(e);
        }
    }

    /// The callable's first exception, if it raised one.
    pub fn finish(self) -> PyResult<()> {
        match self.state.into_inner().ok().and_then(|s| s.error) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

impl Progress for PyProgress {
    fn begin(&self, label: &str, total: u64) {
        if let Ok(mut state) = self.state.lock() {
            state.label = label.to_string();
            state.total = total;
            state.done = 0;
            state.last = Some(Instant::now());
        }
        self.call(label, 0, total);
    }

    fn update(&self, done: u64, total: u64, _detail: Option<&str>) {
        let label = match self.state.lock() {
            Ok(mut state) => {
                let due = state.last.is_none_or(|t| t.elapsed() >= INTERVAL) || done == total;
                if !due {
                    return;
                }
                state.last = Some(Instant::now());
                state.done = done;
                state.label.clone()
            }
            Err(_) => return,
        };
        self.call(&label, done, total);
    }

    fn end(&self) {
        let task = self
            .state
            .lock()
            .map(|s| (s.label.clone(), s.total, s.done));
        if let Ok((label, total, done)) = task
            && (done != total || total == 0)
        {
            self.call(&label, total, total);
        }
    }

    fn note(&self, text: &str) {
        self.call(&format!("note: {text}"), 0, 0);
    }
}

//! Progress of a job, reported to whatever the front end shows: a bar in the command line tool, a
//! widget in the viewer, a Python callable. A job calls [`Progress::begin`] for each task that
//! can take over a second, [`Progress::update`] as it goes, and [`Progress::end`], and passes
//! what the user should know on the way through [`Progress::note`]; library
//! functions that report `(done, total)` rows are fed through [`rows`].

/// Where a job reports its progress. Implementations must be cheap: updates can come once per row
/// of an image, from worker threads.
pub trait Progress: Sync {
    /// A task begins: `label` says what it is, `total` how many steps (0: unknown).
    fn begin(&self, label: &str, total: u64);
    /// `done` of `total` steps of the current task are finished; `detail`, when given, says what
    /// runs now.
    fn update(&self, done: u64, total: u64, detail: Option<&str>);
    /// The current task has ended (finished or failed).
    fn end(&self);
    /// A note the user should see (values clamped on reading, fewer lights than asked, a file
    /// written); the command line tool prints it on stderr.
    fn note(&self, text: &str);
}

/// Reports nothing (scripts, tests).
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Progress for Silent {
    fn begin(&self, _: &str, _: u64) {}
    fn update(&self, _: u64, _: u64, _: Option<&str>) {}
    fn end(&self) {}
    fn note(&self, _: &str) {}
}

/// A `(done, total)` callback for library functions that report rows or runs finished.
pub fn rows(progress: &dyn Progress) -> impl Fn(usize, usize) + Sync + '_ {
    move |done, total| progress.update(done as u64, total as u64, None)
}

/// Runs `task` as one task called `label` of unknown length, ended whether it succeeds or not.
pub fn task<T>(progress: &dyn Progress, label: &str, task: impl FnOnce() -> T) -> T {
    progress.begin(label, 0);
    let out = task();
    progress.end();
    out
}

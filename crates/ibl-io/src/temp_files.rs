//! Temporary files of atomic writes: named so they can be recognised, removed when the process
//! is interrupted, and cleaned up by a later run when a `kill -9` left them.
//!
//! - **Names.** Every temporary output is `.iblkit-tmp-<pid>-<random>` in the output's folder
//!   ([`temp_prefix`]): hidden, and carrying the id of the process writing it.
//! - **Interrupts.** While a temporary file exists its path is in a process-wide list
//!   ([`TempRegistration`]). A front end's signal handler calls [`remove_live_temp_files`] on
//!   SIGINT, SIGTERM or SIGHUP before the process ends (the `ibl` binary does), so an interrupted
//!   write leaves nothing behind. Destructors do not run when a signal ends a process, which is
//!   why the list is needed.
//! - **`kill -9`.** No handler runs. The first write into a folder in each process removes the
//!   temporary files there whose process is no longer running and which have not been modified
//!   for [`STALE_AFTER`] ([`clean_stale_in`]); a live writer in another PID namespace that shares
//!   the folder keeps its file fresh while it writes.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};
use std::time::Duration;

/// The start of every temporary file's name.
pub const TEMP_NAME_START: &str = ".iblkit-tmp-";

/// How long a temporary file of a process that no longer runs must have been left unmodified
/// before a later run removes it.
pub const STALE_AFTER: Duration = Duration::from_secs(60);

/// Paths of the temporary files this process is writing now.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Folders this process has already cleaned of stale temporary files.
static CLEANED: Mutex<Option<HashSet<PathBuf>>> = Mutex::new(None);

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A panic while holding the lock leaves the data consistent (pushes and removals only).
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The name prefix of this process's temporary files: `.iblkit-tmp-<pid>-`.
pub fn temp_prefix() -> String {
    format!("{TEMP_NAME_START}{}-", std::process::id())
}

/// A temporary file's place in the process-wide list: registered when made, removed from the
/// list when dropped (after the file was renamed into place or deleted).
#[derive(Debug)]
pub struct TempRegistration(PathBuf);

impl TempRegistration {
    /// Lists `path` as a temporary file of this process until the registration is dropped.
    pub fn new(path: &Path) -> TempRegistration {
        lock(&LIVE).push(path.to_path_buf());
        TempRegistration(path.to_path_buf())
    }
}

impl Drop for TempRegistration {
    fn drop(&mut self) {
        let mut live = lock(&LIVE);
        if let Some(i) = live.iter().position(|p| *p == self.0) {
            live.swap_remove(i);
        }
    }
}

/// Removes every temporary file this process is writing now; for a signal handler that is about
/// to end the process. Returns how many were removed.
pub fn remove_live_temp_files() -> usize {
    let live = lock(&LIVE);
    live.iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count()
}

/// Removes, once per folder and process, the temporary files in `dir` left by processes that no
/// longer run (see the module note). Returns how many were removed; errors are ignored (cleaning
/// is a courtesy, never a reason to fail a write).
pub fn clean_stale_in(dir: &Path) -> usize {
    let key = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
    if !lock(&CLEANED).get_or_insert_with(HashSet::new).insert(key) {
        return 0;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .filter_map(Result::ok)
        .filter(|e| is_stale(&e.file_name().to_string_lossy(), e))
        .filter(|e| std::fs::remove_file(e.path()).is_ok())
        .count()
}

/// Whether a folder entry is a temporary file of a process that no longer runs, unmodified for
/// [`STALE_AFTER`].
fn is_stale(name: &str, entry: &std::fs::DirEntry) -> bool {
    let Some(pid) = writer_pid(name) else {
        return false;
    };
    if pid == std::process::id() || process_runs(pid) {
        return false;
    }
    entry
        .metadata()
        .ok()
        .filter(std::fs::Metadata::is_file)
        .and_then(|m| m.modified().ok())
        .and_then(|t| t.elapsed().ok())
        .is_some_and(|age| age >= STALE_AFTER)
}

/// The process id in a temporary file's name, `None` for any other name.
fn writer_pid(name: &str) -> Option<u32> {
    let rest = name.strip_prefix(TEMP_NAME_START)?;
    let (pid, _) = rest.split_once('-')?;
    pid.parse().ok()
}

/// Whether process `pid` runs (Linux: `/proc/<pid>` exists). Elsewhere every process is taken to
/// run, so nothing is removed.
fn process_runs(pid: u32) -> bool {
    if cfg!(target_os = "linux") && Path::new("/proc/self").exists() {
        Path::new(&format!("/proc/{pid}")).exists()
    } else {
        true
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    #[test]
    fn names_carry_the_process_id() {
        let prefix = temp_prefix();
        assert_eq!(
            writer_pid(&format!("{prefix}abc.tmp")),
            Some(std::process::id())
        );
        assert_eq!(writer_pid(".iblkit-tmp-12-x-y.mp4"), Some(12));
        assert_eq!(writer_pid(".iblkit-check-12"), None);
        assert_eq!(writer_pid("probe.exr"), None);
    }

    #[test]
    fn registered_files_are_removed_by_the_handler_and_unlisted_when_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join(format!("{}live.tmp", temp_prefix()));
        std::fs::write(&p, b"partial").unwrap();
        let reg = TempRegistration::new(&p);
        assert!(remove_live_temp_files() >= 1);
        assert!(!p.exists());
        drop(reg);
        assert!(!lock(&LIVE).contains(&p));
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn stale_files_of_dead_processes_are_cleaned_once_per_folder() {
        let dir = tempfile::tempdir().unwrap();
        // A process id above Linux's largest (2^22) never runs.
        let dead = dir
            .path()
            .join(format!("{TEMP_NAME_START}4294967000-x.tmp"));
        let mine = dir.path().join(format!("{}y.tmp", temp_prefix()));
        let other = dir.path().join("keep.exr");
        for p in [&dead, &mine, &other] {
            std::fs::write(p, b"x").unwrap();
        }
        let old = std::time::SystemTime::now() - STALE_AFTER - Duration::from_secs(5);
        for p in [&dead, &mine, &other] {
            std::fs::File::options()
                .write(true)
                .open(p)
                .unwrap()
                .set_modified(old)
                .unwrap();
        }
        assert_eq!(clean_stale_in(dir.path()), 1);
        assert!(!dead.exists() && mine.exists() && other.exists());
        // Once per folder: a second call does not look again.
        std::fs::write(&dead, b"x").unwrap();
        assert_eq!(clean_stale_in(dir.path()), 0);
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_fresh_file_of_a_dead_process_is_kept() {
        let dir = tempfile::tempdir().unwrap();
        let dead = dir
            .path()
            .join(format!("{TEMP_NAME_START}4294967001-x.tmp"));
        std::fs::write(&dead, b"x").unwrap();
        assert_eq!(clean_stale_in(dir.path()), 0);
        assert!(dead.exists());
    }
}

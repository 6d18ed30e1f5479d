//! Work off the UI thread: a worker thread that computes only the latest request.
//!
//! Light extraction, the hybrid ambient and the probe overlays take from well under a millisecond
//! (median cut) to seconds (irradiance optimisation with many lights on a large probe). The
//! window must never wait for them: a change in the UI submits a request and keeps drawing with
//! the previous result. Requests made while the worker is busy replace each other (a slider
//! dragged through twenty values computes the value it stopped at, not all twenty), and a result
//! is delivered only if no newer request was made since (so an old slow result never overwrites
//! a newer fast one).

use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What a worker shares with its thread.
struct Shared<Q> {
    /// The request not yet started, with its generation; `None` when there is none.
    pending: Mutex<Slot<Q>>,
    wake: Condvar,
}

struct Slot<Q> {
    request: Option<(u64, Q)>,
    stop: bool,
}

/// A finished job.
#[derive(Debug)]
pub struct Finished<R> {
    /// The generation of the request it answers.
    pub generation: u64,
    /// Its result.
    pub result: R,
    /// Seconds the computation took.
    pub seconds: f64,
}

/// A thread computing `compute(request)` for the latest request only.
pub struct LatestWorker<Q: Send + 'static, R: Send + 'static> {
    shared: Arc<Shared<Q>>,
    results: Receiver<Finished<R>>,
    generation: u64,
    /// Generation of the last result handed out.
    delivered: u64,
    thread: Option<JoinHandle<()>>,
}

impl<Q: Send + 'static, R: Send + 'static> LatestWorker<Q, R> {
    /// Starts the thread (named `name`) that will run `compute`.
    pub fn new(name: &str, compute: impl Fn(Q) -> R + Send + 'static) -> Self {
        let shared = Arc::new(Shared {
            pending: Mutex::new(Slot {
                request: None,
                stop: false,
            }),
            wake: Condvar::new(),
        });
        let (sender, results) = channel();
        let thread_shared = Arc::clone(&shared);
        let thread = std::thread::Builder::new()
            .name(name.to_string())
            .spawn(move || run(&thread_shared, &sender, &compute))
            .ok();
        LatestWorker {
            shared,
            results,
            generation: 0,
            delivered: 0,
            thread,
        }
    }

    /// Asks for `request`, replacing any request not yet started; returns its generation.
    pub fn submit(&mut self, request: Q) -> u64 {
        self.generation += 1;
        let mut slot = self
            .shared
            .pending
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        slot.request = Some((self.generation, request));
        self.shared.wake.notify_one();
        self.generation
    }

    /// The result of the latest request if it has arrived (older results are dropped).
    pub fn poll(&mut self) -> Option<Finished<R>> {
        let mut newest = None;
        loop {
            match self.results.try_recv() {
                Ok(done) if done.generation == self.generation => newest = Some(done),
                Ok(_) => {}
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => break,
            }
        }
        if let Some(done) = &newest {
            self.delivered = done.generation;
        }
        newest
    }

    /// Whether a submitted request has not been answered yet.
    pub fn busy(&self) -> bool {
        self.delivered < self.generation
    }

    /// Waits up to `timeout` for the result of the latest request (headless use and tests).
    pub fn wait(&mut self, timeout: Duration) -> Option<Finished<R>> {
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.results.recv_timeout(left) {
                Ok(done) if done.generation == self.generation => {
                    self.delivered = done.generation;
                    return Some(done);
                }
                Ok(_) => {}
                Err(_) => return None,
            }
        }
    }
}

impl<Q: Send + 'static, R: Send + 'static> Drop for LatestWorker<Q, R> {
    fn drop(&mut self) {
        {
            let mut slot = self
                .shared
                .pending
                .lock()
                .unwrap_or_else(PoisonError::into_inner);
            slot.stop = true;
            slot.request = None;
        }
        self.shared.wake.notify_one();
        if let Some(thread) = self.thread.take() {
            // A job in progress finishes first; the UI is closing, so waiting is fine.
            let _ = thread.join();
        }
    }
}

fn run<Q, R>(shared: &Shared<Q>, sender: &Sender<Finished<R>>, compute: &dyn Fn(Q) -> R) {
    loop {
        let (generation, request) = {
            let mut slot = shared
                .pending
                .lock()
                .unwrap_or_else(PoisonError::into_inner);
            loop {
                if slot.stop {
                    return;
                }
                if let Some(job) = slot.request.take() {
                    break job;
                }
                slot = shared
                    .wake
                    .wait(slot)
                    .unwrap_or_else(PoisonError::into_inner);
            }
        };
        let started = Instant::now();
        let result = compute(request);
        let done = Finished {
            generation,
            result,
            seconds: started.elapsed().as_secs_f64(),
        };
        if sender.send(done).is_err() {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_latest_request_is_answered() {
        let mut worker = LatestWorker::new("test", |n: u64| {
            std::thread::sleep(Duration::from_millis(20));
            n * 2
        });
        for n in 1..=10 {
            worker.submit(n);
        }
        assert!(worker.busy());
        let done = worker.wait(Duration::from_secs(10)).expect("answered");
        assert_eq!(done.result, 20);
        assert_eq!(done.generation, 10);
        assert!(!worker.busy());
        assert!(worker.poll().is_none());
    }
}

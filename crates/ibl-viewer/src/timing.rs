//! Where a frame's time goes: GPU timestamps at the start and end of each render pass (when the
//! device has timestamp queries; lavapipe and every desktop driver do), and the statistics a
//! benchmark reports (median and 95th percentile).
//!
//! A pass skipped in a frame (a shadow atlas that did not need redrawing) writes no timestamps
//! and is reported as 0 for that frame. The window reads the timestamps of a frame when they are
//! ready, without waiting; the headless path waits for each frame.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use serde::Serialize;

use crate::gpu::GpuContext;

/// The passes of a scene frame, in the order they run.
pub const SCENE_PASSES: [&str; 4] = ["real shadows", "virtual shadows", "scene", "display"];
/// The passes of a probe frame.
pub const PROBE_PASSES: [&str; 4] = ["probe", "display", "markers", "room overlay"];

/// Bytes between the resolved timestamps of two passes (wgpu resolves only to 256-byte
/// aligned offsets).
const RESOLVE_STRIDE: u64 = wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT;

/// GPU seconds of each pass of one frame (0 for a pass that did not run).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PassTimes {
    /// `(pass name, seconds)`, in pass order.
    pub passes: Vec<(String, f64)>,
}

impl PassTimes {
    /// The sum over the passes, seconds.
    pub fn total(&self) -> f64 {
        self.passes.iter().map(|(_, s)| s).sum()
    }
}

/// Timestamp queries for a fixed list of passes.
#[derive(Debug)]
pub struct PassTimer {
    names: Vec<&'static str>,
    /// One set of two timestamps (begin, end) per pass: a pass that did not run leaves its set
    /// unresolved rather than resolving queries nobody wrote.
    query_sets: Vec<wgpu::QuerySet>,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// Nanoseconds per timestamp tick.
    period_ns: f32,
    /// Which passes wrote timestamps in the frame being recorded.
    ran: Vec<bool>,
    /// Which passes ran in the frame whose timestamps are in `readback`.
    ran_read: Vec<bool>,
    /// Whether `readback` holds a frame not read yet (mapping requested).
    in_flight: bool,
    mapped: Arc<AtomicBool>,
}

impl PassTimer {
    /// A timer for `names`, or `None` when the device has no timestamp queries.
    pub fn new(gpu: &GpuContext, names: &[&'static str]) -> Option<PassTimer> {
        if !gpu.timestamps {
            return None;
        }
        let bytes = names.len() as u64 * RESOLVE_STRIDE;
        let buffer = |usage, label| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage,
                mapped_at_creation: false,
            })
        };
        Some(PassTimer {
            names: names.to_vec(),
            query_sets: names
                .iter()
                .map(|name| {
                    gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                        label: Some(name),
                        ty: wgpu::QueryType::Timestamp,
                        count: 2,
                    })
                })
                .collect(),
            resolve: buffer(
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                "timestamps",
            ),
            readback: buffer(
                wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                "timestamps read back",
            ),
            period_ns: gpu.queue.get_timestamp_period(),
            ran: vec![false; names.len()],
            ran_read: vec![false; names.len()],
            in_flight: false,
            mapped: Arc::new(AtomicBool::new(false)),
        })
    }

    /// The query set of pass `index`, marking it as run in this frame (`None` while the last
    /// frame's timestamps are being read, or for an unknown pass).
    fn mark_run(&mut self, index: usize) -> Option<&wgpu::QuerySet> {
        if self.in_flight || index >= self.names.len() {
            return None;
        }
        self.ran[index] = true;
        Some(&self.query_sets[index])
    }

    /// The timestamp writes of pass `index` (marks it as run in this frame).
    pub fn writes(&mut self, index: usize) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let query_set = self.mark_run(index)?;
        Some(wgpu::RenderPassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        })
    }

    /// The timestamp writes of pass `index` when it is recorded as two render passes: the
    /// first writes the start, the second the end (marks it as run in this frame).
    pub fn split_writes(
        &mut self,
        index: usize,
    ) -> Option<(
        wgpu::RenderPassTimestampWrites<'_>,
        wgpu::RenderPassTimestampWrites<'_>,
    )> {
        let query_set = self.mark_run(index)?;
        Some((
            wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(0),
                end_of_pass_write_index: None,
            },
            wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: None,
                end_of_pass_write_index: Some(1),
            },
        ))
    }

    /// Records the copy of this frame's timestamps for reading (call after the last pass).
    pub fn resolve(&mut self, encoder: &mut wgpu::CommandEncoder) {
        if self.in_flight {
            return;
        }
        let mut any = false;
        for (i, &ran) in self.ran.iter().enumerate() {
            if ran {
                encoder.resolve_query_set(
                    &self.query_sets[i],
                    0..2,
                    &self.resolve,
                    i as u64 * RESOLVE_STRIDE,
                );
                any = true;
            }
        }
        if any {
            encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, self.resolve.size());
        }
    }

    /// Starts mapping the timestamps of the frame just submitted.
    pub fn after_submit(&mut self) {
        if self.in_flight || !self.ran.iter().any(|&r| r) {
            return;
        }
        self.in_flight = true;
        self.ran_read = std::mem::replace(&mut self.ran, vec![false; self.names.len()]);
        self.mapped.store(false, Ordering::Release);
        let mapped = Arc::clone(&self.mapped);
        self.readback
            .map_async(wgpu::MapMode::Read, .., move |result| {
                if result.is_ok() {
                    mapped.store(true, Ordering::Release);
                }
            });
    }

    /// The pass times of the last submitted frame if they are ready; with `wait`, waits for them.
    pub fn read(&mut self, gpu: &GpuContext, wait: bool) -> Option<PassTimes> {
        if !self.in_flight {
            return None;
        }
        let poll = if wait {
            wgpu::PollType::wait_indefinitely()
        } else {
            wgpu::PollType::Poll
        };
        let _ = gpu.device.poll(poll);
        if !self.mapped.load(Ordering::Acquire) {
            return None;
        }
        let ticks: Vec<u64> = match self.readback.get_mapped_range(..) {
            Ok(view) => bytemuck::pod_collect_to_vec(&view),
            Err(_) => Vec::new(),
        };
        self.readback.unmap();
        self.in_flight = false;
        let per_pass = (RESOLVE_STRIDE / 8) as usize;
        let seconds = |i: usize| -> f64 {
            match (ticks.get(per_pass * i), ticks.get(per_pass * i + 1)) {
                (Some(&a), Some(&b)) if b >= a => (b - a) as f64 * f64::from(self.period_ns) * 1e-9,
                _ => 0.0,
            }
        };
        Some(PassTimes {
            passes: self
                .names
                .iter()
                .enumerate()
                .map(|(i, name)| {
                    let s = if self.ran_read[i] { seconds(i) } else { 0.0 };
                    (name.to_string(), s)
                })
                .collect(),
        })
    }
}

/// Median and 95th percentile of a sample (nearest rank), seconds; zeros when empty.
pub fn median_p95(values: &[f64]) -> (f64, f64) {
    if values.is_empty() {
        return (0.0, 0.0);
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let rank = |q: f64| {
        let k = (q * sorted.len() as f64).ceil() as usize;
        sorted[k.clamp(1, sorted.len()) - 1]
    };
    let n = sorted.len();
    let median = if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    };
    (median, rank(0.95))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_and_p95_by_nearest_rank() {
        let v: Vec<f64> = (1..=20).map(f64::from).collect();
        assert_eq!(median_p95(&v), (10.5, 19.0));
        assert_eq!(median_p95(&[3.0]), (3.0, 3.0));
        assert_eq!(median_p95(&[]), (0.0, 0.0));
    }
}

//! The window's sequence mode: an outdoor scene ([`crate::sequence_player`]) played live. The
//! player lives on a worker thread ([`crate::worker`]), so the window never waits for it: the
//! offline step runs there before the first frame, and while playing, each frame that is due
//! (at the chosen rate of sequence frames per second) is read, estimated (`P_d`, `P_a`) and
//! relit there while the window keeps drawing the previous one; a finished frame hands its
//! image, sun and ambient to the scene renderer. The side panel ([`crate::sequence_panel`])
//! shows the estimates, their chart over the frames played and the relit map.

use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

use eframe::egui;
use ibl_core::tonemap::{Display, to_srgb8};
use ibl_core::{Image, Rgb};

use crate::ViewerError;
use crate::gpu::GpuContext;
use crate::scene_model::SceneModel;
use crate::scene_renderer::SceneRenderer;
use crate::sequence_player::{PlayedFrame, PreparedSequence, SequencePlayer, SequenceStep};
use crate::worker::LatestWorker;

/// The player on the worker thread: before and after its offline step.
enum PlayerSlot {
    Prepared(Box<PreparedSequence>),
    Playing(Box<SequencePlayer>),
    /// The offline step failed (its error was delivered).
    Failed,
}

/// What the worker gives back for a frame.
struct WorkerFrame {
    step: SequenceStep,
    /// The relit map after the frame.
    relit: Image<Rgb>,
    /// Seconds of the offline step, when it ran for this frame.
    setup_seconds: Option<f64>,
}

/// The next frame of the player in `slot` (the offline step first, once), its sky as
/// `sky_lights` shadowed lights (0: the ambient).
fn play_next(slot: &Mutex<PlayerSlot>, sky_lights: usize) -> Result<WorkerFrame, String> {
    let mut slot = slot.lock().unwrap_or_else(PoisonError::into_inner);
    let mut setup_seconds = None;
    if let PlayerSlot::Prepared(_) = &*slot {
        let PlayerSlot::Prepared(prepared) = std::mem::replace(&mut *slot, PlayerSlot::Failed)
        else {
            unreachable!("matched above");
        };
        let player = prepared.start().map_err(|e| e.to_string())?;
        setup_seconds = Some(player.setup_seconds);
        *slot = PlayerSlot::Playing(Box::new(player));
    }
    match &mut *slot {
        PlayerSlot::Playing(player) => {
            player.sky_lights = sky_lights;
            let step = player.step().map_err(|e| e.to_string())?;
            Ok(WorkerFrame {
                step,
                relit: player.relit_map().clone(),
                setup_seconds,
            })
        }
        _ => Err("the sequence's offline step failed".into()),
    }
}

/// Most frames the chart keeps (the oldest are dropped).
pub const MAX_HISTORY: usize = 10_000;
/// Sequence frames per second while playing, unless changed in the panel.
pub const DEFAULT_RATE: f32 = 2.0;

/// A sequence being played in the window.
pub struct SequenceState {
    worker: LatestWorker<usize, Result<WorkerFrame, String>>,
    frame_count: Option<usize>,
    /// Whether frames advance by themselves.
    pub playing: bool,
    /// Sequence frames per second while playing (the frames' own interval is `[outdoor.frames]`'s).
    pub rate: f32,
    /// The frames played since the sequence was opened, oldest first (at most [`MAX_HISTORY`]).
    pub history: Vec<PlayedFrame>,
    /// One step asked for (the panel's "next frame" button).
    pub step_requested: bool,
    last_step: Option<Instant>,
    /// The relit map of the current frame, tone-mapped, not yet uploaded to egui.
    relit_pending: Option<egui::ColorImage>,
    /// The relit map as an egui texture (the panel's thumbnail).
    pub relit_texture: Option<egui::TextureHandle>,
    /// Seconds the offline step took (once it ran).
    pub setup_seconds: Option<f64>,
    /// The sky as this many shadowed lights from the next frame on (0: the ambient).
    pub sky_lights: usize,
}

impl SequenceState {
    /// Opens `model`'s sequence when its scene has an `[outdoor]` table: checked now (a bad
    /// mask, frame folder or time is the caller's error), the offline step on the worker.
    pub fn open(model: &SceneModel) -> Result<Option<SequenceState>, ViewerError> {
        if !SequencePlayer::is_sequence(&model.description) {
            return Ok(None);
        }
        let centre = model.objects_sphere().map(|(c, _)| c);
        let prepared = SequencePlayer::prepare(&model.path, centre, &[])?;
        let frame_count = prepared.frame_count();
        let slot = Mutex::new(PlayerSlot::Prepared(Box::new(prepared)));
        Ok(Some(SequenceState {
            worker: LatestWorker::new("ibl-view sequence", move |sky_lights| {
                play_next(&slot, sky_lights)
            }),
            frame_count,
            playing: true,
            rate: DEFAULT_RATE,
            history: Vec::new(),
            step_requested: false,
            last_step: None,
            relit_pending: None,
            relit_texture: None,
            setup_seconds: None,
            sky_lights: 0,
        }))
    }

    /// The frame shown now.
    pub fn current(&self) -> Option<&PlayedFrame> {
        self.history.last()
    }

    /// Frames in the sequence (`None` for a video).
    pub fn frame_count(&self) -> Option<usize> {
        self.frame_count
    }

    /// Whether the worker is making a frame (or running the offline step).
    pub fn busy(&self) -> bool {
        self.worker.busy()
    }

    /// Whether the next frame is due now: the first frame, a step asked for, or playing and a
    /// frame period since the last was asked for.
    fn due(&self, now: Instant) -> bool {
        let period = Duration::from_secs_f32(1.0 / self.rate.clamp(0.01, 1000.0));
        self.history.is_empty()
            || self.step_requested
            || (self.playing && self.last_step.is_none_or(|t| now - t >= period))
    }

    /// Asks the worker for the next frame when one is due and none is being made, and hands a
    /// finished one to `renderer`: its image as the background, its sun and ambient as the
    /// lights, its relit map as the environment when an object reflects it.
    pub fn poll(
        &mut self,
        gpu: &GpuContext,
        model: &SceneModel,
        renderer: &mut SceneRenderer,
        display: &Display,
    ) -> Result<(), ViewerError> {
        let now = Instant::now();
        if !self.worker.busy() && self.due(now) {
            self.step_requested = false;
            self.last_step = Some(now);
            self.worker.submit(self.sky_lights);
        }
        let Some(done) = self.worker.poll() else {
            return Ok(());
        };
        let frame = done.result.map_err(ViewerError::Lighting)?;
        if frame.setup_seconds.is_some() {
            self.setup_seconds = frame.setup_seconds;
        }
        let played = frame.step.show(gpu, model, renderer, &frame.relit);
        let relit = to_srgb8(&frame.relit, display);
        let rgb: Vec<u8> = relit.pixels().iter().flatten().copied().collect();
        self.relit_pending = Some(egui::ColorImage::from_rgb(
            [relit.width(), relit.height()],
            &rgb,
        ));
        if self.history.len() == MAX_HISTORY {
            self.history.remove(0);
        }
        self.history.push(played);
        Ok(())
    }

    /// Uploads the relit map's thumbnail when a new one is waiting (needs egui's context).
    pub fn upload_thumbnail(&mut self, ctx: &egui::Context) {
        if let Some(image) = self.relit_pending.take() {
            match &mut self.relit_texture {
                Some(t) => t.set(image, egui::TextureOptions::LINEAR),
                None => {
                    self.relit_texture =
                        Some(ctx.load_texture("relit map", image, egui::TextureOptions::LINEAR));
                }
            }
        }
    }
}

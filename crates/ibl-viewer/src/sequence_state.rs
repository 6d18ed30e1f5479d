//! The window's sequence mode: an outdoor scene ([`crate::sequence_player`]) played live. While
//! playing, every repaint that is due (at the chosen rate of sequence frames per second) reads
//! the next frame, estimates `P_d` and `P_a`, relights the map and hands the frame, the sun and
//! the ambient to the scene renderer; the side panel ([`crate::sequence_panel`]) shows the
//! estimates, their chart over the frames played and the relit map.

use std::time::{Duration, Instant};

use eframe::egui;
use ibl_core::tonemap::{Display, to_srgb8};

use crate::ViewerError;
use crate::gpu::GpuContext;
use crate::scene_model::SceneModel;
use crate::scene_renderer::SceneRenderer;
use crate::sequence_player::{PlayedFrame, SequencePlayer};

/// Most frames the chart keeps (the oldest are dropped).
pub const MAX_HISTORY: usize = 10_000;
/// Sequence frames per second while playing, unless changed in the panel.
pub const DEFAULT_RATE: f32 = 2.0;

/// A sequence being played in the window.
pub struct SequenceState {
    player: SequencePlayer,
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
    /// Seconds the offline step took.
    pub setup_seconds: f64,
}

impl SequenceState {
    /// Opens `model`'s sequence when its scene has an `[outdoor]` table (the offline step runs
    /// now, about a second and a half for the bundled courtyard).
    pub fn open(model: &SceneModel) -> Result<Option<SequenceState>, ViewerError> {
        if !SequencePlayer::is_sequence(&model.description) {
            return Ok(None);
        }
        let centre = model.objects_sphere().map(|(c, _)| c);
        let player = SequencePlayer::open(&model.path, centre, &[])?;
        Ok(Some(SequenceState {
            setup_seconds: player.setup_seconds,
            player,
            playing: true,
            rate: DEFAULT_RATE,
            history: Vec::new(),
            step_requested: false,
            last_step: None,
            relit_pending: None,
            relit_texture: None,
        }))
    }

    /// The frame shown now.
    pub fn current(&self) -> Option<&PlayedFrame> {
        self.history.last()
    }

    /// Frames in the sequence (`None` for a video).
    pub fn frame_count(&self) -> Option<usize> {
        self.player.frame_count
    }

    /// Whether the next frame is due now: the first frame, a step asked for, or playing and a
    /// frame period since the last.
    pub fn due(&self, now: Instant) -> bool {
        let period = Duration::from_secs_f32(1.0 / self.rate.clamp(0.01, 1000.0));
        self.history.is_empty()
            || self.step_requested
            || (self.playing && self.last_step.is_none_or(|t| now - t >= period))
    }

    /// Plays the next frame into `renderer`: its image as the background, its sun and ambient
    /// as the lights, its relit map as the environment when an object reflects it.
    pub fn advance(
        &mut self,
        gpu: &GpuContext,
        model: &SceneModel,
        renderer: &mut SceneRenderer,
        display: &Display,
    ) -> Result<(), ViewerError> {
        self.step_requested = false;
        self.last_step = Some(Instant::now());
        let step = self.player.step()?;
        renderer.set_photo(gpu, model, step.image);
        renderer.set_lighting(gpu, step.lighting);
        if model.reflects_environment() {
            renderer.set_environment(gpu, self.player.relit_map());
        }
        let relit = to_srgb8(self.player.relit_map(), display);
        let rgb: Vec<u8> = relit.pixels().iter().flatten().copied().collect();
        self.relit_pending = Some(egui::ColorImage::from_rgb(
            [relit.width(), relit.height()],
            &rgb,
        ));
        if self.history.len() == MAX_HISTORY {
            self.history.remove(0);
        }
        self.history.push(step.frame);
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

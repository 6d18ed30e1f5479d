//! The window (eframe on the viewer's own wgpu device): what is open, what the mouse and keys do
//! to it, and the frame loop. The side panel's widgets are in [`crate::panels`].
//!
//! Every frame the renderer of what is open draws into its own textures (the headless path's
//! code), and egui shows the tone-mapped texture. The lights and overlays are computed by
//! [`crate::worker`] threads; a frame never waits for them. Errors (a file that cannot be read,
//! lights that cannot be made) are shown in the window and the previous content stays; nothing
//! the user can do panics the viewer.
//!
//! Mouse: left-drag turns the camera (orbit about the target; the probe viewer looks around), or
//! moves the virtual object it started on along the ground; Shift turns that object, Ctrl scales
//! it; a click selects (or, on empty space, deselects); right- or middle-drag pans; the wheel
//! zooms (field of view in the probe viewer, distance in the scene viewer). Keys: 1-6 look along
//! +X -X +Y -Y +Z -Z (probe), F frames the selection, F11 full screen, F12 saves the frame as EXR
//! and PNG, Ctrl+S saves the scene, Esc deselects. Files dropped onto the window are opened.
//!
//! Room tools (probe, the side panel's "Room" section, [`crate::room_marking`]): M switches
//! marking lines on and off; while on, a left-drag draws a line (right-drag turns the view), X, Y
//! and Z choose the axis of the next line and Backspace removes the last one. Keys are ignored
//! while a text field has the focus.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

use eframe::egui;
use eframe::egui_wgpu;
use ibl_mapping::Mapping;

use crate::ViewerError;
use crate::gpu::GpuContext;
use crate::panels;
use crate::view_job::ProbeExtras;
use crate::view_state::{Content, PointerInput, ViewEvent};

/// How the window starts.
#[derive(Clone, Debug, PartialEq)]
pub struct WindowOptions {
    /// A probe or scene file to open.
    pub input: Option<PathBuf>,
    /// The mapping of a probe file (guessed when `None`).
    pub mapping: Option<Mapping>,
    /// Inner size of the window, logical points.
    pub size: (u32, u32),
    /// Save a screenshot of the whole window here once it has drawn, then close.
    pub screenshot: Option<PathBuf>,
    /// Shadow map side per light, texels.
    pub shadow_tile: u32,
    /// The camera and the room overlays of the probe opened first (`--yaw`, `--marks`, ...).
    pub probe: ProbeExtras,
}

/// Opens the window and runs it until it is closed.
pub fn run(options: WindowOptions) -> Result<(), ViewerError> {
    let gpu = GpuContext::headless()?;
    let (w, h) = options.size;
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("ibl view")
            .with_inner_size([w as f32 + panels::SIDE_PANEL_WIDTH, h as f32 + 28.0])
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        wgpu_options: egui_wgpu::WgpuConfiguration {
            wgpu_setup: egui_wgpu::WgpuSetup::Existing(egui_wgpu::WgpuSetupExisting {
                instance: gpu.instance.clone(),
                adapter: gpu.adapter.clone(),
                device: gpu.device.clone(),
                queue: gpu.queue.clone(),
            }),
            ..Default::default()
        },
        ..Default::default()
    };
    let outcome = std::sync::Arc::new(std::sync::Mutex::new(None::<String>));
    let app_outcome = std::sync::Arc::clone(&outcome);
    eframe::run_native(
        "ibl view",
        native,
        Box::new(move |_cc| Ok(Box::new(ViewerApp::new(gpu, options, app_outcome)))),
    )
    .map_err(|e| ViewerError::Window(e.to_string()))?;
    let failure = outcome
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .take();
    match failure {
        Some(message) => Err(ViewerError::Window(message)),
        None => Ok(()),
    }
}

/// A screenshot being taken for `--screenshot`.
struct Screenshot {
    path: PathBuf,
    started: Instant,
    requested: bool,
    receiver: Option<Receiver<std::sync::Arc<egui::ColorImage>>>,
}

/// Longest wait for `--screenshot` (lights and first frames), seconds.
const SCREENSHOT_TIMEOUT: Duration = Duration::from_secs(120);

/// The viewer application.
pub struct ViewerApp {
    gpu: GpuContext,
    /// What is open.
    pub content: Content,
    /// The last error, shown until the next successful action.
    pub error: Option<String>,
    /// The last message (saved files).
    pub message: Option<String>,
    texture: Option<(egui::TextureId, (u32, u32))>,
    screenshot: Option<Screenshot>,
    outcome: std::sync::Arc<std::sync::Mutex<Option<String>>>,
    frame_times: std::collections::VecDeque<f64>,
    last_frame: Option<Instant>,
    mapping: Option<Mapping>,
    /// Shadow map side per light, texels.
    pub shadow_tile: u32,
    frames_drawn: u64,
}

impl ViewerApp {
    /// An application on `gpu` (the device eframe draws with too).
    pub fn new(
        gpu: GpuContext,
        options: WindowOptions,
        outcome: std::sync::Arc<std::sync::Mutex<Option<String>>>,
    ) -> ViewerApp {
        let mut app = ViewerApp {
            gpu,
            content: Content::Empty,
            error: None,
            message: None,
            texture: None,
            screenshot: options.screenshot.map(|path| Screenshot {
                path,
                started: Instant::now(),
                requested: false,
                receiver: None,
            }),
            outcome,
            frame_times: std::collections::VecDeque::new(),
            last_frame: None,
            mapping: options.mapping,
            shadow_tile: options.shadow_tile,
            frames_drawn: 0,
        };
        if let Some(input) = options.input {
            app.open_with(&input, &options.probe);
        }
        app
    }

    /// Opens a probe or scene file; on failure the error is shown and the content kept.
    pub fn open(&mut self, path: &Path) {
        self.open_with(path, &ProbeExtras::default());
    }

    /// [`ViewerApp::open`] with a probe's camera and room overlays.
    pub fn open_with(&mut self, path: &Path, extras: &ProbeExtras) {
        let opened = Content::open(
            &self.gpu,
            path,
            self.mapping,
            (640, 480),
            self.shadow_tile,
            extras,
        );
        let opened = opened.and_then(|c| self.gpu.take_errors().map(|()| c));
        match opened {
            Ok(content) => {
                self.content = content;
                self.error = None;
                self.message = Some(format!("opened {}", path.display()));
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// The adapter, one line.
    pub fn adapter_line(&self) -> String {
        self.gpu.summary.line()
    }

    /// Rewrites the GPU materials after an edit in the panel.
    pub fn materials_changed(&self) {
        if let Content::Scene(s) = &self.content {
            s.materials_changed(&self.gpu);
        }
    }

    /// Frames per second over the last second of frames.
    pub fn fps(&self) -> f64 {
        let total: f64 = self.frame_times.iter().sum();
        if total > 0.0 {
            self.frame_times.len() as f64 / total
        } else {
            0.0
        }
    }

    fn tick(&mut self) {
        let now = Instant::now();
        if let Some(last) = self.last_frame {
            self.frame_times.push_back((now - last).as_secs_f64());
            while self.frame_times.iter().sum::<f64>() > 1.0 && self.frame_times.len() > 2 {
                self.frame_times.pop_front();
            }
        }
        self.last_frame = Some(now);
    }

    fn keys(&mut self, ctx: &egui::Context) {
        let typing = ctx.text_edit_focused();
        let (fullscreen, save_frame, save_scene, events) = ctx.input(|i| {
            let mut events = Vec::new();
            for (key, event) in [
                (egui::Key::X, ViewEvent::MarkAxis(ibl_room::Axis::X)),
                (egui::Key::Y, ViewEvent::MarkAxis(ibl_room::Axis::Y)),
                (egui::Key::Z, ViewEvent::MarkAxis(ibl_room::Axis::Z)),
                (egui::Key::M, ViewEvent::ToggleMarking),
                (egui::Key::Backspace, ViewEvent::DeleteLastLine),
                (egui::Key::Num1, ViewEvent::Axis(0)),
                (egui::Key::Num2, ViewEvent::Axis(1)),
                (egui::Key::Num3, ViewEvent::Axis(2)),
                (egui::Key::Num4, ViewEvent::Axis(3)),
                (egui::Key::Num5, ViewEvent::Axis(4)),
                (egui::Key::Num6, ViewEvent::Axis(5)),
                (egui::Key::F, ViewEvent::Frame),
                (egui::Key::Escape, ViewEvent::Deselect),
            ] {
                if !typing && i.key_pressed(key) && !i.modifiers.any() {
                    events.push(event);
                }
            }
            (
                i.key_pressed(egui::Key::F11),
                i.key_pressed(egui::Key::F12),
                i.modifiers.command && i.key_pressed(egui::Key::S),
                events,
            )
        });
        if fullscreen {
            let now = ctx.input(|i| i.viewport().fullscreen.unwrap_or(false));
            ctx.send_viewport_cmd(egui::ViewportCommand::Fullscreen(!now));
        }
        for event in events {
            self.content.handle(event);
        }
        if save_frame {
            self.save_frame();
        }
        if save_scene {
            self.save_scene(None);
        }
    }

    /// Saves the current frame as `<stem>-frame-<n>.exr` and `.png` in the working directory.
    pub fn save_frame(&mut self) {
        match self.content.save_frame(&self.gpu) {
            Ok(paths) => {
                self.message = Some(format!("saved {}", paths.join(", ")));
                self.error = None;
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// Saves the edited scene (to `path`, or the panel's file name).
    pub fn save_scene(&mut self, path: Option<PathBuf>) {
        match self.content.save_scene(path) {
            Ok(Some(path)) => {
                self.message = Some(format!("saved the scene to {}", path.display()));
                self.error = None;
            }
            Ok(None) => {}
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    fn dropped(&mut self, ctx: &egui::Context) {
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .collect()
        });
        if let Some(path) = dropped.last() {
            self.open(path);
        }
    }

    /// Shows the frame texture in `ui` (registering it with egui's renderer) and returns the
    /// response for the mouse.
    fn show_frame(
        &mut self,
        ui: &mut egui::Ui,
        render_state: Option<&egui_wgpu::RenderState>,
        rect: egui::Rect,
    ) -> egui::Response {
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        let Some(targets) = self.content.targets() else {
            return response;
        };
        let Some(state) = render_state else {
            return response;
        };
        let size = targets.size;
        let mut renderer = state.renderer.write();
        let id = match self.texture {
            Some((id, drawn)) if drawn == size => id,
            Some((id, _)) => {
                renderer.update_egui_texture_from_wgpu_texture(
                    &state.device,
                    &targets.display_view,
                    wgpu::FilterMode::Linear,
                    id,
                );
                id
            }
            None => renderer.register_native_texture(
                &state.device,
                &targets.display_view,
                wgpu::FilterMode::Linear,
            ),
        };
        drop(renderer);
        self.texture = Some((id, size));
        let shown = self.content.display_rect(rect, size);
        ui.painter().image(
            id,
            shown,
            egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
            egui::Color32::WHITE,
        );
        response
    }

    fn screenshot(&mut self, ctx: &egui::Context) {
        let Some(shot) = &mut self.screenshot else {
            return;
        };
        if !shot.requested {
            let ready = self.frames_drawn >= 5 && !self.content.busy();
            if ready {
                let (sender, receiver) = channel();
                ctx.request_screenshot(move |image| {
                    let _ = sender.send(image);
                });
                shot.requested = true;
                shot.receiver = Some(receiver);
            } else if shot.started.elapsed() > SCREENSHOT_TIMEOUT {
                self.finish(
                    ctx,
                    Some("the window did not finish its first frames in time".into()),
                );
            }
            ctx.request_repaint();
            return;
        }
        let image = shot.receiver.as_ref().and_then(|r| r.try_recv().ok());
        match image {
            Some(image) => {
                let path = shot.path.clone();
                let result = save_color_image(&path, &image);
                self.finish(ctx, result.err().map(|e| e.to_string()));
            }
            None if shot.started.elapsed() > SCREENSHOT_TIMEOUT => {
                self.finish(ctx, Some("the screenshot never arrived".into()));
            }
            None => ctx.request_repaint(),
        }
    }

    fn finish(&mut self, ctx: &egui::Context, failure: Option<String>) {
        self.screenshot = None;
        *self
            .outcome
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = failure;
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }
}

/// Writes an egui screenshot as PNG (atomically).
pub fn save_color_image(path: &Path, image: &egui::ColorImage) -> Result<(), ViewerError> {
    let [w, h] = image.size;
    let pixels: Vec<[u8; 3]> = image.pixels.iter().map(|c| [c.r(), c.g(), c.b()]).collect();
    let picture = ibl_core::Image::from_vec(w, h, pixels)
        .map_err(|e| ViewerError::Window(format!("screenshot: {e}")))?;
    let bytes = ibl_io::ldr::encode_png(&picture).map_err(|e| e.with_path(path))?;
    ibl_io::write_atomically(path, &bytes)?;
    Ok(())
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let render_state = frame.wgpu_render_state().cloned();
        self.show(ui, render_state.as_ref());
    }
}

impl ViewerApp {
    /// One frame of the whole window into `ui`; the frame texture is shown when egui's
    /// `render_state` (on this app's device) is given (UI tests run without it).
    pub fn show(&mut self, ui: &mut egui::Ui, render_state: Option<&egui_wgpu::RenderState>) {
        let ctx = ui.ctx().clone();
        self.tick();
        self.dropped(&ctx);
        self.keys(&ctx);
        if let Err(e) = self.content.poll_workers(&self.gpu) {
            self.error = Some(e);
        }
        let adapter = self.adapter_line();
        let status = panels::StatusLine {
            fps: self.fps(),
            adapter: &adapter,
            error: self.error.as_deref(),
            message: self.message.as_deref(),
        };
        panels::status_bar(ui, &self.content, status);
        let requests = panels::side_panel(ui, &mut self.content);
        if requests.save_frame {
            self.save_frame();
        }
        if requests.save_scene {
            self.save_scene(None);
        }
        if requests.materials_changed {
            self.materials_changed();
        }
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE.fill(egui::Color32::from_gray(24)))
            .show(ui, |ui| {
                let rect = ui.available_rect_before_wrap();
                let scale = ctx.pixels_per_point();
                let size = self.content.render_size(rect.size(), scale);
                let drawn = self
                    .content
                    .draw(&self.gpu, size, scale)
                    .and_then(|()| self.gpu.take_errors());
                if let Err(e) = drawn {
                    self.error = Some(e.to_string());
                }
                let response = self.show_frame(ui, render_state, rect);
                let shown = self
                    .content
                    .targets()
                    .map(|t| self.content.display_rect(rect, t.size));
                if let Some(shown) = shown {
                    let input = ctx.input(PointerInput::of);
                    self.content.pointer(&response, shown, &input);
                }
                panels::central_messages(ui, &self.content, self.error.as_deref(), rect);
            });
        self.frames_drawn += 1;
        self.screenshot(&ctx);
        if self.content.animating() {
            ctx.request_repaint();
        }
    }
}

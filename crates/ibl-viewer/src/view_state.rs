//! What the window has open (nothing, a probe or a scene) with its renderer, its worker and its
//! view, and what input does to it. The window ([`crate::window`]) owns one [`Content`].

use std::path::{Path, PathBuf};
use std::sync::Arc;

use eframe::egui;
use glam::{Vec2, Vec3};
use ibl_core::tonemap::Display;
use ibl_mapping::Mapping;
use ibl_pipeline::LightingPlan;

use crate::ViewerError;
use crate::frame_targets::FrameTargets;
use crate::gpu::GpuContext;
use crate::lighting::{
    ProbeOverlay, ProbeOverlayRequest, SceneLighting, SceneLightingRequest, probe_overlay,
    scene_lighting,
};
use crate::probe_model::{ProbeModel, ProbeViewSettings};
use crate::probe_pass::ProbeProjection;
use crate::probe_renderer::ProbeRenderer;
use crate::room_edit::RoomEditSession;
use crate::room_marking::{PendingLine, RoomSession};
use crate::room_overlay::{OverlayView, perspective_view};
use crate::scene_model::{DragAction, SceneModel};
use crate::scene_renderer::{GlossySource, SceneFrameSettings, SceneRenderer};
use crate::sequence_state::SequenceState;
use crate::view_camera::{OrbitControl, OutputCamera};
use crate::view_job::ProbeExtras;
use crate::worker::LatestWorker;

/// A discrete action from the keyboard.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewEvent {
    /// Look along an axis: 0..6 = +X -X +Y -Y +Z -Z.
    Axis(usize),
    /// Frame the selection (scene) or reset the view (probe).
    Frame,
    /// Clear the selection.
    Deselect,
    /// The axis of the next marked line (probe: keys X, Y, Z).
    MarkAxis(ibl_room::Axis),
    /// Remove the last marked line (probe: Backspace).
    DeleteLastLine,
    /// Switch marking lines on or off (probe: key M).
    ToggleMarking,
}

/// The probe viewer's state.
pub struct ProbeState {
    /// The probe.
    pub model: ProbeModel,
    /// What is shown.
    pub settings: ProbeViewSettings,
    renderer: ProbeRenderer,
    worker: LatestWorker<ProbeOverlayRequest, Result<ProbeOverlay, String>>,
    requested: Option<(ibl_extract::ModelSpec, usize, usize)>,
    /// Seconds the last overlay took.
    pub overlay_seconds: f64,
    /// The direction and radiance under the cursor.
    pub cursor: Option<(Vec3, ibl_core::Rgb)>,
    /// The room tools: the marks being edited and the room shown over the probe.
    pub room: RoomSession,
    /// Material changes of the room (once switched on in the Room section; needs a room file).
    pub edit: Option<RoomEditSession>,
    /// The probe as read (what the edits start from and what undoing them shows).
    pub original: Arc<ibl_core::Image<ibl_core::Rgb>>,
}

/// How the scene camera is placed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneCamera {
    /// The scene file's own camera, exactly (letterboxed to its aspect).
    File,
    /// A camera the user moved.
    Orbit(OrbitControl),
}

/// A drag on an object in progress.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ObjectDrag {
    object: usize,
    action: DragAction,
    plane_y: f32,
    last_ray: (Vec3, Vec3),
}

impl SceneState {
    /// A scene's state as opened: its lights still to be made by the worker, nothing selected,
    /// the automatic exposure, no save path and no sequence.
    fn new(
        model: SceneModel,
        renderer: SceneRenderer,
        camera: SceneCamera,
        shadow_tile: u32,
    ) -> SceneState {
        let display = Display {
            exposure_stops: crate::headless::auto_exposure(&model),
            ..Display::default()
        };
        SceneState {
            save_path: String::new(),
            model,
            renderer,
            worker: LatestWorker::new("ibl-view lights", |r: SceneLightingRequest| {
                scene_lighting(&r)
            }),
            requested: None,
            camera,
            display,
            glossy: GlossySource::Lights,
            background_rays: 4,
            shadow_tile,
            selected: None,
            drag: None,
            lighting_seconds: 0.0,
            last_camera: None,
            hovered: None,
            sequence: None,
            fixed_lighting: false,
        }
    }

    /// The description of the lights drawn now (none before the first lighting arrives).
    pub fn renderer_lighting_summary(&self) -> Option<String> {
        self.renderer.lighting().map(|l| l.summary.clone())
    }
}

/// The scene viewer's state.
pub struct SceneState {
    /// The scene being edited.
    pub model: SceneModel,
    renderer: SceneRenderer,
    worker: LatestWorker<SceneLightingRequest, Result<SceneLighting, String>>,
    requested: Option<LightingPlan>,
    /// The camera.
    pub camera: SceneCamera,
    /// Exposure and tone curve.
    pub display: Display,
    /// Glossy reflections.
    pub glossy: GlossySource,
    /// Background rays per pixel axis.
    pub background_rays: u32,
    /// Shadow map side per light, texels.
    pub shadow_tile: u32,
    /// The selected object.
    pub selected: Option<usize>,
    drag: Option<ObjectDrag>,
    /// Seconds the last lighting took.
    pub lighting_seconds: f64,
    /// Where "save scene" writes.
    pub save_path: String,
    /// The camera of the last frame.
    pub last_camera: Option<OutputCamera>,
    /// The object under the cursor.
    pub hovered: Option<usize>,
    /// The outdoor sequence played (a scene with an `[outdoor]` table): its frames, sun and
    /// sky replace the background and the scene's `[lighting]`.
    pub sequence: Option<SequenceState>,
    /// The lights were given with the scene (a room's live display, `crate::room_live`): the
    /// scene's `[lighting]` does not replace them, and the scene is not saved (it is the room
    /// and an edits file, not a scene file).
    pub fixed_lighting: bool,
}

/// What the window has open.
pub enum Content {
    /// Nothing yet: the window asks for a file.
    Empty,
    /// A probe.
    Probe(Box<ProbeState>),
    /// A scene.
    Scene(Box<SceneState>),
}

/// The scene file's save name: `<stem>-edited.toml` beside it.
pub fn default_save_path(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or("scene".to_string(), |s| s.to_string_lossy().into_owned());
    scene.with_file_name(format!("{stem}-edited.toml"))
}

impl Content {
    /// Opens a probe or a scene file (`.toml`); `extras` aims a probe's camera and names the
    /// marks and room drawn over it (refused for a scene).
    pub fn open(
        gpu: &GpuContext,
        path: &Path,
        mapping: Option<Mapping>,
        size: (u32, u32),
        shadow_tile: u32,
        extras: &ProbeExtras,
    ) -> Result<Content, ViewerError> {
        let is_scene = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
        if is_scene && !extras.is_empty() {
            return Err(ViewerError::Parameter(
                "--marks, --room, --yaw, --pitch and --fov apply to a probe, not a scene".into(),
            ));
        }
        if let Some((room, edit)) = extras.live_room() {
            extras.check()?;
            let live = crate::room_live::room_live(room, edit, &ibl_pipeline::progress::Silent)?;
            let mut renderer = SceneRenderer::new(gpu, &live.model, size.0, size.1, shadow_tile)?;
            renderer.set_lighting(gpu, live.lighting);
            let mut state = SceneState::new(live.model, renderer, SceneCamera::File, shadow_tile);
            state.requested = Some(state.model.lighting_plan());
            state.fixed_lighting = true;
            return Ok(Content::Scene(Box::new(state)));
        }
        if is_scene {
            let model = SceneModel::open(path)?;
            let sequence = SequenceState::open(&model)?;
            let renderer = SceneRenderer::new(gpu, &model, size.0, size.1, shadow_tile)?;
            let camera = match model.scene.camera {
                ibl_scene::Camera::Pinhole { .. } => SceneCamera::File,
                ibl_scene::Camera::Panorama { position, .. } => SceneCamera::Orbit(OrbitControl {
                    target: position,
                    distance: 0.0,
                    yaw: 0.0,
                    pitch: 0.0,
                    vertical_fov: 60f32.to_radians(),
                }),
            };
            let mut state = SceneState::new(model, renderer, camera, shadow_tile);
            state.save_path = default_save_path(path).display().to_string();
            state.sequence = sequence;
            Ok(Content::Scene(Box::new(state)))
        } else {
            let mut model = ProbeModel::open(path, mapping)?;
            let mut settings = ProbeViewSettings::for_probe(&model.latlong);
            extras.aim(&mut settings.orbit)?;
            // An edits file's panorama replaces the probe (seconds: the estimate and the edits;
            // the objects' display takes longest).
            if let (Some(room), Some(edit)) = (&extras.room, &extras.edit) {
                model.latlong = Arc::new(crate::room_edit::edited_panorama(
                    room,
                    edit,
                    &model.latlong,
                )?);
            }
            let probe_size = (model.mapping == Mapping::LatLong)
                .then(|| [model.latlong.width() as u32, model.latlong.height() as u32]);
            let room = RoomSession::open(
                path,
                probe_size,
                extras.marks.as_deref(),
                extras.room.as_deref(),
            )?;
            let renderer = ProbeRenderer::new(gpu, &model, size.0, size.1)?;
            Ok(Content::Probe(Box::new(ProbeState {
                room,
                edit: None,
                original: Arc::clone(&model.latlong),
                model,
                settings,
                renderer,
                worker: LatestWorker::new("ibl-view overlay", |r: ProbeOverlayRequest| {
                    probe_overlay(&r)
                }),
                requested: None,
                overlay_seconds: 0.0,
                cursor: None,
            })))
        }
    }

    /// The frame's textures.
    pub fn targets(&self) -> Option<&FrameTargets> {
        match self {
            Content::Empty => None,
            Content::Probe(p) => Some(p.renderer.targets()),
            Content::Scene(s) => Some(s.renderer.targets()),
        }
    }

    /// Whether lights or overlays are being computed.
    pub fn busy(&self) -> bool {
        match self {
            Content::Empty => false,
            Content::Probe(p) => {
                p.worker.busy()
                    || p.requested.is_none()
                    || p.edit.as_ref().is_some_and(|e| e.busy())
            }
            Content::Scene(s) if s.sequence.is_some() => {
                s.sequence.as_ref().is_some_and(SequenceState::busy)
            }
            Content::Scene(s) => !s.fixed_lighting && (s.worker.busy() || s.requested.is_none()),
        }
    }

    /// Whether the window should keep repainting (a worker result is awaited, or a sequence
    /// plays).
    pub fn animating(&self) -> bool {
        let playing =
            matches!(self, Content::Scene(s) if s.sequence.as_ref().is_some_and(|q| q.playing));
        playing || self.busy()
    }

    /// Submits work whose inputs changed and takes finished results.
    pub fn poll_workers(&mut self, gpu: &GpuContext) -> Result<(), String> {
        match self {
            Content::Empty => Ok(()),
            Content::Probe(p) => {
                if let Some(edited) = p.edit.as_mut().and_then(|e| e.poll(&p.original)) {
                    p.renderer.set_probe(gpu, &edited);
                    p.model.latlong = edited;
                }
                let wanted = (p.settings.spec, p.settings.lights, p.settings.bands);
                if p.requested != Some(wanted) {
                    p.worker.submit(ProbeOverlayRequest {
                        probe: Arc::clone(&p.model.latlong),
                        spec: wanted.0,
                        lights: wanted.1,
                        bands: wanted.2,
                    });
                    p.requested = Some(wanted);
                }
                match p.worker.poll() {
                    Some(done) => {
                        p.overlay_seconds = done.seconds;
                        let overlay = done.result?;
                        p.renderer.set_overlay(gpu, overlay);
                        Ok(())
                    }
                    None => Ok(()),
                }
            }
            Content::Scene(s) if s.sequence.is_some() => {
                let SceneState {
                    model,
                    renderer,
                    display,
                    sequence,
                    ..
                } = &mut **s;
                match sequence {
                    Some(q) => q
                        .poll(gpu, model, renderer, display)
                        .map_err(|e| e.to_string()),
                    None => Ok(()),
                }
            }
            Content::Scene(s) if s.fixed_lighting => Ok(()),
            Content::Scene(s) => {
                let plan = s.model.lighting_plan();
                if s.requested.as_ref() != Some(&plan) {
                    s.worker.submit(SceneLightingRequest {
                        scene: Arc::clone(&s.model.scene),
                        plan: plan.clone(),
                    });
                    s.requested = Some(plan);
                }
                match s.worker.poll() {
                    Some(done) => {
                        s.lighting_seconds = done.seconds;
                        let lighting = done.result?;
                        s.renderer.set_lighting(gpu, lighting);
                        Ok(())
                    }
                    None => Ok(()),
                }
            }
        }
    }

    /// The frame size for an area of `available` points at `scale` pixels per point: the whole
    /// area, or the largest rectangle of the scene camera's aspect inside it.
    pub fn render_size(&self, available: egui::Vec2, scale: f32) -> (u32, u32) {
        let w = (available.x * scale).round().max(1.0);
        let h = (available.y * scale).round().max(1.0);
        let (w, h) = match self {
            Content::Scene(s) if s.camera == SceneCamera::File => match s.model.scene.camera {
                ibl_scene::Camera::Pinhole {
                    reference_size: (rw, rh),
                    ..
                } => {
                    let aspect = rw as f32 / rh as f32;
                    if w / h > aspect {
                        (h * aspect, h)
                    } else {
                        (w, w / aspect)
                    }
                }
                ibl_scene::Camera::Panorama { .. } => (w, h),
            },
            _ => (w, h),
        };
        let max = crate::frame_targets::MAX_OUTPUT_SIDE as f32;
        (
            w.round().clamp(1.0, max) as u32,
            h.round().clamp(1.0, max) as u32,
        )
    }

    /// Where a frame of `size` pixels is shown inside `rect`: centred, at its own aspect.
    pub fn display_rect(&self, rect: egui::Rect, size: (u32, u32)) -> egui::Rect {
        let aspect = size.0 as f32 / size.1.max(1) as f32;
        let (w, h) = if rect.width() / rect.height().max(1.0) > aspect {
            (rect.height() * aspect, rect.height())
        } else {
            (rect.width(), rect.width() / aspect)
        };
        egui::Rect::from_center_size(rect.center(), egui::vec2(w, h))
    }

    /// Draws a frame of `size` pixels; `scale` is pixels per point (marker sizes).
    pub fn draw(
        &mut self,
        gpu: &GpuContext,
        size: (u32, u32),
        scale: f32,
    ) -> Result<(), ViewerError> {
        match self {
            Content::Empty => Ok(()),
            Content::Probe(p) => {
                p.renderer.resize(gpu, size.0, size.1)?;
                let view = OverlayView::of_settings(&p.settings, size.0, size.1);
                let segments = p.room.segments(&view, scale);
                p.renderer.render_with(gpu, &p.settings, scale, &segments);
                Ok(())
            }
            Content::Scene(s) => {
                s.renderer.resize(gpu, &s.model, size.0, size.1)?;
                let camera = s.camera(size);
                s.last_camera = Some(camera);
                let settings = SceneFrameSettings {
                    camera,
                    display: s.display,
                    glossy: s.glossy,
                    background_rays: s.background_rays,
                    shadow_tile: s.shadow_tile,
                    selected: s.selected,
                    light_culling: true,
                    shadow_culling: true,
                    shadow_levels: true,
                };
                s.renderer.render(gpu, &s.model, &settings);
                let _ = s.renderer.read_pass_times(gpu, false);
                Ok(())
            }
        }
    }

    /// Handles a key.
    pub fn handle(&mut self, event: ViewEvent) {
        match (self, event) {
            (Content::Probe(p), ViewEvent::Axis(axis)) => {
                let (yaw, pitch) = axis_view(axis);
                p.settings.orbit.yaw = yaw;
                p.settings.orbit.pitch = pitch;
                p.settings.projection = ProbeProjection::LookAround;
            }
            (Content::Probe(p), ViewEvent::Frame) => {
                p.settings.orbit.yaw = 0.0;
                p.settings.orbit.pitch = 0.0;
            }
            (Content::Probe(p), ViewEvent::MarkAxis(axis)) => p.room.axis = axis,
            (Content::Probe(p), ViewEvent::DeleteLastLine) => {
                p.room.delete_last_line();
            }
            (Content::Probe(p), ViewEvent::ToggleMarking) => {
                p.room.marking = !p.room.marking;
                p.room.pending = None;
            }
            (Content::Scene(s), ViewEvent::Frame) => s.frame_selection(),
            (Content::Scene(s), ViewEvent::Deselect) => s.selected = None,
            _ => {}
        }
    }

    /// What the mouse did over the frame shown in `shown`.
    pub fn pointer(&mut self, response: &egui::Response, shown: egui::Rect, input: &PointerInput) {
        match self {
            Content::Empty => {}
            Content::Probe(p) => p.pointer(response, shown, input),
            Content::Scene(s) => s.pointer(response, shown, input),
        }
    }

    /// Saves the frame as EXR and PNG in the working directory.
    pub fn save_frame(&self, gpu: &GpuContext) -> Result<Vec<String>, ViewerError> {
        let (targets, source) = match self {
            Content::Empty => return Err(ViewerError::Parameter("nothing is open".into())),
            Content::Probe(p) => (p.renderer.targets(), &p.model.path),
            Content::Scene(s) => (s.renderer.targets(), &s.model.path),
        };
        let images = targets.read_back(gpu)?;
        let stem = source
            .file_stem()
            .map_or("frame".to_string(), |s| s.to_string_lossy().into_owned());
        let (png, exr) = (1..10_000)
            .map(|n| {
                (
                    PathBuf::from(format!("{stem}-frame-{n}.png")),
                    PathBuf::from(format!("{stem}-frame-{n}.exr")),
                )
            })
            .find(|(png, exr)| !png.exists() && !exr.exists())
            .ok_or_else(|| ViewerError::Parameter("no free frame file name".into()))?;
        let bytes = ibl_io::ldr::encode_png(&images.display).map_err(|e| e.with_path(&png))?;
        ibl_io::write_atomically(&png, &bytes)?;
        ibl_io::write_image(&exr, &images.radiance, &ibl_io::WriteOptions::default())?;
        Ok(vec![png.display().to_string(), exr.display().to_string()])
    }

    /// Saves the edited scene to `path` (default: the panel's save path); `Ok(None)` when no
    /// scene is open.
    pub fn save_scene(&self, path: Option<PathBuf>) -> Result<Option<PathBuf>, ViewerError> {
        let Content::Scene(s) = self else {
            return Ok(None);
        };
        let path = path.unwrap_or_else(|| PathBuf::from(&s.save_path));
        s.save(&path)?;
        Ok(Some(path))
    }
}

/// Yaw and pitch that look along axis `k` (0..6 = +X -X +Y -Y +Z -Z).
pub fn axis_view(k: usize) -> (f32, f32) {
    use std::f32::consts::{FRAC_PI_2, PI};
    let up = 89f32.to_radians();
    match k {
        0 => (-FRAC_PI_2, 0.0),
        1 => (FRAC_PI_2, 0.0),
        2 => (0.0, up),
        3 => (0.0, -up),
        4 => (PI, 0.0),
        _ => (0.0, 0.0),
    }
}

/// Pixel coordinates in a frame of `size` of a pointer position over the shown rectangle.
fn frame_pixel(pos: egui::Pos2, shown: egui::Rect, size: (u32, u32)) -> Vec2 {
    Vec2::new(
        (pos.x - shown.min.x) / shown.width() * size.0 as f32,
        (pos.y - shown.min.y) / shown.height() * size.1 as f32,
    )
}

impl ProbeState {
    /// The frame's size, pixels (the size of the view a line marked now is saved with).
    pub fn frame_size(&self) -> (u32, u32) {
        self.renderer.targets().size
    }

    /// Whether a left-drag marks a line now (marking is on and the view looks around).
    pub fn marking_lines(&self) -> bool {
        self.room.marking && self.settings.projection == ProbeProjection::LookAround
    }

    /// A left-drag while marking: starts, moves and finishes the pending line (in the view the
    /// drag started in); a refused line's reason is kept in the room tools.
    fn mark(&mut self, response: &egui::Response, shown: egui::Rect, input: &PointerInput) {
        let size = self.renderer.targets().size;
        let at = |p: egui::Pos2| {
            let px = frame_pixel(p, shown, size);
            [f64::from(px.x), f64::from(px.y)]
        };
        if response.drag_started_by(egui::PointerButton::Primary)
            && let Some(origin) = input.press_origin.or(response.interact_pointer_pos())
        {
            let from = at(origin);
            self.room.pending = Some(PendingLine {
                view: perspective_view(&self.settings.orbit, size.0, size.1),
                axis: self.room.axis,
                from,
                to: from,
            });
        }
        if response.dragged_by(egui::PointerButton::Primary)
            && let (Some(pending), Some(p)) =
                (self.room.pending.as_mut(), response.interact_pointer_pos())
        {
            pending.to = at(p);
        }
        if response.drag_stopped_by(egui::PointerButton::Primary)
            && let Some(p) = self.room.pending.take()
        {
            self.room.refused = self.room.add_line(p.view, p.axis, p.from, p.to).err();
        }
    }

    fn pointer(&mut self, response: &egui::Response, shown: egui::Rect, input: &PointerInput) {
        let size = self.renderer.targets().size;
        let per_pixel = self.settings.orbit.vertical_fov / shown.height().max(1.0);
        // While marking, the left button draws lines and the right one turns the view.
        let turning = if self.marking_lines() {
            self.mark(response, shown, input);
            response.dragged_by(egui::PointerButton::Secondary)
        } else {
            self.room.pending = None;
            response.dragged_by(egui::PointerButton::Primary)
        };
        if turning && self.settings.projection == ProbeProjection::LookAround {
            let d = response.drag_delta();
            self.settings.orbit.turn(d.x * per_pixel, d.y * per_pixel);
        }
        if response.hovered() && input.scroll != 0.0 {
            let fov = self.settings.orbit.vertical_fov * (-input.scroll * 0.002).exp();
            self.settings.orbit.vertical_fov = fov.clamp(10f32.to_radians(), 150f32.to_radians());
        }
        self.cursor = response
            .hover_pos()
            .filter(|p| shown.contains(*p))
            .map(|p| {
                let px = frame_pixel(p, shown, size);
                let d = self.settings.direction_at(px.x, px.y, size.0, size.1);
                (d, self.model.radiance_towards(d))
            });
        // A click picks the material group under the cursor, places a light there or moves a
        // placed one there, while the room's edits ask for it.
        if response.clicked_by(egui::PointerButton::Primary)
            && let (Some(edit), Some((d, _))) = (self.edit.as_mut(), self.cursor)
        {
            edit.click(d);
        }
    }
}

impl SceneState {
    /// The camera of a frame of `size`.
    pub fn camera(&self, size: (u32, u32)) -> OutputCamera {
        match self.camera {
            SceneCamera::File => crate::headless::scene_camera(&self.model, size.0, size.1),
            SceneCamera::Orbit(orbit) => orbit.camera(size.0, size.1),
        }
    }

    /// Whether the camera may move (a photograph fixes it).
    pub fn camera_movable(&self) -> bool {
        matches!(self.model.scene.background, ibl_scene::Background::Panorama)
    }

    /// The orbit equivalent to the current view (switching from the file's camera).
    fn orbit(&mut self) -> &mut OrbitControl {
        if self.camera == SceneCamera::File {
            let c = self.last_camera.unwrap_or_else(|| self.camera((640, 480)));
            let target = self.model.objects_sphere().map_or(
                c.position + c.ray(0.5 * c.size.0 as f32, 0.5 * c.size.1 as f32),
                |(p, _)| p,
            );
            let forward = c.ray(0.5 * c.size.0 as f32, 0.5 * c.size.1 as f32);
            let distance = (target - c.position).dot(forward).max(0.1);
            self.camera = SceneCamera::Orbit(OrbitControl::from_view(
                c.position,
                forward,
                distance,
                c.vertical_fov(),
            ));
        }
        match &mut self.camera {
            SceneCamera::Orbit(o) => o,
            SceneCamera::File => unreachable!("switched to an orbit above"),
        }
    }

    fn frame_selection(&mut self) {
        let Some((centre, radius)) = self.model.objects_sphere() else {
            return;
        };
        if !self.camera_movable() {
            return;
        }
        let orbit = self.orbit();
        orbit.target = centre;
        orbit.distance = (radius / (0.5 * orbit.vertical_fov).tan() * 1.3).max(0.05);
    }

    fn ray_at(&self, camera: &OutputCamera, px: Vec2) -> (Vec3, Vec3) {
        (camera.position, camera.ray(px.x, px.y))
    }

    fn pointer(&mut self, response: &egui::Response, shown: egui::Rect, input: &PointerInput) {
        let Some(camera) = self.last_camera else {
            return;
        };
        let size = camera.size;
        let pixel = |p: egui::Pos2| frame_pixel(p, shown, size);
        let pick = |s: &Self, p: egui::Pos2| {
            let (o, d) = s.ray_at(&camera, pixel(p));
            s.model.pick(o, d).map(|(i, t)| (i, o + d * t))
        };
        self.hovered = response
            .hover_pos()
            .and_then(|p| pick(self, p))
            .map(|(i, _)| i);
        if response.drag_started_by(egui::PointerButton::Primary)
            && let Some(p) = response.interact_pointer_pos()
        {
            self.drag = pick(self, p).map(|(object, at)| ObjectDrag {
                object,
                action: if input.shift {
                    DragAction::Rotate
                } else if input.ctrl {
                    DragAction::Scale
                } else {
                    DragAction::Move
                },
                plane_y: at.y,
                last_ray: self.ray_at(&camera, pixel(p)),
            });
            if let Some(drag) = self.drag {
                self.selected = Some(drag.object);
            }
        }
        if response.dragged_by(egui::PointerButton::Primary) {
            let d = response.drag_delta();
            match (self.drag, response.interact_pointer_pos()) {
                (Some(mut drag), Some(p)) => {
                    if drag.action == DragAction::Move {
                        let ray = self.ray_at(&camera, pixel(p));
                        let reach = self
                            .model
                            .objects_sphere()
                            .map_or(100.0, |(_, r)| 200.0 * r);
                        self.model
                            .drag_to(drag.object, drag.plane_y, drag.last_ray, ray, reach);
                        drag.last_ray = ray;
                        self.drag = Some(drag);
                    } else {
                        self.model.drag_pixels(drag.object, drag.action, d.x, d.y);
                    }
                }
                _ if self.camera_movable() => {
                    let k = 0.005;
                    self.orbit().turn(-d.x * k, -d.y * k);
                }
                _ => {}
            }
        }
        if response.drag_stopped() {
            self.drag = None;
        }
        let panning = response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle);
        if panning && self.camera_movable() {
            let d = response.drag_delta();
            let orbit = self.orbit();
            let s =
                2.0 * orbit.distance.max(0.1) * (0.5 * orbit.vertical_fov).tan() / shown.height();
            orbit.pan(-d.x * s, d.y * s);
        }
        if response.hovered() && input.scroll != 0.0 && self.camera_movable() {
            let factor = (-input.scroll * 0.002).exp();
            let orbit = self.orbit();
            if orbit.distance > 0.0 {
                orbit.dolly(factor);
            } else {
                orbit.vertical_fov = (orbit.vertical_fov * factor).clamp(0.2, 2.6);
            }
        }
        if response.clicked() {
            self.selected = response
                .interact_pointer_pos()
                .and_then(|p| pick(self, p))
                .map(|(i, _)| i);
        }
    }

    /// Writes the edited scene to `path` (refusing to write over any file the scene reads).
    pub fn save(&self, path: &Path) -> Result<(), ViewerError> {
        let mut description = self.model.description.clone();
        if let SceneCamera::Orbit(orbit) = self.camera
            && self.camera_movable()
        {
            let size = self.last_camera.map_or((640, 480), |c| c.size);
            description.camera = Some(crate::scene_save::camera_description(
                &orbit,
                description.camera.as_ref(),
                size,
            ));
        }
        let inputs: Vec<&Path> = self.model.inputs.iter().map(PathBuf::as_path).collect();
        ibl_io::ensure_output_is_not_input(path, &inputs)?;
        let text = crate::scene_save::scene_text(&self.model, &description, path)?;
        ibl_io::write_atomically(path, text.as_bytes())?;
        Ok(())
    }

    /// The lighting drawn now.
    pub fn lighting(&self) -> Option<&SceneLighting> {
        self.renderer.lighting()
    }

    /// Shadow map side per light drawn now.
    pub fn drawn_shadow_tile(&self) -> u32 {
        self.renderer.shadow_tile()
    }

    /// GPU pass times of a recent frame.
    pub fn pass_times(&self) -> Option<&crate::timing::PassTimes> {
        self.renderer.last_pass_times.as_ref()
    }

    /// Rewrites the materials after an edit.
    pub fn materials_changed(&self, gpu: &GpuContext) {
        self.renderer.update_materials(gpu, &self.model);
    }

    /// The last frame, read back.
    pub fn read_frame(
        &self,
        gpu: &GpuContext,
    ) -> Result<crate::frame_targets::FrameImages, ViewerError> {
        self.renderer.targets().read_back(gpu)
    }

    /// Whether lights are being computed.
    pub fn lighting_busy(&self) -> bool {
        self.worker.busy()
    }
}

impl ProbeState {
    /// The overlay drawn now.
    pub fn overlay(&self) -> Option<&ProbeOverlay> {
        self.renderer.overlay()
    }

    /// Whether the overlay is being computed.
    pub fn overlay_busy(&self) -> bool {
        self.worker.busy()
    }
}

/// The pointer state the views need beyond a widget's response.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointerInput {
    /// Wheel movement this frame, points (positive: away from the user).
    pub scroll: f32,
    /// Shift held.
    pub shift: bool,
    /// Ctrl (Cmd on macOS) held.
    pub ctrl: bool,
    /// Where the press of the button held down began, points.
    pub press_origin: Option<egui::Pos2>,
}

impl PointerInput {
    /// The pointer state of a frame's input.
    pub fn of(input: &egui::InputState) -> PointerInput {
        PointerInput {
            scroll: input.smooth_scroll_delta.y,
            shift: input.modifiers.shift,
            ctrl: input.modifiers.command,
            press_origin: input.pointer.press_origin(),
        }
    }
}

//! The iblkit real-time viewer (wgpu + egui): light probes, and virtual objects composited into
//! them by differential rendering with a shadow for every light (Grosch 2005 section 4; Jensen,
//! Andersen & Madsen 2006; the light sets of Madsen & Laursen 2006). Every GPU type and WGSL
//! shader of iblkit lives here, each shader beside the module that drives it; the window and the
//! headless path run the same renderers.
//!
//! Data (CPU):
//! - [`probe_model`]: a probe in any format and mapping, as lat-long; what the probe viewer shows.
//! - [`scene_model`]: a scene file being viewed and edited (picking, moving, materials, saving).
//! - [`scene_geometry`]: the assembled scene's triangles, per object, for the rasteriser.
//! - [`lighting`]: lights, hybrid ambient and probe overlays, through the library.
//! - [`worker`]: a background thread answering only the latest request.
//! - [`view_camera`]: the pinhole camera of `ibl_scene` as a projection, and orbit controls.
//! - [`room_overlay`]: a marks file's lines and a room file's edges as segments in the current
//!   view (Grosch 2005 section 3.1); [`room_marking`]: the marks being edited in the window
//!   (adding lines, calibrating, saving); [`room_edit`]: the room's materials changed by
//!   clicking a surface, with colour bleeding (Grosch 2005 section 4.3).
//! - [`light_space`]: orthographic shadow projections and the atlas layout.
//! - [`sequence_player`]: an outdoor scene's frames played through the library's per-frame sun
//!   and sky estimation (Jensen, Andersen & Madsen 2006), as lights, ambient and background.
//!
//! GPU:
//! - [`gpu`]: the device; [`textures`]: radiance uploads; [`frame_targets`]: what a frame is drawn
//!   into and reading it back; [`gpu_scene`]: the scene's buffers.
//! - [`environment_maps`]: the probe's mip chains (box and Phong-prefiltered).
//! - [`shadow_atlas`]: one shadow map per light, cached by what moves.
//! - [`scene_pass`]: shading and the differential composite; [`probe_pass`]: the probe viewer;
//!   [`display_pass`]: exposure and tone curves; [`markers_pass`]: light markers;
//!   [`lines_pass`]: antialiased lines (the room overlays); [`overlay_pipeline`]: the
//!   pipeline both overlay passes share.
//! - [`scene_renderer`], [`probe_renderer`]: one frame each; [`timing`]: GPU pass timestamps.
//! - [`headless`]: offscreen frames and the benchmark; [`window`]: the eframe application,
//!   [`view_state`] what it has open, [`panels`] its widgets ([`room_panel`] the room tools',
//!   [`sequence_panel`] an outdoor sequence's, played by [`sequence_state`]),
//!   [`scene_save`] saving the scene.
//!
//! The extension points the indoor and outdoor pipelines plug into: [`lighting::SceneLighting`]
//! is the light list a frame draws (directional lights now; area patches, goniometric lights and
//! a per-frame sun and sky join it as further light kinds of the same list and further loops of
//! `scene_pass.wgsl`), the ambient is a world-frame irradiance texture (an irradiance volume
//! replaces it by a 3-D texture read at the shading point), and the worker recomputes either off
//! the UI thread.

pub mod caster_cells;
pub mod command_line;
pub mod demo_frames;
pub mod display_pass;
pub mod environment_maps;
mod error;
pub mod frame_targets;
pub mod gpu;
pub mod gpu_scene;
pub mod headless;
pub mod light_space;
pub mod light_tiles;
pub mod lighting;
pub mod lines_pass;
pub mod markers_pass;
pub mod overlay_pipeline;
pub mod panels;
pub mod point_lights;
pub mod probe_model;
pub mod probe_pass;
pub mod probe_renderer;
pub mod room_edit;
pub mod room_live;
pub mod room_marking;
pub mod room_overlay;
pub mod room_panel;
pub mod scene_geometry;
pub mod scene_model;
pub mod scene_pass;
pub mod scene_renderer;
pub mod scene_save;
pub mod sequence_panel;
pub mod sequence_player;
pub mod sequence_state;
pub mod shadow_atlas;
pub mod shadow_lod;
pub mod textures;
pub mod timing;
pub mod view_camera;
pub mod view_job;
pub mod view_state;
pub mod window;
pub mod worker;

pub use error::ViewerError;
pub use gpu::GpuContext;
pub use headless::{HeadlessOptions, HeadlessRun, Motion};
/// The sphere mappings a probe file may be in (what [`ProbeModel::open`] and the window take).
pub use ibl_mapping::Mapping;
pub use probe_model::{ProbeModel, ProbeViewSettings};
pub use scene_model::SceneModel;
pub use view_job::{ProbeExtras, ViewJob, ViewSummary};

//! The reconstructed room of Grosch 2005 ("Real time augmentation of omni-directional images with
//! consistent lighting", section 3): a simple model of the room (floor, walls, ceiling, furniture
//! as boxes) from one HDR light probe, every surface's diffuse reflectance estimated by radiosity
//! from the probe's radiance, and the "important" light patches.
//!
//! World frame and units as `docs/CONVENTIONS.md` (+Y up, -Z forward, +X right; metres; radiance
//! in the probe's units, radiosity `B = pi L`). The method and a worked example: `docs/ROOMS.md`.
//!
//! - [`description`]: the room file (`[probe]` and `[room]`, parsed as a scene); the `[room]`
//!   table's types (groups, rectangles, boxes, polygons) are `ibl-scene`'s, re-exported.
//! - [`geometry`]: planar faces with their frames; [`patches`]: subdivision by area (3.3).
//! - [`room`]: the resolved room with its BVH and the placed probe.
//! - [`depth_map`]: the omnidirectional depth map from the probe centre (3.2, Fig. 5).
//! - [`observation`]: each patch's radiance from the probe pixels that see it.
//! - [`form_factors`]: form factors by ray casting; [`radiosity`]: the forward solve.
//! - [`reflectance`]: `rho = B / E` and the hidden-region iteration (3.2, steps 1 to 5);
//!   [`analysis`]: all of 3.2 in one call; [`report`]: Table 1 as JSON and Markdown;
//!   [`picture`]: patches coloured by reflectance, the model over the panorama.
//! - [`important`]: the important light patches (3.3).
//! - Augmenting the room (section 4): [`room_radiance`] (the probe's texture where it saw, the
//!   estimate `rho E / pi` where it did not), [`irradiance_volume`] (all and unimportant light
//!   on a grid, 4.1; [`ambient_cube`] the representation it was measured against) and
//!   [`mod@volume_error`] (its interpolation error against direct gathering), [`material_change`]
//!   (new reflectances and colour bleeding by delta radiosity, 4.3), [`novel_view`] (the room
//!   from a moved camera, 4.4) with [`fill_texture`] (its fill modulated by the seen texture,
//!   beyond the paper), [`added_light`] (new goniometric lights, direct per point and their
//!   bounces by delta radiosity, 4.2), [`virtual_objects`] (objects inserted, Grosch's fast and
//!   improved displays, their shadows on the room, 4.1).
//! - Geometry from the probe (3.1): [`view`] (perspective views of the panorama), [`marks`] (the
//!   marks file), [`vanishing`] (vanishing points, axes, `world_from_probe`), [`scale`],
//!   [`placement`] (shapes by constraints, the room file they make); beyond the paper,
//!   [`line_detection`] and [`manhattan`] (an automatic frame proposal).
//!
//! This crate does no file I/O: it parses and writes text; `ibl-io` and the front ends own files.

pub mod added_light;
pub mod ambient_cube;
pub mod analysis;
pub mod depth_map;
pub mod description;
mod error;
pub mod fill_texture;
pub mod form_factors;
pub mod geometry;
pub mod important;
pub mod irradiance_volume;
pub mod line_detection;
pub mod manhattan;
pub mod marks;
pub mod material_change;
pub mod novel_view;
pub mod observation;
pub mod patches;
pub mod picture;
pub mod placement;
pub mod radiosity;
pub mod reflectance;
pub mod report;
pub mod room;
pub mod room_radiance;
pub mod scale;
pub mod vanishing;
pub mod view;
pub mod virtual_objects;
pub mod volume_error;

pub use added_light::{LightAddition, LightAdditionSettings, add_lights};
pub use analysis::{AnalysisSettings, RoomAnalysis, Stage, analyse_room};
pub use depth_map::ProbeDepthMap;
pub use description::{GroupKind, RoomDescription, RoomFile};
pub use error::RoomError;
pub use fill_texture::{FillTexture, FillTextureSettings};
pub use form_factors::{FormFactorSettings, FormFactors};
pub use important::{AreaPatchLight, ImportantLights, important_patches};
pub use irradiance_volume::{KeyPointVisibility, RoomVolume, VolumeSettings};
pub use manhattan::{ManhattanProposal, ManhattanSettings, propose_manhattan_frame};
pub use marks::{Axis, MarksFile};
pub use material_change::{MaterialChange, MaterialEdit, change_materials};
pub use novel_view::{HoleFill, NovelView, NovelViewSettings, render_novel_view};
pub use observation::{ObservationSettings, Observations, observe};
pub use placement::reconstruct;
pub use reflectance::{Estimate, EstimationSettings, estimate_reflectance};
pub use report::RoomReport;
pub use room::{Group, Room};
pub use room_radiance::RoomRadiance;
pub use scale::{Scale, probe_height};
pub use vanishing::{Calibration, calibrate, line_observations};
pub use view::PerspectiveView;
pub use virtual_objects::{DisplayMode, ObjectDisplay, ObjectDisplaySettings, ObjectPicture};
pub use volume_error::{VolumeError, VolumeErrorSettings, volume_error};

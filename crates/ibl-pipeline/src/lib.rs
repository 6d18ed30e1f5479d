//! Every multi-step job the front ends run, so that the `ibl` command line tool, the viewer and
//! the Python bindings call the same code: each job takes an options struct, reads its inputs
//! through `ibl-io`, runs the algorithms of the other crates, writes its outputs (atomically,
//! never over an input) and returns a summary the front end shows (text, JSON, a widget).
//! Progress and notes go through the [`Progress`] the front end supplies; nothing here prints.
//!
//! - [`envmap_files`]: environment maps on disk, one file in any mapping or six cube faces;
//!   [`probe_input`]: the one probe loader (mapping detected or given, converted to lat-long);
//! - [`info`]: probe statistics; [`convert`]: mappings, formats, rotations, frame presets;
//!   [`preview`]: tone-mapped pictures; [`irradiance`]: irradiance on normals and as maps;
//! - [`lights`]: light sets in every format, hybrid lighting, overlays; [`sh`]: spherical
//!   harmonics in every tool's convention; [`prefilter`](mod@prefilter): engine-ready maps (GGX
//!   specular chains, irradiance cube, SH, DFG table as KTX2/DDS);
//! - [`lighting_plan`]: what lights a render (mode, method, light-file rules);
//!   [`render`]: a scene rendered and composited;
//! - [`eval`]: the comparison of the extraction methods as a report folder; [`compare`]: image
//!   metrics between two files;
//! - [`room_calibrate`], [`room_estimate`], [`room_lights`], [`room_render`]: the reconstructed
//!   room of Grosch 2005 (marks to frame and scale, room and probe to reflectance and the
//!   report, the important patches as an area-light file, the room re-rendered after material
//!   changes and from a moved camera), on [`room_input`];
//! - [`outdoor`]: outdoor AR under changing light (Jensen, Andersen & Madsen 2006): per-frame
//!   sun and sky estimates, relit maps and composites of a frame sequence, played through
//!   [`outdoor_sequence`] (which the viewer's sequence mode plays too); [`video`]: video in and
//!   out through ffmpeg;
//! - [`capture`]: brackets merged to HDR ([`exposure_list`]: the time files it reads);
//!   [`capture_views`]: mirror balls and fisheye pairs;
//! - [`batch`]: the per-probe pipeline over a folder, a glob or a list, one row per probe, as
//!   [`batch_spec`] says (`ibl batch`, `python -m iblkit.batch`);
//! - [`demo`]: the main job on the bundled probes and scenes ([`demo_probe`], [`demo_render`],
//!   [`demo_page`], [`demo_paths`], [`demo_room`], [`demo_outdoor`]; [`demo_text`]: what the
//!   command line prints after the demo and the comparison).
//!
//! Every output path is checked before the work starts ([`output_paths`]).
//!
//! Errors are [`PipelineError`]s, split by cause; [`PipelineError::is_bad_input`] tells the
//! caller's fault from ours.

pub mod batch;
pub mod batch_spec;
pub mod capture;
pub mod capture_views;
pub mod compare;
pub mod convert;
pub mod demo;
pub mod demo_outdoor;
pub mod demo_page;
pub mod demo_paths;
pub mod demo_probe;
pub mod demo_render;
pub mod demo_room;
pub mod demo_section;
pub mod demo_text;
pub mod envmap_files;
pub mod error;
pub mod eval;
pub mod exposure_list;
pub mod info;
pub mod interrupts;
pub mod irradiance;
pub mod lighting_plan;
pub mod lights;
pub mod outdoor;
pub mod outdoor_sequence;
pub mod output_paths;
pub mod prefilter;
pub mod preview;
pub mod probe_input;
pub mod progress;
pub mod progress_lines;
pub mod render;
pub mod room_calibrate;
pub mod room_display;
pub mod room_estimate;
pub mod room_input;
pub mod room_lights;
pub mod room_render;
pub mod sh;
pub mod video;

pub use envmap_files::EnvMapping;
pub use error::{PipelineError, Result};
pub use lighting_plan::LightingPlan;
pub use probe_input::{LoadedProbe, ProbeDetection, load_probe};
pub use progress::{Progress, Silent};

//! Core types shared by every iblkit crate: linear RGB radiance, images with row 0 at the top,
//! unit directions in the world frame (+Y up, -Z forward, +X right: the glTF frame), named frame
//! presets, the lat-long parameterisation with exact texel solid angles, Fibonacci normals,
//! summed-area tables, the exact irradiance of a lat-long probe, the display transform (tone
//! mapping to 8-bit sRGB, shared by file previews and the viewer) and a synthetic sky for
//! benchmarks and tests.
//!
//! This crate does no I/O and knows no file formats; see `docs/CONVENTIONS.md` for every formula.

pub mod direction;
pub mod fibonacci;
pub mod frame;
pub mod image;
pub mod irradiance;
pub mod latlong;
pub mod rgb;
pub mod summed_area;
pub mod synthetic;
pub mod tonemap;

pub use direction::UnitDir;
pub use fibonacci::fibonacci_normals;
pub use frame::{EulerDegrees, FramePreset};
pub use glam;
pub use image::Image;
pub use irradiance::{
    RowIrradiance, channel_means, irradiance_exact, irradiance_exact_with_progress, valid_radiance,
};
pub use latlong::LatLong;
pub use rgb::Rgb;
pub use summed_area::SummedAreaTable;
pub use synthetic::SyntheticSky;
